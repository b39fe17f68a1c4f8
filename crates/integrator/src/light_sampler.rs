//! The emitter choice (pbrt-v4's `LightSampler`): which emitter light
//! sampling aims at, with what probability, and the pdfs of the directions
//! that result, summed over the emitters. The sky is an emitter like the
//! lights with an area, sampled by the cosine around the normal. And the
//! direction samples a wave of paths draws together for next-event
//! estimation: toward sphere lights (`SphereDraws`), rectangles
//! (`RectangleDraws`) and the sky (`CosineDraws`).

use glam::{Vec2, Vec3};
use lueur_sampling::{
    DirectionSample, DiscreteDistribution, Frame, RECTANGLE_LANES, RectangleFrame,
    SphericalRectangles, cosine_hemisphere_pdf, sample_cosine_hemisphere,
    sample_cosine_hemisphere_lanes, sample_sphere_light_lanes,
};
use lueur_sdf_math::{Lane, LaneGroups, LaneKernel, LaneVec3, MAX_LANES, SimdLevel};

use lueur_scene::{EmitterSample, Light, QuadSampling};

/// An emitter that light sampling can choose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Emitter {
    /// An index into the scene's lights (never a delta light).
    Light(usize),
    /// The scene's constant sky.
    Sky,
}

/// A chosen emitter's direction sample that a wave drew with its others.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Drawn<'a> {
    /// A light's ([`SphereDraws`], [`RectangleDraws`]).
    Light(&'a Option<DirectionSample>),
    /// The sky's cosine-weighted direction in the normal's frame: request `k` of the
    /// wave's [`CosineDraws`]. Read where it is used: copied out first, the direction is
    /// stored in pieces and loaded whole (docs/PERFORMANCE.md, "Stores loaded whole").
    Cosine(&'a CosineDraws, usize),
}

/// The sky's sample toward the cosine-weighted direction `local` in the frame of the
/// normal `n`, of the emitters' choice chosen with probability `pmf`.
#[inline(always)]
fn sky_sample(sky: Vec3, n: Vec3, local: Vec3, pmf: f32) -> Option<(EmitterSample, Option<usize>)> {
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

/// The choice among emitters: uniform over the lights that are not delta
/// distributions, then the sky if there is one.
#[derive(Clone, Debug)]
pub(crate) struct LightSampler {
    emitters: Vec<Emitter>,
    choice: Option<DiscreteDistribution>,
    /// Whether any emitter is a sphere light.
    spheres: bool,
    /// Per light, its [`Light::rectangle_frame`]: made once here, not at every sample.
    rectangles: Vec<Option<RectangleFrame>>,
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
        let spheres = lights.iter().any(|l| l.as_sphere().is_some());
        LightSampler {
            emitters,
            choice,
            spheres,
            rectangles: lights.iter().map(Light::rectangle_frame).collect(),
        }
    }

    /// Whether there is anything to choose.
    pub fn is_empty(&self) -> bool {
        self.choice.is_none()
    }

    /// Whether choosing an emitter reads its number (`u_choice`): not with one emitter
    /// or none.
    pub fn choice_reads_u(&self) -> bool {
        self.choice
            .as_ref()
            .is_some_and(DiscreteDistribution::reads_u)
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
        self.sample_drawn(p, n, u_choice, u, None)
    }

    /// The centre and radius of the light `u_choice` makes [`Emitters::sample`] aim at,
    /// where that is a sphere light: whose direction sample a wave draws in lanes.
    #[inline]
    pub fn chosen_sphere(&self, u_choice: f32) -> Option<(Vec3, f32)> {
        if !self.sampler.spheres {
            return None;
        }
        match self.sampler.choose(u_choice)?.0 {
            Emitter::Light(i) => self.lights[i].as_sphere(),
            Emitter::Sky => None,
        }
    }

    /// The light `u_choice` makes [`Emitters::sample`] aim at, where that is a rectangle
    /// sampled by solid angle: whose direction samples a wave draws in a loop of their
    /// own ([`RectangleDraws`]).
    #[inline]
    pub fn chosen_rectangle(&self, u_choice: f32) -> Option<usize> {
        match self.sampler.choose(u_choice)?.0 {
            Emitter::Light(i) => self.rectangle(i).map(|_| i),
            Emitter::Sky => None,
        }
    }

    /// Whether `u_choice` makes [`Emitters::sample`] aim at the sky, whose cosine-weighted
    /// directions a wave draws with its others ([`CosineDraws`]).
    #[inline]
    pub fn chosen_sky(&self, u_choice: f32) -> bool {
        self.sky.is_some() && matches!(self.sampler.choose(u_choice), Some((Emitter::Sky, _)))
    }

    /// [`Emitters::sample`], where the chosen emitter's direction sample was `drawn`
    /// already ([`Light::sample_drawn`], or the sky's local direction).
    #[inline]
    pub fn sample_drawn(
        &self,
        p: Vec3,
        n: Vec3,
        u_choice: f32,
        u: Vec2,
        drawn: Option<Drawn<'_>>,
    ) -> Option<(EmitterSample, Option<usize>)> {
        let (emitter, pmf) = self.sampler.choose(u_choice)?;
        match emitter {
            Emitter::Sky => {
                let sky = self.sky?;
                // A sample per arm: where the arms meet in one local direction, it is
                // stored in pieces and loaded whole (docs/PERFORMANCE.md, "Stores loaded
                // whole").
                match drawn {
                    Some(Drawn::Cosine(draws, k)) => {
                        debug_assert_eq!(draws.drawn(k), sample_cosine_hemisphere(u));
                        sky_sample(sky, n, draws.drawn(k), pmf)
                    }
                    _ => sky_sample(sky, n, sample_cosine_hemisphere(u), pmf),
                }
            }
            Emitter::Light(i) => {
                let light = &self.lights[i];
                let drawn = match drawn {
                    Some(Drawn::Light(drawn)) => Some(drawn),
                    _ => None,
                };
                let s = match (drawn, self.rectangle(i)) {
                    (None, Some(frame)) => {
                        light.sample_drawn(p, u, self.quad_sampling, Some(&frame.sample(p, u)))
                    }
                    (drawn, _) => light.sample_drawn(p, u, self.quad_sampling, drawn),
                }?;
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
            Emitter::Light(i) => match self.rectangle(i) {
                Some(frame) => frame.pdf(p, wi),
                None => self.lights[i].pdf(p, wi, self.quad_sampling),
            },
        }
    }

    /// Light `i`'s frame where it is a rectangle sampled by solid angle: then its
    /// samples and pdfs are the frame's ([`Light::rectangle_frame`]).
    #[inline]
    fn rectangle(&self, i: usize) -> Option<&RectangleFrame> {
        match self.quad_sampling {
            QuadSampling::SolidAngle => self.sampler.rectangles[i].as_ref(),
            QuadSampling::Area => None,
        }
    }
}

/// The rectangle lights' direction samples that a wave's next-event estimation asks for,
/// drawn together, four requests to a vector of `f64` lanes
/// ([`RectangleFrame::seen_from_lanes`], [`SphericalRectangles::sample`]): each is the
/// bits [`Emitters::sample`] would draw for it alone, whatever its company. One sample is a
/// chain of about 300 cycles of f64 square roots, divisions and trigonometry; in lanes,
/// two of its divisions or roots issue at once, and no call to libm waits on the last.
#[derive(Debug, Default)]
pub(crate) struct RectangleDraws {
    /// Per request: the shading point, `u` and the light.
    requests: Vec<(Vec3, Vec2, usize)>,
    /// Per group of [`RECTANGLE_LANES`] requests, while they are drawn: the lights seen
    /// from their points.
    seen: Vec<SphericalRectangles>,
    /// Per request, after [`RectangleDraws::draw`]: its sample.
    pub drawn: Vec<Option<DirectionSample>>,
}

impl RectangleDraws {
    pub fn clear(&mut self) {
        self.requests.clear();
        self.seen.clear();
        self.drawn.clear();
    }

    /// Asks for a sample of rectangle light `light` from `p` with `u`; its index in
    /// `drawn`.
    #[inline(always)]
    pub fn request(&mut self, p: Vec3, light: usize, u: Vec2) -> usize {
        self.requests.push((p, u, light));
        self.requests.len() - 1
    }

    /// Draws every request's sample: what [`Emitters::sample`] would draw for it. The
    /// rectangles seen from every point first, then every sample: a loop of both would
    /// be too long for the processor to start one group's chain before the last one's
    /// ends. A short last group repeats its last request in the lanes it lacks.
    pub fn draw(&mut self, emitters: &Emitters<'_>) {
        let frame = |light| emitters.rectangle(light).expect("requests name rectangles");
        self.seen.clear();
        self.seen
            .extend(self.requests.chunks(RECTANGLE_LANES).map(|group| {
                let request = |i: usize| group[i.min(group.len() - 1)];
                RectangleFrame::seen_from_lanes(
                    std::array::from_fn(|i| frame(request(i).2)),
                    std::array::from_fn(|i| request(i).0),
                )
            }));
        // Whole groups of slots, each drawn into in place; the last group's spare lanes
        // are cut off after.
        self.drawn.clear();
        self.drawn.resize(self.seen.len() * RECTANGLE_LANES, None);
        let slots = self.drawn.as_chunks_mut::<RECTANGLE_LANES>().0;
        for ((group, seen), slots) in self
            .requests
            .chunks(RECTANGLE_LANES)
            .zip(&self.seen)
            .zip(slots)
        {
            seen.sample_into(
                std::array::from_fn(|i| group[i.min(group.len() - 1)].1),
                slots,
            );
            // The lanes whose light has no spherical rectangle from their point are
            // sampled by area, alone.
            for (i, (&(p, u, light), slot)) in group.iter().zip(slots).enumerate() {
                if !seen.exists(i) {
                    *slot = frame(light).sample_seen(None, p, u);
                }
            }
        }
        self.drawn.truncate(self.requests.len());
    }
}

/// The sphere lights' direction samples that a wave's next-event estimation asks for,
/// drawn together, a request per lane ([`sample_sphere_light_lanes`]): each is the bits
/// [`lueur_sampling::sample_sphere_light`] gives for it, whatever its company and the
/// SIMD level. One sample is a chain of dependent square roots and divisions; in lanes,
/// a vector of them costs about what one does.
#[derive(Debug, Default)]
pub(crate) struct SphereDraws {
    /// Per request: the shading point, the sphere's centre and radius, `u`.
    requests: LaneGroups<9>,
    /// Per request, after [`SphereDraws::draw`]: its sample.
    pub drawn: Vec<Option<DirectionSample>>,
}

impl SphereDraws {
    pub fn clear(&mut self) {
        self.requests.clear();
        self.drawn.clear();
    }

    /// Asks for a sample of the sphere `(center, radius)` from `p` with `u`; its index in
    /// `drawn`. Inlined: out of line, its vectors pass through memory, stored in pieces
    /// and loaded whole, and each load waits for its stores to retire.
    #[inline(always)]
    pub fn request(&mut self, p: Vec3, (center, radius): (Vec3, f32), u: Vec2) -> usize {
        self.requests.push([
            p.x, p.y, p.z, center.x, center.y, center.z, radius, u.x, u.y,
        ])
    }

    /// Draws every request's sample on `level` (the widest available where it is not).
    pub fn draw(&mut self, level: SimdLevel) {
        self.drawn.clear();
        if self.requests.is_empty() {
            return;
        }
        // The level is available: `or_widest` says so.
        let _ = level.or_widest().dispatch(DrawSpheres {
            rows: self.requests.groups(),
            len: self.requests.len(),
            drawn: &mut self.drawn,
        });
    }
}

/// The kernel of [`SphereDraws::draw`].
struct DrawSpheres<'a> {
    rows: &'a [[[f32; MAX_LANES]; 9]],
    len: usize,
    drawn: &'a mut Vec<Option<DirectionSample>>,
}

impl LaneKernel for DrawSpheres<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(self) {
        let DrawSpheres { rows, len, drawn } = self;
        let width = L::LANES.min(MAX_LANES);
        debug_assert_eq!(MAX_LANES % width, 0);
        let vectors = rows.iter().flat_map(|group| {
            (0..MAX_LANES)
                .step_by(width)
                .map(move |first| (group, first))
        });
        for (v, (group, first)) in vectors.enumerate() {
            let (start, end) = (v * width, ((v + 1) * width).min(len));
            if start >= end {
                break;
            }
            let mut lanes = [L::splat(0.0); 9];
            for (lane, row) in lanes.iter_mut().zip(group) {
                *lane = L::load(&row[first..first + width]);
            }
            let [px, py, pz, cx, cy, cz, radius, u0, u1] = lanes;
            let (p, center) = (LaneVec3::new(px, py, pz), LaneVec3::new(cx, cy, cz));
            let s = sample_sphere_light_lanes(p, center, radius, [u0, u1]);
            let mut out = [[0f32; MAX_LANES]; 11];
            let values = [
                s.wi.x, s.wi.y, s.wi.z, s.distance, s.pdf, s.point.x, s.point.y, s.point.z,
                s.normal.x, s.normal.y, s.normal.z,
            ];
            for (row, v) in out.iter_mut().zip(values) {
                v.store(&mut row[..width]);
            }
            let valid = L::bits(s.valid);
            drawn.extend((0..end - start).map(|lane| {
                (valid >> lane & 1 == 1).then(|| DirectionSample {
                    wi: Vec3::new(out[0][lane], out[1][lane], out[2][lane]),
                    distance: out[3][lane],
                    pdf: out[4][lane],
                    point: Vec3::new(out[5][lane], out[6][lane], out[7][lane]),
                    normal: Vec3::new(out[8][lane], out[9][lane], out[10][lane]),
                })
            }));
        }
    }
}

/// The cosine-weighted local directions of a wave's next-event estimation toward the sky,
/// drawn together, a request per lane ([`sample_cosine_hemisphere_lanes`]): each is the bits
/// `sample_cosine_hemisphere` gives for its numbers alone, whatever its company and the
/// SIMD level. One is a chain of a division, a sine and cosine, and a square root, which
/// the shading of its vertex would wait on; in lanes, a vector of them costs about what
/// one does.
#[derive(Debug, Default)]
pub(crate) struct CosineDraws {
    /// Per request, its two numbers, padded with zeros to whole vectors when drawn.
    u0: Vec<f32>,
    u1: Vec<f32>,
    /// Per request, after [`CosineDraws::draw`]: its direction's coordinates, one row
    /// each, as the kernel stores its vectors (a `Vec3` per lane, picked out of them one
    /// at a time, took most of the kernel's time).
    drawn: [Vec<f32>; 3],
    /// How many requests were drawn.
    len: usize,
}

impl CosineDraws {
    pub fn clear(&mut self) {
        self.u0.clear();
        self.u1.clear();
        self.len = 0;
    }

    /// Request `k`'s direction, after [`CosineDraws::draw`].
    #[inline(always)]
    pub fn drawn(&self, k: usize) -> Vec3 {
        debug_assert!(k < self.len);
        let [x, y, z] = &self.drawn;
        Vec3::new(x[k], y[k], z[k])
    }

    /// How many requests were drawn.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Asks for the direction of `u`; its index in `drawn`.
    pub fn request(&mut self, u: Vec2) -> usize {
        self.u0.push(u.x);
        self.u1.push(u.y);
        self.u0.len() - 1
    }

    /// Draws every request's direction on `level` (the widest available where it is not).
    pub fn draw(&mut self, level: SimdLevel) {
        let n = self.u0.len();
        self.len = n;
        if n == 0 {
            return;
        }
        // Whole vectors of the widest level, so that every load and store is of a known
        // length.
        let padded = n.next_multiple_of(MAX_LANES);
        self.u0.resize(padded, 0.0);
        self.u1.resize(padded, 0.0);
        for row in &mut self.drawn {
            row.resize(padded, 0.0);
        }
        // The level is available: `or_widest` says so.
        let _ = level.or_widest().dispatch(DrawCosines {
            u: [&self.u0, &self.u1],
            n,
            drawn: &mut self.drawn,
        });
    }
}

/// The kernel of [`CosineDraws::draw`].
struct DrawCosines<'a> {
    u: [&'a [f32]; 2],
    n: usize,
    drawn: &'a mut [Vec<f32>; 3],
}

impl LaneKernel for DrawCosines<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(self) {
        let DrawCosines {
            u: [u0, u1],
            n,
            drawn: [x, y, z],
        } = self;
        let width = L::LANES.min(MAX_LANES);
        for start in (0..n).step_by(width) {
            let lanes = start..start + width;
            let d = sample_cosine_hemisphere_lanes([
                L::load(&u0[lanes.clone()]),
                L::load(&u1[lanes.clone()]),
            ]);
            d.x.store(&mut x[lanes.clone()]);
            d.y.store(&mut y[lanes.clone()]);
            d.z.store(&mut z[lanes]);
        }
    }
}
