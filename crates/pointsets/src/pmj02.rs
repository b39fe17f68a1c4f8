//! Progressive multi-jittered (0, 2) sequences, pmj02 (Christensen, Kensler
//! and Kilpatrick 2018, "Progressive Multi-Jittered Sample Sequences",
//! Computer Graphics Forum 37(4), Sections 4 and 5).
//!
//! The sequence grows by doublings. Going from `N = 4^k` to `2N` points
//! (the "even" step), each old point's new partner goes in the diagonally
//! opposite sub-quadrant of the old point's cell of the `2^k x 2^k` grid;
//! going from `2N` to `4N` (the "odd" step), the two remaining
//! sub-quadrants of each cell get one point each, the first chosen at
//! random. Inside its sub-quadrant a point is placed uniformly at random
//! among the positions that leave every elementary interval of the new
//! size `2^m` (every `2^a x 2^(m-a)` grid) with at most one point, so every
//! power-of-two prefix is a (0, m, 2)-net in base 2, and every power-of-four
//! prefix is also a jittered grid.
//!
//! The paper finds such positions by rejection sampling; here a position is
//! first drawn among the free 1D strata (rows and columns of the finest
//! grid) a few times, then, if none was valid (the usual case past a few
//! hundred points: about one free row per free column completes a valid
//! pair), the free columns are taken in random order and the first with a
//! valid row gets a random one of them; in the last resort the whole square
//! is searched. So the construction never loops forever and is a pure
//! function of its seed. Each column tried costs `O(sqrt(n) log n)` checks;
//! measured overall: 4096 points in 8 ms, 2^16 in 1 s, 2^18 in 14 s (about
//! `n^1.8`), hence [`super::PointSetKind::max_points`] of 2^18. A descent
//! of the row's bits constrained by each split would be faster; not needed
//! at the sizes used here.
//!
//! Being sequential (each point depends on all earlier ones), pmj02 is
//! generated into tables; the renderer's sampler uses a few shared tables,
//! each randomized per pixel and dimension by a random digital (XOR) shift,
//! which maps elementary intervals onto elementary intervals and so keeps
//! every prefix a net (as pbrt-v4's `PMJ02BNSampler` draws pixels from a
//! few precomputed sets).

use std::sync::LazyLock;

use rand_pcg::Pcg32;
use rand_pcg::rand_core::Rng;

use super::hash::hash2;

/// The first `n` points of a pmj02 sequence drawn from `seed`, as 32-bit
/// binary fractions `[x, y]` (point `i` is `x / 2^32, y / 2^32`).
/// Every prefix of length `2^m` (`2^m <= n`, `m <= 32`) is a (0, m, 2)-net
/// in base 2. About `n^1.8` time (see the module notes).
pub fn pmj02_u32(n: usize, seed: u64) -> Vec<[u32; 2]> {
    let mut builder = Builder {
        points: Vec::with_capacity(n),
        rng: Pcg32::new(hash2(seed, 0x0070_6d6a_3032), hash2(seed, 1)),
        level: 0,
        occupied: Vec::new(),
    };
    if n == 0 {
        return builder.points;
    }
    let first = [builder.rng.next_u32(), builder.rng.next_u32()];
    builder.points.push(first);
    // `count` is the number of points made so far, a power of two.
    let mut count = 1usize;
    while count < n {
        let target = (2 * count).min(n);
        builder.start_level(2 * count);
        if count.trailing_zeros().is_multiple_of(2) {
            builder.extend_even(count, target);
        } else {
            builder.extend_odd(count, target);
        }
        count *= 2;
    }
    builder.points
}

/// The state of one growing sequence.
struct Builder {
    points: Vec<[u32; 2]>,
    rng: Pcg32,
    /// `log2` of the size of the prefix being completed.
    level: u32,
    /// For each split `a = 0..=level`, which cells of the
    /// `2^a x 2^(level - a)` grid hold a point.
    occupied: Vec<Vec<bool>>,
}

/// The top `bits` bits of `v` (0 for `bits = 0`).
#[inline]
fn top(v: u32, bits: u32) -> u64 {
    if bits == 0 {
        0
    } else {
        u64::from(v >> (32 - bits))
    }
}

impl Builder {
    /// Prepares the occupancy grids for completing a prefix of `size`
    /// points (a power of two) from the points already made.
    fn start_level(&mut self, size: usize) {
        self.level = size.trailing_zeros();
        self.occupied = (0..=self.level).map(|_| vec![false; size]).collect();
        for i in 0..self.points.len() {
            let p = self.points[i];
            self.mark(p);
        }
    }

    /// The cell of `p` in the grid of split `a`.
    #[inline]
    fn cell(&self, p: [u32; 2], a: u32) -> usize {
        (top(p[0], a) | (top(p[1], self.level - a) << a)) as usize
    }

    fn mark(&mut self, p: [u32; 2]) {
        for a in 0..=self.level {
            let c = self.cell(p, a);
            self.occupied[a as usize][c] = true;
        }
    }

    /// True when the finest-strata pair `(sx, sy)` (column and row of the
    /// `2^level` 1D strata) lies in no occupied elementary interval.
    fn is_free(&self, sx: u32, sy: u32) -> bool {
        // Left-align the strata so that `cell` reads their top bits.
        let l = self.level;
        let p = [
            if l == 0 { 0 } else { sx << (32 - l) },
            if l == 0 { 0 } else { sy << (32 - l) },
        ];
        (0..=l).all(|a| !self.occupied[a as usize][self.cell(p, a)])
    }

    /// A uniform random number below `bound` (`bound >= 1`), by Lemire's
    /// multiply-shift (the bias is below 2^-32 times `bound`, immaterial
    /// for jitter).
    fn below(&mut self, bound: u32) -> u32 {
        ((u64::from(self.rng.next_u32()) * u64::from(bound)) >> 32) as u32
    }

    /// Places a new point in sub-quadrant `(qx, qy)` of the grid whose
    /// cells are `2^-half_bits` wide (the sub-quadrant is
    /// `2^-(half_bits)`-aligned and as wide), and records it.
    fn place(&mut self, quadrant: [u32; 2], half_bits: u32) {
        let l = self.level;
        // The sub-quadrant covers `span` consecutive finest strata per axis.
        let span_bits = l - half_bits.min(l);
        let span = 1u32 << span_bits;
        let (x0, y0) = (quadrant[0] << span_bits, quadrant[1] << span_bits);
        let free_x: Vec<u32> = (x0..x0 + span)
            .filter(|&sx| !self.occupied[l as usize][self.cell([sx << (32 - l), 0], l)])
            .collect();
        let free_y: Vec<u32> = (y0..y0 + span)
            .filter(|&sy| !self.occupied[0][self.cell([0, sy << (32 - l)], 0)])
            .collect();
        let mut chosen = None;
        if !free_x.is_empty() && !free_y.is_empty() {
            // Rejection sampling among free rows and columns, as the paper
            // does; a valid pair is usually found within a few tries.
            for _ in 0..16 {
                let sx = free_x[self.below(free_x.len() as u32) as usize];
                let sy = free_y[self.below(free_y.len() as u32) as usize];
                if self.is_free(sx, sy) {
                    chosen = Some((sx, sy));
                    break;
                }
            }
            // Past a few hundred points valid pairs are rare (about one
            // free row per free column), so rejection mostly fails: take
            // the free columns in random order and, for each, the rows that
            // complete a valid pair, until one has some. O(span) checks per
            // column instead of O(span^2) for the whole sub-quadrant.
            let mut columns = free_x;
            while chosen.is_none() && !columns.is_empty() {
                let pick = self.below(columns.len() as u32) as usize;
                let sx = columns.swap_remove(pick);
                let rows: Vec<u32> = free_y
                    .iter()
                    .copied()
                    .filter(|&sy| self.is_free(sx, sy))
                    .collect();
                if !rows.is_empty() {
                    chosen = Some((sx, rows[self.below(rows.len() as u32) as usize]));
                }
            }
        }
        let (sx, sy) = chosen.unwrap_or_else(|| self.anywhere());
        // Uniform jitter inside the finest stratum of each axis.
        let jitter = |rng: &mut Pcg32| {
            if l == 32 { 0 } else { rng.next_u32() >> l }
        };
        let (jx, jy) = (jitter(&mut self.rng), jitter(&mut self.rng));
        let p = [
            if l == 0 { jx } else { (sx << (32 - l)) | jx },
            if l == 0 { jy } else { (sy << (32 - l)) | jy },
        ];
        self.points.push(p);
        self.mark(p);
    }

    /// A free finest-strata pair anywhere in the square: the last resort
    /// when the chosen sub-quadrant holds none. Never reached in the tests
    /// (seeds 0..64, up to 2^12 points); it keeps the construction total.
    fn anywhere(&mut self) -> (u32, u32) {
        let side = 1u32 << self.level;
        let valid: Vec<(u32, u32)> = (0..side)
            .flat_map(|sx| (0..side).map(move |sy| (sx, sy)))
            .filter(|&(sx, sy)| self.is_free(sx, sy))
            .collect();
        // A (0, m, 2)-net prefix of fewer than 2^m points always leaves a
        // free pair (each split has free cells and some pair of free
        // finest strata is consistent with all of them); should it not,
        // the point still lands in a valid 1D position.
        valid
            .get(self.below(valid.len().max(1) as u32) as usize)
            .copied()
            .unwrap_or((0, 0))
    }

    /// The cell of `p` in the `2^bits x 2^bits` grid and its sub-quadrant
    /// (the next bit of each coordinate).
    fn cell_and_half(p: [u32; 2], bits: u32) -> ([u32; 2], [u32; 2]) {
        let cell = [top(p[0], bits) as u32, top(p[1], bits) as u32];
        let half = [
            top(p[0], bits + 1) as u32 & 1,
            top(p[1], bits + 1) as u32 & 1,
        ];
        (cell, half)
    }

    /// From `count = 4^k` points to `target <= 2 count`: each new point in
    /// the sub-quadrant diagonally opposite its old partner's.
    fn extend_even(&mut self, count: usize, target: usize) {
        let bits = count.trailing_zeros() / 2;
        for s in 0..target - count {
            let (cell, half) = Self::cell_and_half(self.points[s], bits);
            let quadrant = [2 * cell[0] + (1 - half[0]), 2 * cell[1] + (1 - half[1])];
            self.place(quadrant, bits + 1);
        }
    }

    /// From `count = 2 * 4^k` points to `target <= 2 count`: the two empty
    /// sub-quadrants of each cell of the `2^k x 2^k` grid (the first half of
    /// the old points and their diagonal partners fill the other two),
    /// the first one picked at random, the second in the next half.
    fn extend_odd(&mut self, count: usize, target: usize) {
        let bits = (count / 2).trailing_zeros() / 2;
        let half_count = count / 2;
        let mut flips = Vec::with_capacity(half_count);
        for s in 0..half_count.min(target - count) {
            let (cell, half) = Self::cell_and_half(self.points[s], bits);
            // Flip x or y of the old sub-quadrant: one of the two empty ones.
            let flip_x = self.rng.next_u32() & 1 == 1;
            flips.push(flip_x);
            let q = if flip_x {
                [1 - half[0], half[1]]
            } else {
                [half[0], 1 - half[1]]
            };
            self.place([2 * cell[0] + q[0], 2 * cell[1] + q[1]], bits + 1);
        }
        let rest = (target - count).saturating_sub(half_count);
        for (s, &flip_x) in flips.iter().enumerate().take(rest) {
            let (cell, half) = Self::cell_and_half(self.points[s], bits);
            // The other flip: the last empty sub-quadrant.
            let q = if flip_x {
                [half[0], 1 - half[1]]
            } else {
                [1 - half[0], half[1]]
            };
            self.place([2 * cell[0] + q[0], 2 * cell[1] + q[1]], bits + 1);
        }
    }
}

/// How many shared tables the renderer's sampler draws from, and their
/// length: enough for 4096 samples per pixel before a new block starts.
pub const PMJ02_TABLES: usize = 16;
/// Points per shared table.
pub const PMJ02_TABLE_LEN: usize = 4096;

/// The shared pmj02 tables of the sampler, built on first use (a few
/// milliseconds each).
static TABLES: LazyLock<Vec<Vec<[u32; 2]>>> = LazyLock::new(|| {
    (0..PMJ02_TABLES)
        .map(|t| pmj02_u32(PMJ02_TABLE_LEN, hash2(0x0070_6d6a_3032, t as u64)))
        .collect()
});

/// Point `index` (`< PMJ02_TABLE_LEN`) of shared table `table`
/// (`< PMJ02_TABLES`).
#[inline]
pub fn pmj02_table_point(table: usize, index: usize) -> [u32; 2] {
    TABLES[table][index]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every elementary interval of each power-of-two prefix holds one
    /// point.
    fn assert_prefix_nets(points: &[[u32; 2]], what: &str) {
        let mut m = 0;
        while (1usize << m) <= points.len() {
            let prefix = &points[..1 << m];
            for a in 0..=m {
                let mut count = vec![0u8; 1 << m];
                for &p in prefix {
                    let c = top(p[0], a) | (top(p[1], m - a) << a);
                    count[c as usize] += 1;
                }
                assert!(
                    count.iter().all(|&c| c == 1),
                    "{what}: prefix 2^{m}, split {a}"
                );
            }
            m += 1;
        }
    }

    #[test]
    fn prefixes_are_nets() {
        for seed in 0..64 {
            assert_prefix_nets(&pmj02_u32(1 << 10, seed), &format!("seed {seed}"));
        }
        assert_prefix_nets(&pmj02_u32(1 << 12, 99), "seed 99");
    }

    #[test]
    fn shorter_requests_are_prefixes() {
        let long = pmj02_u32(256, 5);
        for n in [0, 1, 2, 3, 17, 100, 256] {
            assert_eq!(pmj02_u32(n, 5)[..], long[..n], "n = {n}");
        }
    }

    #[test]
    fn shared_tables_are_nets() {
        for t in [0, PMJ02_TABLES - 1] {
            assert_prefix_nets(&TABLES[t], &format!("table {t}"));
        }
    }
}
