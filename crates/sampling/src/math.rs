//! Small numeric helpers shared by the warps (private).

use glam::{Vec2, Vec3};

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
