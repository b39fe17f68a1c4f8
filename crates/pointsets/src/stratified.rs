//! Stratified point sets: jittered grids, Latin hypercubes and correlated
//! multi-jittered patterns, each built one point at a time from hashes so
//! that the renderer can ask for point `i` of a pattern directly.

use super::hash::{hash3, kensler_unit, permute, u64_to_unit};

/// The grid of strata used for `n` jittered points in 2D: `[columns, rows]`
/// with `columns * rows = n` and `columns` the largest divisor of `n` not
/// above `sqrt(n)`, so the strata are as square as `n` allows (a square
/// grid for square `n`, `2^k x 2^(k+1)` for `n = 2^(2k+1)`, and a single
/// column for prime `n`). `[1, 1]` for `n = 0`.
pub fn strata_shape(n: usize) -> [usize; 2] {
    if n == 0 {
        return [1, 1];
    }
    let mut columns = (n as f64).sqrt() as usize;
    // Correct the float square root, then walk down to a divisor.
    while columns * columns > n {
        columns -= 1;
    }
    while (columns + 1) * (columns + 1) <= n {
        columns += 1;
    }
    while !n.is_multiple_of(columns) {
        columns -= 1;
    }
    [columns, n / columns]
}

/// Point `i` (`i < n`) of a jittered 2D pattern of `n` points: stratum `i`
/// of the [`strata_shape`] grid, in row-major order, jittered uniformly
/// inside it by hashes of `(seed, i)`.
pub fn jittered_2d(i: usize, n: usize, seed: u64) -> [f64; 2] {
    let [columns, rows] = strata_shape(n);
    let (cx, cy) = (i % columns, i / columns);
    let jx = u64_to_unit(hash3(seed, i as u64, 0));
    let jy = u64_to_unit(hash3(seed, i as u64, 1));
    [
        clamp_unit((cx as f64 + jx) / columns as f64),
        clamp_unit((cy as f64 + jy) / rows as f64),
    ]
}

/// Point `i` of a jittered 1D pattern of `n` points: `(i + jitter) / n`.
pub(crate) fn jittered_1d(i: usize, n: usize, seed: u64) -> f64 {
    clamp_unit((i as f64 + u64_to_unit(hash3(seed, i as u64, 2))) / n as f64)
}

/// Coordinate `dimension` of point `i` of a Latin hypercube of `n` points
/// (McKay, Beckman and Conover 1979, "A comparison of three methods for
/// selecting values of input variables in the analysis of output from a
/// computer code", Technometrics 21(2)): each dimension is a jittered 1D
/// pattern whose strata are assigned to points by an independent random
/// permutation, so every row and every column holds exactly one point.
/// `n <= 2^32`.
pub fn latin_hypercube(i: usize, n: usize, dimension: usize, seed: u64) -> f64 {
    let dim_seed = hash3(seed, dimension as u64, 0x004c_4853);
    let stratum = permute(i as u32, n as u32, dim_seed as u32) as usize;
    jittered_1d(stratum, n, dim_seed)
}

/// Point `s` of Kensler's correlated multi-jittered pattern `pattern` of
/// `n` points (Kensler 2013, "Correlated Multi-Jittered Sampling", Pixar
/// Technical Memo 13-01, the final listing, for any `n` and aspect 1).
///
/// With `m = floor(sqrt(n))` columns: for square `n` every cell of the
/// `m x m` grid holds one point, and in both coordinates each of the `n`
/// 1D strata holds one point (n-rooks); the substrata are shuffled by one
/// permutation per row and one per column ("correlated"), which keeps the
/// pattern close to a jittered grid while lowering its discrepancy.
/// `1 <= n <= 2^32`, `s < n`.
pub fn cmj(s: u32, n: u32, pattern: u32) -> [f64; 2] {
    let m = ((f64::from(n)).sqrt() as u32).max(1);
    let rows = n.div_ceil(m);
    let s = permute(s, n, pattern.wrapping_mul(0x5163_3e2d));
    let sx = permute(s % m, m, pattern.wrapping_mul(0x68bc_21eb));
    let sy = permute(s / m, rows, pattern.wrapping_mul(0x02e5_be93));
    let jx = kensler_unit(s, pattern.wrapping_mul(0x967a_889b));
    let jy = kensler_unit(s, pattern.wrapping_mul(0x368c_c8b7));
    [
        clamp_unit((f64::from(sx) + (f64::from(sy) + jx) / f64::from(rows)) / f64::from(m)),
        clamp_unit((f64::from(s) + jy) / f64::from(n)),
    ]
}

/// Guards `[0, 1)` against the rounding of `(k + u) / n` up to 1.
#[inline]
pub(crate) fn clamp_unit(x: f64) -> f64 {
    x.min(super::hash::ONE_MINUS_EPSILON_F64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strata_shapes() {
        for (n, shape) in [
            (0, [1, 1]),
            (1, [1, 1]),
            (16, [4, 4]),
            (32, [4, 8]),
            (12, [3, 4]),
            (13, [1, 13]),
            (1 << 20, [1024, 1024]),
        ] {
            assert_eq!(strata_shape(n), shape, "n = {n}");
        }
    }
}
