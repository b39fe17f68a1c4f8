//! pmj02: every power-of-two prefix is a (0, m, 2)-net, every power-of-four
//! prefix a jittered grid, in every dimension pair of the point sets (the
//! sampler's per-pixel nets are tested in lueur-sampling).

use lueur_pointsets::{PointSetKind, generate, pmj02_u32};

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
