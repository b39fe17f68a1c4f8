//! The render loop: tiles in parallel, samples in order within a pixel.

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

/// A finished render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOutput {
    /// Per-pixel mean and variance.
    pub film: Film,
    /// What it cost.
    pub stats: RenderStats,
}

/// Renders `scene`. `progress` is called after each tile with the number of
/// pixels just finished (the library never prints; the caller draws bars).
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
    settings.validate()?;
    let start = Instant::now();
    let estimator = Estimator {
        scene,
        settings,
        march: March::new(scene, settings),
    };
    let (w, h) = (settings.width, settings.height);
    let tiles: Vec<UVec2> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| UVec2::new(tx * TILE, ty * TILE)))
        .collect();

    let results: Vec<(UVec2, Vec<PixelStats>, RayCounters, u64)> = tiles
        .par_iter()
        .map(|&origin| {
            let r = render_tile(&estimator, origin);
            progress(r.0.len() as u64);
            (origin, r.0, r.1, r.2)
        })
        .collect();

    let mut film = Film::new(w, h);
    let mut stats = RenderStats::default();
    let pixels = film.pixels_mut();
    for (origin, tile, counters, dropped) in results {
        let tw = (w - origin.x).min(TILE);
        for (i, px) in tile.into_iter().enumerate() {
            let (x, y) = (origin.x + i as u32 % tw, origin.y + i as u32 / tw);
            stats.samples += px.n as u64;
            pixels[(y * w + x) as usize] = px;
        }
        stats.rays.merge(&counters);
        stats.dropped_samples += dropped;
    }
    stats.elapsed = start.elapsed();
    Ok(RenderOutput { film, stats })
}

fn render_tile(estimator: &Estimator<'_>, origin: UVec2) -> (Vec<PixelStats>, RayCounters, u64) {
    let settings = estimator.settings;
    let (w, h) = (settings.width, settings.height);
    let (tw, th) = ((w - origin.x).min(TILE), (h - origin.y).min(TILE));
    let mut sampler = Sampler::for_image(settings.sampler, settings.seed, [w, h], settings.spp);
    let mut counters = RayCounters::default();
    let mut dropped = 0u64;
    let mut pixels = Vec::with_capacity((tw * th) as usize);
    for y in origin.y..origin.y + th {
        for x in origin.x..origin.x + tw {
            let mut stats = PixelStats::default();
            for index in 0..settings.spp {
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
    (pixels, counters, dropped)
}
