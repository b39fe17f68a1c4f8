//! The over-relaxed march's state and step, written once over [`Lane`]s: one ray per lane.
//! [`RelaxedMarch`](crate::trace::RelaxedMarch) is the one-lane instance that
//! [`sphere_trace_relaxed`](crate::sphere_trace_relaxed) runs, and the relaxed stream runs
//! the same step for a vector of rays at once, control included, so every lane takes the
//! scalar march's steps bit for bit.
//!
//! Step counts are kept as `f32` so that they live in lanes: exact up to 2^24, the cap
//! [`MAX_STEP_CAP`] every march is held to.

use crate::lanes::{Lane, LaneVec3};

/// How close to the planar estimate's limit a relaxed step goes (below 1, so that a
/// slightly curved surface does not fail every check).
const RELAXATION_MARGIN: f32 = 0.9;

/// The largest step cap a relaxed march honours: the largest count `f32` holds exactly.
pub(crate) const MAX_STEP_CAP: u32 = 1 << 24;

/// How a lane's march stands after a step, as the lanes hold it.
pub(crate) mod status {
    pub const GOING: f32 = 0.0;
    pub const HIT: f32 = 1.0;
    pub const MISS: f32 = 2.0;
    pub const GAVE_UP: f32 = 3.0;
}

/// The state of one over-relaxed march per lane (see
/// [`sphere_trace_relaxed`](crate::sphere_trace_relaxed) for the method).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RelaxedLanes<L> {
    /// The current sample, and the steps (field evaluations) spent.
    pub t: L,
    pub steps: L,
    /// The previous sample and its field value; the step from it to `t` in field units
    /// (`omega * prev_d`, 0 before the first step); whether that step was relaxed (1) and
    /// so must pass the check before `t` is trusted, or not (0).
    pub prev_t: L,
    pub prev_d: L,
    pub last_step: L,
    pub unchecked: L,
    /// Per ray: `1 / (L |dir|)`, the far limit, the step cap and the hit thresholds.
    pub step_scale: L,
    pub t_max: L,
    pub max_steps: L,
    pub eps_abs: L,
    pub eps_rel: L,
}

impl<L: Lane> RelaxedLanes<L> {
    /// Where the march stands before its next evaluation: [`status::GOING`], or how it
    /// ended, with the `t` to report. Past `t_max` is a miss, the step cap reached short
    /// of it a give-up; at the cap, a relaxed step not yet checked is taken back to the
    /// safe one, so a give-up reports a checked point (only plain steps cross `t_max`, so
    /// a miss is declared from one).
    #[inline(always)]
    pub fn standing(&self) -> (L, L) {
        let at_cap = self.steps.ge(self.max_steps);
        let back = L::and(self.unchecked.gt(L::splat(0.0)), at_cap);
        let t = L::select(back, self.prev_t + self.prev_d * self.step_scale, self.t);
        let past = t.gt(self.t_max);
        let status = L::select(
            past,
            L::splat(status::MISS),
            L::select(at_cap, L::splat(status::GAVE_UP), L::splat(status::GOING)),
        );
        (status, t)
    }

    /// Checks the last step and takes the next one from the field's value `d` at `t`:
    /// [`status::GOING`], or how that ends the march (a hit, a NaN, a step too small to
    /// move `t`) with the `t` to report; the state is then left as it was but for the
    /// step count.
    #[inline(always)]
    pub fn advance(&mut self, d: L, omega_max: f32) -> (L, L) {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let t = self.t;
        self.steps = self.steps + one;
        let nan = d.is_nan();
        let eps = self.eps_abs.max(self.eps_rel * t);
        let two_eps = L::splat(2.0) * eps;
        // Written so that a NaN sum also fails (and takes the safe path).
        let failed = L::and(
            self.unchecked.gt(zero),
            L::not((self.prev_d + d - two_eps).ge(self.last_step)),
        );
        let hit = d.lt(eps);
        let k = ((d - self.prev_d) / self.last_step).clamp(-1.0, 1.0);
        // 1 - k = 0 gives +inf, clamped to omega_max; a NaN k (infinite distances) gives a
        // NaN omega, which takes the plain step below.
        let planar = L::splat(RELAXATION_MARGIN) * (L::splat(2.0) - two_eps / d) / (one - k);
        let omega = L::select(self.last_step.gt(zero), planar.clamp(1.0, omega_max), one);
        let safe = d * self.step_scale;
        let relaxed = t + omega * safe;
        let take_relaxed = L::and(omega.gt(one), self.t_max.ge(relaxed));
        let next = L::select(take_relaxed, relaxed, t + safe);
        let stalled = L::and(next.ge(t), t.ge(next));

        let ended = L::or(nan, L::and(L::not(failed), L::or(hit, stalled)));
        let status = L::select(
            nan,
            L::splat(status::GAVE_UP),
            L::select(
                failed,
                L::splat(status::GOING),
                L::select(
                    hit,
                    L::splat(status::HIT),
                    L::select(stalled, L::splat(status::GAVE_UP), L::splat(status::GOING)),
                ),
            ),
        );
        let going = L::not(ended);
        let back_t = self.prev_t + self.prev_d * self.step_scale;
        let new_t = L::select(failed, back_t, next);
        let new_last = L::select(failed, self.prev_d, L::select(take_relaxed, omega * d, d));
        let new_unchecked = L::select(L::and(L::not(failed), take_relaxed), one, zero);
        let new_prev_t = L::select(failed, self.prev_t, t);
        let new_prev_d = L::select(failed, self.prev_d, d);
        self.t = L::select(going, new_t, t);
        self.last_step = L::select(going, new_last, self.last_step);
        self.unchecked = L::select(going, new_unchecked, self.unchecked);
        self.prev_t = L::select(going, new_prev_t, self.prev_t);
        self.prev_d = L::select(going, new_prev_d, self.prev_d);
        (status, t)
    }
}

/// The point `origin + t dir` of each lane, as [`Ray::at`](crate::Ray::at) computes it.
#[inline(always)]
pub(crate) fn point_at<L: Lane>(origin: LaneVec3<L>, dir: LaneVec3<L>, t: L) -> LaneVec3<L> {
    LaneVec3::new(
        origin.x + t * dir.x,
        origin.y + t * dir.y,
        origin.z + t * dir.z,
    )
}
