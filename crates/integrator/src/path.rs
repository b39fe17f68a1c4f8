//! The path-tracing estimator of one pixel sample: the loop that strings the
//! stages together (intersect, emission, delta lights, scatter, roulette).
//! Each stage is a function of its inputs only, so that a tracer of batches
//! of rays can call the same stages on many paths at once.

use glam::Vec3;
use lueur_materials::Material;
use lueur_sampling::Sampler;
use lueur_sdf_math::Ray;

use crate::strategy::{self, EmissionWeight, Lighting, Scatter, Vertex, VertexSample};
use crate::surface::{March, SurfaceHit, SurfacePoint};
use lueur_scene::RenderSettings;

use crate::{Hit, PreparedScene, TraceCounters};

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

    /// The counters of the ray that leaves vertex `depth` of a path (the
    /// camera's at 0).
    fn path_ray(&mut self, depth: u32) -> &mut TraceCounters {
        if depth == 0 {
            &mut self.camera
        } else {
            &mut self.bounce
        }
    }
}

/// State carried from one vertex to the next for weighting emission.
#[derive(Clone, Copy)]
struct Previous {
    /// Point and facing normal of the last scattering vertex.
    p: Vec3,
    n: Vec3,
    /// Whether the path travels inside a solid: it started at a camera
    /// inside an object and every vertex since was shaded on the inside.
    /// (Only then: an outside hit whose coarse normal faces away from the
    /// viewer is rounding, not a way in.)
    in_solid: bool,
    /// How emission found along the current ray counts.
    emission: EmissionWeight,
}

impl Previous {
    /// The camera, as the vertex before the first: what its rays find counts
    /// in full.
    fn camera(position: Vec3) -> Previous {
        Previous {
            p: position,
            n: Vec3::ZERO,
            in_solid: false,
            emission: EmissionWeight::Full,
        }
    }
}

/// What one path estimate needs besides its random numbers.
pub(crate) struct Estimator<'a> {
    pub scene: &'a PreparedScene,
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
    let lighting = Lighting::of(scene, settings, &march);
    let mut radiance = Vec3::ZERO;
    let mut beta = Vec3::ONE;
    let mut previous = Previous::camera(ray.origin);
    let mut depth = 0u32;
    let mut params = march.camera;
    loop {
        let kind = counters.path_ray(depth);
        let maybe_inside = depth == 0 && march.camera_inside || previous.in_solid;
        let hit = scene.intersect_leaving(
            &ray,
            previous.p,
            &params,
            march.marching,
            kind,
            maybe_inside,
        );
        let Some(on_surface) = SurfaceHit::of(hit) else {
            radiance += emission_found(&lighting, &previous, &ray, hit, beta);
            break;
        };
        if depth >= settings.max_depth {
            break;
        }
        let surface = SurfacePoint::at_hit(scene, &march, &ray, on_surface);
        let vertex = Vertex {
            at: surface,
            wo: -ray.dir,
            material: scene.scene().materials[scene.scene().objects[on_surface.object].material],
        };
        let u = VertexSample::draw(sampler, id.pixel, id.index, depth);

        let through = (beta, &mut radiance);
        let scatter = shade(
            &lighting,
            settings,
            &vertex,
            &u,
            through,
            &mut counters.shadow,
        );
        let Some(scatter) = scatter else {
            break;
        };

        beta *= scatter.weight;
        depth += 1;
        if beta == Vec3::ZERO || !beta.is_finite() {
            break;
        }
        previous = Previous {
            in_solid: surface.inside && (depth == 1 && march.camera_inside || previous.in_solid),
            p: surface.p,
            n: surface.n,
            emission: scatter.emission,
        };
        ray = Ray::new(surface.origin, scatter.wi);
        params = march.secondary;

        match roulette(beta, depth, settings.roulette_depth, u.roulette) {
            Some(survivor) => beta = survivor,
            None => break,
        }
    }
    radiance
}

/// Adds to `radiance` the light a vertex gathers by shadow rays (delta
/// lights, and next-event estimation where the strategy uses it), times
/// the path's throughput `beta`; gives the direction the path scatters in:
/// the material's for a mirror, the strategy's at a diffuse vertex.
fn shade(
    lighting: &Lighting<'_>,
    settings: &RenderSettings,
    vertex: &Vertex,
    u: &VertexSample,
    (beta, radiance): (Vec3, &mut Vec3),
    shadow: &mut TraceCounters,
) -> Option<Scatter> {
    match vertex.material {
        Material::Mirror { .. } => strategy::mirror(vertex, u.bsdf),
        Material::Lambertian { .. } => {
            *radiance += beta * lighting.delta_lights(vertex, shadow);
            if strategy::uses_next_event(settings.strategy) {
                *radiance += beta * lighting.next_event(vertex, u, shadow);
            }
            strategy::scatter(settings.strategy, &lighting.emitters, vertex, u)
        }
    }
}

/// What the path gains where it leaves the objects: the sky on a miss, or a
/// light's surface, weighted as the last scattering event said
/// ([`EmissionWeight`]).
fn emission_found(
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

/// Russian roulette (pbrt-v4 style) after `roulette_depth` scattering
/// events, on the throughput's largest component: the surviving throughput,
/// reweighted by `1 / (1 - q)` so that the estimate stays unbiased, or
/// `None` where the path ends.
fn roulette(beta: Vec3, depth: u32, roulette_depth: u32, u: f32) -> Option<Vec3> {
    let max_beta = beta.max_element();
    if depth >= roulette_depth && max_beta < 1.0 {
        let q = (1.0 - max_beta).max(0.0);
        if u < q {
            return None;
        }
        return Some(beta / (1.0 - q));
    }
    Some(beta)
}
