//! The render loop: tiles in parallel, samples in order within a pixel.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use glam::UVec2;
use lueur_sampling::{Sampler, SamplerKind};
use rayon::prelude::*;

use crate::film::{Film, PixelStats};
use crate::path::{Estimator, RayCounters, SampleId, radiance};
use crate::replicates::{BlockCounter, default_replicates};
use crate::strategy::CAMERA_DIMS;
use crate::surface::March;
use crate::{Marching, QuadSampling, RenderError, Scene, Strategy};

/// Side of the square tiles the image is cut into. Small enough that both
/// cores stay busy to the end, large enough that scheduling is negligible.
const TILE: u32 = 16;

/// Largest image side accepted.
pub const MAX_IMAGE_SIDE: u32 = 65_536;
/// Largest number of pixels accepted (the film holds 28 bytes per pixel).
pub const MAX_PIXELS: u64 = 1 << 28;
/// Largest spp accepted: beyond 2^24 a pixel's sample count would no longer
/// be exact in the f32 arithmetic of its running mean.
pub const MAX_SPP: u32 = 1 << 24;

/// Everything that decides an image besides the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// How directions are chosen.
    pub strategy: Strategy,
    /// Which point set feeds the estimator.
    pub sampler: SamplerKind,
    /// Independent randomizations the samples are dealt into, whose spread
    /// is the error bar of each pixel (see `replicates.rs`); `None`
    /// for the sampler's default ([`default_replicates`]).
    pub replicates: Option<u32>,
    /// Maximum number of scattering events (0: emitters seen directly).
    pub max_depth: u32,
    /// Scattering events after which Russian roulette may end a path (on
    /// the throughput's largest component; unbiased, it trades noise for
    /// time). At `max_depth` or above it never plays.
    pub roulette_depth: u32,
    /// Seed of every random number of the render.
    pub seed: u64,
    /// Step cap of the sphere tracer.
    pub max_steps: u32,
    /// Camera rays hit when closer than this many pixel footprints.
    pub pixel_epsilon: f32,
    /// Secondary rays hit when closer than this fraction of the distance
    /// travelled.
    pub epsilon_rel: f32,
    /// How rays are marched through the objects (both modes find the same
    /// surfaces; `Naive` is the reference of the speed-ups).
    pub marching: Marching,
    /// How quad lights are sampled toward a shading point.
    pub quad_sampling: QuadSampling,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 256,
            height: 256,
            spp: 64,
            strategy: Strategy::default(),
            sampler: SamplerKind::default(),
            replicates: None,
            max_depth: 8,
            roulette_depth: 3,
            seed: 0,
            max_steps: 256,
            // A sixteenth of a pixel: a ray that passes this close to a
            // surface is a hit, so silhouettes grow by this much. At a
            // quarter pixel they grew visibly against Mitsuba's exact
            // intersections (24 of 3072 8x8-pixel region-channels beyond
            // 4 sigma at 1024 spp, all on silhouettes and grazing corners;
            // none at a sixteenth: docs/PEERS.md), for no measurable time.
            pixel_epsilon: 0.0625,
            epsilon_rel: 1e-4,
            marching: Marching::default(),
            quad_sampling: QuadSampling::default(),
        }
    }
}

impl RenderSettings {
    /// Checks what a render cannot proceed without.
    pub fn validate(&self) -> Result<(), RenderError> {
        if self.width == 0 || self.height == 0 {
            return Err(RenderError::EmptyImage {
                width: self.width,
                height: self.height,
            });
        }
        if self.spp == 0 {
            return Err(RenderError::NoSamples);
        }
        // The same bounds as scene files, so flags cannot go around them;
        // and a film beyond 2^28 pixels (28 bytes each: 7.5 GB) is refused
        // here rather than failing to allocate halfway.
        if self.width > MAX_IMAGE_SIDE || self.height > MAX_IMAGE_SIDE {
            return Err(RenderError::InvalidSetting(
                "width and height must be at most 65536",
            ));
        }
        if u64::from(self.width) * u64::from(self.height) > MAX_PIXELS {
            return Err(RenderError::InvalidSetting(
                "the image has more than 2^28 pixels (its film would take over 7.5 GB)",
            ));
        }
        if self.spp > MAX_SPP {
            return Err(RenderError::InvalidSetting("spp must be at most 2^24"));
        }
        if let Some(k) = self.replicates {
            self.validate_replicates(k)?;
        }
        if self.max_steps == 0 {
            return Err(RenderError::InvalidSetting("max_steps must be at least 1"));
        }
        for (v, what) in [
            (
                self.pixel_epsilon,
                "pixel_epsilon must be positive and finite",
            ),
            (self.epsilon_rel, "epsilon_rel must be positive and finite"),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(RenderError::InvalidSetting(what));
            }
        }
        Ok(())
    }
}

impl RenderSettings {
    /// The replicates the render deals its samples into: the settings' or
    /// the sampler's default.
    pub fn replicate_count(&self) -> u32 {
        self.replicates
            .unwrap_or_else(|| default_replicates(self.sampler, self.spp))
    }

    fn validate_replicates(&self, k: u32) -> Result<(), RenderError> {
        if k == 0 {
            return Err(RenderError::Replicates("must be at least 1, got 0".into()));
        }
        if k > self.spp {
            return Err(RenderError::Replicates(format!(
                "{k} replicates need at least {k} spp, got {}",
                self.spp
            )));
        }
        if k > 1 && !self.sampler.is_randomized() {
            return Err(RenderError::Replicates(format!(
                "the {} sampler is not randomized: it has no independent replicates \
                 (use 1, or a randomized sampler such as {}-owen)",
                self.sampler,
                if self.sampler == SamplerKind::Halton {
                    "halton"
                } else {
                    "sobol"
                }
            )));
        }
        Ok(())
    }
}

/// What a render measured about itself.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Per kind of ray: rays, steps, hits, misses, step-cap give-ups.
    pub rays: RayCounters,
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
}

impl RenderStats {
    /// Adds another pass's statistics (times add up too).
    pub fn merge(&mut self, other: &RenderStats) {
        self.rays.merge(&other.rays);
        self.dropped_samples += other.dropped_samples;
        self.samples += other.samples;
        self.elapsed += other.elapsed;
        self.film_time += other.film_time;
        self.threads = self.threads.max(other.threads);
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
    scene: &Scene,
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
    scene: &Scene,
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
    scene: &Scene,
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
    let estimator = Estimator {
        scene,
        settings,
        march: March::new(scene, settings),
    };
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
    let results: Vec<Option<TileCost>> = tiles
        .par_iter()
        .map(|&origin| {
            let r = render_tile(&estimator, bounds, origin, plan.pass_blocks(), cancel)?;
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
                dropped: r.dropped,
                film_time,
            })
        })
        .collect();
    drop(sink);

    let mut stats = RenderStats::default();
    for r in results.iter().flatten() {
        stats.rays.merge(&r.counters);
        stats.dropped_samples += r.dropped;
        stats.samples += r.samples;
        stats.film_time += r.film_time;
    }
    let done: Vec<bool> = results.iter().map(Option::is_some).collect();
    let complete = done.iter().all(|&d| d);
    film.end_pass(plan, TILE, done);
    stats.threads = rayon::current_num_threads();
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
    dropped: u64,
}

/// What a finished tile cost, once its statistics are in the film.
struct TileCost {
    samples: u64,
    counters: RayCounters,
    dropped: u64,
    /// Time spent merging the tile into the film.
    film_time: Duration,
}

/// The tile at `origin` of the film of `bounds`; `None` when cancelled.
fn render_tile(
    estimator: &Estimator<'_>,
    bounds: PixelBounds,
    origin: UVec2,
    pass_blocks: &[Range<u32>],
    cancel: &AtomicBool,
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
    let mut counters = RayCounters::default();
    let mut dropped = 0u64;
    let block_count = pass_blocks.len();
    let mut blocks = vec![Vec::with_capacity((tw * th * replicates) as usize); block_count];
    let mut counter = BlockCounter::new(replicates);
    for y in origin.y..origin.y + th {
        for x in origin.x..origin.x + tw {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            counter.clear();
            for index in samples.clone() {
                let id = SampleId {
                    pixel: [x, y],
                    index,
                };
                sampler.start_pixel_sample(id.pixel, index, 0);
                let jitter = sampler.next_2d();
                debug_assert_eq!(CAMERA_DIMS, 2);
                let film_point = glam::Vec2::new(x as f32, y as f32) + jitter;
                let ray = estimator.scene.camera.generate_ray(film_point, w, h);
                let l = radiance(estimator, ray, &mut sampler, id, &mut counters);
                if !l.is_finite() {
                    dropped += 1;
                }
                counter.push(index, PixelStats::of_sample(l));
            }
            debug_assert_eq!(counter.blocks().count(), block_count);
            for (block, (_, slots)) in blocks.iter_mut().zip(counter.blocks()) {
                block.extend_from_slice(slots);
            }
        }
    }
    Some(TileResult {
        width: tw,
        height: th,
        blocks,
        counters,
        dropped,
    })
}
