//! The path-tracing estimator of pixel samples: a wave of paths advanced a
//! vertex at a time through the stages (intersect, emission, shading with
//! its shadow rays, scatter, roulette), each ray kind traced as one stream.
//! Each stage is a function of one path's inputs only, so a path's estimate
//! does not depend on the paths beside it.

use std::collections::VecDeque;

use glam::Vec3;
use lueur_materials::Material;
use lueur_sampling::Sampler;
use lueur_sdf_math::{Ray, SimdLevel};

use lueur_sdf_math::TraceParams;

use crate::roulette::{roulette, roulette_applies};
use crate::stages::{Stage, StageClock, StageTimes};
use crate::strategy::{
    self, CosineScatters, EmissionWeight, Lighting, Scatter, Vertex, VertexReads, VertexSample,
};
use crate::surface::{March, SurfaceHit, SurfacePoint, SurfaceScratch};
use crate::trace::{PathRay, RayCounters, ShadowRay, TraceScratch, Tracing};
use lueur_scene::RenderSettings;

use crate::light_sampler::{
    CosineDraws, Drawn, Emitters, RectangleDraws, SphereNextEvent, SphereNextEvents,
};
use crate::next_event::DiffuseLanes;
use crate::{Hit, PreparedScene};

/// State carried from one vertex to the next for weighting emission.
#[derive(Clone, Copy)]
pub(crate) struct Previous {
    /// Point and facing normal of the last scattering vertex.
    pub p: Vec3,
    pub n: Vec3,
    /// Whether the path travels inside a solid: it started at a camera
    /// inside an object and every vertex since was shaded on the inside.
    /// (Only then: an outside hit whose coarse normal faces away from the
    /// viewer is rounding, not a way in.)
    pub in_solid: bool,
    /// How emission found along the current ray counts.
    pub emission: EmissionWeight,
}

impl Previous {
    /// The camera, as the vertex before the first: what its rays find counts
    /// in full.
    const fn camera(position: Vec3) -> Previous {
        Previous {
            p: position,
            n: Vec3::ZERO,
            in_solid: false,
            emission: EmissionWeight::Full,
        }
    }
}

/// What path estimates need besides their random numbers.
pub(crate) struct Estimator<'a> {
    pub scene: &'a PreparedScene,
    pub settings: &'a RenderSettings,
    pub march: March,
    pub tracing: Tracing,
    /// The lane wave's view of the scene, where it runs ([`crate::lane_wave`]); else the
    /// wave of this module runs.
    pub lanes: Option<&'a crate::lane_wave::LaneWave>,
}

/// Which sample of which pixel a path belongs to.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SampleId {
    pub pixel: [u32; 2],
    pub index: u32,
}

/// One path in flight: the sample it estimates, the ray it traces next and what it has
/// gathered.
#[derive(Clone, Copy)]
struct Path {
    id: SampleId,
    /// The order in which the wave started it, which is the order its estimate is handed
    /// on in.
    ordinal: u64,
    ray: Ray,
    params: TraceParams,
    beta: Vec3,
    radiance: Vec3,
    previous: Previous,
    /// Scattering events so far.
    depth: u32,
}

impl Path {
    /// A path before its sample, camera ray and parameters are written in.
    const START: Path = Path {
        id: SampleId {
            pixel: [0, 0],
            index: 0,
        },
        ordinal: 0,
        ray: PathRay::UNSET.ray,
        params: PathRay::UNSET.params,
        beta: Vec3::ONE,
        radiance: Vec3::ZERO,
        previous: Previous::camera(Vec3::ZERO),
        depth: 0,
    };
}

/// A path shaded at a vertex, waiting for its shadow rays: the vertex, the shadow rays'
/// contributions (`shadow` indexes the wave's shadow rays; the next-event ray, if any, is
/// the last), and where the path goes next. Its shading point is the wave's
/// [`SurfacePoint`] of the same index.
#[derive(Clone, Copy)]
struct Shaded {
    path: usize,
    diffuse: bool,
    shadow: (usize, usize),
    next_event: bool,
    scatter: Option<Scatter>,
    roulette: f32,
}

impl Shaded {
    /// A placeholder for a slot that [`shade`] fills.
    const UNSET: Shaded = Shaded {
        path: 0,
        diffuse: false,
        shadow: (0, 0),
        next_event: false,
        scatter: None,
        roulette: 0.0,
    };
}

/// A vertex waiting to be shaded: its path, the object it met, its numbers, where the wave
/// drew its next-event estimation's light sample, and its sample's index in the wave's
/// [`CosineScatters`] where it scatters by the cosine. Its shading point is the wave's
/// [`SurfacePoint`] of the same index.
struct Pending {
    path: usize,
    on_surface: SurfaceHit,
    u: VertexSample,
    light: Option<LightDraw>,
    cosine: Option<usize>,
}

/// Where a wave drew a vertex's light sample: its index in the wave's
/// [`SphereNextEvents`] (with the light's index, its shadow ray's target; there the
/// estimate is made too) or [`RectangleDraws`], or, toward the sky, in its [`CosineDraws`].
#[derive(Clone, Copy)]
enum LightDraw {
    Sphere(usize, usize),
    Rectangle(usize),
    Sky(usize),
}

/// The light samples a wave draws together.
#[derive(Default)]
struct LightDraws {
    spheres: SphereNextEvents,
    rectangles: RectangleDraws,
}

impl LightDraws {
    fn clear(&mut self) {
        self.spheres.clear();
        self.rectangles.clear();
    }

    /// Draws every request's sample, and the spheres' estimates, on `level`.
    fn draw(&mut self, level: SimdLevel, emitters: &Emitters<'_>) {
        self.spheres.draw(level);
        self.rectangles.draw(emitters);
    }
}

/// A thread's buffers for [`radiance_wave`], kept from one wave to the next.
#[derive(Default)]
pub(crate) struct WaveScratch {
    /// The wave's slots: each path in flight, and each path's own copy of the sampler.
    paths: Vec<Path>,
    samplers: Vec<Sampler>,
    /// The slots whose path has ended, free for the next sample.
    vacant: Vec<usize>,
    /// Estimates from the oldest path in flight on, in the order their paths started, as
    /// they end; handed on from the front as it fills.
    ended: VecDeque<Option<(SampleId, Vec3)>>,
    /// The ordinal of `ended`'s front.
    ended_from: u64,
    /// The slots of the paths in flight.
    active: Vec<usize>,
    rays: Vec<PathRay>,
    hits: Vec<Option<Hit>>,
    /// The hits that scatter, with their rays, and their shading points.
    surface_hits: Vec<(Ray, SurfaceHit)>,
    surfaces: Vec<SurfacePoint>,
    surface_scratch: SurfaceScratch,
    pending: Vec<Pending>,
    lights: LightDraws,
    cosines: CosineDraws,
    scatters: CosineScatters,
    shaded: Vec<Shaded>,
    shadow: ShadowQueue,
    free: Vec<bool>,
    trace: TraceScratch,
}

/// The shadow rays a wave's vertices propose, with what each would bring.
#[derive(Default)]
struct ShadowQueue {
    rays: Vec<ShadowRay>,
    contributions: Vec<Vec3>,
}

/// The material of the object a path met.
pub(crate) fn material_at(scene: &PreparedScene, on_surface: SurfaceHit) -> Material {
    scene.scene().materials[scene.scene().objects[on_surface.object].material]
}

/// Shades the path of `pending` (`path`) at its shading point `surface`: the shadow rays the
/// vertex proposes (queued in `shadow`; at a diffuse vertex the delta lights', then
/// next-event estimation's where the strategy uses it, its light sample taken from
/// `lights` where the wave drew it) and the direction it scatters in.
fn shade(
    estimator: &Estimator<'_>,
    lighting: &Lighting<'_>,
    (pending, surface, path): (&Pending, &SurfacePoint, &Path),
    (lights, cosines, scatters): (&LightDraws, &CosineDraws, &CosineScatters),
    shadow: &mut ShadowQueue,
    out: &mut Shaded,
) {
    let Estimator {
        scene, settings, ..
    } = *estimator;
    let &Pending {
        path: index,
        on_surface,
        ref u,
        light,
        cosine,
    } = pending;
    let material = material_at(scene, on_surface);
    let vertex = Vertex {
        at: surface,
        wo: -path.ray.dir,
        material,
    };
    // Written into its slot a field at a time, as it is made: a record made whole and then
    // pushed is stored in pieces and loaded back whole, and the load waits for the stores
    // to retire (docs/PERFORMANCE.md, "Stores loaded whole").
    out.path = index;
    out.roulette = u.roulette;
    let first = shadow.rays.len();
    match material {
        Material::Mirror { .. } => {
            out.diffuse = false;
            out.next_event = false;
            out.scatter = strategy::mirror(&vertex, u.bsdf);
        }
        Material::Lambertian { .. } => {
            lighting.delta_lights(&vertex, &mut shadow.rays, &mut shadow.contributions);
            out.diffuse = true;
            out.next_event = strategy::uses_next_event(settings.strategy)
                && 'estimate: {
                    let drawn = match light {
                        Some(LightDraw::Sphere(k, light)) => match lights.spheres.outcome(k) {
                            SphereNextEvent::Nothing => break 'estimate false,
                            SphereNextEvent::Found => {
                                shadow.rays.push(ShadowRay::UNSET);
                                shadow.contributions.push(Vec3::ZERO);
                                lights.spheres.write(
                                    k,
                                    (surface.origin, light),
                                    shadow.rays.last_mut().expect("pushed"),
                                    shadow.contributions.last_mut().expect("pushed"),
                                );
                                break 'estimate true;
                            }
                            SphereNextEvent::Alone => None,
                        },
                        Some(LightDraw::Rectangle(k)) => {
                            Some(Drawn::Light(&lights.rectangles.drawn[k]))
                        }
                        Some(LightDraw::Sky(k)) => Some(Drawn::Cosine(cosines, k)),
                        None => None,
                    };
                    // Pushed where it is made: moved through an `Option` and an iterator
                    // chain, the ray is stored in pieces and loaded whole, and the load
                    // waits for the stores.
                    match lighting.next_event(&vertex, u, drawn) {
                        Some((ray, contribution)) => {
                            shadow.rays.push(ray);
                            shadow.contributions.push(contribution);
                            true
                        }
                        None => false,
                    }
                };
            let emitters = &lighting.emitters;
            strategy::scatter_into(
                settings.strategy,
                emitters,
                &vertex,
                u,
                (scatters, cosine),
                &mut out.scatter,
            );
        }
    }
    out.shadow = (first, shadow.rays.len());
}

/// How many estimates, per path in flight, may wait for an older path to end before the
/// wave stops starting paths: bounds a wave's memory when `max_depth` is large, and is
/// not reached otherwise (a path ends within `max_depth + 1` vertices, and each vertex
/// starts at most a wave's worth).
pub(crate) const ENDED_PER_SLOT: usize = 16;

/// The radiance of the pixel samples `next` gives (each as its id, camera ray and a copy
/// of the sampler positioned past the camera's dimensions), estimated by one path each,
/// handed to `estimate` in the order `next` gave them.
///
/// Up to `width` paths advance together, a vertex at a time: their rays are traced as one
/// stream, then each draws its vertex's numbers, the light samples and cosine directions
/// the vertices chose are drawn as batches, then each is shaded, then their shadow rays
/// are traced as another stream, then each gathers what its shadow rays bring and
/// scatters. A path that ends hands its slot to the next sample at once, so the streams
/// stay a wave wide, paths at every depth together, until `next` runs dry, rather than
/// thinning to the few paths that live longest (docs/PERFORMANCE.md, "Waves that stay
/// full"). Every path does exactly what it would do alone (the stages are functions of
/// the path's own inputs, and each path adds to its estimate in the same order), so an
/// estimate does not depend on which paths share its wave, nor on the instruction set
/// the streams run on.
pub(crate) fn radiance_wave(
    estimator: &Estimator<'_>,
    width: usize,
    next: &mut impl FnMut() -> Option<(SampleId, Ray, Sampler)>,
    (counters, stages): (&mut RayCounters, &mut StageTimes),
    scratch: &mut WaveScratch,
    estimate: &mut impl FnMut(SampleId, Vec3),
) {
    let Estimator {
        scene,
        settings,
        march,
        tracing,
        ..
    } = *estimator;
    let width = width.max(1);
    let lighting = Lighting::of(scene, settings, &march);
    let chooses = lighting.emitters.sampler.choice_reads_u();
    let s = scratch;
    s.paths.clear();
    s.samplers.clear();
    s.vacant.clear();
    s.ended.clear();
    s.ended_from = 0;
    s.active.clear();
    let mut dry = false;
    let mut clock = StageClock::start(stages);
    loop {
        // Hand on the estimates that are next in order.
        while let Some(Some(_)) = s.ended.front() {
            let (id, l) = s.ended.pop_front().flatten().expect("an ended path");
            estimate(id, l);
            s.ended_from += 1;
        }
        clock.lap(Stage::Estimates);
        // Start a path in every vacant slot.
        while !dry
            && (!s.vacant.is_empty() || s.paths.len() < width)
            && s.ended.len() < ENDED_PER_SLOT * width
        {
            let Some((id, ray, sampler)) = next() else {
                dry = true;
                break;
            };
            let slot = match s.vacant.pop() {
                Some(slot) => {
                    s.samplers[slot] = sampler;
                    slot
                }
                None => {
                    s.paths.push(Path::START);
                    s.samplers.push(sampler);
                    s.paths.len() - 1
                }
            };
            // Field by field into place: a `Path` made whole per ray is written in pieces
            // on the stack and loaded back whole (docs/PERFORMANCE.md, "Stores loaded
            // whole").
            let path = &mut s.paths[slot];
            *path = Path::START;
            path.id = id;
            // The paths started so far: those handed on, and those waiting.
            path.ordinal = s.ended_from + s.ended.len() as u64;
            path.ray = ray;
            path.previous.p = ray.origin;
            path.params = march.camera;
            s.ended.push_back(None);
            s.active.push(slot);
        }
        if s.active.is_empty() {
            break;
        }
        // Field by field into place: a `PathRay` made whole first is written in pieces on
        // the stack and loaded back whole, and every ray waits for its stores
        // (docs/PERFORMANCE.md, "Stores loaded whole").
        s.rays.resize(s.active.len(), PathRay::UNSET);
        for (ray, &i) in s.rays.iter_mut().zip(&s.active) {
            let path = &s.paths[i];
            ray.ray = path.ray;
            ray.from = path.previous.p;
            ray.params = path.params;
            ray.maybe_inside = path.depth == 0 && march.camera_inside || path.previous.in_solid;
            ray.camera = path.depth == 0;
        }
        clock.lap(Stage::StartPaths);
        scene.intersect_rays(&s.rays, tracing, counters, &mut s.trace, &mut s.hits);
        clock.lap(Stage::PathRays);

        // The shading points of the hits that scatter, as one stream.
        s.surface_hits.clear();
        for (&i, &hit) in s.active.iter().zip(&s.hits) {
            let path = &s.paths[i];
            if let Some(on_surface) = SurfaceHit::of(hit)
                && path.depth < settings.max_depth
            {
                s.surface_hits.push((path.ray, on_surface));
            }
        }
        SurfacePoint::at_hits(
            scene,
            &march,
            tracing.simd,
            &s.surface_hits,
            &mut s.surface_scratch,
            &mut s.surfaces,
        );
        clock.lap(Stage::ShadingPoints);

        s.pending.clear();
        s.lights.clear();
        s.cosines.clear();
        s.scatters.clear();
        let mut surfaces = s.surfaces.iter();
        for (&i, &hit) in s.active.iter().zip(&s.hits) {
            let path = &mut s.paths[i];
            let Some(on_surface) = SurfaceHit::of(hit) else {
                path.radiance +=
                    emission_found(&lighting, &path.previous, &path.ray, hit, path.beta);
                end(path, i, &mut s.ended, s.ended_from, &mut s.vacant);
                continue;
            };
            if path.depth >= settings.max_depth {
                end(path, i, &mut s.ended, s.ended_from, &mut s.vacant);
                continue;
            }
            let surface = surfaces
                .next()
                .expect("a shading point for each hit that scatters");
            // The numbers are drawn into their slot: a `VertexSample` returned whole is
            // stored in pieces and loaded back whole (docs/PERFORMANCE.md, "Stores loaded
            // whole").
            s.pending.push(Pending {
                path: i,
                on_surface,
                u: VertexSample::UNSET,
                light: None,
                cosine: None,
            });
            let pending = s.pending.last_mut().expect("pushed");
            let albedo = match material_at(scene, on_surface) {
                Material::Lambertian { albedo } => Some(albedo),
                Material::Mirror { .. } => None,
            };
            let diffuse = albedo.is_some();
            // `scatter` counts this vertex before its roulette.
            let roulette = roulette_applies(path.depth + 1, settings.roulette_depth);
            pending.u.draw(
                &mut s.samplers[i],
                path.id.pixel,
                path.id.index,
                path.depth,
                VertexReads::of(settings.strategy, diffuse, chooses, roulette),
            );
            let u = &pending.u;
            // Next-event estimation toward a sphere or rectangle light or the sky, and the
            // cosine-weighted direction a diffuse vertex scatters in: drawn below, with the
            // wave's others.
            let next_event = strategy::uses_next_event(settings.strategy) && diffuse;
            let emitters = &lighting.emitters;
            pending.light = if !next_event {
                None
            } else if let Some(chosen) = emitters.chosen_sphere(u.emitter_choice) {
                let vertex = DiffuseLanes {
                    p: surface.p.into(),
                    origin: surface.origin.into(),
                    n: surface.n.into(),
                    wo_n: (-path.ray.dir).dot(surface.n),
                    // Next-event estimation is at diffuse vertices only.
                    albedo: albedo.unwrap_or_default().into(),
                };
                let k = s.lights.spheres.request(&vertex, &chosen, u.emitter);
                Some(LightDraw::Sphere(k, chosen.light))
            } else if let Some(light) = emitters.chosen_rectangle(u.emitter_choice) {
                let k = s.lights.rectangles.request(surface.p, light, u.emitter);
                Some(LightDraw::Rectangle(k))
            } else {
                emitters
                    .chosen_sky(u.emitter_choice)
                    .then(|| LightDraw::Sky(s.cosines.request(u.emitter)))
            };
            pending.cosine = albedo
                .filter(|_| strategy::scatters_by_cosine(settings.strategy))
                .map(|albedo| s.scatters.request(u.bsdf, albedo, -path.ray.dir, surface.n));
        }
        // The shading below and the scattering after pair each vertex with its shading
        // point by index.
        debug_assert_eq!(s.pending.len(), s.surfaces.len());
        clock.lap(Stage::VertexNumbers);
        s.lights.draw(tracing.simd, &lighting.emitters);
        s.cosines.draw(tracing.simd);
        s.scatters.draw(tracing.simd);
        clock.lap(Stage::Draws);

        s.shaded.resize(s.pending.len(), Shaded::UNSET);
        s.shadow.rays.clear();
        s.shadow.contributions.clear();
        for ((pending, surface), out) in s.pending.iter().zip(&s.surfaces).zip(&mut s.shaded) {
            let path = &s.paths[pending.path];
            shade(
                estimator,
                &lighting,
                (pending, surface, path),
                (&s.lights, &s.cosines, &s.scatters),
                &mut s.shadow,
                out,
            );
        }
        clock.lap(Stage::Shading);
        scene.unoccluded_rays(
            &s.shadow.rays,
            &lighting.params,
            tracing,
            &mut counters.shadow,
            &mut s.trace,
            &mut s.free,
        );
        clock.lap(Stage::ShadowRays);

        s.active.clear();
        for (shaded, surface) in s.shaded.iter().zip(&s.surfaces) {
            let slot = shaded.path;
            let path = &mut s.paths[slot];
            if shaded.diffuse {
                gather(path, shaded, &s.shadow.contributions, &s.free, settings);
            }
            if scatter(path, (shaded, surface), &march, settings) {
                s.active.push(slot);
            } else {
                end(path, slot, &mut s.ended, s.ended_from, &mut s.vacant);
            }
        }
        clock.lap(Stage::Scattering);
    }
    debug_assert!(s.ended.is_empty(), "every estimate handed on");
}

/// Ends the path in slot `slot`: its estimate waits in `ended` (whose front is path
/// `ended_from`) for the paths started before it, and the slot is vacant.
fn end(
    path: &Path,
    slot: usize,
    ended: &mut VecDeque<Option<(SampleId, Vec3)>>,
    ended_from: u64,
    vacant: &mut Vec<usize>,
) {
    ended[(path.ordinal - ended_from) as usize] = Some((path.id, path.radiance));
    vacant.push(slot);
}

/// Adds to the path's estimate what its shadow rays bring: the delta lights' sum, then
/// next-event estimation where the strategy uses it, each times the throughput.
fn gather(
    path: &mut Path,
    shaded: &Shaded,
    contributions: &[Vec3],
    free: &[bool],
    settings: &RenderSettings,
) {
    let (first, end) = shaded.shadow;
    let delta_end = if shaded.next_event { end - 1 } else { end };
    let mut delta = Vec3::ZERO;
    for k in first..delta_end {
        if free[k] {
            delta += contributions[k];
        }
    }
    path.radiance += path.beta * delta;
    if strategy::uses_next_event(settings.strategy) {
        let nee = if shaded.next_event && free[end - 1] {
            contributions[end - 1]
        } else {
            Vec3::ZERO
        };
        path.radiance += path.beta * nee;
    }
}

/// Moves the path past its vertex (at `surface`) in the scattered direction, through
/// Russian roulette; whether it goes on.
fn scatter(
    path: &mut Path,
    (shaded, surface): (&Shaded, &SurfacePoint),
    march: &March,
    settings: &RenderSettings,
) -> bool {
    let Some(scatter) = shaded.scatter else {
        return false;
    };
    path.beta *= scatter.weight;
    path.depth += 1;
    if path.beta == Vec3::ZERO || !path.beta.is_finite() {
        return false;
    }
    path.previous = Previous {
        in_solid: surface.inside
            && (path.depth == 1 && march.camera_inside || path.previous.in_solid),
        p: surface.p,
        n: surface.n,
        emission: scatter.emission,
    };
    path.ray = Ray::new(surface.origin, scatter.wi);
    path.params = march.secondary;
    match roulette(
        path.beta,
        path.depth,
        settings.roulette_depth,
        shaded.roulette,
    ) {
        Some(survivor) => {
            path.beta = survivor;
            true
        }
        None => false,
    }
}

/// What the path gains where it leaves the objects: the sky on a miss, or a
/// light's surface, weighted as the last scattering event said
/// ([`EmissionWeight`]).
pub(crate) fn emission_found(
    lighting: &Lighting<'_>,
    previous: &Previous,
    ray: &Ray,
    hit: Option<Hit>,
    beta: Vec3,
) -> Vec3 {
    let emitters = &lighting.emitters;
    match hit {
        None => match lighting.scene.scene().sky {
            Some(sky) => {
                let w = previous
                    .emission
                    .weight(|| emitters.sky_pdf(previous.n, ray.dir));
                beta * sky * w
            }
            None => Vec3::ZERO,
        },
        Some(Hit::Light { t, light }) => {
            // Light hits are measured from the last vertex, not from the lifted origin.
            let from = Ray {
                origin: previous.p,
                dir: ray.dir,
            };
            let le = lighting.scene.emitted(light, &from, t);
            if le == Vec3::ZERO {
                return Vec3::ZERO;
            }
            let w = previous
                .emission
                .weight(|| emitters.light_pdf(light, previous.p, previous.n, ray.dir));
            beta * le * w
        }
        Some(Hit::Surface { .. }) => Vec3::ZERO,
    }
}
