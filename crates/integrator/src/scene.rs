//! The scene as the integrator sees it: the scene model with what tracing
//! and light sampling derive from it once. The queries live beside it:
//! acceleration in `geometry.rs`, tracing in `trace.rs` and the choice
//! among the lights in `light_sampler.rs`.

use glam::Vec3;
use lueur_scene::{Marching, QuadSampling, Scene};
use lueur_sdf_math::{PreparedSdf, Ray};

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
        }
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
