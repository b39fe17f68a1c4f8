//! Helpers shared by the end-to-end tests.

use glam::Vec3;
use lueur::integrator::{Film, PreparedScene, RenderOutput, render};
use lueur::materials::Material;
use lueur::scene::{Camera, Light, Object, RenderSettings, Scene};
use lueur::scene::{SceneFile, parse_scene};
use lueur::sdf_math::Sdf;

/// Loads a shipped scene from `scenes/`.
pub fn shipped(name: &str) -> SceneFile {
    let path = format!("{}/scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    parse_scene(&text, &path).unwrap()
}

/// A parsed file's scene, prepared for rendering.
pub fn prepared(file: &SceneFile) -> PreparedScene {
    PreparedScene::new(file.scene.clone())
}

/// `settings` at `width` x `height` and `spp`, for a test render small enough to repeat.
pub fn sized(settings: &RenderSettings, [width, height]: [u32; 2], spp: u32) -> RenderSettings {
    RenderSettings {
        width,
        height,
        spp,
        ..settings.clone()
    }
}

pub const SHIPPED: [&str; 3] = ["cornell-spheres", "death-star", "donut-mirrors"];

/// Renders on the current rayon pool with no progress reporting.
pub fn run(scene: &Scene, settings: &RenderSettings) -> RenderOutput {
    let out = render(&PreparedScene::new(scene.clone()), settings, &|_| {}).unwrap();
    assert_eq!(out.stats.dropped_samples, 0, "NaN or infinite samples");
    out
}

/// Renders with exactly `threads` worker threads.
pub fn run_with_threads(scene: &Scene, settings: &RenderSettings, threads: usize) -> Film {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| run(scene, settings)).film
}

/// A scene of the given objects seen from `camera`, all of one material.
pub fn scene_of(
    objects: Vec<Sdf>,
    material: Material,
    lights: Vec<Light>,
    sky: Option<Vec3>,
    camera: Camera,
) -> Scene {
    let objects = objects
        .into_iter()
        .map(|sdf| Object { sdf, material: 0 })
        .collect();
    Scene::new(objects, vec![material], lights, sky, camera).unwrap()
}
