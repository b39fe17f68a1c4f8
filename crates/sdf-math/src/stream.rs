//! Sphere tracing a stream of rays, one lane of a SIMD vector each, plain or over-relaxed.
//!
//! The field is the expensive part of a march and the same formula for every ray, so it is
//! evaluated for a vector of rays at once ([`LaneDistance::distance_lanes`]); the control
//! of each march (hit, miss, give-up, the next `t`) stays per lane, in the state machine
//! [`sphere_trace`] itself runs (`HartMarch`; `RelaxedMarch` for
//! [`sphere_trace_relaxed`]). A lane whose ray is done takes the next ray
//! of the stream at once, so the vector stays full until the stream runs dry, whatever the
//! mix of short and long marches.
//!
//! Contract: every ray's outcome is, bit for bit, what [`sphere_trace`] (or
//! [`sphere_trace_relaxed`]) gives for it, on
//! every [`SimdLevel`] and for any length of stream: each lane's field value equals the
//! scalar one (the lane contract), and the march around it is the same code.

use crate::lanes::{Lane, LaneDistance, LaneKernel, LaneVec3, SimdLevel, UnavailableLevel};
use crate::trace::{HartMarch, March, RelaxedMarch};
#[cfg(doc)]
use crate::trace::{sphere_trace, sphere_trace_relaxed};
use crate::{DistanceField, Ray, TraceOutcome, TraceParams, Vec3};

/// The widest vector of any [`SimdLevel`].
const MAX_LANES: usize = 16;

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
    check_lengths(rays, params, out);
    level.dispatch(Stream {
        field,
        rays,
        params,
        out,
        start: |ray: &Ray, params: &TraceParams| HartMarch::start(field, ray, params),
    })
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
    if !(omega_max > 1.0 && omega_max.is_finite()) {
        // As `sphere_trace_relaxed` does: no factor above 1 is the plain march.
        return sphere_trace_stream_at(level, field, rays, params, out);
    }
    check_lengths(rays, params, out);
    level.dispatch(Stream {
        field,
        rays,
        params,
        out,
        start: |ray: &Ray, params: &TraceParams| RelaxedMarch::start(field, ray, params, omega_max),
    })
}

fn check_lengths(rays: &[Ray], params: &[TraceParams], out: &[TraceOutcome]) {
    assert!(
        rays.len() == params.len() && rays.len() == out.len(),
        "sphere_trace_stream: {} rays, {} parameters, {} outcomes",
        rays.len(),
        params.len(),
        out.len()
    );
}

/// The kernel behind both streams: `start` begins a ray's march.
struct Stream<'a, F: ?Sized, S> {
    field: &'a F,
    rays: &'a [Ray],
    params: &'a [TraceParams],
    out: &'a mut [TraceOutcome],
    start: S,
}

/// A lane's march, the index of its ray in the stream, and the point its march evaluates
/// next.
#[derive(Clone, Copy)]
struct InFlight<M> {
    march: M,
    ray: usize,
    point: Vec3,
}

impl<F, S, M> Stream<'_, F, S>
where
    F: LaneDistance + DistanceField + ?Sized,
    S: Fn(&Ray, &TraceParams) -> Result<M, TraceOutcome>,
    M: March,
{
    /// The next ray of the stream that needs the field at all, from `*next` on; rays that
    /// end before their first evaluation get their outcome here.
    #[inline(always)]
    fn take(&mut self, next: &mut usize) -> Option<InFlight<M>> {
        while *next < self.rays.len() {
            let ray = *next;
            *next += 1;
            let started = (self.start)(&self.rays[ray], &self.params[ray]);
            match started.and_then(|march| Ok((march, march.next_point()?))) {
                Ok((march, point)) => return Some(InFlight { march, ray, point }),
                Err(outcome) => self.out[ray] = outcome,
            }
        }
        None
    }
}

impl<F, S, M> LaneKernel for Stream<'_, F, S>
where
    F: LaneDistance + DistanceField + ?Sized,
    S: Fn(&Ray, &TraceParams) -> Result<M, TraceOutcome>,
    M: March,
{
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(mut self) {
        let lanes = L::LANES.min(MAX_LANES);
        let mut flight: [Option<InFlight<M>>; MAX_LANES] = [None; MAX_LANES];
        let mut next = 0;
        for slot in flight.iter_mut().take(lanes) {
            *slot = self.take(&mut next);
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
                L::load(&xs[..lanes]),
                L::load(&ys[..lanes]),
                L::load(&zs[..lanes]),
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
                        self.take(&mut next)
                    }
                };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::*;
    use crate::{OVER_RELAXATION, PreparedSdf, Sdf, sphere_trace, sphere_trace_relaxed};

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

    /// Both streams against their scalar tracers; `omega_max` 1 is the plain march.
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
    fn every_ray_of_a_stream_takes_the_scalar_tracers_steps_plain_or_relaxed() {
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
