//! The scene as the integrator sees it: SDF objects with materials, lights,
//! an optional sky, and the queries the estimators need.

use glam::{Vec2, Vec3};
use lueur_materials::Material;
use lueur_sampling::{
    DirectionSample, DiscreteDistribution, Frame, cosine_hemisphere_pdf, quad_area_pdf,
    quad_solid_angle_pdf, sample_cosine_hemisphere, sample_quad_area, sample_quad_solid_angle,
    sample_sphere_light, sphere_light_pdf,
};
use std::cell::Cell;
use std::time::Instant;

use lueur_sdf_math::{
    Aabb, DistanceField, HalfSpace, OVER_RELAXATION, PreparedSdf, Ray, RayClip, Sdf, TraceOutcome,
    TraceParams, sphere_trace, sphere_trace_relaxed,
};
use smallvec::SmallVec;

use crate::{Camera, SceneError};

/// One piece of geometry and what it is made of.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Its shape.
    pub sdf: Sdf,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

/// A light source. Sphere and quad lights are also visible geometry (they
/// are intersected analytically, which is exact and cheaper than marching a
/// zero-thickness quad); directional lights are not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// A sphere emitting `radiance` outward from its surface.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius (> 0).
        radius: f32,
        /// Emitted radiance.
        radiance: Vec3,
    },
    /// A parallelogram `corner + s edge_u + t edge_v`, emitting on the side
    /// of `edge_u x edge_v`.
    Quad {
        /// One corner.
        corner: Vec3,
        /// First edge.
        edge_u: Vec3,
        /// Second edge.
        edge_v: Vec3,
        /// Emitted radiance.
        radiance: Vec3,
    },
    /// A light at infinity: parallel rays travelling along `direction`.
    Directional {
        /// Unit direction in which the light travels.
        direction: Vec3,
        /// Irradiance received by a surface facing the light.
        irradiance: Vec3,
    },
}

impl Light {
    /// Whether the light is a delta distribution in direction, reachable only
    /// by next-event estimation.
    pub fn is_delta(&self) -> bool {
        matches!(self, Light::Directional { .. })
    }
}

/// How quad lights are sampled toward a shading point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum QuadSampling {
    /// Uniform on the area, converted to solid angle (pdf d^2 / (cos a * A)),
    /// as in the student report.
    Area,
    /// Uniform in the solid angle the rectangle subtends (Urena et al.
    /// 2013); falls back to area sampling for non-rectangular parallelograms.
    #[default]
    SolidAngle,
}

/// How rays are marched through the objects.
///
/// Both modes find the same surfaces (tests hold them to it); `Naive` is kept as the
/// reference every speed-up is measured against, in the same run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Marching {
    /// Plain Hart sphere tracing on the plain union of the objects: every step evaluates
    /// every object; normals by central differences.
    Naive,
    /// Each ray first clipped against every object's bound (a box, or a half-space for
    /// planes): objects whose bound the ray never comes within the hit threshold of are left
    /// out of its march altogether, and the march runs only over the part of the ray some
    /// bound covers. Then over-relaxed sphere tracing (Keinert et al. 2014) on the union of
    /// what is left, where an object whose box is farther than the nearest object found so
    /// far costs one distance to a box, not its own evaluation. The object hit is the one
    /// the last step found nearest (no second pass over the scene); normals by the
    /// tetrahedron (4 evaluations, not 6).
    #[default]
    Fast,
}

/// A complete scene, ready to render.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Geometry.
    pub objects: Vec<Object>,
    /// Materials referenced by the objects.
    pub materials: Vec<Material>,
    /// Light sources.
    pub lights: Vec<Light>,
    /// Constant radiance arriving from every direction a ray escapes to.
    pub sky: Option<Vec3>,
    /// The viewpoint.
    pub camera: Camera,
    /// How quad lights are sampled.
    pub quad_sampling: QuadSampling,
    /// How rays are marched through the objects.
    pub marching: Marching,
    // Derived at construction.
    geometry: Geometry,
    /// Which samplable emitters exist: indices into `lights`, then the sky.
    emitters: Vec<Emitter>,
    emitter_choice: Option<DiscreteDistribution>,
    size: f32,
}

/// An emitter that light sampling can choose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Emitter {
    Light(usize),
    Sky,
}

/// The union of the objects, as a field the tracer marches.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Geometry {
    sdfs: Vec<Sdf>,
    lipschitz: f32,
    /// Per object: what a ray is clipped against before it is marched.
    bounds: Vec<ObjectBound>,
    /// Per object: its transforms folded into one affine map, for fast marching.
    prepared: Vec<PreparedSdf>,
    /// Objects evaluated at every point: those without a bounding sphere (planes) and
    /// those no dearer than their bound (spheres), first, so that the running minimum is
    /// small before the culled objects are reached.
    always: Vec<usize>,
    /// The other objects with their bounding spheres, in scene order.
    culled: Vec<Bounded>,
}

/// What a ray is clipped against for one object (see [`Marching::Fast`]).
#[derive(Clone, Copy, Debug, PartialEq)]
enum ObjectBound {
    /// The object's bounding box; `cull` when checking the box is cheaper than evaluating
    /// the object (not for boxes and spheres, whose box check costs as much as they do).
    Box { aabb: Aabb, cull: bool },
    /// Planes and what is cut from them.
    HalfSpace(HalfSpace),
    /// Nothing known: the object takes part in every march.
    Everywhere,
}

impl ObjectBound {
    fn of(sdf: &Sdf) -> ObjectBound {
        if let Some(aabb) = sdf.bounding_box() {
            let cull = !is_sphere(sdf) && !is_box(sdf);
            ObjectBound::Box { aabb, cull }
        } else if let Some(h) = sdf.bounding_half_space() {
            ObjectBound::HalfSpace(h)
        } else {
            ObjectBound::Everywhere
        }
    }
}

/// One object a ray may hit, and from where along it. Small, so that a ray's list is
/// cheap to build, sort and move.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    object: u32,
    t0: f32,
}

/// The union of the objects one ray can hit ([`Marching::Fast`]), nearest entry first, and
/// which of them the last evaluation found nearest.
///
/// Sphere tracing this field finds the same surface as tracing the whole union: an object
/// left out has no point within the hit threshold on the marched range (its bound's
/// contract, [`Aabb::hit_interval`]), so the whole union's march could not stop on it
/// either, and the objects kept are evaluated exactly. Steps are longer, since the objects
/// left out no longer shorten them: that is the point.
struct RayField<'a> {
    geometry: &'a Geometry,
    candidates: SmallVec<[Candidate; 16]>,
    nearest: Cell<u32>,
}

impl<'a> RayField<'a> {
    /// The candidates of `ray` and the range of `t` to march, `None` when no object can be
    /// hit.
    fn new(geometry: &'a Geometry, ray: &Ray, params: &TraceParams) -> (Self, Option<(f32, f32)>) {
        let mut candidates = SmallVec::new();
        let mut range: Option<(f32, f32)> = None;
        let clip = RayClip::new(ray, params);
        for (object, bound) in geometry.bounds.iter().enumerate() {
            let interval = match bound {
                ObjectBound::Box { aabb, .. } => clip.clip_box(aabb),
                ObjectBound::HalfSpace(h) => clip.clip_half_space(h),
                ObjectBound::Everywhere => Some((params.t_min, params.t_max)),
            };
            let Some((t0, t1)) = interval else {
                continue;
            };
            range = Some(range.map_or((t0, t1), |(a, b)| (a.min(t0), b.max(t1))));
            candidates.push(Candidate {
                object: object as u32,
                t0,
            });
        }
        // Nearest first: the running minimum is small early, so later boxes cull.
        candidates.sort_unstable_by(|a: &Candidate, b: &Candidate| a.t0.total_cmp(&b.t0));
        let field = RayField {
            geometry,
            candidates,
            nearest: Cell::new(0),
        };
        (field, range)
    }

    /// The object the last evaluation found nearest: after a hit, the one that was hit.
    fn nearest(&self) -> usize {
        self.nearest.get() as usize
    }
}

impl DistanceField for RayField<'_> {
    #[inline]
    fn distance(&self, p: Vec3) -> f32 {
        let mut d = f32::INFINITY;
        let mut nearest = self.candidates.first().map_or(0, |c| c.object);
        for c in &self.candidates {
            // The box is at most as far as the object (its contract): when it is already
            // farther than the running minimum, the object cannot lower it.
            if let ObjectBound::Box { aabb, cull: true } = &self.geometry.bounds[c.object as usize]
                && d > 0.0
                && aabb.distance_squared(p) >= d * d
            {
                continue;
            }
            let f = self.geometry.prepared[c.object as usize].distance(p);
            if f < d {
                d = f;
                nearest = c.object;
            }
        }
        self.nearest.set(nearest);
        d
    }

    fn lipschitz(&self) -> f32 {
        self.geometry.lipschitz
    }
}

/// An object with its bounding sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bounded {
    center: Vec3,
    radius: f32,
    object: usize,
}

impl Geometry {
    fn new(objects: &[Object]) -> Geometry {
        let lipschitz = objects
            .iter()
            .map(|o| o.sdf.lipschitz())
            .fold(1.0f32, f32::max);
        let mut always = Vec::new();
        let mut culled = Vec::new();
        for (object, o) in objects.iter().enumerate() {
            match o.sdf.bounding_sphere() {
                Some((center, radius)) if !is_sphere(&o.sdf) => culled.push(Bounded {
                    center,
                    radius,
                    object,
                }),
                _ => always.push(object),
            }
        }
        Geometry {
            sdfs: objects.iter().map(|o| o.sdf.clone()).collect(),
            lipschitz,
            bounds: objects.iter().map(|o| ObjectBound::of(&o.sdf)).collect(),
            prepared: objects.iter().map(|o| PreparedSdf::new(&o.sdf)).collect(),
            always,
            culled,
        }
    }

    /// The plain union: every object, every time.
    #[inline]
    fn distance_naive(&self, p: Vec3) -> f32 {
        let mut d = f32::INFINITY;
        for sdf in &self.sdfs {
            d = d.min(sdf.distance(p));
        }
        d
    }

    /// The same value with bounding-sphere culling. Every `Sdf` honours its bounding
    /// sphere (`f(p) >= |p - c| - r`, a conformance test of `lueur-sdf-math`), so an object
    /// with `|p - c| - r >= d`, the running minimum, cannot lower it and is skipped: the
    /// result is the plain union's minimum, not an approximation of it, and therefore
    /// Lipschitz with the same bound.
    #[inline]
    fn distance_culled(&self, p: Vec3) -> f32 {
        let mut d = f32::INFINITY;
        for &i in &self.always {
            d = d.min(self.sdfs[i].distance(p));
        }
        for b in &self.culled {
            // |p - c| - r >= d without a square root: always true when r + d <= 0.
            let reach = b.radius + d;
            if reach <= 0.0 || (p - b.center).length_squared() >= reach * reach {
                continue;
            }
            d = d.min(self.sdfs[b.object].distance(p));
        }
        d
    }
}

/// Whether the shape is a sphere, possibly moved: its bounding sphere is the shape itself,
/// so checking the bound would cost as much as evaluating it.
fn is_sphere(sdf: &Sdf) -> bool {
    match sdf {
        Sdf::Sphere { .. } => true,
        Sdf::Translate { child, .. } => is_sphere(child),
        _ => false,
    }
}

/// Whether the shape is a box, possibly moved: its bounding box is the shape itself.
fn is_box(sdf: &Sdf) -> bool {
    match sdf {
        Sdf::Box { .. } => true,
        Sdf::Translate { child, .. } => is_box(child),
        _ => false,
    }
}

/// [`Geometry`] as the plain union, for naive marching.
struct Naive<'a>(&'a Geometry);

impl DistanceField for Naive<'_> {
    #[inline]
    fn distance(&self, p: Vec3) -> f32 {
        self.0.distance_naive(p)
    }

    fn lipschitz(&self) -> f32 {
        self.0.lipschitz
    }
}

/// The inside of [`Geometry`]: the negated field, whose zero set is the
/// same surface and which is positive inside objects, so the tracer can
/// march a ray that starts inside a solid to the wall it leaves through.
struct Inside<'a>(&'a Geometry);

impl DistanceField for Inside<'_> {
    #[inline]
    fn distance(&self, p: Vec3) -> f32 {
        -self.0.distance_naive(p)
    }

    fn lipschitz(&self) -> f32 {
        self.0.lipschitz
    }
}

/// What a ray found first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hit {
    /// An object's surface at distance `t`.
    Surface {
        /// Ray parameter.
        t: f32,
        /// Index into [`Scene::objects`].
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
        /// Index into [`Scene::lights`].
        light: usize,
    },
}

/// A direction toward an emitter with the radiance it brings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct EmitterSample {
    pub wi: Vec3,
    pub distance: f32,
    pub radiance: Vec3,
    /// Solid-angle pdf including the probability of choosing this emitter.
    pub pdf: f32,
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
    /// Rays whose tracing was timed: one in [`TIMED_EVERY`], so that the
    /// clock (tens of nanoseconds a reading) costs well under 1% of a render.
    pub timed_rays: u64,
    /// Wall time spent tracing the timed rays (bounds, marching, lights), in
    /// nanoseconds. Never affects the image.
    pub timed_nanos: u64,
}

/// One ray in this many is timed (see [`TraceCounters::timed_nanos`]); a
/// power of two.
pub const TIMED_EVERY: u64 = 16;

/// Buckets of [`TraceCounters::steps_histogram`].
pub const STEP_BUCKETS: usize = 10;

impl TraceCounters {
    fn record(&mut self, outcome: &TraceOutcome) {
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

    /// Estimated wall time spent tracing every ray: the timed rays' time
    /// scaled by the share they are of all rays.
    pub fn tracing_seconds(&self) -> f64 {
        if self.timed_rays == 0 {
            return 0.0;
        }
        self.timed_nanos as f64 * 1e-9 * self.rays as f64 / self.timed_rays as f64
    }

    /// Starts the clock if this ray is one of the timed ones (decided by
    /// the ray count, so deterministically and evenly spread).
    #[inline]
    fn clock(&self) -> Option<Instant> {
        // A mask, not `is_multiple_of` (Rust 1.87; the workspace supports 1.85).
        (self.rays & (TIMED_EVERY - 1) == 0).then(Instant::now)
    }

    #[inline]
    fn stop(&mut self, clock: Option<Instant>) {
        if let Some(start) = clock {
            self.timed_rays += 1;
            self.timed_nanos += start.elapsed().as_nanos() as u64;
        }
    }

    /// Adds another set of counters.
    pub fn merge(&mut self, o: &TraceCounters) {
        self.rays += o.rays;
        self.timed_rays += o.timed_rays;
        self.timed_nanos += o.timed_nanos;
        self.steps += o.steps;
        self.hits += o.hits;
        self.misses += o.misses;
        self.gave_up += o.gave_up;
        for (a, b) in self.steps_histogram.iter_mut().zip(&o.steps_histogram) {
            *a += b;
        }
    }
}

impl Scene {
    /// Assembles and validates a scene.
    pub fn new(
        objects: Vec<Object>,
        materials: Vec<Material>,
        lights: Vec<Light>,
        sky: Option<Vec3>,
        camera: Camera,
    ) -> Result<Scene, SceneError> {
        for (i, o) in objects.iter().enumerate() {
            if o.material >= materials.len() {
                return Err(SceneError::MissingMaterial {
                    object: i,
                    material: o.material,
                });
            }
        }
        for (i, l) in lights.iter().enumerate() {
            let ok = match *l {
                Light::Sphere {
                    center,
                    radius,
                    radiance,
                } => {
                    center.is_finite() && radius > 0.0 && radius.is_finite() && valid_rgb(radiance)
                }
                Light::Quad {
                    corner,
                    edge_u,
                    edge_v,
                    radiance,
                } => {
                    corner.is_finite() && edge_u.cross(edge_v).length() > 0.0 && valid_rgb(radiance)
                }
                Light::Directional {
                    direction,
                    irradiance,
                } => {
                    direction.is_finite()
                        && (direction.length() - 1.0).abs() < 1e-3
                        && valid_rgb(irradiance)
                }
            };
            if !ok {
                return Err(SceneError::InvalidLight(i));
            }
        }
        if let Some(sky) = sky
            && !valid_rgb(sky)
        {
            return Err(SceneError::InvalidSky);
        }
        let geometry = Geometry::new(&objects);

        let mut emitters: Vec<Emitter> = lights
            .iter()
            .enumerate()
            .filter(|(_, l)| !l.is_delta())
            .map(|(i, _)| Emitter::Light(i))
            .collect();
        if sky.is_some() {
            emitters.push(Emitter::Sky);
        }
        // Uniform choice: power-proportional choice needs the sky's power,
        // which depends on the scene's extent; measured first, changed later.
        let emitter_choice = DiscreteDistribution::uniform(emitters.len());

        // The radius of a box around camera, bounded objects and lights:
        // only the far limit follows it (hit thresholds and spawn offsets
        // are local to each ray and hit, see `path::March`).
        let mut lo = camera.position();
        let mut hi = lo;
        let mut include = |c: Vec3, r: f32| {
            lo = lo.min(c - Vec3::splat(r));
            hi = hi.max(c + Vec3::splat(r));
        };
        for o in &objects {
            if let Some((c, r)) = o.sdf.bounding_sphere() {
                include(c, r);
            }
        }
        for l in &lights {
            match *l {
                Light::Sphere { center, radius, .. } => include(center, radius),
                Light::Quad {
                    corner,
                    edge_u,
                    edge_v,
                    ..
                } => {
                    include(corner, 0.0);
                    include(corner + edge_u + edge_v, 0.0);
                }
                Light::Directional { .. } => {}
            }
        }
        let positive_or_one = |v: f32| if v.is_finite() && v > 0.0 { v } else { 1.0 };
        let size = positive_or_one(0.5 * (hi - lo).length());

        Ok(Scene {
            objects,
            materials,
            lights,
            sky,
            camera,
            quad_sampling: QuadSampling::default(),
            marching: Marching::default(),
            geometry,
            emitters,
            emitter_choice,
            size,
        })
    }

    /// The scene's own length scale: the radius of a box around the camera,
    /// the bounded objects and the lights. The far limit of rays is
    /// proportional to it, and nothing else: no tolerance that decides where
    /// a ray starts or stops depends on the size of the whole scene.
    pub fn scale(&self) -> f32 {
        self.size
    }

    /// The union of all objects as a distance field, evaluated as [`Scene::marching`]
    /// says (both modes give the same value).
    pub fn distance(&self, p: Vec3) -> f32 {
        match self.marching {
            Marching::Naive => self.geometry.distance_naive(p),
            Marching::Fast => self.geometry.distance_culled(p),
        }
    }

    /// Marches `ray` through the objects as [`Scene::marching`] says; with a hit, the
    /// object hit.
    fn trace(&self, ray: &Ray, params: &TraceParams) -> (TraceOutcome, Option<usize>) {
        match self.marching {
            Marching::Naive => {
                let outcome = sphere_trace(&Naive(&self.geometry), ray, params);
                let object = outcome.hit_t().map(|t| self.closest_object(ray.at(t)));
                (outcome, object)
            }
            Marching::Fast => {
                let (field, range) = RayField::new(&self.geometry, ray, params);
                let Some((t_min, t_max)) = range else {
                    return (TraceOutcome::Miss { steps: 0 }, None);
                };
                let clipped = TraceParams {
                    t_min,
                    t_max,
                    ..*params
                };
                let outcome = sphere_trace_relaxed(&field, ray, &clipped, OVER_RELAXATION);
                let object = match outcome {
                    TraceOutcome::Miss { .. } => None,
                    TraceOutcome::Hit { .. } | TraceOutcome::GaveUp { .. } => Some(field.nearest()),
                };
                (outcome, object)
            }
        }
    }

    /// Object `i`'s field as fast marching evaluates it (its transforms folded).
    pub(crate) fn prepared(&self, i: usize) -> &PreparedSdf {
        &self.geometry.prepared[i]
    }

    /// The object closest to `p` (after a hit, the one that was hit).
    pub fn closest_object(&self, p: Vec3) -> usize {
        let mut best = (f32::INFINITY, 0);
        for (i, sdf) in self.geometry.sdfs.iter().enumerate() {
            let d = sdf.distance(p);
            if d < best.0 {
                best = (d, i);
            }
        }
        best.1
    }

    /// Finds the first object or light along `ray`.
    pub fn intersect(
        &self,
        ray: &Ray,
        params: &TraceParams,
        counters: &mut TraceCounters,
    ) -> Option<Hit> {
        self.intersect_ray(ray, ray.origin, params, counters, false)
    }

    /// [`Scene::intersect`] for a ray that may start inside a solid: a
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
        counters: &mut TraceCounters,
    ) -> Option<Hit> {
        self.intersect_ray(ray, ray.origin, params, counters, true)
    }

    /// [`Scene::intersect`] (or, with `maybe_inside`, [`Scene::intersect_maybe_inside`])
    /// for a ray leaving the surface point `from`: the objects are marched from
    /// `ray.origin`, lifted off the surface so that the march does not stop on it at once,
    /// but the lights, which are exact, are intersected from `from` itself. So a light is
    /// seen under the solid angle it has from the point that was shaded, the one next-event
    /// estimation and the MIS weights use, however far the origin had to be lifted; light
    /// hits' `t` are measured from `from`.
    pub(crate) fn intersect_leaving(
        &self,
        ray: &Ray,
        from: Vec3,
        params: &TraceParams,
        counters: &mut TraceCounters,
        maybe_inside: bool,
    ) -> Option<Hit> {
        self.intersect_ray(ray, from, params, counters, maybe_inside)
    }

    fn intersect_ray(
        &self,
        ray: &Ray,
        from: Vec3,
        params: &TraceParams,
        counters: &mut TraceCounters,
        maybe_inside: bool,
    ) -> Option<Hit> {
        let clock = counters.clock();
        let params = params.resolving(ray.origin);
        let light_ray = Ray {
            origin: from,
            dir: ray.dir,
        };
        let light_hit = self.intersect_lights(&light_ray, params.t_max, None);
        let t_max = light_hit.map_or(params.t_max, |(t, _)| t);
        let mut surface = None;
        if !self.objects.is_empty() {
            let p = TraceParams { t_max, ..params };
            let start = ray.at(p.t_min);
            let inside = maybe_inside && self.distance(start) < -p.eps_abs.max(p.eps_rel * p.t_min);
            let (outcome, object) = if inside {
                (sphere_trace(&Inside(&self.geometry), ray, &p), None)
            } else {
                self.trace(ray, &p)
            };
            counters.record(&outcome);
            let (t_hit, gave_up) = match outcome {
                // A ray that reaches the step cap without a decision is crawling along a
                // surface it is about to meet (inside a closed solid, its wall), so it
                // stops where it is. Measured on the shipped scenes against a cap 64 times
                // higher (`cargo xtask scale`, docs/SCALE.md): this changes the Death
                // Star's image mean by -0.002%, taking it as a miss by -0.23% (it sees the
                // sky through a wall) and ending the path by -0.37%.
                TraceOutcome::GaveUp { t, steps } if steps > 0 => (Some(t), true),
                _ => (outcome.hit_t(), false),
            };
            if let Some(t) = t_hit {
                let object = object.unwrap_or_else(|| self.closest_object(ray.at(t)));
                let mut epsilon = p.eps_abs.max(p.eps_rel * t);
                if gave_up {
                    // One evaluation, on the rare ray that gave up: where it stopped
                    // may be farther from the surface than a hit threshold.
                    let f = self.geometry.prepared[object].distance(ray.at(t)).abs();
                    if f.is_finite() {
                        epsilon = epsilon.max(f);
                    }
                }
                surface = Some(Hit::Surface {
                    t,
                    object,
                    epsilon,
                    inside,
                });
            }
        } else {
            counters.rays += 1;
        }
        counters.stop(clock);
        surface.or(light_hit.map(|(t, light)| Hit::Light { t, light }))
    }

    /// Whether the segment from `ray.origin` along `ray.dir` is free of
    /// objects and of lights other than `target` up to `distance`.
    pub(crate) fn unoccluded(
        &self,
        ray: &Ray,
        distance: f32,
        target: Option<usize>,
        params: &TraceParams,
        counters: &mut TraceCounters,
    ) -> bool {
        let clock = counters.clock();
        let params = &params.resolving(ray.origin);
        let free = 'free: {
            // Stop short of the light's surface so that its own geometry (for
            // lights that are objects too) does not occlude it.
            let t_max = (distance * (1.0 - 1e-4) - params.eps_abs).min(params.t_max);
            if let Some((_, l)) = self.intersect_lights(ray, t_max, target)
                && Some(l) != target
            {
                break 'free false;
            }
            if self.objects.is_empty() || t_max <= params.t_min {
                break 'free true;
            }
            let (outcome, _) = self.trace(ray, &TraceParams { t_max, ..*params });
            counters.record(&outcome);
            // A shadow ray that gives up is taken as a hit too (see `intersect_ray`).
            matches!(outcome, TraceOutcome::Miss { .. })
        };
        counters.stop(clock);
        free
    }

    fn intersect_lights(&self, ray: &Ray, t_max: f32, skip: Option<usize>) -> Option<(f32, usize)> {
        let mut best: Option<(f32, usize)> = None;
        for (i, l) in self.lights.iter().enumerate() {
            if Some(i) == skip {
                continue;
            }
            let t = match *l {
                Light::Sphere { center, radius, .. } => ray_sphere(ray, center, radius),
                Light::Quad {
                    corner,
                    edge_u,
                    edge_v,
                    ..
                } => ray_quad(ray, corner, edge_u, edge_v),
                Light::Directional { .. } => None,
            };
            if let Some(t) = t
                && t < t_max
                && best.is_none_or(|(bt, _)| t < bt)
            {
                best = Some((t, i));
            }
        }
        best
    }

    /// Radiance emitted by light `i` toward `-dir` from the point its ray hit.
    pub fn emitted(&self, light: usize, ray: &Ray, t: f32) -> Vec3 {
        match self.lights[light] {
            Light::Sphere {
                center, radiance, ..
            } => {
                // Emits outward only: a ray from inside sees the back face.
                if (ray.at(t) - center).dot(ray.dir) < 0.0 {
                    radiance
                } else {
                    Vec3::ZERO
                }
            }
            Light::Quad {
                edge_u,
                edge_v,
                radiance,
                ..
            } => {
                if edge_u.cross(edge_v).dot(ray.dir) < 0.0 {
                    radiance
                } else {
                    Vec3::ZERO
                }
            }
            Light::Directional { .. } => Vec3::ZERO,
        }
    }

    /// Whether light sampling has anything to sample.
    pub(crate) fn has_emitters(&self) -> bool {
        self.emitter_choice.is_some()
    }

    /// Chooses an emitter and a direction toward it from `p` (normal `n`,
    /// used only by the sky's cosine sampling).
    pub(crate) fn sample_emitter(
        &self,
        p: Vec3,
        n: Vec3,
        u_choice: f32,
        u: Vec2,
    ) -> Option<(EmitterSample, Option<usize>)> {
        let choice = self.emitter_choice.as_ref()?;
        let (k, pmf) = choice.sample(u_choice);
        match self.emitters[k] {
            Emitter::Sky => {
                let sky = self.sky?;
                let local = sample_cosine_hemisphere(u);
                let pdf = cosine_hemisphere_pdf(local.z);
                if !(pdf > 0.0) {
                    return None;
                }
                let wi = Frame::from_normal(n).to_world(local).normalize();
                Some((
                    EmitterSample {
                        wi,
                        distance: f32::INFINITY,
                        radiance: sky,
                        pdf: pdf * pmf,
                    },
                    None,
                ))
            }
            Emitter::Light(i) => {
                let (s, radiance) = self.sample_light(i, p, u)?;
                if !(s.pdf > 0.0) || !s.pdf.is_finite() {
                    return None;
                }
                Some((
                    EmitterSample {
                        wi: s.wi,
                        distance: s.distance,
                        radiance,
                        pdf: s.pdf * pmf,
                    },
                    Some(i),
                ))
            }
        }
    }

    fn sample_light(&self, i: usize, p: Vec3, u: Vec2) -> Option<(DirectionSample, Vec3)> {
        match self.lights[i] {
            Light::Sphere {
                center,
                radius,
                radiance,
            } => {
                let s = sample_sphere_light(p, center, radius, u)?;
                // Only the outward face emits.
                if s.normal.dot(s.wi) >= 0.0 {
                    return None;
                }
                Some((s, radiance))
            }
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                radiance,
            } => {
                let s = match self.quad_sampling {
                    QuadSampling::SolidAngle if is_rectangle(edge_u, edge_v) => {
                        // Falls back to area sampling where the solid angle is
                        // too small for the spherical-rectangle warp's f32 math.
                        sample_quad_solid_angle(p, corner, edge_u, edge_v, u)?
                    }
                    _ => sample_quad_area(p, corner, edge_u, edge_v, u)?,
                };
                Some((s, radiance))
            }
            Light::Directional { .. } => None,
        }
    }

    /// Solid-angle pdf with which [`Scene::sample_emitter`] picks `wi` from
    /// `p`, summed over every emitter that direction could come from.
    pub(crate) fn emitter_pdf(&self, p: Vec3, n: Vec3, wi: Vec3) -> f32 {
        let Some(choice) = self.emitter_choice.as_ref() else {
            return 0.0;
        };
        let mut pdf = 0.0;
        for (k, e) in self.emitters.iter().enumerate() {
            pdf += choice.pmf(k) * self.single_emitter_pdf(*e, p, n, wi);
        }
        pdf
    }

    /// The same for emitter light `i` only (the light a BSDF ray hit).
    pub(crate) fn light_pdf(&self, light: usize, p: Vec3, n: Vec3, wi: Vec3) -> f32 {
        let Some(choice) = self.emitter_choice.as_ref() else {
            return 0.0;
        };
        match self
            .emitters
            .iter()
            .position(|e| *e == Emitter::Light(light))
        {
            Some(k) => choice.pmf(k) * self.single_emitter_pdf(Emitter::Light(light), p, n, wi),
            None => 0.0,
        }
    }

    /// The same for the sky only.
    pub(crate) fn sky_pdf(&self, n: Vec3, wi: Vec3) -> f32 {
        let Some(choice) = self.emitter_choice.as_ref() else {
            return 0.0;
        };
        match self.emitters.iter().position(|e| *e == Emitter::Sky) {
            Some(k) => choice.pmf(k) * self.single_emitter_pdf(Emitter::Sky, Vec3::ZERO, n, wi),
            None => 0.0,
        }
    }

    fn single_emitter_pdf(&self, e: Emitter, p: Vec3, n: Vec3, wi: Vec3) -> f32 {
        match e {
            Emitter::Sky => cosine_hemisphere_pdf(n.dot(wi)),
            Emitter::Light(i) => match self.lights[i] {
                Light::Sphere { center, radius, .. } => {
                    // Directions that reach the sphere from inside hit its
                    // back face: the sampler rejects those, so they have
                    // zero density.
                    if (p - center).length_squared() <= radius * radius {
                        let Some(t) = ray_sphere(&Ray::new(p, wi), center, radius) else {
                            return 0.0;
                        };
                        if (p + wi * t - center).dot(wi) >= 0.0 {
                            return 0.0;
                        }
                    }
                    sphere_light_pdf(p, center, radius, wi)
                }
                Light::Quad {
                    corner,
                    edge_u,
                    edge_v,
                    ..
                } => match self.quad_sampling {
                    QuadSampling::SolidAngle if is_rectangle(edge_u, edge_v) => {
                        quad_solid_angle_pdf(p, corner, edge_u, edge_v, wi)
                    }
                    _ => quad_area_pdf(p, corner, edge_u, edge_v, wi),
                },
                Light::Directional { .. } => 0.0,
            },
        }
    }
}

fn valid_rgb(c: Vec3) -> bool {
    c.is_finite() && c.min_element() >= 0.0
}

fn is_rectangle(edge_u: Vec3, edge_v: Vec3) -> bool {
    edge_u.dot(edge_v).abs() <= 1e-4 * edge_u.length() * edge_v.length()
}

/// Nearest positive intersection of a ray with a sphere (from outside or
/// inside). Uses the numerically stable form of pbrt-v4 (section 6.8.1):
/// the discriminant from `|o - c - (b) d|` avoids cancellation far away.
pub(crate) fn ray_sphere(ray: &Ray, center: Vec3, radius: f32) -> Option<f32> {
    let oc = ray.origin - center;
    let b = oc.dot(ray.dir);
    let perp = oc - b * ray.dir;
    let disc = radius * radius - perp.length_squared();
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let q = if b > 0.0 { -b - root } else { -b + root };
    let (mut t0, mut t1) = (
        q,
        if q != 0.0 {
            (oc.length_squared() - radius * radius) / q
        } else {
            q
        },
    );
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    if t0 > 0.0 {
        Some(t0)
    } else if t1 > 0.0 {
        Some(t1)
    } else {
        None
    }
}

/// Intersection of a ray with the parallelogram `corner + s eu + t ev`.
pub(crate) fn ray_quad(ray: &Ray, corner: Vec3, edge_u: Vec3, edge_v: Vec3) -> Option<f32> {
    let n = edge_u.cross(edge_v);
    let denom = n.dot(ray.dir);
    if denom == 0.0 {
        return None;
    }
    let t = n.dot(corner - ray.origin) / denom;
    if !(t > 0.0) || !t.is_finite() {
        return None;
    }
    let q = ray.at(t) - corner;
    // Coordinates in the (edge_u, edge_v) basis by Cramer's rule with the
    // plane normal (works for any parallelogram).
    let nn = n.length_squared();
    let s = n.dot(q.cross(edge_v)) / nn;
    let r = n.dot(edge_u.cross(q)) / nn;
    if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&r) {
        Some(t)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A union of thin and far shapes, a plane among them, as the integrator sees it.
    fn crowd() -> Scene {
        use lueur_sdf_math::Quat;
        let sdfs = vec![
            Sdf::plane(Vec3::Y, 1.0),
            Sdf::torus(1.0, 1e-3).rotate(Quat::from_rotation_x(0.7)),
            Sdf::cuboid(Vec3::new(1.0, 1.0, 1e-3)).translate(Vec3::new(3.0, 0.0, 0.0)),
            Sdf::sphere(0.5).translate(Vec3::new(-2.0, 0.5, -1.0)),
            Sdf::death_star(1.0, 1.0, 0.02).translate(Vec3::new(0.0, 0.0, -40.0)),
            Sdf::torus(0.5, 0.2).translate(Vec3::new(0.0, 30.0, 0.0)),
        ];
        let camera = Camera::new(Vec3::new(0.0, 0.5, 6.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap();
        Scene::new(
            sdfs.into_iter()
                .map(|sdf| Object { sdf, material: 0 })
                .collect(),
            vec![Material::Lambertian { albedo: Vec3::ONE }],
            vec![],
            None,
            camera,
        )
        .unwrap()
    }

    /// A deterministic spread of points in a cube of half-side 50.
    fn points() -> impl Iterator<Item = Vec3> {
        (0..20_000u32).map(|i| {
            let f = |k: u32| ((i.wrapping_mul(k) % 10_007) as f32 / 10_007.0 - 0.5) * 100.0;
            let p = Vec3::new(f(7919), f(104_729), f(1_299_709));
            // Half of them near the origin, where the shapes are.
            if i % 2 == 0 { p * 0.05 } else { p }
        })
    }

    #[test]
    fn culling_gives_the_plain_union() {
        let scene = crowd();
        for p in points() {
            let (plain, culled) = (
                scene.geometry.distance_naive(p),
                scene.geometry.distance_culled(p),
            );
            assert_eq!(plain, culled, "at {p}");
        }
    }

    #[test]
    fn culled_union_is_lipschitz() {
        let scene = crowd();
        let l = scene.geometry.lipschitz;
        let mut previous = Vec3::ZERO;
        for p in points() {
            for q in [previous, p + Vec3::splat(1e-3), p * 1.01] {
                let (fp, fq) = (
                    scene.geometry.distance_culled(p),
                    scene.geometry.distance_culled(q),
                );
                let tol = 1e-5 * (1.0 + p.length() + q.length());
                assert!(
                    (fp - fq).abs() <= l * (p - q).length() + tol,
                    "|f({p}) - f({q})| = |{fp} - {fq}| > {l} |p - q|"
                );
            }
            previous = p;
        }
    }

    #[test]
    fn fast_marching_finds_the_naive_hits() {
        let mut naive = crowd();
        naive.marching = Marching::Naive;
        let fast = crowd();
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
            let a = naive.intersect(&ray, &params, &mut naive_steps);
            let b = fast.intersect(&ray, &params, &mut fast_steps);
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

    #[test]
    fn ray_sphere_from_outside_and_inside() {
        let r = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        assert!((ray_sphere(&r, Vec3::ZERO, 1.0).unwrap() - 4.0).abs() < 1e-5);
        let inside = Ray::new(Vec3::ZERO, Vec3::Z);
        assert!((ray_sphere(&inside, Vec3::ZERO, 1.0).unwrap() - 1.0).abs() < 1e-5);
        let away = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z);
        assert!(ray_sphere(&away, Vec3::ZERO, 1.0).is_none());
        let far = Ray::new(Vec3::new(0.0, 0.0, -1e4), Vec3::Z);
        assert!((ray_sphere(&far, Vec3::ZERO, 1.0).unwrap() - (1e4 - 1.0)).abs() < 1e-2);
    }

    #[test]
    fn ray_quad_hits_inside_only() {
        let (c, u, v) = (
            Vec3::new(-1.0, 2.0, -1.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 2.0),
        );
        let up = Ray::new(Vec3::ZERO, Vec3::Y);
        assert!((ray_quad(&up, c, u, v).unwrap() - 2.0).abs() < 1e-6);
        let off = Ray::new(Vec3::new(1.5, 0.0, 0.0), Vec3::Y);
        assert!(ray_quad(&off, c, u, v).is_none());
        let down = Ray::new(Vec3::ZERO, -Vec3::Y);
        assert!(ray_quad(&down, c, u, v).is_none());
    }
}
