//! lueur: a physically based renderer whose geometry is signed distance
//! functions, rendered by sphere tracing, built to *measure* Monte Carlo.
//!
//! This facade only re-exports the workspace's library crates, bottom to
//! top, so that one dependency gives the whole pipeline, and so that the
//! end-to-end tests in `tests/` can drive it. It adds nothing of its own.
//!
//! ```
//! let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/cornell-spheres.toml")).unwrap();
//! let mut file = lueur::scene::parse_scene(&text, "cornell-spheres.toml").unwrap();
//! file.settings.width = 16;
//! file.settings.height = 16;
//! file.settings.spp = 4;
//! let scene = lueur::integrator::PreparedScene::new(file.scene);
//! let out = lueur::integrator::render(&scene, &file.settings, &|_| {}).unwrap();
//! assert_eq!(out.stats.dropped_samples, 0);
//! ```
#![deny(missing_docs)]

/// Signed distance functions and the sphere tracer.
pub use lueur_sdf_math as sdf_math;

/// Point sets in the unit cube, the measures that compare them, and the
/// registry of kinds.
pub use lueur_pointsets as pointsets;

/// Warps, pdfs, MIS weights and the renderer's sampler.
pub use lueur_sampling as sampling;

/// BSDFs: Lambertian and mirror.
pub use lueur_materials as materials;

/// What a scene is (objects, materials, lights, camera, render settings)
/// and its file format.
pub use lueur_scene as scene;

/// Tracing, strategies, the film and the render loop.
pub use lueur_integrator as integrator;
