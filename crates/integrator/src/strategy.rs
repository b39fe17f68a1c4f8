//! The ways a path chooses its next direction, as pieces: the named sample
//! layout of a vertex, one function per strategy returning a [`Scatter`],
//! next-event estimation and delta lights through a [`Lighting`] context,
//! and the MIS weights in one place ([`EmissionWeight`],
//! [`next_event_weight_lanes`]). Every function here is a pure function of its
//! inputs (and the counters it is handed), so a tracer of batches of rays
//! can call them per ray.

use glam::{Vec2, Vec3};
use lueur_materials::{CosineScatterLanes, HemisphereSampling, Material};
use lueur_sampling::{
    Sampler, power_heuristic, power_heuristic_lanes, sample_cosine_hemisphere_lanes,
};
use lueur_sdf_math::{
    Lane, LaneGroups, LaneKernel, LaneVec3, MAX_LANES, Ray, SimdLevel, TraceParams,
};

use crate::light_sampler::{Drawn, Emitters};
use crate::next_event::{DiffuseLanes, LightSampleLanes, NextEventLanes};
use crate::surface::{March, SurfacePoint};
use lueur_scene::{RenderSettings, Strategy};

use crate::PreparedScene;
use crate::trace::ShadowRay;

/// Sampler dimensions consumed per path vertex, so that each bounce reads the same
/// dimensions whatever happened before (low-discrepancy point sets keep their structure per
/// bounce): the fields of [`VertexSample`] and one spare.
pub(crate) const DIMS_PER_VERTEX: u32 = 8;
/// Dimensions before the first vertex: the position in the pixel.
pub(crate) const CAMERA_DIMS: u32 = 2;
/// The first dimension of the vertex at `depth` ([`VertexSample::draw`] reads from it on).
pub(crate) const fn vertex_dimension(depth: u32) -> u32 {
    CAMERA_DIMS + depth * DIMS_PER_VERTEX
}

/// The random numbers of one vertex, in the order they are drawn (the spare
/// eighth dimension is not drawn).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct VertexSample {
    /// Which emitter light sampling aims at.
    pub emitter_choice: f32,
    /// The point on that emitter.
    pub emitter: Vec2,
    /// Which half of the mixture strategy samples.
    pub mixture: f32,
    /// The BSDF's direction.
    pub bsdf: Vec2,
    /// Whether Russian roulette ends the path.
    pub roulette: f32,
}

impl VertexSample {
    /// Where `emitter`, `bsdf` and `roulette` lie among a vertex's dimensions, in the
    /// order [`VertexSample::draw`] takes them (`emitter_choice` at 0, `mixture` at 3).
    pub const EMITTER_DIM: usize = 1;
    pub const BSDF_DIM: usize = 4;
    pub const ROULETTE_DIM: usize = 6;

    /// Every number 0: a slot for [`VertexSample::draw`] to fill.
    pub const UNSET: VertexSample = VertexSample {
        emitter_choice: 0.0,
        emitter: Vec2::ZERO,
        mixture: 0.0,
        bsdf: Vec2::ZERO,
        roulette: 0.0,
    };

    /// Draws into `self` the numbers of vertex `depth` of sample `index` of `pixel` that
    /// anything will read (`reads`); the others are skipped (left 0), which changes no
    /// number drawn: each has its dimension whatever is drawn before it. Filled in place,
    /// a field at a time, as each number is drawn.
    #[inline]
    pub fn draw(
        &mut self,
        sampler: &mut Sampler,
        pixel: [u32; 2],
        index: u32,
        depth: u32,
        reads: VertexReads,
    ) {
        sampler.start_pixel_sample(pixel, index, vertex_dimension(depth));
        self.emitter_choice = next_1d_read(sampler, reads.emitter_choice);
        self.emitter = next_2d_read(sampler, reads.emitter);
        self.mixture = next_1d_read(sampler, reads.mixture);
        self.bsdf = next_2d_read(sampler, reads.bsdf);
        // The last number: nothing after it to skip to.
        self.roulette = if reads.roulette {
            sampler.next_1d()
        } else {
            0.0
        };
    }
}

/// The sampler's next number where it is `read`; else 0, the number skipped.
#[inline(always)]
fn next_1d_read(sampler: &mut Sampler, read: bool) -> f32 {
    if read {
        sampler.next_1d()
    } else {
        sampler.skip(1);
        0.0
    }
}

/// The sampler's next two numbers where they are `read`; else 0, the numbers skipped.
#[inline(always)]
fn next_2d_read(sampler: &mut Sampler, read: bool) -> Vec2 {
    if read {
        sampler.next_2d()
    } else {
        sampler.skip(2);
        Vec2::ZERO
    }
}

/// Which of a vertex's numbers ([`VertexSample`]) anything reads: only those are drawn
/// (with the hashed samplers, each is a chain of 64-bit hashes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct VertexReads {
    pub emitter_choice: bool,
    pub emitter: bool,
    pub mixture: bool,
    pub bsdf: bool,
    pub roulette: bool,
}

impl VertexReads {
    /// Every number.
    #[cfg(test)]
    pub const ALL: VertexReads = VertexReads {
        emitter_choice: true,
        emitter: true,
        mixture: true,
        bsdf: true,
        roulette: true,
    };

    /// What `strategy` reads at a vertex: a mirror reads no number of its own (its
    /// direction is fixed, and no strategy samples an emitter there); a diffuse vertex
    /// reads the emitter's numbers where the strategy samples emitters (the choice only
    /// where there is one, `chooses`), the mixture's where it mixes, and the BSDF's
    /// unless it samples lights only. The roulette number is read where roulette may end
    /// the path after this vertex (`roulette`).
    pub fn of(strategy: Strategy, diffuse: bool, chooses: bool, roulette: bool) -> VertexReads {
        let emitters = diffuse && samples_emitters(strategy);
        VertexReads {
            emitter_choice: emitters && chooses,
            emitter: emitters,
            mixture: diffuse && strategy == Strategy::Mixture,
            bsdf: diffuse && strategy != Strategy::Light,
            roulette,
        }
    }
}

/// A scattering vertex as the strategies see it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Vertex<'a> {
    /// The shading point, its normal and where rays leave from: borrowed from the wave's
    /// shading points, since a copy made on the stack a field at a time and read back a
    /// vector at a time waits for its stores (docs/PERFORMANCE.md, "Stores loaded whole").
    pub at: &'a SurfacePoint,
    /// Unit direction toward where the path came from.
    pub wo: Vec3,
    /// What the surface is made of.
    pub material: Material,
}

/// How emission found along a sampled direction counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum EmissionWeight {
    /// In full: camera rays, delta bounces, and every strategy but `mis`.
    Full,
    /// By the power heuristic of `bsdf_pdf` against the pdf next-event
    /// estimation had for the same direction, which has counted the rest.
    PowerHeuristic {
        /// The pdf with which the BSDF chose the direction.
        bsdf_pdf: f32,
    },
}

impl EmissionWeight {
    /// The weight of emission found along the direction; `light_pdf` is the
    /// pdf next-event estimation would have had for it, asked only if needed.
    pub fn weight(self, light_pdf: impl FnOnce() -> f32) -> f32 {
        match self {
            EmissionWeight::Full => 1.0,
            EmissionWeight::PowerHeuristic { bsdf_pdf } => {
                power_heuristic(1.0, bsdf_pdf, 1.0, light_pdf())
            }
        }
    }
}

/// The weight of a next-event sample of pdf `light_pdf` against the BSDF
/// sampling of `mis`, which could have found it with `bsdf_pdf`, per lane: the other
/// half of [`EmissionWeight::PowerHeuristic`].
#[inline(always)]
pub(crate) fn next_event_weight_lanes<L: Lane>(light_pdf: L, bsdf_pdf: L) -> L {
    power_heuristic_lanes(L::splat(1.0), light_pdf, L::splat(1.0), bsdf_pdf)
}

/// The BSDF sampling that `mis` combines with next-event estimation.
pub(crate) const MIS_HEMISPHERE: HemisphereSampling = HemisphereSampling::Cosine;

/// Where a path goes next from a vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Scatter {
    /// Unit direction of the next ray.
    pub wi: Vec3,
    /// What the throughput is multiplied by: `f cos / pdf`.
    pub weight: Vec3,
    /// The solid-angle pdf of `wi` (0 for a delta event).
    pub pdf: f32,
    /// How emission found along `wi` counts.
    pub emission: EmissionWeight,
}

/// A delta bounce on a mirror, followed by every strategy.
pub(crate) fn mirror(v: &Vertex<'_>, u_bsdf: Vec2) -> Option<Scatter> {
    let s = v
        .material
        .sample(v.wo, v.at.n, u_bsdf, HemisphereSampling::Cosine)?;
    Some(Scatter {
        wi: s.wi,
        weight: s.weight(v.at.n),
        pdf: 0.0,
        emission: EmissionWeight::Full,
    })
}

/// The direction of `strategy` at a diffuse vertex; `cosine` is the BSDF's sample of
/// `u.bsdf` by the cosine where the wave drew it already ([`CosineScatters`]).
#[inline]
pub(crate) fn scatter(
    strategy: Strategy,
    emitters: &Emitters<'_>,
    v: &Vertex<'_>,
    u: &VertexSample,
    cosine: Option<Option<DrawnScatter>>,
) -> Option<Scatter> {
    match strategy {
        Strategy::Uniform => hemisphere(v, HemisphereSampling::Uniform, u.bsdf, None),
        Strategy::Cosine => hemisphere(v, HemisphereSampling::Cosine, u.bsdf, cosine),
        Strategy::Light => toward_emitters(emitters, v, u.emitter_choice, u.emitter),
        Strategy::Mixture => mixture(emitters, v, u),
        Strategy::Mis => mis_bsdf(v, u.bsdf, cosine),
    }
}

/// [`scatter`], written into `out`; `cosine` is the index of the vertex's request in
/// `scatters` where the wave drew its sample by the cosine. MIS, the default, is written
/// inline, from the drawn rows into the slot a field at a time; the other strategies go
/// through a call. Through one `match`, or through [`CosineScatters::drawn`]'s `Option`,
/// the results meet in a temporary stored in pieces and loaded whole, and the shading
/// waits on the load (docs/PERFORMANCE.md, "Stores loaded whole").
#[inline(always)]
pub(crate) fn scatter_into(
    strategy: Strategy,
    emitters: &Emitters<'_>,
    v: &Vertex<'_>,
    u: &VertexSample,
    (scatters, cosine): (&CosineScatters, Option<usize>),
    out: &mut Option<Scatter>,
) {
    match (strategy, cosine) {
        (Strategy::Mis, Some(k)) => {
            scatters.mis_bsdf_into(k, out);
            debug_assert_eq!(*out, mis_bsdf(v, u.bsdf, None));
        }
        (Strategy::Mis, None) => *out = mis_bsdf(v, u.bsdf, None),
        _ => {
            let cosine = cosine.map(|k| scatters.drawn(k));
            scatter_out_of_line(strategy, emitters, v, u, cosine, out);
        }
    }
}

#[inline(never)]
fn scatter_out_of_line(
    strategy: Strategy,
    emitters: &Emitters<'_>,
    v: &Vertex<'_>,
    u: &VertexSample,
    cosine: Option<Option<DrawnScatter>>,
    out: &mut Option<Scatter>,
) {
    *out = scatter(strategy, emitters, v, u, cosine);
}

/// Whether `strategy` ever samples a point on an emitter (and so reads a vertex's
/// emitter numbers): next-event estimation, or a scatter toward the lights.
fn samples_emitters(strategy: Strategy) -> bool {
    match strategy {
        Strategy::Light | Strategy::Mixture | Strategy::Mis => true,
        Strategy::Uniform | Strategy::Cosine => false,
    }
}

/// Whether `strategy` scatters from a diffuse vertex by cosine sampling, whose
/// samples a wave draws in lanes ([`CosineScatters`]).
pub(crate) fn scatters_by_cosine(strategy: Strategy) -> bool {
    match strategy {
        Strategy::Cosine => true,
        Strategy::Mis => MIS_HEMISPHERE == HemisphereSampling::Cosine,
        Strategy::Uniform | Strategy::Light | Strategy::Mixture => false,
    }
}

/// A diffuse vertex's sample of its BSDF by the cosine, as a wave draws it
/// ([`CosineScatters`]): the direction, its weight `f |cos| / pdf`, and its pdf.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DrawnScatter {
    pub wi: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
}

/// The inputs of a request in [`CosineScatters`], a row each: `u`, the albedo, `wo`, the
/// normal.
const SCATTER_INPUTS: usize = 11;
/// The outputs of a request in [`CosineScatters`], a row each: `wi`, the weight, the
/// pdf, and 1 where the sample carries weight (0 where it has none).
const SCATTER_OUTPUTS: usize = 8;

/// The samples by the cosine that a wave's Lambertian vertices scatter by, drawn
/// together, a request per lane ([`CosineScatterLanes`]): each is the bits
/// [`Material::sample`] and its weight give for it alone, whatever its company and the
/// SIMD level. One is a chain of a sine and cosine, a square root and two divisions that
/// the vertex's shading would wait on; in lanes, a vector of them costs about what
/// one does. The samples are kept as the requests are ([`LaneGroups`]): request `k`'s is
/// lane `k % MAX_LANES` of group `k / MAX_LANES`.
#[derive(Debug, Default)]
pub(crate) struct CosineScatters {
    /// Per request, its inputs.
    inputs: LaneGroups<SCATTER_INPUTS>,
    /// Per group of requests, after [`CosineScatters::draw`]: their samples, a row each.
    drawn: Vec<[[f32; MAX_LANES]; SCATTER_OUTPUTS]>,
}

impl CosineScatters {
    pub fn clear(&mut self) {
        self.inputs.clear();
    }

    /// Asks for the sample of `u` at a Lambertian vertex of `albedo` with normal `n`, seen
    /// along `wo`; its index in the drawn samples.
    #[inline(always)]
    pub fn request(&mut self, u: Vec2, albedo: Vec3, wo: Vec3, n: Vec3) -> usize {
        self.inputs.push([
            u.x, u.y, albedo.x, albedo.y, albedo.z, wo.x, wo.y, wo.z, n.x, n.y, n.z,
        ])
    }

    /// Request `k`'s sample, after [`CosineScatters::draw`]; `None` where it carries no
    /// weight.
    #[inline(always)]
    pub fn drawn(&self, k: usize) -> Option<DrawnScatter> {
        debug_assert!(k < self.inputs.len());
        let [wx, wy, wz, fx, fy, fz, pdf, valid] = &self.drawn[k / MAX_LANES];
        let lane = k % MAX_LANES;
        (valid[lane] != 0.0).then(|| DrawnScatter {
            wi: Vec3::new(wx[lane], wy[lane], wz[lane]),
            weight: Vec3::new(fx[lane], fy[lane], fz[lane]),
            pdf: pdf[lane],
        })
    }

    /// [`mis_bsdf`] of request `k`'s sample, after [`CosineScatters::draw`], written
    /// into `out` a field at a time from the rows.
    #[inline(always)]
    pub fn mis_bsdf_into(&self, k: usize, out: &mut Option<Scatter>) {
        debug_assert!(k < self.inputs.len());
        let [wx, wy, wz, fx, fy, fz, pdf, valid] = &self.drawn[k / MAX_LANES];
        let lane = k % MAX_LANES;
        if valid[lane] == 0.0 {
            *out = None;
            return;
        }
        let pdf = pdf[lane];
        *out = Some(Scatter {
            wi: Vec3::new(wx[lane], wy[lane], wz[lane]),
            weight: Vec3::new(fx[lane], fy[lane], fz[lane]),
            pdf,
            emission: EmissionWeight::PowerHeuristic { bsdf_pdf: pdf },
        });
    }

    /// How many requests were drawn.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.inputs.len()
    }

    /// Draws every request's sample on `level` (the widest available where it is not).
    pub fn draw(&mut self, level: SimdLevel) {
        let inputs = self.inputs.groups();
        self.drawn
            .resize(inputs.len(), [[0.0; MAX_LANES]; SCATTER_OUTPUTS]);
        // The level is available: `or_widest` says so.
        let _ = level.or_widest().dispatch(DrawScatters {
            inputs,
            drawn: &mut self.drawn,
        });
    }
}

/// The kernel of [`CosineScatters::draw`].
struct DrawScatters<'a> {
    inputs: &'a [[[f32; MAX_LANES]; SCATTER_INPUTS]],
    drawn: &'a mut [[[f32; MAX_LANES]; SCATTER_OUTPUTS]],
}

impl LaneKernel for DrawScatters<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(self) {
        let DrawScatters { inputs, drawn } = self;
        let width = L::LANES.min(MAX_LANES);
        debug_assert_eq!(MAX_LANES % width, 0);
        for (input, out) in inputs.iter().zip(drawn) {
            for start in (0..MAX_LANES).step_by(width) {
                let lanes = start..start + width;
                // Not closures: they would be compiled apart from the kernel's features.
                let mut rows = [L::splat(0.0); SCATTER_INPUTS];
                for (lane, row) in rows.iter_mut().zip(input) {
                    *lane = L::load(&row[lanes.clone()]);
                }
                let [u0, u1, ax, ay, az, ox, oy, oz, nx, ny, nz] = rows;
                let local = sample_cosine_hemisphere_lanes([u0, u1]);
                let s = CosineScatterLanes::new(
                    LaneVec3::new(ax, ay, az),
                    LaneVec3::new(ox, oy, oz),
                    LaneVec3::new(nx, ny, nz),
                    local,
                );
                let valid = L::select(s.valid, L::splat(1.0), L::splat(0.0));
                let values = [
                    s.wi.x, s.wi.y, s.wi.z, s.weight.x, s.weight.y, s.weight.z, s.pdf, valid,
                ];
                for (row, value) in out.iter_mut().zip(values) {
                    value.store(&mut row[lanes.clone()]);
                }
            }
        }
    }
}

/// Whether `strategy` adds next-event estimation (a shadow ray toward a chosen emitter) at
/// each diffuse vertex, besides the direction it scatters in; the weight of emission found
/// along that direction then accounts for it.
pub(crate) fn uses_next_event(strategy: Strategy) -> bool {
    match strategy {
        Strategy::Mis => true,
        Strategy::Uniform | Strategy::Cosine | Strategy::Light | Strategy::Mixture => false,
    }
}

/// `uniform` and `cosine`: BSDF sampling over the hemisphere; emission found
/// later counts in full.
pub(crate) fn hemisphere(
    v: &Vertex<'_>,
    hemisphere: HemisphereSampling,
    u: Vec2,
    drawn: Option<Option<DrawnScatter>>,
) -> Option<Scatter> {
    let s = bsdf_sample(v, hemisphere, u, drawn)?;
    Some(Scatter {
        wi: s.wi,
        weight: s.weight,
        pdf: s.pdf,
        emission: EmissionWeight::Full,
    })
}

/// The BSDF's sample of `u` at the vertex, and its weight: `drawn` where the wave drew it
/// ([`CosineScatters`], the same bits), else drawn here.
#[inline(always)]
fn bsdf_sample(
    v: &Vertex<'_>,
    hemisphere: HemisphereSampling,
    u: Vec2,
    drawn: Option<Option<DrawnScatter>>,
) -> Option<DrawnScatter> {
    let alone = || {
        let s = v.material.sample(v.wo, v.at.n, u, hemisphere)?;
        Some(DrawnScatter {
            wi: s.wi,
            weight: s.weight(v.at.n),
            pdf: s.pdf,
        })
    };
    match drawn {
        Some(drawn) => {
            debug_assert_eq!(drawn, alone());
            drawn
        }
        None => alone(),
    }
}

/// `light`: a direction toward a chosen emitter only, with the pdf summed over every
/// emitter (biased: directions no emitter subtends are never taken).
pub(crate) fn toward_emitters(
    emitters: &Emitters<'_>,
    v: &Vertex<'_>,
    u_choice: f32,
    u: Vec2,
) -> Option<Scatter> {
    let (p, n) = (v.at.p, v.at.n);
    let (es, _) = emitters.sample(p, n, u_choice, u)?;
    let pdf = emitters.pdf(p, n, es.wi);
    weighted(v, es.wi, pdf)
}

/// `mixture`: one-sample MIS, the uniform hemisphere or an emitter with
/// probability 1/2 each, weighted by [`mixture_pdf`].
pub(crate) fn mixture(
    emitters: &Emitters<'_>,
    v: &Vertex<'_>,
    u: &VertexSample,
) -> Option<Scatter> {
    let use_light = emitters.any() && u.mixture >= 0.5;
    let wi = if use_light {
        emitters
            .sample(v.at.p, v.at.n, u.emitter_choice, u.emitter)?
            .0
            .wi
    } else {
        v.material
            .sample(v.wo, v.at.n, u.bsdf, HemisphereSampling::Uniform)?
            .wi
    };
    weighted(v, wi, mixture_pdf(emitters, v, wi))
}

/// The pdf with which [`mixture`] picks `wi`: the average of the uniform hemisphere's and
/// the emitters', or the hemisphere's alone without emitters.
pub(crate) fn mixture_pdf(emitters: &Emitters<'_>, v: &Vertex<'_>, wi: Vec3) -> f32 {
    let hemisphere_pdf = v
        .material
        .pdf(v.wo, wi, v.at.n, HemisphereSampling::Uniform);
    if emitters.any() {
        0.5 * hemisphere_pdf + 0.5 * emitters.pdf(v.at.p, v.at.n, wi)
    } else {
        hemisphere_pdf
    }
}

/// `mis`'s BSDF half: cosine sampling, with emission found along it weighted against
/// next-event estimation ([`Lighting::next_event`] is the other half).
///
/// Always inlined: out of line, its result comes back through memory, stored in pieces
/// and loaded whole.
#[inline(always)]
pub(crate) fn mis_bsdf(
    v: &Vertex<'_>,
    u: Vec2,
    drawn: Option<Option<DrawnScatter>>,
) -> Option<Scatter> {
    let s = bsdf_sample(v, MIS_HEMISPHERE, u, drawn)?;
    Some(Scatter {
        wi: s.wi,
        weight: s.weight,
        pdf: s.pdf,
        emission: EmissionWeight::PowerHeuristic { bsdf_pdf: s.pdf },
    })
}

/// A direction `wi` chosen with `pdf` by a strategy that does not sample the
/// BSDF; `None` where it carries no weight.
fn weighted(v: &Vertex<'_>, wi: Vec3, pdf: f32) -> Option<Scatter> {
    let n = v.at.n;
    let f = v.material.eval(v.wo, wi, n);
    if !(pdf > 0.0) || f == Vec3::ZERO {
        return None;
    }
    Some(Scatter {
        wi,
        weight: f * n.dot(wi).abs() / pdf,
        pdf,
        emission: EmissionWeight::Full,
    })
}

/// What shadow rays need: the scene to trace them in, its emitters, and how
/// secondary rays are marched.
#[derive(Clone, Copy)]
pub(crate) struct Lighting<'a> {
    pub scene: &'a PreparedScene,
    pub emitters: Emitters<'a>,
    pub params: TraceParams,
    /// Whether any light is a delta light, which only [`Lighting::delta_lights`] reaches.
    pub any_delta: bool,
}

impl<'a> Lighting<'a> {
    /// The lighting of `scene` rendered with `settings`, secondary rays marched as
    /// `march` says.
    pub fn of(scene: &'a PreparedScene, settings: &RenderSettings, march: &March) -> Lighting<'a> {
        Lighting {
            scene,
            emitters: scene.emitters(settings.quad_sampling),
            params: march.secondary,
            any_delta: (scene.scene().lights.iter()).any(|l| l.delta_arrival().is_some()),
        }
    }

    /// The light every delta light would bring, with the shadow ray each needs (a delta
    /// light can be reached no other way), pushed to `contributions` and `rays` in the
    /// lights' order; the vertex gathers the sum of those whose ray is free, in that order.
    /// Pushed where they are made: through a `Vec` of pairs, or built whole, the ray's
    /// origin is stored in pieces and loaded whole (docs/PERFORMANCE.md, "Stores loaded
    /// whole").
    #[inline]
    pub fn delta_lights(
        &self,
        v: &Vertex<'_>,
        rays: &mut Vec<ShadowRay>,
        contributions: &mut Vec<Vec3>,
    ) {
        // Most scenes have none: their vertices skip the loop over the lights.
        if !self.any_delta {
            return;
        }
        let (n, wo, origin) = (v.at.n, v.wo, v.at.origin);
        for light in &self.scene.scene().lights {
            let Some((wi, irradiance)) = light.delta_arrival() else {
                continue;
            };
            let cos = n.dot(wi);
            if cos <= 0.0 {
                continue;
            }
            let f = v.material.eval(wo, wi, n);
            if f == Vec3::ZERO {
                continue;
            }
            rays.push(ShadowRay::UNSET);
            let slot = rays.last_mut().expect("pushed");
            slot.ray = Ray::new(origin, wi);
            slot.distance = f32::INFINITY;
            contributions.push(f * irradiance * cos);
        }
    }

    /// Next-event estimation toward one chosen emitter, weighted against `mis`'s BSDF
    /// sampling by [`next_event_weight_lanes`]: what it brings if its shadow ray is free, with
    /// that ray; `None` where it brings nothing whatever the ray finds.
    ///
    /// `drawn` is the chosen emitter's direction sample where the wave drew it already
    /// ([`crate::light_sampler::SphereNextEvents`], [`crate::light_sampler::RectangleDraws`],
    /// or the sky's in [`crate::light_sampler::CosineDraws`]), `None` otherwise.
    #[inline]
    pub fn next_event(
        &self,
        v: &Vertex<'_>,
        u: &VertexSample,
        drawn: Option<Drawn<'_>>,
    ) -> Option<(ShadowRay, Vec3)> {
        let (es, light) =
            self.emitters
                .sample_drawn(v.at.p, v.at.n, u.emitter_choice, u.emitter, drawn)?;
        // A mirror's BSDF is 0 toward any sampled direction.
        let Material::Lambertian { albedo } = v.material else {
            return None;
        };
        let vertex = DiffuseLanes {
            p: v.at.p.into(),
            origin: v.at.origin.into(),
            n: v.at.n.into(),
            wo_n: v.wo.dot(v.at.n),
            albedo: albedo.into(),
        };
        let sample = LightSampleLanes {
            wi: es.wi.into(),
            distance: es.distance,
            pdf: es.pdf,
            radiance: es.radiance.into(),
        };
        let e = NextEventLanes::new(&vertex, &sample);
        if !e.weighs {
            return None;
        }
        let (ray, distance) = v.at.shadow_ray(es.wi, es.distance);
        let ray = ShadowRay {
            ray,
            distance,
            target: light,
        };
        Some((ray, e.contribution(&sample).into()))
    }
}

#[cfg(test)]
mod tests {
    //! Each strategy's directions against the pdf it reports: Pearson's
    //! chi-square in equal-solid-angle bins over the hemisphere of the
    //! normal (`lueur_stats::DirectionBins`), after checking that the pdf
    //! each sample reports is the strategy's pdf at its direction.
    use super::*;
    use crate::light_sampler::{CosineDraws, RectangleDraws};
    use lueur_sampling::SamplerKind;
    use lueur_scene::{Camera, Light, QuadSampling, Scene};
    use lueur_stats::DirectionBins;

    /// `draw` takes each number at the dimension `VertexSample::*_DIM` names, the lane
    /// wave's kernel reading them from the independent kind's stream.
    #[test]
    fn a_vertex_s_numbers_lie_at_their_dimensions() {
        let mut sampler = Sampler::for_render(SamplerKind::Independent, 3, [16, 16], 8, 1);
        let (pixel, index, depth) = ([5, 9], 6, 2);
        let mut u = VertexSample::UNSET;
        let reads = VertexReads::of(Strategy::Mixture, true, true, true);
        u.draw(&mut sampler, pixel, index, depth, reads);
        let mut dims = [0.0f32; DIMS_PER_VERTEX as usize];
        sampler.start_pixel_sample(pixel, index, vertex_dimension(depth));
        for d in &mut dims {
            *d = sampler.next_1d();
        }
        let at = |k: usize| dims[k].to_bits();
        assert_eq!(u.emitter.x.to_bits(), at(VertexSample::EMITTER_DIM));
        assert_eq!(u.emitter.y.to_bits(), at(VertexSample::EMITTER_DIM + 1));
        assert_eq!(u.bsdf.x.to_bits(), at(VertexSample::BSDF_DIM));
        assert_eq!(u.bsdf.y.to_bits(), at(VertexSample::BSDF_DIM + 1));
        assert_eq!(u.roulette.to_bits(), at(VertexSample::ROULETTE_DIM));
        assert_eq!(u.emitter_choice.to_bits(), at(0));
        assert_eq!(u.mixture.to_bits(), at(3));
    }

    const N_SAMPLES: usize = 200_000;
    const N_Z: usize = 16;
    const N_PHI: usize = 32;
    /// Midpoint sub-grid per bin: fine enough that the bins straddling a
    /// light's edge are integrated to well under one standard deviation.
    const SUB: usize = 16;
    /// A correct strategy is rejected with probability 1e-4 (seeds are
    /// fixed, so a pass is reproducible); a pdf off by a few percent over a
    /// light's cone is rejected with p far below it.
    const SIGNIFICANCE: f64 = 1e-4;

    /// Uniform numbers in [0, 1) from a fixed seed (SplitMix64).
    fn uniforms(seed: u64) -> impl FnMut() -> f32 {
        let mut state = seed;
        move || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    fn vertex_sample(next: &mut impl FnMut() -> f32) -> VertexSample {
        VertexSample {
            emitter_choice: next(),
            emitter: Vec2::new(next(), next()),
            mixture: next(),
            bsdf: Vec2::new(next(), next()),
            roulette: next(),
        }
    }

    /// A diffuse vertex at the origin facing +y, seen from above at a slant.
    fn vertex() -> Vertex<'static> {
        const AT: SurfacePoint = SurfacePoint {
            p: Vec3::ZERO,
            n: Vec3::Y,
            origin: Vec3::new(0.0, 1e-5, 0.0),
            inside: false,
        };
        Vertex {
            at: &AT,
            wo: Vec3::new(0.3, 1.0, 0.2).normalize(),
            material: Material::Lambertian {
                albedo: Vec3::splat(0.7),
            },
        }
    }

    /// A sphere light and a quad light above the vertex, apart, facing it;
    /// and a sky if asked.
    fn scene(sky: bool) -> PreparedScene {
        let lights = vec![
            Light::Sphere {
                center: Vec3::new(-2.0, 3.0, 0.5),
                radius: 1.0,
                radiance: Vec3::ONE,
            },
            Light::Quad {
                corner: Vec3::new(1.0, 2.5, -1.0),
                edge_u: Vec3::new(2.0, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 0.0, 2.0),
                radiance: Vec3::ONE,
            },
        ];
        let camera = Camera::new(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap();
        let sky = sky.then_some(Vec3::splat(0.5));
        Scene::new(vec![], vec![], lights, sky, camera)
            .unwrap()
            .into()
    }

    /// Draws `sample` `N_SAMPLES` times; every reported pdf must be `pdf` at
    /// the direction drawn, and the directions must fit `pdf`.
    fn check(
        name: &str,
        seed: u64,
        sample: impl Fn(&VertexSample) -> Option<(Vec3, f32)>,
        pdf: impl Fn(Vec3) -> f32,
    ) {
        let sample = |u: &VertexSample| sample(u).map(|(wi, reported)| (wi, reported, pdf(wi)));
        check_reporting(name, seed, sample, &pdf);
    }

    /// [`check`] where `sample` also says which pdf it should have reported
    /// (next-event estimation reports the pdf of the emitter it chose, not
    /// the sum over the emitters that `pdf` is).
    fn check_reporting(
        name: &str,
        seed: u64,
        sample: impl Fn(&VertexSample) -> Option<(Vec3, f32, f32)>,
        pdf: impl Fn(Vec3) -> f32,
    ) {
        let mut next = uniforms(seed);
        let mut directions = Vec::with_capacity(N_SAMPLES);
        for _ in 0..N_SAMPLES {
            let Some((wi, reported, expected)) = sample(&vertex_sample(&mut next)) else {
                continue;
            };
            assert!(
                (reported - expected).abs() <= 1e-4 * expected,
                "{name}: reports pdf {reported} for {wi}, where its pdf is {expected}"
            );
            directions.push(wi);
        }
        assert!(
            directions.len() >= N_SAMPLES * 999 / 1000,
            "{name}: only {} of {N_SAMPLES} samples drawn",
            directions.len()
        );
        let bins = DirectionBins::new(Vec3::Y, 0.0, N_Z, N_PHI);
        let test = bins.test(directions, &pdf, SUB);
        assert!(test.accepts(SIGNIFICANCE), "{name}: {test:?}");
    }

    /// A wave's cosine directions drawn in lanes are the bits each gets alone, on every
    /// SIMD level and for any number of requests (a short last vector included), at the
    /// ends of the square and its centre too.
    #[test]
    fn cosine_draws_are_each_sample_alone() {
        let mut u = uniforms(9);
        let mut requests: Vec<Vec2> = (0..37).map(|_| Vec2::new(u(), u())).collect();
        let ends = [0.0, 0.5, lueur_sampling::ONE_MINUS_EPSILON];
        requests.extend(ends.iter().flat_map(|&a| ends.map(|b| Vec2::new(a, b))));
        for level in SimdLevel::available() {
            for n in [1, 7, 16, 17, requests.len()] {
                let mut draws = CosineDraws::default();
                let indices: Vec<usize> = requests[..n].iter().map(|&u| draws.request(u)).collect();
                draws.draw(level);
                assert_eq!(draws.len(), n);
                for (&k, &u) in indices.iter().zip(&requests) {
                    let alone = lueur_sampling::sample_cosine_hemisphere(u);
                    assert_eq!(draws.drawn(k), alone, "{level:?}, {n} requests, u = {u}");
                }
            }
        }
    }

    /// A wave's next-event estimates toward sphere lights, made in lanes, are the bits
    /// [`Lighting::next_event`] gives for each vertex alone (nothing where it gives none;
    /// the shadow ray's direction and length and what it brings where it aims at its
    /// point), on every SIMD level and for any number of requests, after a wave whose
    /// requests stay in the lanes past this one's: points outside the spheres, inside
    /// them, at their centres and far away, at the ends of the square, viewers on both
    /// sides, five lights to choose among.
    #[test]
    fn sphere_next_events_are_each_estimate_alone() {
        use crate::light_sampler::{SphereNextEvent, SphereNextEvents};
        use crate::next_event::DiffuseLanes;
        use crate::surface::SurfacePoint;
        use lueur_sdf_math::Sdf;

        let mut u = uniforms(17);
        let lights: Vec<Light> = (0..5)
            .map(|_| Light::Sphere {
                center: Vec3::new(u() - 0.5, 1.0 + u(), u() - 0.5),
                radius: 0.05 + 0.3 * u(),
                radiance: Vec3::new(1.0 + u(), 2.0, 0.5 + u()),
            })
            .collect();
        let camera = Camera::new(Vec3::new(0.0, 0.5, 3.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap();
        let objects = vec![lueur_scene::Object {
            sdf: Sdf::sphere(0.5),
            material: 0,
        }];
        let albedo = Vec3::new(0.7, 0.4, 0.2);
        let material = Material::Lambertian { albedo };
        let scene: PreparedScene = Scene::new(objects, vec![material], lights, None, camera)
            .unwrap()
            .into();
        let lighting = Lighting {
            scene: &scene,
            emitters: scene.emitters(QuadSampling::SolidAngle),
            params: TraceParams::default(),
            any_delta: false,
        };
        let ends = [0.0, 0.5, lueur_sampling::ONE_MINUS_EPSILON];
        let mut requests = Vec::new();
        for i in 0..61 {
            let choice = u();
            let chosen = lighting.emitters.chosen_sphere(choice).unwrap();
            let (center, radius) = (chosen.sphere.center, chosen.sphere.radius);
            let p = match i % 4 {
                0 => center + Vec3::new(0.3, -0.2, 0.1) * radius,
                1 => center,
                2 => Vec3::new(1e3, -2e3, 5e2),
                _ => Vec3::new(2.0 * u() - 1.0, 2.0 * u(), 2.0 * u() - 1.0),
            };
            let n = Vec3::new(u() - 0.5, 1.0, u() - 0.5).normalize();
            let wo = Vec3::new(u() - 0.5, if i % 3 == 0 { -0.2 } else { 1.0 }, u()).normalize();
            let at = SurfacePoint {
                p,
                n,
                origin: p + n * 1e-3,
                inside: false,
            };
            let e = if i % 7 == 0 {
                Vec2::new(ends[i % 3], ends[(i / 3) % 3])
            } else {
                Vec2::new(u(), u())
            };
            requests.push((at, wo, choice, e));
        }
        let request =
            |events: &mut SphereNextEvents,
             &(at, wo, choice, e): &(SurfacePoint, Vec3, f32, Vec2)| {
                let vertex = DiffuseLanes {
                    p: at.p.into(),
                    origin: at.origin.into(),
                    n: at.n.into(),
                    wo_n: wo.dot(at.n),
                    albedo: albedo.into(),
                };
                let chosen = lighting.emitters.chosen_sphere(choice).unwrap();
                events.request(&vertex, &chosen, e)
            };
        let (mut found, mut nothing) = (0, 0);
        for level in SimdLevel::available() {
            for count in [1, 7, 16, 17, requests.len()] {
                let mut events = SphereNextEvents::default();
                for r in requests.iter().rev() {
                    request(&mut events, r);
                }
                events.draw(level);
                events.clear();
                let indices: Vec<usize> = (requests[..count].iter())
                    .map(|r| request(&mut events, r))
                    .collect();
                events.draw(level);
                for (&k, (at, wo, choice, e)) in indices.iter().zip(&requests) {
                    let vertex = Vertex {
                        at,
                        wo: *wo,
                        material,
                    };
                    let numbers = VertexSample {
                        emitter_choice: *choice,
                        emitter: *e,
                        ..VertexSample::UNSET
                    };
                    let alone = lighting.next_event(&vertex, &numbers, None);
                    let light = lighting.emitters.chosen_sphere(*choice).unwrap().light;
                    match (events.outcome(k), alone) {
                        (SphereNextEvent::Nothing, None) => nothing += 1,
                        (SphereNextEvent::Found, Some((ray, contribution))) => {
                            let (mut batched, mut brings) = (ShadowRay::UNSET, Vec3::ZERO);
                            events.write(k, (at.origin, light), &mut batched, &mut brings);
                            assert_eq!(batched.ray, ray.ray, "{level:?}, p = {}", at.p);
                            assert_eq!(batched.distance.to_bits(), ray.distance.to_bits());
                            assert_eq!(batched.target, ray.target);
                            assert_eq!(brings, contribution, "{level:?}, p = {}", at.p);
                            found += 1;
                        }
                        (SphereNextEvent::Alone, _) => {}
                        (batched, alone) => panic!(
                            "{level:?}, {count} requests, p = {}: {batched:?} in lanes, {alone:?} alone",
                            at.p
                        ),
                    }
                }
            }
        }
        assert!(
            found > 0 && nothing > 0,
            "{found} found, {nothing} with nothing"
        );
    }

    /// A wave's samples by the cosine, drawn in lanes, are the bits `Material::sample`
    /// and its weight give for each alone (and `None` where that gives none), on every
    /// SIMD level and for any number of requests: normals on both sides of `wo`, along
    /// both poles (where the frame's construction changes sign), at the ends of the
    /// square and its centre, and with a short last vector.
    #[test]
    fn cosine_scatters_are_each_sample_alone() {
        let mut u = uniforms(13);
        let mut unit = || {
            let v = Vec3::new(2.0 * u() - 1.0, 2.0 * u() - 1.0, 2.0 * u() - 1.0);
            v.try_normalize().unwrap_or(Vec3::Z)
        };
        let poles = [
            Vec3::Z,
            -Vec3::Z,
            Vec3::new(1e-4, -2e-4, -1.0).normalize(),
            Vec3::X,
        ];
        let ends = [0.0, 0.5, lueur_sampling::ONE_MINUS_EPSILON];
        let mut requests = Vec::new();
        for i in 0..53 {
            let n = if i % 5 == 0 { poles[i % 4] } else { unit() };
            let wo = unit();
            let albedo = Vec3::new(0.73, 0.05 * (i % 3) as f32, 0.15);
            requests.push((Vec2::new(ends[i % 3], ends[(i / 3) % 3]), albedo, wo, n));
            let mut r = uniforms(i as u64);
            requests.push((Vec2::new(r(), r()), albedo, -wo, n));
        }
        let none = (requests.iter())
            .filter(|&&(u, albedo, wo, n)| {
                let material = Material::Lambertian { albedo };
                material
                    .sample(wo, n, u, HemisphereSampling::Cosine)
                    .is_none()
            })
            .count();
        assert!(
            (1..requests.len() / 2).contains(&none),
            "{none} without a sample"
        );
        for level in SimdLevel::available() {
            for count in [1, 7, 16, 17, requests.len()] {
                let mut draws = CosineScatters::default();
                // A wave before, whose requests stay in the lanes past this one's.
                for &(u, albedo, wo, n) in requests.iter().rev() {
                    draws.request(u, albedo, wo, n);
                }
                draws.draw(level);
                draws.clear();
                let indices: Vec<usize> = (requests[..count].iter())
                    .map(|&(u, albedo, wo, n)| draws.request(u, albedo, wo, n))
                    .collect();
                draws.draw(level);
                assert_eq!(draws.len(), count);
                for (&k, &(u, albedo, wo, n)) in indices.iter().zip(&requests) {
                    let material = Material::Lambertian { albedo };
                    let alone = material
                        .sample(wo, n, u, HemisphereSampling::Cosine)
                        .map(|s| DrawnScatter {
                            wi: s.wi,
                            weight: s.weight(n),
                            pdf: s.pdf,
                        });
                    assert_eq!(
                        draws.drawn(k),
                        alone,
                        "{level:?}, {count} requests, u = {u}"
                    );
                    // What `mis` scatters by, written from the rows: the same sample.
                    let mut mis = None;
                    draws.mis_bsdf_into(k, &mut mis);
                    let expected = alone.map(|s| Scatter {
                        wi: s.wi,
                        weight: s.weight,
                        pdf: s.pdf,
                        emission: EmissionWeight::PowerHeuristic { bsdf_pdf: s.pdf },
                    });
                    assert_eq!(mis, expected, "{level:?}, {count} requests, u = {u}");
                }
            }
        }
    }

    /// A wave's rectangle-light samples, drawn together through the lights' frames, are
    /// the bits the light gives for each alone, for points in front of the light, behind
    /// it (no sample) and far away; and they are asked for only where the light is a
    /// rectangle sampled by solid angle.
    #[test]
    fn rectangle_draws_are_each_sample_alone() {
        let scene = scene(false);
        for quads in [QuadSampling::SolidAngle, QuadSampling::Area] {
            let emitters = scene.emitters(quads);
            let mut u = uniforms(11);
            let mut draws = RectangleDraws::default();
            let mut asked = Vec::new();
            for i in 0..96 {
                let far = if i % 8 == 0 { 1e3 } else { 1.0 };
                let p = Vec3::new(4.0 * u() - 1.0, 4.0 * u() - 1.0, 4.0 * u() - 2.0) * far;
                let (choice, e) = (u(), Vec2::new(u(), u()));
                if let Some(light) = emitters.chosen_rectangle(choice) {
                    asked.push((draws.request(p, light, e), light, p, choice, e));
                }
            }
            draws.draw(&emitters);
            if quads == QuadSampling::Area {
                assert!(
                    asked.is_empty(),
                    "area-sampled quads are drawn where they are used"
                );
                continue;
            }
            assert!(asked.len() > 30, "only {} requests", asked.len());
            let mut sampled = 0;
            for (k, light, p, choice, e) in asked {
                let alone = scene.scene().lights[light].sample(p, e, quads);
                assert_eq!(draws.drawn[k].map(|d| d.wi), alone.map(|s| s.wi), "{p} {e}");
                let n = Vec3::Y;
                let through =
                    emitters.sample_drawn(p, n, choice, e, Some(Drawn::Light(&draws.drawn[k])));
                assert_eq!(through, emitters.sample(p, n, choice, e));
                assert_eq!(through.map(|(s, _)| s.wi), alone.map(|s| s.wi));
                sampled += usize::from(alone.is_some());
            }
            assert!(sampled > 10, "only {sampled} samples had weight");
        }
    }

    /// Next-event estimation toward the sky with its direction drawn among a wave's cosine
    /// draws gives the bits of the sky sampled alone, on every level; and only the sky's
    /// choices ask for one.
    #[test]
    fn sky_draws_are_each_sample_alone() {
        let scene = scene(true);
        let emitters = scene.emitters(QuadSampling::default());
        let mut u = uniforms(13);
        let asked: Vec<(f32, Vec2, Vec3)> = (0..200)
            .map(|_| {
                let n = Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5).normalize();
                (u(), Vec2::new(u(), u()), n)
            })
            .filter(|&(choice, ..)| emitters.chosen_sky(choice))
            .collect();
        assert!(asked.len() > 30, "only {} sky choices", asked.len());
        for level in SimdLevel::available() {
            let mut draws = CosineDraws::default();
            let indices: Vec<usize> = asked.iter().map(|&(_, e, _)| draws.request(e)).collect();
            draws.draw(level);
            for (&k, &(choice, e, n)) in indices.iter().zip(&asked) {
                let p = Vec3::ZERO;
                let through =
                    emitters.sample_drawn(p, n, choice, e, Some(Drawn::Cosine(&draws, k)));
                let alone = emitters.sample(p, n, choice, e);
                assert!(alone.is_some_and(|(_, light)| light.is_none()), "the sky");
                assert_eq!(through, alone, "{level:?}: {choice} {e} {n}");
            }
        }
        let agrees = sky_is_chosen_where_sampled(&emitters);
        assert!(agrees, "chosen_sky agrees with what sampling picks");
    }

    /// Whether `chosen_sky` holds exactly for the choices that sampling aims at the sky.
    fn sky_is_chosen_where_sampled(emitters: &Emitters<'_>) -> bool {
        (0..1000).map(|i| i as f32 / 1000.0).all(|choice| {
            emitters.chosen_sky(choice)
                == emitters
                    .sample(Vec3::ZERO, Vec3::Y, choice, Vec2::splat(0.5))
                    .is_some_and(|(_, light)| light.is_none())
        })
    }

    fn reported(s: Scatter) -> (Vec3, f32) {
        (s.wi, s.pdf)
    }

    #[test]
    fn uniform_and_cosine_follow_the_pdf_they_report() {
        let (v, scene) = (vertex(), scene(true));
        let emitters = scene.emitters(QuadSampling::default());
        for (seed, strategy, hemisphere) in [
            (1, Strategy::Uniform, HemisphereSampling::Uniform),
            (2, Strategy::Cosine, HemisphereSampling::Cosine),
        ] {
            let sample = |u: &VertexSample| scatter(strategy, &emitters, &v, u, None).map(reported);
            let pdf = |wi| v.material.pdf(v.wo, wi, v.at.n, hemisphere);
            check(strategy.name(), seed, sample, pdf);
        }
    }

    #[test]
    fn light_follows_the_pdf_it_reports() {
        let v = vertex();
        for (seed, quads) in [(3, QuadSampling::Area), (4, QuadSampling::SolidAngle)] {
            let scene = scene(true);
            let emitters = scene.emitters(quads);
            let sample =
                |u: &VertexSample| scatter(Strategy::Light, &emitters, &v, u, None).map(reported);
            let pdf = |wi| emitters.pdf(v.at.p, v.at.n, wi);
            check(&format!("light, {quads:?}"), seed, sample, pdf);
        }
    }

    #[test]
    fn mixture_follows_the_pdf_it_reports() {
        let v = vertex();
        for (seed, sky) in [(5, true), (6, false)] {
            let scene = scene(sky);
            let emitters = scene.emitters(QuadSampling::SolidAngle);
            let sample =
                |u: &VertexSample| scatter(Strategy::Mixture, &emitters, &v, u, None).map(reported);
            let pdf = |wi| mixture_pdf(&emitters, &v, wi);
            check(&format!("mixture, sky {sky}"), seed, sample, pdf);
        }
    }

    /// What [`VertexReads::of`] says a vertex reads is all it reads: numbers it calls
    /// unread, drawn otherwise, change no direction, weight, pdf or light sample, for
    /// every strategy, at a diffuse vertex and a mirror, with several emitters and with
    /// one.
    #[test]
    fn numbers_a_vertex_does_not_read_change_nothing() {
        let mut next = uniforms(11);
        let one_light = {
            let camera = Camera::new(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap();
            let light = Light::Sphere {
                center: Vec3::new(-2.0, 3.0, 0.5),
                radius: 1.0,
                radiance: Vec3::ONE,
            };
            PreparedScene::from(Scene::new(vec![], vec![], vec![light], None, camera).unwrap())
        };
        let diffuse = vertex();
        let mirror = Vertex {
            material: Material::Mirror {
                reflectance: Vec3::splat(0.9),
            },
            ..diffuse
        };
        for scene in [scene(true), one_light] {
            let emitters = scene.emitters(QuadSampling::SolidAngle);
            let chooses = emitters.sampler.choice_reads_u();
            for strategy in Strategy::ALL.iter().copied() {
                for v in [&diffuse, &mirror] {
                    let is_diffuse = matches!(v.material, Material::Lambertian { .. });
                    let reads = VertexReads::of(strategy, is_diffuse, chooses, false);
                    for _ in 0..200 {
                        let u = vertex_sample(&mut next);
                        let other = vertex_sample(&mut next);
                        let pick = |read: bool, a: f32, b: f32| if read { a } else { b };
                        let pick2 = |read: bool, a: Vec2, b: Vec2| if read { a } else { b };
                        let w = VertexSample {
                            emitter_choice: pick(
                                reads.emitter_choice,
                                u.emitter_choice,
                                other.emitter_choice,
                            ),
                            emitter: pick2(reads.emitter, u.emitter, other.emitter),
                            mixture: pick(reads.mixture, u.mixture, other.mixture),
                            bsdf: pick2(reads.bsdf, u.bsdf, other.bsdf),
                            roulette: u.roulette,
                        };
                        let what = format!("{strategy:?}, diffuse {is_diffuse}, {reads:?}");
                        if is_diffuse {
                            assert_eq!(
                                scatter(strategy, &emitters, v, &u, None),
                                scatter(strategy, &emitters, v, &w, None),
                                "{what}"
                            );
                            if uses_next_event(strategy) {
                                let (p, n) = (v.at.p, v.at.n);
                                assert_eq!(
                                    emitters.sample(p, n, u.emitter_choice, u.emitter),
                                    emitters.sample(p, n, w.emitter_choice, w.emitter),
                                    "{what}"
                                );
                            }
                        } else {
                            assert_eq!(mirror_of(v, &u), mirror_of(v, &w), "{what}");
                        }
                    }
                }
            }
        }
    }

    fn mirror_of(v: &Vertex<'_>, u: &VertexSample) -> Option<Scatter> {
        mirror(v, u.bsdf)
    }

    /// [`VertexSample::draw`] draws each number it reads as a draw of every number does,
    /// whatever it skips, and leaves the others 0: on every sampler kind, at several
    /// depths and samples.
    #[test]
    fn a_vertex_draws_what_it_reads_as_if_it_drew_all() {
        for &kind in SamplerKind::ALL {
            for mask in 0..32u32 {
                let reads = VertexReads {
                    emitter_choice: mask & 1 != 0,
                    emitter: mask & 2 != 0,
                    mixture: mask & 4 != 0,
                    bsdf: mask & 8 != 0,
                    roulette: mask & 16 != 0,
                };
                let mut all = Sampler::for_render(kind, 5, [8, 8], 16, 4);
                let mut some = all.clone();
                for (pixel, index, depth) in [([0, 0], 0, 0), ([3, 5], 7, 2), ([3, 5], 9, 6)] {
                    let (mut a, mut b) = (VertexSample::UNSET, VertexSample::UNSET);
                    a.draw(&mut all, pixel, index, depth, VertexReads::ALL);
                    b.draw(&mut some, pixel, index, depth, reads);
                    let expect = |read: bool, x: f32| if read { x } else { 0.0 };
                    let expect2 = |read: bool, x: Vec2| if read { x } else { Vec2::ZERO };
                    let wanted = VertexSample {
                        emitter_choice: expect(reads.emitter_choice, a.emitter_choice),
                        emitter: expect2(reads.emitter, a.emitter),
                        mixture: expect(reads.mixture, a.mixture),
                        bsdf: expect2(reads.bsdf, a.bsdf),
                        roulette: expect(reads.roulette, a.roulette),
                    };
                    assert_eq!(b, wanted, "{kind:?}, {reads:?}, depth {depth}");
                }
            }
        }
    }

    /// Both halves of `mis`: its BSDF directions (cosine), whose emission is
    /// weighted against the pdf they report, and the directions next-event
    /// estimation aims at, each reporting the pdf of the emitter chosen
    /// (which the weight of emission found by the BSDF half is taken
    /// against), together distributed as the sum over emitters.
    #[test]
    fn mis_follows_the_pdfs_it_reports() {
        let (v, scene) = (vertex(), scene(true));
        let emitters = scene.emitters(QuadSampling::SolidAngle);
        let bsdf = |u: &VertexSample| {
            let s = scatter(Strategy::Mis, &emitters, &v, u, None)?;
            assert_eq!(
                s.emission,
                EmissionWeight::PowerHeuristic { bsdf_pdf: s.pdf }
            );
            Some(reported(s))
        };
        let cosine = |wi| v.material.pdf(v.wo, wi, v.at.n, MIS_HEMISPHERE);
        check("mis, BSDF", 7, bsdf, cosine);
        let (p, n) = (v.at.p, v.at.n);
        let next_event = |u: &VertexSample| {
            let (es, light) = emitters.sample(p, n, u.emitter_choice, u.emitter)?;
            let chosen = match light {
                Some(light) => emitters.light_pdf(light, p, n, es.wi),
                None => emitters.sky_pdf(n, es.wi),
            };
            Some((es.wi, es.pdf, chosen))
        };
        let pdf = |wi| emitters.pdf(p, n, wi);
        check_reporting("mis, next event", 8, next_event, pdf);
    }
}
