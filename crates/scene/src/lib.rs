//! What a lueur scene is, and its file format: the scene model (SDF
//! objects and their materials, lights, the sky, the camera) and the
//! render settings that decide an image besides it, each validated where
//! it is built; and the TOML scene file that describes both.
//!
//! The integrator (`lueur-integrator`) depends on this crate, never the
//! reverse: here a scene is only data and the geometry of its lights
//! (where a ray meets a light, what it emits, how a direction toward it is
//! sampled and with what pdf), not how it is traced or rendered.
//!
//! The entry point for files is [`parse_scene`]. The design decision that
//! shapes that half: the file is parsed into toml's *spanned* tree and
//! dispatched on `type` by hand, rather than through serde's internally
//! tagged enums, which lose spans and make `deny_unknown_fields`
//! unreliable (toml-rs issue 535, serde issue 2294). So every error, a
//! typo'd key as much as a negative radius, names the file, the line and
//! the dotted key path, and shows the offending text with a caret.
//!
//! Contract: a scene that parses is renderable: numbers are finite,
//! sizes positive, albedos in [0, 1], materials exist, the camera is not
//! degenerate. This crate reads strings, not files, and never prints: the
//! CLI owns the file system and the terminal.
//!
//! ```
//! let text = r#"
//! [camera]
//! position = [0.0, 0.0, 3.0]
//! look_at = [0.0, 0.0, 0.0]
//! vfov = 40.0
//! [materials]
//! white = { type = "lambertian", albedo = [0.8, 0.8, 0.8] }
//! [[objects]]
//! material = "white"
//! shape = { type = "torus", major_radius = 0.6, minor_radius = 0.2, rotate = [90.0, 0.0, 0.0] }
//! [sky]
//! radiance = [1.0, 1.0, 1.0]
//! "#;
//! let file = lueur_scene::parse_scene(text, "donut.toml").unwrap();
//! assert_eq!(file.scene.objects.len(), 1);
//!
//! let err = lueur_scene::parse_scene(&text.replace("0.2, rotate", "-0.2, rotate"), "donut.toml").unwrap_err();
//! // Line 10: the text starts with a newline.
//! assert_eq!((err.line, err.key.as_str()), (10, "objects[0].shape.minor_radius"));
//! ```
#![deny(missing_docs)]

mod camera;
mod error;
mod file;
mod light;
mod model;
mod overrides;
mod parse;
mod settings;
mod shape;

pub use camera::Camera;
pub use error::SceneFileError;
pub use file::{SceneFile, parse_scene, parse_scene_with};
pub use light::{
    EmitterSample, Light, QuadSampling, SphereLight, sphere_emits_along_lanes, usable_pdf_lanes,
};
pub use model::{Object, Scene, SceneError};
pub use settings::{
    DEFAULT_REPLICATES, MAX_IMAGE_SIDE, MAX_PIXELS, MAX_SPP, Marching, RenderError, RenderSettings,
    Strategy, default_replicates,
};

#[cfg(test)]
mod overrides_tests;
#[cfg(test)]
mod tests;
