//! Smooth minimum and maximum: the blend behind the smooth CSG operators.

use crate::lanes::Lane;

/// Quadratic polynomial smooth minimum (iq, "smin", the normalised form with `k *= 4`).
///
/// `k` is the largest amount by which the result undercuts `min(a, b)`, reached where
/// `a == b`; the blend acts only where `|a - b| < 4k`. A `k` that is not positive (or NaN)
/// gives the plain `min`.
///
/// Lipschitz: inside the band the partial derivatives are `w` and `1 - w` with
/// `w = (4k + |a - b|) / 8k` in `[1/2, 1]`, outside they are `(1, 0)` or `(0, 1)`, and the
/// function is C1 across the band's edges. So `|smin(a, b) - smin(a', b')| <=
/// max(|a - a'|, |b - b'|)`: blending L1- and L2-Lipschitz fields is max(L1, L2)-Lipschitz.
#[inline]
pub fn smooth_min(a: f32, b: f32, k: f32) -> f32 {
    smooth_min_lanes(a, b, k)
}

/// Smooth maximum, `-smooth_min(-a, -b, k)`: overshoots `max(a, b)` by at most `k`, with
/// the same Lipschitz argument as [`smooth_min`].
#[inline]
pub fn smooth_max(a: f32, b: f32, k: f32) -> f32 {
    smooth_max_lanes(a, b, k)
}

/// [`smooth_min`] over any [`Lane`] type, its one definition; the blend size is the same
/// in every lane.
#[inline(always)]
pub(crate) fn smooth_min_lanes<L: Lane>(a: L, b: L, k: f32) -> L {
    // Written so that NaN takes the hard-min path too.
    if k.is_nan() || k <= 0.0 {
        return a.min(b);
    }
    let band = 4.0 * k;
    // h in [0, 1]; the product h * h * k cannot overflow even for huge k.
    let h = (L::splat(band) - (a - b).abs()).max(L::splat(0.0)) / L::splat(band);
    a.min(b) - h * h * L::splat(k)
}

/// [`smooth_max`] over any [`Lane`] type.
#[inline(always)]
pub(crate) fn smooth_max_lanes<L: Lane>(a: L, b: L, k: f32) -> L {
    -smooth_min_lanes(-a, -b, k)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(a: f32, b: f32, k: f32, expected: f32) {
        let got = smooth_min(a, b, k);
        assert!(
            (got - expected).abs() <= 1e-6,
            "smin({a}, {b}, {k}) = {got}"
        );
        let got = smooth_max(-a, -b, k);
        assert!(
            (got + expected).abs() <= 1e-6,
            "smax({a}, {b}, {k}) = {got}"
        );
    }

    #[test]
    fn values() {
        check(1.0, 1.0, 0.25, 0.75); // the deepest undercut is k
        check(1.0, 2.0, 0.25, 1.0); // |a - b| = 4k: already the plain min
        check(1.0, 1.5, 0.25, 1.0 - 0.0625); // h = 1/2
        check(1.0, 3.0, 0.0, 1.0);
        check(1.0, 3.0, -1.0, 1.0);
        check(1.0, 3.0, f32::NAN, 1.0);
        check(0.0, 0.0, 1e30, -1e30);
    }

    #[test]
    fn infinite_arguments_do_not_poison() {
        assert_eq!(smooth_min(1.0, f32::INFINITY, 0.5), 1.0);
        assert_eq!(smooth_min(f32::INFINITY, f32::INFINITY, 0.5), f32::INFINITY);
        assert_eq!(smooth_max(1.0, f32::NEG_INFINITY, 0.5), 1.0);
    }
}
