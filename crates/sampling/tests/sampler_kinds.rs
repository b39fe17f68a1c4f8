//! Every kind of the renderer's sampler: values in [0, 1) with 24 bits,
//! a pure function of (pixel, sample index, dimension) asked in any order,
//! stratified as each kind claims within a pixel, decorrelated between
//! dimensions and pixels, and ZSobol's pixels complementary.

use lueur_sampling::{Sampler, SamplerKind, Vec2};
use lueur_stats::chi_square_test;

use crate::common::SIGNIFICANCE;
use crate::common::assert_0m2_net;

const RESOLUTION: [u32; 2] = [64, 48];

/// The randomized kinds (all but the plain sequences).
fn randomized(kind: SamplerKind) -> bool {
    !matches!(kind, SamplerKind::Halton | SamplerKind::Sobol)
}

/// The values of one path as the integrator reads them: camera 2D at
/// dimension 0, then per vertex `d` at `2 + 8 d`: 1D, 2D, 1D, 2D, 1D.
fn path_values(sampler: &mut Sampler, pixel: [u32; 2], index: u32, depth: u32) -> Vec<f32> {
    sampler.start_pixel_sample(pixel, index, 0);
    let mut out = sampler.next_2d().to_array().to_vec();
    for d in 0..depth {
        sampler.start_pixel_sample(pixel, index, 2 + 8 * d);
        out.push(sampler.next_1d());
        out.extend(sampler.next_2d().to_array());
        out.push(sampler.next_1d());
        out.extend(sampler.next_2d().to_array());
        out.push(sampler.next_1d());
    }
    out
}

#[test]
fn values_are_in_unit_interval_with_24_bits() {
    for &kind in SamplerKind::ALL {
        let mut sampler = Sampler::for_image(kind, 5, RESOLUTION, 16);
        for pixel in 0..40u32 {
            for index in [0, 1, 15, 16, 1000, u32::MAX] {
                for x in path_values(&mut sampler, [pixel, 2 * pixel], index, 40) {
                    assert!((0.0..1.0).contains(&x), "{kind}: {x}");
                    assert_eq!((x * 16_777_216.0).fract(), 0.0, "{kind}");
                }
            }
        }
    }
}

/// pbrt-v4's sampler test: the same (pixel, sample index, dimension) gives
/// the same value whatever was asked before, from a fresh sampler, a clone
/// or a reused one, in any order.
#[test]
fn values_depend_only_on_pixel_index_and_dimension() {
    for &kind in SamplerKind::ALL {
        let make = || Sampler::for_image(kind, 77, RESOLUTION, 8);
        let mut sampler = make();
        let keys: Vec<([u32; 2], u32)> = (0..6u32)
            .flat_map(|p| (0..10u32).map(move |i| ([p * 7 % 64, p * 5 % 48], i)))
            .collect();
        let table: Vec<Vec<f32>> = keys
            .iter()
            .map(|&(pixel, index)| path_values(&mut sampler, pixel, index, 6))
            .collect();
        let mut other = make();
        for k in (0..keys.len())
            .rev()
            .step_by(3)
            .chain((0..keys.len()).step_by(2))
        {
            let (pixel, index) = keys[k];
            assert_eq!(path_values(&mut other, pixel, index, 6), table[k], "{kind}");
            let mut clone = other.clone();
            assert_eq!(path_values(&mut clone, pixel, index, 6), table[k], "{kind}");
        }
        // Starting in the middle of a vertex's dimensions reads the same
        // value as getting there by consuming the ones before.
        sampler.start_pixel_sample([3, 4], 2, 10);
        let _ = sampler.next_1d();
        let after = sampler.next_2d();
        sampler.start_pixel_sample([3, 4], 2, 11);
        assert_eq!(sampler.next_2d(), after, "{kind}");
    }
}

#[test]
fn seeds_pixels_and_indices_change_the_randomized_kinds() {
    for &kind in SamplerKind::ALL.iter().filter(|&&k| randomized(k)) {
        let values = |seed: u64, pixel: [u32; 2], index: u32| {
            let mut sampler = Sampler::for_image(kind, seed, RESOLUTION, 16);
            path_values(&mut sampler, pixel, index, 3)
        };
        let base = values(0, [10, 10], 3);
        for other in [
            values(1, [10, 10], 3),
            values(0, [11, 10], 3),
            values(0, [10, 11], 3),
        ] {
            let same = base.iter().zip(&other).filter(|(a, b)| a == b).count();
            assert!(same <= 1, "{kind}: {base:?} vs {other:?}");
        }
    }
}

/// The plain sequences are the same in every pixel (that is what makes them
/// a poor choice, and why they are only here to be measured).
#[test]
fn plain_sequences_repeat_across_pixels() {
    for kind in [SamplerKind::Halton, SamplerKind::Sobol] {
        let mut sampler = Sampler::for_image(kind, 0, RESOLUTION, 16);
        let a = path_values(&mut sampler, [1, 2], 5, 3);
        assert_eq!(a, path_values(&mut sampler, [30, 40], 5, 3), "{kind}");
        // Sample 1 of Sobol' is 1/2 in every dimension.
        if kind == SamplerKind::Sobol {
            assert!(
                path_values(&mut sampler, [0, 0], 1, 3)
                    .iter()
                    .all(|&x| x == 0.5)
            );
        }
    }
}

/// The 2D points of one pixel over its `2^m` sample indices.
fn pixel_points(
    kind: SamplerKind,
    seed: u64,
    pixel: [u32; 2],
    m: u32,
    dimension: u32,
) -> Vec<[f64; 2]> {
    let mut sampler = Sampler::for_image(kind, seed, RESOLUTION, 1 << m);
    (0..1u32 << m)
        .map(|i| {
            sampler.start_pixel_sample(pixel, i, dimension);
            let u: Vec2 = sampler.next_2d();
            [f64::from(u.x), f64::from(u.y)]
        })
        .collect()
}

#[test]
fn sobol_kinds_give_each_pixel_a_net_in_every_dimension_pair() {
    for kind in [
        SamplerKind::SobolOwen,
        SamplerKind::SobolXor,
        SamplerKind::ZSobol,
        SamplerKind::Sobol,
    ] {
        // Plain Sobol' is a (0, 2)-sequence only in its first two dimensions.
        let dims: &[u32] = if kind == SamplerKind::Sobol {
            &[0]
        } else {
            &[0, 2, 3, 6, 18]
        };
        for m in 0..=8 {
            for &pixel in &[[0, 0], [5, 3], [63, 47]] {
                for &dimension in dims {
                    let points = pixel_points(kind, 9, pixel, m, dimension);
                    assert_0m2_net(
                        &points,
                        m,
                        &format!("{kind} pixel {pixel:?} dim {dimension}"),
                    );
                }
            }
        }
    }
}

#[test]
fn stratified_kinds_stratify_each_pixel() {
    let one_per_cell = |points: &[[f64; 2]], cols: usize, rows: usize, what: &str| {
        let mut count = vec![0; cols * rows];
        for p in points {
            count[(p[1] * rows as f64) as usize * cols + (p[0] * cols as f64) as usize] += 1;
        }
        assert!(count.iter().all(|&c| c == 1), "{what}: {cols}x{rows}");
    };
    for dimension in [0, 3, 6] {
        // 16 spp: a 4x4 grid.
        let s = pixel_points(SamplerKind::Stratified, 1, [2, 3], 4, dimension);
        one_per_cell(&s, 4, 4, "stratified");
        let c = pixel_points(SamplerKind::Cmj, 1, [2, 3], 4, dimension);
        one_per_cell(&c, 4, 4, "cmj");
        one_per_cell(&c, 16, 1, "cmj columns");
        one_per_cell(&c, 1, 16, "cmj rows");
        let l = pixel_points(SamplerKind::Lhs, 1, [2, 3], 4, dimension);
        one_per_cell(&l, 16, 1, "lhs columns");
        one_per_cell(&l, 1, 16, "lhs rows");
    }
    // 1D requests: one value per 1/spp stratum.
    for kind in [
        SamplerKind::Stratified,
        SamplerKind::Lhs,
        SamplerKind::Cmj,
        SamplerKind::SobolOwen,
        SamplerKind::ZSobol,
    ] {
        let mut sampler = Sampler::for_image(kind, 4, RESOLUTION, 32);
        let mut seen = [false; 32];
        for i in 0..32 {
            sampler.start_pixel_sample([9, 9], i, 5);
            let cell = (sampler.next_1d() * 32.0) as usize;
            assert!(!seen[cell], "{kind}: stratum {cell} twice");
            seen[cell] = true;
        }
    }
}

/// ZSobol at 1 spp: the four pixels of an aligned 2x2 quad take four
/// consecutive (permuted) indices of one sequence, so their samples form a
/// (0, 2, 2)-net together: neighbours are complementary, the error is blue.
#[test]
fn zsobol_neighbours_are_complementary() {
    for dimension in [0, 2, 5] {
        for quad in [[0, 0], [2, 0], [10, 6], [62, 46]] {
            let mut sampler = Sampler::for_image(SamplerKind::ZSobol, 3, RESOLUTION, 1);
            let points: Vec<[f64; 2]> = [[0, 0], [1, 0], [0, 1], [1, 1]]
                .iter()
                .map(|d| {
                    sampler.start_pixel_sample([quad[0] + d[0], quad[1] + d[1]], 0, dimension);
                    let u = sampler.next_2d();
                    [f64::from(u.x), f64::from(u.y)]
                })
                .collect();
            assert_0m2_net(&points, 2, &format!("zsobol quad {quad:?} dim {dimension}"));
        }
    }
}

/// Across pixels each randomized kind is uniform in 1D and in 2D (sample 0
/// of many pixels: catches a poor pixel hash), and across dimension pairs a
/// pixel's coordinates do not predict each other (catches a missing
/// per-dimension scramble: without it, dims (0, 1) and (2, 3) coincide).
#[test]
fn randomized_kinds_are_uniform_across_pixels_and_decorrelated_across_dimensions() {
    let side = 16;
    for &kind in SamplerKind::ALL.iter().filter(|&&k| randomized(k)) {
        // A fixed seed; over seeds 0..12 the p-values of stratified,
        // sobol-owen and independent spread evenly over (0, 1).
        let mut sampler = Sampler::for_image(kind, 2, [256, 256], 16);
        let mut observed = vec![0.0; side * side];
        let mut joint = vec![0.0; side * side];
        let n = 40_000u32;
        for p in 0..n {
            let pixel = [p % 200, p / 200];
            let index = p % 16;
            sampler.start_pixel_sample(pixel, index, 0);
            let a = sampler.next_2d();
            observed[(a.y * side as f32) as usize * side + (a.x * side as f32) as usize] += 1.0;
            sampler.start_pixel_sample(pixel, index, 2);
            let b = sampler.next_2d();
            joint[(b.x * side as f32) as usize * side + (a.x * side as f32) as usize] += 1.0;
        }
        let expected = vec![f64::from(n) / (side * side) as f64; side * side];
        for (what, counts) in [("2D across pixels", &observed), ("dims 0 vs 2", &joint)] {
            let test = chi_square_test(counts, &expected);
            // Bonferroni: the family of all kinds' tests rejects a correct
            // sampler with probability SIGNIFICANCE.
            let tests = 2.0 * SamplerKind::ALL.len() as f64;
            assert!(
                test.accepts(SIGNIFICANCE / tests),
                "{kind} {what}: not uniform: {test:?}"
            );
        }
    }
}

/// Within a pixel, each request's points are paired with another request's
/// at random, for every kind that pads its dimensions (all but the
/// sequences, whose dimensions are one point's coordinates): catches
/// requests that read their points in the same order, which moves a pixel's
/// dimension pairs together. Such a sampler is uniform across pixels and
/// stratified in each request, and passes the tests above, yet pmj02 and r2
/// read that way had 1.9x and 1.7x the MSE of `cmj` at 256 spp on
/// cornell-spheres.
///
/// Per pixel, `rho` is the Spearman correlation between the values of two
/// requests (1D, or a 2D request's x) over the pixel's `n` samples. For a
/// uniformly random pairing `(n - 1) rho^2` has mean 1 (about chi-square
/// with one degree of freedom). The kinds that keep every power-of-two prefix a net cannot
/// pair that freely: their index permutations are nested (or, for pmj02,
/// kept within each power-of-two level), coarser than a uniform
/// permutation, and give means of 1.1 to 1.6 here (a uniform
/// permutation of sobol-xor's index gave the same MSE, 3.29e-3 against
/// 3.09e-3 at 64 spp, 6.76e-4 against 6.53e-4 at 256). Reading in order
/// gave 3.8 to 5.5. So the test bounds the mean at 2: over 2000 pixels its
/// standard error is about 0.05 (0.032 for a uniform pairing), which puts 2
/// more than 7 standard errors above the sound kinds and 30 below the
/// broken ones. Fixed seed.
#[test]
fn a_pixel_s_requests_are_paired_at_random() {
    let (n, pixels) = (16u32, 2000u32);
    let ranks = |values: &[f32]| -> Vec<f64> {
        let mut order: Vec<usize> = (0..values.len()).collect();
        order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
        let mut rank = vec![0.0; values.len()];
        for (r, &i) in order.iter().enumerate() {
            rank[i] = r as f64;
        }
        rank
    };
    let padded = |k: &&SamplerKind| randomized(**k) && **k != SamplerKind::HaltonOwen;
    // Requests of the path's layout (`path_values`): the camera's 2D at 0, a
    // vertex's 1D at 2, its 2D at 3 and its next 1D at 5, the next vertex's
    // 2D at 11. A 2D request gives its x.
    let pairs = [(0, 3), (3, 11), (2, 3), (2, 5)];
    let value = |sampler: &mut Sampler, dimension: u32| match dimension {
        2 | 5 => sampler.next_1d(),
        _ => sampler.next_2d().x,
    };
    for &kind in SamplerKind::ALL.iter().filter(padded) {
        let mut sampler = Sampler::for_image(kind, 5, [256, 256], n);
        for (a, b) in pairs {
            let mut sum = 0.0;
            for p in 0..pixels {
                let pixel = [p % 256, p / 256];
                let (mut xa, mut xb) = (Vec::new(), Vec::new());
                for index in 0..n {
                    sampler.start_pixel_sample(pixel, index, a);
                    xa.push(value(&mut sampler, a));
                    sampler.start_pixel_sample(pixel, index, b);
                    xb.push(value(&mut sampler, b));
                }
                let (ra, rb) = (ranks(&xa), ranks(&xb));
                let d2: f64 = ra.iter().zip(&rb).map(|(x, y)| (x - y).powi(2)).sum();
                let nf = f64::from(n);
                let rho = 1.0 - 6.0 * d2 / (nf * (nf * nf - 1.0));
                sum += (nf - 1.0) * rho * rho;
            }
            let mean = sum / f64::from(pixels);
            assert!(
                mean < 2.0,
                "{kind}: requests {a} and {b} of a pixel move together: \
                 mean (n - 1) rho^2 {mean:.2} over {pixels} pixels (1 for a random pairing)"
            );
        }
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

/// The renderer's kinds are the registry's (`lueur-pointsets`), in its
/// order, with its names: every construction the sampler can draw from one
/// sample at a time, which is every one but Poisson-disk sets. `listed` is
/// an exhaustive match (no `_` arm), so a new sampler kind does not compile
/// until it is checked against the list here.
#[test]
fn sampler_kinds_are_the_registrys() {
    use lueur_pointsets::PointSetKind;
    let expected: Vec<SamplerKind> = PointSetKind::ALL
        .iter()
        .filter(|&&k| k != PointSetKind::PoissonDisk)
        .map(|&k| SamplerKind::from_point_set(k).expect("a renderer kind"))
        .collect();
    assert_eq!(SamplerKind::ALL, expected.as_slice());
    assert_eq!(SamplerKind::from_point_set(PointSetKind::PoissonDisk), None);
    fn listed(kind: SamplerKind) -> bool {
        match kind {
            SamplerKind::Independent
            | SamplerKind::Stratified
            | SamplerKind::Lhs
            | SamplerKind::Cmj
            | SamplerKind::Halton
            | SamplerKind::HaltonOwen
            | SamplerKind::Sobol
            | SamplerKind::SobolXor
            | SamplerKind::SobolOwen
            | SamplerKind::ZSobol
            | SamplerKind::R2
            | SamplerKind::Pmj02 => SamplerKind::ALL.contains(&kind),
        }
    }
    for &kind in SamplerKind::ALL {
        assert!(listed(kind));
        assert_eq!(SamplerKind::from_point_set(kind.point_set()), Some(kind));
        assert_eq!(kind.name(), kind.point_set().name());
        assert_eq!(SamplerKind::from_name(kind.name()), Some(kind));
    }
    assert_eq!(SamplerKind::ALL.len(), 12);
    assert_eq!(SamplerKind::from_name("poisson-disk"), None);
}
