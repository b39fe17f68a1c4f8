//! Replicates: the error bars of randomized quasi-Monte Carlo.
//!
//! The spread of a pixel's samples says how noisy its mean is only when
//! the samples are independent. A QMC point set is not: its points are
//! spread on purpose, the error of their mean is smaller than `s^2 / n`,
//! and the per-sample variance overstates it (3x on the Cornell box with
//! `sobol-xor` at 64 spp). The remedy is the one of randomized QMC (Owen
//! 1997; L'Ecuyer and Lemieux 2002): deal the samples into `K`
//! *replicates*, each an independent randomization of the point set, so
//! that the `K` replicate means are independent estimates of the pixel,
//! and the variance of their average is estimated from their spread,
//! without bias for every randomized sampler.
//!
//! The sample indices are interleaved: sample `i` is point `i / K` of
//! replicate `i % K` (see `Sampler::for_render`). So every prefix of a
//! render, and every pass of 1, 1, 2, 4, ... spp, holds as many points of
//! each replicate as it can, the replicates of a sequence stay sequences,
//! and the mapping does not depend on the total spp (a render with a
//! sequence sampler can still be resumed to more samples). The film keeps,
//! per pixel and per dyadic block, one slot per replicate: the count and
//! mean of the block's samples of that replicate (their spread is not
//! needed, see `film/image.rs`), merged slot by slot, so that every cut into passes, shards and resumes gives the same
//! bits, as with one replicate.
//!
//! When the spp is not a multiple of `K`, the first `spp % K` replicates
//! hold one point more; their means are weighted by their counts, and the
//! estimate is exact only for equal counts (off by a share of order
//! `1 / n_r` otherwise).

use std::ops::Range;

use glam::Vec3;

use crate::film::{PixelStats, siblings};

/// A pixel's estimate over all its samples: the mean and the error of the
/// mean, from its replicates' statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelEstimate {
    /// Number of finite samples.
    pub n: u32,
    /// Mean of the samples.
    pub mean: Vec3,
    sample_variance: Vec3,
    variance_of_mean: Vec3,
    /// Variance of the mean of the channel average `(R + G + B) / 3`.
    variance_of_average: f32,
}

impl PixelEstimate {
    /// The estimate from one [`PixelStats`] per replicate, in replicate
    /// order. With one replicate, the variance of the mean is the
    /// per-sample variance over `n` (valid for independent samples); with
    /// more, the spread of the replicate means, `sum w_r^2 (mu_r - mu)^2 *
    /// K / (K - 1)` with weights `w_r = n_r / n` (for equal counts the
    /// unbiased `sum (mu_r - mu)^2 / (K (K - 1))`), over the replicates
    /// that hold samples; zero while fewer than two do.
    pub fn of_replicates(replicates: &[PixelStats]) -> PixelEstimate {
        let total = replicates
            .iter()
            .fold(PixelStats::default(), |acc, r| acc.merged(*r));
        let (variance_of_mean, variance_of_average) = match replicates {
            [one] => {
                // The channels of one path are correlated and their
                // covariance is not kept: Cauchy-Schwarz bounds the
                // average's standard error by the channels' mean one (exact
                // when they are proportional, as under white light).
                let v = one.variance_of_mean();
                let sd = (v.x.sqrt() + v.y.sqrt() + v.z.sqrt()) / 3.0;
                (v, sd * sd)
            }
            _ => {
                let filled = replicates.iter().filter(|r| r.n > 0).count();
                if filled < 2 {
                    (Vec3::ZERO, 0.0)
                } else {
                    let n = total.n as f32;
                    let spread: Vec3 = replicates
                        .iter()
                        .filter(|r| r.n > 0)
                        .map(|r| {
                            let d = (r.mean - total.mean) * (r.n as f32 / n);
                            d * d
                        })
                        .sum();
                    let average: f32 = replicates
                        .iter()
                        .filter(|r| r.n > 0)
                        .map(|r| {
                            let d = (r.mean - total.mean).element_sum() / 3.0 * (r.n as f32 / n);
                            d * d
                        })
                        .sum();
                    let dof = filled as f32 / (filled - 1) as f32;
                    (spread * dof, average * dof)
                }
            }
        };
        // With several replicates the film keeps no per-sample spread
        // (see `film/image.rs`): what one sample is worth is then the one
        // the error of the mean shows.
        let sample_variance = match replicates {
            [one] => one.sample_variance(),
            _ => variance_of_mean * total.n as f32,
        };
        PixelEstimate {
            n: total.n,
            mean: total.mean,
            sample_variance,
            variance_of_mean,
            variance_of_average,
        }
    }

    /// Variance of one sample (zero below two samples): with one
    /// replicate, the unbiased spread of the samples; with several, `n`
    /// times the variance of the mean, the variance that independent
    /// samples would need for the error reached (the same thing for
    /// independent samples, less for well-spread ones).
    pub fn sample_variance(&self) -> Vec3 {
        self.sample_variance
    }

    /// Variance of the pixel mean: the squared standard error of the
    /// pixel (see [`PixelEstimate::of_replicates`]).
    pub fn variance_of_mean(&self) -> Vec3 {
        self.variance_of_mean
    }

    /// Variance of the mean of the channel average `(R + G + B) / 3`:
    /// from the replicates when there are several, otherwise bounded
    /// above from the channels' (their covariance is not kept).
    pub fn variance_of_average(&self) -> f32 {
        self.variance_of_average
    }
}

/// Statistics of the dyadic blocks of one pixel's samples, built one sample
/// at a time: a binary counter whose carries are merges (slot by slot, one
/// slot per replicate), so that it holds the `dyadic_blocks` of the samples
/// pushed so far, with their defined values. Allocated once per tile.
pub(crate) struct BlockCounter {
    ranges: [Range<u32>; 65],
    /// Per block, its `replicates` slots.
    slots: Vec<PixelStats>,
    replicates: u32,
    len: usize,
}

impl BlockCounter {
    pub(crate) fn new(replicates: u32) -> BlockCounter {
        let replicates = replicates.max(1);
        BlockCounter {
            ranges: std::array::from_fn(|_| 0..0),
            slots: vec![PixelStats::default(); 65 * replicates as usize],
            replicates,
            len: 0,
        }
    }

    /// Appends sample `index` (the one after the last pushed), which
    /// belongs to replicate `index % replicates`.
    #[inline]
    pub(crate) fn push(&mut self, index: u32, stats: PixelStats) {
        let k = self.replicates as usize;
        let mut pos = self.len;
        self.slots[pos * k..(pos + 1) * k].fill(PixelStats::default());
        self.slots[pos * k + (index % self.replicates) as usize] = stats;
        let mut range = index..index + 1;
        while pos > 0 && siblings(&self.ranges[pos - 1], &range) {
            let (earlier, later) = self.slots.split_at_mut(pos * k);
            for (e, l) in earlier[(pos - 1) * k..].iter_mut().zip(&later[..k]) {
                *e = e.merged(*l);
            }
            range = self.ranges[pos - 1].start..range.end;
            pos -= 1;
        }
        self.ranges[pos] = range;
        self.len = pos + 1;
    }

    /// Forgets every sample, to start the next pixel.
    pub(crate) fn clear(&mut self) {
        self.len = 0;
    }

    /// The blocks, in order, each with its slots (one per replicate).
    pub(crate) fn blocks(&self) -> impl Iterator<Item = (&Range<u32>, &[PixelStats])> {
        let k = self.replicates as usize;
        self.ranges[..self.len].iter().zip(self.slots.chunks(k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_replicate_is_the_per_sample_estimate() {
        let mut s = PixelStats::default();
        for x in [1.0f32, 3.0, 2.0, 7.0] {
            s.add(Vec3::splat(x));
        }
        let e = PixelEstimate::of_replicates(&[s]);
        assert_eq!(e.variance_of_mean(), s.variance_of_mean());
        assert_eq!((e.n, e.mean), (s.n, s.mean));
    }

    #[test]
    fn replicate_spread_is_the_textbook_formula() {
        // Three replicates of two samples: means 2, 4, 9, mean 5; spread
        // (9 + 1 + 16) / (3 * 2) = 26 / 6.
        let reps: Vec<PixelStats> = [(1.0, 3.0), (4.0, 4.0), (8.0, 10.0)]
            .iter()
            .map(|&(a, b)| {
                let mut s = PixelStats::of_sample(Vec3::splat(a));
                s.add(Vec3::splat(b));
                s
            })
            .collect();
        let e = PixelEstimate::of_replicates(&reps);
        assert!((e.mean.x - 5.0).abs() < 1e-6);
        assert!((e.variance_of_mean().x - 26.0 / 6.0).abs() < 1e-5);
        let one = PixelEstimate::of_replicates(&[reps[0], PixelStats::default()]);
        assert_eq!(one.variance_of_mean(), Vec3::ZERO);
    }

    #[test]
    fn counter_deals_samples_into_their_replicates() {
        let mut c = BlockCounter::new(3);
        for i in 0..6u32 {
            c.push(i, PixelStats::of_sample(Vec3::splat(i as f32)));
        }
        let blocks: Vec<_> = c.blocks().collect();
        assert_eq!(blocks.len(), 2, "0..4 and 4..6");
        assert_eq!(*blocks[0].0, 0..4);
        // Block 0..4: replicate 0 holds samples 0 and 3, 1 holds 1, 2 holds 2.
        let n: Vec<u32> = blocks[0].1.iter().map(|s| s.n).collect();
        assert_eq!(n, [2, 1, 1]);
        assert_eq!(blocks[0].1[0].mean.x, 1.5);
        let n: Vec<u32> = blocks[1].1.iter().map(|s| s.n).collect();
        assert_eq!(n, [0, 1, 1], "samples 4 and 5: replicates 1 and 2");
    }
}
