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
use lueur::scene::{Marching, RenderSettings, Strategy};

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
