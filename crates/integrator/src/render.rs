//! The render loop: tiles in parallel, samples in order within a pixel.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use glam::UVec2;
use lueur_sampling::{Sampler, SamplerKind};
use rayon::prelude::*;

use crate::film::{Film, PixelStats};
use crate::path::{CAMERA_DIMS, Estimator, March, RayCounters, SampleId, radiance};
use crate::{RenderError, Scene, Strategy};

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
    /// Maximum number of scattering events (0: emitters seen directly).
    pub max_depth: u32,
    /// Seed of every random number of the render.
    pub seed: u64,
    /// Step cap of the sphere tracer.
    pub max_steps: u32,
    /// Camera rays hit when closer than this many pixel footprints.
    pub pixel_epsilon: f32,
    /// Secondary rays hit when closer than this fraction of the distance
    /// travelled.
    pub epsilon_rel: f32,
    /// Floor of every hit epsilon, as a fraction of the scene's scale.
    pub epsilon_abs: f32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 256,
            height: 256,
            spp: 64,
            strategy: Strategy::default(),
            sampler: SamplerKind::Independent,
            max_depth: 8,
            seed: 0,
            max_steps: 256,
            pixel_epsilon: 0.25,
            epsilon_rel: 1e-4,
            epsilon_abs: 1e-6,
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
        if self.max_steps == 0 {
            return Err(RenderError::InvalidSetting("max_steps must be at least 1"));
        }
        for (v, what) in [
            (
                self.pixel_epsilon,
                "pixel_epsilon must be positive and finite",
            ),
            (self.epsilon_rel, "epsilon_rel must be positive and finite"),
            (self.epsilon_abs, "epsilon_abs must be positive and finite"),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(RenderError::InvalidSetting(what));
            }
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
}

impl RenderStats {
    /// Adds another pass's statistics (times add up too).
    pub fn merge(&mut self, other: &RenderStats) {
        self.rays.merge(&other.rays);
        self.dropped_samples += other.dropped_samples;
        self.samples += other.samples;
        self.elapsed += other.elapsed;
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
/// dimension, seed), and each pixel adds its samples in index order.
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<RenderOutput, RenderError> {
    let mut film = Film::new(settings.width, settings.height);
    let stats = render_pass(
        scene,
        settings,
        &mut film,
        settings.spp,
        &AtomicBool::new(false),
        progress,
    )?
    .expect("a render that cannot be cancelled completes");
    Ok(RenderOutput { film, stats })
}

/// Adds sample indices `film.spp()..until` to every pixel of `film`: one
/// pass of a progressive render. Because each pixel adds its samples in
/// index order, rendering `0..4` then `4..8` gives the bit-identical film
/// of rendering `0..8` at once.
///
/// `cancel` is polled before every pixel; once it is set the pass is
/// abandoned, `film` is left exactly as it was (still a whole number of
/// samples per pixel) and `Ok(None)` is returned.
pub fn render_pass(
    scene: &Scene,
    settings: &RenderSettings,
    film: &mut Film,
    until: u32,
    cancel: &AtomicBool,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Option<RenderStats>, RenderError> {
    settings.validate()?;
    let (w, h) = (settings.width, settings.height);
    if film.width() != w || film.height() != h {
        return Err(RenderError::InvalidSetting(
            "the film's size differs from the settings'",
        ));
    }
    let from = film.spp();
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
    let tiles: Vec<UVec2> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| UVec2::new(tx * TILE, ty * TILE)))
        .collect();

    let existing: &Film = film;
    let results: Vec<Option<TileResult>> = tiles
        .par_iter()
        .map(|&origin| {
            let r = render_tile(&estimator, existing, origin, from..until, cancel)?;
            progress(r.pixels.len() as u64 * u64::from(until - from));
            Some(r)
        })
        .collect();
    if cancel.load(Ordering::Relaxed) || results.iter().any(Option::is_none) {
        return Ok(None);
    }

    let mut stats = RenderStats::default();
    let pixels = film.pixels_mut();
    for r in results.into_iter().flatten() {
        let tw = (w - r.origin.x).min(TILE);
        for (i, px) in r.pixels.into_iter().enumerate() {
            let (x, y) = (r.origin.x + i as u32 % tw, r.origin.y + i as u32 / tw);
            let slot = &mut pixels[(y * w + x) as usize];
            stats.samples += u64::from(px.n - slot.n);
            *slot = px;
        }
        stats.rays.merge(&r.counters);
        stats.dropped_samples += r.dropped;
    }
    film.set_spp(until);
    stats.elapsed = start.elapsed();
    Ok(Some(stats))
}

/// One tile's pixels after a pass, and what the pass cost there.
struct TileResult {
    origin: UVec2,
    pixels: Vec<PixelStats>,
    counters: RayCounters,
    dropped: u64,
}

/// `None` when cancelled.
fn render_tile(
    estimator: &Estimator<'_>,
    film: &Film,
    origin: UVec2,
    samples: Range<u32>,
    cancel: &AtomicBool,
) -> Option<TileResult> {
    let settings = estimator.settings;
    let (w, h) = (settings.width, settings.height);
    let (tw, th) = ((w - origin.x).min(TILE), (h - origin.y).min(TILE));
    let mut sampler = Sampler::for_image(settings.sampler, settings.seed, [w, h], settings.spp);
    let mut counters = RayCounters::default();
    let mut dropped = 0u64;
    let mut pixels = Vec::with_capacity((tw * th) as usize);
    for y in origin.y..origin.y + th {
        for x in origin.x..origin.x + tw {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let mut stats = *film.pixel(x, y);
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
                if l.is_finite() {
                    stats.add(l);
                } else {
                    dropped += 1;
                }
            }
            pixels.push(stats);
        }
    }
    Some(TileResult {
        origin,
        pixels,
        counters,
        dropped,
    })
}
