//! The primitive shapes, each in one place: its parameters ([`Primitive`]), its signed
//! distance, Lipschitz bound and exactness, its bounds, and the [`Sdf`] constructor that
//! makes it. A new primitive is a variant here, its arms of the `impl Primitive` matches
//! and a constructor; the tree in `sdf.rs` and its bounds in `sdf_bounds.rs` only
//! delegate to [`Primitive`] and never name one.
//!
//! The distances are exact, after iq's "distfunctions" article
//! (iquilezles.org/articles/distfunctions). Each formula clamps degenerate parameters
//! (negative sizes) to the nearest meaningful shape instead of trusting them, so that the
//! "exact" claims of [`Primitive::is_exact`] hold for every finite input.

use glam::{Vec2, Vec3};

use crate::Sdf;
use crate::bound::{Aabb, HalfSpace};
use crate::lanes::{Lane, LaneDistance, LaneVec2, LaneVec3};

/// A primitive shape in its own frame, the leaves of the [`Sdf`] tree
/// ([`Sdf::Primitive`]); move, turn or scale it with the tree's transforms.
///
/// The per-variant notes give the Lipschitz bound and whether the value is the exact
/// Euclidean distance ([`Primitive::is_exact`]) or only a bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Primitive {
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
}

impl Primitive {
    /// Signed distance (or bound, see the variant) at `p`; negative inside: the
    /// [`LaneDistance`] formula at `f32`.
    #[inline]
    pub fn distance(&self, p: Vec3) -> f32 {
        self.distance_lanes(LaneVec3::from(p))
    }

    /// Lipschitz bound L of [`Primitive::distance`]: 1, or `|normal|` for a plane with a
    /// longer than unit normal.
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
        }
    }

    /// True where [`Primitive::distance`] is the exact signed Euclidean distance to the
    /// surface everywhere, inside and out: all but a plane with a non-unit normal, a
    /// spindle torus and an empty Death Star.
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
            Self::DeathStar { ra, rb, d } => death_star_kind(*ra, *rb, *d) != DeathStarKind::Empty,
        }
    }

    /// True where [`Primitive::distance`] is exact at every point outside the shape:
    /// everything [`Primitive::is_exact`] accepts, and the spindle torus.
    pub fn is_exact_outside(&self) -> bool {
        match self {
            Self::Torus { .. } => true,
            _ => self.is_exact(),
        }
    }

    /// The bounding sphere `(centre, radius)` with the field contract of
    /// [`Sdf::bounding_sphere`], `None` for a plane; not yet checked for finiteness.
    pub(crate) fn bounding_sphere(&self) -> Option<(Vec3, f32)> {
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
                Vec2::new(*radius, *half_height).max(Vec2::ZERO).length(),
            )),
            Self::Capsule { a, b, radius } => {
                Some(((*a + *b) * 0.5, (*b - *a).length() * 0.5 + radius.max(0.0)))
            }
            Self::DeathStar { ra, .. } => Some((Vec3::ZERO, ra.max(0.0))),
        }
    }

    /// The bounding box with the field contract of [`Sdf::bounding_box`], `None` for a
    /// plane; not yet checked for finiteness.
    pub(crate) fn bounding_box(&self) -> Option<Aabb> {
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
        }
    }

    /// The half-space with the field contract of [`Sdf::bounding_half_space`]: a plane's
    /// own (equality: the field is that linear function), `None` for every bounded shape;
    /// not yet checked for finiteness.
    pub(crate) fn bounding_half_space(&self) -> Option<HalfSpace> {
        match self {
            Self::Plane { normal, height } => Some(HalfSpace {
                normal: *normal,
                height: *height,
            }),
            Self::Sphere { .. }
            | Self::Box { .. }
            | Self::RoundBox { .. }
            | Self::Torus { .. }
            | Self::CappedCylinder { .. }
            | Self::Capsule { .. }
            | Self::DeathStar { .. } => None,
        }
    }
}

/// The one definition of each primitive's distance. Parameters are prepared in `f32`
/// (once per call, the same in every lane); only what depends on the point is lanes.
impl LaneDistance for Primitive {
    #[inline(always)]
    fn distance_lanes<L: Lane>(&self, p: LaneVec3<L>) -> L {
        match *self {
            Self::Sphere { radius } => sphere(p, radius),
            Self::Box { half_extents } => cuboid(p, half_extents),
            Self::RoundBox {
                half_extents,
                radius,
            } => round_box(p, half_extents, radius),
            Self::Plane { normal, height } => plane(p, normal, height),
            Self::Torus {
                major_radius,
                minor_radius,
            } => torus(p, major_radius, minor_radius),
            Self::CappedCylinder {
                radius,
                half_height,
            } => capped_cylinder(p, radius, half_height),
            Self::Capsule { a, b, radius } => capsule(p, a, b, radius),
            Self::DeathStar { ra, rb, d } => death_star(p, ra, rb, d),
        }
    }
}

impl From<Primitive> for Sdf {
    fn from(shape: Primitive) -> Sdf {
        Sdf::Primitive(shape)
    }
}

/// The constructors of the primitive leaves.
impl Sdf {
    /// [`Primitive::Sphere`] of the given radius.
    pub fn sphere(radius: f32) -> Self {
        Primitive::Sphere { radius }.into()
    }

    /// [`Primitive::Box`] with the given half extents (`box` is a Rust keyword).
    pub fn cuboid(half_extents: Vec3) -> Self {
        Primitive::Box { half_extents }.into()
    }

    /// [`Primitive::RoundBox`]: outer half extents, edge radius.
    pub fn round_box(half_extents: Vec3, radius: f32) -> Self {
        Primitive::RoundBox {
            half_extents,
            radius,
        }
        .into()
    }

    /// [`Primitive::Plane`] with `normal` normalised here (a zero or non-finite normal
    /// becomes +Y).
    pub fn plane(normal: Vec3, height: f32) -> Self {
        Primitive::Plane {
            normal: normal.normalize_or(Vec3::Y),
            height,
        }
        .into()
    }

    /// [`Primitive::Torus`] in the XZ plane.
    pub fn torus(major_radius: f32, minor_radius: f32) -> Self {
        Primitive::Torus {
            major_radius,
            minor_radius,
        }
        .into()
    }

    /// [`Primitive::CappedCylinder`] along Y.
    pub fn capped_cylinder(radius: f32, half_height: f32) -> Self {
        Primitive::CappedCylinder {
            radius,
            half_height,
        }
        .into()
    }

    /// [`Primitive::Capsule`] around the segment `ab`.
    pub fn capsule(a: Vec3, b: Vec3, radius: f32) -> Self {
        Primitive::Capsule { a, b, radius }.into()
    }

    /// [`Primitive::DeathStar`].
    pub fn death_star(ra: f32, rb: f32, d: f32) -> Self {
        Primitive::DeathStar { ra, rb, d }.into()
    }
}

#[inline]
fn unit_length(v: Vec3) -> bool {
    (v.length_squared() - 1.0).abs() <= 1e-4
}

#[inline(always)]
fn sphere<L: Lane>(p: LaneVec3<L>, radius: f32) -> L {
    p.length() - L::splat(radius.max(0.0))
}

/// iq sdBox: the outside part is the distance to the nearest point of the box, the inside
/// part the (negative) distance to the nearest face.
#[inline(always)]
fn cuboid<L: Lane>(p: LaneVec3<L>, half_extents: Vec3) -> L {
    let q = p.abs() - LaneVec3::splat(half_extents.max(Vec3::ZERO));
    q.max(LaneVec3::splat(Vec3::ZERO)).length() + q.max_element().min(L::splat(0.0))
}

/// iq sdRoundBox: a box shrunk by `radius` and then inflated by it, so the outer size stays
/// `half_extents`. The radius is clamped to `[0, smallest half extent]`, past which the
/// shrunk box would turn inside out.
#[inline(always)]
fn round_box<L: Lane>(p: LaneVec3<L>, half_extents: Vec3, radius: f32) -> L {
    let b = half_extents.max(Vec3::ZERO);
    let r = round_box_radius(b, radius);
    cuboid(p, b - Vec3::splat(r)) - L::splat(r)
}

#[inline]
fn round_box_radius(half_extents: Vec3, radius: f32) -> f32 {
    radius
        .max(0.0)
        .min(half_extents.max(Vec3::ZERO).min_element())
}

#[inline(always)]
fn plane<L: Lane>(p: LaneVec3<L>, normal: Vec3, height: f32) -> L {
    p.dot(LaneVec3::splat(normal)) - L::splat(height)
}

/// iq sdTorus: the distance to the core circle of radius `major` in the XZ plane, minus the
/// tube radius.
#[inline(always)]
fn torus<L: Lane>(p: LaneVec3<L>, major: f32, minor: f32) -> L {
    let q = LaneVec2::new(
        LaneVec2::new(p.x, p.z).length() - L::splat(major.max(0.0)),
        p.y,
    );
    q.length() - L::splat(minor.max(0.0))
}

/// iq sdCappedCylinder: the 2D box distance in the (radial, height) half-plane.
#[inline(always)]
fn capped_cylinder<L: Lane>(p: LaneVec3<L>, radius: f32, half_height: f32) -> L {
    let size = Vec2::new(radius, half_height).max(Vec2::ZERO);
    let d = LaneVec2::new(LaneVec2::new(p.x, p.z).length(), p.y).abs() - LaneVec2::splat(size);
    d.max_element().min(L::splat(0.0)) + d.max(LaneVec2::splat(Vec2::ZERO)).length()
}

/// iq sdCapsule: distance to the segment `ab`, minus the radius.
#[inline(always)]
fn capsule<L: Lane>(p: LaneVec3<L>, a: Vec3, b: Vec3, radius: f32) -> L {
    let pa = p - LaneVec3::splat(a);
    let ba = b - a;
    let h = pa.dot(LaneVec3::splat(ba)) / L::splat(ba.length_squared());
    // A degenerate segment (a == b) gives 0/0: treat it as the point a.
    let h = L::select(h.is_nan(), L::splat(0.0), h.clamp(0.0, 1.0));
    (pa - LaneVec3::splat(ba) * h).length() - L::splat(radius.max(0.0))
}

/// The three situations a Death Star can be in; `Rim` is the only one with a crater edge.
#[derive(Clone, Copy, Debug, PartialEq)]
enum DeathStarKind {
    /// The small sphere misses the big one, or is a cavity strictly inside it.
    NoRim,
    /// The small sphere swallows the big one: nothing is left.
    Empty,
    /// The spheres' surfaces cross along a circle (the rim).
    Rim,
}

#[inline]
fn death_star_kind(ra: f32, rb: f32, d: f32) -> DeathStarKind {
    let (ra, rb, d) = (ra.max(0.0), rb.max(0.0), d.abs());
    if d + ra <= rb {
        DeathStarKind::Empty
    } else if d <= ra - rb || d >= ra + rb {
        DeathStarKind::NoRim
    } else {
        DeathStarKind::Rim
    }
}

/// iq sdDeathStar: a sphere of radius `ra` at the origin minus a sphere of radius `rb` at
/// `(d, 0, 0)`, exact.
///
/// The shape is symmetric about the x axis, so the work happens in the (x, radial) half
/// plane. Where the spheres cross, points in the cone spanned by the rim circle at (a, b)
/// are nearest to the rim; elsewhere the CSG difference `max(big, -small)` is exact. When
/// there is no rim (disjoint spheres, or a cavity fully inside) that max is exact
/// everywhere; iq's formula divides by `d` and assumes a rim, so those cases are handled
/// first. When nothing is left the max is still positive everywhere, a valid bound.
#[inline(always)]
fn death_star<L: Lane>(p: LaneVec3<L>, ra: f32, rb: f32, d: f32) -> L {
    let (ra, rb) = (ra.max(0.0), rb.max(0.0));
    // Mirror so the small sphere sits on +x.
    let (x, d) = if d < 0.0 { (-p.x, -d) } else { (p.x, d) };
    let q = LaneVec2::new(x, LaneVec2::new(p.y, p.z).length());
    let big = q.length() - L::splat(ra);
    let to_bite = (q - LaneVec2::splat(Vec2::new(d, 0.0))).length();
    // `rb - |q - (d, 0)|` is off by the rounding of `rb`, which near the bite's surface is
    // all there is to it once the bite is much larger than the star: a bite 100 times its
    // size would round the field to 8e-6 there and make the normals noise, one 1e4 times
    // would shadow the whole cut. There it is `(rb^2 - |q - (d, 0)|^2) / (rb + |q - (d, 0)|)`,
    // the numerator factored as `(d + rb - x)(x - (d - rb)) - y^2` (`d - rb` is exact when
    // they are within a factor of 2), rounded to the star's size. A bite up to 4 times the
    // star keeps the plain difference: its rounding is then the star's own, and a division
    // less.
    let large_bite = rb > 4.0 * ra;
    let plain = L::splat(rb) - to_bite;
    let small = if large_bite {
        let x = q.x;
        let numerator = (L::splat(d + rb) - x) * (x - L::splat(d - rb)) - q.y * q.y;
        let stable = numerator / (L::splat(rb) + to_bite);
        // Far points (an infinite coordinate) take the plain difference, exact there.
        L::select(stable.finite(), stable, plain)
    } else {
        plain
    };
    if death_star_kind(ra, rb, d) != DeathStarKind::Rim {
        return big.max(small);
    }
    // Rim circle: x = a, radius b, from intersecting the two sphere equations. Factored
    // as differences of nearly equal numbers first, so that ra close to rb, or a close to
    // ra, does not cancel away the rim's position; for a large bite, around `d - rb`,
    // which is then what is small.
    let a = if large_bite {
        (ra * ra + (d - rb) * (d + rb)) / (2.0 * d)
    } else {
        ((ra - rb) * (ra + rb) + d * d) / (2.0 * d)
    };
    let b = ((ra - a) * (ra + a)).max(0.0).sqrt();
    let (a_, b_) = (L::splat(a), L::splat(b));
    let near_rim = (q.x * b_ - q.y * a_).gt(L::splat(d) * (b_ - q.y).max(L::splat(0.0)));
    L::select(
        near_rim,
        (q - LaneVec2::splat(Vec2::new(a, b))).length(),
        big.max(small),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(p: Vec3) -> LaneVec3<f32> {
        p.into()
    }

    fn check(got: f32, expected: f32) {
        assert!((got - expected).abs() <= 1e-6, "{got} != {expected}");
    }

    #[test]
    fn sphere_and_box() {
        check(sphere(at(Vec3::new(0.0, 3.0, 4.0)), 2.0), 3.0);
        check(sphere(at(Vec3::ZERO), 2.0), -2.0);
        check(sphere(at(Vec3::X), -1.0), 1.0); // a negative radius is a point
        let b = Vec3::new(1.0, 2.0, 3.0);
        check(cuboid(at(Vec3::new(4.0, 6.0, 0.0)), b), 5.0); // nearest is an edge
        check(cuboid(at(Vec3::ZERO), b), -1.0); // nearest face is x = 1
        check(cuboid(at(Vec3::new(0.0, 0.0, 5.0)), b), 2.0);
    }

    #[test]
    fn round_box_keeps_outer_size() {
        let b = Vec3::new(1.0, 2.0, 3.0);
        check(round_box(at(Vec3::new(3.0, 0.0, 0.0)), b, 0.5), 2.0);
        // The corner is rounded: the nearest point is on the radius-0.5 sphere at (0.5, 1.5, 2.5).
        check(round_box(at(b), b, 0.5), 3f32.sqrt() * 0.5 - 0.5);
        // An oversized radius clamps to 1: a capsule-like slab still 1 thick in x.
        check(round_box(at(Vec3::new(3.0, 0.0, 0.0)), b, 10.0), 2.0);
    }

    #[test]
    fn revolved_shapes() {
        check(torus(at(Vec3::new(3.0, 0.0, 0.0)), 2.0, 0.5), 0.5);
        check(torus(at(Vec3::new(0.0, 0.0, 2.0)), 2.0, 0.5), -0.5);
        check(torus(at(Vec3::ZERO), 2.0, 0.5), 1.5);
        check(capped_cylinder(at(Vec3::new(0.0, 5.0, 0.0)), 1.0, 2.0), 3.0);
        check(capped_cylinder(at(Vec3::new(4.0, 6.0, 0.0)), 1.0, 2.0), 5.0);
        check(capped_cylinder(at(Vec3::ZERO), 1.0, 2.0), -1.0);
        let (a, b) = (Vec3::ZERO, Vec3::Y * 2.0);
        check(capsule(at(Vec3::new(0.0, 5.0, 0.0)), a, b, 1.0), 2.0);
        check(capsule(at(Vec3::new(3.0, 1.0, 0.0)), a, b, 1.0), 2.0);
        check(capsule(at(Vec3::new(3.0, 0.0, 4.0)), a, a, 1.0), 4.0);
    }

    #[test]
    fn death_star_cases() {
        use DeathStarKind::*;
        assert_eq!(death_star_kind(1.0, 0.5, 1.0), Rim);
        assert_eq!(death_star_kind(1.0, 0.5, -1.0), Rim);
        assert_eq!(death_star_kind(1.0, 0.5, 2.0), NoRim);
        assert_eq!(death_star_kind(1.0, 0.5, 0.25), NoRim);
        assert_eq!(death_star_kind(1.0, 0.5, 0.0), NoRim);
        assert_eq!(death_star_kind(0.5, 1.0, 0.25), Empty);
        // Unit sphere minus a unit sphere at x = 1: the rim is at x = 0.5, radius sqrt(3)/2.
        let rim = Vec3::new(0.5, 0.75f32.sqrt(), 0.0);
        check(death_star(at(rim), 1.0, 1.0, 1.0), 0.0);
        check(
            death_star(at(Vec3::new(-2.0, 0.0, 0.0)), 1.0, 1.0, 1.0),
            1.0,
        );
        check(
            death_star(at(Vec3::new(0.25, 0.0, 0.0)), 1.0, 1.0, 1.0),
            0.25,
        ); // in the crater
        check(death_star(at(rim * 2.0), 1.0, 1.0, 1.0), 1.0); // beyond the rim, in its cone
        // Mirrored: the crater faces -x.
        check(
            death_star(at(Vec3::new(-0.25, 0.0, 0.0)), 1.0, 1.0, -1.0),
            0.25,
        );
        // Empty: positive everywhere, including where the big sphere used to be.
        assert!(death_star(at(Vec3::ZERO), 0.5, 1.0, 0.25) > 0.0);
        // Cavity: the hollow inside is outside the shape.
        check(death_star(at(Vec3::ZERO), 2.0, 0.5, 0.0), 0.5);
        check(
            death_star(at(Vec3::new(1.0, 0.0, 0.0)), 2.0, 0.5, 0.0),
            -0.5,
        );
    }

    /// A bite far larger than the star (a nearly flat cut, 0.6 from the centre): near the
    /// cut the field keeps the star's precision, not the bite's. Computed as the plain
    /// difference it was off by the rounding of `rb` (8e-6 at 100, 1e-3 at 1e4: noisy
    /// normals, then rays leaving the cut shadowed by it).
    #[test]
    fn a_large_bite_keeps_the_stars_precision() {
        for rb in [1e2f32, 1e4, 1e6] {
            let d = rb + 0.6;
            for i in 0..=20 {
                for j in 0..=20 {
                    let p = Vec3::new(0.55 + 0.005 * i as f32, -0.5 + 0.05 * j as f32, 0.3);
                    let (x, r) = (f64::from(p.x), f64::from(p.y).hypot(f64::from(p.z)));
                    // Inside the big sphere and away from the rim, the field is the bite's.
                    let small = f64::from(rb) - (x - f64::from(d)).hypot(r);
                    let exact = small.max(x.hypot(r) - 1.0);
                    let got = death_star(at(p), 1.0, rb, d);
                    assert!(
                        (f64::from(got) - exact).abs() <= 1e-6,
                        "rb {rb}, at {p}: {got}, exactly {exact}"
                    );
                }
            }
        }
    }
}
