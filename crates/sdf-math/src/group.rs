//! Sphere tracing a group of rays, one lane of a SIMD vector each, marched together by
//! over-relaxed steps until the last of them ends, its state in registers throughout
//! ([`sphere_trace_relaxed_group`]). It is the stream's other schedule (`stream.rs`): it
//! saves the stream's per-ray work (a lane's state written in and read back, the field
//! told of each new ray) and wastes the lanes of rays that end early, so it pays where the
//! rays of a vector take about as many steps as one another.
//!
//! Contract: as the stream's, every ray's outcome is, bit for bit, what
//! [`sphere_trace_relaxed`] gives for it, on every [`SimdLevel`] and whatever the other
//! lanes hold: each lane's field value equals the scalar one, and the step is
//! `RelaxedLanes`, whose one-lane instance the scalar march runs. Tested with the streams
//! (`stream.rs`).

use crate::lanes::{Lane, LaneDistance, LaneKernel, LaneVec3, SimdLevel, UnavailableLevel};
use crate::relaxed::{MAX_STEP_CAP, RelaxedLanes, point_at, status};
use crate::stream::{
    MAX_LANES, Shared, assert_one_each, fill_lane_groups, sphere_trace_relaxed_stream_at,
};
use crate::trace::outcome;
#[cfg(doc)]
use crate::trace::sphere_trace_relaxed;
use crate::{DistanceField, Ray, TraceOutcome, TraceParams};

/// A field a group of rays is marched through together ([`sphere_trace_relaxed_group`]),
/// which may differ from lane to lane.
///
/// Contract: as [`StreamField`]'s, the value of each lane in `going` is what that lane's
/// ray's field gives at its point, whatever the other lanes hold.
pub trait GroupField<L: Lane> {
    /// The field of each lane's ray at that lane's point, for the lanes in `going`; the
    /// other lanes' values are never read.
    fn distance_lanes(&mut self, p: LaneVec3<L>, going: L::Mask) -> L;
}

/// A vector of rays for [`sphere_trace_relaxed_group`], one per lane, each with the
/// fields of its [`TraceParams`] (its step cap as an `f32`); the lanes outside `live`
/// hold no ray, and end as misses in no step.
#[derive(Clone, Copy, Debug)]
pub struct GroupRays<L: Lane> {
    /// Each ray's origin and direction.
    pub origin: LaneVec3<L>,
    /// See `origin`.
    pub dir: LaneVec3<L>,
    /// [`TraceParams::t_min`], per lane.
    pub t_min: L,
    /// [`TraceParams::t_max`], per lane.
    pub t_max: L,
    /// [`TraceParams::max_steps`], per lane, as an `f32` (caps above `2^24` march as
    /// `2^24`, as the scalar march does).
    pub max_steps: L,
    /// [`TraceParams::eps_abs`], per lane.
    pub eps_abs: L,
    /// [`TraceParams::eps_rel`], per lane.
    pub eps_rel: L,
    /// The lanes that hold a ray.
    pub live: L::Mask,
}

/// How each lane's march in a group ended: its [`TraceOutcome`] as lanes.
#[derive(Clone, Copy, Debug)]
pub struct GroupEnds<L> {
    status: L,
    t: L,
    steps: L,
}

impl<L: Lane> GroupEnds<L> {
    /// Keeps, for the lanes of `going` whose march `status` says has ended, that status,
    /// `t` and step count, and takes them out of `going`. A method, not a closure: a
    /// closure's body is compiled for the baseline unless it is inlined.
    #[inline(always)]
    fn record(&mut self, going: &mut L::Mask, now: L, t: L, steps: L) {
        let ended = L::and(*going, now.gt(L::splat(status::GOING)));
        self.status = L::select(ended, now, self.status);
        self.t = L::select(ended, t, self.t);
        self.steps = L::select(ended, steps, self.steps);
        *going = L::and(*going, L::not(ended));
    }

    /// The lanes whose march ended on a hit.
    #[inline(always)]
    pub fn hit(&self) -> L::Mask {
        is_status(self.status, status::HIT)
    }

    /// The lanes whose march gave up: at the step cap, or on a ray that cannot move.
    #[inline(always)]
    pub fn gave_up(&self) -> L::Mask {
        is_status(self.status, status::GAVE_UP)
    }

    /// Where each lane's march ended (its [`TraceOutcome`]'s `t`, where it has one).
    #[inline(always)]
    pub fn t(&self) -> L {
        self.t
    }

    /// The steps (field evaluations) each lane's march took.
    #[inline(always)]
    pub fn steps(&self) -> L {
        self.steps
    }

    /// The outcome of each lane's march, in its lane's place; `out` holds at least
    /// `L::LANES` outcomes.
    #[inline(always)]
    pub fn store(&self, out: &mut [TraceOutcome]) {
        let lanes = L::LANES.min(MAX_LANES);
        let (mut status, mut t, mut steps) =
            ([0f32; MAX_LANES], [0f32; MAX_LANES], [0f32; MAX_LANES]);
        self.status.store(&mut status[..lanes]);
        self.t.store(&mut t[..lanes]);
        self.steps.store(&mut steps[..lanes]);
        for (lane, out) in out[..lanes].iter_mut().enumerate() {
            // Every live lane has ended; the others hold a miss in no step.
            *out = outcome(status[lane], t[lane], steps[lane])
                .unwrap_or(TraceOutcome::Miss { steps: 0 });
        }
    }
}

/// The lanes whose status is `value` (statuses are small integers, exact in `f32`).
#[inline(always)]
fn is_status<L: Lane>(status: L, value: f32) -> L::Mask {
    L::and(
        status.ge(L::splat(value)),
        L::not(status.gt(L::splat(value))),
    )
}

/// Traces each lane's ray of `rays` through `field` by over-relaxed sphere tracing with
/// factors up to `omega_max` (above 1 and finite), every lane a step at a time until the
/// last has ended: each lane's outcome is, bit for bit, what [`sphere_trace_relaxed`]
/// gives for its ray through its own field, whatever the other lanes hold. For a kernel
/// that has its rays in lanes already, and rays that take about as many steps as one
/// another (see the module notes).
#[inline(always)]
pub fn sphere_trace_relaxed_group<L: Lane, F: GroupField<L>>(
    field: &mut F,
    lipschitz: f32,
    rays: &GroupRays<L>,
    omega_max: f32,
) -> GroupEnds<L> {
    debug_assert!(omega_max > 1.0 && omega_max.is_finite());
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    // `RelaxedMarch::start` in lanes: a zero or non-finite direction gives up at once.
    let lipschitz = if lipschitz > 0.0 { lipschitz } else { 1.0 };
    let dir = rays.dir;
    let speed = (dir.x * dir.x + dir.y * dir.y + dir.z * dir.z).sqrt();
    let moves = L::and(speed.gt(zero), speed.lt(L::splat(f32::INFINITY)));
    let mut state = RelaxedLanes {
        t: rays.t_min,
        steps: zero,
        prev_t: rays.t_min,
        prev_d: zero,
        last_step: zero,
        unchecked: zero,
        step_scale: one / (L::splat(lipschitz) * speed),
        t_max: rays.t_max,
        max_steps: rays.max_steps.min(L::splat(MAX_STEP_CAP as f32)),
        eps_abs: rays.eps_abs,
        eps_rel: rays.eps_rel,
    };
    let stuck = L::and(rays.live, L::not(moves));
    let mut ends = GroupEnds {
        status: L::select(stuck, L::splat(status::GAVE_UP), L::splat(status::MISS)),
        t: rays.t_min,
        steps: zero,
    };
    let mut going = L::and(rays.live, moves);
    // Where each march stands before its first evaluation, then after each step: the
    // lanes that end keep their status, `t` and step count from then on.
    let (standing, t_standing) = state.standing();
    ends.record(&mut going, standing, t_standing, state.steps);
    while L::any(going) {
        let d = field.distance_lanes(point_at(rays.origin, dir, state.t), going);
        let (stepped, t_stepped) = state.advance(d, omega_max);
        let (standing, t_standing) = state.standing();
        let ended = stepped.gt(L::splat(status::GOING));
        ends.record(
            &mut going,
            L::select(ended, stepped, standing),
            L::select(ended, t_stepped, t_standing),
            state.steps,
        );
    }
    ends
}

/// [`sphere_trace_relaxed_stream_at`] with the rays marched in groups of a vector each
/// ([`sphere_trace_relaxed_group`]) rather than as a stream: the same outcome for every ray,
/// bit for bit, on every path. The plain march where `omega_max` is not above 1, as a
/// stream.
///
/// # Panics
/// If `rays`, `params` and `out` differ in length.
pub fn sphere_trace_relaxed_groups_at<F>(
    level: SimdLevel,
    field: &F,
    rays: &[Ray],
    params: &[TraceParams],
    omega_max: f32,
    out: &mut [TraceOutcome],
) -> Result<(), UnavailableLevel>
where
    F: LaneDistance + DistanceField + ?Sized,
{
    if !(omega_max > 1.0 && omega_max.is_finite()) {
        return sphere_trace_relaxed_stream_at(level, field, rays, params, omega_max, out);
    }
    assert_one_each("sphere_trace_relaxed_groups", rays, params, out);
    level.dispatch(RelaxedGroups {
        field,
        rays,
        params,
        omega_max,
        out,
    })
}

/// The kernel of [`sphere_trace_relaxed_groups_at`]: each vector of rays loaded from rows
/// and marched to its last ray's end.
struct RelaxedGroups<'a, F: ?Sized> {
    field: &'a F,
    rays: &'a [Ray],
    params: &'a [TraceParams],
    omega_max: f32,
    out: &'a mut [TraceOutcome],
}

impl<F: LaneDistance + DistanceField + ?Sized, L: Lane> GroupField<L> for Shared<'_, F> {
    #[inline(always)]
    fn distance_lanes(&mut self, p: LaneVec3<L>, _: L::Mask) -> L {
        self.0.distance_lanes(p)
    }
}

impl<F: LaneDistance + DistanceField + ?Sized> LaneKernel for RelaxedGroups<'_, F> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(self) {
        let lanes = L::LANES.min(MAX_LANES);
        let records = self.rays.iter().zip(self.params).map(|(r, p)| {
            [
                r.origin.x,
                r.origin.y,
                r.origin.z,
                r.dir.x,
                r.dir.y,
                r.dir.z,
                p.t_min,
                p.t_max,
                p.max_steps as f32,
                p.eps_abs,
                p.eps_rel,
            ]
        });
        let mut rows = Vec::new();
        fill_lane_groups(records, lanes, &mut rows);
        let index: [f32; MAX_LANES] = std::array::from_fn(|i| i as f32);
        let lipschitz = self.field.lipschitz();
        let mut ends = [TraceOutcome::Miss { steps: 0 }; MAX_LANES];
        for (v, out) in rows.iter().zip(self.out.chunks_mut(lanes)) {
            let row = |i: usize| L::load(&v[i][..lanes]);
            let group = GroupRays {
                origin: LaneVec3::new(row(0), row(1), row(2)),
                dir: LaneVec3::new(row(3), row(4), row(5)),
                t_min: row(6),
                t_max: row(7),
                max_steps: row(8),
                eps_abs: row(9),
                eps_rel: row(10),
                live: L::load(&index[..lanes]).lt(L::splat(out.len() as f32)),
            };
            sphere_trace_relaxed_group(&mut Shared(self.field), lipschitz, &group, self.omega_max)
                .store(&mut ends);
            out.copy_from_slice(&ends[..out.len()]);
        }
    }
}
