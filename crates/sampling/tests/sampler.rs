use lueur_sampling::{Sampler, SamplerKind, Vec2};
use lueur_stats::chi_square_test;

use crate::common::assert_fits;

fn value(sampler: &mut Sampler, pixel: [u32; 2], index: u32, dimension: u32) -> f32 {
    sampler.start_pixel_sample(pixel, index, dimension);
    sampler.next_1d()
}

/// Every (pixel, sample index, dimension) asked in a scrambled order, by a
/// fresh sampler and by a clone, gives what sequential consumption gave.
#[test]
fn values_depend_only_on_pixel_index_dimension_and_seed() {
    let mut sampler = Sampler::new(SamplerKind::Independent, 1234);
    let pixels = [[0, 0], [1, 0], [0, 1], [640, 480], [u32::MAX, u32::MAX]];
    let mut table = Vec::new();
    for &pixel in &pixels {
        for index in [0, 1, 7, 1023, u32::MAX] {
            sampler.start_pixel_sample(pixel, index, 0);
            for dimension in 0..24 {
                table.push((pixel, index, dimension, sampler.next_1d()));
            }
        }
    }
    let mut other = Sampler::new(SamplerKind::Independent, 1234);
    // A fixed permutation: stride coprime with the table length.
    let n = table.len();
    let stride = (1..n)
        .rev()
        .find(|s| gcd(*s, n) == 1 && *s < n / 2)
        .unwrap();
    for k in 0..n {
        let (pixel, index, dimension, expected) = table[(k * stride) % n];
        assert_eq!(value(&mut other, pixel, index, dimension), expected);
        let mut clone = other.clone();
        assert_eq!(value(&mut clone, pixel, index, dimension), expected);
    }
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// The same per-pixel sums whatever the number of threads and the order in
/// which they take pixels.
#[test]
fn bit_identical_for_any_thread_count() {
    let (width, height, spp) = (16u32, 12u32, 8u32);
    let render = |threads: u32| -> Vec<u32> {
        let mut image = vec![0u32; (width * height) as usize];
        std::thread::scope(|scope| {
            let handles: Vec<_> = (0..threads)
                .map(|t| {
                    scope.spawn(move || {
                        let mut sampler = Sampler::new(SamplerKind::Independent, 99);
                        let mut out = Vec::new();
                        // Each thread walks its pixels backwards.
                        for i in (0..width * height).rev().filter(|i| i % threads == t) {
                            let mut bits = 0u32;
                            for s in 0..spp {
                                sampler.start_pixel_sample([i % width, i / width], s, 0);
                                for _ in 0..5 {
                                    bits = bits.wrapping_add(sampler.next_2d().x.to_bits());
                                }
                            }
                            out.push((i, bits));
                        }
                        out
                    })
                })
                .collect();
            for handle in handles {
                for (i, bits) in handle.join().unwrap() {
                    image[i as usize] = bits;
                }
            }
        });
        image
    };
    let one = render(1);
    assert_eq!(one, render(3));
    assert_eq!(one, render(8));
}

#[test]
fn values_are_in_unit_interval_with_24_bits() {
    let mut sampler = Sampler::new(SamplerKind::Independent, 0);
    for pixel in 0..64 {
        sampler.start_pixel_sample([pixel, 3 * pixel], pixel, 0);
        for _ in 0..1000 {
            let x = sampler.next_1d();
            assert!((0.0..1.0).contains(&x));
            assert_eq!((x * 16_777_216.0).fract(), 0.0);
        }
    }
}

#[test]
fn pixels_seeds_and_indices_give_different_streams() {
    let stream = |seed: u64, pixel: [u32; 2], index: u32| -> Vec<f32> {
        let mut sampler = Sampler::new(SamplerKind::Independent, seed);
        sampler.start_pixel_sample(pixel, index, 0);
        (0..8).map(|_| sampler.next_1d()).collect()
    };
    let base = stream(0, [0, 0], 0);
    for other in [
        stream(1, [0, 0], 0),
        stream(0, [1, 0], 0),
        stream(0, [0, 1], 0),
        stream(0, [0, 0], 1),
        stream(u64::MAX, [0, 0], 0),
    ] {
        let equal = base.iter().zip(&other).filter(|(a, b)| a == b).count();
        assert!(equal == 0, "{base:?} vs {other:?}");
    }
}

/// 1D across pixels (dimension 0 of many pixels: catches a poor pixel hash)
/// and 2D within a pixel (consecutive dimensions: catches correlation).
#[test]
fn uniformity() {
    let mut sampler = Sampler::new(SamplerKind::Independent, 7);
    let bins = 100;
    let mut observed = vec![0.0; bins];
    let n = 200_000;
    for i in 0..n {
        sampler.start_pixel_sample([i % 512, i / 512], 0, 0);
        observed[(sampler.next_1d() * bins as f32) as usize] += 1.0;
    }
    let expected = vec![n as f64 / bins as f64; bins];
    assert_fits(
        "sampler 1D across pixels",
        chi_square_test(&observed, &expected),
    );

    let side = 32;
    let mut observed = vec![0.0; side * side];
    sampler.start_pixel_sample([5, 9], 0, 0);
    let n = 400_000;
    for _ in 0..n {
        let u: Vec2 = sampler.next_2d() * side as f32;
        observed[u.y as usize * side + u.x as usize] += 1.0;
    }
    let expected = vec![n as f64 / (side * side) as f64; side * side];
    assert_fits("sampler 2D", chi_square_test(&observed, &expected));
}

/// The stability promise: these numbers must never change. If this test
/// fails, every image rendered with a seed changes; that needs a new
/// `SamplerKind`, not an edit here.
#[test]
fn golden_values() {
    let mut sampler = Sampler::new(SamplerKind::Independent, 0);
    let mut got = Vec::new();
    for (pixel, index, dimension) in [
        ([0, 0], 0, 0),
        ([0, 0], 0, 1),
        ([3, 5], 2, 7),
        ([1919, 1079], 4095, 3),
    ] {
        sampler.start_pixel_sample(pixel, index, dimension);
        got.push(sampler.next_1d().to_bits());
    }
    let mut seeded = Sampler::new(SamplerKind::Independent, 0xdead_beef);
    seeded.start_pixel_sample([10, 20], 30, 40);
    got.push(seeded.next_1d().to_bits());
    assert_eq!(got, GOLDEN, "{got:#x?}");
}

const GOLDEN: [u32; 5] = [
    0x3f21_f271,
    0x3dd4_3838,
    0x3eae_a7da,
    0x3f28_4a02,
    0x3f1b_11cf,
];

/// The stability promise for every kind, not only the independent one: a digest (FNV-1a
/// over the bits) of 1D and 2D values at scattered pixels, sample indices and dimensions,
/// with one and with three replicates. A faster way to compute a kind's values must
/// leave its digest as it is.
#[test]
fn golden_digests_of_every_kind() {
    let digest = |kind: SamplerKind, replicates: u32| {
        let mut sampler = Sampler::for_render(kind, 0xdead_beef, [640, 480], 64, replicates);
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        let mut eat = |x: f32| {
            h ^= u64::from(x.to_bits());
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        };
        for pixel in [[0, 0], [1, 0], [3, 5], [639, 479], [200, 17]] {
            for index in [0, 1, 2, 5, 31, 63] {
                for dimension in [0, 1, 2, 5, 9, 17, 40, 255] {
                    sampler.start_pixel_sample(pixel, index, dimension);
                    eat(sampler.next_1d());
                    let u = sampler.next_2d();
                    eat(u.x);
                    eat(u.y);
                    eat(sampler.next_1d());
                }
            }
        }
        h
    };
    let got: Vec<(String, u64, u64)> = SamplerKind::ALL
        .iter()
        .map(|&kind| (kind.to_string(), digest(kind, 1), digest(kind, 3)))
        .collect();
    let expected: Vec<(String, u64, u64)> = GOLDEN_DIGESTS
        .iter()
        .map(|&(name, one, three)| (name.to_string(), one, three))
        .collect();
    assert_eq!(got, expected, "{got:#x?}");
}

/// Every kind's digests, which must never change (see [`golden_values`]) unless a fix
/// raises the kind's [`SamplerKind::revision`], which keeps checkpoints of the old values
/// from being resumed or merged with the new.
const GOLDEN_DIGESTS: [(&str, u64, u64); 12] = [
    ("independent", 0xc2c8c1318fa10877, 0xc2c8c1318fa10877),
    ("stratified", 0x2228afd41c734394, 0xaec88ad0db0eb7f6),
    ("lhs", 0x18da8cb5331117af, 0xd9f57a43bdfecc7f),
    ("cmj", 0xc5cd2a5bda32e629, 0x840b24c9b0b24879),
    ("halton", 0x2f20f2259f9d7d4b, 0x2c642bca41d288a0),
    ("halton-owen", 0xde96a9965f1a8b55, 0xf5024ac94b211cba),
    ("sobol", 0xd4d44cbf31ba8e25, 0x54f0121deed28e25),
    ("sobol-xor", 0xc5fa021503b440b2, 0x08e124f07e0ee129),
    ("sobol-owen", 0x309ff53b71c59f8e, 0xa6a771adf68d4ef2),
    ("zsobol", 0xec1bd70437ca6c1e, 0x118eddba9e24fee2),
    ("r2", 0x27cbe64668771354, 0x09bdde19fbd872ca),
    ("pmj02", 0x74cb40001373f545, 0xf431af034939d2f9),
];
