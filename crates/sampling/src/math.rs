//! Small numeric helpers shared by the warps (private).

use glam::{Vec2, Vec3};
use lueur_sdf_math::{Lane, LaneVec3};

/// The largest `f32` strictly below 1 (`0x1.fffffep-1`), the upper end of every
/// uniform sample this crate accepts or produces (pbrt-v4 §7.2 calls it
/// `OneMinusEpsilon`).
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Clamps a uniform number into `[0, ONE_MINUS_EPSILON]`; NaN becomes 0.
#[inline]
pub(crate) fn clamp_u(u: f32) -> f32 {
    if u.is_nan() {
        0.0
    } else {
        u.clamp(0.0, ONE_MINUS_EPSILON)
    }
}

/// [`clamp_u`] applied to both components.
#[inline]
pub(crate) fn clamp_u2(u: Vec2) -> Vec2 {
    Vec2::new(clamp_u(u.x), clamp_u(u.y))
}

/// `sqrt(max(x, 0))`: rounding can push a squared sine a hair below zero.
#[inline]
pub(crate) fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

/// Normalises `v`, returning the unit vector and the length, or `None` when the
/// length is zero, subnormal-small or not finite.
#[inline]
pub(crate) fn normalize_with_length(v: Vec3) -> Option<(Vec3, f32)> {
    let length = v.length();
    if length.is_finite() && length > f32::MIN_POSITIVE {
        let unit = v / length;
        unit.is_finite().then_some((unit, length))
    } else {
        None
    }
}

/// [`clamp_u`] per lane.
#[inline(always)]
pub(crate) fn clamp_u_lanes<L: Lane>(u: L) -> L {
    L::select(u.is_nan(), L::splat(0.0), u.clamp(0.0, ONE_MINUS_EPSILON))
}

/// [`safe_sqrt`] per lane.
#[inline(always)]
pub(crate) fn safe_sqrt_lanes<L: Lane>(x: L) -> L {
    x.max(L::splat(0.0)).sqrt()
}

/// [`normalize_with_length`] per lane: the unit vector, the length, and where they are
/// valid (elsewhere the values are meaningless).
#[inline(always)]
pub(crate) fn normalize_with_length_lanes<L: Lane>(v: LaneVec3<L>) -> (LaneVec3<L>, L, L::Mask) {
    let length = v.length();
    let unit = v / length;
    let valid = L::and(
        L::and(length.finite(), length.gt(L::splat(f32::MIN_POSITIVE))),
        unit.finite(),
    );
    (unit, length, valid)
}

/// `(sin, cos)` of `2 pi u` for `u` in `[0, 1]`, to within about 2e-7, the same bits
/// for one lane as for a vector of them (libm's `sincosf` has no vector form to match).
///
/// The angle is kept in turns, where folding is exact: `t = u - 1/2` in `[-1/2, 1/2]`
/// flips both signs, `sin` folds `t` into `[-1/4, 1/4]` by `t -> +-1/2 - t`, and
/// `cos(2 pi t) = sin(2 pi (1/4 - |t|))`. On that quarter turn, `sin(2 pi t)` is its
/// Taylor series to `t^13`, whose truncation error is below 2e-10, clamped to
/// `[-1, 1]`.
#[inline(always)]
pub(crate) fn sin_cos_turns<L: Lane>(u: L) -> (L, L) {
    #[inline(always)]
    fn sin_quarter<L: Lane>(t: L) -> L {
        // sin(2 pi t) = sum_k (-1)^k (2 pi)^(2k+1) t^(2k+1) / (2k+1)!.
        const C: [f32; 7] = [
            6.283_185_5,
            -41.341_7,
            81.605_25,
            -76.705_86,
            42.058_693,
            -15.094_643,
            3.819_952_6,
        ];
        let t2 = t * t;
        let mut p = L::splat(C[6]);
        for c in C[..6].iter().rev() {
            p = p * t2 + L::splat(*c);
        }
        // Rounding can carry the peak a hair past 1.
        (p * t).clamp(-1.0, 1.0)
    }
    let (half, quarter) = (L::splat(0.5), L::splat(0.25));
    let t = u - half;
    let folded = L::select(
        t.gt(quarter),
        half - t,
        L::select(t.lt(-quarter), -half - t, t),
    );
    let sin = -sin_quarter(folded);
    let cos = -sin_quarter(quarter - t.abs());
    (sin, cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against f64 on a fine grid and at the ends: the error bound the doc states, with
    /// the rounding of `u - 1/2` for small `u` (2^-25 turns) included.
    #[test]
    fn sin_cos_turns_is_accurate_over_the_whole_turn() {
        let n = 1 << 20;
        let mut worst = 0.0f64;
        let grid = (0..=n).map(|i| i as f32 / n as f32);
        for u in grid.chain([ONE_MINUS_EPSILON, 1e-30, 0.25, 0.5, 0.75]) {
            let (sin, cos) = sin_cos_turns(u);
            let angle = std::f64::consts::TAU * f64::from(u);
            worst = worst
                .max((f64::from(sin) - angle.sin()).abs())
                .max((f64::from(cos) - angle.cos()).abs());
            assert!(sin.abs() <= 1.0 && cos.abs() <= 1.0, "u = {u}");
        }
        assert!(worst < 4e-7, "worst error {worst:e}");
        // The quarter turns land on the axes, as the folding makes them.
        assert_eq!(sin_cos_turns(0.25f32), (1.0, -0.0));
        assert_eq!(sin_cos_turns(0.0f32).1, 1.0);
        assert_eq!(sin_cos_turns(0.5f32).1, -1.0);
    }
}
