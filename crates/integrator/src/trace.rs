//! Tracing: where a ray first meets an object or a light, whether a shadow
//! ray is free, and the counters and timing of every ray traced.

use std::time::Instant;

use glam::Vec3;

use lueur_sdf_math::{
    DistanceField, Lane, LaneKernel, LaneVec3, MAX_LANES, Ray, SimdLevel, TraceOutcome,
    TraceParams, fill_lane_groups, sphere_trace,
};

use lueur_scene::{Light, Marching};

use crate::PreparedScene;
use crate::geometry::MarchBatch;

/// What a ray found first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hit {
    /// An object's surface at distance `t`.
    Surface {
        /// Ray parameter.
        t: f32,
        /// Index into `Scene::objects`.
        object: usize,
        /// How thick the shell the tracer stopped in is: the hit threshold in
        /// force at that distance, or, for a ray that gave up at the step cap,
        /// the field's value where it stopped if that is larger. The hit lies
        /// within it of the surface.
        epsilon: f32,
        /// Whether the ray was marched inside the solid, so that it meets the
        /// surface from inside whatever the sign of a normal estimated at a
        /// grazing hit.
        inside: bool,
    },
    /// A light's surface at distance `t`.
    Light {
        /// Ray parameter.
        t: f32,
        /// Index into `Scene::lights`.
        light: usize,
    },
}

/// Counters of one trace, for statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraceCounters {
    /// Rays traced.
    pub rays: u64,
    /// Scene evaluations (sphere-tracing steps).
    pub steps: u64,
    /// Rays that hit a surface.
    pub hits: u64,
    /// Rays that escaped.
    pub misses: u64,
    /// Rays stopped by the step cap, taken as hits where they stopped.
    pub gave_up: u64,
    /// Rays by steps taken, in powers of two: bucket `i` counts rays of
    /// `2^i ..= 2^(i+1) - 1` steps (bucket 0 also counts rays of 0 steps,
    /// the last one every ray of 512 steps or more).
    pub steps_histogram: [u64; STEP_BUCKETS],
    /// Wall time spent tracing these rays (bounds, marching, lights), in nanoseconds:
    /// every stream is timed as a whole (the clock, tens of nanoseconds a reading, is read
    /// twice per stream of many rays). Never affects the image.
    pub tracing_nanos: u64,
}

/// Buckets of [`TraceCounters::steps_histogram`].
pub const STEP_BUCKETS: usize = 10;

impl TraceCounters {
    pub(crate) fn record(&mut self, outcome: &TraceOutcome) {
        self.rays += 1;
        let steps = outcome.steps() as u64;
        self.steps += steps;
        let bucket = (u64::BITS - 1).saturating_sub(steps.max(1).leading_zeros()) as usize;
        self.steps_histogram[bucket.min(STEP_BUCKETS - 1)] += 1;
        match outcome {
            TraceOutcome::Hit { .. } => self.hits += 1,
            TraceOutcome::Miss { .. } => self.misses += 1,
            TraceOutcome::GaveUp { .. } => self.gave_up += 1,
        }
    }

    /// Wall time spent tracing the rays.
    pub fn tracing_seconds(&self) -> f64 {
        self.tracing_nanos as f64 * 1e-9
    }

    /// Rays and steps: what the time of a stream is shared by.
    pub(crate) fn work(&self) -> u64 {
        self.rays + self.steps
    }

    /// Adds the time of a stream that started at `start`.
    pub(crate) fn timed(&mut self, start: Instant) {
        self.tracing_nanos += start.elapsed().as_nanos() as u64;
    }

    /// Adds another set of counters.
    pub fn merge(&mut self, o: &TraceCounters) {
        self.rays += o.rays;
        self.tracing_nanos += o.tracing_nanos;
        self.steps += o.steps;
        self.hits += o.hits;
        self.misses += o.misses;
        self.gave_up += o.gave_up;
        for (a, b) in self.steps_histogram.iter_mut().zip(&o.steps_histogram) {
            *a += b;
        }
    }
}

/// [`TraceCounters::record`] for the rays of many vectors, each lane a ray: what a kernel
/// counts as it goes, added to the counters once at its end ([`CountLanes::add_to`]).
/// The steps are summed per lane in `f32` while every lane's sum stays below 2^23, so each
/// sum is exact, and moved to an integer before.
pub(crate) struct CountLanes<L: Lane> {
    rays: u64,
    hits: u64,
    gave_up: u64,
    steps: L,
    /// Steps moved out of `steps`.
    moved_steps: u64,
    /// Rays of at least `2^k` steps, `k` from 1.
    at_least: [u64; STEP_BUCKETS],
}

impl<L: Lane> CountLanes<L> {
    #[inline(always)]
    pub fn new() -> CountLanes<L> {
        CountLanes {
            rays: 0,
            hits: 0,
            gave_up: 0,
            steps: L::splat(0.0),
            moved_steps: 0,
            at_least: [0; STEP_BUCKETS],
        }
    }

    /// The sum of the lanes of `x`, each a whole number below 2^24.
    #[inline(always)]
    fn lane_sum(x: L) -> u64 {
        let mut lanes = [0.0f32; MAX_LANES];
        x.store(&mut lanes[..L::LANES]);
        lanes.iter().map(|&s| s as u64).sum()
    }

    /// The rays of the lanes of `rays`, each of `steps` (whole numbers), that hit (`hit`)
    /// or gave up (`gave_up`, never with `hit`) or else missed.
    #[inline(always)]
    pub fn record(&mut self, rays: L::Mask, steps: L, hit: L::Mask, gave_up: L::Mask) {
        let count = |m: L::Mask| u64::from(L::bits(m).count_ones());
        let n = count(rays);
        if n == 0 {
            return;
        }
        self.rays += n;
        self.hits += count(L::and(rays, hit));
        self.gave_up += count(L::and(rays, gave_up));
        let steps_of_rays = L::select(rays, steps, L::splat(0.0));
        let limit = L::splat(8_388_608.0);
        if L::any(steps_of_rays.ge(limit)) {
            self.moved_steps += Self::lane_sum(steps_of_rays);
        } else {
            self.steps = self.steps + steps_of_rays;
            if L::any(self.steps.ge(limit)) {
                self.moved_steps += Self::lane_sum(self.steps);
                self.steps = L::splat(0.0);
            }
        }
        let mut longer = rays;
        for k in 1..STEP_BUCKETS {
            longer = L::and(longer, steps.ge(L::splat((1u32 << k) as f32)));
            let c = count(longer);
            if c == 0 {
                break;
            }
            self.at_least[k] += c;
        }
    }

    /// Adds what was counted to `counters`.
    pub fn add_to(&self, counters: &mut TraceCounters) {
        counters.rays += self.rays;
        counters.steps += self.moved_steps + Self::lane_sum(self.steps);
        counters.hits += self.hits;
        counters.gave_up += self.gave_up;
        counters.misses += self.rays - self.hits - self.gave_up;
        let mut at_least = self.at_least;
        at_least[0] = self.rays;
        for k in 0..STEP_BUCKETS {
            let next = at_least.get(k + 1).copied().unwrap_or(0);
            counters.steps_histogram[k] += at_least[k] - next;
        }
    }
}

/// Counters per kind of ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounters {
    /// Rays from the camera.
    pub camera: TraceCounters,
    /// Rays continuing a path after a scattering event.
    pub bounce: TraceCounters,
    /// Shadow rays of next-event estimation.
    pub shadow: TraceCounters,
}

impl RayCounters {
    /// Adds another set of counters.
    pub fn merge(&mut self, o: &RayCounters) {
        self.camera.merge(&o.camera);
        self.bounce.merge(&o.bounce);
        self.shadow.merge(&o.shadow);
    }

    /// The counters of a path's ray: the camera's, or a bounce's.
    pub(crate) fn path_ray(&mut self, camera: bool) -> &mut TraceCounters {
        if camera {
            &mut self.camera
        } else {
            &mut self.bounce
        }
    }

    /// Adds the time of a stream of path rays that started at `start` to the camera's
    /// and the bounces' counters, shared by the work each kind did in it (rays and
    /// steps, from `before`, the two kinds' work when it started): one stream holds both
    /// kinds, and the clock is read once per stream.
    pub(crate) fn timed_paths(&mut self, start: Instant, before: [u64; 2]) {
        let nanos = start.elapsed().as_nanos() as u64;
        let camera = self.camera.work() - before[0];
        let bounce = self.bounce.work() - before[1];
        let to_camera = if camera + bounce == 0 {
            nanos
        } else {
            (nanos as u128 * camera as u128 / (camera + bounce) as u128) as u64
        };
        self.camera.tracing_nanos += to_camera;
        self.bounce.tracing_nanos += nanos - to_camera;
    }
}

/// A ray a path traces to its next vertex.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathRay {
    /// The ray the objects are marched along (its origin lifted off the last surface).
    pub ray: Ray,
    /// The point the ray leaves (the camera, or the last shading point), from which the
    /// lights, which are exact, are intersected.
    pub from: Vec3,
    pub params: TraceParams,
    /// Whether the ray may start inside a solid ([`PreparedScene::intersect_maybe_inside`]).
    pub maybe_inside: bool,
    /// Whether the ray leaves the camera, for the counters.
    pub camera: bool,
}

impl PathRay {
    /// A placeholder for a slot about to be written.
    pub const UNSET: PathRay = PathRay {
        ray: Ray {
            origin: Vec3::ZERO,
            dir: Vec3::Z,
        },
        from: Vec3::ZERO,
        params: TraceParams {
            t_min: 0.0,
            t_max: 0.0,
            max_steps: 0,
            eps_abs: 0.0,
            eps_rel: 0.0,
        },
        maybe_inside: false,
        camera: false,
    };
}

/// A shadow ray: is the segment from `ray.origin` along `ray.dir` free of objects and of
/// lights other than `target` up to `distance`?
#[derive(Clone, Copy, Debug)]
pub(crate) struct ShadowRay {
    pub ray: Ray,
    pub distance: f32,
    pub target: Option<usize>,
}

impl ShadowRay {
    /// A placeholder for a slot about to be written.
    pub const UNSET: ShadowRay = ShadowRay {
        ray: PathRay::UNSET.ray,
        distance: 0.0,
        target: None,
    };
}

/// How rays are traced: the marching mode, and the instruction set fast marching's
/// streams run on (every level gives the same bits).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tracing {
    pub marching: Marching,
    pub simd: SimdLevel,
}

/// A thread's buffers for tracing streams, kept from one stream to the next.
#[derive(Debug, Default)]
pub(crate) struct TraceScratch {
    batch: MarchBatch,
    /// Per path ray: its parameters as marched, and whether it was marched inside.
    marched: Vec<(TraceParams, bool)>,
    /// Per path ray, the nearest light it meets before its far limit, from [`LightTests`]:
    /// its `t` and its index, or a negative index for none.
    light_hits: Vec<(f32, f32)>,
    /// [`LightTests`]' rays as rows of lanes ([`LIGHT_ROWS`]).
    light_rows: Vec<[[f32; MAX_LANES]; LIGHT_ROWS]>,
}

/// Rows of a group of rays in [`TraceScratch::light_rows`]: the point the ray leaves, its
/// direction, its far limit.
const LIGHT_ROWS: usize = 7;

/// The kernel that finds the nearest light each path ray meets from the point it leaves,
/// before its far limit: [`PreparedScene::intersect_lights`] for a vector of rays at once,
/// the same answer in each lane (each light's test is written once over lanes, and the
/// nearest is taken in the same order, the first of equals kept).
struct LightTests<'a> {
    lights: &'a [Light],
    rays: &'a [PathRay],
    rows: &'a mut Vec<[[f32; MAX_LANES]; LIGHT_ROWS]>,
    hits: &'a mut Vec<(f32, f32)>,
}

impl LaneKernel for LightTests<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(self) {
        let lanes = L::LANES.min(MAX_LANES);
        let records = self.rays.iter().map(|r| {
            [
                r.from.x,
                r.from.y,
                r.from.z,
                r.ray.dir.x,
                r.ray.dir.y,
                r.ray.dir.z,
                r.params.t_max,
            ]
        });
        fill_lane_groups(records, lanes, self.rows);
        let (mut ts, mut lights) = ([0f32; MAX_LANES], [0f32; MAX_LANES]);
        for (v, rays) in self.rows.iter().zip(self.rays.chunks(lanes)) {
            let row = |i: usize| -> L { L::load(&v[i][..lanes]) };
            let from = LaneVec3::new(row(0), row(1), row(2));
            let dir = LaneVec3::new(row(3), row(4), row(5));
            let t_max = row(6);
            let (best_t, best, _) = nearest_light_lanes(self.lights, from, dir, t_max);
            best_t.store(&mut ts[..lanes]);
            best.store(&mut lights[..lanes]);
            self.hits
                .extend((0..rays.len()).map(|lane| (ts[lane], lights[lane])));
        }
    }
}

/// The nearest of `lights` each lane's ray meets from `from` along `dir` before `t_max`:
/// its `t`, its index (-1 for none) and the lanes that meet one, the lights tested in
/// order and the first of equals kept, each as [`PreparedScene::intersect_lights`] finds it
/// (each light's test is written once over lanes). The one definition for [`LightTests`]
/// and the lane wave's path rays.
#[inline(always)]
pub(crate) fn nearest_light_lanes<L: Lane>(
    lights: &[Light],
    from: LaneVec3<L>,
    dir: LaneVec3<L>,
    t_max: L,
) -> (L, L, L::Mask) {
    let (mut best_t, mut best) = (L::splat(0.0), L::splat(-1.0));
    let mut found = L::splat(0.0).gt(L::splat(0.0));
    for (i, light) in lights.iter().enumerate() {
        let (t, meets) = light.intersect_lanes(from, dir);
        let nearer = L::and(
            L::and(meets, t_max.gt(t)),
            L::not(L::and(found, L::not(best_t.gt(t)))),
        );
        best_t = L::select(nearer, t, best_t);
        best = L::select(nearer, L::splat(i as f32), best);
        found = L::or(found, nearer);
    }
    (best_t, best, found)
}

impl PreparedScene {
    /// Finds the first object or light along `ray`.
    pub fn intersect(
        &self,
        ray: &Ray,
        params: &TraceParams,
        marching: Marching,
        counters: &mut TraceCounters,
    ) -> Option<Hit> {
        self.intersect_one(ray, params, marching, counters, false)
    }

    /// [`PreparedScene::intersect`] for a ray that may start inside a solid: a
    /// camera ray, or a ray leaving a surface that was shaded on its inside.
    /// If its origin is below a surface (not merely in its shell), the ray
    /// is marched by the negated field to the wall it leaves through, so
    /// that a camera inside an object sees the inner wall and paths there
    /// stay inside. Costs one field evaluation.
    ///
    /// Other rays never do this: a secondary origin a hair under a surface
    /// is rounding, which the projection at the next vertex repairs.
    pub fn intersect_maybe_inside(
        &self,
        ray: &Ray,
        params: &TraceParams,
        marching: Marching,
        counters: &mut TraceCounters,
    ) -> Option<Hit> {
        self.intersect_one(ray, params, marching, counters, true)
    }

    fn intersect_one(
        &self,
        ray: &Ray,
        params: &TraceParams,
        marching: Marching,
        counters: &mut TraceCounters,
        maybe_inside: bool,
    ) -> Option<Hit> {
        let path_ray = PathRay {
            ray: *ray,
            from: ray.origin,
            params: *params,
            maybe_inside,
            camera: true,
        };
        let tracing = Tracing {
            marching,
            simd: SimdLevel::Scalar,
        };
        let mut hits = Vec::with_capacity(1);
        let scratch = &mut TraceScratch::default();
        let mut kinds = RayCounters::default();
        self.intersect_rays(&[path_ray], tracing, &mut kinds, scratch, &mut hits);
        counters.merge(&kinds.camera);
        hits[0]
    }

    /// What each of `rays` finds first, into `hits` (cleared first), as
    /// [`PreparedScene::intersect`] or [`PreparedScene::intersect_maybe_inside`] find it for
    /// the ray alone: the objects are marched from `ray.origin`, lifted off the surface
    /// so that the march does not stop on it at once, but the lights, which are exact,
    /// are intersected from `from` itself. So a light is seen under the solid angle it has
    /// from the point that was shaded, the one next-event estimation and the MIS weights
    /// use, however far the origin had to be lifted; light hits' `t` are measured from
    /// `from`. Fast marching marches the rays as one stream.
    pub(crate) fn intersect_rays(
        &self,
        rays: &[PathRay],
        tracing: Tracing,
        counters: &mut RayCounters,
        scratch: &mut TraceScratch,
        hits: &mut Vec<Option<Hit>>,
    ) {
        let clock = Instant::now();
        let before = [counters.camera.work(), counters.bounce.work()];
        hits.clear();
        scratch.batch.clear();
        scratch.marched.clear();
        let has_objects = !self.scene().objects.is_empty();
        let lights = &self.scene().lights;
        scratch.light_hits.clear();
        if !lights.is_empty() {
            // The level is available: `or_widest` says so.
            let _ = tracing.simd.or_widest().dispatch(LightTests {
                lights,
                rays,
                rows: &mut scratch.light_rows,
                hits: &mut scratch.light_hits,
            });
        }
        for (i, r) in rays.iter().enumerate() {
            let params = r.params.resolving(r.ray.origin);
            let light_hit = match scratch.light_hits.get(i) {
                Some(&(t, light)) if light >= 0.0 => Some((t, light as usize)),
                _ => None,
            };
            hits.push(light_hit.map(|(t, light)| Hit::Light { t, light }));
            let p = TraceParams {
                t_max: light_hit.map_or(params.t_max, |(t, _)| t),
                ..params
            };
            let inside = has_objects
                && r.maybe_inside
                && self.distance(r.ray.at(p.t_min), tracing.marching)
                    < -p.eps_abs.max(p.eps_rel * p.t_min);
            scratch.marched.push((p, inside));
            if !has_objects {
                counters.path_ray(r.camera).rays += 1;
                continue;
            }
            // The rare paths take a copy by reference, so that `p` itself stays in
            // registers: built in memory a field at a time and copied whole into the
            // queues, it makes every ray wait for its stores (docs/PERFORMANCE.md, "Stores
            // loaded whole").
            let done = if inside {
                let copy = p;
                Some((sphere_trace(&self.geometry.inside(), &r.ray, &copy), None))
            } else if tracing.marching == Marching::Naive {
                let copy = p;
                Some(self.geometry.trace_naive(&r.ray, &copy))
            } else {
                scratch.batch.queue(i, r.ray, p);
                None
            };
            if let Some((outcome, object)) = done {
                counters.path_ray(r.camera).record(&outcome);
                let (p, inside) = scratch.marched[i];
                hits[i] = self
                    .surface_hit(&r.ray, &p, inside, outcome, object)
                    .or(hits[i]);
            }
        }
        self.geometry.march(tracing.simd, &mut scratch.batch);
        for (i, outcome, object) in scratch.batch.results() {
            counters.path_ray(rays[i].camera).record(&outcome);
            let (p, inside) = scratch.marched[i];
            hits[i] = self
                .surface_hit(&rays[i].ray, &p, inside, outcome, object)
                .or(hits[i]);
        }
        counters.timed_paths(clock, before);
    }

    /// The surface a march of `ray` with parameters `params` found, if any. Inlined: its
    /// result, returned through memory, is loaded whole before its stores retire.
    #[inline(always)]
    pub(crate) fn surface_hit(
        &self,
        ray: &Ray,
        p: &TraceParams,
        inside: bool,
        outcome: TraceOutcome,
        object: Option<usize>,
    ) -> Option<Hit> {
        let (t, gave_up) = match outcome {
            // A ray that reaches the step cap without a decision is crawling along a
            // surface it is about to meet (inside a closed solid, its wall), so it
            // stops where it is. Measured on the shipped scenes against a cap 64 times
            // higher (`cargo xtask scale`, docs/SCALE.md): this changes the Death
            // Star's image mean by -0.002%, taking it as a miss by -0.23% (it sees the
            // sky through a wall) and ending the path by -0.37%.
            TraceOutcome::GaveUp { t, steps } if steps > 0 => (t, true),
            _ => (outcome.hit_t()?, false),
        };
        let object = object.unwrap_or_else(|| self.closest_object(ray.at(t)));
        let mut epsilon = p.eps_abs.max(p.eps_rel * t);
        if gave_up {
            // One evaluation, on the rare ray that gave up: where it stopped
            // may be farther from the surface than a hit threshold.
            let f = self.geometry.prepared(object).distance(ray.at(t)).abs();
            if f.is_finite() {
                epsilon = epsilon.max(f);
            }
        }
        Some(Hit::Surface {
            t,
            object,
            epsilon,
            inside,
        })
    }

    /// Whether each of `rays` is free, into `free` (cleared first), every ray traced
    /// with `params`; fast marching marches them as one stream.
    pub(crate) fn unoccluded_rays(
        &self,
        rays: &[ShadowRay],
        params: &TraceParams,
        tracing: Tracing,
        counters: &mut TraceCounters,
        scratch: &mut TraceScratch,
        free: &mut Vec<bool>,
    ) {
        let clock = Instant::now();
        free.clear();
        scratch.batch.clear();
        for (i, r) in rays.iter().enumerate() {
            // By value, not by reference, for the reason given in `intersect_rays`.
            let params = params.resolving(r.ray.origin);
            // Stop short of the light's surface so that its own geometry (for
            // lights that are objects too) does not occlude it.
            let t_max = (r.distance * (1.0 - 1e-4) - params.eps_abs).min(params.t_max);
            let blocked = self
                .intersect_lights(r.ray, t_max, r.target)
                .is_some_and(|(_, l)| Some(l) != r.target);
            free.push(!blocked);
            if blocked || self.scene().objects.is_empty() || t_max <= params.t_min {
                continue;
            }
            let p = TraceParams { t_max, ..params };
            match tracing.marching {
                Marching::Naive => {
                    let copy = p;
                    let outcome = self.geometry.trace_naive(&r.ray, &copy).0;
                    counters.record(&outcome);
                    free[i] = matches!(outcome, TraceOutcome::Miss { .. });
                }
                Marching::Fast => scratch.batch.queue(i, r.ray, p),
            }
        }
        self.geometry.march(tracing.simd, &mut scratch.batch);
        for (i, outcome, _) in scratch.batch.results() {
            counters.record(&outcome);
            // A shadow ray that gives up is taken as a hit too (see `surface_hit`).
            free[i] = matches!(outcome, TraceOutcome::Miss { .. });
        }
        counters.timed(clock);
    }

    /// The nearest light `ray` meets before `t_max`, other than `skip`. The ray by value
    /// and the lights' tests inlined: a ray passed by reference is stored in pieces and
    /// loaded whole, and the load waits for the stores to retire.
    #[inline(always)]
    fn intersect_lights(&self, ray: Ray, t_max: f32, skip: Option<usize>) -> Option<(f32, usize)> {
        let mut best: Option<(f32, usize)> = None;
        for (i, l) in self.scene().lights.iter().enumerate() {
            if Some(i) == skip {
                continue;
            }
            let t = l.intersect(&ray);
            if let Some(t) = t
                && t < t_max
                && best.is_none_or(|(bt, _)| t < bt)
            {
                best = Some((t, i));
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::tests::{crowd, points};
    use lueur_materials::Material;
    use lueur_scene::{Camera, Scene};

    /// [`crate::geometry::tests::crowd`] as a scene.
    fn crowd_scene() -> PreparedScene {
        let camera = Camera::new(Vec3::new(0.0, 0.5, 6.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap();
        let white = Material::Lambertian { albedo: Vec3::ONE };
        Scene::new(crowd(), vec![white], vec![], None, camera)
            .unwrap()
            .into()
    }

    /// Rays counted a vector at a time are the counts of each ray recorded alone, on every
    /// level, with steps in every bucket and every outcome.
    #[test]
    fn rays_counted_in_lanes_are_each_ray_s_record() {
        struct Count<'a>(&'a [(u32, u8)], &'a mut TraceCounters);
        impl LaneKernel for Count<'_> {
            type Output = ();
            fn run<L: Lane>(self) {
                let mut lanes = CountLanes::<L>::new();
                for chunk in self.0.chunks(L::LANES) {
                    let mut rows = [[0.0f32; MAX_LANES]; 4];
                    for (j, &(steps, kind)) in chunk.iter().enumerate() {
                        rows[0][j] = 1.0;
                        rows[1][j] = steps as f32;
                        rows[2][j] = f32::from(kind == 0);
                        rows[3][j] = f32::from(kind == 1);
                    }
                    let [rays, steps, hit, gave_up] = rows.map(|r| L::load(&r[..L::LANES]));
                    let half = L::splat(0.5);
                    lanes.record(rays.gt(half), steps, hit.gt(half), gave_up.gt(half));
                }
                lanes.add_to(self.1);
            }
        }
        // Every bucket, and sums past what an f32 holds exactly (2^24).
        let rays: Vec<(u32, u8)> = (0..300u32)
            .map(|i| (((i * 7919) % 1500) >> (i % 11), (i % 3) as u8))
            .chain((0..40u32).map(|i| ((3 << 21) + 2 * i + 1, (i % 3) as u8)))
            .collect();
        let mut alone = TraceCounters::default();
        for &(steps, kind) in &rays {
            alone.record(&match kind {
                0 => TraceOutcome::Hit { t: 1.0, steps },
                1 => TraceOutcome::GaveUp { t: 1.0, steps },
                _ => TraceOutcome::Miss { steps },
            });
        }
        assert!(alone.steps_histogram.iter().all(|&n| n > 0));
        for level in SimdLevel::available() {
            let mut counted = TraceCounters::default();
            level.dispatch(Count(&rays, &mut counted)).unwrap();
            assert_eq!(counted, alone, "{level:?}");
        }
    }

    #[test]
    fn fast_marching_finds_the_naive_hits() {
        let scene = crowd_scene();
        let params = TraceParams {
            t_max: 200.0,
            max_steps: 100_000,
            eps_abs: 1e-6,
            eps_rel: 1e-5,
            ..TraceParams::default()
        };
        let (mut naive_steps, mut fast_steps) =
            (TraceCounters::default(), TraceCounters::default());
        for (i, p) in points().enumerate() {
            let origin = Vec3::new(0.0, 0.5, 6.0) + Vec3::Y * (i % 3) as f32;
            let ray = Ray::new(origin, p * 0.1 - origin);
            let a = scene.intersect(&ray, &params, Marching::Naive, &mut naive_steps);
            let b = scene.intersect(&ray, &params, Marching::Fast, &mut fast_steps);
            match (a, b) {
                (None, None) => {}
                (
                    Some(Hit::Surface {
                        t: ta, object: oa, ..
                    }),
                    Some(Hit::Surface {
                        t: tb, object: ob, ..
                    }),
                ) => {
                    assert_eq!(oa, ob, "ray {ray:?}: objects {oa} and {ob} at {ta}, {tb}");
                    assert!(
                        (ta - tb).abs() <= 1e-3 * ta,
                        "ray {ray:?}: naive {ta}, fast {tb}"
                    );
                }
                _ => panic!("ray {ray:?}: naive {a:?}, fast {b:?}"),
            }
        }
        assert!(fast_steps.steps < naive_steps.steps);
    }
}
