//! Surface normals as normalised finite-difference gradients of a distance field.

use glam::Vec3;

use crate::DistanceField;

/// The direction returned where the gradient estimate vanishes or is not finite (the centre
/// of a sphere, the axis of a torus, a NaN field). Any fixed unit vector would do; what
/// matters is that callers never receive NaN and that images stay deterministic.
pub const FALLBACK_NORMAL: Vec3 = Vec3::Y;

/// Normal by the tetrahedron technique (4 evaluations, iq "normalsSDF"), with step `h`.
///
/// Always finite and unit length, even where the gradient vanishes (centre of a sphere,
/// axis of a torus): falls back to [`FALLBACK_NORMAL`] there.
///
/// `h` is made non-negative and raised to a few ulps of `p`'s largest coordinate, because
/// below that `p + h` rounds back to `p` and every sample would be the same number.
pub fn normal<F: DistanceField + ?Sized>(field: &F, p: Vec3, h: f32) -> Vec3 {
    unit_or_fallback(gradient(field, p, h))
}

/// The gradient of the field at `p` by the same tetrahedron (4 evaluations), not
/// normalised: its length is the local Lipschitz ratio, 1 for exact distances, which lets
/// a caller move a point onto the surface (`p - grad f(p) / |grad|^2`).
///
/// Unlike [`normal`] this may be zero or non-finite; callers must check.
pub fn gradient<F: DistanceField + ?Sized>(field: &F, p: Vec3, h: f32) -> Vec3 {
    // iq, "normalsSDF": the vertices of a tetrahedron sum to zero, so sum_i k_i f(p + h k_i)
    // is proportional to the gradient, with one evaluation fewer than central differences.
    const K: [Vec3; 4] = [
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(1.0, 1.0, 1.0),
    ];
    let h = usable_step(p, h);
    // sum_i k_i (k_i . grad) h = 4 h grad, since sum_i k_i k_i^T = 4 I.
    K.iter()
        .fold(Vec3::ZERO, |acc, &k| acc + k * field.distance(p + k * h))
        / (4.0 * h)
}

/// The gradient by central differences (6 evaluations), not normalised: the naive
/// reference for [`gradient`], with the same treatment of `h` and the same caveat.
pub fn gradient_central<F: DistanceField + ?Sized>(field: &F, p: Vec3, h: f32) -> Vec3 {
    let h = usable_step(p, h);
    let d = |e: Vec3| field.distance(p + e * h) - field.distance(p - e * h);
    Vec3::new(d(Vec3::X), d(Vec3::Y), d(Vec3::Z)) / (2.0 * h)
}

/// Central differences (6 evaluations), kept as the naive reference for [`normal`].
///
/// Same guarantees and the same treatment of `h` as [`normal`].
pub fn normal_central<F: DistanceField + ?Sized>(field: &F, p: Vec3, h: f32) -> Vec3 {
    let h = usable_step(p, h);
    let d = |e: Vec3| field.distance(p + e * h) - field.distance(p - e * h);
    unit_or_fallback(Vec3::new(d(Vec3::X), d(Vec3::Y), d(Vec3::Z)))
}

/// `|h|`, but at least 8 ulps of the largest coordinate of `p` (and 0 for a NaN `h` at the
/// origin, which then takes the fallback path rather than producing NaN).
#[inline]
fn usable_step(p: Vec3, h: f32) -> f32 {
    let floor = p.abs().max_element() * (8.0 * f32::EPSILON);
    let h = h.abs();
    if h >= floor { h } else { floor }
}

/// Normalises without overflow or underflow: dividing by the largest component first keeps
/// the squared length in [1, 3] whatever the magnitude of the raw difference vector.
#[inline]
fn unit_or_fallback(v: Vec3) -> Vec3 {
    if !v.is_finite() {
        return FALLBACK_NORMAL;
    }
    let largest = v.abs().max_element();
    if largest > 0.0 {
        let v = v / largest;
        v / v.length()
    } else {
        FALLBACK_NORMAL
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Constant(f32);

    impl DistanceField for Constant {
        fn distance(&self, _: Vec3) -> f32 {
            self.0
        }
        fn lipschitz(&self) -> f32 {
            0.0
        }
    }

    /// `p . gradient`: the same gradient everywhere.
    struct Linear(Vec3);

    impl DistanceField for Linear {
        fn distance(&self, p: Vec3) -> f32 {
            p.dot(self.0)
        }
        fn lipschitz(&self) -> f32 {
            self.0.length()
        }
    }

    #[test]
    fn degenerate_fields_fall_back() {
        for f in [0.0, 1.0, f32::NAN, f32::INFINITY] {
            assert_eq!(normal(&Constant(f), Vec3::ONE, 1e-3), FALLBACK_NORMAL);
            assert_eq!(
                normal_central(&Constant(f), Vec3::ONE, 1e-3),
                FALLBACK_NORMAL
            );
        }
    }

    #[test]
    fn tiny_and_huge_gradients_normalise() {
        for scale in [1e-30, 1.0, 1e30] {
            let field = Linear(Vec3::new(3.0, 0.0, 4.0) * scale);
            let expected = Vec3::new(0.6, 0.0, 0.8);
            assert!((normal(&field, Vec3::ONE, 1e-2) - expected).length() < 1e-3);
            assert!((normal_central(&field, Vec3::ONE, 1e-2) - expected).length() < 1e-3);
        }
    }

    #[test]
    fn both_gradients_are_exact_on_linear_fields_at_any_offset() {
        // A linear field has the same gradient everywhere: both difference
        // schemes must return it, not a multiple, near and far from the
        // origin (where h is raised to a few ulps of p).
        let g = Vec3::new(0.36, -0.48, 0.8);
        for p in [Vec3::ZERO, Vec3::ONE, Vec3::splat(1e3)] {
            for grad in [
                gradient(&Linear(g), p, 1e-2),
                gradient_central(&Linear(g), p, 1e-2),
            ] {
                assert!(
                    (grad - g).length() < 1e-3 * (1.0 + p.length() * 1e-2),
                    "{p}: {grad}"
                );
            }
        }
    }

    #[test]
    fn step_is_raised_to_representable() {
        assert_eq!(usable_step(Vec3::ZERO, -2.0), 2.0);
        assert!(usable_step(Vec3::splat(1e4), 1e-9) > 0.0);
        assert_eq!(usable_step(Vec3::ZERO, f32::NAN), 0.0);
    }
}
