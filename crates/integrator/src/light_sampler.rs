//! The emitter choice (pbrt-v4's `LightSampler`): which emitter light
//! sampling aims at, with what probability, and the pdfs of the directions
//! that result, summed over the emitters. The sky is an emitter like the
//! lights with an area, sampled by the cosine around the normal. And the
//! direction samples a wave of paths draws together for next-event
//! estimation: toward sphere lights, with their estimates (`SphereNextEvents`), rectangles
//! (`RectangleDraws`) and the sky (`CosineDraws`).

use glam::{Vec2, Vec3};
use lueur_sampling::{
    DirectionSample, DiscreteDistribution, Frame, RECTANGLE_LANES, RectangleFrame,
    SphericalRectangles, cosine_hemisphere_pdf, sample_cosine_hemisphere,
    sample_cosine_hemisphere_lanes,
};
use lueur_sdf_math::{Lane, LaneGroups, LaneKernel, LaneVec3, MAX_LANES, SimdLevel};

use lueur_scene::{EmitterSample, Light, QuadSampling, SphereLight};

use crate::next_event::{AimedSphereLanes, DiffuseLanes, sphere_next_event_lanes};
use crate::trace::ShadowRay;

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
    /// A rectangle light's ([`RectangleDraws`]).
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

    /// The light `u_choice` makes [`Emitters::sample`] aim at, where that is a sphere
    /// light: whose next-event estimates a wave makes in lanes ([`SphereNextEvents`]).
    #[inline]
    pub fn chosen_sphere(&self, u_choice: f32) -> Option<ChosenSphere> {
        if !self.sampler.spheres {
            return None;
        }
        match self.sampler.choose(u_choice)? {
            (Emitter::Light(i), pmf) => self.lights[i].as_sphere().map(|sphere| ChosenSphere {
                light: i,
                sphere,
                pmf,
            }),
            (Emitter::Sky, _) => None,
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

/// A sphere light that light sampling chose ([`Emitters::chosen_sphere`]): its index
/// among the scene's lights, its fields, and the probability of the choice.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ChosenSphere {
    pub light: usize,
    pub sphere: SphereLight,
    pub pmf: f32,
}

/// The next-event estimates toward sphere lights that a wave's diffuse vertices ask for,
/// made together, a vertex per lane: the light's direction sample
/// ([`lueur_sampling::sample_sphere_light_lanes`]), the tests [`Light::sample_drawn`] puts it to, and the
/// estimate ([`NextEventLanes`]). Each is the bits [`crate::strategy::Lighting::next_event`]
/// gives for its vertex alone, whatever its company and the SIMD level. One estimate is a
/// chain of dependent square roots and divisions (the sample's, the shadow ray's, the
/// weight's); in lanes, a vector of them costs about what one does.
#[derive(Debug, Default)]
pub(crate) struct SphereNextEvents {
    /// Per request: the vertex (shading point, normal, `wo . n`, origin, albedo) and `u`.
    requests: LaneGroups<15>,
    /// Per request: which of `spheres` it aims at.
    aims: Vec<usize>,
    /// The sphere lights the requests aim at, each once: its index among the scene's
    /// lights, its fields and the probability of its choice. A scene's few sphere lights
    /// are looked up here rather than written into every request's rows.
    spheres: Vec<(usize, SphereLight, f32)>,
    /// Per group of requests, after [`SphereNextEvents::draw`]: the shadow rays'
    /// directions and distances, and the contributions, a row each.
    estimates: Vec<[[f32; MAX_LANES]; 7]>,
    /// Per request, after [`SphereNextEvents::draw`]: what its estimate came to.
    outcomes: Vec<SphereNextEvent>,
}

/// What a vertex's next-event estimate toward a sphere light came to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum SphereNextEvent {
    /// Nothing, whatever its shadow ray would find.
    Nothing,
    /// A shadow ray, and what it brings if free: [`SphereNextEvents::write`] writes them.
    Found,
    /// An estimate whose shadow ray does not aim at its point ([`crate::surface::ShadowAim::at_point`]):
    /// made again alone, by [`crate::strategy::Lighting::next_event`].
    Alone,
}

impl SphereNextEvents {
    pub fn clear(&mut self) {
        self.requests.clear();
        self.aims.clear();
        self.spheres.clear();
        self.estimates.clear();
        self.outcomes.clear();
    }

    /// Asks for the estimate of `vertex` toward `chosen` with `u`; its index. Inlined: out
    /// of line, its vectors pass through memory, stored in pieces and loaded whole, and
    /// each load waits for its stores to retire.
    #[inline(always)]
    pub fn request(&mut self, vertex: &DiffuseLanes<f32>, chosen: &ChosenSphere, u: Vec2) -> usize {
        let aim = match self.spheres.iter().rposition(|s| s.0 == chosen.light) {
            Some(aim) => aim,
            None => {
                self.spheres.push((chosen.light, chosen.sphere, chosen.pmf));
                self.spheres.len() - 1
            }
        };
        self.aims.push(aim);
        let v = vertex;
        self.requests.push([
            v.p.x, v.p.y, v.p.z, v.n.x, v.n.y, v.n.z, v.wo_n, v.origin.x, v.origin.y, v.origin.z,
            v.albedo.x, v.albedo.y, v.albedo.z, u.x, u.y,
        ])
    }

    /// Makes every request's estimate on `level` (the widest available where it is not).
    pub fn draw(&mut self, level: SimdLevel) {
        self.estimates.clear();
        self.outcomes.clear();
        if self.requests.is_empty() {
            return;
        }
        // The level is available: `or_widest` says so.
        let _ = level.or_widest().dispatch(EstimateSpheres {
            rows: self.requests.groups(),
            len: self.requests.len(),
            aims: &self.aims,
            spheres: &self.spheres,
            estimates: &mut self.estimates,
            outcomes: &mut self.outcomes,
        });
    }

    /// What request `k`'s estimate came to.
    #[inline(always)]
    pub fn outcome(&self, k: usize) -> SphereNextEvent {
        self.outcomes[k]
    }

    /// Writes request `k`'s shadow ray, from `origin` toward light `target`, and what it
    /// brings if free, into their slots, where its estimate found them. A field at a time:
    /// records made whole first are stored in pieces and loaded whole, and the loads wait
    /// for the stores (docs/PERFORMANCE.md, "Stores loaded whole").
    #[inline(always)]
    pub fn write(
        &self,
        k: usize,
        (origin, target): (Vec3, usize),
        ray: &mut ShadowRay,
        contribution: &mut Vec3,
    ) {
        debug_assert_eq!(self.outcomes[k], SphereNextEvent::Found);
        let (rows, lane) = (&self.estimates[k / MAX_LANES], k % MAX_LANES);
        ray.ray.origin = origin;
        ray.ray.dir = Vec3::new(rows[0][lane], rows[1][lane], rows[2][lane]);
        ray.distance = rows[3][lane];
        ray.target = Some(target);
        *contribution = Vec3::new(rows[4][lane], rows[5][lane], rows[6][lane]);
    }
}

/// The kernel of [`SphereNextEvents::draw`].
struct EstimateSpheres<'a> {
    rows: &'a [[[f32; MAX_LANES]; 15]],
    len: usize,
    aims: &'a [usize],
    spheres: &'a [(usize, SphereLight, f32)],
    estimates: &'a mut Vec<[[f32; MAX_LANES]; 7]>,
    outcomes: &'a mut Vec<SphereNextEvent>,
}

impl LaneKernel for EstimateSpheres<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(self) {
        let EstimateSpheres {
            rows,
            len,
            aims,
            spheres,
            estimates,
            outcomes,
        } = self;
        let width = L::LANES.min(MAX_LANES);
        debug_assert_eq!(MAX_LANES % width, 0);
        estimates.resize(rows.len(), [[0.0; MAX_LANES]; 7]);
        for (v, (group, out)) in rows.iter().zip(estimates.iter_mut()).enumerate() {
            for first in (0..MAX_LANES).step_by(width) {
                let start = v * MAX_LANES + first;
                if start >= len {
                    break;
                }
                let end = (start + width).min(len);
                let mut lanes = [L::splat(0.0); 15 + 8];
                for (lane, row) in lanes.iter_mut().zip(group) {
                    *lane = L::load(&row[first..first + width]);
                }
                // Each lane's sphere: a vector of one sphere (a scene of one sphere light)
                // splats it; else each lane's is laid out first.
                let aims = &aims[start..end];
                let sphere = |(_, s, pmf): (usize, SphereLight, f32)| {
                    let (c, r) = (s.center, s.radiance);
                    [c.x, c.y, c.z, s.radius, r.x, r.y, r.z, pmf]
                };
                if aims.iter().all(|&a| a == aims[0]) {
                    for (lane, value) in lanes[15..].iter_mut().zip(sphere(spheres[aims[0]])) {
                        *lane = L::splat(value);
                    }
                } else {
                    let mut rows = [[0.0; MAX_LANES]; 8];
                    for j in 0..width {
                        let values = sphere(spheres[aims[j.min(aims.len() - 1)]]);
                        for (row, value) in rows.iter_mut().zip(values) {
                            row[j] = value;
                        }
                    }
                    for (lane, row) in lanes[15..].iter_mut().zip(&rows) {
                        *lane = L::load(&row[..width]);
                    }
                }
                let vec3 = |i: usize| LaneVec3::new(lanes[i], lanes[i + 1], lanes[i + 2]);
                let vertex = DiffuseLanes {
                    p: vec3(0),
                    n: vec3(3),
                    wo_n: lanes[6],
                    origin: vec3(7),
                    albedo: vec3(10),
                };
                let u = [lanes[13], lanes[14]];
                let (center, radius, radiance, pmf) = (vec3(15), lanes[18], vec3(19), lanes[22]);
                let sphere = AimedSphereLanes {
                    center,
                    radius,
                    radiance,
                    pmf,
                };
                let (found, aim, contribution) = sphere_next_event_lanes(&vertex, &sphere, u);
                let values = [
                    aim.dir.x,
                    aim.dir.y,
                    aim.dir.z,
                    aim.distance,
                    contribution.x,
                    contribution.y,
                    contribution.z,
                ];
                for (row, value) in out.iter_mut().zip(values) {
                    value.store(&mut row[first..first + width]);
                }
                let found = L::bits(found);
                let at_point = L::bits(aim.at_point);
                outcomes.extend((0..end - start).map(|lane| {
                    match (found >> lane & 1 == 1, at_point >> lane & 1 == 1) {
                        (false, _) => SphereNextEvent::Nothing,
                        (true, true) => SphereNextEvent::Found,
                        (true, false) => SphereNextEvent::Alone,
                    }
                }));
            }
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
