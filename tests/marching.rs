//! The fast marching (rays clipped against the objects' bounds,
//! over-relaxed, tetrahedron normals) against the naive reference (plain
//! Hart tracing, central differences): different code, the same images in
//! distribution.
//!
//! This test has little power against a bias confined to a few bright
//! pixels: a 10% change of the light's reflection in the donut's mirrors
//! (+1% on the image mean, z = 9 at 64x64 and 1024 spp) passed it. That
//! mechanism (the shading point depending on where in the hit shell the
//! tracer stopped) has its own deterministic test in `lueur-integrator`
//! (`shading_point_is_on_the_ray_wherever_the_tracer_stopped`).
//!
//! Each image is cut into 4x4 regions and every region's mean (per channel)
//! is compared by a z-test on the two renders' combined standard error, with
//! independent seeds. |z| < 4.5 over 48 comparisons per scene: a false alarm
//! has probability ~3e-4 per scene for normal means; a surface skipped or
//! shaded wrong over a region of a few pixels moves its mean by far more.

use lueur::integrator::Film;
use lueur::sampling::SamplerKind;
use lueur::scene::{Marching, RenderSettings, Strategy, parse_scene};

use crate::common::{SHIPPED, run, shipped};

const SIZE: u32 = 32;
const REGIONS: u32 = 4;

fn render(name: &str, marching: Marching, seed: u64) -> Film {
    let file = shipped(name);
    let settings = RenderSettings {
        sampler: SamplerKind::Independent,
        width: SIZE,
        height: SIZE,
        spp: 256,
        strategy: Strategy::Mis,
        seed,
        marching,
        ..file.settings.clone()
    };
    run(&file.scene, &settings).film
}

/// Per region and channel: mean of the pixel means, and its variance.
fn regions(film: &Film) -> Vec<(f64, f64)> {
    let side = SIZE / REGIONS;
    let mut out = Vec::new();
    for ry in 0..REGIONS {
        for rx in 0..REGIONS {
            for c in 0..3 {
                let (mut mean, mut var) = (0.0, 0.0);
                for y in ry * side..(ry + 1) * side {
                    for x in rx * side..(rx + 1) * side {
                        let p = film.pixel(x, y);
                        mean += f64::from(p.mean[c]);
                        var += f64::from(p.variance_of_mean()[c]);
                    }
                }
                let n = f64::from(side * side);
                out.push((mean / n, var / (n * n)));
            }
        }
    }
    out
}

#[test]
fn naive_and_fast_marching_agree_within_standard_error() {
    for name in SHIPPED {
        let fast = regions(&render(name, Marching::Fast, 1));
        let naive = regions(&render(name, Marching::Naive, 2));
        for (i, (f, n)) in fast.iter().zip(&naive).enumerate() {
            let se = (f.1 + n.1).sqrt();
            let z = (f.0 - n.0) / se.max(1e-12);
            assert!(
                z.abs() < 4.5,
                "{name}, region {} channel {}: fast {:.5} vs naive {:.5} (z = {z:.2})",
                i / 3,
                i % 3,
                f.0,
                n.0
            );
        }
    }
}

/// An open floor under a sky and a light at infinity, seen from above: every ray leaving
/// the floor escapes to the sky, so each pixel is `albedo (E cos / pi + L_sky)` exactly,
/// and with `mis` every sample gives it (in f32, within 1e-7 of it).
const OPEN_FLOOR: &str = r#"
[image]
width = 32
height = 32
[render]
spp = 64
strategy = "mis"
sampler = "independent"
max_depth = 4
[camera]
position = [0.0, 1.0, 0.0]
look_at = [0.0, 0.0, -1.0]
vfov = 60.0
[materials]
floor = { type = "lambertian", albedo = [0.5, 0.5, 0.5] }
[[objects]]
material = "floor"
shape = { type = "plane", normal = [0.0, 1.0, 0.0], height = 0.0 }
[[lights]]
type = "directional"
direction = [0.5, -0.8, -0.35]
irradiance = [1.0, 1.0, 1.0]
[sky]
radiance = [0.2, 0.2, 0.2]
"#;

/// Rays leaving a plane at a shallow angle crawl away from it (sphere tracing grows `t`
/// by `1 + sin(angle)` a step); one that reaches the step cap is taken as a hit where it
/// stopped, in the air, and misses the sky. With 256 steps naive marching gives up on
/// about 0.3% of the bounce rays here, and the image mean came out 0.068% too dark. At
/// the default settings naive marching must leave the mean within 2e-5 of its closed form
/// (it takes 16 times `max_steps`); fast marching, which clips these rays away from the
/// plane's bound, every pixel within 1e-5.
#[test]
fn rays_leaving_an_open_floor_see_the_sky() {
    let file = parse_scene(OPEN_FLOOR, "open-floor.toml").unwrap();
    let cosine = 0.8 / (0.5f64 * 0.5 + 0.8 * 0.8 + 0.35 * 0.35).sqrt();
    let expected = 0.5 * (cosine / std::f64::consts::PI + 0.2);
    let naive = RenderSettings {
        marching: Marching::Naive,
        ..file.settings.clone()
    };
    let capped = RenderSettings {
        max_steps: naive.max_steps / 16,
        ..naive.clone()
    };
    let rays = run(&file.scene, &capped).stats.rays;
    assert!(
        rays.bounce.gave_up > 100,
        "the scene no longer makes naive rays crawl to 256 steps ({} did)",
        rays.bounce.gave_up
    );
    let out = run(&file.scene, &naive);
    let (mean, _) = out.film.image_mean();
    let error = mean / expected - 1.0;
    assert!(
        error.abs() < 2e-5,
        "naive: image mean {mean:.7} against {expected:.7} ({error:+.2e}; {} bounce rays \
         gave up)",
        out.stats.rays.bounce.gave_up
    );
    let fast = run(&file.scene, &file.settings).film;
    for y in 0..32 {
        for x in 0..32 {
            let got = f64::from(fast.pixel(x, y).mean[0]);
            assert!(
                (got / expected - 1.0).abs() < 1e-5,
                "fast: pixel ({x}, {y}) {got:.7} against its closed form {expected:.7}"
            );
        }
    }
}
