//! The scene as the integrator sees it: the scene model with what tracing
//! and light sampling derive from it once. The queries live beside it:
//! acceleration in `geometry/`, tracing in `trace.rs` and the choice
//! among the lights in `light_sampler.rs`.

use glam::Vec3;
use lueur_scene::{Marching, QuadSampling, Scene};
use lueur_sdf_math::{PreparedSdf, Ray, SimdLevel};

use crate::geometry::Geometry;
use crate::light_sampler::{Emitters, LightSampler};

/// A [`Scene`] prepared for rendering: its objects' fields folded for fast
/// evaluation and bounded for culling, and the choice among its emitters.
/// Preparing costs a pass over the objects; a progressive render prepares
/// once and renders every pass from it.
#[derive(Clone, Debug)]
pub struct PreparedScene {
    scene: Scene,
    pub(crate) geometry: Geometry,
    /// The choice among the lights and the sky that light sampling aims at.
    light_sampler: LightSampler,
    scale: f32,
    execution: Execution,
}

/// How renders of a scene run on this machine, which never changes an image: the
/// instruction set the ray streams run on, and how many paths are in flight together.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Execution {
    /// The vectors of fast marching's streams; a level this CPU lacks runs on the widest
    /// it has ([`SimdLevel::detect`]). By default the widest it has: AVX-512's 16 lanes
    /// ran the shipped scenes 1.09-1.15x as fast as AVX2's 8 on the Intel Xeon measured
    /// (docs/PERFORMANCE.md, "Sixteen lanes with bit masks").
    pub simd: SimdLevel,
    /// Paths a wave keeps in flight (at least 1): enough to fill a vector's lanes many
    /// times over, few enough that a wave's rays stay in cache. A path that ends hands its
    /// slot to the next sample, so the streams stay this wide until a tile runs dry.
    pub wave: usize,
    /// Whether a wave keeps each path in a lane of the vectors from one vertex to the
    /// next, where the lane wave models the scene (`mis`, one sphere light, boxes, spheres
    /// and planes: issue 18's Cornell box), rather than as a record that each stage copies
    /// into lanes and back. The same bits either way; by default in lanes, 1.25x as fast
    /// on that scene (docs/PERFORMANCE.md, "The lane wave").
    pub lane_wave: bool,
}

impl Execution {
    /// Paths per wave by default: 32 vectors of 16 lanes, measured against 16 to 4096
    /// paths in docs/PERFORMANCE.md (on 16 lanes, 512 ran 1-5% faster than 256 and as
    /// fast as 1024).
    pub const WAVE: usize = 512;
}

impl Default for Execution {
    fn default() -> Execution {
        Execution {
            simd: SimdLevel::detect(),
            wave: Execution::WAVE,
            lane_wave: true,
        }
    }
}

impl PreparedScene {
    /// Prepares `scene`; validation is [`Scene::new`]'s.
    pub fn new(scene: Scene) -> PreparedScene {
        let geometry = Geometry::new(&scene.objects);
        let light_sampler = LightSampler::new(&scene.lights, scene.sky.is_some());
        let scale = scene.scale();
        PreparedScene {
            scene,
            geometry,
            light_sampler,
            scale,
            execution: Execution::default(),
        }
    }

    /// The same scene, rendered as `execution` says.
    pub fn with_execution(self, execution: Execution) -> PreparedScene {
        PreparedScene { execution, ..self }
    }

    /// How renders of this scene run.
    pub fn execution(&self) -> Execution {
        self.execution
    }

    /// The scene this was prepared from.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// [`PreparedScene::scale`], computed once.
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// The union of all objects as a distance field, evaluated as `marching` says (both
    /// modes give the same value).
    pub fn distance(&self, p: Vec3, marching: Marching) -> f32 {
        self.geometry.distance(p, marching)
    }

    /// Object `i`'s field as fast marching evaluates it (its transforms folded).
    pub(crate) fn prepared(&self, i: usize) -> &PreparedSdf {
        self.geometry.prepared(i)
    }

    /// The object closest to `p` (after a hit, the one that was hit).
    pub fn closest_object(&self, p: Vec3) -> usize {
        self.geometry.closest_object(p)
    }

    /// The emitters light sampling chooses among, with their pdfs, quads
    /// sampled as `quad_sampling` says.
    pub(crate) fn emitters(&self, quad_sampling: QuadSampling) -> Emitters<'_> {
        Emitters {
            lights: &self.scene.lights,
            sky: self.scene.sky,
            sampler: &self.light_sampler,
            quad_sampling,
        }
    }

    /// Radiance emitted by light `light` toward `-ray.dir` from the point at
    /// `t` along `ray`.
    pub fn emitted(&self, light: usize, ray: &Ray, t: f32) -> Vec3 {
        self.scene.lights[light].emitted(ray, t)
    }
}

impl From<Scene> for PreparedScene {
    fn from(scene: Scene) -> PreparedScene {
        PreparedScene::new(scene)
    }
}
