//! Monte Carlo estimators of the rendering equation over SDF scenes: the
//! scene model, the strategies that choose directions, the film and the
//! parallel render loop of lueur.
//!
//! The primary entry point is [`render`], which takes a [`Scene`] and
//! [`RenderSettings`] and returns a [`Film`] of per-pixel means *and
//! variances* with [`RenderStats`]: lueur exists to compare sampling
//! choices, so every render carries its own error estimate.
//!
//! The design decision that shapes the crate: a [`Strategy`] is one function
//! from a vertex and its random numbers to a named scatter (`strategy.rs`),
//! so the five ways of choosing a direction share everything else (tracing,
//! mirrors, Russian roulette, directional lights) and differ only where the
//! report says they do; the path loop (`path.rs`) strings the stages
//! together.
//!
//! Contracts: renders are deterministic (same scene, settings and seed give
//! the same film bit for bit, whatever the thread count); NaN or infinite
//! samples never reach the film (they are counted in
//! [`RenderStats::dropped_samples`]); every strategy but `light` is unbiased.
//!
//! This crate deliberately does no I/O: it neither reads scene files (see
//! `lueur-scene`) nor writes images nor prints (see the `lueur` CLI).
//!
//! ```
//! use glam::Vec3;
//! use lueur_integrator::{render, Camera, Light, Object, RenderSettings, Scene, Strategy};
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
//! let out = render(&scene, &settings, &|_| {}).unwrap();
//! let (mean, stderr) = out.film.image_mean();
//! assert!((mean - 1.0).abs() < 5.0 * stderr + 1e-3);
//! ```
#![deny(missing_docs)]

mod camera;
mod film;
mod geometry;
mod light;
mod light_sampler;
mod path;
mod render;
mod replicates;
mod scene;
mod strategy;
mod surface;
mod trace;

pub use camera::Camera;
pub use film::{BlockSlots, Film, FilmError, PixelStats, SlotFill, dyadic_blocks, is_dyadic};
pub use geometry::Marching;
pub use light::{Light, QuadSampling};
pub use path::RayCounters;
pub use render::{
    Pass, PixelBounds, RenderOutput, RenderSettings, RenderStats, render, render_pass,
    render_pass_in,
};
pub use replicates::{DEFAULT_REPLICATES, PixelEstimate, default_replicates};
pub use scene::{Object, Scene};
pub use strategy::Strategy;
pub use trace::{Hit, STEP_BUCKETS, TIMED_EVERY, TraceCounters};

/// A scene that cannot be rendered as given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// The camera is degenerate.
    #[error("invalid camera: {0}")]
    Camera(String),
    /// An object names a material that does not exist.
    #[error("object {object} uses material {material}, which does not exist")]
    MissingMaterial {
        /// Index of the object.
        object: usize,
        /// The missing material index.
        material: usize,
    },
    /// A light has a non-positive size, a non-finite position or a negative
    /// radiance.
    #[error("light {0} is degenerate (zero size, non-finite, or negative radiance)")]
    InvalidLight(usize),
    /// The sky's radiance is negative or not finite.
    #[error("the sky's radiance must be finite and non-negative")]
    InvalidSky,
}

/// Settings a render cannot proceed with.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RenderError {
    /// Zero width or height.
    #[error("the image is empty ({width}x{height})")]
    EmptyImage {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// Zero samples per pixel.
    #[error("spp must be at least 1")]
    NoSamples,
    /// Another setting out of its range.
    #[error("{0}")]
    InvalidSetting(&'static str),
    /// Replicates that are zero, more than the spp, or asked of a sampler
    /// without randomization.
    #[error("replicates: {0}")]
    Replicates(String),
}
