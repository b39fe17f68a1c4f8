//! Sampling directions toward a spherical light.
//!
//! From outside the sphere the visible cap subtends a cone; sampling that cone
//! uniformly (pbrt-v4 §6.2.4, "Sampling") has a constant solid-angle pdf and
//! never wastes a sample on the hidden side. From inside (or on) the sphere
//! every direction sees the sphere once, and uniform area sampling converted
//! to solid angle is used instead.

use std::f32::consts::TAU;
use std::f64::consts::PI as PI64;

use glam::{Vec2, Vec3};

use crate::frame::Frame;
use crate::light::DirectionSample;
use crate::math::{clamp_u2, normalize_with_length, safe_sqrt};
use crate::warp::sample_uniform_sphere;

/// True when `p` is inside or on the sphere; the sampler and the pdf must
/// take this decision with the same arithmetic.
#[inline]
fn is_inside(p: Vec3, center: Vec3, radius: f32) -> bool {
    (center - p).length_squared() <= radius * radius
}

#[inline]
fn valid(p: Vec3, center: Vec3, radius: f32) -> bool {
    radius.is_finite() && radius > 0.0 && p.is_finite() && center.is_finite()
}

/// Geometry of the cone of directions from an outside point to the sphere.
struct Cone {
    axis: Vec3,
    sin_theta_max: f32,
    sin2_theta_max: f32,
    /// `1 - cos_theta_max`, computed as `sin2 / (1 + cos)` so that it is
    /// accurate for tiny cones, where pbrt-v4 switches to a Taylor expansion.
    one_minus_cos_max: f32,
}

impl Cone {
    fn new(p: Vec3, center: Vec3, radius: f32) -> Option<Self> {
        let (axis, dist) = normalize_with_length(center - p)?;
        let sin_theta_max = (radius / dist).min(1.0);
        let sin2_theta_max = sin_theta_max * sin_theta_max;
        let cos_theta_max = safe_sqrt(1.0 - sin2_theta_max);
        let one_minus_cos_max = sin2_theta_max / (1.0 + cos_theta_max);
        (sin_theta_max > 0.0 && one_minus_cos_max > 0.0).then_some(Self {
            axis,
            sin_theta_max,
            sin2_theta_max,
            one_minus_cos_max,
        })
    }

    /// Uniform cone pdf `1 / (2pi (1 - cos_theta_max))` (pbrt-v4 §A.5.4).
    fn pdf(&self) -> f32 {
        1.0 / (TAU * self.one_minus_cos_max)
    }
}

/// Samples a direction from `p` toward the sphere light (`center`, `radius`).
///
/// Outside the sphere: uniform sampling of the cone of directions subtended
/// by the sphere, mapped back to the point on the sphere through the angle
/// `alpha` at the centre (pbrt-v4 §6.2.4):
/// `cos(alpha) = sin^2(theta) / sin(theta_max) + cos(theta) sqrt(1 -
/// sin^2(theta) / sin^2(theta_max))`. The pdf is `1 / (2pi (1 -
/// cos_theta_max))`.
///
/// Inside or on the sphere: a uniform point on the surface with the
/// area-to-solid-angle pdf `d^2 / (|cos| 4pi r^2)` (pbrt-v4 §4.2.3).
///
/// Returns `None` for a non-positive or non-finite radius, non-finite
/// positions, or when no finite, positive pdf exists for the sample.
pub fn sample_sphere_light(p: Vec3, center: Vec3, radius: f32, u: Vec2) -> Option<DirectionSample> {
    if !valid(p, center, radius) {
        return None;
    }
    let u = clamp_u2(u);
    if is_inside(p, center, radius) {
        let normal = sample_uniform_sphere(u);
        let point = center + radius * normal;
        let area = 2.0 * TAU * radius * radius;
        return DirectionSample::toward_with(p, point, normal, |wi, distance| {
            let cos = normal.dot(wi).abs();
            distance * distance / (cos * area)
        });
    }
    let cone = Cone::new(p, center, radius)?;
    let one_minus_cos = u.x * cone.one_minus_cos_max;
    let cos_theta = 1.0 - one_minus_cos;
    let sin2_theta = one_minus_cos * (2.0 - one_minus_cos);
    let cos_alpha = sin2_theta / cone.sin_theta_max
        + cos_theta * safe_sqrt(1.0 - sin2_theta / cone.sin2_theta_max);
    let cos_alpha = cos_alpha.min(1.0);
    let sin_alpha = safe_sqrt(1.0 - cos_alpha * cos_alpha);
    let phi = TAU * u.y;
    let w = Vec3::new(sin_alpha * phi.cos(), sin_alpha * phi.sin(), cos_alpha);
    // `w` points from the centre away from `p` along the axis; the visible
    // point is on the near side, hence the minus sign.
    let normal = Frame::from_normal(cone.axis).to_world(-w);
    let point = center + radius * normal;
    DirectionSample::toward(p, point, normal, cone.pdf())
}

/// Solid-angle pdf with which [`sample_sphere_light`] produces `wi` from `p`;
/// 0 when the ray `(p, wi)` misses the sphere or the inputs are invalid.
///
/// From outside, the ray test (in f64) allows a few f32 ulps of slack, scaled
/// by the coordinates' magnitude: a sampled point on the silhouette of a
/// sphere 1e-4 wide at coordinates near 2 is rounded by 1% of the radius,
/// and a sphere 1e-4 wide seen from 1e3 away is narrower than the f32 grid of
/// unit vectors. So a direction the sampler produced is never reported as a
/// miss, at the price of a sliver of extra support (about 1e-6 relative for
/// ordinary lights) where the pdf is reported but no sample lands.
pub fn sphere_light_pdf(p: Vec3, center: Vec3, radius: f32, wi: Vec3) -> f32 {
    if !valid(p, center, radius) || !wi.is_finite() {
        return 0.0;
    }
    let wi64 = wi.as_dvec3();
    let length = wi64.length();
    if length <= 0.0 {
        return 0.0;
    }
    let wi64 = wi64 / length;
    let to_center = center.as_dvec3() - p.as_dvec3();
    let r = f64::from(radius);
    let b = to_center.dot(wi64);
    let h2 = to_center.cross(wi64).length_squared();
    if is_inside(p, center, radius) {
        // Exit point of the ray: t = b + sqrt(r^2 - h^2); there the cosine
        // with the normal is sqrt(r^2 - h^2) / r.
        let s = (r * r - h2).max(0.0).sqrt();
        let t = b + s;
        let cos = s / r;
        let pdf = t * t / (cos * 4.0 * PI64 * r * r);
        return finite_pdf(pdf);
    }
    // The sampled point carries the f32 rounding of its coordinates, which
    // for a small sphere far from the origin dwarfs the radius's own.
    let magnitude =
        to_center.length() + f64::from(p.abs().max_element().max(center.abs().max_element()));
    let tolerance = r * 1e-5 + magnitude * 2e-7;
    if b <= 0.0 || h2.sqrt() > r + tolerance {
        return 0.0;
    }
    Cone::new(p, center, radius).map_or(0.0, |cone| cone.pdf())
}

/// Casts an f64 pdf to f32, mapping anything non-finite, negative or
/// overflowing to 0 ("no weight").
#[inline]
pub(crate) fn finite_pdf(pdf: f64) -> f32 {
    let pdf = pdf as f32;
    if pdf.is_finite() && pdf > 0.0 {
        pdf
    } else {
        0.0
    }
}

/// The exact solid angle subtended by the sphere from an outside point,
/// `2pi (1 - cos_theta_max)`, or `4pi` from inside. Useful as a reference.
pub fn sphere_solid_angle(p: Vec3, center: Vec3, radius: f32) -> f32 {
    if !valid(p, center, radius) {
        return 0.0;
    }
    if is_inside(p, center, radius) {
        return 2.0 * TAU;
    }
    Cone::new(p, center, radius).map_or(0.0, |cone| TAU * cone.one_minus_cos_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::ONE_MINUS_EPSILON;

    #[test]
    fn outside_samples_hit_sphere_with_consistent_pdf() {
        let (p, c, r) = (Vec3::new(0.2, -0.1, 0.3), Vec3::new(1.0, 2.0, 3.0), 0.7);
        for &a in &[0.0, 0.3, 0.77, ONE_MINUS_EPSILON] {
            for &b in &[0.0, 0.5, ONE_MINUS_EPSILON] {
                let s = sample_sphere_light(p, c, r, Vec2::new(a, b)).unwrap();
                assert!(((s.point - c).length() - r).abs() < 1e-5);
                assert!((p + s.distance * s.wi - s.point).length() < 1e-4);
                assert!(s.normal.dot(-s.wi) >= -1e-4, "point on the far side");
                assert_eq!(sphere_light_pdf(p, c, r, s.wi), s.pdf);
            }
        }
        assert_eq!(sphere_light_pdf(p, c, r, -(c - p).normalize()), 0.0);
    }

    #[test]
    fn inside_samples_have_matching_pdf() {
        let (p, c, r) = (Vec3::new(0.9, 0.1, 0.0), Vec3::ZERO, 1.5);
        for &a in &[0.0, 0.3, 0.77, ONE_MINUS_EPSILON] {
            for &b in &[0.0, 0.5, ONE_MINUS_EPSILON] {
                let s = sample_sphere_light(p, c, r, Vec2::new(a, b)).unwrap();
                let pdf = sphere_light_pdf(p, c, r, s.wi);
                assert!((pdf - s.pdf).abs() <= 1e-3 * s.pdf, "{pdf} vs {}", s.pdf);
            }
        }
    }

    #[test]
    fn degenerate_inputs() {
        let u = Vec2::splat(0.5);
        assert!(sample_sphere_light(Vec3::ZERO, Vec3::X, 0.0, u).is_none());
        assert!(sample_sphere_light(Vec3::ZERO, Vec3::X, f32::NAN, u).is_none());
        assert!(sample_sphere_light(Vec3::NAN, Vec3::X, 1.0, u).is_none());
        assert_eq!(sphere_light_pdf(Vec3::ZERO, Vec3::X, -1.0, Vec3::X), 0.0);
        assert_eq!(
            sphere_light_pdf(Vec3::ZERO, 2.0 * Vec3::X, 1.0, Vec3::ZERO),
            0.0
        );
    }
}
