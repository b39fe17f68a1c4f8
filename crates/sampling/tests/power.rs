//! A goodness-of-fit test that accepts everything is worthless. Here the very
//! samples and bins of the conformance tests are checked against pdfs that are
//! wrong by 10% on half of the domain (`pdf * 1.1` there, the whole then
//! renormalised), and the test must reject them. Smaller errors are reported
//! with `--nocapture`, to show where the power ends.

use lueur_sampling::{
    SphericalRectangle, Vec3, cosine_hemisphere_pdf, quad_solid_angle_pdf,
    sample_cosine_hemisphere, sample_sphere_light, sample_uniform_hemisphere, sphere_light_pdf,
};
use lueur_stats::{ChiSquareTest, DirectionBins, chi_square_test};

use crate::common::{N_PHI, N_SAMPLES, N_Z, QuadBins, SIGNIFICANCE, SUB, assert_fits, directions};

/// `expected` with the bins where `in_half` holds scaled by `factor`, then
/// renormalised to the same total.
fn perturb(expected: &[f64], in_half: impl Fn(usize) -> bool, factor: f64) -> Vec<f64> {
    let total: f64 = expected.iter().sum();
    let scaled: Vec<f64> = expected
        .iter()
        .enumerate()
        .map(|(i, &e)| if in_half(i) { e * factor } else { e })
        .collect();
    let new_total: f64 = scaled.iter().sum();
    scaled.iter().map(|e| e * total / new_total).collect()
}

/// The true pdf passes, the 10%-broken one is rejected; returns the broken
/// test for reporting.
fn check_power(
    name: &str,
    observed: &[f64],
    expected: &[f64],
    in_half: impl Fn(usize) -> bool,
) -> ChiSquareTest {
    assert_fits(name, chi_square_test(observed, expected));
    let broken = chi_square_test(observed, &perturb(expected, &in_half, 1.1));
    assert!(
        !broken.accepts(SIGNIFICANCE),
        "{name}: a pdf 10% off was accepted: {broken:?}"
    );
    for factor in [1.1, 1.05, 1.02, 1.01] {
        let t = chi_square_test(observed, &perturb(expected, &in_half, factor));
        eprintln!(
            "{name}: pdf x{factor} on half the domain: statistic {:.1}, dof {}, p-value {:.3e}",
            t.statistic, t.dof, t.p_value
        );
    }
    broken
}

/// Directional bins: "half the domain" is the half-space of azimuth below pi.
fn directional(name: &str, bins: &DirectionBins, dirs: Vec<Vec3>, pdf: impl Fn(Vec3) -> f32) {
    let (mut observed, outside) = bins.histogram(dirs);
    let mut expected = bins.expected_counts(pdf, N_SAMPLES as f64, SUB);
    observed.push(outside);
    expected.push(0.0);
    check_power(name, &observed, &expected, |i| {
        i < bins.len() && i % N_PHI < N_PHI / 2
    });
}

#[test]
fn cosine_hemisphere_rejects_ten_percent_error() {
    let bins = DirectionBins::new(Vec3::Z, 0.0, N_Z, N_PHI);
    let dirs = directions(2, |u| Some(sample_cosine_hemisphere(u)));
    directional("cosine hemisphere", &bins, dirs, |w| {
        cosine_hemisphere_pdf(w.z)
    });
}

#[test]
fn sphere_light_rejects_ten_percent_error() {
    let (p, center, radius) = (Vec3::new(0.3, -0.2, 0.1), Vec3::new(1.0, 2.0, 3.0), 1.2);
    let to_center = (center - p).as_dvec3();
    let z_min = (1.0 - (f64::from(radius) / to_center.length()).powi(2)).sqrt();
    let bins = DirectionBins::new(to_center.normalize().as_vec3(), z_min, N_Z, N_PHI);
    let dirs = directions(10, |u| {
        sample_sphere_light(p, center, radius, u).map(|s| s.wi)
    });
    directional("sphere light", &bins, dirs, |w| {
        sphere_light_pdf(p, center, radius, w)
    });
}

#[test]
fn spherical_rectangle_rejects_ten_percent_error() {
    let bins = QuadBins {
        p: Vec3::new(0.2, 0.1, 0.0),
        corner: Vec3::new(-0.5, 0.5, 1.0),
        edge_u: Vec3::new(1.5, 0.0, 0.0),
        edge_v: Vec3::new(0.0, -1.0, 0.0),
        n: 24,
    };
    let rect = SphericalRectangle::new(bins.p, bins.corner, bins.edge_u, bins.edge_v).unwrap();
    let observed = bins.histogram(&directions(30, |u| rect.sample(u).map(|s| s.wi)));
    let expected = bins.expected(
        |w| quad_solid_angle_pdf(bins.p, bins.corner, bins.edge_u, bins.edge_v, w),
        N_SAMPLES as f64,
    );
    // Half the domain: the cells with s < 1/2.
    let n = bins.n;
    check_power("spherical rectangle", &observed, &expected, |i| {
        i < n * n && i % n < n / 2
    });
}

/// A plainly wrong warp: uniform samples tested against the cosine pdf.
#[test]
fn uniform_samples_fail_the_cosine_pdf() {
    let bins = DirectionBins::new(Vec3::Z, 0.0, N_Z, N_PHI);
    let dirs = directions(2, |u| Some(sample_uniform_hemisphere(u)));
    let test = bins.test(dirs, |w| cosine_hemisphere_pdf(w.z), SUB);
    assert!(!test.accepts(SIGNIFICANCE), "{test:?}");
}
