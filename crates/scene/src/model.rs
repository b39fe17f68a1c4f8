//! The scene itself: SDF objects with their materials, the lights, an
//! optional sky and the camera, validated once.

use glam::Vec3;
use lueur_materials::Material;
use lueur_sdf_math::Sdf;

use crate::light::valid_rgb;
use crate::{Camera, Light};

/// One piece of geometry and what it is made of.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Its shape.
    pub sdf: Sdf,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

/// A complete scene, ready to be prepared for rendering.
#[derive(Clone, Debug, PartialEq)]
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
}

impl Scene {
    /// Assembles and validates a scene: every object's material exists,
    /// every light is valid, the sky's radiance is finite and non-negative.
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
        Ok(Scene {
            objects,
            materials,
            lights,
            sky,
            camera,
        })
    }

    /// The scene's own length scale: the radius of a box around the camera,
    /// the bounded objects and the lights (1 if that is empty). The far
    /// limit of rays is proportional to it, and nothing else: no tolerance
    /// that decides where a ray starts or stops depends on the size of the
    /// whole scene.
    pub fn scale(&self) -> f32 {
        let mut lo = self.camera.position();
        let mut hi = lo;
        let mut include = |c: Vec3, r: f32| {
            lo = lo.min(c - Vec3::splat(r));
            hi = hi.max(c + Vec3::splat(r));
        };
        for o in &self.objects {
            if let Some((c, r)) = o.sdf.bounding_sphere() {
                include(c, r);
            }
        }
        for l in &self.lights {
            if let Some((l_lo, l_hi)) = l.bounds() {
                lo = lo.min(l_lo);
                hi = hi.max(l_hi);
            }
        }
        let positive_or_one = |v: f32| if v.is_finite() && v > 0.0 { v } else { 1.0 };
        positive_or_one(0.5 * (hi - lo).length())
    }
}

/// A scene that cannot be rendered as given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// The camera is degenerate.
    #[error("invalid camera: {0}")]
    Camera(String),
    /// An object names a material that does not exist.
    #[error("object {object} uses material {material}, which does not exist")]
    MissingMaterial {
        /// Index of the object.
        object: usize,
        /// The missing material index.
        material: usize,
    },
    /// A light has a non-positive size, a non-finite position or a negative
    /// radiance.
    #[error("light {0} is degenerate (zero size, non-finite, or negative radiance)")]
    InvalidLight(usize),
    /// The sky's radiance is negative or not finite.
    #[error("the sky's radiance must be finite and non-negative")]
    InvalidSky,
}
