//! Which construction the renderer's [`crate::Sampler`] draws from: the
//! renderer's view of the registry of kinds in `lueur-pointsets`, from which
//! it takes its names and its list.

use std::fmt;

use lueur_pointsets::PointSetKind;

/// How many kinds of the registry the renderer draws from.
const RENDERER_KIND_COUNT: usize = {
    let mut count = 0;
    let mut i = 0;
    while i < PointSetKind::ALL.len() {
        if SamplerKind::from_point_set(PointSetKind::ALL[i]).is_some() {
            count += 1;
        }
        i += 1;
    }
    count
};

/// The registry's list with the kinds the renderer cannot draw from left out.
const RENDERER_KINDS: [SamplerKind; RENDERER_KIND_COUNT] = {
    let mut kinds = [SamplerKind::Independent; RENDERER_KIND_COUNT];
    let (mut i, mut k) = (0, 0);
    while i < PointSetKind::ALL.len() {
        if let Some(kind) = SamplerKind::from_point_set(PointSetKind::ALL[i]) {
            kinds[k] = kind;
            k += 1;
        }
        i += 1;
    }
    kinds
};

/// Which construction a [`crate::Sampler`] draws from. An enum, dispatched by `match`,
/// because the set is closed and the call is in the innermost loop.
///
/// Except for the plain constructions ([`SamplerKind::Halton`],
/// [`SamplerKind::Sobol`]), every kind is randomized per pixel and per
/// dimension, and "padded" like pbrt-v4's samplers: each 1D or 2D request
/// is a fresh low-dimensional pattern over the pixel's sample indices,
/// decorrelated from the other requests by a scramble seed and an index
/// shuffle hashed from (seed, pixel, dimension), so that high dimensions do
/// not alias with low ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum SamplerKind {
    /// Independent uniform numbers from PCG32 (pbrt-v4 §8.3,
    /// `IndependentSampler`).
    Independent,
    /// Jittered sampling over the pixel's `spp` samples: a 2D request is one
    /// point per cell of the most square `columns x rows = spp` grid, a 1D
    /// request one per `1/spp` stratum; sample indices are assigned to
    /// strata by a random permutation per (pixel, dimension) (pbrt-v4 §8.5).
    Stratified,
    /// Latin hypercube over the pixel's `spp` samples (McKay, Beckman and
    /// Conover 1979): one sample per `1/spp` stratum in every dimension.
    Lhs,
    /// Correlated multi-jittered 2D patterns of `spp` points (Kensler 2013),
    /// one pattern per (pixel, dimension); 1D requests as
    /// [`SamplerKind::Stratified`].
    Cmj,
    /// The plain Halton sequence over sample indices, dimension `k` in the
    /// `k`-th prime base (wrapping after 1024), the same in every pixel.
    /// Unrandomized: its errors are correlated across pixels; here to be
    /// measured, not to be used.
    Halton,
    /// Halton, Owen-scrambled (nested random digit permutations) with a seed
    /// per (pixel, dimension).
    HaltonOwen,
    /// The plain Sobol' sequence over sample indices, dimension `k` of the
    /// Joe–Kuo table (wrapping after 256), the same in every pixel.
    /// Unrandomized, like [`SamplerKind::Halton`].
    Sobol,
    /// Sobol' (0, 2)-sequence per request, randomized by a digital XOR shift
    /// and an Owen-scrambled index shuffle per (pixel, dimension).
    ///
    /// The default: the lowest image MSE measured at 64 and 256 spp on the
    /// shipped scenes (`cargo xtask samplers`, docs/SAMPLERS.md), tied with
    /// `cmj`, and unlike `cmj` a sequence, so a render can be resumed or
    /// stopped by a time budget at any spp without losing its quality.
    #[default]
    SobolXor,
    /// Burley 2020's padded Owen-scrambled Sobol': each request is the first
    /// two Sobol' dimensions (a (0, 2)-sequence), Owen-scrambled with seeds
    /// hashed from (seed, pixel, dimension), its index shuffled by an Owen
    /// scramble, which keeps power-of-two prefixes (0, m, 2)-nets.
    SobolOwen,
    /// pbrt-v4's `ZSobolSampler` (Ahmed and Wonka 2020, "Screen-space blue
    /// noise sampling by ordered dithering"; pbrt-v4 §8.7.7): one global
    /// Owen-scrambled Sobol' sequence indexed by the Morton code of the pixel
    /// followed by the sample index, with base-4 digits randomly permuted,
    /// so neighbouring pixels get complementary points and the image error
    /// is blue noise.
    ZSobol,
    /// Roberts's R2 Kronecker sequence for 2D requests and the golden-ratio
    /// sequence for 1D requests, with a Cranley–Patterson rotation per
    /// (pixel, dimension), read at the sample index Owen-scrambled per
    /// (pixel, dimension) so that requests pair their points at random.
    R2,
    /// Progressive multi-jittered (0, 2) sequences (Christensen, Kensler and
    /// Kilpatrick 2018): each request reads one of a few shared pmj02 tables
    /// at the pixel's sample index permuted within its power-of-two level,
    /// chosen and randomized by a digital (XOR) shift per (pixel,
    /// dimension), which keeps every power-of-two prefix a (0, m, 2)-net,
    /// like pbrt-v4's `PMJ02BNSampler` (without its blue-noise pixel
    /// ordering). 1D requests take the x coordinate, a
    /// stratified (0, 1)-sequence. Tables hold 4096 samples; past them (or
    /// past `spp`), a new independent block starts.
    Pmj02,
}

impl SamplerKind {
    /// Every kind, in the order of the registry, [`PointSetKind::ALL`]
    /// (derived from it, so it cannot leave a kind out).
    pub const ALL: &'static [SamplerKind] = &RENDERER_KINDS;

    /// The construction of the registry this kind draws from.
    pub const fn point_set(&self) -> PointSetKind {
        match self {
            SamplerKind::Independent => PointSetKind::Independent,
            SamplerKind::Stratified => PointSetKind::Stratified,
            SamplerKind::Lhs => PointSetKind::LatinHypercube,
            SamplerKind::Cmj => PointSetKind::Cmj,
            SamplerKind::Halton => PointSetKind::Halton,
            SamplerKind::HaltonOwen => PointSetKind::HaltonOwen,
            SamplerKind::Sobol => PointSetKind::Sobol,
            SamplerKind::SobolXor => PointSetKind::SobolXor,
            SamplerKind::SobolOwen => PointSetKind::SobolOwen,
            SamplerKind::ZSobol => PointSetKind::ZSobol,
            SamplerKind::R2 => PointSetKind::R2,
            SamplerKind::Pmj02 => PointSetKind::Pmj02,
        }
    }

    /// The sampler kind that draws from construction `kind`, if the
    /// renderer has one: every construction but Poisson-disk sets, whose
    /// points are built all at once by relaxation and cannot be asked for
    /// one sample at a time.
    pub const fn from_point_set(kind: PointSetKind) -> Option<SamplerKind> {
        Some(match kind {
            PointSetKind::Independent => SamplerKind::Independent,
            PointSetKind::Stratified => SamplerKind::Stratified,
            PointSetKind::LatinHypercube => SamplerKind::Lhs,
            PointSetKind::Cmj => SamplerKind::Cmj,
            PointSetKind::Halton => SamplerKind::Halton,
            PointSetKind::HaltonOwen => SamplerKind::HaltonOwen,
            PointSetKind::Sobol => SamplerKind::Sobol,
            PointSetKind::SobolXor => SamplerKind::SobolXor,
            PointSetKind::SobolOwen => SamplerKind::SobolOwen,
            PointSetKind::ZSobol => SamplerKind::ZSobol,
            PointSetKind::R2 => SamplerKind::R2,
            PointSetKind::Pmj02 => SamplerKind::Pmj02,
            PointSetKind::PoissonDisk => return None,
        })
    }

    /// Whether a sample's value depends on the render's total spp: the
    /// patterns laid out over `spp` points (stratified, Latin hypercube,
    /// CMJ) and ZSobol's Morton index. Such a render can only be resumed or
    /// sharded with the same total spp; the sequences can be extended.
    pub fn depends_on_spp(&self) -> bool {
        matches!(
            self,
            SamplerKind::Stratified | SamplerKind::Lhs | SamplerKind::Cmj | SamplerKind::ZSobol
        )
    }

    /// The revision of the kind's construction, raised when a fix changes the
    /// values it gives (its golden digest), so that a checkpoint or shard
    /// made of the old values is never resumed or merged with new ones.
    /// pmj02 and r2 are at 2: their requests read their points in the same
    /// order, which moved a pixel's dimension pairs together.
    pub fn revision(&self) -> u32 {
        match self {
            SamplerKind::R2 | SamplerKind::Pmj02 => 2,
            _ => 1,
        }
    }

    /// Whether the kind is randomized (every kind but the plain Halton and
    /// Sobol' sequences): only then does a different seed give an
    /// independent point set, which is what replicates are made of.
    pub fn is_randomized(&self) -> bool {
        !matches!(self, SamplerKind::Halton | SamplerKind::Sobol)
    }

    /// One line on the construction, for `--help`.
    pub fn summary(&self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent uniform random numbers (PCG32)",
            SamplerKind::Stratified => "jittered strata over the total spp",
            SamplerKind::Lhs => "Latin hypercube over the total spp",
            SamplerKind::Cmj => "correlated multi-jittered (Kensler 2013) over the total spp",
            SamplerKind::Halton => "plain Halton sequence, unrandomized (to measure, not to use)",
            SamplerKind::HaltonOwen => "Halton sequence, Owen-scrambled per pixel",
            SamplerKind::Sobol => "plain Sobol' sequence, unrandomized (to measure, not to use)",
            SamplerKind::SobolXor => "Sobol' sequence, random digital shift (default)",
            SamplerKind::SobolOwen => "padded Owen-scrambled Sobol' (Burley 2020)",
            SamplerKind::ZSobol => {
                "pbrt-v4's ZSobol: blue-noise error across pixels; total spp fixed"
            }
            SamplerKind::R2 => "R2 Kronecker sequence, rotated per pixel",
            SamplerKind::Pmj02 => "progressive multi-jittered (0,2) sequences",
        }
    }

    /// The lowercase name used on command lines and in scene files: the
    /// registry's name of its construction.
    pub const fn name(&self) -> &'static str {
        self.point_set().name()
    }

    /// The kind called `s` (ASCII case-insensitive), if any.
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL
            .iter()
            .copied()
            .find(|kind| kind.name().eq_ignore_ascii_case(s))
    }
}

impl fmt::Display for SamplerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
