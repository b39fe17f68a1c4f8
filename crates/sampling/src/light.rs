//! The result type shared by the light-sampling routines.

use glam::Vec3;
use lueur_sdf_math::{Lane, LaneVec3};

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

/// [`DirectionSample`] per lane, with where each lane's is one (`valid`: the invariant
/// holds); elsewhere the values are meaningless.
#[derive(Clone, Copy, Debug)]
pub struct DirectionSampleLanes<L: Lane> {
    /// Unit direction from each shading point toward its `point`.
    pub wi: LaneVec3<L>,
    /// Distance from each shading point to its `point`.
    pub distance: L,
    /// Density of `wi` with respect to solid angle.
    pub pdf: L,
    /// The sampled points on the light.
    pub point: LaneVec3<L>,
    /// The light's unit normals at `point`.
    pub normal: LaneVec3<L>,
    /// Where the lane holds a sample.
    pub valid: L::Mask,
}

impl<L: Lane> DirectionSampleLanes<L> {
    /// [`DirectionSample::toward_with`] per lane: the sample from `p` toward `point`, where
    /// the routine's pdf there is `pdf` and it has one where `has_pdf`. (Values, not a
    /// closure as the scalar form takes: a vector kernel inlines only what is marked to
    /// be inlined.)
    #[inline(always)]
    pub(crate) fn toward(
        p: LaneVec3<L>,
        (point, normal): (LaneVec3<L>, LaneVec3<L>),
        (wi, distance, toward): (LaneVec3<L>, L, L::Mask),
        (pdf, has_pdf): (L, L::Mask),
    ) -> Self {
        let zero = L::splat(0.0);
        // `DirectionSample::is_valid`, and the inputs' finiteness, which the scalar
        // routines check first.
        let valid = L::and(
            L::and(L::and(toward, has_pdf), p.finite()),
            L::and(
                L::and(pdf.finite(), pdf.gt(zero)),
                L::and(
                    L::and(distance.finite(), distance.gt(zero)),
                    L::and(point.finite(), normal.finite()),
                ),
            ),
        );
        Self {
            wi,
            distance,
            pdf,
            point,
            normal,
            valid,
        }
    }
}

impl DirectionSampleLanes<f32> {
    /// The one lane's sample, `None` where it has none.
    #[inline]
    pub fn single(self) -> Option<DirectionSample> {
        self.valid.then(|| DirectionSample {
            wi: self.wi.into(),
            distance: self.distance,
            pdf: self.pdf,
            point: self.point.into(),
            normal: self.normal.into(),
        })
    }
}
