//! The render loop: tiles in parallel, samples in order within a pixel.

use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use glam::UVec2;
use lueur_sampling::Sampler;
use lueur_sdf_math::SimdLevel;
use rayon::prelude::*;

use crate::RayCounters;
use crate::film::{Film, PixelStats};
use crate::lane_wave::{LaneScratch, LaneWave, radiance_lanes};
use crate::path::{Estimator, SampleId, WaveScratch, radiance_wave};
use crate::replicates::BlockCounter;
use crate::stages::StageTimes;
use crate::strategy::CAMERA_DIMS;
use crate::surface::March;
use crate::trace::Tracing;
use lueur_scene::{RenderError, RenderSettings};

use crate::PreparedScene;

/// Side of the square tiles the image is cut into. Small enough that both
/// cores stay busy to the end, large enough that scheduling is negligible.
const TILE: u32 = 16;

/// What a render measured about itself.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Per kind of ray: rays, steps, hits, misses, step-cap give-ups.
    pub rays: RayCounters,
    /// Thread time per stage of the wave of paths, summed over threads.
    pub stages: StageTimes,
    /// Samples that were NaN or infinite and were not added to the film.
    pub dropped_samples: u64,
    /// Samples added to the film.
    pub samples: u64,
    /// Wall-clock time of the render.
    pub elapsed: Duration,
    /// Time the threads spent merging finished tiles into the film (summed
    /// over threads, like the tracing time).
    pub film_time: Duration,
    /// Threads the render ran on (of the rayon pool in force).
    pub threads: usize,
    /// The instruction set the ray streams ran on (`None` before any pass).
    pub simd: Option<SimdLevel>,
    /// Whether the paths were kept in lanes from vertex to vertex (`Execution::lane_wave`).
    pub lane_wave: bool,
}

impl RenderStats {
    /// Adds another pass's statistics (times add up too).
    pub fn merge(&mut self, other: &RenderStats) {
        self.rays.merge(&other.rays);
        self.stages.merge(&other.stages);
        self.dropped_samples += other.dropped_samples;
        self.samples += other.samples;
        self.elapsed += other.elapsed;
        self.film_time += other.film_time;
        self.threads = self.threads.max(other.threads);
        self.simd = self.simd.or(other.simd);
        self.lane_wave |= other.lane_wave;
    }
}

/// A finished render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOutput {
    /// Per-pixel mean and variance.
    pub film: Film,
    /// What it cost.
    pub stats: RenderStats,
}

/// Renders `scene` in one pass of `settings.spp` samples per pixel.
/// `progress` is called after each tile with the number of pixel samples
/// just finished (the library never prints; the caller draws bars).
///
/// Runs on the current rayon thread pool: wrap the call in
/// `ThreadPool::install` to choose the thread count. The image does not
/// depend on it: each random number depends only on (pixel, sample index,
/// dimension, seed), and each pixel merges its samples in a fixed tree (see
/// `film.rs`).
pub fn render(
    scene: &PreparedScene,
    settings: &RenderSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<RenderOutput, RenderError> {
    let mut film = Film::new(settings.width, settings.height);
    let pass = render_pass(
        scene,
        settings,
        &mut film,
        settings.spp,
        &AtomicBool::new(false),
        progress,
    )?;
    debug_assert!(pass.complete, "a render that cannot be cancelled completes");
    Ok(RenderOutput {
        film,
        stats: pass.stats,
    })
}

/// What one pass did.
#[derive(Clone, Debug, PartialEq)]
pub struct Pass {
    /// What it cost and measured (of the tiles it finished).
    pub stats: RenderStats,
    /// Whether every tile finished: false when it was cancelled.
    pub complete: bool,
}

/// Adds sample indices `film.samples().end..until` to every pixel of
/// `film`: one pass of a progressive render, or one shard's part of a
/// render (a film made by [`Film::starting_at`]). Every way of cutting
/// `0..spp` into passes and shards gives the bit-identical film (see
/// `film.rs`), and the image does not depend on the thread
/// count either.
///
/// `settings.spp` is the spp of the whole render: some samplers lay their
/// patterns out over it, so shards must share it; `until` may not pass it.
///
/// Each tile is merged into the film as soon as it finishes, so the film
/// never exists twice. `cancel` is polled before every pixel; once it is
/// set, no tile starts or finishes, and the pass returns with `complete`
/// false: the film keeps the tiles finished before the signal (it is then
/// [unfinished](Film::unfinished_pass) and can be written out but not
/// extended), or is left exactly as it was if there were none.
pub fn render_pass(
    scene: &PreparedScene,
    settings: &RenderSettings,
    film: &mut Film,
    until: u32,
    cancel: &AtomicBool,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Pass, RenderError> {
    let whole = PixelBounds::whole(settings.width, settings.height);
    render_pass_in(scene, settings, whole, film, until, cancel, progress)
}

/// A rectangle of the image's pixels: columns `x0..x1`, rows `y0..y1`
/// (pbrt-v4's pixel bounds), row 0 at the top.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelBounds {
    /// First column.
    pub x0: u32,
    /// Column after the last.
    pub x1: u32,
    /// First row.
    pub y0: u32,
    /// Row after the last.
    pub y1: u32,
}

impl PixelBounds {
    /// Every pixel of a `width` x `height` image.
    pub fn whole(width: u32, height: u32) -> PixelBounds {
        PixelBounds {
            x0: 0,
            x1: width,
            y0: 0,
            y1: height,
        }
    }

    /// Columns covered.
    pub fn width(&self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }

    /// Rows covered.
    pub fn height(&self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }
}

/// [`render_pass`] over the pixels `bounds` of the image only, into a film
/// of their size (a crop): each pixel is bit-identical to the same pixel
/// of the whole image's film, since the sampler and the camera see the
/// whole image's pixel coordinates and resolution.
pub fn render_pass_in(
    scene: &PreparedScene,
    settings: &RenderSettings,
    bounds: PixelBounds,
    film: &mut Film,
    until: u32,
    cancel: &AtomicBool,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Pass, RenderError> {
    settings.validate()?;
    if bounds.width() == 0
        || bounds.height() == 0
        || bounds.x1 > settings.width
        || bounds.y1 > settings.height
    {
        return Err(RenderError::InvalidSetting(
            "the pixel bounds must be a non-empty part of the image",
        ));
    }
    let (w, h) = (bounds.width(), bounds.height());
    if film.width() != w || film.height() != h {
        return Err(RenderError::InvalidSetting(
            "the film's size differs from the pixel bounds'",
        ));
    }
    if film.unfinished_pass().is_some() {
        return Err(RenderError::InvalidSetting(
            "the film's last pass was interrupted: it cannot be extended",
        ));
    }
    let from = film.samples().end;
    if until <= from || until > settings.spp {
        return Err(RenderError::InvalidSetting(
            "a pass must add samples, and stop at or before the render's spp",
        ));
    }
    let start = Instant::now();
    let mut estimator = Estimator {
        scene,
        settings,
        march: March::new(scene, settings),
        tracing: Tracing {
            marching: settings.marching,
            simd: Some(scene.execution().simd)
                .filter(|level| level.is_available())
                .unwrap_or_else(SimdLevel::detect),
        },
        lanes: None,
    };
    let lane_wave = scene
        .execution()
        .lane_wave
        .then(|| LaneWave::of(&estimator))
        .flatten();
    estimator.lanes = lane_wave.as_ref();
    let tiles_x = w.div_ceil(TILE);
    let tiles: Vec<UVec2> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..tiles_x).map(move |tx| UVec2::new(tx * TILE, ty * TILE)))
        .collect();

    let plan = film
        .begin_pass(from..until, settings.replicate_count())
        .map_err(|_| {
            RenderError::InvalidSetting(
                "the film holds another number of replicates than the settings",
            )
        })?;
    let sink = film.pass_sink(&plan, TILE);
    let scratch = ScratchPool::default();
    // One tile per job: rayon's adaptive split would otherwise hand each thread runs of
    // up to a quarter of the tiles as one job it cannot share, and a pass would end with a
    // thread idle for several tiles (docs/PERFORMANCE.md, "The progressive passes").
    let results: Vec<Option<TileCost>> = tiles
        .par_iter()
        .with_max_len(1)
        .map(|&origin| {
            let r = scratch.lend(|scratch| {
                render_tile(
                    &estimator,
                    (bounds, origin),
                    plan.pass_blocks(),
                    cancel,
                    scratch,
                )
            })?;
            // Checked again so that no tile commits after the signal has
            // been seen: what an interrupt writes is what was there then.
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let film_start = Instant::now();
            sink.commit(origin, UVec2::new(r.width, r.height), &r.blocks);
            let film_time = film_start.elapsed();
            progress(u64::from(r.width * r.height) * u64::from(until - from));
            // The tile's statistics are in the film now; keeping them until
            // the pass ends would hold the pass twice.
            Some(TileCost {
                samples: r.blocks.iter().flatten().map(|p| u64::from(p.n)).sum(),
                counters: r.counters,
                stages: r.stages,
                dropped: r.dropped,
                film_time,
            })
        })
        .collect();
    drop(sink);

    let mut stats = RenderStats::default();
    for r in results.iter().flatten() {
        stats.rays.merge(&r.counters);
        stats.stages.merge(&r.stages);
        stats.dropped_samples += r.dropped;
        stats.samples += r.samples;
        stats.film_time += r.film_time;
    }
    let done: Vec<bool> = results.iter().map(Option::is_some).collect();
    let complete = done.iter().all(|&d| d);
    film.end_pass(plan, TILE, done);
    stats.threads = rayon::current_num_threads();
    stats.simd = Some(estimator.tracing.simd);
    stats.lane_wave = estimator.lanes.is_some();
    stats.elapsed = start.elapsed();
    Ok(Pass { stats, complete })
}

/// One tile's statistics after a pass, and what the pass cost there.
struct TileResult {
    width: u32,
    height: u32,
    /// Per dyadic block of the pass's samples, the tile's pixels over it,
    /// row-major.
    blocks: Vec<Vec<PixelStats>>,
    counters: RayCounters,
    stages: StageTimes,
    dropped: u64,
}

/// What a finished tile cost, once its statistics are in the film.
struct TileCost {
    samples: u64,
    counters: RayCounters,
    stages: StageTimes,
    dropped: u64,
    /// Time spent merging the tile into the film.
    film_time: Duration,
}

/// A tile's statistics as its estimates arrive, pixel after pixel and in sample order
/// within a pixel.
struct TileSink {
    /// Per dyadic block of the pass, the tile's finished pixels over it.
    blocks: Vec<Vec<PixelStats>>,
    /// The blocks of the pixel being filled.
    counter: BlockCounter,
    pixel: Option<[u32; 2]>,
    dropped: u64,
}

impl TileSink {
    fn push(&mut self, id: SampleId, l: glam::Vec3) {
        if self.pixel != Some(id.pixel) {
            self.end_pixel();
            self.pixel = Some(id.pixel);
        }
        if !l.is_finite() {
            self.dropped += 1;
        }
        self.counter.push(id.index, PixelStats::of_sample(l));
    }

    /// Moves the pixel being filled, if any, to the blocks.
    fn end_pixel(&mut self) {
        if self.pixel.take().is_none() {
            return;
        }
        debug_assert_eq!(self.counter.blocks().count(), self.blocks.len());
        for (block, (_, slots)) in self.blocks.iter_mut().zip(self.counter.blocks()) {
            block.extend_from_slice(slots);
        }
        self.counter.clear();
    }
}

/// A thread's buffers for rendering a tile: everything its wave's paths are traced and
/// shaded with. Cleared before use, so what they held never reaches an image.
#[derive(Default)]
struct TileScratch {
    wave: WaveScratch,
    lanes: LaneScratch,
}

/// The [`TileScratch`]es of a pass, lent to one tile at a time, so that a thread
/// allocates and grows its buffers once a pass rather than once a tile (at 16x16 pixels
/// and a few samples a pixel, a tile's own work is not much larger than growing them).
#[derive(Default)]
struct ScratchPool(Mutex<Vec<TileScratch>>);

impl ScratchPool {
    /// Runs `f` with a scratch no other tile holds, and takes it back after.
    fn lend<T>(&self, f: impl FnOnce(&mut TileScratch) -> T) -> T {
        // A poisoned pool is a panic elsewhere, already on its way out: lend a fresh one.
        let taken = self.0.lock().ok().and_then(|mut pool| pool.pop());
        let mut scratch = taken.unwrap_or_default();
        let out = f(&mut scratch);
        if let Ok(mut pool) = self.0.lock() {
            pool.push(scratch);
        }
        out
    }
}

/// The tile at `origin` of the film of `bounds`; `None` when cancelled.
fn render_tile(
    estimator: &Estimator<'_>,
    (bounds, origin): (PixelBounds, UVec2),
    pass_blocks: &[Range<u32>],
    cancel: &AtomicBool,
    scratch: &mut TileScratch,
) -> Option<TileResult> {
    let samples = pass_blocks[0].start..pass_blocks[pass_blocks.len() - 1].end;
    let settings = estimator.settings;
    let (w, h) = (settings.width, settings.height);
    let (tw, th) = (
        (bounds.width() - origin.x).min(TILE),
        (bounds.height() - origin.y).min(TILE),
    );
    // Pixels are named by their place in the whole image.
    let origin = origin + UVec2::new(bounds.x0, bounds.y0);
    let replicates = settings.replicate_count();
    let mut sampler = Sampler::for_render(
        settings.sampler,
        settings.seed,
        [w, h],
        settings.spp,
        replicates,
    );
    let block_count = pass_blocks.len();
    let mut tile = TileSink {
        blocks: vec![Vec::with_capacity((tw * th * replicates) as usize); block_count],
        counter: BlockCounter::new(replicates),
        pixel: None,
        dropped: 0,
    };
    let mut counters = RayCounters::default();
    let mut stages = StageTimes::default();
    let wave = estimator.scene.execution().wave.max(1);
    let camera = &estimator.scene.scene().camera;
    let pixels =
        (origin.y..origin.y + th).flat_map(|y| (origin.x..origin.x + tw).map(move |x| [x, y]));
    let mut pixel_samples =
        pixels.flat_map(|pixel| samples.clone().map(move |index| SampleId { pixel, index }));
    let mut cancelled = false;
    // Polled at each path's start: a cancelled tile stops starting paths, and the paths in
    // flight end within `max_depth + 1` vertices.
    let mut next = || {
        cancelled = cancelled || cancel.load(Ordering::Relaxed);
        let id = pixel_samples.next().filter(|_| !cancelled)?;
        sampler.start_pixel_sample(id.pixel, id.index, 0);
        let jitter = sampler.next_2d();
        debug_assert_eq!(CAMERA_DIMS, 2);
        let film_point = glam::Vec2::new(id.pixel[0] as f32, id.pixel[1] as f32) + jitter;
        // Each path keeps its own copy of the sampler, positioned past its camera
        // dimensions, so that its vertices are reached from where it stands.
        Some((id, camera.generate_ray(film_point, w, h), sampler.clone()))
    };
    if let Some(lanes) = estimator.lanes {
        radiance_lanes(
            lanes,
            estimator,
            wave,
            &mut next,
            (&mut counters, &mut stages),
            &mut scratch.lanes,
            &mut |id, l| tile.push(id, l),
        );
    } else {
        radiance_wave(
            estimator,
            wave,
            &mut next,
            (&mut counters, &mut stages),
            &mut scratch.wave,
            &mut |id, l| tile.push(id, l),
        );
    }
    if cancelled {
        return None;
    }
    tile.end_pixel();
    debug_assert!(
        tile.blocks
            .iter()
            .all(|b| b.len() == (tw * th * replicates) as usize)
    );
    let TileSink {
        blocks, dropped, ..
    } = tile;
    Some(TileResult {
        width: tw,
        height: th,
        blocks,
        counters,
        stages,
        dropped,
    })
}
