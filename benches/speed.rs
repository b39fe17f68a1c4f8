//! Speed of lueur on its shipped scenes, naive against fast marching: one scene
//! evaluation, one camera ray, one sample of each strategy, a small whole render.
//!
//! `cargo bench -p lueur` runs them; CI only builds them (`cargo bench --no-run`). Every
//! group measures both [`Marching`] modes in one run, so a speed-up reads as a ratio.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use lueur_integrator::{PreparedScene, TraceCounters, render};
use lueur_scene::parse_scene;
use lueur_scene::{Marching, RenderSettings, Strategy};
use lueur_sdf_math::{Ray, TraceParams};

const SCENES: [&str; 3] = ["cornell-spheres", "death-star", "donut-mirrors"];
const MODES: [(Marching, &str); 2] = [(Marching::Naive, "naive"), (Marching::Fast, "fast")];

fn load(name: &str, marching: Marching) -> (PreparedScene, RenderSettings) {
    let file = format!("{}/scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&file).expect("shipped scenes are readable");
    let parsed = parse_scene(&text, &file).expect("shipped scenes parse");
    let settings = RenderSettings {
        marching,
        ..parsed.settings
    };
    (PreparedScene::new(parsed.scene), settings)
}

/// Camera rays through a 32x32 grid of pixel centres of a 256x256 image.
fn camera_rays(scene: &PreparedScene) -> Vec<Ray> {
    (0..32 * 32)
        .map(|i| {
            let film = Vec2::new((i % 32) as f32 * 8.0 + 4.0, (i / 32) as f32 * 8.0 + 4.0);
            scene.scene().camera.generate_ray(film, 256, 256)
        })
        .collect()
}

/// Camera-ray parameters as the integrator derives them for a 256x256 render (the
/// integrator raises the absolute threshold per ray to the rounding at its origin, which
/// `intersect` does here too).
fn camera_params(scene: &PreparedScene, settings: &RenderSettings) -> TraceParams {
    TraceParams {
        t_min: 0.0,
        t_max: 100.0 * scene.scale(),
        max_steps: settings.max_steps,
        eps_abs: 0.0,
        eps_rel: settings.pixel_epsilon * scene.scene().camera.pixel_angle(256),
    }
}

fn scene_evaluation(c: &mut Criterion) {
    let mut group = c.benchmark_group("scene_evaluation");
    for name in SCENES {
        for (marching, mode) in MODES {
            let (scene, _) = load(name, marching);
            // Points along camera rays, from the eye to well past the scene.
            let points: Vec<Vec3> = camera_rays(&scene)
                .iter()
                .enumerate()
                .map(|(i, r)| r.at(scene.scale() * (i % 17) as f32 / 8.0))
                .collect();
            group.throughput(Throughput::Elements(points.len() as u64));
            group.bench_function(BenchmarkId::new(name, mode), |b| {
                b.iter(|| {
                    points
                        .iter()
                        .map(|&p| scene.distance(black_box(p), marching))
                        .sum::<f32>()
                })
            });
        }
    }
    group.finish();
}

fn camera_ray(c: &mut Criterion) {
    let mut group = c.benchmark_group("camera_ray");
    for name in SCENES {
        for (marching, mode) in MODES {
            let (scene, settings) = load(name, marching);
            let rays = camera_rays(&scene);
            let params = camera_params(&scene, &settings);
            group.throughput(Throughput::Elements(rays.len() as u64));
            group.bench_function(BenchmarkId::new(name, mode), |b| {
                b.iter(|| {
                    let mut counters = TraceCounters::default();
                    for ray in &rays {
                        black_box(scene.intersect(
                            black_box(ray),
                            &params,
                            marching,
                            &mut counters,
                        ));
                    }
                    counters.steps
                })
            });
        }
    }
    group.finish();
}

/// A 16x16 render at 1 spp on one thread: 256 samples of one strategy.
fn sample(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("one thread starts");
    let mut group = c.benchmark_group("sample");
    group.sample_size(20);
    group.throughput(Throughput::Elements(256));
    for strategy in Strategy::ALL {
        for (marching, mode) in MODES {
            let (scene, settings) = load("donut-mirrors", marching);
            let settings = RenderSettings {
                width: 16,
                height: 16,
                spp: 1,
                strategy,
                max_depth: 8,
                ..settings
            };
            group.bench_function(BenchmarkId::new(strategy.name(), mode), |b| {
                b.iter(|| pool.install(|| render(&scene, &settings, &|_| {}).expect("renders")))
            });
        }
    }
    group.finish();
}

/// A whole 32x32 render at 4 spp of each shipped scene, on the default thread pool.
fn small_render(c: &mut Criterion) {
    let mut group = c.benchmark_group("render_32x32_4spp");
    group.sample_size(10);
    group.throughput(Throughput::Elements(32 * 32 * 4));
    for name in SCENES {
        for (marching, mode) in MODES {
            let (scene, settings) = load(name, marching);
            let settings = RenderSettings {
                width: 32,
                height: 32,
                spp: 4,
                ..settings
            };
            group.bench_function(BenchmarkId::new(name, mode), |b| {
                b.iter(|| render(&scene, &settings, &|_| {}).expect("renders"))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, scene_evaluation, camera_ray, sample, small_render);
criterion_main!(benches);
