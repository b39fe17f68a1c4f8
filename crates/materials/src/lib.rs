//! Surface scattering for lueur: the Lambertian and mirror BSDFs and what
//! an emitter gives off.
//!
//! The primary type is [`Material`], a closed enum: shading dispatches with a
//! `match`, never a virtual call, because it runs once per path vertex. A BSDF
//! is queried in a world frame given the shading normal `n`; every direction
//! (`wo` toward the viewer, `wi` toward the light) points away from the
//! surface.
//!
//! Contract: `eval` returns the BSDF value `f(wo, wi)` (not multiplied by the
//! cosine), `pdf` the solid-angle density with which `sample` produces `wi`,
//! and a [`BsdfSample`] never carries a NaN or an infinity. A delta lobe (the
//! mirror) is sampled only: it evaluates to zero and has zero pdf for any
//! given direction, since a direction chosen by anything else hits it with
//! probability zero.
//!
//! [`CosineScatterLanes`] is the Lambertian's sample by the cosine for a vector of
//! vertices at once, the one definition that [`Material::sample`] runs at one lane.
//!
//! This crate deliberately knows nothing of lights' geometry, scenes or rays:
//! light sampling lives in `lueur-sampling` and the estimators that combine
//! both live in `lueur-integrator`.
//!
//! ```
//! use lueur_materials::{HemisphereSampling, Material};
//! use glam::{Vec2, Vec3};
//!
//! let white = Material::Lambertian { albedo: Vec3::splat(0.5) };
//! let n = Vec3::Z;
//! let wo = Vec3::new(0.0, 0.6, 0.8);
//! let s = white
//!     .sample(wo, n, Vec2::new(0.3, 0.7), HemisphereSampling::Cosine)
//!     .expect("a Lambertian surface always scatters");
//! // With cosine sampling the throughput of a Lambertian bounce is the albedo.
//! assert!((s.weight(n) - Vec3::splat(0.5)).abs().max_element() < 1e-5);
//! ```
#![deny(missing_docs)]

use glam::{Vec2, Vec3};
use lueur_sampling::{
    Frame, FrameLanes, cosine_hemisphere_pdf_lanes, sample_cosine_hemisphere,
    sample_uniform_hemisphere, uniform_hemisphere_pdf,
};
use lueur_sdf_math::{Lane, LaneVec3};
use std::f32::consts::FRAC_1_PI;

/// How a diffuse lobe picks its directions: the integrator's strategy
/// decides, since comparing them is the point of lueur.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HemisphereSampling {
    /// Uniform over the hemisphere, pdf 1/(2 pi): the report's first sampler.
    Uniform,
    /// Proportional to the cosine, pdf cos/pi: the Lambertian BSDF's own shape.
    Cosine,
}

/// A surface's response to light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Ideal diffuse reflector, BRDF = albedo / pi.
    Lambertian {
        /// Fraction of incident power reflected, per RGB channel.
        albedo: Vec3,
    },
    /// Perfect specular reflection, a delta lobe.
    Mirror {
        /// Multiplies the reflected radiance, per RGB channel.
        reflectance: Vec3,
    },
}

/// A direction chosen by a BSDF, with what it carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Sampled incident direction (world frame, unit length, away from the surface).
    pub wi: Vec3,
    /// BSDF value `f(wo, wi)`; for a delta lobe, the reflectance itself
    /// (pbrt folds the 1/cos into the delta; we fold the whole throughput).
    pub f: Vec3,
    /// Solid-angle pdf of `wi`; 1 by convention for a delta lobe.
    pub pdf: f32,
    /// Whether `wi` came from a delta lobe (never evaluated nor light-sampled).
    pub is_delta: bool,
}

impl BsdfSample {
    /// The path throughput factor `f |cos| / pdf` this sample contributes.
    pub fn weight(&self, n: Vec3) -> Vec3 {
        if self.is_delta {
            self.f
        } else {
            weight_lanes(self.f.into(), n.into(), self.wi.into(), self.pdf).into()
        }
    }
}

/// [`BsdfSample::weight`] of a lobe that is not a delta, per lane: its one definition.
#[inline(always)]
fn weight_lanes<L: Lane>(f: LaneVec3<L>, n: LaneVec3<L>, wi: LaneVec3<L>, pdf: L) -> LaneVec3<L> {
    f * n.dot(wi).abs() / pdf
}

/// A Lambertian surface of `albedo` evaluated for a pair of directions, per lane: the one
/// definition of [`Material::eval`] and [`Material::pdf`] for it, which run it at `f32`,
/// so that a batch of vertices gets each vertex's bits.
#[derive(Clone, Copy, Debug)]
pub struct LambertianLanes<L: Lane> {
    /// The BSDF's value: `albedo / pi` where `wo` and `wi` are on one side of the
    /// surface, else 0.
    pub f: LaneVec3<L>,
    /// `|n . wi|`.
    pub cos: L,
    /// Where `wo` and `wi` are on one side of the surface (the surface is two-sided).
    pub same_side: L::Mask,
}

impl<L: Lane> LambertianLanes<L> {
    /// The surface of `albedo` with normal `n`, seen along `wo`, lit along `wi`.
    #[inline(always)]
    pub fn new(
        albedo: LaneVec3<L>,
        wo: LaneVec3<L>,
        wi: LaneVec3<L>,
        n: LaneVec3<L>,
    ) -> LambertianLanes<L> {
        LambertianLanes::seen_at(albedo, wo.dot(n), wi, n)
    }

    /// [`LambertianLanes::new`] from `wo . n` (`wo_n`) rather than `wo`: all it needs of
    /// the viewer.
    #[inline(always)]
    pub fn seen_at(albedo: LaneVec3<L>, wo_n: L, wi: LaneVec3<L>, n: LaneVec3<L>) -> Self {
        let zero = L::splat(0.0);
        let same_side = (wo_n * wi.dot(n)).gt(zero);
        let f = albedo * L::splat(FRAC_1_PI);
        LambertianLanes {
            f: LaneVec3::new(
                L::select(same_side, f.x, zero),
                L::select(same_side, f.y, zero),
                L::select(same_side, f.z, zero),
            ),
            cos: n.dot(wi).abs(),
            same_side,
        }
    }

    /// The solid-angle pdf with which [`Material::sample`] returns `wi` by `hemisphere`.
    #[inline(always)]
    pub fn pdf(&self, hemisphere: HemisphereSampling) -> L {
        let pdf = match hemisphere {
            HemisphereSampling::Uniform => L::splat(uniform_hemisphere_pdf()),
            HemisphereSampling::Cosine => cosine_hemisphere_pdf_lanes(self.cos),
        };
        L::select(self.same_side, pdf, L::splat(0.0))
    }
}

/// A Lambertian surface's direction sampled by the cosine, per lane:
/// [`Material::sample`] with [`HemisphereSampling::Cosine`] and then
/// [`BsdfSample::weight`], given the local direction drawn from the lane's numbers
/// ([`lueur_sampling::sample_cosine_hemisphere_lanes`]). The one definition of that
/// sample: the scalar method is this at `f32`, so a batch of vertices gets each vertex's
/// bits.
#[derive(Clone, Copy, Debug)]
pub struct CosineScatterLanes<L: Lane> {
    /// The direction in the world frame.
    pub wi: LaneVec3<L>,
    /// Its solid-angle pdf.
    pub pdf: L,
    /// The BSDF's value `albedo / pi`.
    pub f: LaneVec3<L>,
    /// The throughput factor `f |cos| / pdf`.
    pub weight: LaneVec3<L>,
    /// Where the sample carries weight; elsewhere the other fields mean nothing.
    pub valid: L::Mask,
}

impl<L: Lane> CosineScatterLanes<L> {
    /// The sample of a Lambertian surface of `albedo` with normal `n`, seen along `wo`,
    /// whose cosine-weighted local direction is `local`.
    #[inline(always)]
    pub fn new(
        albedo: LaneVec3<L>,
        wo: LaneVec3<L>,
        n: LaneVec3<L>,
        local: LaneVec3<L>,
    ) -> CosineScatterLanes<L> {
        let zero = L::splat(0.0);
        let pdf = cosine_hemisphere_pdf_lanes(local.z);
        let valid = L::and(pdf.gt(zero), local.z.gt(zero));
        let n = two_sided_lanes(n, wo);
        // Unit to within a few ulps (an orthonormal frame and a unit `local`), without the
        // square root and division the next ray waits on.
        let wi = FrameLanes::from_normal(n).to_world(local);
        let f = albedo * L::splat(FRAC_1_PI);
        CosineScatterLanes {
            wi,
            pdf,
            f,
            weight: weight_lanes(f, n, wi, pdf),
            valid,
        }
    }
}

/// The normal on the side `wo` is on, per lane: surfaces are two-sided.
#[inline(always)]
fn two_sided_lanes<L: Lane>(n: LaneVec3<L>, wo: LaneVec3<L>) -> LaneVec3<L> {
    let behind = n.dot(wo).lt(L::splat(0.0));
    let flipped = -n;
    LaneVec3::new(
        L::select(behind, flipped.x, n.x),
        L::select(behind, flipped.y, n.y),
        L::select(behind, flipped.z, n.z),
    )
}

impl Material {
    /// Whether every lobe is a delta (no light sampling can help here).
    pub fn is_delta(&self) -> bool {
        matches!(self, Material::Mirror { .. })
    }

    /// BSDF value for the pair of directions; zero for delta lobes and for
    /// directions on opposite sides of the surface.
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3, n: Vec3) -> Vec3 {
        match *self {
            Material::Lambertian { albedo } => {
                let lobe = LambertianLanes::new(albedo.into(), wo.into(), wi.into(), n.into());
                lobe.f.into()
            }
            Material::Mirror { .. } => Vec3::ZERO,
        }
    }

    /// Solid-angle pdf with which [`Material::sample`] returns `wi`.
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3, n: Vec3, hemisphere: HemisphereSampling) -> f32 {
        match *self {
            Material::Lambertian { .. } => {
                let lobe = LambertianLanes::new(Vec3::ZERO.into(), wo.into(), wi.into(), n.into());
                lobe.pdf(hemisphere)
            }
            Material::Mirror { .. } => 0.0,
        }
    }

    /// Chooses an incident direction from two uniform numbers. `None` when
    /// the sample carries no weight (a grazing direction with zero pdf).
    pub fn sample(
        &self,
        wo: Vec3,
        n: Vec3,
        u: Vec2,
        hemisphere: HemisphereSampling,
    ) -> Option<BsdfSample> {
        match *self {
            Material::Lambertian { albedo } => match hemisphere {
                HemisphereSampling::Uniform => {
                    let n: Vec3 = two_sided_lanes(n.into(), wo.into()).into();
                    let local = sample_uniform_hemisphere(u);
                    let pdf = uniform_hemisphere_pdf();
                    if !(pdf > 0.0) || local.z <= 0.0 {
                        return None;
                    }
                    // Unit to within a few ulps (an orthonormal frame and a unit `local`),
                    // without the square root and division the next ray waits on.
                    let wi = Frame::from_normal(n).to_world(local);
                    Some(BsdfSample {
                        wi,
                        f: albedo * FRAC_1_PI,
                        pdf,
                        is_delta: false,
                    })
                }
                HemisphereSampling::Cosine => {
                    let local = sample_cosine_hemisphere(u);
                    let s =
                        CosineScatterLanes::new(albedo.into(), wo.into(), n.into(), local.into());
                    s.valid.then(|| BsdfSample {
                        wi: s.wi.into(),
                        f: s.f.into(),
                        pdf: s.pdf,
                        is_delta: false,
                    })
                }
            },
            Material::Mirror { reflectance } => {
                let n: Vec3 = two_sided_lanes(n.into(), wo.into()).into();
                let wi = reflect(wo, n);
                Some(BsdfSample {
                    wi,
                    f: reflectance,
                    pdf: 1.0,
                    is_delta: true,
                })
            }
        }
    }
}

/// Mirror reflection of `wo` (pointing away from the surface) about `n`.
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    (2.0 * wo.dot(n) * n - wo).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lambert() -> Material {
        Material::Lambertian {
            albedo: Vec3::new(0.2, 0.5, 0.9),
        }
    }

    #[test]
    fn lambertian_sample_agrees_with_eval_and_pdf() {
        let n = Vec3::new(0.3, -0.4, 0.5).normalize();
        let wo = (n + Vec3::X * 0.5).normalize();
        for hemisphere in [HemisphereSampling::Uniform, HemisphereSampling::Cosine] {
            for i in 0..64 {
                let u = Vec2::new((i as f32 + 0.5) / 64.0, ((i * 37 % 64) as f32 + 0.5) / 64.0);
                let s = lambert().sample(wo, n, u, hemisphere).unwrap();
                assert!((s.wi.length() - 1.0).abs() < 1e-5);
                assert!(s.wi.dot(n) > 0.0);
                assert_eq!(s.f, lambert().eval(wo, s.wi, n));
                let pdf = lambert().pdf(wo, s.wi, n, hemisphere);
                assert!((pdf - s.pdf).abs() <= 1e-4 * pdf, "{pdf} vs {}", s.pdf);
            }
        }
    }

    #[test]
    fn lambertian_is_two_sided_and_zero_across() {
        let n = Vec3::Z;
        let wo = Vec3::new(0.0, 0.6, -0.8);
        let s = lambert()
            .sample(wo, n, Vec2::new(0.5, 0.5), HemisphereSampling::Cosine)
            .unwrap();
        assert!(s.wi.z < 0.0, "scatters on the viewer's side");
        assert_eq!(lambert().eval(wo, Vec3::Z, n), Vec3::ZERO);
        assert_eq!(
            lambert().pdf(wo, Vec3::Z, n, HemisphereSampling::Uniform),
            0.0
        );
    }

    #[test]
    fn mirror_reflects_and_is_never_evaluated() {
        let m = Material::Mirror {
            reflectance: Vec3::splat(0.9),
        };
        let n = Vec3::Y;
        let wo = Vec3::new(1.0, 1.0, 0.0).normalize();
        let s = m
            .sample(wo, n, Vec2::ZERO, HemisphereSampling::Cosine)
            .unwrap();
        assert!(s.is_delta);
        assert!((s.wi - Vec3::new(-1.0, 1.0, 0.0).normalize()).length() < 1e-6);
        assert_eq!(s.weight(n), Vec3::splat(0.9));
        assert_eq!(m.eval(wo, s.wi, n), Vec3::ZERO);
        assert_eq!(m.pdf(wo, s.wi, n, HemisphereSampling::Cosine), 0.0);
    }

    #[test]
    fn grazing_and_extreme_u_stay_finite() {
        let n = Vec3::Y;
        let one = 1.0 - f32::EPSILON / 2.0;
        for wo in [Vec3::new(1.0, 1e-7, 0.0).normalize(), Vec3::Y] {
            for u in [
                Vec2::ZERO,
                Vec2::splat(one),
                Vec2::new(0.0, one),
                Vec2::new(one, 0.0),
            ] {
                for h in [HemisphereSampling::Uniform, HemisphereSampling::Cosine] {
                    if let Some(s) = lambert().sample(wo, n, u, h) {
                        assert!(s.wi.is_finite() && s.pdf.is_finite() && s.pdf > 0.0);
                        assert!(s.weight(n).is_finite());
                    }
                }
            }
        }
    }
}
