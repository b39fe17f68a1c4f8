//! Halton points: radical inverses in the first prime bases, plain or with
//! nested (Owen) random digit permutations.
//!
//! Halton 1960, "On the efficiency of certain quasi-random sequences of
//! points in evaluating multi-dimensional integrals", Numer. Math. 2. The
//! scrambling is Owen 1995's nested uniform scrambling in base `b`, with
//! each node's permutation drawn by hashing the digits above it (as
//! pbrt-v4's `OwenScrambledRadicalInverse` does with random digit shifts;
//! here the permutations are full random permutations).

use std::sync::LazyLock;

use super::hash::{GOLDEN_GAMMA, ONE_MINUS_EPSILON_F64, hash2, mix64, permute, u64_to_unit};

/// Dimensions available to Halton points (the first this many primes).
pub const HALTON_MAX_DIMENSIONS: usize = 1024;

static PRIMES: LazyLock<Vec<u64>> = LazyLock::new(|| {
    let mut primes: Vec<u64> = Vec::with_capacity(HALTON_MAX_DIMENSIONS);
    let mut candidate = 2u64;
    while primes.len() < HALTON_MAX_DIMENSIONS {
        if primes
            .iter()
            .take_while(|&&p| p * p <= candidate)
            .all(|&p| !candidate.is_multiple_of(p))
        {
            primes.push(candidate);
        }
        candidate += 1;
    }
    primes
});

/// The base of Halton dimension `dimension`: the `dimension`-th prime (2, 3,
/// 5, ...). Panics if `dimension >= HALTON_MAX_DIMENSIONS`.
pub fn halton_base(dimension: usize) -> u64 {
    PRIMES[dimension]
}

/// The radical inverse of `index` in `base`: its base-`base` digits
/// mirrored about the radix point (`0.d_0 d_1 d_2 ...`).
///
/// Exact: the result is the correctly rounded value of the rational
/// `reversed / base^digits` (one division of two integers, both exact in
/// `f64` whenever `base^digits <= 2^53`). `base >= 2`.
pub fn radical_inverse(base: u64, mut index: u64) -> f64 {
    debug_assert!(base >= 2);
    let (mut reversed, mut denominator) = (0u128, 1u128);
    while index > 0 {
        let next = index / base;
        reversed = reversed * u128::from(base) + u128::from(index - next * base);
        denominator *= u128::from(base);
        index = next;
    }
    (reversed as f64 / denominator as f64).min(ONE_MINUS_EPSILON_F64)
}

/// The radical inverse of `index` in `base` after nested uniform scrambling
/// seeded by `seed`: digit `k` (from the radix point) is sent through a
/// random permutation of `0..base` chosen by hashing `seed` with digits
/// `0..k`.
///
/// Past the index's last digit every digit is 0, and a nested scramble of an
/// all-zero tail is a uniformly random tail: so instead of permuting digits
/// until they no longer change an `f64` (53 of them in base 2, as pbrt-v4
/// does), the tail is one uniform number hashed from the node reached. Same
/// distribution, a few digits' work: the points are uniform in `[0, 1)`, not
/// on a grid, and every elementary interval keeps its share.
pub fn owen_scrambled_radical_inverse(base: u64, mut index: u64, seed: u64) -> f64 {
    debug_assert!((2..=u64::from(u32::MAX)).contains(&base));
    let (mut reversed, mut denominator) = (0u64, 1u64);
    // The node of the scrambling tree: a hash of the digits seen so far.
    let mut node = seed;
    // Stop before the denominator overflows: the tail's 53 random bits cover
    // whatever digits are left (only for indices near 2^64).
    while index > 0 && denominator <= u64::MAX / base {
        let next = index / base;
        let digit = index - next * base;
        let permuted = permute(digit as u32, base as u32, node as u32);
        reversed = reversed * base + u64::from(permuted);
        denominator *= base;
        node = mix64(node ^ (digit + 1).wrapping_mul(GOLDEN_GAMMA));
        index = next;
    }
    let tail = u64_to_unit(hash2(node, 0x7461_696c));
    ((reversed as f64 + tail) / denominator as f64).min(ONE_MINUS_EPSILON_F64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_primes() {
        assert_eq!(&PRIMES[..10], &[2, 3, 5, 7, 11, 13, 17, 19, 23, 29]);
        assert_eq!(PRIMES[HALTON_MAX_DIMENSIONS - 1], 8161);
    }
}
