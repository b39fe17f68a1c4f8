//! How a film keeps one block's statistics: per slot (a pixel's replicate)
//! its count and mean, 16 bytes; and, with one replicate only, the sum of
//! squared deviations beside them, 12 bytes more. With several replicates
//! the variance of the mean is their spread, so the per-sample spread is
//! not kept: a 4K film of 2 replicates is 265 MB, not 464. The mean of a
//! merge does not depend on the squared deviations, so dropping them
//! changes no mean.

use std::ops::Range;

use glam::Vec3;

use super::{FilmError, PixelStats};

/// A slot's count and mean.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Slot {
    n: u32,
    mean: Vec3,
}

/// Every slot of one block, pixel-major.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Image {
    slots: Vec<Slot>,
    /// Per slot its sum of squared deviations; empty unless the film has
    /// one replicate.
    m2: Vec<Vec3>,
}

impl Image {
    pub(super) fn new(len: usize, replicates: u32) -> Image {
        Image {
            slots: vec![Slot::default(); len],
            m2: if replicates == 1 {
                vec![Vec3::ZERO; len]
            } else {
                Vec::new()
            },
        }
    }

    pub(super) fn len(&self) -> usize {
        self.slots.len()
    }

    #[inline]
    pub(super) fn get(&self, i: usize) -> PixelStats {
        stats(self.slots[i], self.m2.get(i))
    }

    #[inline]
    pub(super) fn set(&mut self, i: usize, s: PixelStats) {
        set(&mut self.slots[i], self.m2.get_mut(i), s);
    }

    /// Merges `later`'s slots into these, slot by slot.
    pub(super) fn merge_later(&mut self, later: &Image) {
        for i in 0..self.len() {
            self.set(i, self.get(i).merged(later.get(i)));
        }
    }

    /// The image cut into bands of `band_len` slots, for the tiles of a
    /// pass to write under their band's lock.
    pub(super) fn bands(&mut self, band_len: usize) -> impl Iterator<Item = Band<'_>> {
        let mut m2 = self.m2.chunks_mut(band_len);
        self.slots.chunks_mut(band_len).map(move |slots| Band {
            slots,
            m2: m2.next().unwrap_or_default(),
        })
    }
}

/// The slots of a band of rows of one image.
pub(super) struct Band<'a> {
    slots: &'a mut [Slot],
    m2: &'a mut [Vec3],
}

impl Band<'_> {
    #[inline]
    pub(super) fn get(&self, i: usize) -> PixelStats {
        stats(self.slots[i], self.m2.get(i))
    }

    #[inline]
    pub(super) fn set(&mut self, i: usize, s: PixelStats) {
        set(&mut self.slots[i], self.m2.get_mut(i), s);
    }
}

#[inline]
fn stats(slot: Slot, m2: Option<&Vec3>) -> PixelStats {
    PixelStats {
        n: slot.n,
        mean: slot.mean,
        m2: m2.copied().unwrap_or(Vec3::ZERO),
    }
}

#[inline]
fn set(slot: &mut Slot, m2: Option<&mut Vec3>, s: PixelStats) {
    *slot = Slot {
        n: s.n,
        mean: s.mean,
    };
    if let Some(m2) = m2 {
        *m2 = s.m2;
    }
}

/// One block's statistics as a film holds them, to read out (a checkpoint
/// saves them): slot `pixel * replicates + replicate`.
#[derive(Clone, Copy)]
pub struct BlockSlots<'a>(pub(super) &'a Image);

impl BlockSlots<'_> {
    /// The statistics of one slot; with several replicates the film keeps
    /// no sum of squared deviations, and `m2` reads as zero.
    pub fn slot(&self, i: usize) -> PixelStats {
        self.0.get(i)
    }

    /// Whether the sums of squared deviations are kept (one replicate).
    pub fn keeps_m2(&self) -> bool {
        !self.0.m2.is_empty()
    }
}

/// Where saved statistics of one block are decoded into a film (see
/// [`super::Film::append_decoded`]): straight into its image, or merged
/// into the block they are the later half of, so the block is never held
/// twice.
pub struct SlotFill<'a> {
    pub(super) image: &'a mut Image,
    /// Merge into the image's slots instead of writing them.
    pub(super) merge: bool,
    pub(super) samples: Range<u32>,
    /// One bit per slot: whether it was put.
    pub(super) written: Vec<u64>,
}

impl SlotFill<'_> {
    /// Slots to put: `width * height * replicates`.
    pub fn len(&self) -> usize {
        self.image.len()
    }

    /// Whether there is no slot to put.
    pub fn is_empty(&self) -> bool {
        self.image.len() == 0
    }

    /// Puts slot `i`'s statistics over the block. Refused for a slot out of
    /// range or put twice, and for statistics no block of this length can
    /// have (more samples than it, non-finite values, negative squares).
    pub fn put(&mut self, i: usize, s: PixelStats) -> Result<(), FilmError> {
        let len = self.samples.end.wrapping_sub(self.samples.start);
        let valid =
            s.n <= len && s.mean.is_finite() && s.m2.is_finite() && s.m2.min_element() >= 0.0;
        let bit = self.written.get(i / 64).map(|w| w >> (i % 64) & 1);
        if !valid || bit != Some(0) || i >= self.image.len() {
            return Err(FilmError::InvalidStats(self.samples.clone()));
        }
        self.written[i / 64] |= 1 << (i % 64);
        if self.merge {
            let earlier = self.image.get(i);
            self.image.set(i, earlier.merged(s));
        } else {
            self.image.set(i, s);
        }
        Ok(())
    }

    /// Whether every slot was put.
    pub(super) fn complete(&self) -> bool {
        let len = self.image.len();
        self.written.iter().enumerate().all(|(w, bits)| {
            let in_word = (len - w * 64).min(64);
            let want = if in_word == 64 {
                u64::MAX
            } else {
                (1u64 << in_word) - 1
            };
            *bits == want
        })
    }
}
