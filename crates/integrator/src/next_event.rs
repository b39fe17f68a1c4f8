//! Next-event estimation's estimate at a diffuse vertex from one light sample, written once
//! over lanes ([`NextEventLanes`]): [`crate::strategy::Lighting::next_event`] runs it at
//! `f32` for one vertex, and a wave's vertices that aim at sphere lights run it a vector
//! at a time beside their light samples ([`crate::light_sampler::SphereNextEvents`]), so
//! each vertex gets the bits it has alone.

use lueur_materials::LambertianLanes;
use lueur_sampling::sample_sphere_light_lanes;
use lueur_scene::{sphere_emits_along_lanes, usable_pdf_lanes};
use lueur_sdf_math::{Lane, LaneVec3};

use crate::strategy::{MIS_HEMISPHERE, next_event_weight_lanes};
use crate::surface::ShadowAim;

/// A diffuse vertex as next-event estimation sees it, per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct DiffuseLanes<L: Lane> {
    /// The shading point.
    pub p: LaneVec3<L>,
    /// Where rays leave the surface from.
    pub origin: LaneVec3<L>,
    /// The shading normal.
    pub n: LaneVec3<L>,
    /// `wo . n`, with `wo` toward the viewer: which side the viewer is on.
    pub wo_n: L,
    /// The Lambertian's albedo.
    pub albedo: LaneVec3<L>,
}

/// A light sample as next-event estimation weighs it, per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LightSampleLanes<L: Lane> {
    /// Unit direction toward the sampled point.
    pub wi: LaneVec3<L>,
    /// Distance to it (infinite for the sky).
    pub distance: L,
    /// Its solid-angle pdf, the emitter's choice included.
    pub pdf: L,
    /// The radiance it emits toward the vertex.
    pub radiance: LaneVec3<L>,
}

/// A diffuse vertex's estimate through one light sample, per lane, in two steps: where
/// it brings anything ([`NextEventLanes::new`]), then what
/// ([`NextEventLanes::contribution`]), so that one vertex alone stops where it brings
/// nothing.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NextEventLanes<L: Lane> {
    /// The BSDF toward the sample.
    lobe: LambertianLanes<L>,
    /// Where the sample brings anything: the BSDF, the cosine and the radiance are not 0.
    pub weighs: L::Mask,
}

impl<L: Lane> NextEventLanes<L> {
    #[inline(always)]
    pub fn new(v: &DiffuseLanes<L>, s: &LightSampleLanes<L>) -> NextEventLanes<L> {
        let lobe = LambertianLanes::seen_at(v.albedo, v.wo_n, s.wi, v.n);
        let nothing = L::or(
            L::or(all_zero(lobe.f), is_zero(lobe.cos)),
            all_zero(s.radiance),
        );
        NextEventLanes {
            lobe,
            weighs: L::not(nothing),
        }
    }

    /// What the light brings if the shadow ray is free: `f L cos w / pdf`, with `w` the
    /// power heuristic against `mis`'s BSDF sampling.
    #[inline(always)]
    pub fn contribution(&self, s: &LightSampleLanes<L>) -> LaneVec3<L> {
        let (f, cos) = (self.lobe.f, self.lobe.cos);
        let w = next_event_weight_lanes(s.pdf, self.lobe.pdf(MIS_HEMISPHERE));
        // glam's order: `f * radiance * cos * w / pdf`, left to right.
        let f_l = LaneVec3::new(f.x * s.radiance.x, f.y * s.radiance.y, f.z * s.radiance.z);
        f_l * cos * w / s.pdf
    }
}

/// A sphere light as next-event estimation aims at it, per lane: its centre, radius and
/// radiance, and the probability that the vertex chose it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AimedSphereLanes<L: Lane> {
    pub center: LaneVec3<L>,
    pub radius: L,
    pub radiance: LaneVec3<L>,
    pub pmf: L,
}

/// Next-event estimation at `vertex` toward `sphere` with the numbers `u`, per lane, as
/// [`crate::strategy::Lighting::next_event`] makes it: the light's sample and the tests
/// `Light::sample_drawn` puts it to, the estimate, and the shadow ray's aim. Where it
/// brings anything, the aim, and what it brings if the shadow ray is free. The one
/// definition for a wave's estimates in lanes (`SphereNextEvents`, the lane wave's
/// `Shade`).
#[inline(always)]
pub(crate) fn sphere_next_event_lanes<L: Lane>(
    vertex: &DiffuseLanes<L>,
    sphere: &AimedSphereLanes<L>,
    u: [L; 2],
) -> (L::Mask, ShadowAim<L>, LaneVec3<L>) {
    let s = sample_sphere_light_lanes(vertex.p, sphere.center, sphere.radius, u);
    let sampled = L::and(
        s.valid,
        L::and(
            sphere_emits_along_lanes(s.normal, s.wi),
            usable_pdf_lanes(s.pdf),
        ),
    );
    let sample = LightSampleLanes {
        wi: s.wi,
        distance: s.distance,
        pdf: s.pdf * sphere.pmf,
        radiance: sphere.radiance,
    };
    let e = NextEventLanes::new(vertex, &sample);
    let aim = ShadowAim::new(vertex.p, vertex.origin, sample.wi, sample.distance);
    (L::and(sampled, e.weighs), aim, e.contribution(&sample))
}

/// Where `x` is 0 (either sign): no float lies between 0 and the least subnormal.
#[inline(always)]
fn is_zero<L: Lane>(x: L) -> L::Mask {
    x.abs().lt(L::splat(f32::from_bits(1)))
}

/// Where every coordinate is 0: glam's `== Vec3::ZERO`.
#[inline(always)]
pub(crate) fn all_zero<L: Lane>(v: LaneVec3<L>) -> L::Mask {
    L::and(L::and(is_zero(v.x), is_zero(v.y)), is_zero(v.z))
}
