//! The lane wave: the wave of paths ([`crate::path`]) with each path's state kept in a
//! lane of a SIMD vector from one vertex to the next, as Mitsuba's and pbrt-v4's wavefront
//! integrators keep theirs, for the scenes it models (see [`LaneWave::of`]); the other
//! scenes run the wave of `path.rs`.
//!
//! Why: the wave of `path.rs` keeps each path as a record, and every stage that runs in
//! lanes (the march, the light samples, the BSDF's samples) copies its inputs from the
//! records into rows of lanes and its outputs back, a lane at a time. That copying cost
//! about what the lanes saved (docs/PERFORMANCE.md, "Next-event estimation in lanes,
//! rebuilt"). Here the path state is the rows: blocks of 16 paths, a field per row
//! ([`rows`]), that each stage's kernel ([`kernels`]) loads and stores a vector at a time.
//! What stays scalar, per lane, is what branches by path: the numbers of the samplers other
//! than the independent and default kinds (which are drawn in lanes, `PcgLanes` and
//! `SobolXorLanes`), the shading points (`SurfacePoint::at_source`, grouped by object, from
//! and to the rows), emission found on a light, a mirror's bounce, and the paths that end
//! and start.
//!
//! Contract: the image is the wave of `path.rs`'s, bit for bit, on every SIMD level, for
//! any number of paths in flight and threads. Each lane runs the scalar wave's own
//! definitions (the march [`Geometry::march_vector`], `Light::intersect_lanes`,
//! `sample_sphere_light_lanes`, `NextEventLanes`, `ShadowAim`, `CosineScatterLanes`,
//! `roulette_lanes`), which the scalar wave runs at `f32`, and the independent and default
//! kinds' numbers from `PcgLanes` and `SobolXorLanes`, which their tests hold to `Sampler`;
//! `tests/` holds both waves to it.

mod kernels;
mod rows;

use std::collections::VecDeque;
use std::time::Instant;

use glam::{Vec2, Vec3};
use lueur_materials::Material;
use lueur_sampling::{PcgLanes, Sampler, SamplerKind, SobolXorLanes};
use lueur_scene::{Light, Marching, Strategy};
use lueur_sdf_math::{Ray, TraceOutcome, TraceParams};

use self::kernels::{LaneNumbers, PathRays, Scatter, Shade, ShadowRays, VertexNumbers};
use self::rows::{Block, LANES, get3, set3};
use crate::Hit;
use crate::next_event::AimedSphereLanes;
use crate::path::{ENDED_PER_SLOT, Estimator, Previous, SampleId, emission_found, material_at};
use crate::roulette::roulette_applies;
use crate::stages::{Stage, StageClock, StageTimes};
use crate::strategy::{self, EmissionWeight, Lighting, Vertex, VertexReads, VertexSample};
use crate::surface::{HitSource, SurfaceHit, SurfacePoint, SurfaceScratch};
use crate::trace::RayCounters;

/// What the lane wave needs of a scene it models: the sphere light next-event estimation
/// aims at.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneWave {
    sphere: AimedSphereLanes<f32>,
}

impl LaneWave {
    /// The lane wave where it models the render: `mis` with fast marching; one light, a
    /// sphere, and no sky; objects marched in groups (boxes, spheres and planes, at most
    /// 32); the camera outside every solid. These are the scenes whose vertices it can
    /// shade in lanes (the Cornell box of issue 18); it gives the other wave's image, bit
    /// for bit, so the choice never changes one.
    pub fn of(estimator: &Estimator<'_>) -> Option<LaneWave> {
        let Estimator {
            scene,
            settings,
            march,
            ..
        } = estimator;
        let model = scene.scene();
        let &[Light::Sphere { .. }] = model.lights.as_slice() else {
            return None;
        };
        if settings.strategy != Strategy::Mis
            || settings.marching != Marching::Fast
            || model.sky.is_some()
            || model.objects.is_empty()
            || march.camera_inside
            || !scene.geometry.marches_in_groups()
        {
            return None;
        }
        let lighting = Lighting::of(scene, settings, march);
        if lighting.emitters.sampler.choice_reads_u() {
            return None;
        }
        let chosen = lighting.emitters.chosen_sphere(0.0)?;
        Some(LaneWave {
            sphere: AimedSphereLanes {
                center: chosen.sphere.center.into(),
                radius: chosen.sphere.radius,
                radiance: chosen.sphere.radiance.into(),
                pmf: chosen.pmf,
            },
        })
    }
}

/// A lane's path beside its rows: the sample it estimates and the order it started in.
struct Slot {
    id: SampleId,
    ordinal: u64,
}

/// A thread's buffers for the lane wave, kept from tile to tile.
#[derive(Default)]
pub(crate) struct LaneScratch {
    blocks: Vec<Block>,
    /// Each block's generators, where the independent kind's numbers are drawn in lanes.
    generators: Vec<PcgLanes<LANES>>,
    /// Each block's pixel samples, where the default kind's numbers are drawn in lanes.
    sobol: Vec<SobolXorLanes<LANES>>,
    slots: Vec<Option<Slot>>,
    /// Each lane's path's own copy of the sampler, where its numbers are drawn by it (not
    /// in lanes): kept apart from the slots, which are then a few words to start and end.
    samplers: Vec<Option<Sampler>>,
    ended: VecDeque<Option<(SampleId, Vec3)>>,
    /// The lanes whose hit is shaded this round, and the object each hit.
    lanes: Vec<usize>,
    objects: Vec<u32>,
    surface: SurfaceScratch,
    /// Lanes waiting for a path (the wave held back while estimates wait).
    vacant: Vec<usize>,
    /// Per block, a row's lanes as bits ([`lanes_where`]).
    masks: Vec<u32>,
}

/// `radiance_wave`'s contract, in lanes: the radiance of the pixel samples `next` gives,
/// estimated by one path each, handed to `estimate` in the order `next` gave them; up to
/// `width` paths in flight (rounded up to whole blocks of 16).
pub(crate) fn radiance_lanes(
    wave: &LaneWave,
    estimator: &Estimator<'_>,
    width: usize,
    next: &mut impl FnMut() -> Option<(SampleId, Ray, Sampler)>,
    (counters, stages): (&mut RayCounters, &mut StageTimes),
    s: &mut LaneScratch,
    estimate: &mut impl FnMut(SampleId, Vec3),
) {
    let Estimator {
        scene,
        settings,
        march,
        tracing,
        ..
    } = *estimator;
    let level = tracing.simd.or_widest();
    let lighting = Lighting::of(scene, settings, &march);
    let blocks = width.max(1).div_ceil(LANES);
    s.blocks.clear();
    s.blocks.resize(blocks, rows::EMPTY);
    // The independent and default kinds' numbers are drawn for a vector of paths at once
    // (`VertexNumbers`); the other kinds' by each path's sampler.
    let numbers_in_lanes = matches!(
        settings.sampler,
        SamplerKind::Independent | SamplerKind::SobolXor
    );
    s.generators.clear();
    s.generators.resize(blocks, PcgLanes::UNSET);
    s.sobol.clear();
    s.sobol.resize(blocks, SobolXorLanes::UNSET);
    s.slots.clear();
    s.slots.resize_with(blocks * LANES, || None);
    s.samplers.clear();
    s.samplers.resize_with(blocks * LANES, || None);
    s.ended.clear();
    s.vacant.clear();
    s.vacant.extend((0..blocks * LANES).rev());
    let (mut started, mut handed) = (0u64, 0u64);
    let mut dry = false;
    let mut clock = StageClock::start(stages);
    loop {
        // Start a path in every vacant lane, unless too many estimates wait.
        while !dry && s.ended.len() < ENDED_PER_SLOT * blocks * LANES {
            let Some(&lane) = s.vacant.last() else {
                break;
            };
            let Some((id, ray, sampler)) = next() else {
                dry = true;
                break;
            };
            s.vacant.pop();
            start(&mut s.blocks[lane / LANES], lane % LANES, ray);
            if let Some(generator) = sampler.independent_generator() {
                s.generators[lane / LANES].set(lane % LANES, generator);
            }
            if let Some(sample) = sampler.sobol_xor_sample() {
                s.sobol[lane / LANES].set(lane % LANES, sample);
            }
            if !numbers_in_lanes {
                s.samplers[lane] = Some(sampler);
            }
            s.slots[lane] = Some(Slot {
                id,
                ordinal: started,
            });
            started += 1;
            s.ended.push_back(None);
        }
        if s.vacant.len() == blocks * LANES {
            break;
        }
        clock.lap(Stage::StartPaths);

        let time = Instant::now();
        let before = [counters.camera.work(), counters.bounce.work()];
        // The level is available: `or_widest` says so.
        let _ = level.dispatch(PathRays {
            geometry: &scene.geometry,
            lights: &scene.scene().lights,
            camera: march.camera,
            secondary: march.secondary,
            blocks: &mut s.blocks,
            counters,
        });
        counters.timed_paths(time, before);
        clock.lap(Stage::PathRays);

        // What each path found, and the numbers of each vertex that scatters.
        s.lanes.clear();
        s.objects.clear();
        // The live lanes, found by their rows rather than by their slots.
        for lane in lanes_where(&s.blocks, rows::ALIVE, &mut s.masks) {
            let b = &mut s.blocks[lane / LANES];
            let l = lane % LANES;
            b[rows::SHADE][l] = 0.0;
            let outcome = path_outcome(b, l);
            let ray = Ray {
                origin: get3(b, rows::O, l),
                dir: get3(b, rows::D, l),
            };
            // Marched with these thresholds; the other parameters do not enter the hit.
            let params = TraceParams {
                eps_abs: b[rows::EPS_ABS][l],
                eps_rel: b[rows::EPS_REL][l],
                ..march.secondary
            };
            let light = b[rows::LIGHT][l];
            let hit = scene
                .surface_hit(
                    &ray,
                    &params,
                    false,
                    outcome,
                    Some(b[rows::NEAR][l] as usize),
                )
                .or_else(|| {
                    (light >= 0.0).then(|| Hit::Light {
                        t: b[rows::LIGHT_T][l],
                        light: light as usize,
                    })
                });
            let Some(on_surface) = SurfaceHit::of(hit) else {
                let previous = Previous {
                    p: get3(b, rows::FROM, l),
                    n: get3(b, rows::FROM_N, l),
                    in_solid: false,
                    emission: if b[rows::EMIT_MIS][l] > 0.0 {
                        EmissionWeight::PowerHeuristic {
                            bsdf_pdf: b[rows::EMIT_PDF][l],
                        }
                    } else {
                        EmissionWeight::Full
                    },
                };
                let beta = get3(b, rows::BETA, l);
                let radiance =
                    get3(b, rows::L, l) + emission_found(&lighting, &previous, &ray, hit, beta);
                set3(b, rows::L, l, radiance);
                b[rows::ENDED][l] = 1.0;
                continue;
            };
            let depth = b[rows::DEPTH][l] as u32;
            if depth >= settings.max_depth {
                b[rows::ENDED][l] = 1.0;
                continue;
            }
            let material = material_at(scene, on_surface);
            let (albedo, diffuse) = match material {
                Material::Lambertian { albedo } => (albedo, true),
                Material::Mirror { reflectance } => (reflectance, false),
            };
            b[rows::SHADE][l] = 1.0;
            b[rows::DIFFUSE][l] = if diffuse { 1.0 } else { 0.0 };
            set3(b, rows::ALBEDO, l, albedo);
            // The march's end and object are the hit's (`surface_hit` keeps them); its
            // shell is new.
            debug_assert_eq!(
                (on_surface.t, on_surface.object),
                (b[rows::T][l], b[rows::NEAR][l] as usize)
            );
            debug_assert!(!on_surface.inside, "the camera is outside every solid");
            b[rows::SHELL][l] = on_surface.epsilon;
            s.lanes.push(lane);
            s.objects.push(on_surface.object as u32);
            if numbers_in_lanes {
                continue;
            }
            let slot = s.slots[lane].as_ref().expect("a live lane's path");
            let sampler = s.samplers[lane].as_mut().expect("a path's own sampler");
            let mut u = VertexSample::UNSET;
            u.draw(
                sampler,
                slot.id.pixel,
                slot.id.index,
                depth,
                VertexReads::of(
                    settings.strategy,
                    diffuse,
                    false,
                    roulette_applies(depth + 1, settings.roulette_depth),
                ),
            );
            b[rows::U_EMITTER][l] = u.emitter.x;
            b[rows::U_EMITTER + 1][l] = u.emitter.y;
            b[rows::U_BSDF][l] = u.bsdf.x;
            b[rows::U_BSDF + 1][l] = u.bsdf.y;
            b[rows::U_ROULETTE][l] = u.roulette;
        }
        if numbers_in_lanes {
            // The level is available: `or_widest` says so.
            let numbers = if settings.sampler == SamplerKind::SobolXor {
                LaneNumbers::SobolXor(&s.sobol)
            } else {
                LaneNumbers::Independent(&mut s.generators)
            };
            let _ = level.dispatch(VertexNumbers {
                blocks: &mut s.blocks,
                numbers,
            });
        }
        clock.lap(Stage::VertexNumbers);

        SurfacePoint::at_source(
            scene,
            &march,
            level,
            &mut RowHits {
                blocks: &mut s.blocks,
                lanes: &s.lanes,
                objects: &s.objects,
            },
            &mut s.surface,
        );
        clock.lap(Stage::ShadingPoints);

        // The level is available: `or_widest` says so.
        let _ = level.dispatch(Shade {
            sphere: wave.sphere,
            blocks: &mut s.blocks,
        });
        // A mirror's bounce (`strategy::mirror`), and an estimate whose shadow ray does not
        // aim at its point, made again alone.
        for &lane in &s.lanes {
            let (b, l) = (&mut s.blocks[lane / LANES], lane % LANES);
            let diffuse = b[rows::DIFFUSE][l] > 0.0;
            if diffuse && b[rows::NEE][l] != 2.0 {
                continue;
            }
            let (ray, hit) = row_hit(b, l);
            let vertex = Vertex {
                at: &SurfacePoint {
                    p: get3(b, rows::P, l),
                    n: get3(b, rows::N, l),
                    origin: get3(b, rows::ORIGIN, l),
                    inside: false,
                },
                wo: -ray.dir,
                material: material_at(scene, hit),
            };
            if !diffuse {
                let bounce = strategy::mirror(&vertex, Vec2::ZERO);
                b[rows::WVALID][l] = if bounce.is_some() { 1.0 } else { 0.0 };
                if let Some(bounce) = bounce {
                    set3(b, rows::WI, l, bounce.wi);
                    set3(b, rows::WEIGHT, l, bounce.weight);
                    b[rows::WPDF][l] = bounce.pdf;
                }
                continue;
            }
            let mut u = VertexSample::UNSET;
            u.emitter = Vec2::new(b[rows::U_EMITTER][l], b[rows::U_EMITTER + 1][l]);
            match lighting.next_event(&vertex, &u, None) {
                Some((ray, contribution)) => {
                    b[rows::NEE][l] = 1.0;
                    set3(b, rows::SD, l, ray.ray.dir);
                    b[rows::SDIST][l] = ray.distance;
                    set3(b, rows::C, l, contribution);
                }
                None => b[rows::NEE][l] = 0.0,
            }
        }
        clock.lap(Stage::Shading);

        let time = Instant::now();
        // The level is available: `or_widest` says so.
        let _ = level.dispatch(ShadowRays {
            geometry: &scene.geometry,
            params: lighting.params,
            blocks: &mut s.blocks,
            counters: &mut counters.shadow,
        });
        counters.shadow.timed(time);
        clock.lap(Stage::ShadowRays);

        // The level is available: `or_widest` says so.
        let _ = level.dispatch(Scatter {
            roulette_depth: settings.roulette_depth,
            blocks: &mut s.blocks,
        });
        clock.lap(Stage::Scattering);

        // The paths that ended leave their estimates and their lanes, found by their rows.
        for lane in lanes_where(&s.blocks, rows::ENDED, &mut s.masks) {
            let (b, l) = (&mut s.blocks[lane / LANES], lane % LANES);
            (b[rows::ENDED][l], b[rows::ALIVE][l], b[rows::SHADE][l]) = (0.0, 0.0, 0.0);
            let Some(slot) = s.slots[lane].take() else {
                continue;
            };
            s.ended[(slot.ordinal - handed) as usize] = Some((slot.id, get3(b, rows::L, l)));
            s.vacant.push(lane);
        }
        while let Some(Some(_)) = s.ended.front() {
            let (id, l) = s.ended.pop_front().flatten().expect("an ended path");
            estimate(id, l);
            handed += 1;
        }
        clock.lap(Stage::Estimates);
    }
    debug_assert!(s.ended.is_empty(), "every estimate handed on");
}

/// The lanes whose `row` is not 0, in order, from one test of each block's row (its bits
/// kept in `masks`, so that the blocks can change while the lanes are visited).
fn lanes_where<'m>(
    blocks: &[Block],
    row: usize,
    masks: &'m mut Vec<u32>,
) -> impl Iterator<Item = usize> + use<'m> {
    masks.clear();
    masks.extend(blocks.iter().map(|b| {
        b[row]
            .iter()
            .enumerate()
            .fold(0u32, |m, (l, &x)| m | u32::from(x != 0.0) << l)
    }));
    masks.iter().enumerate().flat_map(|(v, &mask)| {
        let mut mask = mask;
        std::iter::from_fn(move || {
            (mask != 0).then(|| {
                let l = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                v * LANES + l
            })
        })
    })
}

/// Lane `l`'s path ray and the surface it hit, shaded this round.
#[inline(always)]
fn row_hit(b: &Block, l: usize) -> (Ray, SurfaceHit) {
    let ray = Ray {
        origin: get3(b, rows::O, l),
        dir: get3(b, rows::D, l),
    };
    let hit = SurfaceHit {
        t: b[rows::T][l],
        object: b[rows::NEAR][l] as usize,
        epsilon: b[rows::SHELL][l],
        inside: false,
    };
    (ray, hit)
}

/// The hits shaded this round, in the rows: hit `k` is lane `lanes[k]`'s, on object
/// `objects[k]` (kept apart too, so that grouping the hits by object reads one array), and
/// its shading point goes to its rows `P`, `N` and `ORIGIN` (not `inside`: the camera is
/// outside every solid, so no path is in one).
struct RowHits<'a> {
    blocks: &'a mut [Block],
    lanes: &'a [usize],
    objects: &'a [u32],
}

impl HitSource for RowHits<'_> {
    #[inline(always)]
    fn len(&self) -> usize {
        self.lanes.len()
    }

    #[inline(always)]
    fn object(&self, k: usize) -> usize {
        self.objects[k] as usize
    }

    #[inline(always)]
    fn hit(&self, k: usize) -> (Ray, SurfaceHit) {
        let lane = self.lanes[k];
        row_hit(&self.blocks[lane / LANES], lane % LANES)
    }

    #[inline(always)]
    fn put(&mut self, k: usize, point: SurfacePoint) {
        let lane = self.lanes[k];
        let (b, l) = (&mut self.blocks[lane / LANES], lane % LANES);
        set3(b, rows::P, l, point.p);
        set3(b, rows::N, l, point.n);
        set3(b, rows::ORIGIN, l, point.origin);
    }
}

/// A new path in lane `l` of `b`, with its camera ray: as `Path::START`.
fn start(b: &mut Block, l: usize, ray: Ray) {
    set3(b, rows::O, l, ray.origin);
    set3(b, rows::D, l, ray.dir);
    set3(b, rows::FROM, l, ray.origin);
    set3(b, rows::FROM_N, l, Vec3::ZERO);
    set3(b, rows::BETA, l, Vec3::ONE);
    set3(b, rows::L, l, Vec3::ZERO);
    b[rows::DEPTH][l] = 0.0;
    b[rows::EMIT_MIS][l] = 0.0;
    b[rows::EMIT_PDF][l] = 0.0;
    b[rows::ALIVE][l] = 1.0;
}

/// How lane `l`'s path ray's march ended.
fn path_outcome(b: &Block, l: usize) -> TraceOutcome {
    let (t, steps) = (b[rows::T][l], b[rows::STEPS][l] as u32);
    if b[rows::HIT][l] > 0.0 {
        TraceOutcome::Hit { t, steps }
    } else if b[rows::GAVE_UP][l] > 0.0 {
        TraceOutcome::GaveUp { t, steps }
    } else {
        TraceOutcome::Miss { steps }
    }
}
