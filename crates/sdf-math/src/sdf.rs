//! The `Sdf` expression tree: primitives, CSG, smooth blends and rigid transforms.

use glam::{Quat, Vec3};

use crate::DistanceField;
use crate::blend::{smooth_max, smooth_min};
use crate::primitives::{self, DeathStarKind};

/// A signed distance function as a closed enum tree: evaluation is a `match`, never a
/// virtual call, and never allocates.
///
/// Every node is Lipschitz with the bound [`Sdf::lipschitz`] reports, for every finite
/// parameter value: degenerate sizes (negative radii, a rounding radius larger than the
/// box) are clamped to the nearest meaningful shape rather than trusted. The per-variant
/// notes give the bound and whether the value is the exact Euclidean distance
/// ([`Sdf::is_exact`]) or only a bound.
#[derive(Clone, Debug, PartialEq)]
pub enum Sdf {
    /// Sphere centred at the origin. Exact; L = 1.
    Sphere {
        /// Radius; negative is treated as 0 (a point).
        radius: f32,
    },
    /// Axis-aligned box centred at the origin (iq sdBox). Exact; L = 1.
    Box {
        /// Half the side lengths; negative components are treated as 0.
        half_extents: Vec3,
    },
    /// Box with rounded edges (iq sdRoundBox); the outer size is still `half_extents`.
    /// Exact; L = 1.
    RoundBox {
        /// Half the side lengths of the outer box; negative components are treated as 0.
        half_extents: Vec3,
        /// Edge radius, clamped to `[0, smallest half extent]`.
        radius: f32,
    },
    /// Half-space below a plane: `distance = dot(p, normal) - height`. Exact with L = 1
    /// when `normal` is unit (as [`Sdf::plane`] makes it); otherwise L = `|normal|` (or 1
    /// if smaller) and only a bound.
    Plane {
        /// Outward unit normal.
        normal: Vec3,
        /// Offset of the plane along `normal`.
        height: f32,
    },
    /// Torus: a ring in the XZ plane around the Y axis (iq sdTorus). L = 1; exact unless
    /// `minor_radius > major_radius` (a self-intersecting spindle torus), where it is exact
    /// outside and a bound inside.
    Torus {
        /// Radius of the core circle; negative is treated as 0.
        major_radius: f32,
        /// Radius of the tube; negative is treated as 0.
        minor_radius: f32,
    },
    /// Cylinder with flat caps, axis Y, centred at the origin (iq sdCappedCylinder).
    /// Exact; L = 1.
    CappedCylinder {
        /// Radius; negative is treated as 0.
        radius: f32,
        /// Half the height; negative is treated as 0.
        half_height: f32,
    },
    /// Points within `radius` of the segment `ab` (iq sdCapsule). Exact; L = 1.
    Capsule {
        /// One end of the core segment.
        a: Vec3,
        /// The other end of the core segment.
        b: Vec3,
        /// Radius; negative is treated as 0.
        radius: f32,
    },
    /// Sphere of radius `ra` at the origin minus a sphere of radius `rb` at `(d, 0, 0)`
    /// (iq sdDeathStar). Exact; L = 1. When the small sphere swallows the big one nothing
    /// is left and the value is a positive bound instead.
    DeathStar {
        /// Radius of the kept sphere; negative is treated as 0.
        ra: f32,
        /// Radius of the carved sphere; negative is treated as 0.
        rb: f32,
        /// Offset of the carved sphere along x (either sign).
        d: f32,
    },
    /// `min` of the children. L = max over children. Exact outside when the children are
    /// exact outside; inside, where children overlap, only a bound. Empty: `+inf` (nothing).
    Union(Vec<Sdf>),
    /// `max` of the children. L = max over children. A bound outside (exact inside when the
    /// children are exact). Empty: `-inf` (everything).
    Intersection(Vec<Sdf>),
    /// The first child minus all the others: `max(f0, -f1, -f2, ...)`. L = max over
    /// children. A bound. Empty: `+inf`.
    Difference(Vec<Sdf>),
    /// Children folded left to right with [`smooth_min`](crate::smooth_min). L = max over
    /// children (the quadratic smin's partial derivatives are non-negative and sum to 1). A
    /// bound. Empty: `+inf`.
    SmoothUnion {
        /// Blend size: each fold undercuts the hard `min` by at most `k`.
        k: f32,
        /// The blended shapes.
        children: Vec<Sdf>,
    },
    /// Children folded with [`smooth_max`](crate::smooth_max). L = max over children. A
    /// bound. Empty: `-inf`.
    SmoothIntersection {
        /// Blend size: each fold overshoots the hard `max` by at most `k`.
        k: f32,
        /// The intersected shapes.
        children: Vec<Sdf>,
    },
    /// `smooth_max(f0, -f1)`, then the same with `-f2`, and so on. L = max over children.
    /// A bound. Empty: `+inf`.
    SmoothDifference {
        /// Blend size, as for [`Sdf::SmoothIntersection`].
        k: f32,
        /// The first shape, then the shapes carved out of it.
        children: Vec<Sdf>,
    },
    /// The child moved by `offset`. L and exactness as the child's.
    Translate {
        /// Displacement applied to the child.
        offset: Vec3,
        /// The moved shape.
        child: Box<Sdf>,
    },
    /// The child rotated by `rotation` about the origin. L and exactness as the child's.
    /// A non-unit quaternion is normalised during evaluation (a zero one is the identity),
    /// so it cannot scale space and break the bound.
    Rotate {
        /// Rotation applied to the child.
        rotation: Quat,
        /// The rotated shape.
        child: Box<Sdf>,
    },
    /// Uniform scale about the origin: `f(p) = |factor| * child(p / factor)`. L and
    /// exactness as the child's. A negative factor also mirrors through the origin; a
    /// factor of magnitude below `f32::MIN_POSITIVE` (or NaN) collapses the shape to
    /// nothing (`+inf`).
    Scale {
        /// Scale factor.
        factor: f32,
        /// The scaled shape.
        child: Box<Sdf>,
    },
}

impl Sdf {
    /// [`Sdf::Sphere`] of the given radius.
    pub fn sphere(radius: f32) -> Self {
        Self::Sphere { radius }
    }

    /// [`Sdf::Box`] with the given half extents (`box` is a Rust keyword).
    pub fn cuboid(half_extents: Vec3) -> Self {
        Self::Box { half_extents }
    }

    /// [`Sdf::RoundBox`]: outer half extents, edge radius.
    pub fn round_box(half_extents: Vec3, radius: f32) -> Self {
        Self::RoundBox {
            half_extents,
            radius,
        }
    }

    /// [`Sdf::Plane`] with `normal` normalised here (a zero or non-finite normal becomes +Y).
    pub fn plane(normal: Vec3, height: f32) -> Self {
        Self::Plane {
            normal: normal.normalize_or(Vec3::Y),
            height,
        }
    }

    /// [`Sdf::Torus`] in the XZ plane.
    pub fn torus(major_radius: f32, minor_radius: f32) -> Self {
        Self::Torus {
            major_radius,
            minor_radius,
        }
    }

    /// [`Sdf::CappedCylinder`] along Y.
    pub fn capped_cylinder(radius: f32, half_height: f32) -> Self {
        Self::CappedCylinder {
            radius,
            half_height,
        }
    }

    /// [`Sdf::Capsule`] around the segment `ab`.
    pub fn capsule(a: Vec3, b: Vec3, radius: f32) -> Self {
        Self::Capsule { a, b, radius }
    }

    /// [`Sdf::DeathStar`].
    pub fn death_star(ra: f32, rb: f32, d: f32) -> Self {
        Self::DeathStar { ra, rb, d }
    }

    /// [`Sdf::Union`].
    pub fn union(children: Vec<Sdf>) -> Self {
        Self::Union(children)
    }

    /// [`Sdf::Intersection`].
    pub fn intersection(children: Vec<Sdf>) -> Self {
        Self::Intersection(children)
    }

    /// [`Sdf::Difference`]: the first child minus the others.
    pub fn difference(children: Vec<Sdf>) -> Self {
        Self::Difference(children)
    }

    /// [`Sdf::SmoothUnion`] with blend size `k`.
    pub fn smooth_union(k: f32, children: Vec<Sdf>) -> Self {
        Self::SmoothUnion { k, children }
    }

    /// [`Sdf::SmoothIntersection`] with blend size `k`.
    pub fn smooth_intersection(k: f32, children: Vec<Sdf>) -> Self {
        Self::SmoothIntersection { k, children }
    }

    /// [`Sdf::SmoothDifference`] with blend size `k`.
    pub fn smooth_difference(k: f32, children: Vec<Sdf>) -> Self {
        Self::SmoothDifference { k, children }
    }

    /// This shape moved by `offset`.
    pub fn translate(self, offset: Vec3) -> Self {
        Self::Translate {
            offset,
            child: Box::new(self),
        }
    }

    /// This shape rotated by `rotation`, normalised here (a degenerate one becomes the
    /// identity).
    pub fn rotate(self, rotation: Quat) -> Self {
        let n = rotation.length();
        let rotation = if n.is_normal() {
            rotation / n
        } else {
            Quat::IDENTITY
        };
        Self::Rotate {
            rotation,
            child: Box::new(self),
        }
    }

    /// This shape scaled uniformly by `factor` about the origin.
    pub fn scale(self, factor: f32) -> Self {
        Self::Scale {
            factor,
            child: Box::new(self),
        }
    }

    /// Signed distance (or bound, see the variant) at `p`; negative inside.
    pub fn distance(&self, p: Vec3) -> f32 {
        match self {
            Self::Sphere { radius } => primitives::sphere(p, *radius),
            Self::Box { half_extents } => primitives::cuboid(p, *half_extents),
            Self::RoundBox {
                half_extents,
                radius,
            } => primitives::round_box(p, *half_extents, *radius),
            Self::Plane { normal, height } => primitives::plane(p, *normal, *height),
            Self::Torus {
                major_radius,
                minor_radius,
            } => primitives::torus(p, *major_radius, *minor_radius),
            Self::CappedCylinder {
                radius,
                half_height,
            } => primitives::capped_cylinder(p, *radius, *half_height),
            Self::Capsule { a, b, radius } => primitives::capsule(p, *a, *b, *radius),
            Self::DeathStar { ra, rb, d } => primitives::death_star(p, *ra, *rb, *d),
            Self::Union(children) => children
                .iter()
                .fold(f32::INFINITY, |m, c| m.min(c.distance(p))),
            Self::Intersection(children) => children
                .iter()
                .fold(f32::NEG_INFINITY, |m, c| m.max(c.distance(p))),
            Self::Difference(children) => match children.split_first() {
                None => f32::INFINITY,
                Some((first, rest)) => rest
                    .iter()
                    .fold(first.distance(p), |m, c| m.max(-c.distance(p))),
            },
            Self::SmoothUnion { k, children } => match children.split_first() {
                None => f32::INFINITY,
                Some((first, rest)) => rest
                    .iter()
                    .fold(first.distance(p), |m, c| smooth_min(m, c.distance(p), *k)),
            },
            Self::SmoothIntersection { k, children } => match children.split_first() {
                None => f32::NEG_INFINITY,
                Some((first, rest)) => rest
                    .iter()
                    .fold(first.distance(p), |m, c| smooth_max(m, c.distance(p), *k)),
            },
            Self::SmoothDifference { k, children } => match children.split_first() {
                None => f32::INFINITY,
                Some((first, rest)) => rest
                    .iter()
                    .fold(first.distance(p), |m, c| smooth_max(m, -c.distance(p), *k)),
            },
            Self::Translate { offset, child } => child.distance(p - *offset),
            Self::Rotate { rotation, child } => child.distance(rotate(rotation.conjugate(), p)),
            Self::Scale { factor, child } => {
                if usable_factor(*factor) {
                    factor.abs() * child.distance(p / *factor)
                } else {
                    f32::INFINITY
                }
            }
        }
    }

    /// Lipschitz bound L of [`Sdf::distance`]: 1 for every primitive (`|normal|` for a
    /// plane with a longer than unit normal), the maximum over children for every CSG and
    /// smooth operator, and the child's for every transform. See the variants for why.
    pub fn lipschitz(&self) -> f32 {
        match self {
            Self::Sphere { .. }
            | Self::Box { .. }
            | Self::RoundBox { .. }
            | Self::Torus { .. }
            | Self::CappedCylinder { .. }
            | Self::Capsule { .. }
            | Self::DeathStar { .. } => 1.0,
            // NaN.max(1.0) is 1.0, but a NaN normal makes NaN distances, which the tracer
            // reports as GaveUp anyway.
            Self::Plane { normal, .. } => normal.length().max(1.0),
            Self::Union(children)
            | Self::Intersection(children)
            | Self::Difference(children)
            | Self::SmoothUnion { children, .. }
            | Self::SmoothIntersection { children, .. }
            | Self::SmoothDifference { children, .. } => {
                children.iter().fold(1.0, |l, c| l.max(c.lipschitz()))
            }
            Self::Translate { child, .. }
            | Self::Rotate { child, .. }
            | Self::Scale { child, .. } => child.lipschitz(),
        }
    }

    /// True where [`Sdf::distance`] is the exact signed Euclidean distance to the surface
    /// everywhere, inside and out: the primitives (see the torus and Death Star caveats),
    /// one-child CSG nodes of exact children, and transforms of exact shapes. CSG of two or
    /// more shapes is never claimed exact; see [`Sdf::is_exact_outside`].
    pub fn is_exact(&self) -> bool {
        match self {
            Self::Sphere { .. }
            | Self::Box { .. }
            | Self::RoundBox { .. }
            | Self::CappedCylinder { .. }
            | Self::Capsule { .. } => true,
            Self::Plane { normal, .. } => unit_length(*normal),
            Self::Torus {
                major_radius,
                minor_radius,
            } => major_radius.max(0.0) >= minor_radius.max(0.0),
            Self::DeathStar { ra, rb, d } => {
                primitives::death_star_kind(*ra, *rb, *d) != DeathStarKind::Empty
            }
            Self::Union(children)
            | Self::Intersection(children)
            | Self::Difference(children)
            | Self::SmoothUnion { children, .. }
            | Self::SmoothIntersection { children, .. }
            | Self::SmoothDifference { children, .. } => match children.as_slice() {
                [only] => only.is_exact(),
                _ => false,
            },
            Self::Translate { child, .. } | Self::Rotate { child, .. } => child.is_exact(),
            Self::Scale { factor, child } => usable_factor(*factor) && child.is_exact(),
        }
    }

    /// True where [`Sdf::distance`] is exact at every point outside the shape (positive
    /// values), which is where a tracer marches: everything [`Sdf::is_exact`] accepts, the
    /// spindle torus, and unions of shapes exact outside (the distance to a union is the
    /// minimum of the distances).
    pub fn is_exact_outside(&self) -> bool {
        match self {
            Self::Torus { .. } => true,
            Self::Union(children) => children.iter().all(Self::is_exact_outside),
            Self::Intersection(children)
            | Self::Difference(children)
            | Self::SmoothUnion { children, .. }
            | Self::SmoothIntersection { children, .. }
            | Self::SmoothDifference { children, .. } => match children.as_slice() {
                [only] => only.is_exact_outside(),
                _ => false,
            },
            Self::Translate { child, .. } | Self::Rotate { child, .. } => child.is_exact_outside(),
            Self::Scale { factor, child } => usable_factor(*factor) && child.is_exact_outside(),
            _ => self.is_exact(),
        }
    }
}

impl DistanceField for Sdf {
    #[inline]
    fn distance(&self, p: Vec3) -> f32 {
        Sdf::distance(self, p)
    }

    #[inline]
    fn lipschitz(&self) -> f32 {
        Sdf::lipschitz(self)
    }
}

/// Rotates `v` by `q / |q|`, treating a zero or non-finite-norm `q` as the identity.
///
/// Written out rather than `q * v` because glam's version assumes (and, with its assert
/// features, panics on) a non-unit quaternion; for `q = s u` the sandwich product below is
/// `s^2 R(u) v`, so dividing by `|q|^2` removes the scale at the cost of one division.
#[inline]
pub(crate) fn rotate(q: Quat, v: Vec3) -> Vec3 {
    let n2 = q.length_squared();
    if !n2.is_normal() {
        return v;
    }
    let w = q.w;
    let b = Vec3::new(q.x, q.y, q.z);
    let rotated = v * (w * w - b.dot(b)) + b * (2.0 * v.dot(b)) + b.cross(v) * (2.0 * w);
    rotated / n2
}

/// Whether `p / factor` stays meaningful; smaller factors (and NaN) collapse the shape.
#[inline]
pub(crate) fn usable_factor(factor: f32) -> bool {
    factor.abs() >= f32::MIN_POSITIVE && factor.is_finite()
}

#[inline]
fn unit_length(v: Vec3) -> bool {
    (v.length_squared() - 1.0).abs() <= 1e-4
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(sdf: &Sdf, p: Vec3, expected: f32) {
        let got = sdf.distance(p);
        assert!(
            got == expected || (got - expected).abs() <= 1e-5 * (1.0 + expected.abs()),
            "{sdf:?} at {p}: {got} != {expected}"
        );
    }

    #[test]
    fn csg() {
        let a = Sdf::sphere(1.0);
        let b = Sdf::sphere(1.0).translate(Vec3::X);
        let p = Vec3::new(-2.0, 0.0, 0.0);
        check(&Sdf::union(vec![a.clone(), b.clone()]), p, 1.0);
        check(&Sdf::intersection(vec![a.clone(), b.clone()]), p, 2.0);
        check(
            &Sdf::difference(vec![b.clone(), a.clone()]),
            Vec3::ZERO,
            1.0,
        );
        check(&Sdf::union(vec![]), p, f32::INFINITY);
        check(&Sdf::intersection(vec![]), p, f32::NEG_INFINITY);
        check(&Sdf::difference(vec![]), p, f32::INFINITY);
        // Where both children are equal the blend undercuts by exactly k.
        let mid = Vec3::new(0.5, 2.0, 0.0);
        let both = (mid.length() - 1.0, 0.25);
        check(
            &Sdf::smooth_union(0.25, vec![a.clone(), b.clone()]),
            mid,
            both.0 - both.1,
        );
        check(
            &Sdf::smooth_intersection(0.25, vec![a.clone(), b.clone()]),
            mid,
            both.0 + both.1,
        );
        check(&Sdf::smooth_difference(0.25, vec![a, b]), p, 1.0);
    }

    #[test]
    fn transforms() {
        let s = Sdf::capsule(Vec3::ZERO, Vec3::X, 0.5);
        check(&s.clone().translate(Vec3::Y), Vec3::new(0.5, 3.0, 0.0), 1.5);
        let turned = s
            .clone()
            .rotate(Quat::from_rotation_z(std::f32::consts::FRAC_PI_2));
        check(&turned, Vec3::new(0.0, 3.0, 0.0), 1.5);
        // An unnormalised quaternion must not scale space.
        let sloppy = Sdf::Rotate {
            rotation: Quat::from_rotation_z(std::f32::consts::FRAC_PI_2) * 3.0,
            child: Box::new(s.clone()),
        };
        check(&sloppy, Vec3::new(0.0, 3.0, 0.0), 1.5);
        check(&s.clone().scale(2.0), Vec3::new(1.0, 3.0, 0.0), 2.0);
        check(&s.clone().scale(-2.0), Vec3::new(-1.0, 3.0, 0.0), 2.0);
        check(&s.scale(0.0), Vec3::ZERO, f32::INFINITY);
    }

    #[test]
    fn exactness_is_honest() {
        let s = Sdf::sphere(1.0);
        let two = Sdf::union(vec![s.clone(), s.clone().translate(Vec3::X)]);
        assert!(s.is_exact());
        assert!(!two.is_exact() && two.is_exact_outside());
        assert!(!Sdf::torus(0.5, 1.0).is_exact() && Sdf::torus(0.5, 1.0).is_exact_outside());
        assert!(!Sdf::death_star(0.5, 1.0, 0.1).is_exact());
        assert!(Sdf::death_star(1.0, 0.5, 0.8).is_exact());
        assert!(
            !Sdf::Plane {
                normal: Vec3::ONE,
                height: 0.0
            }
            .is_exact()
        );
        assert!(!Sdf::sphere(1.0).scale(0.0).is_exact());
        assert!(Sdf::union(vec![s.clone()]).is_exact());
    }

    #[test]
    fn lipschitz_per_node() {
        let s = Sdf::sphere(1.0);
        assert_eq!(s.lipschitz(), 1.0);
        let steep = Sdf::Plane {
            normal: Vec3::new(0.0, 3.0, 4.0),
            height: 0.0,
        };
        assert_eq!(steep.lipschitz(), 5.0);
        assert_eq!(
            Sdf::smooth_union(0.1, vec![s, steep])
                .scale(3.0)
                .lipschitz(),
            5.0
        );
    }

    #[test]
    fn bounding_spheres() {
        let s = Sdf::sphere(1.0);
        assert_eq!(Sdf::plane(Vec3::Y, 0.0).bounding_sphere(), None);
        let pair = Sdf::union(vec![s.clone(), s.clone().translate(Vec3::X * 4.0)]);
        assert_eq!(pair.bounding_sphere(), Some((Vec3::X * 2.0, 3.0)));
        let blended = Sdf::smooth_union(0.5, vec![s.clone(), s.clone().translate(Vec3::X * 4.0)]);
        assert_eq!(blended.bounding_sphere(), Some((Vec3::X * 2.0, 3.5)));
        let cut = Sdf::intersection(vec![Sdf::plane(Vec3::Y, 0.0), s.clone()]);
        assert_eq!(cut.bounding_sphere(), Some((Vec3::ZERO, 1.0)));
        let moved = s
            .translate(Vec3::X)
            .rotate(Quat::from_rotation_z(std::f32::consts::PI))
            .scale(2.0);
        let (c, r) = moved.bounding_sphere().unwrap();
        assert!((c - Vec3::new(-2.0, 0.0, 0.0)).length() < 1e-6 && r == 2.0);
    }
}
