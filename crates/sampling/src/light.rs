//! The result type shared by the light-sampling routines.

use glam::Vec3;

use crate::math::normalize_with_length;

/// A direction sampled toward a light from a shading point `p`, with its
/// solid-angle pdf.
///
/// Invariant: every field is finite, `wi` is unit length, `distance > 0` and
/// `pdf > 0`. A routine that cannot meet this returns `None` instead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionSample {
    /// Unit direction from the shading point toward `point`.
    pub wi: Vec3,
    /// Distance from the shading point to `point`.
    pub distance: f32,
    /// Density of `wi` with respect to solid angle at the shading point.
    pub pdf: f32,
    /// The sampled point on the light.
    pub point: Vec3,
    /// The light's unit surface normal at `point` (for a one-sided emitter,
    /// the emitting side).
    pub normal: Vec3,
}

impl DirectionSample {
    /// Builds the sample from `p` toward `point`, checking the invariant.
    pub(crate) fn toward(p: Vec3, point: Vec3, normal: Vec3, pdf: f32) -> Option<Self> {
        let (wi, distance) = normalize_with_length(point - p)?;
        let sample = Self {
            wi,
            distance,
            pdf,
            point,
            normal,
        };
        sample.is_valid().then_some(sample)
    }

    /// Builds the sample when the pdf depends on the direction and distance.
    pub(crate) fn toward_with(
        p: Vec3,
        point: Vec3,
        normal: Vec3,
        pdf: impl FnOnce(Vec3, f32) -> f32,
    ) -> Option<Self> {
        let (wi, distance) = normalize_with_length(point - p)?;
        let sample = Self {
            wi,
            distance,
            pdf: pdf(wi, distance),
            point,
            normal,
        };
        sample.is_valid().then_some(sample)
    }

    fn is_valid(&self) -> bool {
        self.pdf.is_finite()
            && self.pdf > 0.0
            && self.distance.is_finite()
            && self.distance > 0.0
            && self.wi.is_finite()
            && self.point.is_finite()
            && self.normal.is_finite()
    }
}
