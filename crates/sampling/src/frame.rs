//! Orthonormal frames for moving directions between world space and the
//! z-up local space in which every warp of this crate is written.

use glam::Vec3;
use lueur_sdf_math::{Lane, LaneVec3};

/// A right-handed orthonormal basis: `s` and `t` span the tangent plane and
/// `n` is the normal (`s x t = n`). Warps produce directions in the local frame
/// where `n` is `+z`; [`Frame::to_world`] moves them out.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// First tangent (local `+x`).
    pub s: Vec3,
    /// Second tangent (local `+y`).
    pub t: Vec3,
    /// Normal (local `+z`).
    pub n: Vec3,
}

impl Frame {
    /// Builds a frame around the unit vector `n` without branches or
    /// normalisation.
    ///
    /// Duff, Burgess, Christensen, Hery, Kensler, Liani and Villemin 2017,
    /// "Building an Orthonormal Basis, Revisited", JCGT 6(1), Listing 3: the
    /// form with the sign of `n.z`, which stays accurate as `n.z -> -1` (the
    /// singularity of Frisvad's original construction). `n` must be unit length;
    /// the result is then orthonormal to within a few ulps.
    #[inline]
    pub fn from_normal(n: Vec3) -> Self {
        let FrameLanes { s, t, n } = FrameLanes::from_normal(n.into());
        Self {
            s: s.into(),
            t: t.into(),
            n: n.into(),
        }
    }

    /// Local (z-up) to world: `v.x * s + v.y * t + v.z * n`.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        v.x * self.s + v.y * self.t + v.z * self.n
    }

    /// World to local (z-up): the projections of `v` on `s`, `t` and `n`.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }
}

/// [`Frame`] for a normal per lane: the one definition of the construction, whose
/// one-lane instance [`Frame::from_normal`] is.
#[derive(Clone, Copy, Debug)]
pub struct FrameLanes<L> {
    /// First tangent (local `+x`).
    pub s: LaneVec3<L>,
    /// Second tangent (local `+y`).
    pub t: LaneVec3<L>,
    /// Normal (local `+z`).
    pub n: LaneVec3<L>,
}

impl<L: Lane> FrameLanes<L> {
    /// [`Frame::from_normal`], per lane. The sign is that of `n.z`, with `-0` taken as
    /// positive: both signs give an orthonormal frame at `n.z = 0`.
    #[inline(always)]
    pub fn from_normal(n: LaneVec3<L>) -> Self {
        let one = L::splat(1.0);
        let sign = L::select(n.z.lt(L::splat(0.0)), -one, one);
        let a = -one / (sign + n.z);
        let b = n.x * n.y * a;
        let s = LaneVec3::new(one + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = LaneVec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { s, t, n }
    }

    /// [`Frame::to_world`], per lane.
    #[inline(always)]
    pub fn to_world(self, v: LaneVec3<L>) -> LaneVec3<L> {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(n: Vec3) {
        let n = n.normalize();
        let f = Frame::from_normal(n);
        for (name, v) in [("s", f.s), ("t", f.t), ("n", f.n)] {
            assert!((v.length() - 1.0).abs() < 1e-5, "{name} not unit for {n}");
        }
        assert!(
            f.s.dot(f.t).abs() < 1e-5 && f.s.dot(f.n).abs() < 1e-5 && f.t.dot(f.n).abs() < 1e-5
        );
        assert!(
            (f.s.cross(f.t) - f.n).length() < 1e-5,
            "left-handed for {n}"
        );
        let v = Vec3::new(0.3, -0.5, 0.8);
        assert!((f.to_local(f.to_world(v)) - v).length() < 1e-5);
        assert!((f.to_world(Vec3::Z) - n).length() < 1e-6);
    }

    #[test]
    fn orthonormal_right_handed_round_trip() {
        for n in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::Y,
            Vec3::new(0.0, 0.0, -0.0).with_z(-1.0),
            Vec3::new(1e-4, -2e-4, -1.0),
            Vec3::new(1e-4, 2e-4, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(-0.3, 0.9, -0.1),
        ] {
            check(n);
        }
    }
}
