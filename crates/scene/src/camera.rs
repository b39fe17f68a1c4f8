//! Pinhole camera.

use glam::{Vec2, Vec3};
use lueur_sdf_math::Ray;

use crate::SceneError;

/// A pinhole camera; pixel (0, 0) is the top-left corner of the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    position: Vec3,
    /// Unit vectors of the view frame: right, up, forward.
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    /// tan(vfov / 2).
    tan_half_vfov: f32,
}

impl Camera {
    /// Builds a camera at `position` looking at `look_at`, `vfov_degrees`
    /// being the full vertical field of view.
    pub fn new(
        position: Vec3,
        look_at: Vec3,
        up: Vec3,
        vfov_degrees: f32,
    ) -> Result<Camera, SceneError> {
        let forward = (look_at - position).normalize_or_zero();
        if forward == Vec3::ZERO || !forward.is_finite() {
            return Err(SceneError::Camera(
                "`look_at` must differ from `position`".into(),
            ));
        }
        // Nearly parallel is as bad as parallel: the cross product is then
        // mostly rounding and the image's roll is arbitrary. 1e-3 is about
        // 0.06 degrees between `up` and the view direction.
        let up_unit = up.normalize_or_zero();
        let cross = forward.cross(up_unit);
        let right = if cross.length() > 1e-3 {
            cross.normalize()
        } else {
            Vec3::ZERO
        };
        if right == Vec3::ZERO || !right.is_finite() {
            return Err(SceneError::Camera(
                "`up` must not be zero nor (nearly) parallel to the view direction (look_at - position)"
                    .into(),
            ));
        }
        if !(vfov_degrees > 0.0 && vfov_degrees < 180.0) {
            return Err(SceneError::Camera(format!(
                "`vfov` must be in (0, 180) degrees, got {vfov_degrees}"
            )));
        }
        let up = right.cross(forward);
        Ok(Camera {
            position,
            right,
            up,
            forward,
            tan_half_vfov: (vfov_degrees.to_radians() * 0.5).tan(),
        })
    }

    /// The camera's position.
    pub fn position(&self) -> Vec3 {
        self.position
    }

    /// The ray through film position `film` (in pixels, continuous) of an
    /// image of `width` x `height` pixels.
    pub fn generate_ray(&self, film: Vec2, width: u32, height: u32) -> Ray {
        let aspect = width as f32 / height as f32;
        let ndc_x = 2.0 * film.x / width as f32 - 1.0;
        let ndc_y = 1.0 - 2.0 * film.y / height as f32;
        let dir = self.forward
            + self.right * (ndc_x * aspect * self.tan_half_vfov)
            + self.up * (ndc_y * self.tan_half_vfov);
        // `Ray::new` normalises: once is enough.
        Ray::new(self.position, dir)
    }

    /// Angle subtended by one pixel at the image centre: the footprint that
    /// sets the hit epsilon of camera rays (cone tracing).
    pub fn pixel_angle(&self, height: u32) -> f32 {
        2.0 * self.tan_half_vfov / height as f32
    }
}
