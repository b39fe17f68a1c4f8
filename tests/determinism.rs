use lueur::scene::Strategy;

use crate::common::{SHIPPED, run_with_threads, shipped, sized};

#[test]
fn every_shipped_scene_is_bit_identical_on_one_and_two_threads() {
    for name in SHIPPED {
        let file = shipped(name);
        for strategy in Strategy::ALL {
            let mut settings = sized(&file.settings, [24, 20], 4);
            settings.strategy = strategy;
            let one = run_with_threads(&file.scene, &settings, 1);
            let two = run_with_threads(&file.scene, &settings, 2);
            assert!(
                one == two,
                "{name} with {strategy}: the image depends on the thread count"
            );
        }
    }
}

/// The image is the same bit for bit whatever instruction set the ray streams run on and
/// however many paths share a wave: a path's rays take the same steps in any lane of any
/// vector, next to any other rays (a wave of 1 is the one-path loop).
#[test]
fn every_simd_level_and_wave_size_gives_the_same_image() {
    use lueur::integrator::{Execution, render};
    use lueur::sdf_math::SimdLevel;

    let levels = SimdLevel::available();
    assert!(levels.contains(&SimdLevel::Scalar) && levels.len() >= 2);
    for name in SHIPPED {
        let file = shipped(name);
        for strategy in [Strategy::Mis, Strategy::Mixture] {
            let mut settings = sized(&file.settings, [20, 12], 4);
            settings.strategy = strategy;
            let reference = run_with_threads(&file.scene, &settings, 1);
            for &simd in &levels {
                for wave in [1, 7, 16, Execution::WAVE] {
                    for lane_wave in [false, true] {
                        let execution = Execution {
                            simd,
                            wave,
                            lane_wave,
                        };
                        let scene = crate::common::prepared(&file).with_execution(execution);
                        let film = render(&scene, &settings, &|_| {}).unwrap().film;
                        assert!(
                            film == reference,
                            "{name} with {strategy}: {execution:?} changes the image"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn the_seed_changes_the_image_and_only_the_seed() {
    let file = shipped("donut-mirrors");
    let mut settings = sized(&file.settings, [16, 16], 2);
    let a = run_with_threads(&file.scene, &settings, 2);
    let again = run_with_threads(&file.scene, &settings, 2);
    settings.seed += 1;
    let b = run_with_threads(&file.scene, &settings, 2);
    assert!(a == again);
    assert!(a != b, "a different seed must give different samples");
}

/// A progressive render (passes of 1, 1, 2, 4 spp, as the CLI runs them)
/// ends bit-identical to one pass of the same total, for every sampler: each
/// pixel merges its samples in the same fixed tree whatever the passes.
#[test]
fn passes_add_up_to_the_single_pass_image_bit_for_bit() {
    use std::sync::atomic::AtomicBool;

    use lueur::integrator::{Film, render_pass};
    use lueur::sampling::SamplerKind;

    let file = shipped("donut-mirrors");
    for &sampler in SamplerKind::ALL {
        let mut settings = sized(&file.settings, [20, 18], 8);
        settings.sampler = sampler;
        let whole = run_with_threads(&file.scene, &settings, 2);
        let mut film = Film::new(settings.width, settings.height);
        let never = AtomicBool::new(false);
        for until in [1, 2, 4, 8] {
            let pass = render_pass(
                &crate::common::prepared(&file),
                &settings,
                &mut film,
                until,
                &never,
                &|_| {},
            )
            .unwrap();
            assert!(pass.complete);
            assert_eq!(film.spp(), until);
        }
        assert!(film == whole, "{sampler}: passes differ from one pass");
    }
}

/// Shards cut anywhere, rendered apart (each in its own passes) and merged
/// in any order, give the film of one render bit for bit, for every sampler
/// (the samplers laid out over the total spp get that total), with their
/// samples dealt into three replicates.
#[test]
fn shards_merge_into_the_single_render_bit_for_bit() {
    use std::sync::atomic::AtomicBool;

    use lueur::integrator::{Film, render_pass};
    use lueur::sampling::SamplerKind;

    let file = shipped("donut-mirrors");
    let never = AtomicBool::new(false);
    for &sampler in SamplerKind::ALL {
        let mut settings = sized(&file.settings, [11, 7], 13);
        settings.sampler = sampler;
        // Three replicates, which 13 spp does not divide: the interleaved
        // replicates are cut by the shards' ends too.
        settings.replicates = sampler.is_randomized().then_some(3);
        let whole = run_with_threads(&file.scene, &settings, 1);
        let shard = |range: std::ops::Range<u32>, step: u32| {
            let mut film = Film::starting_at(11, 7, range.start);
            let mut until = range.start;
            while until < range.end {
                until = (until + step).min(range.end);
                let pass = render_pass(
                    &crate::common::prepared(&file),
                    &settings,
                    &mut film,
                    until,
                    &never,
                    &|_| {},
                )
                .unwrap();
                assert!(pass.complete);
            }
            film
        };
        let shards = vec![shard(9..13, 3), shard(0..3, 1), shard(3..9, 4)];
        let merged = Film::merge(shards).unwrap();
        assert!(
            merged == whole,
            "{sampler}: merged shards differ from one render"
        );
        assert_eq!(merged.samples(), 0..13);
    }
}

/// A pass cancelled before any tile finished leaves the film exactly as it
/// was.
#[test]
fn a_pass_cancelled_at_once_changes_nothing() {
    use std::sync::atomic::AtomicBool;

    use lueur::integrator::{Film, render_pass};

    let file = shipped("cornell-spheres");
    let settings = sized(&file.settings, [16, 16], 4);
    let mut film = Film::new(16, 16);
    let first = render_pass(
        &crate::common::prepared(&file),
        &settings,
        &mut film,
        2,
        &AtomicBool::new(false),
        &|_| {},
    )
    .unwrap();
    assert!(first.complete);
    let before = film.clone();
    let cancelled = render_pass(
        &crate::common::prepared(&file),
        &settings,
        &mut film,
        4,
        &AtomicBool::new(true),
        &|_| {},
    )
    .unwrap();
    assert!(!cancelled.complete && cancelled.stats.samples == 0);
    assert!(film == before && film.spp() == 2 && film.unfinished_pass().is_none());
    // A pass that adds nothing, or overshoots the render's spp, is refused.
    let never = AtomicBool::new(false);
    assert!(
        render_pass(
            &crate::common::prepared(&file),
            &settings,
            &mut film,
            2,
            &never,
            &|_| {}
        )
        .is_err()
    );
    assert!(
        render_pass(
            &crate::common::prepared(&file),
            &settings,
            &mut film,
            5,
            &never,
            &|_| {}
        )
        .is_err()
    );
}

/// A pass cancelled midway keeps the tiles it finished, bit for bit as the
/// whole pass would have left them, and the other tiles as they were; such
/// a film says so, and refuses to be saved, merged or extended.
#[test]
fn a_pass_cancelled_midway_keeps_its_finished_tiles() {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

    use lueur::integrator::{Film, render_pass};

    let file = shipped("cornell-spheres");
    // 4 x 3 tiles of 16 pixels, the last column and row of them cut short.
    let settings = sized(&file.settings, [60, 40], 8);
    let never = AtomicBool::new(false);
    let mut film = Film::new(60, 40);
    for until in [1, 3] {
        render_pass(
            &crate::common::prepared(&file),
            &settings,
            &mut film,
            until,
            &never,
            &|_| {},
        )
        .unwrap();
    }
    let before = film.clone();
    let mut whole = film.clone();
    render_pass(
        &crate::common::prepared(&file),
        &settings,
        &mut whole,
        8,
        &never,
        &|_| {},
    )
    .unwrap();

    let cancel = AtomicBool::new(false);
    let tiles_done = AtomicUsize::new(0);
    let stop_after_five = |_| {
        if tiles_done.fetch_add(1, Ordering::SeqCst) + 1 == 5 {
            cancel.store(true, Ordering::SeqCst);
        }
    };
    let pass = render_pass(
        &crate::common::prepared(&file),
        &settings,
        &mut film,
        8,
        &cancel,
        &stop_after_five,
    )
    .unwrap();
    assert!(!pass.complete);
    let (samples, share) = film.unfinished_pass().expect("unfinished");
    assert_eq!(samples, 3..8);
    assert_eq!(
        film.spp(),
        3,
        "the whole-film spp is the last complete pass's"
    );

    let mut at_8 = 0;
    for y in 0..40 {
        for x in 0..60 {
            let p = film.pixel(x, y);
            let tile_corner = film.pixel(x / 16 * 16, y / 16 * 16);
            if p == whole.pixel(x, y) && tile_corner == whole.pixel(x / 16 * 16, y / 16 * 16) {
                at_8 += 1;
            } else {
                assert_eq!(p, before.pixel(x, y), "pixel ({x}, {y}) is neither");
            }
        }
    }
    // The film's own division of the same two integers, so exact: the
    // product `share * 2400` is not (0.56 * 2400 = 1344.0000000000002).
    assert_eq!(share, at_8 as f64 / 2400.0);
    assert!(
        at_8 >= 5 * 12 * 8,
        "at least the 5 tiles finished first: {at_8}"
    );
    assert!(at_8 < 2400, "the cancel stopped the pass");
    assert_eq!(
        pass.stats.samples,
        5 * at_8 as u64,
        "the stats count the finished tiles' samples"
    );

    assert!(film.blocks().is_err());
    assert!(Film::merge(vec![film.clone()]).is_err());
    assert!(
        render_pass(
            &crate::common::prepared(&file),
            &settings,
            &mut film,
            8,
            &never,
            &|_| {}
        )
        .is_err()
    );
}

/// A film sealed at its end folds its blocks into one image on the pass
/// that reaches it: the image is bit-identical to the unsealed film's,
/// from a fresh start (0..16 then 16..24) as from a film that already held
/// two blocks (0..16, 16..20, resumed to 24); the sealed film refuses to be
/// saved, merged or extended.
#[test]
fn a_sealed_film_has_the_unsealed_image_bit_for_bit() {
    use std::sync::atomic::AtomicBool;

    use lueur::integrator::{Film, FilmError, render_pass};

    let file = shipped("donut-mirrors");
    let settings = sized(&file.settings, [20, 18], 24);
    let never = AtomicBool::new(false);
    let run = |film: &mut Film, passes: &[u32]| {
        for &until in passes {
            let pass = render_pass(
                &crate::common::prepared(&file),
                &settings,
                film,
                until,
                &never,
                &|_| {},
            )
            .unwrap();
            assert!(pass.complete);
        }
    };
    for passes in [&[1, 2, 4, 8, 16, 24][..], &[16, 20, 24], &[24]] {
        let mut open = Film::new(20, 18);
        run(&mut open, passes);
        let mut sealed = Film::new(20, 18).sealed_at(24);
        run(&mut sealed, passes);
        assert!(open.blocks().unwrap().count() == 2 && !open.is_sealed());
        assert!(sealed.is_sealed(), "{passes:?}");
        assert!(
            sealed.pixels().eq(open.pixels()),
            "{passes:?}: the sealed image differs"
        );
        assert_eq!(sealed.samples(), 0..24);
        assert!(matches!(sealed.blocks().err(), Some(FilmError::Sealed(_))));
        assert!(Film::merge(vec![sealed.clone()]).is_err());
    }
    // A film sealed at the render's end that stops short of it (a time
    // budget) is an ordinary film.
    let mut short = Film::new(20, 18).sealed_at(24);
    run(&mut short, &[1, 2, 4]);
    assert!(!short.is_sealed() && short.blocks().is_ok());
}

/// The lane wave (each path kept in a lane from vertex to vertex, where it models the
/// scene) gives the image of the wave of records, bit for bit, on every level and wave
/// size, at the extremes of what it runs: rays that give up at the step cap, paths cut at
/// their first vertex or played by roulette from it, and a 1 mm diffuse and a 1 mm mirror
/// sphere on a kilometre floor under a 2 mm sphere light, seen from 1 cm.
#[test]
fn the_lane_wave_gives_the_image_of_the_wave_of_records() {
    use glam::Vec3;
    use lueur::integrator::{Execution, PreparedScene, render};
    use lueur::materials::Material;
    use lueur::sampling::SamplerKind;
    use lueur::scene::{Camera, Light, Object, Scene};
    use lueur::sdf_math::{Sdf, SimdLevel};

    // The rays and their steps, without the time they took.
    let untimed = |mut rays: lueur::integrator::RayCounters| {
        for kind in [&mut rays.camera, &mut rays.bounce, &mut rays.shadow] {
            kind.tracing_nanos = 0;
        }
        rays
    };
    let cornell = shipped("cornell-spheres");
    let mut base = sized(&cornell.settings, [20, 12], 4);
    base.strategy = Strategy::Mis;
    let mut cases = vec![(
        "cornell, sobol-xor numbers",
        cornell.scene.clone(),
        base.clone(),
    )];
    let mut capped = base.clone();
    capped.max_steps = 3;
    cases.push(("cornell, 3 steps a ray", cornell.scene.clone(), capped));
    let mut first = base.clone();
    first.max_depth = 1;
    cases.push(("cornell, one vertex", cornell.scene.clone(), first));
    let mut independent = base.clone();
    independent.sampler = SamplerKind::Independent;
    cases.push((
        "cornell, independent numbers",
        cornell.scene.clone(),
        independent,
    ));
    let mut roulette = base.clone();
    (roulette.roulette_depth, roulette.max_depth) = (0, 64);
    roulette.sampler = SamplerKind::Independent;
    cases.push((
        "cornell, roulette from the start",
        cornell.scene.clone(),
        roulette,
    ));

    let objects = vec![
        Object {
            sdf: Sdf::cuboid(Vec3::new(500.0, 0.05, 500.0)).translate(Vec3::new(0.0, -0.05, 0.0)),
            material: 0,
        },
        Object {
            sdf: Sdf::sphere(5e-4).translate(Vec3::new(-1e-3, 5e-4, 0.0)),
            material: 0,
        },
        Object {
            sdf: Sdf::sphere(5e-4).translate(Vec3::new(1e-3, 5e-4, 0.0)),
            material: 1,
        },
    ];
    let materials = vec![
        Material::Lambertian {
            albedo: Vec3::splat(0.6),
        },
        Material::Mirror {
            reflectance: Vec3::splat(0.9),
        },
    ];
    let light = Light::Sphere {
        center: Vec3::new(0.0, 4e-3, 2e-3),
        radius: 1e-3,
        radiance: Vec3::splat(5.0),
    };
    let camera = Camera::new(Vec3::new(0.0, 3e-3, 1e-2), Vec3::ZERO, Vec3::Y, 30.0).unwrap();
    let tiny = Scene::new(objects, materials, vec![light], None, camera).unwrap();
    cases.push(("1 mm spheres on a 1 km floor", tiny, base.clone()));

    for (name, scene, settings) in cases {
        let records = Execution {
            simd: SimdLevel::Scalar,
            lane_wave: false,
            ..Execution::default()
        };
        let prepared = PreparedScene::new(scene);
        let reference = render(
            &prepared.clone().with_execution(records),
            &settings,
            &|_| {},
        )
        .unwrap();
        assert!(!reference.stats.lane_wave);
        for &simd in &SimdLevel::available() {
            for wave in [1, 16, Execution::WAVE] {
                let execution = Execution {
                    simd,
                    wave,
                    lane_wave: true,
                };
                let lanes = prepared.clone().with_execution(execution);
                let out = render(&lanes, &settings, &|_| {}).unwrap();
                assert!(out.stats.lane_wave, "{name}: the lane wave did not run");
                assert!(
                    out.film == reference.film,
                    "{name}: the lane wave on {simd:?} in waves of {wave} changes the image"
                );
                assert_eq!(
                    untimed(out.stats.rays),
                    untimed(reference.stats.rays),
                    "{name}: the lane wave traces other rays"
                );
            }
        }
    }
}
