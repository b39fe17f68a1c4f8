//! lueur-pointsets: point sets in the unit cube `[0, 1)^d`, reusable on
//! their own. Random, stratified, low-discrepancy and blue-noise generators
//! behind one call, [`generate`], which returns a [`PointSet`] (the primary
//! type: `n` points of `dim` coordinates, row-major), and the measures that
//! compare them: L2 discrepancies, the exact 2D star discrepancy,
//! integration error and its convergence rate as UTK measures it, and the
//! radially averaged power spectrum.
//!
//! [`PointSetKind`] is the one registry of constructions in lueur: their
//! names, their limits, and which of them [`generate`] can build. The
//! renderer's per-(pixel, sample, dimension) sampler, in `lueur-sampling`,
//! draws from the same constructions ([`construct`]) and takes its kinds and
//! names from this registry.
//!
//! What it is not: no rendering, no `f32` vectors, no I/O, no printing; it
//! does not know pixels (the screen-space ordering of
//! [`PointSetKind::ZSobol`] is the sampler's alone).
//!
//! The design decision: every coordinate is a pure function of (kind, seed,
//! point index, dimension), computed from integer hashes or from the
//! point's index, never from a generator's running state (the only
//! exceptions are [`PointSetKind::Independent`], a PCG32 stream, and
//! [`PointSetKind::PoissonDisk`] and [`PointSetKind::Pmj02`], whose points
//! depend on each other by construction). That is what lets the renderer's
//! sampler ask for sample `i` of a pixel in any order, and what makes
//! randomizations independent: two seeds give two independent
//! randomizations of the same construction, over which errors can be
//! averaged.
//!
//! **Contract.** [`generate`] returns exactly `n` points of `dim`
//! coordinates, each in `[0, 1)` (never 1), the same ones for the same
//! arguments on every platform, or a typed [`PointSetError`] when the kind
//! cannot make that many points or dimensions.
//!
//! ```
//! use lueur_pointsets::{PointSetKind, generate, l2_star_discrepancy};
//!
//! let sobol = generate(PointSetKind::SobolOwen, 256, 2, 7).unwrap();
//! let random = generate(PointSetKind::Independent, 256, 2, 7).unwrap();
//! assert_eq!(sobol.point(3).len(), 2);
//! assert!(l2_star_discrepancy(&sobol) < l2_star_discrepancy(&random));
//! ```

#![deny(missing_docs)]

use std::fmt;

use rand_pcg::Pcg32;
use rand_pcg::rand_core::Rng;

mod halton;
mod hash;
mod integration;
mod kronecker;
mod metrics;
mod pmj02;
mod poisson;
mod sobol;
mod spectrum;
mod stratified;

pub use halton::{
    HALTON_MAX_DIMENSIONS, halton_base, owen_scrambled_radical_inverse, radical_inverse,
};
pub use integration::{
    Convergence, Integrand, IntegrandFamily, convergence_slope, integrate, integration_mse,
    least_squares_slope,
};
pub use kronecker::generalized_golden_ratio;
pub use metrics::{
    centered_l2_discrepancy, l2_star_discrepancy, star_discrepancy_2d, wraparound_l2_discrepancy,
};
pub use pmj02::pmj02_u32;
pub use poisson::{poisson_disk_max_radius, toroidal_distance};
pub use sobol::{
    SOBOL_MAX_DIMENSIONS, laine_karras_permutation, nested_uniform_scramble, sobol_owen_u32,
    sobol_u32, sobol_u32_at_reversed_index,
};
pub use spectrum::{RadialSpectrum, radial_power_spectrum};
pub use stratified::strata_shape;

/// The per-point constructions that [`generate`] builds on and that the
/// renderer's sampler (`lueur-sampling`) calls one sample at a time: integer
/// hashes, Kensler's permutation and jitter, jittered, Latin hypercube and
/// CMJ strata, the shared pmj02 tables, Kronecker increments. They live here,
/// with the point sets, so that the sampler and the point sets are the same
/// constructions by definition, and dependencies point one way (the sampler
/// depends on this crate, never the reverse).
pub mod construct {
    pub use super::hash::{hash_key, hash2, hash2_keyed, hash3, kensler_unit, mix64, permute};
    pub use super::kronecker::increments as kronecker_increments;
    pub use super::pmj02::{PMJ02_TABLE_LEN, PMJ02_TABLES, pmj02_table_point};
    pub use super::stratified::{cmj, jittered_2d, latin_hypercube};
}

use hash::{hash2, permute, u32_to_unit, u64_to_unit};
use stratified::cmj;

/// Declares [`PointSetKind`] and its list and names from one table, so that
/// [`PointSetKind::ALL`] holds every variant by construction: a kind cannot
/// be added without its name, nor left out of the list.
macro_rules! kinds {
    ($($(#[$doc:meta])* $kind:ident => $name:literal,)*) => {
        /// The registry of constructions: every random, stratified,
        /// low-discrepancy and blue-noise construction in lueur, whether
        /// [`generate`] builds it as a point set or the renderer's sampler
        /// draws from it per pixel (`lueur-sampling`'s `SamplerKind` is the
        /// renderer's view of this list). An enum, dispatched by `match`: the
        /// set is closed and each kind is one algorithm.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum PointSetKind {
            $($(#[$doc])* $kind,)*
        }

        impl PointSetKind {
            /// Every kind, in a stable order.
            pub const ALL: &'static [PointSetKind] = &[$(PointSetKind::$kind,)*];

            /// The lowercase name used on command lines and in scene files,
            /// by the point sets and the renderer's sampler alike.
            pub const fn name(&self) -> &'static str {
                match self {
                    $(PointSetKind::$kind => $name,)*
                }
            }
        }
    };
}

kinds! {
    /// Independent uniform points from PCG32 (O'Neill 2014, "PCG: A family of
    /// simple fast space-efficient statistically good algorithms for random
    /// number generation"). The baseline every other kind is measured
    /// against.
    Independent => "independent",
    /// Jittered (stratified) sampling: one point uniformly in each cell of a
    /// [`strata_shape`] grid. Dimensions are paired, `(0, 1)`, `(2, 3)`...,
    /// each pair an independent jittered pattern whose points are shuffled
    /// by a random permutation (padding, as pbrt-v4 §8.5 does), and an odd
    /// last dimension is a shuffled 1D jitter.
    Stratified => "stratified",
    /// Latin hypercube sampling (McKay, Beckman and Conover 1979): in every
    /// dimension, each of the `n` strata holds one point.
    LatinHypercube => "lhs",
    /// Correlated multi-jittered sampling (Kensler 2013), padded by pairs
    /// like [`PointSetKind::Stratified`], each pair its own pattern.
    Cmj => "cmj",
    /// The Halton sequence: radical inverses in the first primes (Halton
    /// 1960), unscrambled; starts at the origin. Seed ignored.
    Halton => "halton",
    /// Halton with nested (Owen) random digit permutations per dimension.
    HaltonOwen => "halton-owen",
    /// The Sobol' sequence with Joe–Kuo direction numbers, unscrambled, in
    /// natural order; starts at the origin. Seed ignored.
    Sobol => "sobol",
    /// Sobol' with a random digital shift: every coordinate XORed with a
    /// per-dimension random 32-bit word (a (t, m, s)-net stays one).
    SobolXor => "sobol-xor",
    /// Sobol' with hash-based nested uniform (Owen) scrambling per
    /// dimension (Burley 2020).
    SobolOwen => "sobol-owen",
    /// pbrt-v4's `ZSobolSampler` (Ahmed and Wonka 2020, "Screen-space blue
    /// noise sampling by ordered dithering"): one global Owen-scrambled
    /// Sobol' sequence indexed by the Morton code of the pixel followed by the
    /// sample index. A screen-space ordering across an image's pixels, so a
    /// kind of the renderer's sampler only: [`generate`] refuses it.
    ZSobol => "zsobol",
    /// The rank-1 Kronecker sequence R_d (Roberts 2018; "R2" in 2D) with a
    /// random Cranley–Patterson rotation.
    R2 => "r2",
    /// A 2D Poisson-disk set by relaxation dart throwing on the torus
    /// (McCool and Fiume 1992): blue noise. 2D only.
    PoissonDisk => "poisson-disk",
    /// Progressive multi-jittered (0, 2) sequences (Christensen, Kensler
    /// and Kilpatrick 2018): every power-of-two prefix is a (0, m, 2)-net
    /// and every power-of-four prefix a jittered grid. A 2D construction,
    /// padded by pairs like [`PointSetKind::Stratified`], each pair its own
    /// sequence, the pairs after the first shuffled.
    Pmj02 => "pmj02",
}

impl PointSetKind {
    /// Whether [`generate`] can build this kind as a point set of its own
    /// (every kind but [`PointSetKind::ZSobol`], which orders samples across
    /// an image's pixels).
    pub fn is_point_set(&self) -> bool {
        !matches!(self, PointSetKind::ZSobol)
    }

    /// The kinds [`generate`] can build, in the order of [`PointSetKind::ALL`].
    pub fn point_sets() -> impl Iterator<Item = PointSetKind> {
        Self::ALL.iter().copied().filter(PointSetKind::is_point_set)
    }

    /// The kind called `s` (ASCII case-insensitive), if any.
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL
            .iter()
            .copied()
            .find(|kind| kind.name().eq_ignore_ascii_case(s))
    }

    /// The most dimensions this kind can generate, if bounded.
    pub fn max_dimensions(&self) -> Option<usize> {
        match self {
            PointSetKind::Halton | PointSetKind::HaltonOwen => Some(HALTON_MAX_DIMENSIONS),
            PointSetKind::Sobol
            | PointSetKind::SobolXor
            | PointSetKind::SobolOwen
            | PointSetKind::ZSobol => Some(SOBOL_MAX_DIMENSIONS),
            PointSetKind::PoissonDisk => Some(2),
            _ => None,
        }
    }

    /// The most points this kind can generate, if bounded: `2^32` for the
    /// kinds indexed by 32-bit integers (Sobol' matrices, Kensler's
    /// permutations).
    pub fn max_points(&self) -> Option<u64> {
        match self {
            PointSetKind::Sobol
            | PointSetKind::SobolXor
            | PointSetKind::SobolOwen
            | PointSetKind::ZSobol
            | PointSetKind::LatinHypercube
            | PointSetKind::Cmj
            | PointSetKind::Stratified => Some(1 << 32),
            // Built sequentially in about n^1.8 time: 2^18 points take 14 s,
            // 2^20 three minutes.
            PointSetKind::Pmj02 => Some(1 << 18),
            _ => None,
        }
    }
}

impl fmt::Display for PointSetKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a point set could not be made or read.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PointSetError {
    /// A point set has at least one dimension.
    #[error("a point set needs at least one dimension")]
    ZeroDimensions,
    /// More dimensions than the kind's tables hold.
    #[error("{kind} supports at most {max} dimensions, {dim} were asked")]
    TooManyDimensions {
        /// The generator.
        kind: PointSetKind,
        /// Dimensions asked for.
        dim: usize,
        /// The kind's limit.
        max: usize,
    },
    /// A construction or measure defined only in some dimensions.
    #[error("{what} is only defined in {supported} dimensions, {dim} were asked")]
    UnsupportedDimensions {
        /// The generator or measure.
        what: &'static str,
        /// Dimensions asked for.
        dim: usize,
        /// The dimensions it supports, in words.
        supported: &'static str,
    },
    /// A kind of the renderer's sampler only, not a point set of its own.
    #[error("{kind} orders samples across an image's pixels: it is a sampler, not a point set")]
    NotAPointSet {
        /// The kind asked for.
        kind: PointSetKind,
    },
    /// More points than the kind can index.
    #[error("{kind} supports at most {max} points, {n} were asked")]
    TooManyPoints {
        /// The generator.
        kind: PointSetKind,
        /// Points asked for.
        n: usize,
        /// The kind's limit.
        max: u64,
    },
    /// Coordinates that do not split into whole points.
    #[error("{len} coordinates do not make whole points of {dim} dimensions")]
    RaggedData {
        /// Number of coordinates given.
        len: usize,
        /// Dimensions per point.
        dim: usize,
    },
    /// A coordinate outside `[0, 1)` (or NaN).
    #[error("coordinate {index} is {value}, outside [0, 1)")]
    OutsideUnitCube {
        /// Index of the coordinate in the row-major data.
        index: usize,
        /// Its value.
        value: f64,
    },
}

/// `n` points of `[0, 1)^dim`, stored row-major: coordinate `k` of point `i`
/// is `data[i * dim + k]`.
///
/// Invariant: `dim >= 1`, `data.len() = n * dim`, every coordinate in
/// `[0, 1)`.
#[derive(Clone, Debug, PartialEq)]
pub struct PointSet {
    dim: usize,
    data: Vec<f64>,
}

impl PointSet {
    /// Wraps row-major coordinates (from a file, another library...), checking
    /// the invariant, so they can be measured like generated ones.
    pub fn new(dim: usize, data: Vec<f64>) -> Result<Self, PointSetError> {
        if dim == 0 {
            return Err(PointSetError::ZeroDimensions);
        }
        if !data.len().is_multiple_of(dim) {
            return Err(PointSetError::RaggedData {
                len: data.len(),
                dim,
            });
        }
        if let Some((index, &value)) = data
            .iter()
            .enumerate()
            .find(|(_, v)| !(0.0..1.0).contains(*v))
        {
            return Err(PointSetError::OutsideUnitCube { index, value });
        }
        Ok(Self { dim, data })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.data.len() / self.dim
    }

    /// True when there are no points.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Coordinates per point.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The coordinates of point `i`. Panics if `i >= len()`.
    pub fn point(&self, i: usize) -> &[f64] {
        &self.data[i * self.dim..(i + 1) * self.dim]
    }

    /// The points in order, each a slice of `dim` coordinates.
    pub fn points(&self) -> std::slice::ChunksExact<'_, f64> {
        self.data.chunks_exact(self.dim)
    }

    /// All coordinates, row-major.
    pub fn as_slice(&self) -> &[f64] {
        &self.data
    }

    /// The row-major coordinates, consuming the set.
    pub fn into_vec(self) -> Vec<f64> {
        self.data
    }
}

/// `n` points of `[0, 1)^dim` from generator `kind`, randomized by `seed`
/// (ignored by the deterministic constructions [`PointSetKind::Halton`] and
/// [`PointSetKind::Sobol`]).
///
/// For the sequences (Halton, Sobol', R2) the result is the first `n` points,
/// so a prefix of a larger set is the smaller set; for the others (jittered,
/// Latin hypercube, CMJ, Poisson disk) the construction depends on `n`.
/// Sobol' points are (0, m, 2)-nets in their first two dimensions when
/// `n = 2^m`, scrambled or not.
pub fn generate(
    kind: PointSetKind,
    n: usize,
    dim: usize,
    seed: u64,
) -> Result<PointSet, PointSetError> {
    check_request(kind, n, dim)?;
    let mut data = vec![0.0; n * dim];
    let dim_seed = |k: usize| dim_seed(seed, k);
    match kind {
        PointSetKind::Independent => {
            let state = hash2(seed, 0x0069_6e64_6570);
            let mut rng = Pcg32::new(state, hash2(state, 1));
            for x in &mut data {
                *x = u64_to_unit(rng.next_u64());
            }
        }
        PointSetKind::Stratified | PointSetKind::Cmj => {
            stratified_pairs(kind, n, dim, seed, &mut data)
        }
        PointSetKind::LatinHypercube => {
            for k in 0..dim {
                for i in 0..n {
                    data[i * dim + k] = stratified::latin_hypercube(i, n, k, seed);
                }
            }
        }
        PointSetKind::Halton => {
            for k in 0..dim {
                let base = halton_base(k);
                for i in 0..n {
                    data[i * dim + k] = radical_inverse(base, i as u64);
                }
            }
        }
        PointSetKind::HaltonOwen => {
            for k in 0..dim {
                let (base, scramble) = (halton_base(k), dim_seed(k));
                for i in 0..n {
                    data[i * dim + k] = owen_scrambled_radical_inverse(base, i as u64, scramble);
                }
            }
        }
        PointSetKind::Sobol | PointSetKind::SobolXor | PointSetKind::SobolOwen => {
            for k in 0..dim {
                let scramble = dim_seed(k) as u32;
                for i in 0..n {
                    let x = sobol_u32(i as u32, k);
                    let x = match kind {
                        PointSetKind::SobolXor => x ^ scramble,
                        PointSetKind::SobolOwen => nested_uniform_scramble(x, scramble),
                        _ => x,
                    };
                    data[i * dim + k] = u32_to_unit(x);
                }
            }
        }
        PointSetKind::R2 => {
            let increments = kronecker::increments(dim);
            for (k, &a) in increments.iter().enumerate() {
                let shift = dim_seed(k);
                for i in 0..n {
                    data[i * dim + k] = u64_to_unit(shift.wrapping_add((i as u64).wrapping_mul(a)));
                }
            }
        }
        PointSetKind::Pmj02 => pmj02_pairs(n, dim, seed, &mut data),
        PointSetKind::ZSobol => return Err(PointSetError::NotAPointSet { kind }),
        PointSetKind::PoissonDisk => {
            for (i, p) in poisson::poisson_disk_2d(n, seed).into_iter().enumerate() {
                data[2 * i] = p[0];
                data[2 * i + 1] = p[1];
            }
        }
    }
    Ok(PointSet { dim, data })
}

/// Refuses what `generate` cannot build: no dimension, a kind that is not a
/// point set, more dimensions or points than the kind has.
fn check_request(kind: PointSetKind, n: usize, dim: usize) -> Result<(), PointSetError> {
    if dim == 0 {
        return Err(PointSetError::ZeroDimensions);
    }
    if !kind.is_point_set() {
        return Err(PointSetError::NotAPointSet { kind });
    }
    if let Some(max) = kind.max_dimensions() {
        if kind == PointSetKind::PoissonDisk && dim != 2 {
            return Err(PointSetError::UnsupportedDimensions {
                what: "poisson-disk",
                dim,
                supported: "2",
            });
        }
        if dim > max {
            return Err(PointSetError::TooManyDimensions { kind, dim, max });
        }
    }
    if let Some(max) = kind.max_points().filter(|&max| n as u64 > max) {
        return Err(PointSetError::TooManyPoints { kind, n, max });
    }
    Ok(())
}

/// The seed of the randomization of dimension (or pair) `k`: one word per
/// (seed, k), hashed so that nearby seeds and dimensions give unrelated
/// scrambles.
fn dim_seed(seed: u64, k: usize) -> u64 {
    hash2(seed, k as u64)
}

/// Jittered or CMJ points, pair of dimensions by pair.
fn stratified_pairs(kind: PointSetKind, n: usize, dim: usize, seed: u64, data: &mut [f64]) {
    let dim_seed = |k: usize| dim_seed(seed, k);
    for pair in 0..dim.div_ceil(2) {
        let pair_seed = dim_seed(pair);
        // The first pair keeps its natural order; the others are
        // shuffled so that no pair is aligned with another.
        let order = |i: usize| {
            if pair == 0 {
                i
            } else {
                permute(i as u32, n as u32, (pair_seed >> 32) as u32) as usize
            }
        };
        let two = 2 * pair + 1 < dim;
        for i in 0..n {
            let j = order(i);
            let p = if kind == PointSetKind::Cmj {
                cmj(j as u32, n as u32, pair_seed as u32)
            } else if two {
                stratified::jittered_2d(j, n, pair_seed)
            } else {
                [stratified::jittered_1d(j, n, pair_seed), 0.0]
            };
            data[i * dim + 2 * pair] = p[0];
            if two {
                data[i * dim + 2 * pair + 1] = p[1];
            }
        }
    }
}

/// PMJ02 points, pair of dimensions by pair.
fn pmj02_pairs(n: usize, dim: usize, seed: u64, data: &mut [f64]) {
    let dim_seed = |k: usize| dim_seed(seed, k);
    for pair in 0..dim.div_ceil(2) {
        let pair_seed = dim_seed(pair);
        let sequence = pmj02::pmj02_u32(n, pair_seed);
        let two = 2 * pair + 1 < dim;
        for i in 0..n {
            // As for the stratified kinds: the first pair in order
            // (so prefixes stay nets), the others shuffled.
            let j = if pair == 0 {
                i
            } else {
                permute(i as u32, n as u32, (pair_seed >> 32) as u32) as usize
            };
            data[i * dim + 2 * pair] = u32_to_unit(sequence[j][0]);
            if two {
                data[i * dim + 2 * pair + 1] = u32_to_unit(sequence[j][1]);
            }
        }
    }
}
