//! Sphere tracing (Hart 1996): march along a ray by steps no field value can overshoot,
//! and its over-relaxed variant (Keinert et al. 2014), which steps further and checks.

use glam::Vec3;

use crate::lanes::{Lane, LaneVec3};
use crate::relaxed::{MAX_STEP_CAP, RelaxedLanes, status};
use crate::{DistanceField, Ray};

/// The hit threshold is never below this many [`position_rounding`]s of the ray's origin,
/// nor below this many `f32::EPSILON` of `t`: closer than that, the field is evaluated at
/// positions that f32 cannot tell apart, and a smaller threshold would only make the
/// tracer crawl.
pub const HIT_ULPS: f32 = 4.0;

/// The rounding of f32 positions near `p`: `f32::EPSILON` times its largest coordinate,
/// which is at least one unit in the last place of every coordinate, so two points closer
/// than this may round to the same one. Never zero (at the origin it is the smallest
/// normal f32), so that thresholds built on it stay positive.
#[inline]
pub fn position_rounding(p: Vec3) -> f32 {
    position_rounding_lanes(LaneVec3::from(p))
}

/// [`position_rounding`] of each lane's point.
#[inline(always)]
pub fn position_rounding_lanes<L: Lane>(p: LaneVec3<L>) -> L {
    (L::splat(f32::EPSILON) * p.abs().max_element()).max(L::splat(f32::MIN_POSITIVE))
}

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

impl TraceParams {
    /// These parameters for a ray starting at `origin`: the absolute hit threshold raised to
    /// [`HIT_ULPS`] roundings of the origin, and the relative one to [`HIT_ULPS`] ulps of
    /// `t` (a point at `t` is at most `|origin| + t` from the origin). Everything else, and
    /// any larger threshold the caller chose, is kept. The threshold then follows what f32
    /// can resolve *along this ray*, whatever else the scene holds.
    #[inline]
    pub fn resolving(self, origin: Vec3) -> TraceParams {
        let (eps_abs, eps_rel) = resolving_lanes(self.eps_abs, self.eps_rel, origin.into());
        TraceParams {
            eps_abs,
            eps_rel,
            ..self
        }
    }
}

/// [`TraceParams::resolving`]'s thresholds for each lane's ray from `origin`, `eps_abs`
/// and `eps_rel` raised as it raises them: its one definition.
#[inline(always)]
pub fn resolving_lanes<L: Lane>(eps_abs: L, eps_rel: L, origin: LaneVec3<L>) -> (L, L) {
    (
        eps_abs.max(L::splat(HIT_ULPS) * position_rounding_lanes(origin)),
        eps_rel.max(L::splat(HIT_ULPS * f32::EPSILON)),
    )
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

/// The factor from field values to ray parameter, `1 / (L |dir|)`: one
/// division per trace, not per step. `None` for a zero or non-finite
/// direction. A `lipschitz()` that is NaN, zero or negative breaks the
/// field's contract and is replaced by 1 rather than trusted.
#[inline]
fn step_scale(lipschitz: f32, ray: &Ray) -> Option<f32> {
    let lipschitz = if lipschitz > 0.0 { lipschitz } else { 1.0 };
    let speed = ray.dir.length();
    (speed > 0.0 && speed.is_finite()).then(|| 1.0 / (lipschitz * speed))
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
    match HartMarch::start(field.lipschitz(), ray, params) {
        Ok(march) => run_to_end(march, field),
        Err(outcome) => outcome,
    }
}

/// One ray's march as a state machine: where to evaluate next (or how it ended), and what
/// the value found there decides. The scalar tracers drive one ray to its end
/// ([`run_to_end`]); the stream tracers drive one per lane.
pub(crate) trait March: Copy {
    /// The point to evaluate next, or the outcome if the march is over.
    fn next_point(&self) -> Result<Vec3, TraceOutcome>;
    /// Takes the step the field's value `d` at [`March::next_point`] allows; the outcome
    /// if that ends the march.
    fn advance(&mut self, d: f32) -> Option<TraceOutcome>;
}

/// Drives `march` through `field`, one evaluation at a time, to its outcome.
#[inline]
fn run_to_end<M: March, F: DistanceField + ?Sized>(mut march: M, field: &F) -> TraceOutcome {
    loop {
        match march.next_point() {
            Err(outcome) => return outcome,
            Ok(p) => {
                if let Some(outcome) = march.advance(field.distance(p)) {
                    return outcome;
                }
            }
        }
    }
}

/// One ray's plain sphere trace as a state machine: where to evaluate next, and what the
/// value found there decides. [`sphere_trace`] drives it one ray at a time and
/// `stream::sphere_trace_stream` many rays a lane each, so both take exactly the same
/// steps.
#[derive(Clone, Copy, Debug)]
pub(crate) struct HartMarch {
    ray: Ray,
    params: TraceParams,
    step_scale: f32,
    t: f32,
    steps: u32,
}

impl HartMarch {
    /// The march of `ray`, or its outcome at once for a zero or non-finite direction.
    #[inline]
    pub(crate) fn start(
        lipschitz: f32,
        ray: &Ray,
        params: &TraceParams,
    ) -> Result<HartMarch, TraceOutcome> {
        match step_scale(lipschitz, ray) {
            Some(step_scale) => Ok(HartMarch {
                ray: *ray,
                params: *params,
                step_scale,
                t: params.t_min,
                steps: 0,
            }),
            None => Err(TraceOutcome::GaveUp {
                t: params.t_min,
                steps: 0,
            }),
        }
    }
}

impl March for HartMarch {
    /// The point to evaluate next, or the outcome if the march is over: past `t_max` is a
    /// miss, the step cap reached short of it a give-up.
    #[inline]
    fn next_point(&self) -> Result<Vec3, TraceOutcome> {
        if self.t > self.params.t_max {
            Err(TraceOutcome::Miss { steps: self.steps })
        } else if self.steps >= self.params.max_steps {
            Err(TraceOutcome::GaveUp {
                t: self.t,
                steps: self.steps,
            })
        } else {
            Ok(self.ray.at(self.t))
        }
    }

    /// Takes the step that the field's value `d` at [`HartMarch::next_point`] allows;
    /// the outcome if that ends the march (a hit, a NaN, a step too small to move `t`).
    #[inline]
    fn advance(&mut self, d: f32) -> Option<TraceOutcome> {
        let (t, params) = (self.t, &self.params);
        self.steps += 1;
        let steps = self.steps;
        if d.is_nan() {
            return Some(TraceOutcome::GaveUp { t, steps });
        }
        if d < params.eps_abs.max(params.eps_rel * t) {
            return Some(TraceOutcome::Hit { t, steps });
        }
        let next = t + d * self.step_scale;
        if next == t {
            return Some(TraceOutcome::GaveUp { t, steps });
        }
        self.t = next;
        None
    }
}

/// The largest over-relaxation factor lueur lets [`sphere_trace_relaxed`] use. Steps this
/// long are only chosen where the field grows as fast as the ray moves (rays leaving a
/// surface); the check after each step keeps any factor safe.
pub const OVER_RELAXATION: f32 = 8.0;

/// Over-relaxed sphere tracing: steps of `omega * f(p) / L` with `omega >= 1`, each checked
/// afterwards (Keinert et al. 2014, "Enhanced Sphere Tracing"), with `omega` chosen per step
/// from the slope of the field along the ray (Balint and Valasek 2018, "Accelerating
/// Sphere Tracing").
///
/// **The check.** The ball of radius `f / L` around each sample holds no surface. After a
/// step of `omega * f_prev / L` the balls around the previous and the current sample cover
/// the segment between them when `f_prev + f_cur >= omega * f_prev`; when they do not, a
/// surface may lie in the gap, so the march goes back to the safe step `f_prev / L` from
/// the previous sample (one more evaluation) and goes on from there. lueur checks with a
/// margin of two hit thresholds (`f_prev + f_cur - 2 eps >= omega * f_prev`): the balls
/// shrunk by `eps` still cover the segment, so a relaxed step never jumps over a point where
/// the field is below the hit threshold, not only over points below zero. A sample inside
/// a surface (`f < 0`) always fails.
///
/// **The factor.** With `k` the change of `f` per unit of step over the last step (`-1`
/// head-on toward a plane, `0` parallel to it, `+1` straight away from it), a plane would
/// pass the check (margin included) for any `omega <= (2 - 2 eps / f) / (1 - k)`; the step
/// uses `0.9` of that, clamped to `[1, omega_max]`. Within two thresholds of a surface that
/// is 1: rays crawling along a surface take plain steps rather than failing every check. The first step, with no slope known yet, is a plain one. So head-on
/// approaches take plain steps (Keinert's fixed `omega` overshoots there and fails once per
/// ray), grazing ones nearly double their steps, and receding ones grow fast.
///
/// Same contract as [`sphere_trace`] (outcomes, step cap, NaN and degenerate inputs), plus:
/// - a relaxed step is never taken past `t_max` (the plain one is instead), so `Miss` is
///   only declared from a checked point;
/// - a `GaveUp` at the step cap reports the last checked point, not an unchecked one;
/// - `omega_max <= 1`, NaN or infinite gives exactly [`sphere_trace`].
pub fn sphere_trace_relaxed<F: DistanceField + ?Sized>(
    field: &F,
    ray: &Ray,
    params: &TraceParams,
    omega_max: f32,
) -> TraceOutcome {
    if !(omega_max > 1.0 && omega_max.is_finite()) {
        return sphere_trace(field, ray, params);
    }
    match RelaxedMarch::start(field.lipschitz(), ray, params, omega_max) {
        Ok(march) => run_to_end(march, field),
        Err(outcome) => outcome,
    }
}

/// One ray's over-relaxed sphere trace as a state machine, as [`HartMarch`] is for the
/// plain one: [`sphere_trace_relaxed`] drives it one ray at a time; its state and step are
/// the one-lane instance of [`RelaxedLanes`], which the relaxed streams run for a vector
/// of rays at once.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RelaxedMarch {
    pub ray: Ray,
    pub omega_max: f32,
    pub state: RelaxedLanes<f32>,
}

impl RelaxedMarch {
    /// The march of `ray` with factors up to `omega_max` (above 1 and finite: below that
    /// the plain march is the one to run), or its outcome at once for a zero or non-finite
    /// direction.
    #[inline]
    pub(crate) fn start(
        lipschitz: f32,
        ray: &Ray,
        params: &TraceParams,
        omega_max: f32,
    ) -> Result<RelaxedMarch, TraceOutcome> {
        let Some(step_scale) = step_scale(lipschitz, ray) else {
            return Err(TraceOutcome::GaveUp {
                t: params.t_min,
                steps: 0,
            });
        };
        Ok(RelaxedMarch {
            ray: *ray,
            omega_max,
            state: RelaxedLanes {
                t: params.t_min,
                steps: 0.0,
                prev_t: params.t_min,
                prev_d: 0.0,
                last_step: 0.0,
                unchecked: 0.0,
                step_scale,
                t_max: params.t_max,
                max_steps: params.max_steps.min(MAX_STEP_CAP) as f32,
                eps_abs: params.eps_abs,
                eps_rel: params.eps_rel,
            },
        })
    }
}

/// The outcome a lane's `status` and `t` stand for, after `steps` evaluations; `None`
/// while the march goes on.
#[inline(always)]
pub(crate) fn outcome(status: f32, t: f32, steps: f32) -> Option<TraceOutcome> {
    let steps = steps as u32;
    if status == status::HIT {
        Some(TraceOutcome::Hit { t, steps })
    } else if status == status::MISS {
        Some(TraceOutcome::Miss { steps })
    } else if status == status::GAVE_UP {
        Some(TraceOutcome::GaveUp { t, steps })
    } else {
        None
    }
}

impl March for RelaxedMarch {
    #[inline]
    fn next_point(&self) -> Result<Vec3, TraceOutcome> {
        let (status, t) = self.state.standing();
        match outcome(status, t, self.state.steps) {
            Some(outcome) => Err(outcome),
            None => Ok(self.ray.at(t)),
        }
    }

    #[inline]
    fn advance(&mut self, d: f32) -> Option<TraceOutcome> {
        let (status, t) = self.state.advance(d, self.omega_max);
        outcome(status, t, self.state.steps)
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

    fn check_relaxed(
        field: &dyn DistanceField,
        ray: Ray,
        params: TraceParams,
        expected: TraceOutcome,
    ) {
        let got = sphere_trace_relaxed(field, &ray, &params, OVER_RELAXATION);
        assert_eq!(got, expected);
    }

    /// A wall behind (x = -1) and a wall ahead (x = 10): the field first grows along +x,
    /// which invites long steps, then falls.
    struct Corridor;

    impl DistanceField for Corridor {
        fn distance(&self, p: Vec3) -> f32 {
            (p.x + 1.0).min(10.0 - p.x)
        }
        fn lipschitz(&self) -> f32 {
            1.0
        }
    }

    #[test]
    fn relaxed_outcomes() {
        let x = Ray::new(Vec3::ZERO, Vec3::X);
        let p = TraceParams::default();
        // The first step is plain, so an exact wall head-on is as cheap as ever.
        check_relaxed(&Wall(1.0), x, p, TraceOutcome::Hit { t: 10.0, steps: 2 });
        // Away from the wall the field grows as fast as t: t = 0, 10, then steps of 8 f
        // (170, 1610) until one would pass t_max, then plain ones (3230, 6470): 6 steps
        // where the plain tracer takes 10.
        let away = Ray::new(Vec3::ZERO, -Vec3::X);
        check_relaxed(&Wall(1.0), away, p, TraceOutcome::Miss { steps: 6 });
        // Starting inside is an immediate hit, as for the plain tracer.
        check_relaxed(
            &Wall(1.0),
            Ray::new(Vec3::new(11.0, 0.0, 0.0), Vec3::X),
            p,
            TraceOutcome::Hit { t: 0.0, steps: 1 },
        );
        // omega_max <= 1, NaN or infinite is the plain tracer.
        for omega in [1.0, 0.5, f32::NAN, f32::INFINITY] {
            assert_eq!(
                sphere_trace_relaxed(&Wall(2.0), &x, &p, omega),
                sphere_trace(&Wall(2.0), &x, &p)
            );
        }
    }

    #[test]
    fn relaxed_steps_back_when_the_balls_leave_a_gap() {
        let x = Ray::new(Vec3::ZERO, Vec3::X);
        let p = TraceParams::default();
        // t = 0 (f 1), plain to 1 (f 2, slope +1), relaxed by 8 to 17 (f -7): the check
        // fails, back to 1 + 2 = 3 (f 4), relaxed to 35 (f -25): fails, back to 7 (f 3,
        // slope -1/4), relaxed by 1.44 to 11.32 (f -1.32): fails, back to 10: the wall.
        check_relaxed(&Corridor, x, p, TraceOutcome::Hit { t: 10.0, steps: 8 });
        // Plain tracing: 0, 1, 3, 7, 10.
        assert_eq!(
            sphere_trace(&Corridor, &x, &p),
            TraceOutcome::Hit { t: 10.0, steps: 5 }
        );
        // A cap right after an unchecked step (1 -> 17) reports the checked 1 + 2 = 3.
        let capped = TraceParams { max_steps: 2, ..p };
        check_relaxed(
            &Corridor,
            x,
            capped,
            TraceOutcome::GaveUp { t: 3.0, steps: 2 },
        );
    }

    #[test]
    fn relaxed_never_steps_over_a_thin_slab() {
        /// A wall behind (x = -1) and a slab 1e-3 thick at x in [10, 10.001].
        struct Slab;
        impl DistanceField for Slab {
            fn distance(&self, p: Vec3) -> f32 {
                (p.x + 1.0).min((p.x - 10.0005).abs() - 0.0005)
            }
            fn lipschitz(&self) -> f32 {
                1.0
            }
        }
        let out = sphere_trace_relaxed(
            &Slab,
            &Ray::new(Vec3::ZERO, Vec3::X),
            &TraceParams::default(),
            OVER_RELAXATION,
        );
        assert_eq!(out.hit_t(), Some(10.0), "{out:?}");
    }

    #[test]
    fn thresholds_resolve_to_the_origins_rounding() {
        let p = TraceParams {
            eps_abs: 0.0,
            eps_rel: 0.0,
            ..TraceParams::default()
        };
        // At the origin the floor is the smallest normal f32, never zero.
        assert_eq!(
            p.resolving(Vec3::ZERO).eps_abs,
            HIT_ULPS * f32::MIN_POSITIVE
        );
        // It grows with the largest coordinate only, and keeps a larger chosen threshold.
        let far = p.resolving(Vec3::new(-1e4, 3.0, 2.0));
        assert_eq!(far.eps_abs, HIT_ULPS * f32::EPSILON * 1e4);
        assert_eq!(far.eps_rel, HIT_ULPS * f32::EPSILON);
        let chosen = TraceParams::default();
        assert_eq!(chosen.resolving(Vec3::ONE).eps_abs, chosen.eps_abs);
        assert_eq!(chosen.resolving(Vec3::ONE).eps_rel, chosen.eps_rel);
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
