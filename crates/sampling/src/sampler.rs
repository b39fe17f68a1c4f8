//! The renderer-side sampler: uniform numbers as a pure function of
//! (seed, pixel, sample index, dimension).

use glam::Vec2;
use rand_pcg::Pcg32;
use rand_pcg::rand_core::Rng;

use lueur_pointsets::construct::{
    PMJ02_TABLE_LEN, PMJ02_TABLES, cmj, hash_key, hash2, hash2_keyed, mix64, permute,
    pmj02_table_point,
};
use lueur_pointsets::{
    HALTON_MAX_DIMENSIONS, SOBOL_MAX_DIMENSIONS, halton_base, nested_uniform_scramble,
    owen_scrambled_radical_inverse, radical_inverse, sobol_u32,
};

use crate::SamplerKind;
use crate::padded_sobol::padded_sobol;

/// Dimensions reserved per sample index: the PCG stream position of
/// `(sample_index, dimension)` is `sample_index * 65536 + dimension`, as in
/// pbrt-v4. A path using more dimensions than this would reuse numbers of the
/// next sample index.
pub const DIMENSIONS_PER_SAMPLE: u32 = 65536;

/// A deterministic source of uniform numbers for rendering.
///
/// Every value depends only on (kind, seed, image size, spp, pixel, sample
/// index, dimension, and whether it was asked by [`Sampler::next_1d`] or
/// [`Sampler::next_2d`]): [`Sampler::start_pixel_sample`] positions the
/// sampler, `next_1d` moves one dimension on and `next_2d` two. Threads may
/// therefore render pixels in any order and the image is bit-identical.
///
/// **Stability promise:** the numbers are pinned by the algorithm below and by
/// golden-value tests, not by a library's choice of default generator, so a
/// seed gives the same image tomorrow. For [`SamplerKind::Independent`]:
/// the stream is `h = mix(key ^ mix(seed + 0x9e3779b97f4a7c15))`, where
/// `key = pixel.x | pixel.y << 32` and `mix` is the splitmix64 finaliser; the
/// generator is `Pcg32::new(mix(h), h)` (PCG XSH-RR 64/32, `rand_pcg` 0.10),
/// advanced by `sample_index * 65536 + dimension`; a value is the top 24 bits
/// of the output times `2^-24`. Every kind's values are multiples of
/// `2^-24` in `[0, 1)`.
#[derive(Clone, Debug)]
pub struct Sampler {
    kind: SamplerKind,
    seed: u64,
    /// Independent randomizations the render's samples are dealt into
    /// (sample `i` is point `i / replicates` of randomization
    /// `i % replicates`), at least 1.
    replicates: u32,
    /// The randomization seed of the current sample's replicate: `seed`
    /// for replicate 0, hashed from it for the others.
    replicate_seed: u64,
    /// Points per replicate, at least 1: the size of the stratified
    /// patterns (the render's spp over the replicates, rounded up).
    spp: u32,
    /// `ceil(log2(spp))`, for ZSobol's Morton index.
    log2_spp: u32,
    /// Base-4 digits of ZSobol's Morton index (pbrt-v4's `nBase4Digits`).
    base4_digits: u32,
    pixel: [u32; 2],
    index: u32,
    dimension: u32,
    /// For the hashed kinds: `hash2(replicate_seed, pixel key)`, the part of every
    /// request's scramble seed ([`Sampler::sequence_hash`]) that a pixel sample shares,
    /// hashed once when it starts.
    pixel_hash: u64,
    /// The sample index `pixel_hash` and `replicate_seed` were made for (with `pixel`),
    /// `None` before any: a path's vertices start the same pixel sample again at each
    /// depth, and find them made.
    hashed_sample: Option<u32>,
    /// `index.reverse_bits()`, where the padded Sobol' kinds scramble it.
    reversed_index: u32,
    rng: Pcg32,
    /// For the independent kind: how far `rng` stands from the start of its pixel's
    /// stream (`u64::MAX` before any pixel), so that a later dimension of the same
    /// sample is reached by advancing the difference, not the whole way again.
    stream_position: u64,
    /// For the independent kind: the sample index `rng` last started in its pixel, with
    /// the generator's state at that sample's dimension 0 (`None` before any), from which
    /// any dimension of that sample, and the start of the next one, are reached in a few
    /// steps.
    sample_start: Option<(u32, u64)>,
}

/// The multiplier of the LCG under `rand_pcg`'s `Pcg32` (PCG's 64-bit default).
pub(crate) const PCG_MULTIPLIER: u64 = 6_364_136_223_846_793_005;

/// `(a, g)` such that `delta` steps of the LCG `s -> PCG_MULTIPLIER s + inc` take `s`
/// to `a s + g inc` (mod 2^64), whatever `inc`: Brown's jump ("Random Number Generation
/// with Arbitrary Strides", 1994), the one `Pcg32::advance` takes, with the increment
/// factored out (the jump's constant term is linear in it).
const fn lcg_jump(mut delta: u64) -> (u64, u64) {
    let (mut acc_mult, mut acc_plus) = (1u64, 0u64);
    let (mut cur_mult, mut cur_plus) = (PCG_MULTIPLIER, 1u64);
    while delta > 0 {
        if delta & 1 != 0 {
            acc_mult = acc_mult.wrapping_mul(cur_mult);
            acc_plus = acc_plus.wrapping_mul(cur_mult).wrapping_add(cur_plus);
        }
        cur_plus = cur_mult.wrapping_add(1).wrapping_mul(cur_plus);
        cur_mult = cur_mult.wrapping_mul(cur_mult);
        delta /= 2;
    }
    (acc_mult, acc_plus)
}

/// The jump from one sample's dimension 0 to the next's, made at compile time: the
/// independent kind's step from sample to sample of a pixel, which `Pcg32::advance`
/// would take in 16 rounds of its loop.
const SAMPLE_JUMP: (u64, u64) = lcg_jump(DIMENSIONS_PER_SAMPLE as u64);

/// The 64-bit key of a pixel that the per-pixel hashes start from.
#[inline]
fn pixel_key(pixel: [u32; 2]) -> u64 {
    u64::from(pixel[0]) | (u64::from(pixel[1]) << 32)
}

/// A 32-bit binary fraction as an `f32` in `[0, 1)`: its top 24 bits.
#[inline(always)]
pub(crate) fn fraction_to_f32(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// An `f64` in `[0, 1)` rounded down to a multiple of `2^-24`, so that the
/// `f32` can never round up to 1.
#[inline]
fn unit_to_f32(x: f64) -> f32 {
    ((x * 16_777_216.0) as u32).min((1 << 24) - 1) as f32 * (1.0 / 16_777_216.0)
}

/// The 64-bit fraction `x / 2^64` as an `f32` in `[0, 1)`.
#[inline]
fn fraction64_to_f32(x: u64) -> f32 {
    (x >> 40) as f32 * (1.0 / 16_777_216.0)
}

/// Interleaves the bits of `x` and `y` (`x` in the even bits): the Morton
/// code, Z-order.
#[inline]
fn morton2(x: u32, y: u32) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = u64::from(v);
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        (v | (v << 1)) & 0x5555_5555_5555_5555
    }
    spread(x) | (spread(y) << 1)
}

/// The 24 permutations of four base-4 digits (pbrt-v4's `ZSobolSampler`).
const PERMUTATIONS_4: [[u8; 4]; 24] = [
    [0, 1, 2, 3],
    [0, 1, 3, 2],
    [0, 2, 1, 3],
    [0, 2, 3, 1],
    [0, 3, 2, 1],
    [0, 3, 1, 2],
    [1, 0, 2, 3],
    [1, 0, 3, 2],
    [1, 2, 0, 3],
    [1, 2, 3, 0],
    [1, 3, 2, 0],
    [1, 3, 0, 2],
    [2, 1, 0, 3],
    [2, 1, 3, 0],
    [2, 0, 1, 3],
    [2, 0, 3, 1],
    [2, 3, 0, 1],
    [2, 3, 1, 0],
    [3, 1, 2, 0],
    [3, 1, 0, 2],
    [3, 2, 1, 0],
    [3, 2, 0, 1],
    [3, 0, 2, 1],
    [3, 0, 1, 2],
];

/// `hash_key(d)` of the first dimensions (every vertex of a path to depth 30), which every
/// request of a hashed kind hashes its pixel sample's seed with: made at compile time,
/// a load instead of a chain of two multiplications per request.
pub(crate) const DIMENSION_KEYS: [u64; 256] = {
    let mut keys = [0; 256];
    let mut d = 0;
    while d < keys.len() {
        keys[d] = hash_key(d as u64);
        d += 1;
    }
    keys
};

/// `hash_key(dimension)`, from [`DIMENSION_KEYS`] where it holds it.
#[inline]
fn dimension_key(dimension: u32) -> u64 {
    match DIMENSION_KEYS.get(dimension as usize) {
        Some(&key) => key,
        None => hash_key(u64::from(dimension)),
    }
}

/// Mixed into the seed of replicates past the first, so that their
/// randomizations are not those of another seed's replicate 0.
const REPLICATE_KEY: u64 = 0x7265_706c_6963_6174;

/// The golden-ratio increment `2^64 / phi` of the 1D Kronecker sequence
/// (Weyl's, the best-spread rank-1 sequence in 1D).
const GOLDEN_1D: u64 = 0x9e37_79b9_7f4a_7c15;

impl Sampler {
    /// A sampler of the given kind and seed for an image of unknown size and
    /// sample count, positioned at pixel (0, 0), sample 0, dimension 0.
    ///
    /// It assumes 1 sample per pixel and a 1x1 image: fine for
    /// [`SamplerKind::Independent`] and the sequences, but the stratified
    /// kinds then have a single stratum and [`SamplerKind::ZSobol`] gives
    /// overlapping sequences to neighbouring pixels. A renderer uses
    /// [`Sampler::for_image`].
    pub fn new(kind: SamplerKind, seed: u64) -> Self {
        Self::for_image(kind, seed, [1, 1], 1)
    }

    /// A sampler for an image of `resolution` pixels rendered with `spp`
    /// samples per pixel (0 counts as 1), positioned at pixel (0, 0), sample
    /// 0, dimension 0. Sample indices should stay below `spp`: past it the
    /// stratified kinds start a new, independent pattern, and ZSobol runs
    /// into the next pixel's samples (best with `spp` a power of two, for
    /// the Sobol' kinds). ZSobol indexes a 32-bit sequence, so it is meant
    /// for `width * height * spp <= 2^32` (rounded up to powers of 2 and 4).
    pub fn for_image(kind: SamplerKind, seed: u64, resolution: [u32; 2], spp: u32) -> Self {
        Self::for_render(kind, seed, resolution, spp, 1)
    }

    /// A sampler for a render of `spp` samples per pixel dealt into
    /// `replicates` independent randomizations (0 counts as 1): sample `i`
    /// is point `i / replicates` of randomization `i % replicates`, each
    /// randomization with its own scramble seeds and, for the kinds laid
    /// out over the spp, its own pattern of `ceil(spp / replicates)`
    /// points. With one replicate it is [`Sampler::for_image`]. The
    /// independent kind is the same for every count (its samples are
    /// independent already); the plain sequences have no randomization
    /// to replicate, and a renderer refuses more than one for them.
    pub fn for_render(
        kind: SamplerKind,
        seed: u64,
        resolution: [u32; 2],
        spp: u32,
        replicates: u32,
    ) -> Self {
        let replicates = replicates.max(1);
        let spp = spp.max(1).div_ceil(replicates);
        let log2_spp = spp
            .checked_next_power_of_two()
            .map_or(32, |p| p.trailing_zeros());
        let res = resolution[0].max(resolution[1]).max(1).next_power_of_two();
        let base4_digits = res.trailing_zeros() + log2_spp.div_ceil(2);
        let mut sampler = Self {
            kind,
            seed,
            replicates,
            replicate_seed: seed,
            spp,
            log2_spp,
            base4_digits,
            pixel: [0, 0],
            index: 0,
            dimension: 0,
            pixel_hash: 0,
            hashed_sample: None,
            reversed_index: 0,
            rng: Pcg32::new(0, 0),
            stream_position: u64::MAX,
            sample_start: None,
        };
        sampler.start_pixel_sample([0, 0], 0, 0);
        sampler
    }

    /// The kind this sampler was built with.
    pub fn kind(&self) -> SamplerKind {
        self.kind
    }

    /// The randomizations its samples are dealt into.
    pub fn replicates(&self) -> u32 {
        self.replicates
    }

    /// The seed this sampler was built with.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// For [`SamplerKind::Independent`], the generator where the sampler stands, as
    /// [`PcgLanes`](crate::PcgLanes) keeps a lane's: its state and increment. Its outputs
    /// in order are the current pixel sample's dimensions from the one the sampler
    /// stands at (each position of the stream is a step of the generator, so stepping it
    /// over dimensions no one reads reaches a later dimension). `None` for the other kinds.
    pub fn independent_generator(&self) -> Option<(u64, u64)> {
        (self.kind == SamplerKind::Independent)
            .then(|| (self.rng.state(), (self.rng.stream() << 1) | 1))
    }

    /// For the default kind, [`SamplerKind::SobolXor`]: the current pixel sample's hash and
    /// bit-reversed index, from which [`SobolXorLanes`](crate::SobolXorLanes) gives its
    /// numbers at any dimension. `None` for the other kinds.
    pub fn sobol_xor_sample(&self) -> Option<(u64, u32)> {
        (self.kind == SamplerKind::SobolXor).then_some((self.pixel_hash, self.reversed_index))
    }

    /// Positions the sampler so that the next value is dimension `dimension`
    /// of sample `sample_index` of `pixel` (pbrt-v4 `StartPixelSample`).
    pub fn start_pixel_sample(&mut self, pixel: [u32; 2], sample_index: u32, dimension: u32) {
        let same_pixel = self.pixel == pixel;
        self.pixel = pixel;
        self.dimension = dimension;
        if self.kind != SamplerKind::Independent {
            if same_pixel && self.hashed_sample == Some(sample_index) {
                return;
            }
            self.hashed_sample = Some(sample_index);
            if self.replicates > 1 {
                let replicate = sample_index % self.replicates;
                self.index = sample_index / self.replicates;
                self.replicate_seed = if replicate == 0 {
                    self.seed
                } else {
                    hash2(self.seed ^ REPLICATE_KEY, u64::from(replicate))
                };
            } else {
                self.index = sample_index;
            }
            self.pixel_hash = hash2(self.replicate_seed, pixel_key(pixel));
            self.reversed_index = self.index.reverse_bits();
        } else {
            self.index = sample_index;
            self.start_independent(same_pixel, sample_index, dimension);
        }
    }

    /// [`Sampler::start_pixel_sample`] for the independent kind, on the pixel's stream.
    /// Every position is reached from one the generator has stood at (an LCG's jumps
    /// compose exactly): a later dimension of the sample from where it stands, an
    /// earlier one from the sample's start, the next sample from this one's start by
    /// [`SAMPLE_JUMP`], and only a new pixel from the stream's beginning.
    #[inline]
    fn start_independent(&mut self, same_pixel: bool, sample_index: u32, dimension: u32) {
        let start = u64::from(sample_index) * u64::from(DIMENSIONS_PER_SAMPLE);
        let position = start + u64::from(dimension);
        let started = if same_pixel { self.sample_start } else { None };
        match started {
            Some((index, _)) if index == sample_index && self.stream_position <= position => {}
            Some((index, state)) if index == sample_index => {
                self.rng = Pcg32::from_state(state, self.rng.stream());
                self.stream_position = start;
            }
            Some((index, state)) if index.checked_add(1) == Some(sample_index) => {
                let stream = self.rng.stream();
                let (a, g) = SAMPLE_JUMP;
                let increment = (stream << 1) | 1;
                let state = a
                    .wrapping_mul(state)
                    .wrapping_add(g.wrapping_mul(increment));
                self.rng = Pcg32::from_state(state, stream);
                self.stream_position = start;
            }
            Some(_) if self.stream_position <= start => {
                self.rng.advance(start - self.stream_position);
                self.stream_position = start;
            }
            _ => {
                let key = pixel_key(self.pixel);
                let stream = mix64(key ^ mix64(self.seed.wrapping_add(0x9e37_79b9_7f4a_7c15)));
                // pbrt-v4's RNG::SetSequence(seq) is Pcg32::new(MixBits(seq), seq).
                self.rng = Pcg32::new(mix64(stream), stream);
                self.rng.advance(start);
                self.stream_position = start;
            }
        }
        if self.stream_position == start {
            self.sample_start = Some((sample_index, self.rng.state()));
        }
        self.rng.advance(position - self.stream_position);
        self.stream_position = position;
    }

    /// The next uniform number, in `[0, 1)`: a multiple of `2^-24`, so 1.0 is
    /// impossible.
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        if self.kind == SamplerKind::Independent {
            self.stream_position = self.stream_position.wrapping_add(1);
            return fraction_to_f32(self.rng.next_u32());
        }
        // The default kind inline, the others through `sample_1d`'s table.
        let value = if self.kind == SamplerKind::SobolXor {
            fraction_to_f32(self.padded_sobol::<1>()[0])
        } else {
            self.sample_1d()
        };
        self.dimension = self.dimension.wrapping_add(1);
        value
    }

    /// The next two uniform numbers (two dimensions, `x` first). For the
    /// structured kinds the pair is one point of a 2D pattern, which is why
    /// it is not the same as two calls of [`Sampler::next_1d`].
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        if self.kind == SamplerKind::Independent {
            let x = self.next_1d();
            let y = self.next_1d();
            return Vec2::new(x, y);
        }
        let value = if self.kind == SamplerKind::SobolXor {
            let [x, y] = self.padded_sobol::<2>();
            Vec2::new(fraction_to_f32(x), fraction_to_f32(y))
        } else {
            self.sample_2d()
        };
        self.dimension = self.dimension.wrapping_add(2);
        value
    }

    /// Moves `n` dimensions on without drawing them, leaving the sampler where `n` calls of
    /// [`Sampler::next_1d`] would (or `n / 2` of [`Sampler::next_2d`]): for the numbers of
    /// a fixed layout that a caller has no use for, whose hashing it then does not pay.
    #[inline]
    pub fn skip(&mut self, n: u32) {
        if self.kind == SamplerKind::Independent {
            for _ in 0..n {
                self.rng.next_u32();
            }
            self.stream_position = self.stream_position.wrapping_add(u64::from(n));
        } else {
            self.dimension = self.dimension.wrapping_add(n);
        }
    }

    /// The scramble seed of the current (pixel, dimension), and of the
    /// block of `spp` sample indices the current index is in, so that
    /// indices past `spp` start an independent pattern.
    #[inline]
    fn request_hash(&self) -> u64 {
        let block = self.index / self.spp;
        hash2(self.sequence_hash(self.dimension), u64::from(block))
    }

    /// Pixel-wide seed of `dimension`, without the index block: for the
    /// sequences, whose index is used whole. It is `hash3(replicate_seed, pixel key,
    /// dimension)`, its first step done once per pixel sample.
    #[inline]
    fn sequence_hash(&self, dimension: u32) -> u64 {
        hash2_keyed(self.pixel_hash, dimension_key(dimension))
    }

    /// Dimension `dimension` of the plain or scrambled Halton or Sobol'
    /// sequence at the current sample index.
    fn sequence_1d(&self, dimension: u32) -> f32 {
        let index = self.index;
        match self.kind {
            SamplerKind::Halton => unit_to_f32(radical_inverse(
                halton_base(dimension as usize % HALTON_MAX_DIMENSIONS),
                u64::from(index),
            )),
            SamplerKind::HaltonOwen => unit_to_f32(owen_scrambled_radical_inverse(
                halton_base(dimension as usize % HALTON_MAX_DIMENSIONS),
                u64::from(index),
                self.sequence_hash(dimension),
            )),
            _ => fraction_to_f32(sobol_u32(index, dimension as usize % SOBOL_MAX_DIMENSIONS)),
        }
    }

    /// The current sample's index within its pattern of `spp` points.
    #[inline]
    fn index_in_pattern(&self) -> u32 {
        self.index % self.spp
    }

    /// A stratified 1D value: stratum `permute(index)` of `spp`, jittered.
    #[inline]
    fn stratified_1d(&self) -> f32 {
        let h = self.request_hash();
        let stratum = permute(self.index_in_pattern(), self.spp, h as u32);
        let jitter = lueur_pointsets::construct::kensler_unit(stratum, (h >> 32) as u32);
        unit_to_f32((f64::from(stratum) + jitter) / f64::from(self.spp))
    }

    fn sample_1d(&self) -> f32 {
        match self.kind {
            SamplerKind::Independent => unreachable!("handled by next_1d"),
            SamplerKind::Stratified | SamplerKind::Lhs | SamplerKind::Cmj => self.stratified_1d(),
            SamplerKind::Halton | SamplerKind::HaltonOwen | SamplerKind::Sobol => {
                self.sequence_1d(self.dimension)
            }
            SamplerKind::SobolXor | SamplerKind::SobolOwen => {
                fraction_to_f32(self.padded_sobol::<1>()[0])
            }
            SamplerKind::ZSobol => fraction_to_f32(self.zsobol()[0]),
            SamplerKind::R2 => {
                let shift = self.sequence_hash(self.dimension);
                let i = self.kronecker_index(shift);
                fraction64_to_f32(shift.wrapping_add(i.wrapping_mul(GOLDEN_1D)))
            }
            SamplerKind::Pmj02 => fraction_to_f32(self.pmj02()[0]),
        }
    }

    fn sample_2d(&self) -> Vec2 {
        match self.kind {
            SamplerKind::Independent => unreachable!("handled by next_2d"),
            SamplerKind::Stratified => {
                let h = self.request_hash();
                let j = permute(self.index_in_pattern(), self.spp, h as u32);
                let [x, y] =
                    lueur_pointsets::construct::jittered_2d(j as usize, self.spp as usize, h);
                Vec2::new(unit_to_f32(x), unit_to_f32(y))
            }
            SamplerKind::Lhs => {
                let h = self.request_hash();
                let (i, n) = (self.index_in_pattern() as usize, self.spp as usize);
                Vec2::new(
                    unit_to_f32(lueur_pointsets::construct::latin_hypercube(i, n, 0, h)),
                    unit_to_f32(lueur_pointsets::construct::latin_hypercube(i, n, 1, h)),
                )
            }
            SamplerKind::Cmj => {
                let h = self.request_hash();
                let [x, y] = cmj(self.index_in_pattern(), self.spp, h as u32);
                Vec2::new(unit_to_f32(x), unit_to_f32(y))
            }
            SamplerKind::Halton | SamplerKind::HaltonOwen | SamplerKind::Sobol => {
                // Consecutive dimensions of one sequence.
                Vec2::new(
                    self.sequence_1d(self.dimension),
                    self.sequence_1d(self.dimension.wrapping_add(1)),
                )
            }
            SamplerKind::SobolXor | SamplerKind::SobolOwen => {
                let [x, y] = self.padded_sobol::<2>();
                Vec2::new(fraction_to_f32(x), fraction_to_f32(y))
            }
            SamplerKind::ZSobol => {
                let [x, y] = self.zsobol();
                Vec2::new(fraction_to_f32(x), fraction_to_f32(y))
            }
            SamplerKind::R2 => {
                let shift = self.sequence_hash(self.dimension);
                let i = self.kronecker_index(shift);
                let [ax, ay] = R2_INCREMENTS;
                Vec2::new(
                    fraction64_to_f32(shift.wrapping_add(i.wrapping_mul(ax))),
                    fraction64_to_f32(hash2(shift, 1).wrapping_add(i.wrapping_mul(ay))),
                )
            }
            SamplerKind::Pmj02 => {
                let [x, y] = self.pmj02();
                Vec2::new(fraction_to_f32(x), fraction_to_f32(y))
            }
        }
    }

    /// The index R2 reads for the request whose rotation is `shift`: the sample
    /// index Owen-scrambled per request, so that each request's points are
    /// paired with the others' at random. Read at the index itself, every
    /// request's `i`-th point is its rotation plus the same `i a`, and a pixel's
    /// dimension pairs would move together (1.7x the MSE of `cmj` at 256 spp on
    /// cornell-spheres). A Kronecker sequence's points at any run of consecutive
    /// indices are its first ones rotated, and the scramble maps each aligned
    /// block of `2^m` indices to another, so every power-of-two prefix keeps
    /// R2's spacing, whatever the total spp.
    #[inline]
    fn kronecker_index(&self, shift: u64) -> u64 {
        u64::from(nested_uniform_scramble(self.index, hash2(shift, 2) as u32))
    }

    /// The current sample of a pmj02 table: the index within the pixel's
    /// pattern of `spp`, permuted per request within its level, selects the
    /// point, and the pattern block (and, past the table's length, the table
    /// block) joins the hash that picks the table, the permutation and the
    /// XOR shift, so every block is an independent randomization.
    ///
    /// The permutation pairs each request's points with the others' at
    /// random, as pbrt-v4's `PMJ02BNSampler` permutes its index past its
    /// tables. Read at the index itself, every request's `j`-th point sits in
    /// the same place of the progressive construction (point 1 in the quadrant
    /// opposite point 0, and so on), up to the shift, and two requests that
    /// pick the same table differ by a shift alone, so a pixel's dimension
    /// pairs would move together (1.9x the MSE of `cmj` at 256 spp on
    /// cornell-spheres). Only the table's power-of-two prefixes are nets (not
    /// every aligned block), so the index is permuted within its level
    /// `[2^k, 2^(k+1))`: each prefix `[0, 2^m)` is the table's own, whatever
    /// the total spp.
    #[inline]
    fn pmj02(&self) -> [u32; 2] {
        const { assert!(PMJ02_TABLE_LEN.is_power_of_two()) };
        let j = self.index_in_pattern() as usize;
        let h = hash2(self.request_hash(), (j / PMJ02_TABLE_LEN) as u64);
        let table = (h % PMJ02_TABLES as u64) as usize;
        let j = (j % PMJ02_TABLE_LEN) as u32;
        // The level of `j`: `[2^k, 2^(k+1))`, or `{0}`.
        let level = if j == 0 { 0 } else { 1 << j.ilog2() };
        let index = level + permute(j - level, level.max(1), (h >> 32) as u32);
        let [x, y] = pmj02_table_point(table, index as usize);
        let shift = hash2(h, 0x0078_6f72);
        [x ^ shift as u32, y ^ (shift >> 32) as u32]
    }

    /// The first `N` (1 or 2) Sobol' dimensions at a shuffled index, randomized by XOR or
    /// Owen scrambling: [`padded_sobol`] at the current dimension.
    #[inline]
    fn padded_sobol<const N: usize>(&self) -> [u32; N] {
        let key = dimension_key(self.dimension);
        if self.kind == SamplerKind::SobolXor {
            padded_sobol::<N, false>(self.pixel_hash, self.reversed_index, key)
        } else {
            padded_sobol::<N, true>(self.pixel_hash, self.reversed_index, key)
        }
    }

    /// pbrt-v4's `ZSobolSampler::Get1D/Get2D`: Owen-scrambled Sobol' (0, 2)
    /// point at the randomly permuted Morton index, with scramble seeds
    /// depending on the dimension and seed only (the pixel enters through
    /// the index).
    #[inline]
    fn zsobol(&self) -> [u32; 2] {
        let index = self.zsobol_index() as u32;
        let h = hash2(self.replicate_seed, u64::from(self.dimension));
        [
            nested_uniform_scramble(sobol_u32(index, 0), h as u32),
            nested_uniform_scramble(sobol_u32(index, 1), (h >> 32) as u32),
        ]
    }

    /// pbrt-v4's `ZSobolSampler::GetSampleIndex`: the Morton index of
    /// (pixel, sample) with each base-4 digit permuted by one of the 24
    /// permutations, chosen by hashing the digits above it and the
    /// dimension. Nested like Owen scrambling, so the samples of a pixel
    /// stay an aligned block of the sequence (a net for power-of-two spp),
    /// while neighbouring pixels get complementary blocks.
    fn zsobol_index(&self) -> u64 {
        let morton =
            (morton2(self.pixel[0], self.pixel[1]) << self.log2_spp) | u64::from(self.index);
        let dimension_key = hash2(self.replicate_seed, u64::from(self.dimension));
        let odd = self.log2_spp & 1 == 1;
        let last_digit = u32::from(odd);
        let mut index = 0u64;
        for i in (last_digit..self.base4_digits).rev() {
            let shift = 2 * i - u32::from(odd);
            let digit = (morton >> shift) & 3;
            let higher = morton.checked_shr(shift + 2).unwrap_or(0);
            let p = (mix64(higher ^ dimension_key) >> 24) % 24;
            index |= u64::from(PERMUTATIONS_4[p as usize][digit as usize]) << shift;
        }
        if odd {
            let digit = morton & 1;
            index |= digit ^ (mix64((morton >> 1) ^ dimension_key) & 1);
        }
        index
    }
}

/// R2's increments `1/phi_2` and `1/phi_2^2` (`phi_2 = 1.3247179572...`,
/// the plastic number) as 64-bit fractions, computed to 60 digits (the
/// unit tests check them against `lueur_pointsets`' Newton iteration).
const R2_INCREMENTS: [u64; 2] = [0xc13f_a9a9_02a6_328f, 0x91e1_0da5_c79e_7b1c];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depends_on_spp_says_which_kinds_change_with_the_total() {
        // Resumed and sharded renders rely on it: a kind that claims not to
        // depend on the total spp must give the same values for the first
        // 16 samples of a 16-spp and of a 64-spp render.
        for &kind in SamplerKind::ALL {
            let values = |spp: u32| {
                let mut s = Sampler::for_image(kind, 5, [8, 8], spp);
                let mut v = Vec::new();
                for index in 0..16 {
                    s.start_pixel_sample([3, 5], index, 0);
                    v.push(s.next_2d());
                    v.push(Vec2::splat(s.next_1d()));
                }
                v
            };
            let same = values(16) == values(64);
            assert_eq!(same, !kind.depends_on_spp(), "{kind}");
        }
    }

    #[test]
    fn names_round_trip() {
        for &kind in SamplerKind::ALL {
            assert_eq!(SamplerKind::from_name(kind.name()), Some(kind));
            assert_eq!(kind.to_string(), kind.name());
        }
        assert_eq!(
            SamplerKind::from_name("Independent"),
            Some(SamplerKind::Independent)
        );
        assert_eq!(SamplerKind::from_name("ZSOBOL"), Some(SamplerKind::ZSobol));
        assert_eq!(SamplerKind::from_name("pmj02"), Some(SamplerKind::Pmj02));
        assert_eq!(SamplerKind::from_name("pmj02bn"), None);
        assert_eq!(SamplerKind::default(), SamplerKind::SobolXor);
    }

    #[test]
    fn kronecker_constants_match_newton() {
        let [x, y] = lueur_pointsets::construct::kronecker_increments(2)[..] else {
            panic!("two increments");
        };
        // The f64 route has 53 significant bits; the constants 64.
        for (constant, newton) in [(R2_INCREMENTS[0], x), (R2_INCREMENTS[1], y)] {
            assert!(
                constant.abs_diff(newton) < 1 << 12,
                "{constant:#x} {newton:#x}"
            );
        }
        let golden = lueur_pointsets::construct::kronecker_increments(1)[0];
        assert!(GOLDEN_1D.abs_diff(golden) < 1 << 12);
    }

    #[test]
    fn morton_interleaves_x_in_even_bits() {
        assert_eq!(morton2(0, 0), 0);
        assert_eq!(morton2(1, 0), 1);
        assert_eq!(morton2(0, 1), 2);
        assert_eq!(morton2(3, 5), 0b10_01_11);
        assert_eq!(morton2(u32::MAX, 0), 0x5555_5555_5555_5555);
    }

    #[test]
    fn dimension_offset_equals_consuming_values() {
        let mut a = Sampler::new(SamplerKind::Independent, 7);
        a.start_pixel_sample([3, 4], 5, 0);
        let values: Vec<f32> = (0..10).map(|_| a.next_1d()).collect();
        for (d, &v) in values.iter().enumerate() {
            a.start_pixel_sample([3, 4], 5, d as u32);
            assert_eq!(a.next_1d(), v);
        }
    }

    /// A sampler that moves along its pixel's stream (the next vertex of a path), back,
    /// to another sample or to another pixel gives, at every position, what a fresh
    /// sampler positioned there gives: the independent kind's short advances from where
    /// it stands are the jump from the stream's start.
    #[test]
    fn every_position_gives_the_fresh_samplers_values_whatever_came_before() {
        let moves: [([u32; 2], u32, u32); 11] = [
            ([3, 4], 5, 2),
            ([3, 4], 5, 300),
            ([3, 4], 5, 254),
            ([3, 4], 5, 10),
            ([3, 4], 5, 18),
            ([3, 4], 6, 2),
            ([3, 4], 5, 26),
            ([3, 4], 5, 4),
            ([9, 4], 5, 26),
            ([3, 4], 5, 34),
            ([3, 4], 63, 65_535),
        ];
        for (&kind, replicates) in SamplerKind::ALL.iter().flat_map(|k| [(k, 1), (k, 3)]) {
            let mut moving = Sampler::for_render(kind, 11, [16, 16], 64, replicates);
            for &(pixel, index, dimension) in &moves {
                let mut fresh = Sampler::for_render(kind, 11, [16, 16], 64, replicates);
                fresh.start_pixel_sample(pixel, index, dimension);
                moving.start_pixel_sample(pixel, index, dimension);
                for _ in 0..3 {
                    assert_eq!(
                        moving.next_1d().to_bits(),
                        fresh.next_1d().to_bits(),
                        "{kind:?} at {pixel:?}, sample {index}, dimension {dimension}"
                    );
                    assert_eq!(moving.next_2d(), fresh.next_2d(), "{kind:?}");
                }
            }
        }
    }

    /// Skipped numbers leave the sampler where drawing them would: the next request is
    /// the same, bit for bit, for every kind, 1D and 2D, across the dimension table's end.
    #[test]
    fn skipping_dimensions_lands_where_drawing_them_would() {
        for (&kind, replicates) in SamplerKind::ALL.iter().flat_map(|k| [(k, 1), (k, 2)]) {
            for (start, n) in [(0, 1), (2, 3), (10, 2), (253, 5), (400, 1)] {
                let mut drawn = Sampler::for_render(kind, 5, [8, 8], 16, replicates);
                let mut skipped = drawn.clone();
                drawn.start_pixel_sample([1, 2], 3, start);
                skipped.start_pixel_sample([1, 2], 3, start);
                for _ in 0..n {
                    drawn.next_1d();
                }
                skipped.skip(n);
                assert_eq!(
                    drawn.next_1d().to_bits(),
                    skipped.next_1d().to_bits(),
                    "{kind:?}"
                );
                assert_eq!(drawn.next_2d(), skipped.next_2d(), "{kind:?}");
            }
        }
    }
}
