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
//! Memory is the other constraint (a 4K image of statistics is 232 MB, or
//! 265 MB for 2 replicates: see `film/image.rs`):
//! a pass is merged in tile by tile as its tiles finish, never held as a
//! second image, and a film that nobody will extend can be *sealed* so
//! that its last pass folds the blocks into one image.

use std::ops::Range;
use std::sync::Mutex;

use glam::Vec3;
use smallvec::SmallVec;

use crate::replicates::PixelEstimate;

mod image;
mod pass;
mod readout;

use image::Image;
pub use image::{BlockSlots, SlotFill};
use pass::join;
pub(crate) use pass::{PassPlan, PassSink};

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
    /// A saved block that does not give every pixel's statistics.
    #[error("block {0:?} does not hold every pixel")]
    Incomplete(Range<u32>),
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
/// exists twice: at 4K one image of statistics is 232 MB, 265 MB with 2
/// replicates). So a cancelled pass leaves the tiles it finished with its
/// samples and the others without: an *unfinished* film, which can be looked at (every pixel still
/// holds a whole number of samples) but not saved, merged or extended.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    /// First sample index (0 unless the film is a shard).
    start: u32,
    /// Replicates per pixel (see `replicates.rs`): every image holds
    /// this many slots per pixel, pixel-major. Taken from the first pass
    /// while the film is empty.
    replicates: u32,
    /// The [`dyadic_blocks`] of `start..end`, in order.
    ranges: Vec<Range<u32>>,
    /// Per block, every pixel's statistics over it. Holds more images than
    /// `ranges` while a pass is unfinished (those of its `after`).
    images: Vec<Image>,
    unfinished: Option<UnfinishedPass>,
    /// The pass that reaches this sample index folds the blocks into one
    /// image (see [`Film::sealed_at`]).
    seal_at: Option<u32>,
    /// Whether it has: `ranges` is then one block, not a dyadic tiling.
    sealed: bool,
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
    pub fn blocks(&self) -> Result<impl Iterator<Item = (Range<u32>, BlockSlots<'_>)>, FilmError> {
        self.check_whole()?;
        Ok(self
            .ranges
            .iter()
            .zip(&self.images)
            .map(|(r, img)| (r.clone(), BlockSlots(img))))
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

    /// Appends one saved block (of a checkpoint or a shard) that follows
    /// the film's samples, its slots put by `fill` straight into the film:
    /// into a new image, or merged into the film's last block when the two
    /// are the halves of one dyadic block (then into nothing new at all),
    /// after which siblings merge as a binary counter carries, as a render
    /// does. `replicates` is the saved film's; an empty film takes it.
    /// Every slot must be put once. The film is consumed, since a failure
    /// may leave a block half merged. Saved blocks that are not the maximal
    /// dyadic tiling of their range (saved by hand, say) are merged as they
    /// come: the film is still right, but adding to it is no longer
    /// bit-identical to rendering at once.
    pub fn append_decoded<E: From<FilmError>>(
        mut self,
        samples: Range<u32>,
        replicates: u32,
        fill: impl FnOnce(&mut SlotFill<'_>) -> Result<(), E>,
    ) -> Result<Film, E> {
        self.check_follows(&samples)?;
        let replicates = replicates.max(1);
        if self.ranges.is_empty() {
            self.replicates = replicates;
        } else if self.replicates != replicates {
            return Err(FilmError::Replicates(self.replicates, replicates).into());
        }
        let count = self.width as usize * self.height as usize * self.replicates as usize;
        let later_half = self
            .ranges
            .last()
            .is_some_and(|top| siblings(top, &samples));
        if !later_half {
            self.images.push(Image::new(count, self.replicates));
        }
        let mut slots = SlotFill {
            image: self.images.last_mut().expect("an image to fill"),
            merge: later_half,
            samples: samples.clone(),
            written: vec![0; count.div_ceil(64)],
        };
        fill(&mut slots)?;
        if !slots.complete() {
            return Err(FilmError::Incomplete(samples).into());
        }
        match self.ranges.last_mut() {
            Some(top) if later_half => top.end = samples.end,
            _ => self.ranges.push(samples),
        }
        self.carry();
        Ok(self)
    }

    /// Appends a block of another film that follows this film's samples,
    /// merging dyadic siblings as a binary counter carries (the
    /// whole-image form of [`PassPlan::apply`]). The image is moved, not
    /// copied: merges go into the earlier image, as `PixelStats::merged`
    /// wants the earlier samples first.
    fn append(&mut self, samples: Range<u32>, pixels: Image) -> Result<(), FilmError> {
        let count = self.width as usize * self.height as usize * self.replicates as usize;
        if pixels.len() != count {
            return Err(FilmError::PixelCount(pixels.len(), count));
        }
        self.check_follows(&samples)?;
        match self.ranges.last_mut() {
            Some(top) if siblings(top, &samples) => {
                self.images
                    .last_mut()
                    .expect("one image per block")
                    .merge_later(&pixels);
                top.end = samples.end;
            }
            _ => {
                self.ranges.push(samples);
                self.images.push(pixels);
            }
        }
        self.carry();
        Ok(())
    }

    /// Merges the last block into the one below while they are siblings.
    fn carry(&mut self) {
        while let [.., below, top] = self.ranges.as_slice()
            && siblings(below, top)
        {
            let later = self.images.pop().expect("one image per block");
            self.images
                .last_mut()
                .expect("one image per block")
                .merge_later(&later);
            let end = self.ranges.pop().expect("two blocks").end;
            self.ranges.last_mut().expect("two blocks").end = end;
        }
        debug_assert_eq!(self.ranges.len(), self.images.len());
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
            self.images.push(Image::new(count, self.replicates));
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
        let mut bands: Vec<Vec<image::Band<'_>>> = (0..bands_count).map(|_| Vec::new()).collect();
        for image in self.images[plan.keep..].iter_mut() {
            for (band, pixels) in bands.iter_mut().zip(image.bands(band_len)) {
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
                acc.merged(self.images[j].get(i * k + r))
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
mod tests;
