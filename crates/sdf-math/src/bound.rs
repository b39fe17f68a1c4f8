//! Bounds a ray can be clipped against before it is marched: an axis-aligned box (for
//! bounded shapes) and a half-space (for planes and what is cut from them).
//!
//! A bound is only useful with its contract, stronger than containment: the shape's
//! *field* never undercuts the distance to the bound ([`Sdf::bounding_box`],
//! [`Sdf::bounding_half_space`]). Then the parameters along a ray where a tracer could
//! declare a hit on the shape (field below `max(eps_abs, eps_rel t)`) lie inside the
//! interval [`Aabb::hit_interval`] or [`HalfSpace::hit_interval`] returns, and a tracer
//! may ignore the shape outside it, or altogether when it is empty, without changing
//! which surface the ray finds.
//!
//! [`Sdf::bounding_box`]: crate::Sdf::bounding_box
//! [`Sdf::bounding_half_space`]: crate::Sdf::bounding_half_space

use glam::Vec3;

use crate::{Ray, TraceParams};

/// Relative widening of every interval end: covers the rounding of the slab test itself.
const WIDEN: f32 = 1e-5;

/// An axis-aligned box `min..=max` (every `min` component <= its `max` component).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lowest corner.
    pub min: Vec3,
    /// Highest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The box with this centre and (non-negative) half extents.
    #[inline]
    pub fn from_center(center: Vec3, half_extents: Vec3) -> Aabb {
        Aabb {
            min: center - half_extents,
            max: center + half_extents,
        }
    }

    /// Centre of the box.
    #[inline]
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Half the side lengths.
    #[inline]
    pub fn half_extents(&self) -> Vec3 {
        (self.max - self.min) * 0.5
    }

    /// The smallest box holding both.
    #[inline]
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// This box grown by `margin` on every side.
    #[inline]
    pub fn inflate(&self, margin: f32) -> Aabb {
        Aabb {
            min: self.min - Vec3::splat(margin),
            max: self.max + Vec3::splat(margin),
        }
    }

    /// Squared Euclidean distance from `p` to the box (0 inside): cheap enough to decide,
    /// before evaluating a shape, whether it can be nearer than what was already found.
    #[inline]
    pub fn distance_squared(&self, p: Vec3) -> f32 {
        let outside = (self.min - p).max(p - self.max).max(Vec3::ZERO);
        outside.length_squared()
    }

    /// Whether every coordinate is finite.
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }

    /// The part of `[params.t_min, params.t_max]` where a field honouring this box (at
    /// least the distance to the box, outside it) can fall below the tracer's hit
    /// threshold `max(eps_abs, eps_rel t)`; `None` where there is no such part.
    ///
    /// The box is grown by the largest threshold a point near it can have (a point within
    /// `m` of the box is at most `|o - c| + |h| + sqrt(3) m` from the origin, so
    /// `m = eps_rel (|o - c| + |h|) / (|d| - sqrt(3) eps_rel)` covers it) plus the `f32`
    /// rounding of positions that far from the world origin, then clipped by the slab
    /// method (Kay and Kajiya 1986; pbrt-v4 section 6.1.2), whose ends are widened by a
    /// relative `1e-5`. Conservative: a wider interval only costs steps.
    pub fn hit_interval(&self, ray: &Ray, params: &TraceParams) -> Option<(f32, f32)> {
        let whole = Some((params.t_min, params.t_max));
        let speed = ray.dir.length();
        let (eps_abs, eps_rel) = (params.eps_abs.max(0.0), params.eps_rel.max(0.0));
        let (center, half) = (self.center(), self.half_extents());
        let reach = (ray.origin - center).length() + half.length();
        let room = speed - 3f32.sqrt() * eps_rel;
        if !(room > 0.5 * speed && reach.is_finite()) {
            // A threshold that grows as fast as the ray moves: no useful bound.
            return whole;
        }
        let relative = (eps_rel * reach / room).min(eps_rel * params.t_max.max(0.0));
        let rounding = 16.0 * f32::EPSILON * (ray.origin.length() + center.length() + reach);
        let grown = self.inflate(eps_abs.max(relative) + rounding);

        let (mut t0, mut t1) = (params.t_min, params.t_max);
        for axis in 0..3 {
            let (o, d) = (ray.origin[axis], ray.dir[axis]);
            let (lo, hi) = (grown.min[axis], grown.max[axis]);
            if d == 0.0 {
                if o < lo || o > hi {
                    return None;
                }
                continue;
            }
            let inv = 1.0 / d;
            let (mut near, mut far) = ((lo - o) * inv, (hi - o) * inv);
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            // NaN-proof: a NaN end leaves the running interval as it was.
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
        }
        widen(t0, t1, params)
    }
}

/// The half-space `dot(p, normal) <= height`, with a normal of any positive length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfSpace {
    /// Outward normal (not necessarily unit).
    pub normal: Vec3,
    /// Offset: the boundary is `dot(p, normal) = height`.
    pub height: f32,
}

impl HalfSpace {
    /// `dot(p, normal) - height`: what a field honouring this half-space is at least.
    #[inline]
    pub fn value(&self, p: Vec3) -> f32 {
        p.dot(self.normal) - self.height
    }

    /// The part of `[params.t_min, params.t_max]` where a field at least
    /// [`HalfSpace::value`] can fall below the hit threshold `max(eps_abs, eps_rel t)`.
    ///
    /// Along the ray the bound is linear, `a + b t`, so the set where it is below either
    /// threshold is a union of two half-lines, solved exactly (then widened for rounding).
    /// A ray parallel to a plane does reach it: `eps_rel t` grows until it exceeds the
    /// ray's height, as it does for a tracer marching that ray.
    pub fn hit_interval(&self, ray: &Ray, params: &TraceParams) -> Option<(f32, f32)> {
        let (eps_abs, eps_rel) = (params.eps_abs.max(0.0), params.eps_rel.max(0.0));
        let rounding =
            16.0 * f32::EPSILON * (ray.origin.length() * self.normal.length() + self.height.abs());
        let a = self.value(ray.origin) - rounding;
        let b = ray.dir.dot(self.normal);
        let below_abs = half_line(a - eps_abs, b);
        let below_rel = half_line(a, b - eps_rel);
        let (t0, t1) = match (below_abs, below_rel) {
            (None, None) => return None,
            (Some(x), None) | (None, Some(x)) => x,
            (Some(x), Some(y)) => (x.0.min(y.0), x.1.max(y.1)),
        };
        widen(t0.max(params.t_min), t1.min(params.t_max), params)
    }
}

/// `{t : alpha + beta t < 0}` as an interval with infinite ends, or `None`.
fn half_line(alpha: f32, beta: f32) -> Option<(f32, f32)> {
    if beta > 0.0 {
        Some((f32::NEG_INFINITY, -alpha / beta))
    } else if beta < 0.0 {
        Some((-alpha / beta, f32::INFINITY))
    } else if alpha < 0.0 {
        Some((f32::NEG_INFINITY, f32::INFINITY))
    } else if alpha.is_nan() || beta.is_nan() {
        // Unknown: keep everything rather than guess.
        Some((f32::NEG_INFINITY, f32::INFINITY))
    } else {
        None
    }
}

/// Widens `[t0, t1]` by a relative [`WIDEN`] and clips it to the trace's range.
fn widen(t0: f32, t1: f32, params: &TraceParams) -> Option<(f32, f32)> {
    if t0.is_nan() || t1.is_nan() {
        return Some((params.t_min, params.t_max));
    }
    let t0 = (t0 - WIDEN * t0.abs()).max(params.t_min);
    let t1 = (t1 + WIDEN * t1.abs()).min(params.t_max);
    (t0 <= t1).then_some((t0, t1))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> TraceParams {
        TraceParams {
            t_min: 0.0,
            t_max: 100.0,
            max_steps: 512,
            eps_abs: 1e-4,
            eps_rel: 1e-3,
        }
    }

    #[test]
    fn box_interval_clips_and_grows_by_the_threshold() {
        let b = Aabb::from_center(Vec3::ZERO, Vec3::ONE);
        let hit = Ray::new(Vec3::new(0.0, 0.0, -10.0), Vec3::Z);
        let (t0, t1) = b.hit_interval(&hit, &params()).unwrap();
        // Grown by eps_rel * ~11.7 = ~0.012 on each side.
        assert!(t0 < 9.0 && t0 > 8.98, "{t0}");
        assert!(t1 > 11.0 && t1 < 11.02, "{t1}");
        // Passing 0.005 above the top: within the grown box, so kept.
        let graze = Ray::new(Vec3::new(0.0, 1.005, -10.0), Vec3::Z);
        assert!(b.hit_interval(&graze, &params()).is_some());
        // Passing 0.5 above it: nothing to march.
        let over = Ray::new(Vec3::new(0.0, 1.5, -10.0), Vec3::Z);
        assert_eq!(b.hit_interval(&over, &params()), None);
        // Behind the ray, or beyond t_max.
        let away = Ray::new(Vec3::new(0.0, 0.0, -10.0), -Vec3::Z);
        assert_eq!(b.hit_interval(&away, &params()), None);
        let short = TraceParams {
            t_max: 5.0,
            ..params()
        };
        assert_eq!(b.hit_interval(&hit, &short), None);
        // From inside, the interval starts at t_min.
        let inside = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(b.hit_interval(&inside, &params()).unwrap().0, 0.0);
    }

    #[test]
    fn box_interval_axis_parallel_rays() {
        let b = Aabb::from_center(Vec3::ZERO, Vec3::ONE);
        // dir has zero y and z components: the slabs in y and z are tested by position.
        let inside_slab = Ray::new(Vec3::new(-5.0, 0.99, 0.0), Vec3::X);
        assert!(b.hit_interval(&inside_slab, &params()).is_some());
        let outside_slab = Ray::new(Vec3::new(-5.0, 1.5, 0.0), Vec3::X);
        assert_eq!(b.hit_interval(&outside_slab, &params()), None);
    }

    #[test]
    fn half_space_interval_is_exact_for_planes() {
        // The floor y <= 0, seen from y = 1.
        let floor = HalfSpace {
            normal: Vec3::Y,
            height: 0.0,
        };
        let p = params();
        let down = Ray::new(Vec3::Y, -Vec3::Y);
        let (t0, t1) = floor.hit_interval(&down, &p).unwrap();
        // The bound 1 - t meets the threshold 1e-3 t at t = 1 / 1.001.
        assert!((t0 - 1.0 / 1.001).abs() < 1e-4, "{t0}");
        assert_eq!(t1, p.t_max);
        // Leaving the floor: never within the threshold.
        let up = Ray::new(Vec3::Y * 0.01, Vec3::Y);
        assert_eq!(floor.hit_interval(&up, &p), None);
        // Parallel at height 0.05: eps_rel t reaches 0.05 at t = 50.
        let level = Ray::new(Vec3::Y * 0.05, Vec3::X);
        let (t0, _) = floor.hit_interval(&level, &p).unwrap();
        assert!((t0 - 50.0).abs() < 1e-2, "{t0}");
        // Parallel at height 0.5: not before t_max = 100.
        let high = Ray::new(Vec3::Y * 0.5, Vec3::X);
        assert_eq!(floor.hit_interval(&high, &p), None);
    }

    #[test]
    fn degenerate_inputs_keep_everything_or_nothing_never_panic() {
        let b = Aabb::from_center(Vec3::ZERO, Vec3::ONE);
        let p = params();
        let nan = Ray {
            origin: Vec3::ZERO,
            dir: Vec3::NAN,
        };
        assert_eq!(b.hit_interval(&nan, &p), Some((p.t_min, p.t_max)));
        let h = HalfSpace {
            normal: Vec3::Y,
            height: 0.0,
        };
        assert!(h.hit_interval(&nan, &p).is_some());
        // A threshold growing faster than the ray: the whole range.
        let wild = TraceParams { eps_rel: 2.0, ..p };
        let far = Ray::new(Vec3::new(0.0, 50.0, 0.0), Vec3::X);
        assert_eq!(b.hit_interval(&far, &wild), Some((p.t_min, p.t_max)));
    }
}
