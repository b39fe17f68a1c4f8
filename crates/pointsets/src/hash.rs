//! Integer hashes and hash-driven permutations shared by the generators
//! (private). Every random choice of a point set goes through these, so a
//! point is a pure function of (seed, index, dimension) and can be computed
//! in any order.

/// Weyl increment of splitmix64: `2^64 / golden ratio`, odd.
pub(crate) const GOLDEN_GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// splitmix64's output function (Steele, Lea and Flood 2014, "Fast
/// splittable pseudorandom number generators", OOPSLA; constants from
/// Stafford's "Mix13"): a bijective 64-bit mixer with good avalanche.
#[inline(always)]
pub const fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Hash of two words. Not symmetric: `hash2(a, b) != hash2(b, a)` in
/// general, so `(seed, dimension)` and `(dimension, seed)` give different
/// streams.
#[inline(always)]
pub fn hash2(a: u64, b: u64) -> u64 {
    hash2_keyed(a, hash_key(b))
}

/// What [`hash2`] makes of its second word alone: `hash2(a, b)` is
/// `hash2_keyed(a, hash_key(b))`, so that a caller hashing many `a`s with
/// few `b`s (a sampler's dimensions) can make the keys once.
#[inline(always)]
pub const fn hash_key(b: u64) -> u64 {
    mix64(b.wrapping_add(GOLDEN_GAMMA))
}

/// [`hash2`] of `a` and the word `key` was made from by [`hash_key`].
#[inline(always)]
pub fn hash2_keyed(a: u64, key: u64) -> u64 {
    mix64(a ^ key)
}

/// Hash of three words.
#[inline]
pub fn hash3(a: u64, b: u64, c: u64) -> u64 {
    hash2(hash2(a, b), c)
}

/// `x / 2^32`: exact, and at most `1 - 2^-32`, so never 1.
#[inline]
pub(crate) fn u32_to_unit(x: u32) -> f64 {
    f64::from(x) * (1.0 / 4_294_967_296.0)
}

/// The top 53 bits of `x` over `2^53`: exact, and never 1.
#[inline]
pub(crate) fn u64_to_unit(x: u64) -> f64 {
    (x >> 11) as f64 * (1.0 / 9_007_199_254_740_992.0)
}

/// The largest `f64` below 1.
pub(crate) const ONE_MINUS_EPSILON_F64: f64 = 1.0 - f64::EPSILON / 2.0;

/// Element `i` of a pseudo-random permutation of `0..len` chosen by
/// `pattern`, without storing the permutation.
///
/// Kensler 2013, "Correlated Multi-Jittered Sampling", Pixar Technical Memo
/// 13-01, `permute()`: a hash that is a bijection on the smallest power of
/// two `>= len` (each step is invertible on the masked bits), restricted to
/// `0..len` by cycle walking. Requires `i < len`; `len >= 1`.
#[inline]
pub fn permute(mut i: u32, len: u32, pattern: u32) -> u32 {
    debug_assert!(len >= 1 && i < len);
    if len == 1 {
        return 0;
    }
    let p = pattern;
    let mut w = len - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170_893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < len {
            break;
        }
    }
    // A final rotation by `p` modulo `len`. Done in 64 bits: Kensler's
    // 32-bit `i + p` can wrap, which would break the bijection.
    ((u64::from(i) + u64::from(p)) % u64::from(len)) as u32
}

/// A uniform number in `[0, 1)` for index `i` of pattern `pattern`
/// (Kensler 2013, `randfloat()`), as 32 bits over `2^32`.
#[inline]
pub fn kensler_unit(mut i: u32, pattern: u32) -> f64 {
    let p = pattern;
    i ^= p;
    i ^= i >> 17;
    i ^= i >> 10;
    i = i.wrapping_mul(0xb365_34e5);
    i ^= i >> 12;
    i ^= i >> 21;
    i = i.wrapping_mul(0x93fc_4795);
    i ^= 0xdf6e_307f;
    i ^= i >> 17;
    i = i.wrapping_mul(1 | p >> 18);
    u32_to_unit(i)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permute_is_a_bijection() {
        for len in [1u32, 2, 3, 5, 16, 17, 100, 1000] {
            for pattern in [0u32, 1, 0xdead_beef] {
                let mut seen = vec![false; len as usize];
                for i in 0..len {
                    let j = permute(i, len, pattern) as usize;
                    assert!(!seen[j], "len {len} pattern {pattern}: {j} twice");
                    seen[j] = true;
                }
            }
        }
    }

    #[test]
    fn units_are_below_one() {
        assert!(u32_to_unit(u32::MAX) < 1.0);
        assert!(u64_to_unit(u64::MAX) < 1.0);
        assert!(kensler_unit(u32::MAX, u32::MAX) < 1.0);
    }
}
