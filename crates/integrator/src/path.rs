//! The path-tracing estimator of one pixel sample.

use glam::Vec3;
use lueur_materials::{HemisphereSampling, Material};
use lueur_sampling::{Sampler, power_heuristic};
use lueur_sdf_math::{
    DistanceField, FALLBACK_NORMAL, PreparedSdf, Ray, TraceParams, gradient, gradient_central,
    position_rounding,
};

use crate::{Hit, Marching, Scene, TraceCounters};
use crate::{RenderSettings, Strategy};

/// Sampler dimensions consumed per path vertex, so that each bounce reads
/// the same dimensions whatever happened before (low-discrepancy point sets
/// keep their structure per bounce).
pub(crate) const DIMS_PER_VERTEX: u32 = 8;
/// Dimensions before the first vertex: the position in the pixel.
/// Within a vertex, in order: emitter choice (1), point on the emitter (2),
/// mixture choice (1), BSDF direction (2), Russian roulette (1), unused (1).
pub(crate) const CAMERA_DIMS: u32 = 2;

/// Counters per kind of ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounters {
    /// Rays from the camera.
    pub camera: TraceCounters,
    /// Rays continuing a path after a scattering event.
    pub bounce: TraceCounters,
    /// Shadow rays of next-event estimation.
    pub shadow: TraceCounters,
}

impl RayCounters {
    /// Adds another set of counters.
    pub fn merge(&mut self, o: &RayCounters) {
        self.camera.merge(&o.camera);
        self.bounce.merge(&o.bounce);
        self.shadow.merge(&o.shadow);
    }
}

/// Marching parameters for one render. Only the far limit follows the scene's size; the
/// hit thresholds are the pixel cone (camera rays) or a fraction of the distance travelled
/// (secondary rays), raised per ray to what f32 resolves at its origin
/// ([`TraceParams::resolving`], in `Scene`), and never depend on what else the scene holds.
#[derive(Clone, Copy, Debug)]
pub(crate) struct March {
    pub camera: TraceParams,
    pub secondary: TraceParams,
    /// Whether the (pinhole) camera sits inside a solid: every camera ray
    /// then starts inside. Decided once per render, not per ray.
    pub camera_inside: bool,
    /// Normals by central differences (6 evaluations), the naive mode's
    /// reference, instead of the tetrahedron (4).
    pub central_normals: bool,
}

impl March {
    pub fn new(scene: &Scene, settings: &RenderSettings) -> March {
        let camera = TraceParams {
            t_min: 0.0,
            t_max: FAR_LIMIT * scene.scale(),
            max_steps: settings.max_steps,
            eps_abs: 0.0,
            eps_rel: settings.pixel_epsilon * scene.camera.pixel_angle(settings.height),
        };
        let secondary = TraceParams {
            eps_rel: settings.epsilon_rel,
            ..camera
        };
        March {
            camera,
            secondary,
            camera_inside: scene.distance(scene.camera.position()) < 0.0,
            central_normals: scene.marching == Marching::Naive,
        }
    }
}

/// Rays travel at most this many scene radii ([`Scene::scale`]): the one length that
/// follows the whole scene, since where a ray gives up looking decides nothing about where
/// it starts or stops on a surface.
const FAR_LIMIT: f32 = 100.0;

/// A ray leaves a surface at least this many roundings above it: of the hit point's
/// position ([`position_rounding`]) and of the hit object's own evaluation there
/// ([`PreparedSdf::evaluation_scale`]). Four times [`lueur_sdf_math::HIT_ULPS`], so the
/// new ray's first sample is clear of its own hit threshold, with the point's rounding
/// (half a unit) and the field's (a few) to spare.
const SPAWN_ROUNDINGS: f32 = 16.0;

/// The finite-difference step of normals and of the Newton step is at least this many
/// roundings of the object's evaluation: the field's rounding error over the step is then
/// below 1e-3 of the gradient (the rounding of positions is removed by the normal
/// estimators themselves, which use the real offsets of their samples).
const GRADIENT_ROUNDINGS: f32 = 1024.0;

/// What limits the precision of one hit: the tracer's shell there and f32 rounding.
#[derive(Clone, Copy, Debug)]
pub(crate) struct HitPrecision {
    /// The hit threshold in force where the tracer stopped: it stopped somewhere in a
    /// shell this thick.
    pub shell: f32,
    /// The rounding of the hit point's position.
    pub position: f32,
    /// The rounding of the hit object's field at the hit point.
    pub evaluation: f32,
    /// Whether the ray reached the surface from inside the solid (it was
    /// marched by the negated field).
    pub from_inside: bool,
}

impl HitPrecision {
    /// The precision of a hit on `object` at `hit` within a shell `shell` thick.
    pub fn at(object: &PreparedSdf, hit: Vec3, shell: f32, from_inside: bool) -> HitPrecision {
        HitPrecision {
            shell,
            position: position_rounding(hit),
            evaluation: f32::EPSILON * object.evaluation_scale(hit),
            from_inside,
        }
    }

    /// The smallest offset of a ray's origin above the surface.
    fn spawn_floor(&self) -> f32 {
        SPAWN_ROUNDINGS * self.position.max(self.evaluation)
    }
}

/// A hit made usable for shading: the tracer stops anywhere in a shell of
/// width `epsilon` around the surface (a sixteenth of a pixel for camera
/// rays, by default), so
/// shading there would measure light from the wrong point. One Newton step
/// *along the ray* moves the point onto the surface where the ray crosses
/// it; rays leave from just above it, by an offset that covers what the
/// step left over. Sampling, pdfs and MIS weights use `p`; only ray origins
/// use `origin` (pbrt-v4's split between the interaction point and
/// `SpawnRay`).
pub(crate) struct SurfacePoint {
    /// The point on the surface.
    pub p: Vec3,
    /// Unit normal, facing the side the ray came from (surfaces are two-sided).
    pub n: Vec3,
    /// Where rays leaving the surface start.
    pub origin: Vec3,
    /// Whether the ray arrived from inside the solid (the normal was
    /// flipped inward), so rays leaving this point travel inside too.
    pub inside: bool,
}

impl SurfacePoint {
    /// 7 field evaluations (9 where the ray grazes): the distance at the hit
    /// and one step further along the ray, the tetrahedron gradient at the
    /// corrected point (central differences, 6 evaluations, in naive mode),
    /// and the distance there.
    ///
    /// Why along the ray and not along the normal: projecting a point of the
    /// shell onto the surface along the normal moves it sideways by up to
    /// `epsilon tan(theta)`, and with it the normal and everything a mirror
    /// reflects, by an amount that depends on where in the shell the tracer
    /// happened to stop. Measured: the light's reflection in the donut's
    /// mirror spheres came out 10% brighter with fast marching than naive
    /// (the image mean +1.0%, z = 9) only because the two stopped at
    /// different depths of the shell. Along the ray, the shading point is
    /// the ray's own intersection (to second order) wherever the tracer
    /// stopped, and the normal is taken there.
    fn new<F: DistanceField>(
        sdf: &F,
        hit: Vec3,
        wo: Vec3,
        precision: HitPrecision,
        march: &March,
    ) -> SurfacePoint {
        let spawn_floor = precision.spawn_floor();
        let epsilon = precision.shell;
        let reach = 4.0 * epsilon.max(spawn_floor);
        // The difference step is an eighth of the hit shell: finite
        // differences blur a crease (the Death Star's rim) over about h,
        // and at the shell's width (then a quarter pixel for camera rays) that
        // blur biased whole rows of rim pixels, differently for the
        // tetrahedron and for central differences (measured: z = 7 between
        // the two at 32x32, 256 spp). Smooth surfaces do not care: their
        // gradient is exact at any h. Below, the field's own rounding would
        // show in the normal.
        let h = (epsilon * 0.125)
            .max(GRADIENT_ROUNDINGS * precision.evaluation)
            .max(2.0 * precision.position);
        // Newton along the ray: f(hit + s dir) = 0 with the slope of f along
        // the ray by a forward difference (over the offset actually taken,
        // which rounding makes differ from h far from the origin). Taken only
        // where the ray meets the surface at more than ~75 degrees from
        // grazing (the slope is at least a quarter of a unit gradient) and
        // the step stays within a few shells; elsewhere the normal projection
        // below does the work.
        let dir = -wo;
        let f_hit = sdf.distance(hit);
        let ahead = hit + dir * h;
        let slope = (sdf.distance(ahead) - f_hit) / (ahead - hit).dot(dir);
        let along = -f_hit / slope;
        let on_ray = slope.abs() >= 0.25 && along.is_finite() && along.abs() <= reach;
        let start = if on_ray { hit + dir * along } else { hit };
        let grad = if march.central_normals {
            gradient_central(sdf, start, h)
        } else {
            gradient(sdf, start, h)
        };
        let g = grad.length();
        let n_geo = if g.is_finite() && g > 0.0 {
            grad / g
        } else {
            FALLBACK_NORMAL
        };
        // What is left (second order on the ray; the whole shell where the
        // ray grazes) goes along the normal: f / |grad f| is the distance to
        // first order, also for bounds (L > 1).
        let f_start = sdf.distance(start);
        let step = f_start / g;
        let (p, residual) = if on_ray {
            (start, (f_start / g.max(1e-3)).abs())
        } else if step.is_finite() && step.abs() <= reach {
            let p = start - n_geo * step;
            (p, (sdf.distance(p) / g.max(1e-3)).abs())
        } else {
            (start, (f_start / g.max(1e-3)).abs())
        };
        // A ray marched inside the solid meets it from inside even where it
        // grazes the wall and the normal's sign is noise.
        let inside = precision.from_inside || n_geo.dot(wo) < 0.0;
        let n = if inside { -n_geo } else { n_geo };
        // The roundings where the ray will start: at `p`, which the Newton step
        // may have moved far from where the tracer stopped (along a ray that
        // meets the surface at 20 degrees, four times the shell).
        let moved = f32::EPSILON * (p - hit).abs().max_element();
        let spawn_floor = spawn_floor
            .max(SPAWN_ROUNDINGS * position_rounding(p).max(precision.evaluation + moved));
        let offset = spawn_floor.max(if residual.is_finite() {
            4.0 * residual
        } else {
            epsilon
        });
        SurfacePoint {
            p,
            n,
            origin: p + n * offset,
            inside,
        }
    }

    /// A ray from the surface toward what lies at `distance` along `wi` from
    /// `p`, and the distance to it from the ray's origin.
    fn shadow_ray(&self, wi: Vec3, distance: f32) -> (Ray, f32) {
        if distance.is_finite() {
            let to = self.p + wi * distance - self.origin;
            let d = to.length();
            if d > 0.0 && d.is_finite() {
                return (Ray::new(self.origin, to / d), d);
            }
        }
        (Ray::new(self.origin, wi), distance)
    }
}

/// State carried from one vertex to the next for weighting emission.
#[derive(Clone, Copy)]
struct Previous {
    /// Point and facing normal of the last scattering vertex.
    p: Vec3,
    n: Vec3,
    /// pdf with which the BSDF chose the current direction (MIS only).
    bsdf_pdf: f32,
    /// Whether the path travels inside a solid: it started at a camera
    /// inside an object and every vertex since was shaded on the inside.
    /// (Only then: an outside hit whose coarse normal faces away from the
    /// viewer is rounding, not a way in.)
    in_solid: bool,
    /// Whether emission found along this ray counts in full: camera rays,
    /// delta bounces, and every strategy but `mis` (where next-event
    /// estimation has already counted part of it).
    full_weight: bool,
}

/// What one path estimate needs besides its random numbers.
pub(crate) struct Estimator<'a> {
    pub scene: &'a Scene,
    pub settings: &'a RenderSettings,
    pub march: March,
}

/// Which sample of which pixel a path belongs to.
#[derive(Clone, Copy)]
pub(crate) struct SampleId {
    pub pixel: [u32; 2],
    pub index: u32,
}

/// Radiance arriving along `ray`, estimated by one path.
pub(crate) fn radiance(
    estimator: &Estimator<'_>,
    mut ray: Ray,
    sampler: &mut Sampler,
    id: SampleId,
    counters: &mut RayCounters,
) -> Vec3 {
    let Estimator {
        scene,
        settings,
        march,
    } = *estimator;
    let strategy = settings.strategy;
    let mut radiance = Vec3::ZERO;
    let mut beta = Vec3::ONE;
    let mut previous = Previous {
        p: ray.origin,
        n: Vec3::ZERO,
        bsdf_pdf: 0.0,
        in_solid: false,
        full_weight: true,
    };
    let mut depth = 0u32;
    let mut params = march.camera;
    let started_inside = march.camera_inside;

    loop {
        let kind = if depth == 0 {
            &mut counters.camera
        } else {
            &mut counters.bounce
        };
        let maybe_inside = depth == 0 && started_inside || previous.in_solid;
        let hit = scene.intersect_leaving(&ray, previous.p, &params, kind, maybe_inside);
        let (t, object, epsilon, marched_inside) = match hit {
            None => {
                if let Some(sky) = scene.sky {
                    let w = if previous.full_weight {
                        1.0
                    } else {
                        power_heuristic(
                            1.0,
                            previous.bsdf_pdf,
                            1.0,
                            scene.emitters().sky_pdf(previous.n, ray.dir),
                        )
                    };
                    radiance += beta * sky * w;
                }
                break;
            }
            Some(Hit::Light { t, light }) => {
                // Light hits are measured from the last vertex, not from the lifted origin.
                let from = Ray {
                    origin: previous.p,
                    dir: ray.dir,
                };
                let le = scene.emitted(light, &from, t);
                if le != Vec3::ZERO {
                    let w = if previous.full_weight {
                        1.0
                    } else {
                        let light_pdf = scene
                            .emitters()
                            .light_pdf(light, previous.p, previous.n, ray.dir);
                        power_heuristic(1.0, previous.bsdf_pdf, 1.0, light_pdf)
                    };
                    radiance += beta * le * w;
                }
                break;
            }
            Some(Hit::Surface {
                t,
                object,
                epsilon,
                inside,
            }) => (t, object, epsilon, inside),
        };
        if depth >= settings.max_depth {
            break;
        }

        let wo = -ray.dir;
        let hit = ray.at(t);
        let precision = HitPrecision::at(scene.prepared(object), hit, epsilon, marched_inside);
        let surface = match scene.marching {
            Marching::Naive => {
                SurfacePoint::new(&scene.objects[object].sdf, hit, wo, precision, &march)
            }
            Marching::Fast => SurfacePoint::new(scene.prepared(object), hit, wo, precision, &march),
        };
        let (p, n, origin) = (surface.p, surface.n, surface.origin);
        let material = scene.materials[scene.objects[object].material];

        sampler.start_pixel_sample(id.pixel, id.index, CAMERA_DIMS + depth * DIMS_PER_VERTEX);
        let u_emitter_choice = sampler.next_1d();
        let u_emitter = sampler.next_2d();
        let u_mixture = sampler.next_1d();
        let u_bsdf = sampler.next_2d();
        let u_roulette = sampler.next_1d();

        let secondary = march.secondary;

        // Choose the next direction and how emission along it is weighted.
        let (wi, throughput, bsdf_pdf, full_weight) = match material {
            Material::Mirror { .. } => {
                let Some(s) = material.sample(wo, n, u_bsdf, HemisphereSampling::Cosine) else {
                    break;
                };
                (s.wi, s.weight(n), 0.0, true)
            }
            Material::Lambertian { .. } => {
                radiance +=
                    beta * directional_light(scene, &material, origin, wo, n, &secondary, counters);
                match strategy {
                    Strategy::Uniform | Strategy::Cosine => {
                        let hemisphere = if strategy == Strategy::Uniform {
                            HemisphereSampling::Uniform
                        } else {
                            HemisphereSampling::Cosine
                        };
                        let Some(s) = material.sample(wo, n, u_bsdf, hemisphere) else {
                            break;
                        };
                        (s.wi, s.weight(n), s.pdf, true)
                    }
                    Strategy::Light => {
                        let Some((es, _)) =
                            scene.emitters().sample(p, n, u_emitter_choice, u_emitter)
                        else {
                            break;
                        };
                        let pdf = scene.emitters().pdf(p, n, es.wi);
                        let f = material.eval(wo, es.wi, n);
                        if !(pdf > 0.0) || f == Vec3::ZERO {
                            break;
                        }
                        (es.wi, f * n.dot(es.wi).abs() / pdf, pdf, true)
                    }
                    Strategy::Mixture => {
                        let use_light = scene.emitters().any() && u_mixture >= 0.5;
                        let wi = if use_light {
                            match scene.emitters().sample(p, n, u_emitter_choice, u_emitter) {
                                Some((es, _)) => es.wi,
                                None => break,
                            }
                        } else {
                            match material.sample(wo, n, u_bsdf, HemisphereSampling::Uniform) {
                                Some(s) => s.wi,
                                None => break,
                            }
                        };
                        let hemisphere_pdf = material.pdf(wo, wi, n, HemisphereSampling::Uniform);
                        let pdf = if scene.emitters().any() {
                            0.5 * hemisphere_pdf + 0.5 * scene.emitters().pdf(p, n, wi)
                        } else {
                            hemisphere_pdf
                        };
                        let f = material.eval(wo, wi, n);
                        if !(pdf > 0.0) || f == Vec3::ZERO {
                            break;
                        }
                        (wi, f * n.dot(wi).abs() / pdf, pdf, true)
                    }
                    Strategy::Mis => {
                        radiance += beta
                            * next_event(
                                scene,
                                &material,
                                &surface,
                                wo,
                                n,
                                u_emitter_choice,
                                u_emitter,
                                &secondary,
                                counters,
                            );
                        let Some(s) = material.sample(wo, n, u_bsdf, HemisphereSampling::Cosine)
                        else {
                            break;
                        };
                        (s.wi, s.weight(n), s.pdf, false)
                    }
                }
            }
        };

        beta *= throughput;
        depth += 1;
        if beta == Vec3::ZERO || !beta.is_finite() {
            break;
        }
        previous = Previous {
            in_solid: surface.inside && (depth == 1 && started_inside || previous.in_solid),
            p,
            n,
            bsdf_pdf,
            full_weight,
        };
        ray = Ray::new(origin, wi);
        params = secondary;

        // Russian roulette (pbrt-v4 style): unbiased, since survivors are
        // reweighted by 1 / (1 - q).
        let max_beta = beta.max_element();
        if depth >= settings.roulette_depth && max_beta < 1.0 {
            let q = (1.0 - max_beta).max(0.0);
            if u_roulette < q {
                break;
            }
            beta /= 1.0 - q;
        }
    }
    radiance
}

/// Light from every directional light, by a shadow ray each.
fn directional_light(
    scene: &Scene,
    material: &Material,
    origin: Vec3,
    wo: Vec3,
    n: Vec3,
    params: &TraceParams,
    counters: &mut RayCounters,
) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for light in &scene.lights {
        if let Some((wi, irradiance)) = light.delta_arrival() {
            let cos = n.dot(wi);
            if cos <= 0.0 {
                continue;
            }
            let f = material.eval(wo, wi, n);
            if f == Vec3::ZERO {
                continue;
            }
            if scene.unoccluded(
                &Ray::new(origin, wi),
                f32::INFINITY,
                None,
                params,
                &mut counters.shadow,
            ) {
                sum += f * irradiance * cos;
            }
        }
    }
    sum
}

/// Next-event estimation toward one chosen emitter, MIS-weighted against
/// cosine BSDF sampling.
#[allow(clippy::too_many_arguments)]
fn next_event(
    scene: &Scene,
    material: &Material,
    surface: &SurfacePoint,
    wo: Vec3,
    n: Vec3,
    u_choice: f32,
    u: glam::Vec2,
    params: &TraceParams,
    counters: &mut RayCounters,
) -> Vec3 {
    let Some((es, light)) = scene.emitters().sample(surface.p, n, u_choice, u) else {
        return Vec3::ZERO;
    };
    let f = material.eval(wo, es.wi, n);
    let cos = n.dot(es.wi).abs();
    if f == Vec3::ZERO || cos == 0.0 || es.radiance == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let (shadow_ray, distance) = surface.shadow_ray(es.wi, es.distance);
    if !scene.unoccluded(&shadow_ray, distance, light, params, &mut counters.shadow) {
        return Vec3::ZERO;
    }
    let bsdf_pdf = material.pdf(wo, es.wi, n, HemisphereSampling::Cosine);
    let w = power_heuristic(1.0, es.pdf, 1.0, bsdf_pdf);
    f * es.radiance * cos * w / es.pdf
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::ray_sphere;
    use lueur_materials::Material;
    use lueur_sdf_math::Sdf;

    /// A march with the default thresholds.
    fn march(central_normals: bool) -> March {
        let params = TraceParams::default();
        March {
            camera: params,
            secondary: params,
            camera_inside: false,
            central_normals,
        }
    }

    /// Where along `ray` the sphere's field equals `level` (bisection).
    fn t_at_level(sdf: &Sdf, ray: &Ray, level: f32, mut lo: f32, mut hi: f32) -> f32 {
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if sdf.distance(ray.at(mid)) > level {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// Wherever in the shell the tracer stopped, the shading point is the
    /// ray's own intersection and the normal the one there. Projecting along
    /// the normal instead is off by up to `epsilon tan(theta)`
    /// sideways: 1.7 shells at 60 degrees, which this test would catch.
    #[test]
    fn shading_point_is_on_the_ray_wherever_the_tracer_stopped() {
        let (radius, epsilon) = (0.38f32, 0.01f32);
        let sdf = Sdf::sphere(radius);
        for central in [false, true] {
            // Head-on, 45 and 60 degrees from the normal.
            for offset in [0.0f32, 0.27, 0.33] {
                let origin = Vec3::new(offset, 0.0, 5.0);
                let ray = Ray::new(origin, -Vec3::Z);
                let t_true = ray_sphere(&ray, Vec3::ZERO, radius).unwrap();
                let x_true = ray.at(t_true);
                let n_true = x_true / radius;
                for depth in [0.0f32, 0.3, 0.6, 0.95] {
                    let t_hit = t_at_level(&sdf, &ray, depth * epsilon, 0.0, t_true);
                    let hit = ray.at(t_hit);
                    let precision = HitPrecision::at(&PreparedSdf::new(&sdf), hit, epsilon, false);
                    let s = SurfacePoint::new(&sdf, hit, -ray.dir, precision, &march(central));
                    let off = (s.p - x_true).length();
                    assert!(
                        off < 0.1 * epsilon,
                        "central {central}, offset {offset}, depth {depth}: {off} from the intersection"
                    );
                    let angle = s.n.dot(n_true).clamp(-1.0, 1.0).acos();
                    assert!(
                        angle < 0.1 * epsilon / radius,
                        "central {central}, offset {offset}, depth {depth}: normal off by {angle}"
                    );
                    assert!((s.origin - s.p).dot(s.n) > 0.0);
                }
            }
        }
    }

    /// The shape a property test puts in a scene: `size` is its largest half-extent.
    fn shape(kind: u8, size: f32) -> Sdf {
        match kind {
            0 => Sdf::sphere(size),
            1 => Sdf::cuboid(Vec3::new(1.0, 0.4, 0.7) * size),
            _ => Sdf::torus(0.7 * size, 0.3 * size),
        }
    }

    /// What else a scene may hold besides the object hit: nothing, a floor 1e4 wide under
    /// it, an unbounded plane far below, or a large sphere 1e4 away.
    fn rest_of_scene(kind: u8, below: f32) -> Vec<Sdf> {
        match kind {
            0 => vec![],
            1 => vec![Sdf::cuboid(Vec3::new(5e3, 0.5, 5e3)).translate(Vec3::Y * (below - 0.5))],
            2 => vec![Sdf::plane(Vec3::Y, below - 100.0)],
            _ => vec![Sdf::sphere(100.0).translate(Vec3::new(1e4, 0.0, 0.0))],
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(512))]

        /// At any hit, the ray leaving the surface starts no higher above it than a small
        /// multiple of the rounding at the hit (of its position and of the object's own
        /// evaluation) plus the tracer's shell there, whatever else the scene holds: a
        /// floor 1e4 wide, an unbounded plane, a sphere 1e4 away. For objects from 1e-3 to
        /// 1e2 across, up to 1e3 from the origin, that f32 resolves: at least 1000
        /// roundings of their position across their thinnest part (a torus of 1e-3 at 700
        /// from the origin has a tube four roundings thick; nothing there is resolved).
        #[test]
        fn spawn_offsets_follow_the_hit_not_the_scene(
            kind in 0u8..3,
            size_exp in -3.0f32..2.0,
            cx in -1e3f32..1e3, cy in -1e3f32..1e3, cz in -1e3f32..1e3,
            theta in 0.0f32..std::f32::consts::PI, phi in 0.0f32..std::f32::consts::TAU,
            aim in -0.5f32..0.5,
            rest in 0u8..4,
        ) {
            let size = 10f32.powf(size_exp);
            let center = Vec3::new(cx, cy, cz);
            proptest::prop_assume!(0.3 * size >= 1e3 * position_rounding(center));
            let object = shape(kind, size).translate(center);
            let dir = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            let side = dir.any_orthonormal_vector();
            let origin = center - dir * 5.0 * size + side * aim * size;
            let ray = Ray::new(origin, dir);
            let camera = crate::Camera::new(origin, center, dir.any_orthonormal_vector(), 40.0)
                .unwrap();
            let mut offsets = Vec::new();
            for others in [rest_of_scene(0, 0.0), rest_of_scene(rest, cy - 2.0 * size)] {
                let objects = std::iter::once(object.clone())
                    .chain(others)
                    .map(|sdf| crate::Object { sdf, material: 0 })
                    .collect();
                let white = Material::Lambertian { albedo: Vec3::ONE };
                let scene = Scene::new(objects, vec![white], vec![], None, camera).unwrap();
                let march = March::new(&scene, &RenderSettings::default());
                let mut counters = crate::TraceCounters::default();
                let Some(Hit::Surface { t, object: 0, epsilon, .. }) =
                    scene.intersect(&ray, &march.secondary, &mut counters)
                else {
                    continue;
                };
                let hit = ray.at(t);
                let precision = HitPrecision::at(scene.prepared(0), hit, epsilon, false);
                let s = SurfacePoint::new(scene.prepared(0), hit, -ray.dir, precision, &march);
                let offset = (s.origin - s.p).length();
                let rounding = position_rounding(s.p) + f32::EPSILON * size;
                let bound = 32.0 * rounding + 2.0 * epsilon;
                proptest::prop_assert!(
                    offset <= bound,
                    "offset {offset} above {bound} (rounding {rounding}, shell {epsilon})"
                );
                proptest::prop_assert!(offset >= 8.0 * position_rounding(s.p));
                offsets.push(offset);
            }
        }
    }
}
