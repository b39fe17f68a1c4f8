//! Sobol' points in base 2 with Joe–Kuo direction numbers, and their
//! randomizations: random digital (XOR) shift and hash-based nested uniform
//! (Owen) scrambling.
//!
//! Sobol' 1967, "On the distribution of points in a cube and the approximate
//! evaluation of integrals", USSR Comput. Math. Math. Phys. 7(4). Direction
//! numbers: Joe and Kuo 2008, "Constructing Sobol sequences with better
//! two-dimensional projections", SIAM J. Sci. Comput. 30 (the
//! `new-joe-kuo-6.21201` set, first 256 dimensions, checked in beside this
//! file with its source and licence).

use std::sync::LazyLock;

/// Dimensions for which direction numbers are shipped.
pub const SOBOL_MAX_DIMENSIONS: usize = 256;

/// The direction-number table: for each dimension `j`, the 32 columns `v[k]`
/// of its generator matrix, bit-reversed so that `v[k]` is the binary
/// fraction `m_k / 2^(k+1)` left-aligned in a `u32`.
static MATRICES: LazyLock<Vec<[u32; 32]>> = LazyLock::new(|| {
    // The text is compiled in and parsed by the tests of this module; a
    // failure here is a corrupted checkout, not a runtime condition.
    parse_joe_kuo(
        include_str!("new-joe-kuo-6.21201.txt"),
        SOBOL_MAX_DIMENSIONS,
    )
    .expect("the checked-in Joe-Kuo table parses")
});

/// The generator matrices by nibbles: `NIBBLES[j][q][b]` is the XOR of the
/// columns `4q..4q+4` of dimension `j` selected by the bits of `b`, so a
/// point costs 8 table reads instead of one branch per index bit (a
/// scrambled index has about 16 bits set). 128 KiB for 256 dimensions.
static NIBBLES: LazyLock<Vec<[[u32; 16]; 8]>> = LazyLock::new(|| nibble_tables(|v, k| v[k]));

/// The same in the bit-reversed domain: `REVERSED[j][q][b]` is the XOR of
/// the reversed columns `31 - (4q + bit)` for the set bits of `b`, so that
/// `sobol_reversed(index.reverse_bits())` is `sobol_u32(index).reverse_bits()`.
/// Owen scrambling works on reversed bits (Burley 2020), and staying there
/// saves two bit reversals per scrambled sample (as `sobol_burley` does).
static REVERSED: LazyLock<Vec<[[u32; 16]; 8]>> =
    LazyLock::new(|| nibble_tables(|v, k| v[31 - k].reverse_bits()));

/// Per dimension, `table[q][b]` = XOR of `column(matrix, 4q + bit)` over the
/// set bits of `b`: the shared construction of [`NIBBLES`] and [`REVERSED`].
fn nibble_tables(column: impl Fn(&[u32; 32], usize) -> u32) -> Vec<[[u32; 16]; 8]> {
    MATRICES.iter().map(|v| nibble_table(v, &column)).collect()
}

/// One matrix's nibble table (see [`nibble_tables`]).
fn nibble_table(v: &[u32; 32], column: impl Fn(&[u32; 32], usize) -> u32) -> [[u32; 16]; 8] {
    let mut table = [[0u32; 16]; 8];
    for (q, row) in table.iter_mut().enumerate() {
        for (b, entry) in row.iter_mut().enumerate() {
            *entry = (0..4)
                .filter(|bit| (b >> bit) & 1 == 1)
                .fold(0, |x, bit| x ^ column(v, 4 * q + bit));
        }
    }
    table
}

/// The XOR of the table entries the nibbles of `x` select: a matrix product over GF(2)
/// by eight reads.
#[inline]
fn xor_nibbles(table: &[[u32; 16]; 8], x: u32) -> u32 {
    let mut sum = 0;
    for (q, row) in table.iter().enumerate() {
        sum ^= row[((x >> (4 * q)) & 15) as usize];
    }
    sum
}

/// `sobol_u32(r.reverse_bits(), dimension).reverse_bits()`, from tables.
#[inline]
fn sobol_reversed(reversed_index: u32, dimension: usize) -> u32 {
    xor_nibbles(&REVERSED[dimension], reversed_index)
}

/// Parses the Joe–Kuo table format (`d s a m_1 .. m_s` per line, `#`
/// comments and the `d s a m_i` header skipped) into generator matrices for
/// `dims` dimensions, dimension 0 being van der Corput's. `None` on a
/// malformed or short table.
fn parse_joe_kuo(text: &str, dims: usize) -> Option<Vec<[u32; 32]>> {
    let mut matrices = Vec::with_capacity(dims);
    let mut first = [0u32; 32];
    for (k, v) in first.iter_mut().enumerate() {
        *v = 1 << (31 - k);
    }
    matrices.push(first);
    for line in text.lines() {
        if matrices.len() == dims {
            break;
        }
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with('d') {
            continue;
        }
        let numbers: Vec<u32> = line
            .split_whitespace()
            .map(|t| t.parse().ok())
            .collect::<Option<_>>()?;
        if numbers.len() < 3 {
            return None;
        }
        let (d, s, a, m) = (numbers[0], numbers[1] as usize, numbers[2], &numbers[3..]);
        if d as usize != matrices.len() + 1 || m.len() != s || s == 0 || s > 31 {
            return None;
        }
        // Joe and Kuo's recurrence (their `sobol.cc`), with V_k = m_k 2^(32-k):
        // v_k = v_{k-s} ^ (v_{k-s} >> s) ^ sum_{l=1}^{s-1} a_l v_{k-l}.
        let mut v = [0u32; 32];
        for k in 0..32 {
            v[k] = if k < s {
                m[k] << (31 - k)
            } else {
                let mut x = v[k - s] ^ (v[k - s] >> s);
                for l in 1..s {
                    if (a >> (s - 1 - l)) & 1 == 1 {
                        x ^= v[k - l];
                    }
                }
                x
            };
        }
        matrices.push(v);
    }
    (matrices.len() == dims).then_some(matrices)
}

/// Coordinate `dimension` of point `index` of the plain (unscrambled) Sobol'
/// sequence, as a 32-bit binary fraction (the value is `x / 2^32`).
///
/// Points are in natural order (index `i` multiplies the generator matrix),
/// not Gray-code order: the first `2^m` points are the same set either way.
/// Panics if `dimension >= SOBOL_MAX_DIMENSIONS`.
#[inline]
pub fn sobol_u32(index: u32, dimension: usize) -> u32 {
    xor_nibbles(&NIBBLES[dimension], index)
}

/// [`sobol_u32`] at the index `reversed_index.reverse_bits()`: where an index is kept
/// bit-reversed, as nested uniform scrambling of the index leaves it, dimensions 0 (van
/// der Corput's, which is the bit reversal itself) and 1 need no reversal back. The
/// other dimensions reverse the index and read [`sobol_u32`].
/// Panics if `dimension >= SOBOL_MAX_DIMENSIONS`.
#[inline(always)]
pub fn sobol_u32_at_reversed_index(reversed_index: u32, dimension: usize) -> u32 {
    match dimension {
        0 => reversed_index,
        1 => second_at_reversed_index(reversed_index),
        _ => sobol_u32(reversed_index.reverse_bits(), dimension),
    }
}

/// Dimension 1 at the index `reversed_index.reverse_bits()`, unreversed: `sobol_u32(index,
/// 1)`, in five shifts instead of a table's eight reads. Dimension 1's matrix is Pascal's
/// triangle mod 2 (its primitive polynomial is `x + 1` and every `m_k` is 1), so with the
/// index's bits as the coefficients of a polynomial `I(t)` the point's bits, from the top,
/// are those of `I(t + 1)`. Over GF(2), `(t + 1)^p` is the product of `t^s + 1` over the
/// powers of two `s` in `p` (Frobenius: `(t + 1)^(2^m) = t^(2^m) + 1`), so the substitution
/// is one pass per bit of the exponent: each term whose exponent has bit `s` also adds the
/// term `s` lower. In the reversed domain, lower exponents are higher bits, hence the left
/// shifts, and the masks are the reversed ones.
#[inline(always)]
fn second_at_reversed_index(reversed_index: u32) -> u32 {
    let mut y = reversed_index;
    y ^= (y & 0x5555_5555) << 1;
    y ^= (y & 0x3333_3333) << 2;
    y ^= (y & 0x0f0f_0f0f) << 4;
    y ^= (y & 0x00ff_00ff) << 8;
    y ^= (y & 0x0000_ffff) << 16;
    y
}

/// The Laine–Karras permutation with Burley's improved constants: a hash
/// in which output bit `k` depends only on input bits `0..=k` and flips
/// bit `k` as a function of them.
///
/// Laine and Karras 2011, "Stratified sampling for stochastic transparency",
/// EGSR; constants from Burley 2020, "Practical Hash-based Owen Scrambling",
/// JCGT 9(4), Listing 1.
#[inline(always)]
pub fn laine_karras_permutation(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Hash-based nested uniform (Owen) scrambling of a 32-bit binary fraction:
/// each bit is flipped as a function of the bits above it, which is what
/// keeps a (t, m, s)-net a (t, m, s)-net (Owen 1995, "Randomly permuted
/// (t,m,s)-nets and (t,s)-sequences"). Burley 2020, Listing 2: the
/// Laine–Karras permutation applied to the bit-reversed value.
#[inline(always)]
pub fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras_permutation(x.reverse_bits(), seed).reverse_bits()
}

/// Burley 2020's Owen-scrambled Sobol' sample (Listing 3): the index is
/// itself Owen-scrambled (a shuffle that maps the first `2^m` indices to an
/// aligned block of `2^m`, so prefixes of power-of-two length stay nets),
/// then the point is scrambled with a per-dimension seed. Returns the 32-bit
/// fraction. Panics if `dimension >= SOBOL_MAX_DIMENSIONS`.
#[inline]
pub fn sobol_owen_u32(index: u32, dimension: usize, seed: u32) -> u32 {
    // The shuffled index, reversed.
    let shuffled = laine_karras_permutation(index.reverse_bits(), seed);
    // Burley's `hash_combine(seed, hash(dimension))`, with the murmur3
    // finaliser as the hash: cheap, and distinct dimensions get unrelated
    // scramble seeds.
    let dim_seed = seed
        ^ fmix32((dimension as u32).wrapping_add(1))
            .wrapping_add(0x9e37_79b9)
            .wrapping_add(seed << 6)
            .wrapping_add(seed >> 2);
    laine_karras_permutation(sobol_reversed(shuffled, dimension), dim_seed).reverse_bits()
}

/// murmur3's 32-bit finaliser (Appleby 2011): a bijective mixer.
#[inline]
fn fmix32(mut h: u32) -> u32 {
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_parses_all_dimensions() {
        assert_eq!(MATRICES.len(), SOBOL_MAX_DIMENSIONS);
        // Every generator matrix is upper triangular with a unit diagonal
        // (so non-singular): column k has row k (bit 31-k) set and no row
        // below it.
        for (j, v) in MATRICES.iter().enumerate() {
            for (k, &col) in v.iter().enumerate() {
                assert_eq!(col.trailing_zeros() as usize, 31 - k, "dim {j} col {k}");
            }
        }
    }

    #[test]
    fn nibble_tables_equal_the_matrix_product() {
        let by_bits = |index: u32, dim: usize| {
            let v = &MATRICES[dim];
            (0..32)
                .filter(|k| (index >> k) & 1 == 1)
                .fold(0, |x, k| x ^ v[k])
        };
        for dim in [0, 1, 2, 17, 255] {
            for index in [0, 1, 2, 3, 255, 256, 0xdead_beef, u32::MAX] {
                assert_eq!(sobol_u32(index, dim), by_bits(index, dim));
            }
        }
    }

    #[test]
    fn points_at_reversed_indices_are_the_points() {
        for dim in [0, 1, 2, 17, 255] {
            for index in [0, 1, 2, 3, 255, 256, 0xdead_beef, 0x8000_0001, u32::MAX] {
                assert_eq!(
                    sobol_u32_at_reversed_index(index.reverse_bits(), dim),
                    sobol_u32(index, dim),
                    "dim {dim} index {index}"
                );
            }
        }
    }

    #[test]
    fn the_second_dimension_by_shifts_is_its_matrix() {
        // Both maps are linear over GF(2), so agreeing on the 32 one-bit indices they agree
        // on every index.
        for k in 0..32 {
            let index = 1u32 << k;
            assert_eq!(
                second_at_reversed_index(index.reverse_bits()),
                MATRICES[1][k],
                "index bit {k}"
            );
        }
        assert_eq!(second_at_reversed_index(0), 0);
    }

    #[test]
    fn owen_sample_is_burleys_listing() {
        for (index, dim, seed) in [
            (0, 0, 0),
            (5, 1, 9),
            (1000, 37, 0xdead_beef),
            (u32::MAX, 255, 1),
        ] {
            let shuffled = nested_uniform_scramble(index, seed);
            let dim_seed = seed
                ^ fmix32((dim as u32).wrapping_add(1))
                    .wrapping_add(0x9e37_79b9)
                    .wrapping_add(seed << 6)
                    .wrapping_add(seed >> 2);
            let expected = nested_uniform_scramble(sobol_u32(shuffled, dim), dim_seed);
            assert_eq!(sobol_owen_u32(index, dim, seed), expected);
            assert_eq!(
                sobol_reversed(index.reverse_bits(), dim),
                sobol_u32(index, dim).reverse_bits()
            );
        }
    }

    #[test]
    fn malformed_tables_are_refused() {
        assert!(parse_joe_kuo("2 1 0 1\n", 3).is_none());
        assert!(parse_joe_kuo("2 1 0 1 1\n", 2).is_none());
        assert!(parse_joe_kuo("3 1 0 1\n", 2).is_none());
        assert!(parse_joe_kuo("2 1 0 x\n", 2).is_none());
        assert!(parse_joe_kuo("2 1 0 1\n", 2).is_some());
    }

    #[test]
    fn scramble_flips_depend_only_on_higher_bits() {
        // Two fractions that agree in their top k bits agree in the top k
        // bits after scrambling.
        for seed in [0u32, 7, 0xdead_beef] {
            for k in 1..32 {
                let a = 0x9abc_def0u32;
                let b = a ^ (1 << (31 - k));
                let mask = !((1u32 << (32 - k)) - 1);
                assert_eq!(
                    nested_uniform_scramble(a, seed) & mask,
                    nested_uniform_scramble(b, seed) & mask
                );
                assert_ne!(
                    nested_uniform_scramble(a, seed) & (1 << (31 - k)),
                    nested_uniform_scramble(b, seed) & (1 << (31 - k))
                );
            }
        }
    }
}
