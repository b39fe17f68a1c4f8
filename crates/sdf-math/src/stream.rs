//! Sphere tracing a stream of rays, one lane of a SIMD vector each, plain or over-relaxed.
//!
//! The field is the expensive part of a march and the same formula for every ray, so it is
//! evaluated for a vector of rays at once ([`LaneDistance::distance_lanes`], or a
//! [`StreamField`] that differs per ray). The plain march keeps each lane's control (hit,
//! miss, give-up, the next `t`) per lane, in the state machine [`sphere_trace`] itself
//! runs (`HartMarch`); the over-relaxed one advances every lane's control in one vector
//! step (`RelaxedLanes`, whose one-lane instance [`sphere_trace_relaxed`] runs). A lane
//! whose ray is done takes the next ray of the stream at once, so the vector stays full
//! until the stream runs dry, whatever the mix of short and long marches.
//!
//! A group (`group.rs`) is the other schedule.
//!
//! Contract: every ray's outcome is, bit for bit, what [`sphere_trace`] (or
//! [`sphere_trace_relaxed`]) gives for it, on every [`SimdLevel`] and for any length of
//! stream: each lane's field value equals the scalar one (the lane contract), and the
//! march around it is the same code.

use crate::lanes::{Lane, LaneDistance, LaneKernel, LaneVec3, SimdLevel, UnavailableLevel};
use crate::relaxed::{RelaxedLanes, point_at, status};
use crate::trace::{HartMarch, March, RelaxedMarch, outcome};
#[cfg(doc)]
use crate::trace::{sphere_trace, sphere_trace_relaxed};
use crate::{DistanceField, Ray, TraceOutcome, TraceParams, Vec3};

/// The widest vector of any [`SimdLevel`].
pub const MAX_LANES: usize = 16;

/// A field a stream of rays is marched through that may differ from ray to ray (each ray
/// with the objects its bounds let it meet, say), evaluated for a vector of rays at once.
///
/// Contract: the value of each lane is what the field of that lane's ray gives at its
/// point, bit for bit the same whichever lane, vector width or company the ray has, so
/// that a ray's march does not depend on how the stream was cut into vectors.
pub trait StreamField {
    /// A Lipschitz bound of every ray's field: it sets each ray's step.
    fn lipschitz(&self) -> f32;
    /// Lane `lane` (below [`MAX_LANES`]) marches ray `ray` of the stream from now on, or
    /// idles (`None`) until the next call for it.
    fn assign(&mut self, lane: usize, ray: Option<usize>);
    /// The field of each lane's ray at that lane's point; idle lanes' values are never
    /// read.
    fn distance_lanes<L: Lane>(&mut self, p: LaneVec3<L>) -> L;
}

/// Sets lane `lane` of each row to its value: how a kernel that keeps its lanes' state as
/// rows of `f32` (structure of arrays) puts a new ray in a lane.
#[inline(always)]
pub fn write_lane<const R: usize>(rows: &mut [[f32; MAX_LANES]; R], lane: usize, values: [f32; R]) {
    for (row, value) in rows.iter_mut().zip(values) {
        row[lane] = value;
    }
}

/// Rows of lanes for a kernel that takes its inputs a vector at a time: record `k` of
/// `records` in lane `k % width` of group `k / width` of `groups` (cleared first). Every group is written before the kernel loads the first: a vector loaded
/// right after the scalar stores of its lanes waits for them to retire, where one loaded
/// later is read from the cache. Lanes past a short last group hold the group before's
/// records (zeros where there is none): finite, for the kernel to ignore.
pub fn fill_lane_groups<const R: usize>(
    records: impl ExactSizeIterator<Item = [f32; R]>,
    width: usize,
    groups: &mut Vec<[[f32; MAX_LANES]; R]>,
) {
    assert!((1..=MAX_LANES).contains(&width), "{width} lanes");
    groups.clear();
    groups.resize(records.len().div_ceil(width), [[0.0; MAX_LANES]; R]);
    // Counted, not `k / width` and `k % width`: the width is known only at run time, so
    // those would be two integer divisions a record.
    let (mut group, mut lane) = (0, 0);
    for values in records {
        write_lane(&mut groups[group], lane, values);
        lane += 1;
        if lane == width {
            (group, lane) = (group + 1, 0);
        }
    }
    // `lane` is now how many lanes the last group fills, 0 if all.
    if let ([.., before, last], 1..) = (&mut groups[..], lane) {
        for (row, before) in last.iter_mut().zip(before.iter()) {
            row[lane..width].copy_from_slice(&before[lane..width]);
        }
    }
}

/// Records of `R` numbers kept for a kernel that loads them a vector at a time, in groups
/// of [`MAX_LANES`] lanes as rows: record `k` is lane `k % MAX_LANES` of group
/// `k / MAX_LANES`. Each is written in place as it is pushed (one bounds check, fixed
/// offsets, no per-row length), long before the kernel loads it, and every level's
/// vectors divide a group. Lanes past the last record hold earlier records, or zeros:
/// finite, for the kernel to ignore.
#[derive(Clone, Debug, Default)]
pub struct LaneGroups<const R: usize> {
    groups: Vec<[[f32; MAX_LANES]; R]>,
    len: usize,
}

impl<const R: usize> LaneGroups<R> {
    /// Forgets every record (keeping the memory).
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Adds a record; its index.
    #[inline(always)]
    pub fn push(&mut self, values: [f32; R]) -> usize {
        let k = self.len;
        let group = k / MAX_LANES;
        if group == self.groups.len() {
            self.groups.push([[0.0; MAX_LANES]; R]);
        }
        write_lane(&mut self.groups[group], k % MAX_LANES, values);
        self.len += 1;
        k
    }

    /// How many records there are.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The groups that hold the records, the last one partly past them.
    pub fn groups(&self) -> &[[[f32; MAX_LANES]; R]] {
        &self.groups[..self.len.div_ceil(MAX_LANES)]
    }
}

/// One field for every ray of a stream or group.
pub(crate) struct Shared<'a, F: ?Sized>(pub(crate) &'a F);

impl<F: LaneDistance + DistanceField + ?Sized> StreamField for Shared<'_, F> {
    fn lipschitz(&self) -> f32 {
        self.0.lipschitz()
    }

    #[inline(always)]
    fn assign(&mut self, _: usize, _: Option<usize>) {}

    #[inline(always)]
    fn distance_lanes<L: Lane>(&mut self, p: LaneVec3<L>) -> L {
        self.0.distance_lanes(p)
    }
}

/// Traces every ray of `rays` with its `params` through `field` by plain sphere tracing,
/// writing each outcome to `out`, on the widest path this CPU has.
///
/// # Panics
/// If `rays`, `params` and `out` differ in length.
pub fn sphere_trace_stream<F>(
    field: &F,
    rays: &[Ray],
    params: &[TraceParams],
    out: &mut [TraceOutcome],
) where
    F: LaneDistance + DistanceField + ?Sized,
{
    // `detect` only returns levels the CPU has.
    let _ = sphere_trace_stream_at(SimdLevel::detect(), field, rays, params, out);
}

/// [`sphere_trace_stream`] on a forced path; the same outcomes on every path.
///
/// # Panics
/// If `rays`, `params` and `out` differ in length.
pub fn sphere_trace_stream_at<F>(
    level: SimdLevel,
    field: &F,
    rays: &[Ray],
    params: &[TraceParams],
    out: &mut [TraceOutcome],
) -> Result<(), UnavailableLevel>
where
    F: LaneDistance + DistanceField + ?Sized,
{
    sphere_trace_relaxed_stream_of(level, &mut Shared(field), rays, params, 1.0, out)
}

/// Traces every ray of `rays` with its `params` through `field` by over-relaxed sphere
/// tracing with factors up to `omega_max`, writing each outcome to `out`, on the widest
/// path this CPU has.
///
/// # Panics
/// If `rays`, `params` and `out` differ in length.
pub fn sphere_trace_relaxed_stream<F>(
    field: &F,
    rays: &[Ray],
    params: &[TraceParams],
    omega_max: f32,
    out: &mut [TraceOutcome],
) where
    F: LaneDistance + DistanceField + ?Sized,
{
    // `detect` only returns levels the CPU has.
    let _ =
        sphere_trace_relaxed_stream_at(SimdLevel::detect(), field, rays, params, omega_max, out);
}

/// [`sphere_trace_relaxed_stream`] on a forced path; the same outcomes on every path.
///
/// # Panics
/// If `rays`, `params` and `out` differ in length.
pub fn sphere_trace_relaxed_stream_at<F>(
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
    sphere_trace_relaxed_stream_of(level, &mut Shared(field), rays, params, omega_max, out)
}

/// Panics, naming `march`, unless `rays`, `params` and `out` have one entry per ray each.
pub(crate) fn assert_one_each(
    march: &str,
    rays: &[Ray],
    params: &[TraceParams],
    out: &[TraceOutcome],
) {
    assert!(
        rays.len() == params.len() && rays.len() == out.len(),
        "{march}: {} rays, {} parameters, {} outcomes",
        rays.len(),
        params.len(),
        out.len()
    );
}

/// [`sphere_trace_relaxed_stream_at`] through a field that may differ per ray: each ray's
/// outcome is what [`sphere_trace_relaxed`] gives for it through its own field (the plain
/// march where `omega_max` is not above 1), on every path and for any length of stream.
///
/// # Panics
/// If `rays`, `params` and `out` differ in length.
pub fn sphere_trace_relaxed_stream_of<F: StreamField>(
    level: SimdLevel,
    field: &mut F,
    rays: &[Ray],
    params: &[TraceParams],
    omega_max: f32,
    out: &mut [TraceOutcome],
) -> Result<(), UnavailableLevel> {
    assert_one_each("sphere_trace_stream", rays, params, out);
    let lipschitz = field.lipschitz();
    if omega_max > 1.0 && omega_max.is_finite() {
        level.dispatch(RelaxedStream {
            field,
            rays,
            params,
            out,
            lipschitz,
            omega_max,
        })
    } else {
        // As `sphere_trace_relaxed` does: no factor above 1 is the plain march.
        level.dispatch(PlainStream {
            field,
            rays,
            params,
            out,
            lipschitz,
        })
    }
}

/// The kernel of the plain streams: the field per vector, each lane's march
/// ([`HartMarch`]) per lane.
struct PlainStream<'a, F> {
    field: &'a mut F,
    rays: &'a [Ray],
    params: &'a [TraceParams],
    out: &'a mut [TraceOutcome],
    lipschitz: f32,
}

/// A lane's march, the index of its ray in the stream, and the point its march evaluates
/// next.
#[derive(Clone, Copy)]
struct InFlight {
    march: HartMarch,
    ray: usize,
    point: Vec3,
}

impl<F: StreamField> PlainStream<'_, F> {
    /// The next ray of the stream that needs the field at all, from `*next` on, for
    /// `lane`; rays that end before their first evaluation get their outcome here.
    #[inline(always)]
    fn take(&mut self, lane: usize, next: &mut usize) -> Option<InFlight> {
        while *next < self.rays.len() {
            let ray = *next;
            *next += 1;
            let started = HartMarch::start(self.lipschitz, &self.rays[ray], &self.params[ray]);
            match started.and_then(|march| Ok((march, march.next_point()?))) {
                Ok((march, point)) => {
                    self.field.assign(lane, Some(ray));
                    return Some(InFlight { march, ray, point });
                }
                Err(outcome) => self.out[ray] = outcome,
            }
        }
        self.field.assign(lane, None);
        None
    }
}

impl<F: StreamField> LaneKernel for PlainStream<'_, F> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(mut self) {
        let lanes = L::LANES.min(MAX_LANES);
        let mut flight: [Option<InFlight>; MAX_LANES] = [None; MAX_LANES];
        let mut next = 0;
        for (lane, slot) in flight.iter_mut().enumerate().take(lanes) {
            *slot = self.take(lane, &mut next);
        }
        let (mut xs, mut ys, mut zs) = ([0f32; MAX_LANES], [0f32; MAX_LANES], [0f32; MAX_LANES]);
        let mut d = [0f32; MAX_LANES];
        while flight[..lanes].iter().any(Option::is_some) {
            for (lane, slot) in flight[..lanes].iter().enumerate() {
                // An idle lane evaluates the origin; its value is never read.
                let p = slot.map_or(Vec3::ZERO, |f| f.point);
                (xs[lane], ys[lane], zs[lane]) = (p.x, p.y, p.z);
            }
            let p = LaneVec3::new(
                L::assemble(&xs[..lanes]),
                L::assemble(&ys[..lanes]),
                L::assemble(&zs[..lanes]),
            );
            self.field.distance_lanes(p).store(&mut d[..lanes]);
            for lane in 0..lanes {
                let Some(mut f) = flight[lane] else {
                    continue;
                };
                let next_point = match f.march.advance(d[lane]) {
                    None => f.march.next_point(),
                    Some(outcome) => Err(outcome),
                };
                flight[lane] = match next_point {
                    Ok(point) => Some(InFlight { point, ..f }),
                    Err(outcome) => {
                        self.out[f.ray] = outcome;
                        self.take(lane, &mut next)
                    }
                };
            }
        }
    }
}

/// The kernel of the relaxed streams: every lane's march, control included, advances in
/// one vector step ([`RelaxedLanes`]); a lane whose ray is done takes the next one.
struct RelaxedStream<'a, F> {
    field: &'a mut F,
    rays: &'a [Ray],
    params: &'a [TraceParams],
    out: &'a mut [TraceOutcome],
    lipschitz: f32,
    omega_max: f32,
}

/// The rows of a relaxed stream's lane state, one `f32` per lane each.
const ROWS: usize = 17;

impl<F: StreamField> RelaxedStream<'_, F> {
    /// Gives `lane` the next ray of the stream that needs the field at all, from `*next`
    /// on, writing its state into `rows`; rays that end before their first evaluation get
    /// their outcome here. `None` when the stream is dry: the lane idles.
    ///
    /// Never inlined, though the kernel inlines everything else: inlined, its scalar
    /// stores into `rows` reach the next step's vector loads of them, and the optimiser
    /// forwards the stored lanes into those loads, splitting every row into pieces put
    /// back together with shuffles at every step, refill or not. Out of line, the kernel
    /// loads each row whole: a step takes about 200 instructions on AVX2 against 630
    /// inlined (docs/PERFORMANCE.md, "Instructions per sample"), for one call per ray,
    /// whose work needs no vector instruction.
    #[inline(never)]
    fn take(
        &mut self,
        lane: usize,
        next: &mut usize,
        rows: &mut [[f32; MAX_LANES]; ROWS],
    ) -> Option<usize> {
        while *next < self.rays.len() {
            let ray = *next;
            *next += 1;
            let started = RelaxedMarch::start(
                self.lipschitz,
                &self.rays[ray],
                &self.params[ray],
                self.omega_max,
            );
            match started.and_then(|march| march.next_point().map(|_| march)) {
                Ok(march) => {
                    let (o, d, s) = (march.ray.origin, march.ray.dir, march.state);
                    let values = [
                        o.x,
                        o.y,
                        o.z,
                        d.x,
                        d.y,
                        d.z,
                        s.t,
                        s.steps,
                        s.prev_t,
                        s.prev_d,
                        s.last_step,
                        s.unchecked,
                        s.step_scale,
                        s.t_max,
                        s.max_steps,
                        s.eps_abs,
                        s.eps_rel,
                    ];
                    write_lane(rows, lane, values);
                    self.field.assign(lane, Some(ray));
                    return Some(ray);
                }
                Err(outcome) => self.out[ray] = outcome,
            }
        }
        self.field.assign(lane, None);
        None
    }
}

impl<F: StreamField> LaneKernel for RelaxedStream<'_, F> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(mut self) {
        let lanes = L::LANES.min(MAX_LANES);
        let mut rows = [[0f32; MAX_LANES]; ROWS];
        let mut flight = [0usize; MAX_LANES];
        // The lanes with a ray in flight, lane `i` in bit `i`.
        let mut flying = 0u32;
        let mut next = 0;
        for (lane, slot) in flight.iter_mut().enumerate().take(lanes) {
            if let Some(ray) = self.take(lane, &mut next, &mut rows) {
                *slot = ray;
                flying |= 1 << lane;
            }
        }
        let (mut status, mut t_out) = ([0f32; MAX_LANES], [0f32; MAX_LANES]);
        while flying != 0 {
            let row = |i: usize| L::load(&rows[i][..lanes]);
            let origin = LaneVec3::new(row(0), row(1), row(2));
            let dir = LaneVec3::new(row(3), row(4), row(5));
            let mut state = RelaxedLanes {
                t: row(6),
                steps: row(7),
                prev_t: row(8),
                prev_d: row(9),
                last_step: row(10),
                unchecked: row(11),
                step_scale: row(12),
                t_max: row(13),
                max_steps: row(14),
                eps_abs: row(15),
                eps_rel: row(16),
            };
            let d = self.field.distance_lanes(point_at(origin, dir, state.t));
            let (stepped, t_stepped) = state.advance(d, self.omega_max);
            let (standing, t_standing) = state.standing();
            let ended = stepped.gt(L::splat(status::GOING));
            let lane_status = L::select(ended, stepped, standing);
            lane_status.store(&mut status[..lanes]);
            L::select(ended, t_stepped, t_standing).store(&mut t_out[..lanes]);
            // Only the lanes whose ray ended visit their outcome.
            let mut done = L::bits(lane_status.gt(L::splat(status::GOING))) & flying;
            for (i, v) in [
                state.t,
                state.steps,
                state.prev_t,
                state.prev_d,
                state.last_step,
                state.unchecked,
            ]
            .into_iter()
            .enumerate()
            {
                v.store(&mut rows[6 + i][..lanes]);
            }
            while done != 0 {
                let lane = done.trailing_zeros() as usize;
                done &= done - 1;
                if let Some(outcome) = outcome(status[lane], t_out[lane], rows[7][lane]) {
                    self.out[flight[lane]] = outcome;
                    match self.take(lane, &mut next, &mut rows) {
                        Some(ray) => flight[lane] = ray,
                        None => flying &= !(1 << lane),
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    /// Record `k` is lane `k % MAX_LANES` of group `k / MAX_LANES`; the groups cover the
    /// records and no more, and a cleared set refills from the first lane.
    #[test]
    fn lane_groups_hold_record_k_in_its_lane() {
        let mut records = LaneGroups::<2>::default();
        for round in 0..2 {
            records.clear();
            let n = if round == 0 { 37 } else { 5 };
            for k in 0..n {
                assert_eq!(records.push([k as f32, -(k as f32) - round as f32]), k);
            }
            assert_eq!(records.len(), n);
            assert_eq!(records.groups().len(), n.div_ceil(MAX_LANES));
            for k in 0..n {
                let [a, b] = &records.groups()[k / MAX_LANES];
                assert_eq!(
                    (a[k % MAX_LANES], b[k % MAX_LANES]),
                    (k as f32, -(k as f32) - round as f32)
                );
            }
        }
        records.clear();
        assert!(records.is_empty() && records.groups().is_empty());
    }

    use super::*;
    use crate::{
        OVER_RELAXATION, PreparedSdf, Sdf, sphere_trace, sphere_trace_relaxed,
        sphere_trace_relaxed_groups_at,
    };

    /// Each record lands in its group and lane, for every count and width; a short last
    /// group's spare lanes copy the group before's, and a buffer reused shrinks.
    #[test]
    fn lane_groups_hold_each_record_in_its_lane() {
        let mut groups = Vec::new();
        for width in [1, 4, 7, 8, 16] {
            for n in [0, 1, width - 1, width, width + 1, 3 * width + 2] {
                let records = (0..n).map(|k| [k as f32, -(k as f32)]);
                fill_lane_groups(records, width, &mut groups);
                assert_eq!(
                    groups.len(),
                    n.div_ceil(width),
                    "{n} records, {width} lanes"
                );
                for k in 0..n {
                    let (g, lane) = (k / width, k % width);
                    assert_eq!(groups[g][0][lane], k as f32);
                    assert_eq!(groups[g][1][lane], -(k as f32));
                }
                if n > width && n % width != 0 {
                    let (last, spare) = (groups.len() - 1, n % width..width);
                    assert_eq!(groups[last][0][spare.clone()], groups[last - 1][0][spare]);
                }
            }
        }
    }

    /// An outcome as bits, so that equality is bitwise (`-0.0 != 0.0`, NaN == NaN).
    fn bits(o: &TraceOutcome) -> (u8, u32, u32) {
        match *o {
            TraceOutcome::Hit { t, steps } => (0, t.to_bits(), steps),
            TraceOutcome::Miss { steps } => (1, 0, steps),
            TraceOutcome::GaveUp { t, steps } => (2, t.to_bits(), steps),
        }
    }

    /// A fixed, varied set of rays: aimed near the origin from a shell of radius 2 to 6,
    /// some grazing, some away; a few degenerate directions; parameters with small step
    /// caps and short far limits among them, so every outcome occurs.
    fn rays(n: usize) -> (Vec<Ray>, Vec<TraceParams>) {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut rays = Vec::new();
        let mut params = Vec::new();
        for i in 0..n {
            let dir = Vec3::new(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5);
            let origin = dir.normalize_or(Vec3::X) * (2.0 + 4.0 * uniform());
            let aim = Vec3::new(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5) * 1.5;
            let dir = match i % 23 {
                0 => Vec3::ZERO,
                11 => -(aim - origin),
                _ => aim - origin,
            };
            rays.push(Ray::new(origin, dir));
            params.push(TraceParams {
                max_steps: if i % 5 == 0 { 1 + i as u32 % 7 } else { 128 },
                t_max: if i % 7 == 0 { 1.5 } else { 50.0 },
                t_min: if i % 13 == 0 { 0.5 } else { 0.0 },
                ..TraceParams::default()
            });
        }
        (rays, params)
    }

    fn fields() -> Vec<(&'static str, Sdf)> {
        let spheres = (0..8)
            .map(|i| Sdf::sphere(0.3).translate(Vec3::new(i as f32 * 0.4 - 1.4, 0.1, 0.0)))
            .collect();
        vec![
            ("sphere", Sdf::sphere(1.0)),
            (
                "torus",
                Sdf::torus(1.0, 0.25).rotate(Quat::from_rotation_x(0.7)),
            ),
            ("union of spheres", Sdf::union(spheres)),
            (
                "smooth union",
                Sdf::smooth_union(
                    0.2,
                    vec![
                        Sdf::cuboid(Vec3::splat(0.5)),
                        Sdf::sphere(0.6).translate(Vec3::X),
                    ],
                ),
            ),
            ("death star", Sdf::death_star(1.0, 0.8, 0.9)),
        ]
    }

    /// Both streams and the groups against their scalar tracers; `omega_max` 1 is the plain
    /// march.
    fn check<F: LaneDistance + DistanceField>(name: &str, field: &F) {
        for omega_max in [1.0, 2.0, OVER_RELAXATION] {
            for n in [1, 7, 16, 100] {
                let (rays, params) = rays(n);
                let expected: Vec<_> = rays
                    .iter()
                    .zip(&params)
                    .map(|(r, p)| bits(&sphere_trace_relaxed(field, r, p, omega_max)))
                    .collect();
                for level in SimdLevel::available() {
                    let mut out = vec![TraceOutcome::Miss { steps: u32::MAX }; n];
                    sphere_trace_relaxed_stream_at(
                        level, field, &rays, &params, omega_max, &mut out,
                    )
                    .unwrap();
                    let got: Vec<_> = out.iter().map(bits).collect();
                    assert_eq!(
                        got, expected,
                        "{name}, omega {omega_max}, {n} rays, {level:?}"
                    );
                    out.fill(TraceOutcome::GaveUp { t: 0.0, steps: 9 });
                    sphere_trace_relaxed_groups_at(
                        level, field, &rays, &params, omega_max, &mut out,
                    )
                    .unwrap();
                    let groups: Vec<_> = out.iter().map(bits).collect();
                    assert_eq!(
                        groups, expected,
                        "{name}, groups, omega {omega_max}, {n} rays, {level:?}"
                    );
                    if omega_max == 1.0 {
                        sphere_trace_stream_at(level, field, &rays, &params, &mut out).unwrap();
                        let plain: Vec<_> = out.iter().map(bits).collect();
                        let scalar: Vec<_> = rays
                            .iter()
                            .zip(&params)
                            .map(|(r, p)| bits(&sphere_trace(field, r, p)))
                            .collect();
                        assert_eq!(plain, scalar, "{name}, plain, {n} rays, {level:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn every_ray_of_a_stream_or_group_takes_the_scalar_tracers_steps() {
        for (name, sdf) in fields() {
            check(name, &sdf);
            check(
                name,
                &PreparedSdf::new(&sdf.clone().translate(Vec3::Y * 0.25)),
            );
        }
    }

    #[test]
    fn the_test_rays_reach_every_outcome() {
        let (rays, params) = rays(100);
        let mut out = vec![TraceOutcome::Miss { steps: 0 }; 100];
        sphere_trace_stream(&Sdf::sphere(1.0), &rays, &params, &mut out);
        for kind in 0..3 {
            assert!(
                out.iter().any(|o| bits(o).0 == kind),
                "no outcome of kind {kind}"
            );
        }
    }

    #[test]
    #[should_panic(expected = "3 rays, 2 parameters")]
    fn mismatched_lengths_panic() {
        let (rays, params) = rays(3);
        let mut out = vec![TraceOutcome::Miss { steps: 0 }; 3];
        sphere_trace_stream(&Sdf::sphere(1.0), &rays, &params[..2], &mut out);
    }
}
