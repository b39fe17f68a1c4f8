//! Monte Carlo estimators of the rendering equation over SDF scenes:
//! tracing, the strategies that choose directions, the film and the
//! parallel render loop of lueur.
//!
//! The primary entry point is [`render`], which takes a [`PreparedScene`]
//! (a `lueur_scene::Scene` with its acceleration) and the scene's
//! `RenderSettings` and returns a [`Film`] of per-pixel means *and
//! variances* with [`RenderStats`]: lueur exists to compare sampling
//! choices, so every render carries its own error estimate.
//!
//! What a scene is (objects, materials, lights, camera, settings) is not
//! this crate's: it lives in `lueur-scene`, which this crate depends on.
//!
//! The design decision that shapes the crate: a `Strategy` is one function
//! from a vertex and its random numbers to a named scatter (`strategy.rs`),
//! so the five ways of choosing a direction share everything else (tracing,
//! mirrors, Russian roulette, directional lights) and differ only where the
//! report says they do; the wave of paths (`path.rs`) strings the stages
//! together, tracing each kind of ray as one SIMD stream, and where the scene
//! allows, the lane wave (`lane_wave/`) runs the same stages with each path
//! kept in a lane of the vectors, for the same bits.
//!
//! Contracts: renders are deterministic (same scene, settings and seed give
//! the same film bit for bit, whatever the thread count, the SIMD level or
//! the number of paths per wave, [`Execution`]); NaN or infinite
//! samples never reach the film (they are counted in
//! [`RenderStats::dropped_samples`]); every strategy but `light` is unbiased.
//!
//! This crate deliberately does no I/O: it neither reads scene files (see
//! `lueur-scene`) nor writes images nor prints (see the `lueur` CLI).
//!
//! ```
//! use glam::Vec3;
//! use lueur_integrator::{render, PreparedScene};
//! use lueur_scene::{Camera, Light, Object, RenderSettings, Scene, Strategy};
//! use lueur_materials::Material;
//! use lueur_sdf_math::Sdf;
//!
//! // A white sphere under a uniform white sky: a furnace, radiance 1.
//! let camera = Camera::new(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 30.0).unwrap();
//! let scene = Scene::new(
//!     vec![Object { sdf: Sdf::sphere(0.5), material: 0 }],
//!     vec![Material::Lambertian { albedo: Vec3::ONE }],
//!     Vec::<Light>::new(),
//!     Some(Vec3::ONE),
//!     camera,
//! )
//! .unwrap();
//! let settings = RenderSettings { width: 8, height: 8, spp: 64, strategy: Strategy::Mis, ..Default::default() };
//! let out = render(&PreparedScene::new(scene), &settings, &|_| {}).unwrap();
//! let (mean, stderr) = out.film.image_mean();
//! assert!((mean - 1.0).abs() < 5.0 * stderr + 1e-3);
//! ```
#![deny(missing_docs)]

mod film;
mod geometry;
mod lane_wave;
mod light_sampler;
mod next_event;
mod path;
mod render;
mod replicates;
mod roulette;
mod scene;
mod stages;
mod strategy;
mod surface;
mod trace;

pub use film::{BlockSlots, Film, FilmError, PixelStats, SlotFill, dyadic_blocks, is_dyadic};
pub use lueur_sdf_math::SimdLevel;
pub use render::{
    Pass, PixelBounds, RenderOutput, RenderStats, render, render_pass, render_pass_in,
};
pub use replicates::PixelEstimate;
pub use scene::{Execution, PreparedScene};
pub use stages::{Stage, StageTimes};
pub use trace::{Hit, RayCounters, STEP_BUCKETS, TraceCounters};
