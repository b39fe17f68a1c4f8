//! A render pass's side of the film: the plan of how its blocks join the
//! film's, and the sink its tiles commit their pixels into.

use std::ops::Range;
use std::sync::Mutex;

use glam::UVec2;
use smallvec::SmallVec;

use super::{PixelStats, image, siblings};

/// How a pass's blocks join a film's: computed once from the ranges, then
/// applied to every pixel with the same merges, in the same order, as
/// [`Film::append`] applies to whole images.
#[derive(Clone, Debug)]
pub(crate) struct PassPlan {
    pub(super) samples: Range<u32>,
    /// The pass's own blocks, as a tile delivers them.
    pub(super) pass: Vec<Range<u32>>,
    /// The film's blocks below this position are not touched.
    pub(super) keep: usize,
    /// Whether the blocks after the pass are folded into one image.
    pub(super) seal: bool,
    pub(super) before: Vec<Range<u32>>,
    pub(super) after: Vec<Range<u32>>,
}

/// One block joined to a stack of blocks as a binary counter carries:
/// merged into the top when they are siblings, pushed otherwise, then the
/// top merged into the one below while they are siblings. Returns the
/// lowest position written.
pub(super) fn join<T: Copy>(
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
    pub(super) plan: &'a PassPlan,
    pub(super) width: u32,
    pub(super) tile: u32,
    pub(super) replicates: usize,
    /// Per band of rows, per block from `plan.keep` on, the band's pixels.
    pub(super) bands: Vec<Mutex<Vec<image::Band<'a>>>>,
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
                let old: SmallVec<[PixelStats; 8]> = images.iter().map(|img| img.get(i)).collect();
                self.plan
                    .apply(|j| old[j - keep], &pass, |j, v| images[j - keep].set(i, v));
            }
        }
    }
}
