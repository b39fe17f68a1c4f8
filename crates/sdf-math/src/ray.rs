//! Rays: the one piece of geometry every other module in the crate shares.

use glam::Vec3;

/// A ray `origin + t * dir`; `dir` is unit length, so `t` is a Euclidean distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts (`t = 0`).
    pub origin: Vec3,
    /// Unit direction of travel.
    pub dir: Vec3,
}

impl Ray {
    /// A ray from `origin` along `dir`, which is normalised here so that `t` keeps meaning
    /// distance even when the caller's direction has drifted from unit length.
    ///
    /// A zero or non-finite `dir` gives a NaN direction rather than a made-up one: tracing
    /// such a ray then ends at once as [`TraceOutcome::GaveUp`](crate::TraceOutcome::GaveUp).
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        // Not `Vec3::normalize`: with glam's assert features that panics on a zero vector.
        Self {
            origin,
            dir: dir * dir.length_recip(),
        }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_normalises_and_at_walks_distance() {
        let ray = Ray::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.0, 4.0));
        assert_eq!(ray.dir, Vec3::Z);
        assert_eq!(ray.at(2.0), Vec3::new(1.0, 2.0, 5.0));
    }

    #[test]
    fn zero_direction_is_nan_not_a_panic() {
        let ray = Ray::new(Vec3::ZERO, Vec3::ZERO);
        assert!(ray.dir.is_nan());
    }
}
