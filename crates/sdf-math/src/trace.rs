//! Sphere tracing (Hart 1996): march along a ray by steps no field value can overshoot.

use crate::{DistanceField, Ray};

/// Sphere tracing parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceParams {
    /// Where marching starts along the ray.
    pub t_min: f32,
    /// Far limit: marching past it is a [`TraceOutcome::Miss`].
    pub t_max: f32,
    /// Step cap: reaching it without a decision is a [`TraceOutcome::GaveUp`].
    pub max_steps: u32,
    /// Absolute hit threshold: a hit when `f < max(eps_abs, eps_rel * t)`.
    pub eps_abs: f32,
    /// Relative hit threshold: the pixel footprint (an angle) for camera rays, so that far
    /// surfaces are not refined below what a pixel can resolve.
    pub eps_rel: f32,
}

impl Default for TraceParams {
    fn default() -> Self {
        Self {
            t_min: 0.0,
            t_max: 1e4,
            max_steps: 512,
            eps_abs: 1e-5,
            eps_rel: 1e-4,
        }
    }
}

/// How a march ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TraceOutcome {
    /// The field fell below the hit threshold at `t`.
    Hit {
        /// Ray parameter of the hit.
        t: f32,
        /// Field evaluations spent.
        steps: u32,
    },
    /// The march passed `t_max`.
    Miss {
        /// Field evaluations spent.
        steps: u32,
    },
    /// Neither: the step cap was reached, the field returned NaN, or the step became too
    /// small to move `t` (a float stall). `t` is where marching stopped.
    GaveUp {
        /// Ray parameter where marching stopped.
        t: f32,
        /// Field evaluations spent.
        steps: u32,
    },
}

impl TraceOutcome {
    /// Field evaluations spent, whatever the outcome.
    #[inline]
    pub fn steps(&self) -> u32 {
        match *self {
            Self::Hit { steps, .. } | Self::Miss { steps } | Self::GaveUp { steps, .. } => steps,
        }
    }

    /// The hit's ray parameter, if this is a hit.
    #[inline]
    pub fn hit_t(&self) -> Option<f32> {
        match *self {
            Self::Hit { t, .. } => Some(t),
            Self::Miss { .. } | Self::GaveUp { .. } => None,
        }
    }
}

/// Plain Hart sphere tracing: step = f(p) / L.
///
/// Hart 1996, "Sphere tracing": if `f` is L-Lipschitz, the ball of radius `f(p) / L` around
/// `p` holds no zero of `f`, so stepping that far cannot tunnel through a surface.
///
/// - `steps` counts field evaluations and never exceeds `params.max_steps`; the march
///   always ends.
/// - A ray whose first sample is already below the threshold (inside the surface, or
///   within its epsilon shell) is an immediate `Hit` at `t_min` after one step. Secondary
///   rays should therefore start off the surface: offset the origin along the normal by a
///   few times the hit threshold, or pass a `t_min` of that size.
/// - A NaN distance ends the march as `GaveUp` at the current `t`; so does a step too
///   small to change `t` in `f32`.
/// - A `lipschitz()` that is NaN, zero or negative breaks the field's contract; it is
///   replaced by 1 rather than trusted. A non-unit `ray.dir` is allowed (steps are divided
///   by its length); a zero or non-finite one gives up at once with no step.
pub fn sphere_trace<F: DistanceField + ?Sized>(
    field: &F,
    ray: &Ray,
    params: &TraceParams,
) -> TraceOutcome {
    let lipschitz = field.lipschitz();
    let lipschitz = if lipschitz > 0.0 { lipschitz } else { 1.0 };
    let speed = ray.dir.length();
    if !(speed > 0.0 && speed.is_finite()) {
        return TraceOutcome::GaveUp {
            t: params.t_min,
            steps: 0,
        };
    }
    // One division per trace, not per step.
    let step_scale = 1.0 / (lipschitz * speed);

    let mut t = params.t_min;
    let mut steps = 0;
    while steps < params.max_steps {
        if t > params.t_max {
            return TraceOutcome::Miss { steps };
        }
        let d = field.distance(ray.at(t));
        steps += 1;
        if d.is_nan() {
            return TraceOutcome::GaveUp { t, steps };
        }
        if d < params.eps_abs.max(params.eps_rel * t) {
            return TraceOutcome::Hit { t, steps };
        }
        let next = t + d * step_scale;
        if next == t {
            return TraceOutcome::GaveUp { t, steps };
        }
        t = next;
    }
    if t > params.t_max {
        TraceOutcome::Miss { steps }
    } else {
        TraceOutcome::GaveUp { t, steps }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Distance to the plane x = 10, with a Lipschitz bound the test chooses.
    struct Wall(f32);

    impl DistanceField for Wall {
        fn distance(&self, p: Vec3) -> f32 {
            10.0 - p.x
        }
        fn lipschitz(&self) -> f32 {
            self.0
        }
    }

    fn check(field: &dyn DistanceField, ray: Ray, params: TraceParams, expected: TraceOutcome) {
        assert_eq!(sphere_trace(field, &ray, &params), expected);
    }

    #[test]
    fn outcomes() {
        let x = Ray::new(Vec3::ZERO, Vec3::X);
        let p = TraceParams::default();
        // An exact planar field is reached in one step, confirmed by a second.
        check(&Wall(1.0), x, p, TraceOutcome::Hit { t: 10.0, steps: 2 });
        check(
            &Wall(1.0),
            Ray::new(Vec3::ZERO, -Vec3::X),
            p,
            // Steps double away from the wall: t = 0, 10, 30, ..., 5110, 10230 > t_max.
            TraceOutcome::Miss { steps: 10 },
        );
        // Starting inside is an immediate hit.
        check(
            &Wall(1.0),
            Ray::new(Vec3::new(11.0, 0.0, 0.0), Vec3::X),
            p,
            TraceOutcome::Hit { t: 0.0, steps: 1 },
        );
        let capped = TraceParams { max_steps: 3, ..p };
        // L = 2 halves every step: 10 -> 5 -> 2.5 left, so three steps reach t = 8.75.
        check(
            &Wall(2.0),
            x,
            capped,
            TraceOutcome::GaveUp { t: 8.75, steps: 3 },
        );
        let none = TraceParams { max_steps: 0, ..p };
        check(
            &Wall(1.0),
            x,
            none,
            TraceOutcome::GaveUp { t: 0.0, steps: 0 },
        );
    }

    #[test]
    fn broken_inputs_end_without_panic() {
        let x = Ray::new(Vec3::ZERO, Vec3::X);
        let p = TraceParams::default();
        for l in [0.0, -1.0, f32::NAN] {
            check(&Wall(l), x, p, TraceOutcome::Hit { t: 10.0, steps: 2 });
        }
        // An infinite bound means no step is safe: the march stalls and says so.
        check(
            &Wall(f32::INFINITY),
            x,
            p,
            TraceOutcome::GaveUp { t: 0.0, steps: 1 },
        );
        let zero = Ray {
            origin: Vec3::ZERO,
            dir: Vec3::ZERO,
        };
        check(
            &Wall(1.0),
            zero,
            p,
            TraceOutcome::GaveUp { t: 0.0, steps: 0 },
        );
        let nan_start = TraceParams {
            t_min: f32::NAN,
            ..p
        };
        let out = sphere_trace(&Wall(1.0), &x, &nan_start);
        assert!(matches!(out, TraceOutcome::GaveUp { steps: 1, .. }));
    }

    #[test]
    fn accessors() {
        let hit = TraceOutcome::Hit { t: 2.0, steps: 7 };
        assert_eq!((hit.steps(), hit.hit_t()), (7, Some(2.0)));
        let miss = TraceOutcome::Miss { steps: 3 };
        assert_eq!((miss.steps(), miss.hit_t()), (3, None));
        let gave_up = TraceOutcome::GaveUp { t: 1.0, steps: 9 };
        assert_eq!((gave_up.steps(), gave_up.hit_t()), (9, None));
    }
}
