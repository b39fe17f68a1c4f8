//! The film's merges and tilings.

use super::*;
use crate::replicates::BlockCounter;

#[test]
fn welford_matches_two_pass() {
    let xs = [1.0f32, 4.0, 2.5, 10.0, -3.0, 0.25];
    let mut s = PixelStats::default();
    for &x in &xs {
        s.add(Vec3::splat(x));
    }
    let mean = xs.iter().sum::<f32>() / xs.len() as f32;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / (xs.len() - 1) as f32;
    assert!((s.mean.x - mean).abs() < 1e-5);
    assert!((s.sample_variance().x - var).abs() < 1e-4);
    assert!((s.variance_of_mean().y - var / xs.len() as f32).abs() < 1e-4);
}

#[test]
fn pairwise_merge_matches_two_pass() {
    let xs: Vec<f32> = (0..37)
        .map(|i| ((i * 7919) % 101) as f32 * 0.37 - 9.0)
        .collect();
    let mut counter = BlockCounter::new(1);
    for (i, &x) in xs.iter().enumerate() {
        counter.push(i as u32, PixelStats::of_sample(Vec3::splat(x)));
    }
    let ranges: Vec<_> = counter.blocks().map(|b| b.0.clone()).collect();
    assert_eq!(ranges, dyadic_blocks(0..37));
    let s = counter
        .blocks()
        .fold(PixelStats::default(), |a, b| a.merged(b.1[0]));
    let mean = xs.iter().map(|&x| f64::from(x)).sum::<f64>() / xs.len() as f64;
    let var = xs
        .iter()
        .map(|&x| (f64::from(x) - mean).powi(2))
        .sum::<f64>()
        / (xs.len() - 1) as f64;
    assert_eq!(s.n, 37);
    assert!((f64::from(s.mean.x) - mean).abs() < 1e-5 * mean.abs().max(1.0));
    assert!((f64::from(s.sample_variance().x) - var).abs() < 1e-5 * var);
}

#[test]
fn dropped_samples_do_not_count() {
    let mut s = PixelStats::of_sample(Vec3::new(f32::NAN, 0.0, 0.0));
    assert_eq!(s.n, 0);
    s = s.merged(PixelStats::of_sample(Vec3::ONE));
    s = s.merged(PixelStats::of_sample(Vec3::splat(f32::INFINITY)));
    assert_eq!((s.n, s.mean), (1, Vec3::ONE));
}

#[test]
fn one_sample_has_no_variance() {
    let mut s = PixelStats::default();
    s.add(Vec3::ONE);
    assert_eq!(s.variance_of_mean(), Vec3::ZERO);
}

#[test]
fn dyadic_blocks_tile_any_range() {
    assert_eq!(dyadic_blocks(0..100), vec![0..64, 64..96, 96..100]);
    assert_eq!(dyadic_blocks(64..128), vec![64..128]);
    assert_eq!(dyadic_blocks(3..13), vec![3..4, 4..8, 8..12, 12..13]);
    assert_eq!(dyadic_blocks(0..u32::MAX).len(), 32);
    assert!(dyadic_blocks(5..5).is_empty());
    for a in 0..70u32 {
        for b in a..70 {
            let blocks = dyadic_blocks(a..b);
            let mut at = a;
            for r in &blocks {
                assert!(is_dyadic(r), "{r:?}");
                assert_eq!(r.start, at);
                at = r.end;
            }
            assert_eq!(at, b);
            // Maximal: no two neighbours are the halves of one block.
            assert!(blocks.windows(2).all(|w| !siblings(&w[0], &w[1])));
        }
    }
}

/// A film of one pixel over `samples`, as a checkpoint of it reads back.
fn film_of(samples: Range<u32>, value: impl Fn(u32) -> f32) -> Film {
    let mut film = Film::starting_at(1, 1, samples.start);
    for r in dyadic_blocks(samples) {
        let mut counter = BlockCounter::new(1);
        for i in r.clone() {
            counter.push(i, PixelStats::of_sample(Vec3::splat(value(i))));
        }
        for (range, stats) in counter.blocks() {
            film = film
                .append_decoded(range.clone(), 1, |fill| put_all(fill, stats))
                .unwrap();
        }
    }
    film
}

fn put_all(fill: &mut SlotFill<'_>, stats: &[PixelStats]) -> Result<(), FilmError> {
    stats
        .iter()
        .enumerate()
        .try_for_each(|(i, s)| fill.put(i, *s))
}

#[test]
fn any_cut_gives_the_same_bits() {
    let value = |i: u32| (i as f32 * 0.618_034).fract() * 10.0 + 1e3;
    let whole = film_of(0..100, value);
    assert_eq!(whole.blocks().unwrap().count(), 3);
    for cut in [1, 37, 64, 65, 99] {
        let parts = vec![film_of(cut..100, value), film_of(0..cut, value)];
        let merged = Film::merge(parts).unwrap();
        assert_eq!(merged, whole, "cut at {cut}");
    }
    let three = Film::merge(vec![
        film_of(0..10, value),
        film_of(10..50, value),
        film_of(50..100, value),
    ])
    .unwrap();
    assert_eq!(three, whole);
}

#[test]
fn merge_refuses_gaps_and_overlaps() {
    let v = |_| 1.0;
    let gap = Film::merge(vec![film_of(0..8, v), film_of(9..16, v)]);
    assert!(matches!(gap, Err(FilmError::NotContiguous(..))));
    let overlap = Film::merge(vec![film_of(0..8, v), film_of(4..16, v)]);
    assert!(matches!(overlap, Err(FilmError::NotContiguous(..))));
    assert_eq!(Film::merge(vec![]), Err(FilmError::Empty));
    let other_size = Film::starting_at(2, 1, 8);
    assert!(matches!(
        Film::merge(vec![film_of(0..8, v), other_size]),
        Err(FilmError::SizeMismatch(..))
    ));
}

/// A film of two pixels and `k` replicates over `samples`, decoded one
/// saved block of `step` samples at a time (each block as a render of it
/// would save it).
fn film_in_steps(samples: Range<u32>, k: u32, step: u32, value: impl Fn(u32) -> f32) -> Film {
    let mut film = Film::starting_at(2, 1, samples.start);
    let mut at = samples.start;
    while at < samples.end {
        let part = at..(at + step).min(samples.end);
        for r in dyadic_blocks(part.clone()) {
            let mut counters = [BlockCounter::new(k), BlockCounter::new(k)];
            for (p, counter) in counters.iter_mut().enumerate() {
                for i in r.clone() {
                    let x = value(i) + p as f32;
                    counter.push(i, PixelStats::of_sample(Vec3::new(x, -x, x * x)));
                }
            }
            let slots: Vec<PixelStats> = counters
                .iter()
                .flat_map(|c| c.blocks().next().expect("one block").1.to_vec())
                .collect();
            film = film
                .append_decoded(r, k, |fill| put_all(fill, &slots))
                .unwrap();
        }
        at = part.end;
    }
    film
}

#[test]
fn decoding_block_by_block_merges_in_place_to_the_same_bits() {
    let value = |i: u32| (i as f32 * 0.618_034).fract() * 10.0 + 1e3;
    for k in [1, 2, 3] {
        let whole = film_in_steps(0..100, k, 100, value);
        // Blocks of one sample: every odd one is merged into the block
        // before it as it is decoded, then carried.
        for step in [1, 3, 7, 64] {
            assert_eq!(
                film_in_steps(0..100, k, step, value),
                whole,
                "k {k}, step {step}"
            );
        }
        let keeps_m2 = whole.blocks().unwrap().all(|(_, b)| b.keeps_m2());
        assert_eq!(keeps_m2, k == 1, "only one replicate keeps its spread");
        // The error of the mean comes from the replicates, not from m2.
        assert!(whole.pixels().all(|p| p.variance_of_mean().x > 0.0));
    }
}

#[test]
fn a_saved_block_must_put_every_slot_once() {
    let one = PixelStats::of_sample(Vec3::ONE);
    let twice = Film::starting_at(1, 1, 0).append_decoded(0..1, 2, |fill| {
        fill.put(0, one)?;
        fill.put(0, one)
    });
    assert!(matches!(twice, Err(FilmError::InvalidStats(_))));
    let missing = Film::starting_at(1, 1, 0).append_decoded(0..1, 2, |fill| fill.put(1, one));
    assert!(matches!(missing, Err(FilmError::Incomplete(_))));
    let outside = Film::starting_at(1, 1, 0).append_decoded(0..1, 2, |fill| fill.put(2, one));
    assert!(matches!(outside, Err(FilmError::InvalidStats(_))));
    let too_many = PixelStats { n: 2, ..one };
    let bad = Film::starting_at(1, 1, 0).append_decoded(0..1, 1, |fill| fill.put(0, too_many));
    assert!(matches!(bad, Err(FilmError::InvalidStats(_))));
    let other_k = film_in_steps(0..4, 2, 4, |_| 1.0).append_decoded(4..8, 3, |_| Ok(()));
    assert!(matches!(other_k, Err(FilmError::Replicates(2, 3))));
}
