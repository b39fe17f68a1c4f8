//! The `Sdf` expression tree: primitives, CSG, smooth blends and rigid transforms.

use glam::{Quat, Vec3};

use crate::DistanceField;
use crate::blend::{smooth_max_lanes, smooth_min_lanes};
use crate::lanes::{Lane, LaneDistance, LaneVec3, Task};
use crate::primitives::Primitive;

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
    /// A primitive shape: see [`Primitive`] for each one's bound and exactness.
    Primitive(Primitive),
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

    /// Signed distance (or bound, see the variant) at `p`; negative inside: the
    /// [`LaneDistance`] formula at `f32`.
    pub fn distance(&self, p: Vec3) -> f32 {
        self.distance_lanes(LaneVec3::from(p))
    }

    /// Lipschitz bound L of [`Sdf::distance`]: the primitive's ([`Primitive::lipschitz`]),
    /// the maximum over children for every CSG and smooth operator, and the child's for
    /// every transform. See the variants for why.
    pub fn lipschitz(&self) -> f32 {
        match self {
            Self::Primitive(shape) => shape.lipschitz(),
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
    /// everywhere, inside and out: the exact primitives ([`Primitive::is_exact`]), one-child
    /// CSG nodes of exact children, and transforms of exact shapes. CSG of two or
    /// more shapes is never claimed exact; see [`Sdf::is_exact_outside`].
    pub fn is_exact(&self) -> bool {
        match self {
            Self::Primitive(shape) => shape.is_exact(),
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
    /// primitives exact outside ([`Primitive::is_exact_outside`]: the spindle torus), and unions of shapes exact outside (the distance to a union is the
    /// minimum of the distances).
    pub fn is_exact_outside(&self) -> bool {
        match self {
            Self::Primitive(shape) => shape.is_exact_outside(),
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
        }
    }
}

/// The one definition of each operator and transform. A primitive is evaluated in place;
/// below an operator the recursion is a call the compiler cannot inline, which runs with the
/// compilation target's baseline instructions rather than the dispatched ones (entering the
/// dispatched instruction set again at each node was measured slower: the call costs more
/// than a small child's evaluation). The bits are the same either way.
impl LaneDistance for Sdf {
    #[inline(always)]
    fn distance_lanes<L: Lane>(&self, p: LaneVec3<L>) -> L {
        match self {
            Self::Primitive(shape) => shape.distance_lanes(p),
            _ => L::apart(NodeDistance { sdf: self, p }),
        }
    }
}

impl Sdf {
    /// An interior node's distance over its children. Loops, not closures, so that all of
    /// it is inlined into the function [`Lane::apart`] compiles for the level.
    #[inline(always)]
    fn node_distance<L: Lane>(&self, p: LaneVec3<L>) -> L {
        let inf = L::splat(f32::INFINITY);
        match self {
            Self::Primitive(shape) => shape.distance_lanes(p),
            Self::Union(children) => {
                let mut d = inf;
                for c in children {
                    d = d.min(c.distance_lanes(p));
                }
                d
            }
            Self::Intersection(children) => {
                let mut d = -inf;
                for c in children {
                    d = d.max(c.distance_lanes(p));
                }
                d
            }
            Self::Difference(children) => match children.split_first() {
                None => inf,
                Some((first, rest)) => {
                    let mut d = first.distance_lanes(p);
                    for c in rest {
                        d = d.max(-c.distance_lanes(p));
                    }
                    d
                }
            },
            Self::SmoothUnion { k, children } => match children.split_first() {
                None => inf,
                Some((first, rest)) => {
                    let mut d = first.distance_lanes(p);
                    for c in rest {
                        d = smooth_min_lanes(d, c.distance_lanes(p), *k);
                    }
                    d
                }
            },
            Self::SmoothIntersection { k, children } => match children.split_first() {
                None => -inf,
                Some((first, rest)) => {
                    let mut d = first.distance_lanes(p);
                    for c in rest {
                        d = smooth_max_lanes(d, c.distance_lanes(p), *k);
                    }
                    d
                }
            },
            Self::SmoothDifference { k, children } => match children.split_first() {
                None => inf,
                Some((first, rest)) => {
                    let mut d = first.distance_lanes(p);
                    for c in rest {
                        d = smooth_max_lanes(d, -c.distance_lanes(p), *k);
                    }
                    d
                }
            },
            Self::Translate { offset, child } => child.distance_lanes(p - LaneVec3::splat(*offset)),
            Self::Rotate { rotation, child } => {
                child.distance_lanes(rotate_lanes(rotation.conjugate(), p))
            }
            Self::Scale { factor, child } => {
                if usable_factor(*factor) {
                    L::splat(factor.abs()) * child.distance_lanes(p / L::splat(*factor))
                } else {
                    inf
                }
            }
        }
    }
}

/// [`Sdf::node_distance`] as a [`Task`], run apart ([`Lane::apart`]): cold and out of
/// line, so that a kernel marching primitives keeps the point in registers. Otherwise the
/// compiler may store the point's vectors for this call before the branch, on every
/// evaluation, and the primitive's loads wait on those stores (docs/PERFORMANCE.md,
/// "Stores loaded whole").
struct NodeDistance<'a, L> {
    sdf: &'a Sdf,
    p: LaneVec3<L>,
}

impl<L: Lane> Task for NodeDistance<'_, L> {
    type Output = L;
    #[inline(always)]
    fn run(self) -> L {
        self.sdf.node_distance(self.p)
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
    rotate_lanes(q, LaneVec3::from(v)).into()
}

/// [`rotate`] over any [`Lane`] type, its one definition.
#[inline(always)]
fn rotate_lanes<L: Lane>(q: Quat, v: LaneVec3<L>) -> LaneVec3<L> {
    let n2 = q.length_squared();
    if !n2.is_normal() {
        return v;
    }
    let w = q.w;
    let b = Vec3::new(q.x, q.y, q.z);
    let lanes_b = LaneVec3::splat(b);
    let rotated = v * L::splat(w * w - b.dot(b))
        + lanes_b * (L::splat(2.0) * v.dot(lanes_b))
        + lanes_b.cross(v) * L::splat(2.0 * w);
    rotated / L::splat(n2)
}

/// Whether `p / factor` stays meaningful; smaller factors (and NaN) collapse the shape.
#[inline]
pub(crate) fn usable_factor(factor: f32) -> bool {
    factor.abs() >= f32::MIN_POSITIVE && factor.is_finite()
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
            !Sdf::from(Primitive::Plane {
                normal: Vec3::ONE,
                height: 0.0
            })
            .is_exact()
        );
        assert!(!Sdf::sphere(1.0).scale(0.0).is_exact());
        assert!(Sdf::union(vec![s.clone()]).is_exact());
    }

    #[test]
    fn lipschitz_per_node() {
        let s = Sdf::sphere(1.0);
        assert_eq!(s.lipschitz(), 1.0);
        let steep = Sdf::from(Primitive::Plane {
            normal: Vec3::new(0.0, 3.0, 4.0),
            height: 0.0,
        });
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
