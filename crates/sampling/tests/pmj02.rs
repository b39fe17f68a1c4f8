//! pmj02: every power-of-two prefix is a (0, m, 2)-net, every power-of-four
//! prefix a jittered grid, for the point sets and per pixel in the sampler.

use lueur_sampling::pointsets::{PointSetKind, generate, pmj02_u32};
use lueur_sampling::{Sampler, SamplerKind};

use crate::pointsets::assert_0m2_net;

fn unit(p: [u32; 2]) -> [f64; 2] {
    [
        f64::from(p[0]) / 4_294_967_296.0,
        f64::from(p[1]) / 4_294_967_296.0,
    ]
}

#[test]
fn every_power_of_two_prefix_is_a_net() {
    for seed in 0..16 {
        let points: Vec<[f64; 2]> = pmj02_u32(1 << 10, seed).into_iter().map(unit).collect();
        for m in 0..=10 {
            assert_0m2_net(&points[..1 << m], m, &format!("pmj02 seed {seed}"));
        }
    }
}

/// Progressive jittering: the first 4^k points hold one point per cell of
/// the 2^k x 2^k grid.
#[test]
fn power_of_four_prefixes_are_jittered() {
    for seed in 0..16 {
        let points = pmj02_u32(1 << 10, seed);
        for k in 0..=5u32 {
            let side = 1usize << k;
            let mut count = vec![0; side * side];
            for &p in &points[..side * side] {
                let [x, y] = unit(p);
                count[(y * side as f64) as usize * side + (x * side as f64) as usize] += 1;
            }
            assert!(count.iter().all(|&c| c == 1), "seed {seed}: {side}x{side}");
        }
    }
}

/// The point-set kind: its first pair is the sequence itself; every pair is
/// a net of its own (the later ones shuffled, which keeps the set a net).
#[test]
fn point_set_pairs_are_nets() {
    let points = generate(PointSetKind::Pmj02, 256, 5, 3).unwrap();
    for (a, b) in [(0, 1), (2, 3)] {
        let pair: Vec<[f64; 2]> = points.points().map(|p| [p[a], p[b]]).collect();
        assert_0m2_net(&pair, 8, &format!("pmj02 dims ({a}, {b})"));
    }
    // The odd last dimension: one point per 1/256 stratum.
    let mut seen = vec![false; 256];
    for p in points.points() {
        let cell = (p[4] * 256.0) as usize;
        assert!(!seen[cell], "stratum {cell} twice");
        seen[cell] = true;
    }
}

/// In the renderer, each pixel's samples form a net in every dimension
/// pair, for every power-of-two spp up to 2^10.
#[test]
fn sampler_gives_each_pixel_a_net() {
    for m in 0..=10u32 {
        for pixel in [[0, 0], [5, 3], [63, 47]] {
            for dimension in [0, 2, 7] {
                let mut sampler = Sampler::for_image(SamplerKind::Pmj02, 9, [64, 48], 1 << m);
                let points: Vec<[f64; 2]> = (0..1u32 << m)
                    .map(|i| {
                        sampler.start_pixel_sample(pixel, i, dimension);
                        let u = sampler.next_2d();
                        [f64::from(u.x), f64::from(u.y)]
                    })
                    .collect();
                assert_0m2_net(
                    &points,
                    m,
                    &format!("pmj02 pixel {pixel:?} dim {dimension}"),
                );
            }
        }
    }
}
