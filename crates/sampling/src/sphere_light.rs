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
use lueur_sdf_math::{Lane, LaneVec3};

use crate::frame::FrameLanes;
use crate::light::{DirectionSample, DirectionSampleLanes};
use crate::math::{clamp_u_lanes, normalize_with_length_lanes, safe_sqrt_lanes, sin_cos_turns};
use crate::warp::sample_uniform_sphere_lanes;

/// True when `p` is inside or on the sphere; the sampler and the pdf must
/// take this decision with the same arithmetic.
#[inline(always)]
fn is_inside<L: Lane>(p: LaneVec3<L>, center: LaneVec3<L>, radius: L) -> L::Mask {
    (radius * radius).ge((center - p).length_squared())
}

#[inline]
fn valid(p: Vec3, center: Vec3, radius: f32) -> bool {
    radius.is_finite() && radius > 0.0 && p.is_finite() && center.is_finite()
}

/// Geometry of the cone of directions from an outside point to the sphere, per lane.
struct Cone<L> {
    axis: LaneVec3<L>,
    sin_theta_max: L,
    sin2_theta_max: L,
    /// `1 - cos_theta_max`, computed as `sin2 / (1 + cos)` so that it is
    /// accurate for tiny cones, where pbrt-v4 switches to a Taylor expansion.
    one_minus_cos_max: L,
}

impl<L: Lane> Cone<L> {
    /// The cone from each lane's `p`, and where it exists.
    #[inline(always)]
    fn lanes(p: LaneVec3<L>, center: LaneVec3<L>, radius: L) -> (Self, L::Mask) {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let (axis, dist, valid) = normalize_with_length_lanes(center - p);
        let sin_theta_max = (radius / dist).min(one);
        let sin2_theta_max = sin_theta_max * sin_theta_max;
        let cos_theta_max = safe_sqrt_lanes(one - sin2_theta_max);
        let one_minus_cos_max = sin2_theta_max / (one + cos_theta_max);
        let valid = L::and(
            valid,
            L::and(sin_theta_max.gt(zero), one_minus_cos_max.gt(zero)),
        );
        let cone = Self {
            axis,
            sin_theta_max,
            sin2_theta_max,
            one_minus_cos_max,
        };
        (cone, valid)
    }

    /// Uniform cone pdf `1 / (2pi (1 - cos_theta_max))` (pbrt-v4 §A.5.4).
    #[inline(always)]
    fn pdf(&self) -> L {
        L::splat(1.0) / (L::splat(TAU) * self.one_minus_cos_max)
    }
}

impl Cone<f32> {
    fn new(p: Vec3, center: Vec3, radius: f32) -> Option<Self> {
        let (cone, valid) = Self::lanes(p.into(), center.into(), radius);
        valid.then_some(cone)
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
/// positions, or when no finite, positive pdf exists for the sample. This is
/// [`sample_sphere_light_lanes`] for one point.
pub fn sample_sphere_light(p: Vec3, center: Vec3, radius: f32, u: Vec2) -> Option<DirectionSample> {
    sample_sphere_light_lanes(p.into(), center.into(), radius, [u.x, u.y]).single()
}

/// [`sample_sphere_light`] for a shading point and a sphere per lane (`u` the two
/// numbers of each), its one definition: each lane is, bit for bit, what the scalar
/// function gives for that lane's inputs, valid where it gives `Some`. The outside
/// cone is computed for every lane, the inside sample where any lane is inside, and
/// each lane keeps its side, so that a vector of shading points costs about what one
/// does.
#[inline(always)]
pub fn sample_sphere_light_lanes<L: Lane>(
    p: LaneVec3<L>,
    center: LaneVec3<L>,
    radius: L,
    u: [L; 2],
) -> DirectionSampleLanes<L> {
    let one = L::splat(1.0);
    let valid_sphere = L::and(
        L::and(radius.finite(), radius.gt(L::splat(0.0))),
        center.finite(),
    );
    let inside = is_inside(p, center, radius);
    // Inside or on: a uniform point on the sphere, where some lane needs it (a shading
    // point is seldom inside a light).
    let normal_inside = if L::any(inside) {
        sample_uniform_sphere_lanes(u)
    } else {
        LaneVec3::splat(Vec3::ZERO)
    };
    // Outside: a uniform direction in the cone, mapped to the visible point.
    let (cone, cone_valid) = Cone::lanes(p, center, radius);
    let one_minus_cos = clamp_u_lanes(u[0]) * cone.one_minus_cos_max;
    let cos_theta = one - one_minus_cos;
    let sin2_theta = one_minus_cos * (L::splat(2.0) - one_minus_cos);
    let cos_alpha = sin2_theta / cone.sin_theta_max
        + cos_theta * safe_sqrt_lanes(one - sin2_theta / cone.sin2_theta_max);
    let cos_alpha = cos_alpha.min(one);
    let sin_alpha = safe_sqrt_lanes(one - cos_alpha * cos_alpha);
    let (sin_phi, cos_phi) = sin_cos_turns(clamp_u_lanes(u[1]));
    let w = LaneVec3::new(sin_alpha * cos_phi, sin_alpha * sin_phi, cos_alpha);
    // `w` points from the centre away from `p` along the axis; the visible
    // point is on the near side, hence the minus sign.
    let normal_outside = FrameLanes::from_normal(cone.axis).to_world(-w);

    let normal = LaneVec3::new(
        L::select(inside, normal_inside.x, normal_outside.x),
        L::select(inside, normal_inside.y, normal_outside.y),
        L::select(inside, normal_inside.z, normal_outside.z),
    );
    let point = center + normal * radius;
    let (wi, distance, toward) = normalize_with_length_lanes(point - p);
    let area = L::splat(2.0 * TAU) * radius * radius;
    let pdf_inside = distance * distance / (normal.dot(wi).abs() * area);
    let pdf = L::select(inside, pdf_inside, cone.pdf());
    let has_pdf = L::and(L::or(inside, cone_valid), valid_sphere);
    DirectionSampleLanes::toward(p, (point, normal), (wi, distance, toward), (pdf, has_pdf))
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
    if is_inside(p.into(), center.into(), radius) {
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
    if is_inside(p.into(), center.into(), radius) {
        return 2.0 * TAU;
    }
    Cone::new(p, center, radius).map_or(0.0, |cone| TAU * cone.one_minus_cos_max)
}

#[cfg(test)]
mod tests {
    use lueur_sdf_math::{LaneKernel, SimdLevel};

    use super::*;
    use crate::math::ONE_MINUS_EPSILON;

    /// Samples each `(p, u)` a lane each on the level it runs on, as bits.
    struct Lanes<'a> {
        sphere: (Vec3, f32),
        queries: &'a [(Vec3, Vec2)],
    }

    impl LaneKernel for Lanes<'_> {
        type Output = Vec<Option<[u32; 12]>>;

        fn run<L: Lane>(self) -> Self::Output {
            let (center, radius) = self.sphere;
            let mut out = Vec::new();
            for chunk in self.queries.chunks(L::LANES) {
                let row = |f: &dyn Fn(&(Vec3, Vec2)) -> f32| {
                    L::load(&chunk.iter().map(f).collect::<Vec<_>>())
                };
                let p = LaneVec3::new(row(&|q| q.0.x), row(&|q| q.0.y), row(&|q| q.0.z));
                let u = [row(&|q| q.1.x), row(&|q| q.1.y)];
                let s = sample_sphere_light_lanes(p, LaneVec3::splat(center), L::splat(radius), u);
                let values = [
                    s.wi.x, s.wi.y, s.wi.z, s.distance, s.pdf, s.point.x, s.point.y, s.point.z,
                    s.normal.x, s.normal.y, s.normal.z,
                ];
                let mut columns = [[0f32; 16]; 11];
                for (column, v) in columns.iter_mut().zip(values) {
                    v.store(&mut column[..chunk.len()]);
                }
                let valid = L::bits(s.valid);
                for lane in 0..chunk.len() {
                    out.push((valid >> lane & 1 == 1).then(|| {
                        let mut bits = [1u32; 12];
                        for (b, column) in bits.iter_mut().zip(&columns) {
                            *b = column[lane].to_bits();
                        }
                        bits
                    }));
                }
            }
            out
        }
    }

    /// The batch form gives, in every lane and on every SIMD level this CPU has, the
    /// scalar function's bits: inside and outside the sphere, on it, at its centre, far
    /// away, at non-finite points and at the ends of `u`.
    #[test]
    fn lanes_give_the_scalar_bits_on_every_level() {
        let (center, radius) = (Vec3::new(0.3, 1.7, -0.2), 0.15);
        let points = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.3, 1.7, -0.2),
            Vec3::new(0.3, 1.6, -0.2),
            Vec3::new(0.3, 1.85, -0.2),
            Vec3::new(1e4, -3e3, 2e4),
            Vec3::new(0.31, 1.72, -0.19),
            Vec3::new(f32::NAN, 0.0, 0.0),
            Vec3::new(0.0, f32::INFINITY, 0.0),
        ];
        let us = [0.0, 0.3, 0.5, 0.77, ONE_MINUS_EPSILON, f32::NAN, 1.5];
        let mut queries = Vec::new();
        for &p in &points {
            for &a in &us {
                for &b in &us {
                    queries.push((p, Vec2::new(a, b)));
                }
            }
        }
        let expected: Vec<Option<[u32; 12]>> = queries
            .iter()
            .map(|&(p, u)| {
                sample_sphere_light(p, center, radius, u).map(|s| {
                    let v = [
                        s.wi.x, s.wi.y, s.wi.z, s.distance, s.pdf, s.point.x, s.point.y, s.point.z,
                        s.normal.x, s.normal.y, s.normal.z,
                    ];
                    let mut bits = [1u32; 12];
                    for (b, v) in bits.iter_mut().zip(v) {
                        *b = v.to_bits();
                    }
                    bits
                })
            })
            .collect();
        assert!(expected.iter().filter(|s| s.is_some()).count() > queries.len() / 2);
        for level in SimdLevel::available() {
            let kernel = Lanes {
                sphere: (center, radius),
                queries: &queries,
            };
            let got = level.dispatch(kernel).unwrap();
            assert_eq!(got, expected, "{level:?}");
        }
    }

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
