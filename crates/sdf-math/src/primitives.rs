//! Exact signed distances to the primitive shapes, after iq's "distfunctions" article
//! (iquilezles.org/articles/distfunctions). Each function clamps degenerate parameters
//! (negative sizes) to the nearest meaningful shape instead of trusting them, so that the
//! "exact" claims in `Sdf::is_exact` hold for every finite input.

use glam::{Vec2, Vec3};

#[inline]
pub(crate) fn sphere(p: Vec3, radius: f32) -> f32 {
    p.length() - radius.max(0.0)
}

/// iq sdBox: the outside part is the distance to the nearest point of the box, the inside
/// part the (negative) distance to the nearest face.
#[inline]
pub(crate) fn cuboid(p: Vec3, half_extents: Vec3) -> f32 {
    let q = p.abs() - half_extents.max(Vec3::ZERO);
    q.max(Vec3::ZERO).length() + q.max_element().min(0.0)
}

/// iq sdRoundBox: a box shrunk by `radius` and then inflated by it, so the outer size stays
/// `half_extents`. The radius is clamped to `[0, smallest half extent]`, past which the
/// shrunk box would turn inside out.
#[inline]
pub(crate) fn round_box(p: Vec3, half_extents: Vec3, radius: f32) -> f32 {
    let b = half_extents.max(Vec3::ZERO);
    let r = round_box_radius(b, radius);
    cuboid(p, b - Vec3::splat(r)) - r
}

#[inline]
pub(crate) fn round_box_radius(half_extents: Vec3, radius: f32) -> f32 {
    radius
        .max(0.0)
        .min(half_extents.max(Vec3::ZERO).min_element())
}

#[inline]
pub(crate) fn plane(p: Vec3, normal: Vec3, height: f32) -> f32 {
    p.dot(normal) - height
}

/// iq sdTorus: the distance to the core circle of radius `major` in the XZ plane, minus the
/// tube radius.
#[inline]
pub(crate) fn torus(p: Vec3, major: f32, minor: f32) -> f32 {
    let q = Vec2::new(Vec2::new(p.x, p.z).length() - major.max(0.0), p.y);
    q.length() - minor.max(0.0)
}

/// iq sdCappedCylinder: the 2D box distance in the (radial, height) half-plane.
#[inline]
pub(crate) fn capped_cylinder(p: Vec3, radius: f32, half_height: f32) -> f32 {
    let size = Vec2::new(radius, half_height).max(Vec2::ZERO);
    let d = Vec2::new(Vec2::new(p.x, p.z).length(), p.y).abs() - size;
    d.max_element().min(0.0) + d.max(Vec2::ZERO).length()
}

/// iq sdCapsule: distance to the segment `ab`, minus the radius.
#[inline]
pub(crate) fn capsule(p: Vec3, a: Vec3, b: Vec3, radius: f32) -> f32 {
    let pa = p - a;
    let ba = b - a;
    let h = pa.dot(ba) / ba.length_squared();
    // A degenerate segment (a == b) gives 0/0: treat it as the point a.
    let h = if h.is_nan() { 0.0 } else { h.clamp(0.0, 1.0) };
    (pa - ba * h).length() - radius.max(0.0)
}

/// The three situations a Death Star can be in; `Rim` is the only one with a crater edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum DeathStarKind {
    /// The small sphere misses the big one, or is a cavity strictly inside it.
    NoRim,
    /// The small sphere swallows the big one: nothing is left.
    Empty,
    /// The spheres' surfaces cross along a circle (the rim).
    Rim,
}

#[inline]
pub(crate) fn death_star_kind(ra: f32, rb: f32, d: f32) -> DeathStarKind {
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
#[inline]
pub(crate) fn death_star(p: Vec3, ra: f32, rb: f32, d: f32) -> f32 {
    let (ra, rb) = (ra.max(0.0), rb.max(0.0));
    // Mirror so the small sphere sits on +x.
    let (x, d) = if d < 0.0 { (-p.x, -d) } else { (p.x, d) };
    let q = Vec2::new(x, Vec2::new(p.y, p.z).length());
    let big = q.length() - ra;
    let small = rb - (q - Vec2::new(d, 0.0)).length();
    if death_star_kind(ra, rb, d) != DeathStarKind::Rim {
        return big.max(small);
    }
    // Rim circle: x = a, radius b, from intersecting the two sphere equations. Factored
    // as differences of nearly equal numbers first, so that ra close to rb, or a close to
    // ra, does not cancel away the rim's position.
    let a = ((ra - rb) * (ra + rb) + d * d) / (2.0 * d);
    let b = ((ra - a) * (ra + a)).max(0.0).sqrt();
    if q.x * b - q.y * a > d * (b - q.y).max(0.0) {
        (q - Vec2::new(a, b)).length()
    } else {
        big.max(small)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(got: f32, expected: f32) {
        assert!((got - expected).abs() <= 1e-6, "{got} != {expected}");
    }

    #[test]
    fn sphere_and_box() {
        check(sphere(Vec3::new(0.0, 3.0, 4.0), 2.0), 3.0);
        check(sphere(Vec3::ZERO, 2.0), -2.0);
        check(sphere(Vec3::X, -1.0), 1.0); // a negative radius is a point
        let b = Vec3::new(1.0, 2.0, 3.0);
        check(cuboid(Vec3::new(4.0, 6.0, 0.0), b), 5.0); // nearest is an edge
        check(cuboid(Vec3::ZERO, b), -1.0); // nearest face is x = 1
        check(cuboid(Vec3::new(0.0, 0.0, 5.0), b), 2.0);
    }

    #[test]
    fn round_box_keeps_outer_size() {
        let b = Vec3::new(1.0, 2.0, 3.0);
        check(round_box(Vec3::new(3.0, 0.0, 0.0), b, 0.5), 2.0);
        // The corner is rounded: the nearest point is on the radius-0.5 sphere at (0.5, 1.5, 2.5).
        check(round_box(b, b, 0.5), 3f32.sqrt() * 0.5 - 0.5);
        // An oversized radius clamps to 1: a capsule-like slab still 1 thick in x.
        check(round_box(Vec3::new(3.0, 0.0, 0.0), b, 10.0), 2.0);
    }

    #[test]
    fn revolved_shapes() {
        check(torus(Vec3::new(3.0, 0.0, 0.0), 2.0, 0.5), 0.5);
        check(torus(Vec3::new(0.0, 0.0, 2.0), 2.0, 0.5), -0.5);
        check(torus(Vec3::ZERO, 2.0, 0.5), 1.5);
        check(capped_cylinder(Vec3::new(0.0, 5.0, 0.0), 1.0, 2.0), 3.0);
        check(capped_cylinder(Vec3::new(4.0, 6.0, 0.0), 1.0, 2.0), 5.0);
        check(capped_cylinder(Vec3::ZERO, 1.0, 2.0), -1.0);
        let (a, b) = (Vec3::ZERO, Vec3::Y * 2.0);
        check(capsule(Vec3::new(0.0, 5.0, 0.0), a, b, 1.0), 2.0);
        check(capsule(Vec3::new(3.0, 1.0, 0.0), a, b, 1.0), 2.0);
        check(capsule(Vec3::new(3.0, 0.0, 4.0), a, a, 1.0), 4.0);
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
        check(death_star(rim, 1.0, 1.0, 1.0), 0.0);
        check(death_star(Vec3::new(-2.0, 0.0, 0.0), 1.0, 1.0, 1.0), 1.0);
        check(death_star(Vec3::new(0.25, 0.0, 0.0), 1.0, 1.0, 1.0), 0.25); // in the crater
        check(death_star(rim * 2.0, 1.0, 1.0, 1.0), 1.0); // beyond the rim, in its cone
        // Mirrored: the crater faces -x.
        check(death_star(Vec3::new(-0.25, 0.0, 0.0), 1.0, 1.0, -1.0), 0.25);
        // Empty: positive everywhere, including where the big sphere used to be.
        assert!(death_star(Vec3::ZERO, 0.5, 1.0, 0.25) > 0.0);
        // Cavity: the hollow inside is outside the shape.
        check(death_star(Vec3::ZERO, 2.0, 0.5, 0.0), 0.5);
        check(death_star(Vec3::new(1.0, 0.0, 0.0), 2.0, 0.5, 0.0), -0.5);
    }
}
