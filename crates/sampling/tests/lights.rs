use glam::DVec3;
use lueur_sampling::{
    DirectionSample, Frame, SphericalRectangle, Vec2, Vec3, polygon_irradiance, quad_area_pdf,
    quad_solid_angle_pdf, sample_quad_area, sample_sphere_light, sphere_light_pdf,
    sphere_solid_angle,
};
use lueur_stats::{DirectionBins, chi_square_test};

use crate::common::{N_PHI, N_SAMPLES, N_Z, QuadBins, SUB, Uniforms, assert_fits, directions};

/// Chi-square of the sphere-light sampler against its pdf, in bins over the
/// cone the sphere subtends (the whole sphere from inside), and the pdf's
/// integral over that cone.
fn check_sphere(name: &str, seed: u64, p: Vec3, center: Vec3, radius: f32) {
    let to_center = (center - p).as_dvec3();
    let (d, r) = (to_center.length(), f64::from(radius));
    let z_min = if d <= r {
        -1.0
    } else {
        (1.0 - (r / d).powi(2)).sqrt()
    };
    let bins = DirectionBins::new(to_center.normalize().as_vec3(), z_min, N_Z, N_PHI);
    let pdf = |w| sphere_light_pdf(p, center, radius, w);
    let dirs = directions(seed, |u| {
        sample_sphere_light(p, center, radius, u).map(|s| s.wi)
    });
    assert_fits(name, bins.test(dirs, pdf, SUB));
    let total: f64 = bins.expected_counts(pdf, 1.0, SUB).iter().sum();
    assert!(
        (total - 1.0).abs() < 1e-3,
        "{name}: pdf integrates to {total}"
    );
}

#[test]
fn sphere_light_from_outside() {
    let center = Vec3::new(1.0, 2.0, 3.0);
    check_sphere("sphere, far", 10, Vec3::new(0.3, -0.2, 0.1), center, 1.2);
    // Close to the surface the cone is almost a hemisphere.
    let p = center + 1.05 * Vec3::new(0.6, -0.8, 0.0);
    check_sphere("sphere, near", 11, p, center, 1.0);
    // Narrow cones, where 1 - cos(theta_max) cancels in f32 (pbrt-v4 switches
    // to a Taylor expansion below sin^2(theta_max) = 6.85e-4).
    let p = center + Vec3::new(0.0, 0.6, 0.8) * 3.0;
    check_sphere("sphere, sin(theta_max) = 1e-2", 13, p, center, 0.03);
    check_sphere("sphere, sin(theta_max) = 1e-3", 14, p, center, 0.003);
}

#[test]
fn sphere_light_from_inside() {
    let center = Vec3::new(-1.0, 0.5, 2.0);
    check_sphere(
        "sphere, inside",
        12,
        center + Vec3::new(0.5, 0.2, -0.1),
        center,
        0.8,
    );
}

#[test]
fn sphere_light_pdf_times_solid_angle_is_one_outside() {
    let (p, center, radius) = (Vec3::ZERO, Vec3::new(0.0, 3.0, 4.0), 2.0);
    let wi = (center - p).normalize();
    let product = sphere_light_pdf(p, center, radius, wi) * sphere_solid_angle(p, center, radius);
    assert!((product - 1.0).abs() < 1e-6, "{product}");
}

/// A quad light configuration: shading point, corner, two edges.
#[derive(Clone, Copy)]
struct Quad {
    name: &'static str,
    p: Vec3,
    corner: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
}

const QUADS: [Quad; 6] = [
    Quad {
        name: "overhead",
        p: Vec3::new(0.2, 0.1, 0.0),
        corner: Vec3::new(-0.5, 0.5, 1.0),
        edge_u: Vec3::new(1.5, 0.0, 0.0),
        edge_v: Vec3::new(0.0, -1.0, 0.0),
    },
    Quad {
        name: "tilted, to the side",
        p: Vec3::ZERO,
        corner: Vec3::new(1.0, -0.5, 0.5),
        edge_u: Vec3::new(0.5, 0.0, 0.8),
        edge_v: Vec3::new(0.0, 1.0, 0.0),
    },
    Quad {
        name: "close (large solid angle)",
        p: Vec3::new(0.1, -0.2, 0.9),
        corner: Vec3::new(-1.0, 1.0, 1.0),
        edge_u: Vec3::new(2.0, 0.0, 0.0),
        edge_v: Vec3::new(0.0, -2.0, 0.0),
    },
    Quad {
        name: "grazing",
        p: Vec3::new(3.0, 0.3, 0.95),
        corner: Vec3::new(-0.5, 0.5, 1.0),
        edge_u: Vec3::new(1.0, 0.0, 0.0),
        edge_v: Vec3::new(0.0, -1.0, 0.0),
    },
    Quad {
        name: "small (1e-4 sr)",
        p: Vec3::new(0.3, 0.2, 0.0),
        corner: Vec3::new(-0.005, 0.005, 1.0),
        edge_u: Vec3::new(0.01, 0.0, 0.0),
        edge_v: Vec3::new(0.0, -0.01, 0.0),
    },
    Quad {
        name: "tiny (1e-8 sr)",
        p: Vec3::new(0.3, 0.2, 0.0),
        corner: Vec3::new(-0.5e-4, 0.5e-4, 1.0),
        edge_u: Vec3::new(1e-4, 0.0, 0.0),
        edge_v: Vec3::new(0.0, -1e-4, 0.0),
    },
];

impl Quad {
    fn bins(&self) -> QuadBins {
        QuadBins {
            p: self.p,
            corner: self.corner,
            edge_u: self.edge_u,
            edge_v: self.edge_v,
            n: 24,
        }
    }

    /// Integral of a solid-angle `pdf` over directions: the midpoint rule on
    /// a 1024 x 1024 grid in `(z, phi)` (where `d omega = dz dphi`) around the
    /// axis pointing straight at the light's plane, over the patch of `z` and
    /// `phi` the light covers plus a margin. A patch fitted to the light
    /// resolves a light seen at grazing angles (thin in `z`) and a tiny one
    /// alike; it extends beyond the light, so a pdf leaking outside it shows.
    fn integrate(&self, pdf: impl Fn(Vec3) -> f32) -> f64 {
        use std::f64::consts::{PI, TAU};
        let axis = -self.edge_u.cross(self.edge_v).normalize();
        let frame = Frame::from_normal(axis);
        let local = |q: Vec3| frame.to_local((q - self.p).normalize()).as_dvec3();
        let center = local(self.corner + 0.5 * (self.edge_u + self.edge_v));
        let phi_c = center.y.atan2(center.x);
        let (mut z_lo, mut z_hi, mut phi_lo, mut phi_hi) = (1.0f64, 0.0f64, 0.0f64, 0.0f64);
        let n = 64;
        for i in 0..=n {
            for j in 0..=n {
                let (s, t) = (i as f32 / n as f32, j as f32 / n as f32);
                let w = local(self.corner + s * self.edge_u + t * self.edge_v);
                z_lo = z_lo.min(w.z);
                z_hi = z_hi.max(w.z);
                // Azimuth relative to the centre's, wrapped into [-pi, pi).
                let phi = (w.y.atan2(w.x) - phi_c + PI).rem_euclid(TAU) - PI;
                phi_lo = phi_lo.min(phi);
                phi_hi = phi_hi.max(phi);
            }
        }
        let margin = 0.1 * (z_hi - z_lo);
        let (z_lo, z_hi) = ((z_lo - margin).max(0.0), (z_hi + margin).min(1.0));
        let margin = 0.1 * (phi_hi - phi_lo);
        let (mut phi_lo, mut phi_hi) = (phi_lo - margin, phi_hi + margin);
        if z_hi >= 1.0 || phi_hi - phi_lo >= PI {
            // The light surrounds the axis: all azimuths.
            (phi_lo, phi_hi) = (-PI, PI);
        }
        let m = 1024;
        let (dz, dphi) = ((z_hi - z_lo) / m as f64, (phi_hi - phi_lo) / m as f64);
        let mut sum = 0.0;
        for i in 0..m {
            let z = z_lo + (i as f64 + 0.5) * dz;
            let r = (1.0 - z * z).max(0.0).sqrt();
            for j in 0..m {
                let phi = phi_c + phi_lo + (j as f64 + 0.5) * dphi;
                let w = DVec3::new(r * phi.cos(), r * phi.sin(), z).as_vec3();
                sum += f64::from(pdf(frame.to_world(w)));
            }
        }
        sum * dz * dphi
    }

    /// Relative tolerance of [`Quad::integrate`]. The pdfs accept directions
    /// a few f32 ulps of the coordinates beyond the light's edges (so that
    /// rounded samples are not reported as misses); for a light 1e-4 wide at
    /// coordinates near 1 that is 1.6% of its area, otherwise under 1e-3.
    fn directional_tolerance(&self) -> f64 {
        let edge = self.edge_u.length().min(self.edge_v.length());
        if edge < 1e-3 { 0.05 } else { 2e-3 }
    }

    fn check(
        &self,
        strategy: &str,
        seed: u64,
        sample: impl Fn(Vec2) -> Option<DirectionSample>,
        pdf: impl Fn(Vec3) -> f32,
    ) {
        let name = format!("{strategy}, {}", self.name);
        let bins = self.bins();
        let observed = bins.histogram(&directions(seed, |u| sample(u).map(|s| s.wi)));
        let expected = bins.expected(&pdf, N_SAMPLES as f64);
        assert_fits(&name, chi_square_test(&observed, &expected));
        let total = self.integrate(&pdf);
        eprintln!("{name}: pdf integral over directions {total:.6}");
        let tolerance = self.directional_tolerance();
        assert!(
            (total - 1.0).abs() < tolerance,
            "{name}: pdf integrates to {total} over directions"
        );
        // The same integral through the change of variables to the light's
        // area, which has no discontinuity and so is accurate to 1e-5.
        let total = expected[..expected.len() - 1].iter().sum::<f64>() / N_SAMPLES as f64;
        assert!(
            (total - 1.0).abs() < 1e-4,
            "{name}: pdf integrates to {total} over the area"
        );
    }
}

#[test]
fn quad_area_sampling() {
    for (i, q) in QUADS.iter().enumerate() {
        q.check(
            "quad area",
            20 + i as u64,
            |u| sample_quad_area(q.p, q.corner, q.edge_u, q.edge_v, u),
            |w| quad_area_pdf(q.p, q.corner, q.edge_u, q.edge_v, w),
        );
    }
}

#[test]
fn spherical_rectangle_sampling() {
    for (i, q) in QUADS.iter().enumerate() {
        let rect = SphericalRectangle::new(q.p, q.corner, q.edge_u, q.edge_v)
            .unwrap_or_else(|| panic!("{}: no spherical rectangle", q.name));
        q.check(
            "spherical rectangle",
            30 + i as u64,
            |u| rect.sample(u),
            |w| quad_solid_angle_pdf(q.p, q.corner, q.edge_u, q.edge_v, w),
        );
        // The solid angle agrees with the directional integral of the
        // indicator of the light.
        let solid_angle = q.integrate(|w| {
            if quad_area_pdf(q.p, q.corner, q.edge_u, q.edge_v, w) > 0.0 {
                1.0
            } else {
                0.0
            }
        });
        let s = f64::from(rect.solid_angle());
        let tolerance = q.directional_tolerance();
        assert!(
            (solid_angle - s).abs() < tolerance * s,
            "{}: {solid_angle} vs {s}",
            q.name
        );
    }
}

/// Mean and variance of `f(wi) / pdf` over `n` samples.
fn estimate(
    n: usize,
    seed: u64,
    sample: impl Fn(Vec2) -> Option<DirectionSample>,
    f: impl Fn(Vec3) -> f64,
) -> (f64, f64) {
    let mut u = Uniforms::new(seed);
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let x = sample(u.next_2d()).map_or(0.0, |s| f(s.wi) / f64::from(s.pdf));
        sum += x;
        sum2 += x * x;
    }
    let mean = sum / n as f64;
    (mean, (sum2 / n as f64 - mean * mean).max(0.0))
}

/// Irradiance at a point under a unit-radiance rectangle, estimated by area
/// and by spherical-rectangle sampling: both agree with Lambert's closed form,
/// and solid-angle sampling has the lower variance (here, a light close to
/// the shading point, where `d^2 / cos` varies most over the light).
#[test]
fn irradiance_variance_area_versus_spherical_rectangle() {
    let (p, n) = (Vec3::new(0.3, 0.2, 0.0), Vec3::Z);
    let (corner, eu, ev) = (Vec3::new(-0.5, 0.5, 0.5), Vec3::X, -Vec3::Y);
    let reference = f64::from(polygon_irradiance(
        p,
        n,
        &[corner, corner + eu, corner + eu + ev, corner + ev],
    ));
    let cos = |w: Vec3| f64::from(w.dot(n).max(0.0));
    let n_samples = 200_000;
    let rect = SphericalRectangle::new(p, corner, eu, ev).unwrap();
    let (area_mean, area_var) = estimate(
        n_samples,
        40,
        |u| sample_quad_area(p, corner, eu, ev, u),
        cos,
    );
    let (rect_mean, rect_var) = estimate(n_samples, 41, |u| rect.sample(u), cos);
    for (name, mean, var) in [
        ("area", area_mean, area_var),
        ("spherical rectangle", rect_mean, rect_var),
    ] {
        let standard_error = (var / n_samples as f64).sqrt();
        assert!(
            (mean - reference).abs() < 5.0 * standard_error + 1e-6,
            "{name}: {mean} vs reference {reference} (standard error {standard_error})"
        );
    }
    assert!(
        rect_var < area_var,
        "spherical rectangle {rect_var} vs area {area_var}"
    );
    eprintln!(
        "irradiance {reference:.6}: area mean {area_mean:.6} variance {area_var:.6}; \
         spherical rectangle mean {rect_mean:.6} variance {rect_var:.6} (ratio {:.2})",
        area_var / rect_var
    );
}
