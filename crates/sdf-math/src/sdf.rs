//! The `Sdf` expression tree: primitives, CSG, smooth blends and rigid transforms.

use glam::{Quat, Vec3};

use crate::DistanceField;
use crate::blend::{smooth_max, smooth_min};
use crate::bound::{Aabb, HalfSpace};
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

    /// A conservative bounding sphere `(centre, radius)`, or `None` when the shape is
    /// unbounded (a plane, an intersection of unbounded shapes).
    ///
    /// Contract, stronger than containment: for every `p`,
    /// `distance(p) >= |p - centre| - radius`. So a ray that misses the sphere misses the
    /// shape, and outside it the sphere is itself a safe step. Smooth unions widen the
    /// sphere by `k` per blended child, the most each fold can undercut the hard minimum.
    ///
    /// The centre and radius are always finite: where extreme parameters overflow, the
    /// answer is `None`, which is always conservative.
    pub fn bounding_sphere(&self) -> Option<(Vec3, f32)> {
        self.bounding_sphere_unchecked()
            .filter(|(centre, radius)| centre.is_finite() && radius.is_finite())
    }

    fn bounding_sphere_unchecked(&self) -> Option<(Vec3, f32)> {
        const NOTHING: Option<(Vec3, f32)> = Some((Vec3::ZERO, 0.0));
        match self {
            Self::Sphere { radius } => Some((Vec3::ZERO, radius.max(0.0))),
            Self::Box { half_extents } | Self::RoundBox { half_extents, .. } => {
                Some((Vec3::ZERO, half_extents.max(Vec3::ZERO).length()))
            }
            Self::Plane { .. } => None,
            Self::Torus {
                major_radius,
                minor_radius,
            } => Some((Vec3::ZERO, major_radius.max(0.0) + minor_radius.max(0.0))),
            Self::CappedCylinder {
                radius,
                half_height,
            } => Some((
                Vec3::ZERO,
                glam::Vec2::new(*radius, *half_height)
                    .max(glam::Vec2::ZERO)
                    .length(),
            )),
            Self::Capsule { a, b, radius } => {
                Some(((*a + *b) * 0.5, (*b - *a).length() * 0.5 + radius.max(0.0)))
            }
            Self::DeathStar { ra, .. } => Some((Vec3::ZERO, ra.max(0.0))),
            Self::Union(children) => merge_all(children),
            Self::SmoothUnion { k, children } => {
                let (centre, radius) = merge_all(children)?;
                let blends = children.len().saturating_sub(1) as f32;
                Some((centre, radius + blends * k.max(0.0)))
            }
            // max(f0, ...) >= f_i for every i, so any bounded child's sphere will do.
            Self::Intersection(children) | Self::SmoothIntersection { children, .. } => children
                .iter()
                .filter_map(Self::bounding_sphere)
                .min_by(|x, y| x.1.total_cmp(&y.1)),
            // Every fold is >= its left argument, so the result is >= f0.
            Self::Difference(children) | Self::SmoothDifference { children, .. } => {
                match children.first() {
                    None => NOTHING,
                    Some(first) => first.bounding_sphere(),
                }
            }
            Self::Translate { offset, child } => {
                let (centre, radius) = child.bounding_sphere()?;
                Some((centre + *offset, radius))
            }
            Self::Rotate { rotation, child } => {
                let (centre, radius) = child.bounding_sphere()?;
                Some((rotate(*rotation, centre), radius))
            }
            Self::Scale { factor, child } => {
                if usable_factor(*factor) {
                    let (centre, radius) = child.bounding_sphere()?;
                    Some((centre * *factor, radius * factor.abs()))
                } else {
                    NOTHING
                }
            }
        }
    }
}

impl Sdf {
    /// A conservative axis-aligned bounding box, or `None` when the shape is unbounded.
    ///
    /// Contract, as for [`Sdf::bounding_sphere`] stronger than containment: for every `p`
    /// outside the box, `distance(p) >=` the Euclidean distance from `p` to the box. So a
    /// ray that stays farther from the box than the hit threshold can never hit the shape
    /// ([`Aabb::hit_interval`]), and outside the box its distance is a safe step.
    ///
    /// Tighter than the sphere for flat and long shapes (a wall's sphere holds the whole
    /// room; its box is the wall). Rotated children get the box around their rotated box,
    /// which may be up to sqrt(3) times larger. Always finite, or `None`.
    pub fn bounding_box(&self) -> Option<Aabb> {
        self.bounding_box_unchecked().filter(Aabb::is_finite)
    }

    fn bounding_box_unchecked(&self) -> Option<Aabb> {
        const NOTHING: Option<Aabb> = Some(Aabb {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
        });
        let centered = |half: Vec3| Some(Aabb::from_center(Vec3::ZERO, half.max(Vec3::ZERO)));
        match self {
            Self::Sphere { radius } => centered(Vec3::splat(*radius)),
            Self::Box { half_extents } | Self::RoundBox { half_extents, .. } => {
                centered(*half_extents)
            }
            Self::Plane { .. } => None,
            Self::Torus {
                major_radius,
                minor_radius,
            } => {
                let (big, small) = (major_radius.max(0.0), minor_radius.max(0.0));
                centered(Vec3::new(big + small, small, big + small))
            }
            Self::CappedCylinder {
                radius,
                half_height,
            } => centered(Vec3::new(*radius, *half_height, *radius)),
            Self::Capsule { a, b, radius } => {
                let r = Vec3::splat(radius.max(0.0));
                Some(Aabb {
                    min: a.min(*b) - r,
                    max: a.max(*b) + r,
                })
            }
            // The field is at least the distance to the kept sphere (the rim circle lies
            // on it), so that sphere's box will do.
            Self::DeathStar { ra, .. } => centered(Vec3::splat(*ra)),
            Self::Union(children) => union_boxes(children),
            Self::SmoothUnion { k, children } => {
                let merged = union_boxes(children)?;
                let blends = children.len().saturating_sub(1) as f32;
                Some(merged.inflate(blends * k.max(0.0)))
            }
            // max(f0, ...) >= f_i for every i: any bounded child's box will do; the
            // smallest by its diagonal.
            Self::Intersection(children) | Self::SmoothIntersection { children, .. } => children
                .iter()
                .filter_map(Self::bounding_box)
                .min_by(|x, y| {
                    let size = |b: &Aabb| b.half_extents().length_squared();
                    size(x).total_cmp(&size(y))
                }),
            Self::Difference(children) | Self::SmoothDifference { children, .. } => {
                match children.first() {
                    None => NOTHING,
                    Some(first) => first.bounding_box(),
                }
            }
            Self::Translate { offset, child } => {
                let b = child.bounding_box()?;
                Some(Aabb {
                    min: b.min + *offset,
                    max: b.max + *offset,
                })
            }
            // The rotated box's own box (centre rotated, half extents through |R|), or the
            // box around the child's bounding sphere, which rotation does not grow (a
            // sphere's field is at least the distance to that ball, so to its box):
            // whichever is smaller.
            Self::Rotate { rotation, child } => {
                let b = child.bounding_box()?;
                let h = b.half_extents();
                let [x, y, z] = [Vec3::X, Vec3::Y, Vec3::Z].map(|e| rotate(*rotation, e).abs());
                let half = x * h.x + y * h.y + z * h.z;
                let turned = Aabb::from_center(rotate(*rotation, b.center()), half);
                let volume = |b: &Aabb| b.half_extents().element_product();
                match child.bounding_sphere() {
                    Some((c, r)) => {
                        let ball = Aabb::from_center(rotate(*rotation, c), Vec3::splat(r));
                        Some(if volume(&ball) < volume(&turned) {
                            ball
                        } else {
                            turned
                        })
                    }
                    None => Some(turned),
                }
            }
            Self::Scale { factor, child } => {
                if usable_factor(*factor) {
                    let b = child.bounding_box()?;
                    Some(Aabb::from_center(
                        b.center() * *factor,
                        b.half_extents() * factor.abs(),
                    ))
                } else {
                    NOTHING
                }
            }
        }
    }

    /// A half-space the field never undercuts, or `None`: for every `p`,
    /// `distance(p) >= dot(p, normal) - height` (everywhere, inside too). Planes and what
    /// is cut from them (intersections, differences) have one; a tracer clips rays
    /// against it exactly ([`HalfSpace::hit_interval`]), which is what makes rays that
    /// leave a floor, or stay above it, cost nothing for the floor.
    pub fn bounding_half_space(&self) -> Option<HalfSpace> {
        self.bounding_half_space_unchecked()
            .filter(|h| h.normal.is_finite() && h.height.is_finite())
    }

    fn bounding_half_space_unchecked(&self) -> Option<HalfSpace> {
        match self {
            // Equality: the field is that linear function.
            Self::Plane { normal, height } => Some(HalfSpace {
                normal: *normal,
                height: *height,
            }),
            Self::Intersection(children) | Self::SmoothIntersection { children, .. } => {
                children.iter().find_map(Self::bounding_half_space)
            }
            Self::Difference(children) | Self::SmoothDifference { children, .. } => {
                children.first()?.bounding_half_space()
            }
            Self::Translate { offset, child } => {
                let h = child.bounding_half_space()?;
                Some(HalfSpace {
                    normal: h.normal,
                    height: h.height + offset.dot(h.normal),
                })
            }
            Self::Rotate { rotation, child } => {
                let h = child.bounding_half_space()?;
                Some(HalfSpace {
                    normal: rotate(*rotation, h.normal),
                    height: h.height,
                })
            }
            // |c| f(p / c) >= |c| (dot(p / c, n) - h) = dot(p, sign(c) n) - |c| h.
            Self::Scale { factor, child } if usable_factor(*factor) => {
                let h = child.bounding_half_space()?;
                Some(HalfSpace {
                    normal: h.normal * factor.signum(),
                    height: h.height * factor.abs(),
                })
            }
            _ => None,
        }
    }
}

/// Union of the children's boxes: an empty box for no children (the empty shape), `None`
/// if any child is unbounded.
fn union_boxes(children: &[Sdf]) -> Option<Aabb> {
    let mut boxes = children.iter().map(Sdf::bounding_box);
    let Some(first) = boxes.next() else {
        return Some(Aabb {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
        });
    };
    boxes.try_fold(first?, |acc, b| Some(acc.union(&b?)))
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
fn rotate(q: Quat, v: Vec3) -> Vec3 {
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
fn usable_factor(factor: f32) -> bool {
    factor.abs() >= f32::MIN_POSITIVE && factor.is_finite()
}

#[inline]
fn unit_length(v: Vec3) -> bool {
    (v.length_squared() - 1.0).abs() <= 1e-4
}

/// The smallest sphere holding both spheres.
fn merge(x: (Vec3, f32), y: (Vec3, f32)) -> (Vec3, f32) {
    let ((cx, rx), (cy, ry)) = (x, y);
    let gap = (cy - cx).length();
    if gap + ry <= rx {
        return x;
    }
    if gap + rx <= ry {
        return y;
    }
    let radius = (gap + rx + ry) * 0.5;
    // gap > |rx - ry| >= 0 here, so the division is safe.
    let centre = cx + (cy - cx) * ((radius - rx) / gap);
    (centre, radius)
}

/// Merged sphere of all children: `Some((0, 0))` for no children (the empty shape), `None`
/// if any child is unbounded.
fn merge_all(children: &[Sdf]) -> Option<(Vec3, f32)> {
    let mut spheres = children.iter().map(Sdf::bounding_sphere);
    let Some(first) = spheres.next() else {
        return Some((Vec3::ZERO, 0.0));
    };
    spheres.try_fold(first?, |acc, s| Some(merge(acc, s?)))
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
