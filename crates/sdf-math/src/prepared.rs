//! A shape prepared once for evaluation in a hot loop: its chain of rigid transforms and
//! uniform scales folded into one affine map.

use glam::{Affine3A, Mat3A, Quat, Vec3};

use crate::lanes::{Lane, LaneDistance, LaneVec3};
use crate::{DistanceField, Sdf};

/// [`Sdf`] with the transforms above its first non-transform node folded into one affine
/// map and one factor: `distance(p) = factor * shape.distance(to_local(p))`.
///
/// The same field as the tree up to `f32` rounding (a few ulps: the map is applied as one
/// matrix, not node by node), with the same Lipschitz bound and exactness, but evaluated
/// without walking the transform nodes and without the tree's per-evaluation
/// normalisation of each rotation (a division), which is what a moved and turned
/// primitive, the common object of a scene file, spends most of its time on. Shapes
/// under a degenerate scale (which the tree evaluates to `+inf`) keep that node.
#[derive(Clone, Debug, PartialEq)]
pub struct PreparedSdf {
    to_local: Affine3A,
    /// Whether the map only moves (its matrix is the identity): the common object of a
    /// scene file, whose frame is then `p + translation`, three additions instead of nine
    /// products and nine sums.
    moved_only: bool,
    factor: f32,
    shape: Sdf,
    lipschitz: f32,
}

impl PreparedSdf {
    /// Folds the transforms at the top of `sdf`.
    pub fn new(sdf: &Sdf) -> PreparedSdf {
        let mut to_local = Affine3A::IDENTITY;
        let mut factor = 1.0f32;
        let mut node = sdf;
        loop {
            match node {
                Sdf::Translate { offset, child } => {
                    to_local = Affine3A::from_translation(-*offset) * to_local;
                    node = child;
                }
                Sdf::Rotate { rotation, child } => {
                    to_local = Affine3A::from_mat3(inverse_rotation(*rotation).into()) * to_local;
                    node = child;
                }
                Sdf::Scale { factor: s, child }
                    if s.abs() >= f32::MIN_POSITIVE && s.is_finite() =>
                {
                    factor *= s.abs();
                    to_local = Affine3A::from_scale(Vec3::splat(1.0 / *s)) * to_local;
                    node = child;
                }
                _ => break,
            }
        }
        PreparedSdf {
            to_local,
            moved_only: to_local.matrix3 == Mat3A::IDENTITY,
            factor,
            shape: node.clone(),
            lipschitz: sdf.lipschitz(),
        }
    }
}

/// The matrix of `q / |q|` inverted (transposed), the identity for a degenerate `q`, as
/// [`Sdf::Rotate`] evaluates it.
fn inverse_rotation(q: Quat) -> Mat3A {
    let n = q.length();
    if !(n * n).is_normal() {
        return Mat3A::IDENTITY;
    }
    Mat3A::from_quat(q / n).transpose()
}

impl PreparedSdf {
    /// The magnitude of the numbers the shape is evaluated with at `p`, as a world length:
    /// the field's rounding error at `p` is a few `f32::EPSILON` of it. For a primitive
    /// that is only moved it is the largest coordinate of `p` in the primitive's frame
    /// (about its size, wherever it stands, since `p - offset` is exact near it); a turned
    /// or scaled one mixes or multiplies the coordinates of `p` first, which rounds them
    /// at `|p|`.
    #[inline]
    pub fn evaluation_scale(&self, p: Vec3) -> f32 {
        self.evaluation_scale_lanes(LaneVec3::from(p))
    }

    /// [`PreparedSdf::evaluation_scale`] at each lane's point.
    #[inline(always)]
    pub fn evaluation_scale_lanes<L: Lane>(&self, p: LaneVec3<L>) -> L {
        let own = L::splat(self.factor) * self.local(p).abs().max_element();
        if self.moved_only {
            own
        } else {
            own.max(p.abs().max_element())
        }
    }
}

impl PreparedSdf {
    /// `p` in the shape's frame: `p + T` for a map that only moves, else glam's
    /// `Affine3A::transform_point3a` written out in its order, `((X p.x + Y p.y) + Z p.z)
    /// + T` with the matrix's columns `X`, `Y`, `Z`.
    #[inline(always)]
    fn local<L: Lane>(&self, p: LaneVec3<L>) -> LaneVec3<L> {
        let m = &self.to_local.matrix3;
        let t = self.to_local.translation;
        if self.moved_only {
            return LaneVec3::new(
                p.x + L::splat(t.x),
                p.y + L::splat(t.y),
                p.z + L::splat(t.z),
            );
        }
        LaneVec3::new(
            affine_coordinate(p, Vec3::new(m.x_axis.x, m.y_axis.x, m.z_axis.x), t.x),
            affine_coordinate(p, Vec3::new(m.x_axis.y, m.y_axis.y, m.z_axis.y), t.y),
            affine_coordinate(p, Vec3::new(m.x_axis.z, m.y_axis.z, m.z_axis.z), t.z),
        )
    }
}

/// One coordinate of the affine map: `((row.x p.x + row.y p.y) + row.z p.z) + t`.
#[inline(always)]
fn affine_coordinate<L: Lane>(p: LaneVec3<L>, row: Vec3, t: f32) -> L {
    L::splat(row.x) * p.x + L::splat(row.y) * p.y + L::splat(row.z) * p.z + L::splat(t)
}

/// The one definition of the prepared field: the affine map, the tree, the factor.
impl LaneDistance for PreparedSdf {
    // Always: a vector kernel that calls it must compile it for its own instruction set.
    #[inline(always)]
    fn distance_lanes<L: Lane>(&self, p: LaneVec3<L>) -> L {
        L::splat(self.factor) * self.shape.distance_lanes(self.local(p))
    }
}

impl DistanceField for PreparedSdf {
    #[inline]
    fn distance(&self, p: Vec3) -> f32 {
        self.distance_lanes(LaneVec3::from(p))
    }

    #[inline]
    fn lipschitz(&self) -> f32 {
        self.lipschitz
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prepared_is_the_tree_up_to_rounding() {
        let shapes = [
            Sdf::torus(0.5, 0.2)
                .rotate(Quat::from_rotation_x(0.4))
                .translate(Vec3::new(0.0, 0.45, 0.0)),
            Sdf::cuboid(Vec3::new(1.0, 0.1, 2.0))
                .translate(Vec3::X)
                .rotate(Quat::from_rotation_y(1.1))
                .scale(-2.5)
                .translate(Vec3::new(3.0, -1.0, 0.5)),
            // A rotation that is not unit, as a hand-built tree may hold.
            Sdf::Rotate {
                rotation: Quat::from_rotation_z(0.7) * 3.0,
                child: Box::new(Sdf::capsule(Vec3::ZERO, Vec3::X, 0.3)),
            },
            Sdf::death_star(1.0, 0.7, 1.1).rotate(Quat::from_euler(
                glam::EulerRot::YXZ,
                -1.0,
                0.0,
                0.35,
            )),
            Sdf::sphere(1.0).scale(0.0),
            Sdf::union(vec![Sdf::sphere(1.0), Sdf::sphere(0.5).translate(Vec3::Y)])
                .translate(Vec3::Z),
        ];
        for sdf in &shapes {
            let prepared = PreparedSdf::new(sdf);
            assert_eq!(prepared.lipschitz(), sdf.lipschitz());
            for i in 0..500 {
                let f = |k: u32| ((i * k) % 997) as f32 / 997.0 * 8.0 - 4.0;
                let p = Vec3::new(f(7), f(13), f(31));
                let (a, b) = (sdf.distance(p), prepared.distance(p));
                assert!(
                    a == b || (a - b).abs() <= 1e-5 * (1.0 + a.abs() + p.length()),
                    "{sdf:?} at {p}: tree {a}, prepared {b}"
                );
            }
        }
    }
}
