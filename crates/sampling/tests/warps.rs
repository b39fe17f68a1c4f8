use lueur_sampling::{
    Vec2, Vec3, cosine_hemisphere_pdf, sample_cosine_hemisphere, sample_uniform_cone,
    sample_uniform_hemisphere, sample_uniform_sphere, uniform_cone_pdf, uniform_hemisphere_pdf,
    uniform_sphere_pdf,
};
use lueur_stats::DirectionBins;

use crate::common::{N_PHI, N_Z, SUB, assert_fits, directions};

/// Chi-square of `sample` against `pdf` over bins covering the cap
/// `z >= support_z_min` around +z (the warp's support), and the pdf's
/// integral over that cap, which must be 1.
fn check(
    name: &str,
    seed: u64,
    support_z_min: f64,
    sample: impl Fn(Vec2) -> Vec3,
    pdf: impl Fn(Vec3) -> f32,
) {
    let bins = DirectionBins::new(Vec3::Z, support_z_min, N_Z, N_PHI);
    let test = bins.test(directions(seed, |u| Some(sample(u))), &pdf, SUB);
    assert_fits(name, test);
    let total: f64 = bins.expected_counts(&pdf, 1.0, SUB).iter().sum();
    assert!(
        (total - 1.0).abs() < 1e-4,
        "{name}: pdf integrates to {total}"
    );
}

#[test]
fn uniform_hemisphere() {
    check(
        "uniform hemisphere",
        1,
        0.0,
        sample_uniform_hemisphere,
        |w| {
            if w.z >= 0.0 {
                uniform_hemisphere_pdf()
            } else {
                0.0
            }
        },
    );
}

#[test]
fn cosine_hemisphere() {
    check("cosine hemisphere", 2, 0.0, sample_cosine_hemisphere, |w| {
        cosine_hemisphere_pdf(w.z)
    });
}

#[test]
fn uniform_sphere() {
    check("uniform sphere", 3, -1.0, sample_uniform_sphere, |_| {
        uniform_sphere_pdf()
    });
}

#[test]
fn uniform_cones() {
    for (i, cos_theta_max) in [0.6f32, -0.4, 0.995].into_iter().enumerate() {
        check(
            &format!("cone cos_theta_max={cos_theta_max}"),
            4 + i as u64,
            f64::from(cos_theta_max),
            |u| sample_uniform_cone(u, cos_theta_max),
            |w| {
                if w.z >= cos_theta_max {
                    uniform_cone_pdf(cos_theta_max)
                } else {
                    0.0
                }
            },
        );
    }
}
