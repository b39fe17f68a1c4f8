//! The lane wave's kernels: each reads and writes the blocks' rows a vector at a time, and
//! each lane's values are the bits the scalar wave computes for its path alone (every
//! formula here is a definition the scalar wave runs at `f32`).

use lueur_materials::CosineScatterLanes;
use lueur_sampling::{PcgLanes, SobolXorLanes, sample_cosine_hemisphere_lanes};
use lueur_scene::Light;
use lueur_sdf_math::{GroupRays, Lane, LaneKernel, LaneVec3, TraceParams, resolving_lanes};

use super::rows::{self, Block, LANES, ld, ld_mask, ld3, select3, st, st_mask, st3};
use crate::geometry::Geometry;
use crate::next_event::{AimedSphereLanes, DiffuseLanes, all_zero, sphere_next_event_lanes};
use crate::roulette::roulette_lanes;
use crate::strategy::{DIMS_PER_VERTEX, VertexSample, vertex_dimension};
use crate::trace::{CountLanes, RayCounters, TraceCounters, nearest_light_lanes};

/// The lanes whose next-event estimate found a shadow ray to trace (`rows::NEE` 1).
#[inline(always)]
fn shadow_ray_found<V: Lane>(b: &Block, at: usize) -> V::Mask {
    let state = ld::<V>(b, rows::NEE, at);
    V::and(state.gt(V::splat(0.5)), state.lt(V::splat(1.5)))
}

/// `a` where `first`, else `b`.
#[inline(always)]
fn pick<V: Lane>(first: V::Mask, a: f32, b: f32) -> V {
    V::select(first, V::splat(a), V::splat(b))
}

/// Per coordinate, `a * b`: glam's product of two vectors.
#[inline(always)]
fn mul3<V: Lane>(a: LaneVec3<V>, b: LaneVec3<V>) -> LaneVec3<V> {
    LaneVec3::new(a.x * b.x, a.y * b.y, a.z * b.z)
}

/// Every live path's ray (`rows::ALIVE`): the nearest light it meets from the point it
/// leaves, before its far limit, then the objects, marched from its origin to that light
/// or the far limit, as `PreparedScene::intersect_rays` traces it (the lights' tests in
/// `LightTests`' order, the march [`Geometry::march_vector`]).
pub(super) struct PathRays<'a> {
    pub geometry: &'a Geometry,
    pub lights: &'a [Light],
    /// The parameters of camera rays (depth 0) and of the others.
    pub camera: TraceParams,
    pub secondary: TraceParams,
    pub blocks: &'a mut [Block],
    /// The camera's and the bounces' counters, where each ray is recorded.
    pub counters: &'a mut RayCounters,
}

impl LaneKernel for PathRays<'_> {
    type Output = ();

    #[inline(always)]
    fn run<V: Lane>(self) {
        let PathRays {
            geometry,
            lights,
            camera: c,
            secondary: s,
            blocks,
            counters,
        } = self;
        let (mut camera, mut bounce) = (CountLanes::<V>::new(), CountLanes::<V>::new());
        for b in blocks.iter_mut() {
            for at in (0..LANES).step_by(V::LANES) {
                let alive = ld_mask::<V>(b, rows::ALIVE, at);
                if !V::any(alive) {
                    continue;
                }
                let (o, d, from) = (
                    ld3::<V>(b, rows::O, at),
                    ld3::<V>(b, rows::D, at),
                    ld3::<V>(b, rows::FROM, at),
                );
                let first = ld::<V>(b, rows::DEPTH, at).lt(V::splat(0.5));
                let t_max = pick::<V>(first, c.t_max, s.t_max);
                let (best_t, best, found) = nearest_light_lanes(lights, from, d, t_max);
                let (eps_abs, eps_rel) = resolving_lanes(
                    pick::<V>(first, c.eps_abs, s.eps_abs),
                    pick::<V>(first, c.eps_rel, s.eps_rel),
                    o,
                );
                let rays = GroupRays {
                    origin: o,
                    dir: d,
                    t_min: pick::<V>(first, c.t_min, s.t_min),
                    t_max: V::select(found, best_t, t_max),
                    max_steps: pick::<V>(first, c.max_steps as f32, s.max_steps as f32),
                    eps_abs,
                    eps_rel,
                    live: alive,
                };
                let (ends, nearest) = geometry.march_vector(&rays);
                st(ends.t(), b, rows::T, at);
                st_mask::<V>(ends.hit(), b, rows::HIT, at);
                st_mask::<V>(ends.gave_up(), b, rows::GAVE_UP, at);
                st(ends.steps(), b, rows::STEPS, at);
                st(nearest, b, rows::NEAR, at);
                st(eps_abs, b, rows::EPS_ABS, at);
                st(eps_rel, b, rows::EPS_REL, at);
                st(best, b, rows::LIGHT, at);
                st(best_t, b, rows::LIGHT_T, at);
                // A hit first, as the outcome read from the rows takes it.
                let gave_up = V::and(ends.gave_up(), V::not(ends.hit()));
                let outcome = (ends.steps(), ends.hit(), gave_up);
                camera.record(V::and(alive, first), outcome.0, outcome.1, outcome.2);
                bounce.record(
                    V::and(alive, V::not(first)),
                    outcome.0,
                    outcome.1,
                    outcome.2,
                );
            }
        }
        camera.add_to(&mut counters.camera);
        bounce.add_to(&mut counters.bounce);
    }
}

/// The numbers of every vertex shaded this round (`rows::SHADE`), drawn for a block of
/// paths at once into the rows `VertexSample::draw` fills, at the dimensions it takes them
/// from (`VertexSample::*_DIM`). Numbers the vertex does not read are written too (no
/// kernel reads them: a mirror's, or roulette's before it applies). Blocks with no vertex
/// to shade are left as they are.
pub(super) struct VertexNumbers<'a> {
    pub blocks: &'a mut [Block],
    pub numbers: LaneNumbers<'a>,
}

/// Where a block's paths' numbers come from, per sampler kind drawn in lanes.
pub(super) enum LaneNumbers<'a> {
    /// The independent kind's generators, stepped over each vertex's
    /// [`DIMS_PER_VERTEX`] dimensions: each lane's stands at its vertex's first (the
    /// vertex numbers are the only ones a path draws after its camera's), and a number
    /// no one reads is drawn too, so that the next vertex starts where it should.
    Independent(&'a mut [PcgLanes<LANES>]),
    /// The default kind's pixel samples, each number hashed at its lane's dimension
    /// (from its vertex's depth, `rows::DEPTH`).
    SobolXor(&'a [SobolXorLanes<LANES>]),
}

impl LaneKernel for VertexNumbers<'_> {
    type Output = ();

    #[inline(always)]
    fn run<V: Lane>(self) {
        let VertexNumbers { blocks, numbers } = self;
        match numbers {
            LaneNumbers::Independent(generators) => {
                for (b, generators) in blocks.iter_mut().zip(generators.iter_mut()) {
                    if b[rows::SHADE].iter().all(|&shade| shade == 0.0) {
                        continue;
                    }
                    let mut numbers = [[0.0; LANES]; DIMS_PER_VERTEX as usize];
                    for number in &mut numbers {
                        *number = generators.next_1d();
                    }
                    b[rows::U_EMITTER] = numbers[VertexSample::EMITTER_DIM];
                    b[rows::U_EMITTER + 1] = numbers[VertexSample::EMITTER_DIM + 1];
                    b[rows::U_BSDF] = numbers[VertexSample::BSDF_DIM];
                    b[rows::U_BSDF + 1] = numbers[VertexSample::BSDF_DIM + 1];
                    b[rows::U_ROULETTE] = numbers[VertexSample::ROULETTE_DIM];
                }
            }
            LaneNumbers::SobolXor(samples) => {
                for (b, samples) in blocks.iter_mut().zip(samples) {
                    if b[rows::SHADE].iter().all(|&shade| shade == 0.0) {
                        continue;
                    }
                    // Each lane's dimensions of the three requests (no closures: a vector
                    // kernel inlines only what is marked to be inlined).
                    let mut dims = [[0u32; LANES]; 3];
                    for (l, &depth) in b[rows::DEPTH].iter().enumerate() {
                        let first = vertex_dimension(depth as u32);
                        dims[0][l] = first + VertexSample::EMITTER_DIM as u32;
                        dims[1][l] = first + VertexSample::BSDF_DIM as u32;
                        dims[2][l] = first + VertexSample::ROULETTE_DIM as u32;
                    }
                    [b[rows::U_EMITTER], b[rows::U_EMITTER + 1]] = samples.get_2d(&dims[0]);
                    [b[rows::U_BSDF], b[rows::U_BSDF + 1]] = samples.get_2d(&dims[1]);
                    b[rows::U_ROULETTE] = samples.get_1d(&dims[2]);
                }
            }
        }
    }
}

/// At every diffuse vertex (`rows::DIFFUSE`): next-event estimation toward the sphere light
/// (`sphere_next_event_lanes`, as `SphereNextEvents` makes it), and the BSDF's sample by
/// the cosine (`CosineScatterLanes`, as `CosineScatters` draws it for `mis`). A vector
/// with no diffuse vertex only clears its estimates; the other lanes' scatter rows are
/// the mirrors' to write, after the kernel.
pub(super) struct Shade<'a> {
    pub sphere: AimedSphereLanes<f32>,
    pub blocks: &'a mut [Block],
}

impl LaneKernel for Shade<'_> {
    type Output = ();

    #[inline(always)]
    fn run<V: Lane>(self) {
        let Shade { sphere, blocks } = self;
        for b in blocks.iter_mut() {
            for at in (0..LANES).step_by(V::LANES) {
                let diffuse = V::and(
                    ld_mask::<V>(b, rows::SHADE, at),
                    ld_mask::<V>(b, rows::DIFFUSE, at),
                );
                if !V::any(diffuse) {
                    st(V::splat(0.0), b, rows::NEE, at);
                    continue;
                }
                let (p, n, origin) = (
                    ld3::<V>(b, rows::P, at),
                    ld3::<V>(b, rows::N, at),
                    ld3::<V>(b, rows::ORIGIN, at),
                );
                let wo = -ld3::<V>(b, rows::D, at);
                let albedo = ld3::<V>(b, rows::ALBEDO, at);
                let vertex = DiffuseLanes {
                    p,
                    origin,
                    n,
                    wo_n: wo.dot(n),
                    albedo,
                };
                let u = [
                    ld::<V>(b, rows::U_EMITTER, at),
                    ld::<V>(b, rows::U_EMITTER + 1, at),
                ];
                let sphere = AimedSphereLanes {
                    center: LaneVec3::splat(sphere.center.into()),
                    radius: V::splat(sphere.radius),
                    radiance: LaneVec3::splat(sphere.radiance.into()),
                    pmf: V::splat(sphere.pmf),
                };
                let (found, aim, contribution) = sphere_next_event_lanes(&vertex, &sphere, u);
                let found = V::and(diffuse, found);
                let state = V::select(
                    V::and(found, aim.at_point),
                    V::splat(1.0),
                    V::select(found, V::splat(2.0), V::splat(0.0)),
                );
                st(state, b, rows::NEE, at);
                st3(aim.dir, b, rows::SD, at);
                st(aim.distance, b, rows::SDIST, at);
                st3(contribution, b, rows::C, at);

                let local = sample_cosine_hemisphere_lanes([
                    ld::<V>(b, rows::U_BSDF, at),
                    ld::<V>(b, rows::U_BSDF + 1, at),
                ]);
                // A mirror's lanes are written over after the kernel.
                let cs = CosineScatterLanes::new(albedo, wo, n, local);
                st3(cs.wi, b, rows::WI, at);
                st3(cs.weight, b, rows::WEIGHT, at);
                st(cs.pdf, b, rows::WPDF, at);
                st_mask::<V>(cs.valid, b, rows::WVALID, at);
            }
        }
    }
}

/// Every shadow ray next-event estimation found (`rows::NEE` 1): free of objects up to
/// short of the light, as `PreparedScene::unoccluded_rays` traces it (no other light to
/// block it: the wave runs scenes of one light).
pub(super) struct ShadowRays<'a> {
    pub geometry: &'a Geometry,
    pub params: TraceParams,
    pub blocks: &'a mut [Block],
    /// The shadow rays' counters, where each ray marched is recorded.
    pub counters: &'a mut TraceCounters,
}

impl LaneKernel for ShadowRays<'_> {
    type Output = ();

    #[inline(always)]
    fn run<V: Lane>(self) {
        let ShadowRays {
            geometry,
            params,
            blocks,
            counters,
        } = self;
        let mut count = CountLanes::<V>::new();
        for b in blocks.iter_mut() {
            for at in (0..LANES).step_by(V::LANES) {
                let found = shadow_ray_found::<V>(b, at);
                if !V::any(found) {
                    continue;
                }
                let origin = ld3::<V>(b, rows::ORIGIN, at);
                let (eps_abs, eps_rel) =
                    resolving_lanes(V::splat(params.eps_abs), V::splat(params.eps_rel), origin);
                // Short of the light's surface, so that its own geometry (for lights that are
                // objects too) does not occlude it.
                let distance = ld::<V>(b, rows::SDIST, at);
                let t_max = (distance * V::splat(1.0 - 1e-4) - eps_abs).min(V::splat(params.t_max));
                let t_min = V::splat(params.t_min);
                let marched = V::and(found, V::not(t_min.ge(t_max)));
                let rays = GroupRays {
                    origin,
                    dir: ld3::<V>(b, rows::SD, at),
                    t_min,
                    t_max,
                    max_steps: V::splat(params.max_steps as f32),
                    eps_abs,
                    eps_rel,
                    live: marched,
                };
                let (ends, _) = geometry.march_vector(&rays);
                // A shadow ray that gives up is taken as blocked, as a path ray that gives up
                // is taken as a hit.
                let blocked = V::and(marched, V::or(ends.hit(), ends.gave_up()));
                st_mask::<V>(V::not(blocked), b, rows::FREE, at);
                // A free ray missed; a blocked one gave up, or else hit.
                let gave_up = V::and(blocked, ends.gave_up());
                let hit = V::and(blocked, V::not(ends.gave_up()));
                count.record(marched, ends.steps(), hit, gave_up);
            }
        }
        count.add_to(counters);
    }
}

/// Every shaded vertex (`rows::SHADE`): what its shadow ray brings, then the scatter,
/// the throughput, Russian roulette and the next ray, as the scalar wave's `gather` and
/// `scatter` make them; where the path ends, `rows::ENDED`.
pub(super) struct Scatter<'a> {
    pub roulette_depth: u32,
    pub blocks: &'a mut [Block],
}

impl LaneKernel for Scatter<'_> {
    type Output = ();

    #[inline(always)]
    fn run<V: Lane>(self) {
        let Scatter {
            roulette_depth,
            blocks,
        } = self;
        for b in blocks.iter_mut() {
            for at in (0..LANES).step_by(V::LANES) {
                let shade = ld_mask::<V>(b, rows::SHADE, at);
                if !V::any(shade) {
                    continue;
                }
                let beta = ld3::<V>(b, rows::BETA, at);
                let brings = V::and(
                    shadow_ray_found::<V>(b, at),
                    ld_mask::<V>(b, rows::FREE, at),
                );
                let radiance = ld3::<V>(b, rows::L, at);
                let gathered = radiance + mul3(beta, ld3::<V>(b, rows::C, at));
                st3(
                    select3(V::and(shade, brings), gathered, radiance),
                    b,
                    rows::L,
                    at,
                );

                let scattered = mul3(beta, ld3::<V>(b, rows::WEIGHT, at));
                let depth = ld::<V>(b, rows::DEPTH, at) + V::splat(1.0);
                let dark = V::or(all_zero(scattered), V::not(scattered.finite()));
                let goes = V::and(
                    V::and(shade, ld_mask::<V>(b, rows::WVALID, at)),
                    V::not(dark),
                );
                let (survivor, killed) = roulette_lanes(
                    scattered,
                    depth.ge(V::splat(roulette_depth as f32)),
                    ld::<V>(b, rows::U_ROULETTE, at),
                );
                let next = V::and(goes, V::not(killed));
                let ended = V::or(
                    ld_mask::<V>(b, rows::ENDED, at),
                    V::and(shade, V::not(next)),
                );
                st_mask::<V>(ended, b, rows::ENDED, at);
                if !V::any(next) {
                    continue;
                }
                let wi = ld3::<V>(b, rows::WI, at);
                // `Ray::new`'s direction: `wi` times the reciprocal of its length.
                let dir = wi * (V::splat(1.0) / wi.length());
                // A lane that does not go on ends, and its next path overwrites these rows.
                st3(survivor, b, rows::BETA, at);
                st(depth, b, rows::DEPTH, at);
                st3(ld3::<V>(b, rows::ORIGIN, at), b, rows::O, at);
                st3(dir, b, rows::D, at);
                st3(ld3::<V>(b, rows::P, at), b, rows::FROM, at);
                st3(ld3::<V>(b, rows::N, at), b, rows::FROM_N, at);
                st(ld::<V>(b, rows::DIFFUSE, at), b, rows::EMIT_MIS, at);
                st(ld::<V>(b, rows::WPDF, at), b, rows::EMIT_PDF, at);
            }
        }
    }
}
