//! The padded Sobol' kinds' numbers ([`padded_sobol`]), for one request of a path's
//! [`Sampler`](crate::Sampler) or for a vector of paths at once ([`SobolXorLanes`]): one
//! formula for both.

use lueur_pointsets::construct::{hash_key, hash2, hash2_keyed};
use lueur_pointsets::{
    laine_karras_permutation, nested_uniform_scramble, sobol_u32_at_reversed_index,
};

use crate::sampler::{DIMENSION_KEYS, fraction_to_f32};

/// The padded Sobol' kinds' numbers: the first `N` (1 or 2) Sobol' dimensions at a
/// shuffled index, randomized by XOR (`OWEN` false,
/// [`SamplerKind::SobolXor`](crate::SamplerKind::SobolXor)) or Owen scrambling (Burley
/// 2020, Listing 3, in 2D), for the request whose dimension's key is `key`
/// (`hash_key(dimension)`) in the pixel sample of `pixel_hash` and `reversed_index` (see
/// [`Sampler`](crate::Sampler)'s fields). A pure function of them, so that a path's
/// sampler and a vector of paths' lanes ([`SobolXorLanes`]) give the same bits.
#[inline(always)]
pub(crate) fn padded_sobol<const N: usize, const OWEN: bool>(
    pixel_hash: u64,
    reversed_index: u32,
    key: u64,
) -> [u32; N] {
    let h = hash2_keyed(pixel_hash, key);
    // The index scrambled is `nested_uniform_scramble(index, h)`, kept bit-reversed (the
    // scramble's last step undone), where dimensions 0 and 1 read it directly.
    let index = laine_karras_permutation(reversed_index, h as u32);
    // Not a closure: a vector kernel inlines only what is marked to be inlined.
    #[inline(always)]
    fn scrambled<const OWEN: bool>(x: u32, seed: u32) -> u32 {
        if OWEN {
            nested_uniform_scramble(x, seed)
        } else {
            x ^ seed
        }
    }
    // Dimension by dimension, not over a loop's index: each reads its own matrix inline
    // (a loop's `k` left the choice of matrix to run time, out of line).
    let mut out = [0; N];
    out[0] = scrambled::<OWEN>(sobol_u32_at_reversed_index(index, 0), (h >> 32) as u32);
    if N == 2 {
        out[1] = scrambled::<OWEN>(sobol_u32_at_reversed_index(index, 1), hash2(h, 1) as u32);
    }
    out
}

/// `N` pixel samples of [`SamplerKind::SobolXor`](crate::SamplerKind::SobolXor), one per
/// lane, each kept as the two words its numbers depend on besides the dimension (the
/// pixel sample's hash and its index, bit-reversed): a number is then a pure function of
/// a lane's words and its dimension, computed for every lane by one loop that a caller
/// compiled for a SIMD level turns into vector instructions (64-bit multiplies per lane),
/// where a path's own [`Sampler`](crate::Sampler) hashes one request at a time. Lane `i`
/// gives, at any dimension, the numbers of the sampler whose
/// [`Sampler::sobol_xor_sample`](crate::Sampler::sobol_xor_sample) it was set from,
/// bit for bit: both compute `padded_sobol`, which holds the formula once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SobolXorLanes<const N: usize> {
    /// Each lane's pixel sample's hash (of its replicate's seed and its pixel).
    pub pixel_hash: [u64; N],
    /// Each lane's index within its replicate, bit-reversed.
    pub reversed_index: [u32; N],
}

impl<const N: usize> SobolXorLanes<N> {
    /// Every lane at hash 0 and index 0 (a placeholder, until each lane is set from a
    /// sampler).
    pub const UNSET: SobolXorLanes<N> = SobolXorLanes {
        pixel_hash: [0; N],
        reversed_index: [0; N],
    };

    /// Lane `lane`'s pixel sample, from a sampler's
    /// [`sobol_xor_sample`](crate::Sampler::sobol_xor_sample).
    #[inline]
    pub fn set(&mut self, lane: usize, (pixel_hash, reversed_index): (u64, u32)) {
        self.pixel_hash[lane] = pixel_hash;
        self.reversed_index[lane] = reversed_index;
    }

    /// Each lane's two numbers at its dimension `dimensions[i]`: what
    /// [`Sampler::next_2d`](crate::Sampler::next_2d) draws there, `x` then `y`.
    #[inline(always)]
    pub fn get_2d(&self, dimensions: &[u32; N]) -> [[f32; N]; 2] {
        let keys = keys(dimensions);
        let mut out = [[0.0; N]; 2];
        for i in 0..N {
            let [x, y] =
                padded_sobol::<2, false>(self.pixel_hash[i], self.reversed_index[i], keys[i]);
            out[0][i] = fraction_to_f32(x);
            out[1][i] = fraction_to_f32(y);
        }
        out
    }

    /// Each lane's number at its dimension `dimensions[i]`: what
    /// [`Sampler::next_1d`](crate::Sampler::next_1d) draws there.
    #[inline(always)]
    pub fn get_1d(&self, dimensions: &[u32; N]) -> [f32; N] {
        let keys = keys(dimensions);
        let mut out = [0.0; N];
        for i in 0..N {
            let [x] = padded_sobol::<1, false>(self.pixel_hash[i], self.reversed_index[i], keys[i]);
            out[i] = fraction_to_f32(x);
        }
        out
    }
}

/// Each dimension's key, `hash_key(dimension)`: read from the sampler's table where every
/// lane's dimension is in it (a vector gather), else hashed (`dimension_key`'s two cases,
/// each over all the lanes).
#[inline(always)]
fn keys<const N: usize>(dimensions: &[u32; N]) -> [u64; N] {
    let mut keys = [0; N];
    if dimensions
        .iter()
        .all(|&d| (d as usize) < DIMENSION_KEYS.len())
    {
        for (key, &d) in keys.iter_mut().zip(dimensions) {
            // Within the table: the mask only spares a bounds check.
            *key = DIMENSION_KEYS[d as usize % DIMENSION_KEYS.len()];
        }
    } else {
        for (key, &d) in keys.iter_mut().zip(dimensions) {
            *key = hash_key(u64::from(d));
        }
    }
    keys
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Sampler, SamplerKind};

    /// Every lane, set from a sampler of its own pixel and sample (with replicates, so
    /// that the index and the seed are each replicate's), gives that sampler's numbers
    /// bit for bit at any dimension, past the sampler's table of keys too.
    #[test]
    fn each_lane_gives_its_sampler_s_numbers_at_any_dimension() {
        const N: usize = 16;
        for replicates in [1, 4] {
            let mut lanes = SobolXorLanes::<N>::UNSET;
            let ids: Vec<([u32; 2], u32)> = (0..N)
                .map(|i| {
                    (
                        [(i * 5) as u32 % 64, (i * 11) as u32 % 64],
                        (i * 7) as u32 % 64,
                    )
                })
                .collect();
            let sampler =
                || Sampler::for_render(SamplerKind::SobolXor, 7, [64, 64], 64, replicates);
            for (i, &(pixel, index)) in ids.iter().enumerate() {
                let mut s = sampler();
                s.start_pixel_sample(pixel, index, 2);
                lanes.set(i, s.sobol_xor_sample().expect("sobol-xor"));
            }
            for step in 0..40u32 {
                // Each lane at a dimension of its own.
                let dims: [u32; N] = std::array::from_fn(|i| 2 + step * 9 + i as u32 * 3);
                let pairs = lanes.get_2d(&dims);
                let ones = lanes.get_1d(&dims);
                for (i, &(pixel, index)) in ids.iter().enumerate() {
                    let mut s = sampler();
                    s.start_pixel_sample(pixel, index, dims[i]);
                    let xy = s.next_2d();
                    assert_eq!(
                        xy.x.to_bits(),
                        pairs[0][i].to_bits(),
                        "lane {i}, dim {}",
                        dims[i]
                    );
                    assert_eq!(
                        xy.y.to_bits(),
                        pairs[1][i].to_bits(),
                        "lane {i}, dim {}",
                        dims[i]
                    );
                    s.start_pixel_sample(pixel, index, dims[i]);
                    assert_eq!(s.next_1d().to_bits(), ones[i].to_bits(), "lane {i}");
                }
            }
        }
    }

    #[test]
    fn only_the_sobol_xor_kind_has_a_sample_for_lanes() {
        for kind in SamplerKind::ALL {
            let mut s = Sampler::for_render(*kind, 1, [8, 8], 16, 1);
            s.start_pixel_sample([1, 2], 3, 0);
            assert_eq!(
                s.sobol_xor_sample().is_some(),
                *kind == SamplerKind::SobolXor
            );
        }
    }
}
