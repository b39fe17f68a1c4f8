//! The scene as the integrator sees it: SDF objects with materials, lights,
//! an optional sky and the camera, validated once. Its queries live beside
//! it: acceleration in `geometry.rs`, tracing in `trace.rs`, the lights in
//! `light.rs` and the choice among them in `light_sampler.rs`.

use glam::Vec3;
use lueur_materials::Material;
use lueur_sdf_math::{PreparedSdf, Ray, Sdf};

use crate::geometry::Geometry;
use crate::light::valid_rgb;
use crate::light_sampler::{Emitters, LightSampler};
use crate::{Camera, Light, Marching, QuadSampling, SceneError};

/// One piece of geometry and what it is made of.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Its shape.
    pub sdf: Sdf,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

/// A complete scene, ready to render.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Geometry.
    pub objects: Vec<Object>,
    /// Materials referenced by the objects.
    pub materials: Vec<Material>,
    /// Light sources.
    pub lights: Vec<Light>,
    /// Constant radiance arriving from every direction a ray escapes to.
    pub sky: Option<Vec3>,
    /// The viewpoint.
    pub camera: Camera,
    // Derived at construction.
    pub(crate) geometry: Geometry,
    /// The choice among the lights and the sky that light sampling aims at.
    light_sampler: LightSampler,
    size: f32,
}

impl Scene {
    /// Assembles and validates a scene.
    pub fn new(
        objects: Vec<Object>,
        materials: Vec<Material>,
        lights: Vec<Light>,
        sky: Option<Vec3>,
        camera: Camera,
    ) -> Result<Scene, SceneError> {
        for (i, o) in objects.iter().enumerate() {
            if o.material >= materials.len() {
                return Err(SceneError::MissingMaterial {
                    object: i,
                    material: o.material,
                });
            }
        }
        for (i, l) in lights.iter().enumerate() {
            if !l.is_valid() {
                return Err(SceneError::InvalidLight(i));
            }
        }
        if let Some(sky) = sky
            && !valid_rgb(sky)
        {
            return Err(SceneError::InvalidSky);
        }
        let geometry = Geometry::new(&objects);

        let light_sampler = LightSampler::new(&lights, sky.is_some());

        // The radius of a box around camera, bounded objects and lights:
        // only the far limit follows it (hit thresholds and spawn offsets
        // are local to each ray and hit, see `surface::March`).
        let mut lo = camera.position();
        let mut hi = lo;
        let mut include = |c: Vec3, r: f32| {
            lo = lo.min(c - Vec3::splat(r));
            hi = hi.max(c + Vec3::splat(r));
        };
        for o in &objects {
            if let Some((c, r)) = o.sdf.bounding_sphere() {
                include(c, r);
            }
        }
        for l in &lights {
            if let Some((l_lo, l_hi)) = l.bounds() {
                lo = lo.min(l_lo);
                hi = hi.max(l_hi);
            }
        }
        let positive_or_one = |v: f32| if v.is_finite() && v > 0.0 { v } else { 1.0 };
        let size = positive_or_one(0.5 * (hi - lo).length());

        Ok(Scene {
            objects,
            materials,
            lights,
            sky,
            camera,
            geometry,
            light_sampler,
            size,
        })
    }

    /// The scene's own length scale: the radius of a box around the camera,
    /// the bounded objects and the lights. The far limit of rays is
    /// proportional to it, and nothing else: no tolerance that decides where
    /// a ray starts or stops depends on the size of the whole scene.
    pub fn scale(&self) -> f32 {
        self.size
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
            lights: &self.lights,
            sky: self.sky,
            sampler: &self.light_sampler,
            quad_sampling,
        }
    }

    /// Radiance emitted by light `light` toward `-ray.dir` from the point at
    /// `t` along `ray`.
    pub fn emitted(&self, light: usize, ray: &Ray, t: f32) -> Vec3 {
        self.lights[light].emitted(ray, t)
    }
}
