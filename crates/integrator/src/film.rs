//! The film: per-pixel statistics of the sample estimates, kept so that
//! any way of cutting a render into pieces gives the same numbers.
//!
//! A pixel's statistics over sample indices `a..b` are not a running
//! (Welford) sum in index order: that order would make the result of two
//! shards, `0..64` and `64..128`, differ in the last bits from one render
//! of `0..128`. Instead every *dyadic block* of indices (`k 2^j ..
//! (k+1) 2^j`) has one defined value, the merge (Chan, Golub and LeVeque
//! 1979) of its two halves' values, down to single samples; and a film over
//! `a..b` holds the values of the maximal dyadic blocks that tile `a..b`,
//! largest first (at most two per bit of `b - a`; one when `a..b` is
//! `0..2^k`). Whether the samples arrive in one pass, in pbrt's passes of
//! 1, 1, 2, 4, ..., after a resume or from shards rendered on different
//! machines, every block ends up with the same bits, so resuming and
//! merging are exact. (Pairwise merging is also more accurate than a
//! running sum, as pairwise summation is.)
//!
//! Memory is the other constraint (a 4K image of statistics is 232 MB):
//! a pass is merged in tile by tile as its tiles finish, never held as a
//! second image, and a film that nobody will extend can be *sealed* so
//! that its last pass folds the blocks into one image.

use std::ops::Range;
use std::sync::Mutex;

use glam::{UVec2, Vec3};
use smallvec::SmallVec;

use crate::replicates::PixelEstimate;

mod readout;

/// Mean and variance of one pixel's estimates over a set of samples, per
/// RGB channel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelStats {
    /// Number of finite estimates (NaN and infinite ones are dropped).
    pub n: u32,
    /// Mean of the estimates.
    pub mean: Vec3,
    /// Sum of squared deviations from the mean.
    pub m2: Vec3,
}

impl PixelStats {
    /// The statistics of one estimate: a single sample if it is finite,
    /// none if not (the caller counts the drop).
    #[inline]
    pub fn of_sample(x: Vec3) -> PixelStats {
        if x.is_finite() {
            PixelStats {
                n: 1,
                mean: x,
                m2: Vec3::ZERO,
            }
        } else {
            PixelStats::default()
        }
    }

    /// The statistics of the union of two disjoint sets of samples (Chan,
    /// Golub and LeVeque 1979, "Updating formulae and a pairwise algorithm
    /// for computing sample variances"). Not commutative in the last bits:
    /// `self` must be the earlier samples, so that every way of cutting a
    /// render gives the same film.
    #[inline]
    pub fn merged(self, later: PixelStats) -> PixelStats {
        if later.n == 0 {
            return self;
        }
        if self.n == 0 {
            return later;
        }
        let n = self.n + later.n;
        let w_later = later.n as f32 / n as f32;
        let delta = later.mean - self.mean;
        PixelStats {
            n,
            mean: self.mean + delta * w_later,
            m2: self.m2 + later.m2 + delta * delta * (self.n as f32 * w_later),
        }
    }

    /// Adds one estimate at the end (Welford's update, a merge with one
    /// sample). The caller has checked that it is finite.
    #[inline]
    pub fn add(&mut self, x: Vec3) {
        *self = self.merged(PixelStats::of_sample(x));
    }

    /// Unbiased sample variance of one estimate (zero below two samples).
    pub fn sample_variance(&self) -> Vec3 {
        if self.n < 2 {
            Vec3::ZERO
        } else {
            self.m2 / (self.n - 1) as f32
        }
    }

    /// Variance of the pixel mean: the squared standard error of the pixel.
    pub fn variance_of_mean(&self) -> Vec3 {
        if self.n < 2 {
            Vec3::ZERO
        } else {
            self.sample_variance() / self.n as f32
        }
    }
}

/// Whether `r` is a dyadic block: a power-of-two length that divides its
/// start.
pub fn is_dyadic(r: &Range<u32>) -> bool {
    let len = r.end.wrapping_sub(r.start);
    r.end > r.start && len.is_power_of_two() && r.start.is_multiple_of(len)
}

/// The maximal dyadic blocks that tile `r`, in order: the blocks a film
/// over `r` holds.
pub fn dyadic_blocks(r: Range<u32>) -> Vec<Range<u32>> {
    let mut blocks = Vec::new();
    let mut start = u64::from(r.start);
    let end = u64::from(r.end);
    while start < end {
        // The largest block that starts here (its length divides `start`)
        // and fits before `end`.
        let align = if start == 0 {
            1 << 32
        } else {
            1u64 << start.trailing_zeros()
        };
        let fits = 1u64 << (63 - (end - start).leading_zeros());
        let len = align.min(fits);
        blocks.push(start as u32..(start + len) as u32);
        start += len;
    }
    blocks
}

/// Whether `a` and `b` are the two halves of one dyadic block, `a` first.
pub(crate) fn siblings(a: &Range<u32>, b: &Range<u32>) -> bool {
    let len = a.end - a.start;
    a.end == b.start
        && b.end - b.start == len
        && len.is_power_of_two()
        && u64::from(a.start).is_multiple_of(2 * u64::from(len))
}

/// Why saved or merged statistics do not make a film.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FilmError {
    /// Films of different image sizes.
    #[error("films of different sizes: {0}x{1} and {2}x{3}")]
    SizeMismatch(u32, u32, u32, u32),
    /// Sample ranges that leave a gap or overlap.
    #[error("sample ranges do not follow each other: {0:?} then {1:?}")]
    NotContiguous(Range<u32>, Range<u32>),
    /// A block whose pixel count is not the image's.
    #[error("a block holds {0} pixels, the image has {1}")]
    PixelCount(usize, usize),
    /// A pixel with more samples than its block, or non-finite statistics.
    #[error("invalid statistics in block {0:?}")]
    InvalidStats(Range<u32>),
    /// Nothing to merge.
    #[error("no films to merge")]
    Empty,
    /// A film whose last pass was interrupted: some tiles hold more samples
    /// than others, so it has no single range to save, merge or extend.
    #[error(
        "the pass of samples {0:?} was interrupted after some tiles: the film is not a whole \
         number of samples per pixel"
    )]
    UnfinishedPass(Range<u32>),
    /// Films, or a film and a pass, with different replicate counts.
    #[error("a film of {0} replicates cannot take samples dealt into {1}")]
    Replicates(u32, u32),
    /// A film that merged its blocks into one image on reaching its end
    /// (see [`Film::sealed_at`]).
    #[error(
        "the film of samples {0:?} kept only its image: it cannot be saved, merged or extended"
    )]
    Sealed(Range<u32>),
}

/// A pass cancelled after some of its tiles were merged in: those tiles
/// hold the blocks of `after`, the others still those of the film's
/// `ranges`.
#[derive(Clone, Debug, PartialEq)]
struct UnfinishedPass {
    /// The pass's sample indices.
    samples: Range<u32>,
    /// The block ranges of the tiles that finished it.
    after: Vec<Range<u32>>,
    /// Side of the square tiles.
    tile: u32,
    /// Per tile, row-major: whether it finished the pass.
    done: Vec<bool>,
}

/// An image of per-pixel statistics over a range of sample indices,
/// row-major, row 0 at the top.
///
/// Passes are merged in tile by tile as the tiles finish (the film never
/// exists twice: at 4K one image of statistics is 232 MB). So a cancelled
/// pass leaves the tiles it finished with its samples and the others
/// without: an *unfinished* film, which can be looked at (every pixel still
/// holds a whole number of samples) but not saved, merged or extended.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    /// First sample index (0 unless the film is a shard).
    start: u32,
    /// Replicates per pixel (see `replicates.rs`): every image holds
    /// this many [`PixelStats`] per pixel, pixel-major. Taken from the
    /// first pass while the film is empty.
    replicates: u32,
    /// The [`dyadic_blocks`] of `start..end`, in order.
    ranges: Vec<Range<u32>>,
    /// Per block, every pixel's statistics over it. Holds more images than
    /// `ranges` while a pass is unfinished (those of its `after`).
    images: Vec<Vec<PixelStats>>,
    unfinished: Option<UnfinishedPass>,
    /// The pass that reaches this sample index folds the blocks into one
    /// image (see [`Film::sealed_at`]).
    seal_at: Option<u32>,
    /// Whether it has: `ranges` is then one block, not a dyadic tiling.
    sealed: bool,
}

/// How a pass's blocks join a film's: computed once from the ranges, then
/// applied to every pixel with the same merges, in the same order, as
/// [`Film::append`] applies to whole images.
#[derive(Clone, Debug)]
pub(crate) struct PassPlan {
    samples: Range<u32>,
    /// The pass's own blocks, as a tile delivers them.
    pass: Vec<Range<u32>>,
    /// The film's blocks below this position are not touched.
    keep: usize,
    /// Whether the blocks after the pass are folded into one image.
    seal: bool,
    before: Vec<Range<u32>>,
    after: Vec<Range<u32>>,
}

/// One block joined to a stack of blocks as a binary counter carries:
/// merged into the top when they are siblings, pushed otherwise, then the
/// top merged into the one below while they are siblings. Returns the
/// lowest position written.
fn join<T: Copy>(
    stack: &mut SmallVec<[(Range<u32>, T); 8]>,
    block: (Range<u32>, T),
    mut merge: impl FnMut(T, T) -> T,
) -> usize {
    let mut lowest = stack.len();
    match stack.last_mut() {
        Some(top) if siblings(&top.0, &block.0) => {
            top.0.end = block.0.end;
            top.1 = merge(top.1, block.1);
            lowest = stack.len() - 1;
        }
        _ => stack.push(block),
    }
    while stack.len() >= 2 && siblings(&stack[stack.len() - 2].0, &stack[stack.len() - 1].0) {
        let (range, later) = stack.pop().expect("two blocks");
        let below = stack.last_mut().expect("two blocks");
        below.0.end = range.end;
        below.1 = merge(below.1, later);
        lowest = lowest.min(stack.len() - 1);
    }
    lowest
}

impl PassPlan {
    /// The statistics of one pixel after the pass: `old(j)` is its value in
    /// the film's block `j` (for `j >= keep`), `pass[m]` its value over the
    /// pass's block `m`; `write(j, v)` receives the new value of block `j`
    /// for every `j >= keep`.
    #[inline]
    pub(crate) fn apply(
        &self,
        old: impl Fn(usize) -> PixelStats,
        pass: &[PixelStats],
        mut write: impl FnMut(usize, PixelStats),
    ) {
        let mut stack: SmallVec<[(Range<u32>, PixelStats); 8]> = (self.keep..self.before.len())
            .map(|j| (self.before[j].clone(), old(j)))
            .collect();
        for (range, stats) in self.pass.iter().zip(pass) {
            join(&mut stack, (range.clone(), *stats), PixelStats::merged);
        }
        if self.seal {
            // The fold `Film::pixel_at` would do on the blocks: the same
            // merges in the same order.
            write(
                0,
                stack
                    .into_iter()
                    .fold(PixelStats::default(), |acc, (_, b)| acc.merged(b)),
            );
            return;
        }
        debug_assert_eq!(stack.len() + self.keep, self.after.len());
        for (k, (_, stats)) in stack.into_iter().enumerate() {
            write(self.keep + k, stats);
        }
    }

    /// The pass's blocks, in order.
    pub(crate) fn pass_blocks(&self) -> &[Range<u32>] {
        &self.pass
    }
}

/// Where the tiles of a pass merge their pixels into the film, each under
/// the lock of its band of rows (a tile's pixels are not contiguous in a
/// row-major image; a band of `tile` rows is). A tile's commit takes
/// microseconds against its milliseconds of rendering, so the locks are
/// not contended.
pub(crate) struct PassSink<'a> {
    plan: &'a PassPlan,
    width: u32,
    tile: u32,
    replicates: usize,
    /// Per band of rows, per block from `plan.keep` on, the band's pixels.
    bands: Vec<Mutex<Vec<&'a mut [PixelStats]>>>,
}

impl PassSink<'_> {
    /// Merges a finished tile in: `blocks[m]` holds the tile's pixels
    /// (row-major, `size` wide, each its replicates' slots) over the
    /// pass's block `m`. Each slot joins the film's as one pixel does.
    pub(crate) fn commit(&self, origin: UVec2, size: UVec2, blocks: &[Vec<PixelStats>]) {
        let band = origin.y / self.tile;
        let mut images = self.bands[band as usize]
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        let mut pass: SmallVec<[PixelStats; 8]> = SmallVec::new();
        let k = self.replicates;
        for ty in 0..size.y {
            for (tx, r) in (0..size.x).flat_map(|tx| (0..k).map(move |r| (tx, r))) {
                let in_tile = (ty * size.x + tx) as usize * k + r;
                let i = ((origin.y % self.tile + ty) * self.width + origin.x + tx) as usize * k + r;
                pass.clear();
                pass.extend(blocks.iter().map(|b| b[in_tile]));
                let keep = self.plan.keep;
                let old: SmallVec<[PixelStats; 8]> = images.iter().map(|img| img[i]).collect();
                self.plan
                    .apply(|j| old[j - keep], &pass, |j, v| images[j - keep][i] = v);
            }
        }
    }
}

impl Film {
    /// An empty film, to be filled from sample index 0.
    pub fn new(width: u32, height: u32) -> Film {
        Film::starting_at(width, height, 0)
    }

    /// An empty film to be filled from sample index `start`: a shard of a
    /// render that other machines render the rest of.
    pub fn starting_at(width: u32, height: u32, start: u32) -> Film {
        Film {
            width,
            height,
            start,
            replicates: 1,
            ranges: Vec::new(),
            images: Vec::new(),
            unfinished: None,
            seal_at: None,
            sealed: false,
        }
    }

    /// The sample indices every pixel has seen (less any NaN or infinite
    /// sample, dropped and counted by the render): a film is a whole number
    /// of samples per pixel however its render was cut, except for the
    /// tiles that finished an interrupted pass (see
    /// [`Film::unfinished_pass`]), which hold more.
    pub fn samples(&self) -> Range<u32> {
        let end = self.ranges.last().map_or(self.start, |b| b.end);
        self.start..end
    }

    /// Samples per pixel that every pixel has.
    pub fn spp(&self) -> u32 {
        let r = self.samples();
        r.end - r.start
    }

    /// The interrupted pass's sample indices and the share of pixels that
    /// have them, if the last pass was cancelled after some of its tiles.
    pub fn unfinished_pass(&self) -> Option<(Range<u32>, f64)> {
        let u = self.unfinished.as_ref()?;
        let (w, h) = (self.width, self.height);
        let tiles_x = w.div_ceil(u.tile);
        let done: u64 = (0..u.done.len() as u32)
            .filter(|&t| u.done[t as usize])
            .map(|t| {
                let (x, y) = ((t % tiles_x) * u.tile, (t / tiles_x) * u.tile);
                u64::from((w - x).min(u.tile)) * u64::from((h - y).min(u.tile))
            })
            .sum();
        Some((
            u.samples.clone(),
            done as f64 / (f64::from(w) * f64::from(h)),
        ))
    }

    /// Each dyadic block of samples with every pixel's statistics over it,
    /// in order: the film's full state, what a checkpoint saves. A pixel
    /// is [`Film::replicates`] consecutive slots, one per replicate. Refused
    /// for a film whose last pass was interrupted.
    pub fn blocks(&self) -> Result<impl Iterator<Item = (Range<u32>, &[PixelStats])>, FilmError> {
        self.check_whole()?;
        Ok(self
            .ranges
            .iter()
            .zip(&self.images)
            .map(|(r, img)| (r.clone(), img.as_slice())))
    }

    fn check_whole(&self) -> Result<(), FilmError> {
        match &self.unfinished {
            Some(u) => Err(FilmError::UnfinishedPass(u.samples.clone())),
            None if self.sealed => Err(FilmError::Sealed(self.samples())),
            None => Ok(()),
        }
    }

    /// Declares that the film will only be looked at once it reaches sample
    /// index `end`, never saved or extended: the pass that reaches `end`
    /// merges the film's blocks into one image as its tiles commit. The
    /// image is bit-identical to the unsealed film's (both merge the same
    /// blocks in the same order), and it takes one image's memory whatever
    /// `end`, where a film of `0..24` otherwise holds two (`0..16` and
    /// `16..24`) for exact resumes and merges. A render without a
    /// checkpoint wants this.
    pub fn sealed_at(mut self, end: u32) -> Film {
        self.seal_at = Some(end);
        self
    }

    /// Whether the film has merged its blocks into one image (see
    /// [`Film::sealed_at`]).
    pub fn is_sealed(&self) -> bool {
        self.sealed
    }

    /// A film from saved blocks (a checkpoint or a shard): each block's
    /// sample range and its `width * height` pixels, row-major, each pixel
    /// its `replicates` slots (as [`Film::blocks`] gives them). Refused
    /// unless the ranges follow each other and every statistic is valid.
    /// Blocks that are not the maximal dyadic tiling of their range (saved
    /// by hand, say) are merged as they come: the film is still right, but
    /// adding to it is no longer bit-identical to rendering at once.
    pub fn from_blocks(
        width: u32,
        height: u32,
        start: u32,
        replicates: u32,
        blocks: Vec<(Range<u32>, Vec<PixelStats>)>,
    ) -> Result<Film, FilmError> {
        let mut film = Film::starting_at(width, height, start);
        film.replicates = replicates.max(1);
        for (samples, pixels) in blocks {
            film.append(samples, pixels)?;
        }
        Ok(film)
    }

    /// Appends the statistics of the samples that follow the film's (each
    /// pixel's, row-major), merging dyadic siblings as a binary counter
    /// carries (the whole-image form of [`PassPlan::apply`]).
    fn append(&mut self, samples: Range<u32>, pixels: Vec<PixelStats>) -> Result<(), FilmError> {
        let count = self.width as usize * self.height as usize * self.replicates as usize;
        if pixels.len() != count {
            return Err(FilmError::PixelCount(pixels.len(), count));
        }
        let len = samples.end.wrapping_sub(samples.start);
        let valid = pixels.iter().all(|p| {
            p.n <= len && p.mean.is_finite() && p.m2.is_finite() && p.m2.min_element() >= 0.0
        });
        if !valid {
            return Err(FilmError::InvalidStats(samples));
        }
        self.check_follows(&samples)?;
        let mut stack: SmallVec<[(Range<u32>, usize); 8]> =
            self.ranges.iter().cloned().zip(0..).collect();
        // Images are moved, not copied: the merges go into the earlier
        // image, as `PixelStats::merged` wants the earlier samples first.
        let mut incoming = Some(pixels);
        let images = &mut self.images;
        join(&mut stack, (samples, usize::MAX), |earlier, later| {
            let later_pixels = if later == usize::MAX {
                incoming.take().expect("merged once")
            } else {
                images.pop().expect("the later image is the last")
            };
            for (a, p) in images[earlier].iter_mut().zip(&later_pixels) {
                *a = a.merged(*p);
            }
            earlier
        });
        if let Some(pixels) = incoming {
            images.push(pixels);
        }
        self.ranges = stack.into_iter().map(|(r, _)| r).collect();
        debug_assert_eq!(self.ranges.len(), self.images.len());
        Ok(())
    }

    fn check_follows(&self, samples: &Range<u32>) -> Result<(), FilmError> {
        self.check_whole()?;
        if samples.start != self.samples().end || samples.end <= samples.start {
            return Err(FilmError::NotContiguous(self.samples(), samples.clone()));
        }
        Ok(())
    }

    /// Prepares a render pass over `samples`: the plan of its merges, and
    /// the images of the blocks it adds (empty until its tiles commit).
    pub(crate) fn begin_pass(
        &mut self,
        samples: Range<u32>,
        replicates: u32,
    ) -> Result<PassPlan, FilmError> {
        self.check_follows(&samples)?;
        if self.ranges.is_empty() {
            self.replicates = replicates.max(1);
        } else if self.replicates != replicates {
            return Err(FilmError::Replicates(self.replicates, replicates));
        }
        let pass = dyadic_blocks(samples.clone());
        let mut stack: SmallVec<[(Range<u32>, ()); 8]> =
            self.ranges.iter().map(|r| (r.clone(), ())).collect();
        let mut keep = self.ranges.len();
        for b in &pass {
            keep = keep.min(join(&mut stack, (b.clone(), ()), |_, _| ()));
        }
        let mut after: Vec<Range<u32>> = stack.into_iter().map(|(r, _)| r).collect();
        let seal = self.seal_at == Some(samples.end) && after.len() > 1;
        if seal {
            after = std::iter::once(self.start..samples.end).collect();
            keep = 0;
        }
        let count = self.width as usize * self.height as usize * self.replicates as usize;
        while self.images.len() < after.len() {
            self.images.push(vec![PixelStats::default(); count]);
        }
        Ok(PassPlan {
            samples,
            pass,
            keep,
            seal,
            before: self.ranges.clone(),
            after,
        })
    }

    /// Where the tiles of the pass `plan` (of `tile`-sized tiles) commit.
    pub(crate) fn pass_sink<'a>(&'a mut self, plan: &'a PassPlan, tile: u32) -> PassSink<'a> {
        let band_len = (self.width * tile) as usize * self.replicates as usize;
        let bands_count = self.height.div_ceil(tile) as usize;
        let mut bands: Vec<Vec<&mut [PixelStats]>> = (0..bands_count).map(|_| Vec::new()).collect();
        for image in self.images[plan.keep..].iter_mut() {
            for (band, pixels) in bands.iter_mut().zip(image.chunks_mut(band_len)) {
                band.push(pixels);
            }
        }
        PassSink {
            plan,
            width: self.width,
            tile,
            replicates: self.replicates as usize,
            bands: bands.into_iter().map(Mutex::new).collect(),
        }
    }

    /// Ends the pass `plan`: `done[t]` says whether tile `t` (row-major)
    /// committed. When all did, the film is whole again; when none did, it
    /// is as before the pass; otherwise it is unfinished.
    pub(crate) fn end_pass(&mut self, plan: PassPlan, tile: u32, done: Vec<bool>) {
        if done.iter().all(|&d| d) {
            self.images.truncate(plan.after.len());
            self.ranges = plan.after;
            self.sealed = plan.seal;
        } else if !done.iter().any(|&d| d) {
            self.images.truncate(plan.before.len());
        } else {
            self.unfinished = Some(UnfinishedPass {
                samples: plan.samples,
                after: plan.after,
                tile,
                done,
            });
        }
    }

    /// The blocks that pixel `i` holds.
    fn ranges_of(&self, i: usize) -> &[Range<u32>] {
        match &self.unfinished {
            None => &self.ranges,
            Some(u) => {
                let (x, y) = (i as u32 % self.width, i as u32 / self.width);
                let t = (y / u.tile) * self.width.div_ceil(u.tile) + x / u.tile;
                if u.done[t as usize] {
                    &u.after
                } else {
                    &self.ranges
                }
            }
        }
    }

    /// Pixel `i`'s estimate over all its samples: per replicate, its
    /// blocks merged in order.
    fn pixel_at(&self, i: usize) -> PixelEstimate {
        let k = self.replicates as usize;
        let blocks = self.ranges_of(i).len();
        let slot = |r: usize| {
            (0..blocks).fold(PixelStats::default(), |acc, j| {
                acc.merged(self.images[j][i * k + r])
            })
        };
        if k == 1 {
            return PixelEstimate::of_replicates(&[slot(0)]);
        }
        let slots: SmallVec<[PixelStats; 16]> = (0..k).map(slot).collect();
        PixelEstimate::of_replicates(&slots)
    }

    /// Replicates per pixel (see `replicates.rs`).
    pub fn replicates(&self) -> u32 {
        self.replicates
    }

    /// Merges films of consecutive sample ranges (shards of one render, in
    /// any order) into one. When each shard was rendered by lueur, the
    /// result is bit-identical to rendering their union at once.
    pub fn merge(mut shards: Vec<Film>) -> Result<Film, FilmError> {
        shards.sort_by_key(|f| f.start);
        let mut shards = shards.into_iter();
        let mut film = shards.next().ok_or(FilmError::Empty)?;
        film.check_whole()?;
        for shard in shards {
            shard.check_whole()?;
            if (shard.width, shard.height) != (film.width, film.height) {
                return Err(FilmError::SizeMismatch(
                    film.width,
                    film.height,
                    shard.width,
                    shard.height,
                ));
            }
            if film.ranges.is_empty() {
                film.replicates = shard.replicates;
            } else if shard.replicates != film.replicates && !shard.ranges.is_empty() {
                return Err(FilmError::Replicates(film.replicates, shard.replicates));
            }
            if shard.start != film.samples().end {
                return Err(FilmError::NotContiguous(film.samples(), shard.samples()));
            }
            for (samples, pixels) in shard.ranges.into_iter().zip(shard.images) {
                film.append(samples, pixels)?;
            }
        }
        Ok(film)
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Estimate of pixel (x, y) over all its samples.
    pub fn pixel(&self, x: u32, y: u32) -> PixelEstimate {
        self.pixel_at((y * self.width + x) as usize)
    }

    /// Statistics of every pixel over all its samples, row-major, computed
    /// as they are read (its blocks merged in order): looking at a film
    /// never copies it.
    pub fn pixels(&self) -> impl ExactSizeIterator<Item = PixelEstimate> + '_ {
        (0..self.width as usize * self.height as usize).map(|i| self.pixel_at(i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::replicates::BlockCounter;

    #[test]
    fn welford_matches_two_pass() {
        let xs = [1.0f32, 4.0, 2.5, 10.0, -3.0, 0.25];
        let mut s = PixelStats::default();
        for &x in &xs {
            s.add(Vec3::splat(x));
        }
        let mean = xs.iter().sum::<f32>() / xs.len() as f32;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / (xs.len() - 1) as f32;
        assert!((s.mean.x - mean).abs() < 1e-5);
        assert!((s.sample_variance().x - var).abs() < 1e-4);
        assert!((s.variance_of_mean().y - var / xs.len() as f32).abs() < 1e-4);
    }

    #[test]
    fn pairwise_merge_matches_two_pass() {
        let xs: Vec<f32> = (0..37)
            .map(|i| ((i * 7919) % 101) as f32 * 0.37 - 9.0)
            .collect();
        let mut counter = BlockCounter::new(1);
        for (i, &x) in xs.iter().enumerate() {
            counter.push(i as u32, PixelStats::of_sample(Vec3::splat(x)));
        }
        let ranges: Vec<_> = counter.blocks().map(|b| b.0.clone()).collect();
        assert_eq!(ranges, dyadic_blocks(0..37));
        let s = counter
            .blocks()
            .fold(PixelStats::default(), |a, b| a.merged(b.1[0]));
        let mean = xs.iter().map(|&x| f64::from(x)).sum::<f64>() / xs.len() as f64;
        let var = xs
            .iter()
            .map(|&x| (f64::from(x) - mean).powi(2))
            .sum::<f64>()
            / (xs.len() - 1) as f64;
        assert_eq!(s.n, 37);
        assert!((f64::from(s.mean.x) - mean).abs() < 1e-5 * mean.abs().max(1.0));
        assert!((f64::from(s.sample_variance().x) - var).abs() < 1e-5 * var);
    }

    #[test]
    fn dropped_samples_do_not_count() {
        let mut s = PixelStats::of_sample(Vec3::new(f32::NAN, 0.0, 0.0));
        assert_eq!(s.n, 0);
        s = s.merged(PixelStats::of_sample(Vec3::ONE));
        s = s.merged(PixelStats::of_sample(Vec3::splat(f32::INFINITY)));
        assert_eq!((s.n, s.mean), (1, Vec3::ONE));
    }

    #[test]
    fn one_sample_has_no_variance() {
        let mut s = PixelStats::default();
        s.add(Vec3::ONE);
        assert_eq!(s.variance_of_mean(), Vec3::ZERO);
    }

    #[test]
    fn dyadic_blocks_tile_any_range() {
        assert_eq!(dyadic_blocks(0..100), vec![0..64, 64..96, 96..100]);
        assert_eq!(dyadic_blocks(64..128), vec![64..128]);
        assert_eq!(dyadic_blocks(3..13), vec![3..4, 4..8, 8..12, 12..13]);
        assert_eq!(dyadic_blocks(0..u32::MAX).len(), 32);
        assert!(dyadic_blocks(5..5).is_empty());
        for a in 0..70u32 {
            for b in a..70 {
                let blocks = dyadic_blocks(a..b);
                let mut at = a;
                for r in &blocks {
                    assert!(is_dyadic(r), "{r:?}");
                    assert_eq!(r.start, at);
                    at = r.end;
                }
                assert_eq!(at, b);
                // Maximal: no two neighbours are the halves of one block.
                assert!(blocks.windows(2).all(|w| !siblings(&w[0], &w[1])));
            }
        }
    }

    fn film_of(samples: Range<u32>, value: impl Fn(u32) -> f32) -> Film {
        let mut film = Film::starting_at(1, 1, samples.start);
        for r in dyadic_blocks(samples) {
            let mut counter = BlockCounter::new(1);
            for i in r.clone() {
                counter.push(i, PixelStats::of_sample(Vec3::splat(value(i))));
            }
            for (range, stats) in counter.blocks() {
                film.append(range.clone(), stats.to_vec()).unwrap();
            }
        }
        film
    }

    #[test]
    fn any_cut_gives_the_same_bits() {
        let value = |i: u32| (i as f32 * 0.618_034).fract() * 10.0 + 1e3;
        let whole = film_of(0..100, value);
        assert_eq!(whole.blocks().unwrap().count(), 3);
        for cut in [1, 37, 64, 65, 99] {
            let parts = vec![film_of(cut..100, value), film_of(0..cut, value)];
            let merged = Film::merge(parts).unwrap();
            assert_eq!(merged, whole, "cut at {cut}");
        }
        let three = Film::merge(vec![
            film_of(0..10, value),
            film_of(10..50, value),
            film_of(50..100, value),
        ])
        .unwrap();
        assert_eq!(three, whole);
    }

    #[test]
    fn merge_refuses_gaps_and_overlaps() {
        let v = |_| 1.0;
        let gap = Film::merge(vec![film_of(0..8, v), film_of(9..16, v)]);
        assert!(matches!(gap, Err(FilmError::NotContiguous(..))));
        let overlap = Film::merge(vec![film_of(0..8, v), film_of(4..16, v)]);
        assert!(matches!(overlap, Err(FilmError::NotContiguous(..))));
        assert_eq!(Film::merge(vec![]), Err(FilmError::Empty));
        let other_size = Film::starting_at(2, 1, 8);
        assert!(matches!(
            Film::merge(vec![film_of(0..8, v), other_size]),
            Err(FilmError::SizeMismatch(..))
        ));
    }
}
