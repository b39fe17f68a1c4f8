//! The emitter choice (pbrt-v4's `LightSampler`): which emitter light
//! sampling aims at, with what probability, and the pdfs of the directions
//! that result, summed over the emitters. The sky is an emitter like the
//! lights with an area, sampled by the cosine around the normal.

use glam::{Vec2, Vec3};
use lueur_sampling::{
    DiscreteDistribution, Frame, cosine_hemisphere_pdf, sample_cosine_hemisphere,
};

use lueur_scene::{EmitterSample, Light, QuadSampling};

/// An emitter that light sampling can choose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Emitter {
    /// An index into the scene's lights (never a delta light).
    Light(usize),
    /// The scene's constant sky.
    Sky,
}

/// The choice among emitters: uniform over the lights that are not delta
/// distributions, then the sky if there is one.
#[derive(Clone, Debug)]
pub(crate) struct LightSampler {
    emitters: Vec<Emitter>,
    choice: Option<DiscreteDistribution>,
}

impl LightSampler {
    pub fn new(lights: &[Light], has_sky: bool) -> LightSampler {
        let mut emitters: Vec<Emitter> = lights
            .iter()
            .enumerate()
            .filter(|(_, l)| !l.is_delta())
            .map(|(i, _)| Emitter::Light(i))
            .collect();
        if has_sky {
            emitters.push(Emitter::Sky);
        }
        // Uniform choice: power-proportional choice needs the sky's power,
        // which depends on the scene's extent; measured first, changed later.
        let choice = DiscreteDistribution::uniform(emitters.len());
        LightSampler { emitters, choice }
    }

    /// Whether there is anything to choose.
    pub fn is_empty(&self) -> bool {
        self.choice.is_none()
    }

    /// The emitter `u` chooses and the probability of choosing it.
    fn choose(&self, u: f32) -> Option<(Emitter, f32)> {
        let (k, pmf) = self.choice.as_ref()?.sample(u);
        Some((self.emitters[k], pmf))
    }

    /// The probability of choosing `emitter`, `None` for one never chosen.
    fn pmf(&self, emitter: Emitter) -> Option<f32> {
        let choice = self.choice.as_ref()?;
        let k = self.emitters.iter().position(|e| *e == emitter)?;
        Some(choice.pmf(k))
    }
}

/// What the emitter queries need of a scene: its lights, its sky, the
/// choice among them, and how quads are sampled.
#[derive(Clone, Copy)]
pub(crate) struct Emitters<'a> {
    pub lights: &'a [Light],
    pub sky: Option<Vec3>,
    pub sampler: &'a LightSampler,
    pub quad_sampling: QuadSampling,
}

impl Emitters<'_> {
    /// Whether light sampling has anything to sample.
    pub fn any(&self) -> bool {
        !self.sampler.is_empty()
    }

    /// Chooses an emitter and a direction toward it from `p` (normal `n`,
    /// used only by the sky's cosine sampling), with the light chosen
    /// (`None` for the sky). The pdf includes the choice.
    pub fn sample(
        &self,
        p: Vec3,
        n: Vec3,
        u_choice: f32,
        u: Vec2,
    ) -> Option<(EmitterSample, Option<usize>)> {
        let (emitter, pmf) = self.sampler.choose(u_choice)?;
        match emitter {
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
                let s = self.lights[i].sample(p, u, self.quad_sampling)?;
                Some((
                    EmitterSample {
                        pdf: s.pdf * pmf,
                        ..s
                    },
                    Some(i),
                ))
            }
        }
    }

    /// Solid-angle pdf with which [`Emitters::sample`] picks `wi` from `p`,
    /// summed over every emitter that direction could come from.
    pub fn pdf(&self, p: Vec3, n: Vec3, wi: Vec3) -> f32 {
        let Some(choice) = self.sampler.choice.as_ref() else {
            return 0.0;
        };
        let mut pdf = 0.0;
        for (k, e) in self.sampler.emitters.iter().enumerate() {
            pdf += choice.pmf(k) * self.single_pdf(*e, p, n, wi);
        }
        pdf
    }

    /// The same for light `light` only (the light a BSDF ray hit).
    pub fn light_pdf(&self, light: usize, p: Vec3, n: Vec3, wi: Vec3) -> f32 {
        let emitter = Emitter::Light(light);
        self.sampler
            .pmf(emitter)
            .map_or(0.0, |pmf| pmf * self.single_pdf(emitter, p, n, wi))
    }

    /// The same for the sky only.
    pub fn sky_pdf(&self, n: Vec3, wi: Vec3) -> f32 {
        self.sampler.pmf(Emitter::Sky).map_or(0.0, |pmf| {
            pmf * self.single_pdf(Emitter::Sky, Vec3::ZERO, n, wi)
        })
    }

    fn single_pdf(&self, e: Emitter, p: Vec3, n: Vec3, wi: Vec3) -> f32 {
        match e {
            Emitter::Sky => cosine_hemisphere_pdf(n.dot(wi)),
            Emitter::Light(i) => self.lights[i].pdf(p, wi, self.quad_sampling),
        }
    }
}
