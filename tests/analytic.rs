//! Scenes with a closed-form answer. Every check is a z-test against the
//! render's own standard error: |mean - expected| < Z * stderr, with Z = 5
//! per pixel (two-sided p ~ 6e-7 for a normal mean, so a false alarm over a
//! few thousand pixels has probability below 1e-3) and Z = 4 for single
//! quantities. Seeds are fixed, so a pass is reproducible.

use std::f32::consts::PI;

use glam::Vec3;
use lueur::materials::Material;
use lueur::sampling::SamplerKind;
use lueur::scene::{Camera, Light, QuadSampling, RenderSettings, Strategy};
use lueur::sdf_math::{Quat, Sdf};

use crate::common::{run, scene_of};

const UNBIASED: [Strategy; 4] = [
    Strategy::Uniform,
    Strategy::Cosine,
    Strategy::Mixture,
    Strategy::Mis,
];

fn furnace_objects() -> Vec<Sdf> {
    vec![
        Sdf::Translate {
            offset: Vec3::new(-0.6, 0.0, 0.0),
            child: Box::new(Sdf::sphere(0.45)),
        },
        // A torus is not convex: paths bounce on it more than once.
        Sdf::Translate {
            offset: Vec3::new(0.55, 0.0, 0.0),
            child: Box::new(Sdf::Rotate {
                rotation: Quat::from_rotation_x(1.1),
                child: Box::new(Sdf::torus(0.4, 0.15)),
            }),
        },
    ]
}

/// White furnace: albedo-1 objects under a sky of radiance 1 are invisible,
/// every pixel has radiance exactly 1 in expectation.
#[test]
fn white_furnace_is_uniformly_one() {
    let camera = Camera::new(Vec3::new(0.0, 0.3, 3.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap();
    let white = Material::Lambertian { albedo: Vec3::ONE };
    let scene = scene_of(furnace_objects(), white, vec![], Some(Vec3::ONE), camera);
    for strategy in UNBIASED {
        let settings = RenderSettings {
            sampler: SamplerKind::Independent,
            width: 24,
            height: 16,
            spp: 256,
            strategy,
            max_depth: 64,
            ..Default::default()
        };
        let film = run(&scene, &settings).film;
        let (mean, stderr) = film.image_mean();
        assert!(
            (mean - 1.0).abs() < 4.0 * stderr + 1e-6,
            "{strategy}: image mean {mean} +- {stderr}"
        );
        for p in film.pixels() {
            let se = p.variance_of_mean().max_element().sqrt();
            let err = (p.mean - Vec3::ONE).abs().max_element();
            assert!(
                err < 5.0 * se + 1e-5,
                "{strategy}: pixel {} +- {se}",
                p.mean
            );
        }
    }
}

/// Radiance at the point of a Lambertian plane right below a sphere light:
/// irradiance pi L sin^2(theta) with sin(theta) = r / h, times rho / pi.
/// Russian roulette is unbiased: in a grey furnace (albedo 0.5, where it
/// plays from the first bounce on) the image mean with roulette from depth
/// 0 agrees with the one without roulette (z < 4 on independent seeds,
/// two-sided p ~ 6e-5), and roulette ends paths earlier (fewer bounce rays).
#[test]
fn russian_roulette_is_unbiased_and_saves_rays() {
    let camera = Camera::new(Vec3::new(0.0, 0.3, 3.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap();
    let grey = Material::Lambertian {
        albedo: Vec3::splat(0.5),
    };
    let scene = scene_of(furnace_objects(), grey, vec![], Some(Vec3::ONE), camera);
    let render = |roulette_depth: u32, seed: u64| {
        let settings = RenderSettings {
            sampler: SamplerKind::Independent,
            width: 24,
            height: 16,
            spp: 256,
            strategy: Strategy::Mis,
            max_depth: 64,
            roulette_depth,
            seed,
            ..Default::default()
        };
        run(&scene, &settings)
    };
    let with = render(0, 1);
    let without = render(1000, 2);
    let ((a, sa), (b, sb)) = (with.film.image_mean(), without.film.image_mean());
    let z = (a - b) / (sa * sa + sb * sb).sqrt();
    assert!(
        z.abs() < 4.0,
        "roulette {a} +- {sa}, none {b} +- {sb}: z = {z}"
    );
    assert!(
        with.stats.rays.bounce.rays < without.stats.rays.bounce.rays * 9 / 10,
        "roulette saved too few rays: {} vs {}",
        with.stats.rays.bounce.rays,
        without.stats.rays.bounce.rays
    );
}

#[test]
fn sphere_light_over_a_plane_matches_closed_form() {
    let (rho, r, h, radiance) = (0.6, 0.5, 2.0, 10.0);
    let expected = rho * radiance * r * r / (h * h);
    let light = Light::Sphere {
        center: Vec3::new(0.0, h, 0.0),
        radius: r,
        radiance: Vec3::splat(radiance),
    };
    let wrong = direct_light_mismatches(light, expected, QuadSampling::SolidAngle);
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// The same under a square light of side 2a at height c: the view factor
/// from a point to a parallel rectangle, summed over the four quadrants
/// (Howell, "A Catalog of Radiation Heat Transfer Configuration Factors",
/// B-3): F = 4 / (2 pi) [A / sqrt(1 + A^2) atan(B / sqrt(1 + A^2)) + (A <-> B)]
/// with A = B = a / c; the radiance is rho L F.
#[test]
fn quad_light_over_a_plane_matches_closed_form() {
    let (rho, a, c, radiance) = (0.6f32, 0.4f32, 1.5f32, 10.0f32);
    let x = a / c;
    let s = (1.0 + x * x).sqrt();
    let f = 4.0 / (2.0 * PI) * 2.0 * (x / s * (x / s).atan());
    let expected = rho * radiance * f;
    let light = Light::Quad {
        corner: Vec3::new(-a, c, -a),
        edge_u: Vec3::new(2.0 * a, 0.0, 0.0),
        edge_v: Vec3::new(0.0, 0.0, 2.0 * a),
        radiance: Vec3::splat(radiance),
    };
    for mode in [QuadSampling::Area, QuadSampling::SolidAngle] {
        let wrong = direct_light_mismatches(light, expected, mode);
        assert!(wrong.is_empty(), "{wrong:#?}");
    }
}

/// Renders the point of a plane of albedo 0.6 at the origin through a very
/// narrow camera, with every strategy at max_depth 1, and lists the
/// strategies whose result disagrees with `expected`.
fn direct_light_mismatches(
    light: Light,
    expected: f32,
    quad_sampling: QuadSampling,
) -> Vec<String> {
    let mut wrong = Vec::new();
    let camera = Camera::new(Vec3::new(0.0, 1.0, 3.0), Vec3::ZERO, Vec3::Y, 0.02).unwrap();
    let plane = Sdf::plane(Vec3::Y, 0.0);
    let scene = scene_of(
        vec![plane],
        Material::Lambertian {
            albedo: Vec3::splat(0.6),
        },
        vec![light],
        None,
        camera,
    );
    // With one scattering event, `light` sees everything there is to see.
    for strategy in Strategy::ALL {
        let settings = RenderSettings {
            sampler: SamplerKind::Independent,
            width: 2,
            height: 2,
            // The image mean's standard error counts the three channels as
            // the one estimate they are (not three independent ones): at
            // 2^18 spp `uniform` still tells a 3% error from none (its
            // 4-sigma band is 2.2%).
            spp: 1 << 18,
            strategy,
            max_depth: 1,
            quad_sampling,
            ..Default::default()
        };
        let (mean, stderr) = run(&scene, &settings).film.image_mean();
        let err = (mean - expected as f64).abs();
        if err >= 4.0 * stderr + 1e-4 * expected as f64 {
            wrong.push(format!(
                "{strategy} ({quad_sampling:?}): {mean} +- {stderr}, expected {expected}"
            ));
        }
    }
    wrong
}

/// The checks above have power: an answer off by 3% is rejected by the
/// same test at the same sample count, for every strategy.
#[test]
fn a_wrong_answer_is_caught() {
    let (rho, r, h, radiance) = (0.6, 0.5, 2.0, 10.0);
    let off = 1.03 * rho * radiance * r * r / (h * h);
    let light = Light::Sphere {
        center: Vec3::new(0.0, h, 0.0),
        radius: r,
        radiance: Vec3::splat(radiance),
    };
    let wrong = direct_light_mismatches(light, off, QuadSampling::SolidAngle);
    assert_eq!(
        wrong.len(),
        Strategy::ALL.len(),
        "a 3% error went unnoticed by some strategy: {wrong:#?}"
    );
}
