use lueur::integrator::Strategy;

use crate::common::{SHIPPED, run_with_threads, shipped};

#[test]
fn every_shipped_scene_is_bit_identical_on_one_and_two_threads() {
    for name in SHIPPED {
        let file = shipped(name);
        for strategy in Strategy::ALL {
            let mut settings = file.settings.clone();
            (
                settings.width,
                settings.height,
                settings.spp,
                settings.strategy,
            ) = (24, 20, 4, strategy);
            let one = run_with_threads(&file.scene, &settings, 1);
            let two = run_with_threads(&file.scene, &settings, 2);
            assert!(
                one == two,
                "{name} with {strategy}: the image depends on the thread count"
            );
        }
    }
}

#[test]
fn the_seed_changes_the_image_and_only_the_seed() {
    let file = shipped("donut-mirrors");
    let mut settings = file.settings.clone();
    (settings.width, settings.height, settings.spp) = (16, 16, 2);
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
        let mut settings = file.settings.clone();
        (
            settings.width,
            settings.height,
            settings.spp,
            settings.sampler,
        ) = (20, 18, 8, sampler);
        let whole = run_with_threads(&file.scene, &settings, 2);
        let mut film = Film::new(settings.width, settings.height);
        let never = AtomicBool::new(false);
        for until in [1, 2, 4, 8] {
            render_pass(&file.scene, &settings, &mut film, until, &never, &|_| {})
                .unwrap()
                .expect("not cancelled");
            assert_eq!(film.spp(), until);
        }
        assert!(film == whole, "{sampler}: passes differ from one pass");
    }
}

/// Shards cut anywhere, rendered apart (each in its own passes) and merged
/// in any order, give the film of one render bit for bit, for every sampler
/// (the samplers laid out over the total spp get that total).
#[test]
fn shards_merge_into_the_single_render_bit_for_bit() {
    use std::sync::atomic::AtomicBool;

    use lueur::integrator::{Film, render_pass};
    use lueur::sampling::SamplerKind;

    let file = shipped("donut-mirrors");
    let never = AtomicBool::new(false);
    for &sampler in SamplerKind::ALL {
        let mut settings = file.settings.clone();
        (
            settings.width,
            settings.height,
            settings.spp,
            settings.sampler,
        ) = (11, 7, 13, sampler);
        let whole = run_with_threads(&file.scene, &settings, 1);
        let shard = |range: std::ops::Range<u32>, step: u32| {
            let mut film = Film::starting_at(11, 7, range.start);
            let mut until = range.start;
            while until < range.end {
                until = (until + step).min(range.end);
                render_pass(&file.scene, &settings, &mut film, until, &never, &|_| {})
                    .unwrap()
                    .expect("not cancelled");
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

/// A cancelled pass leaves the film exactly as it was.
#[test]
fn a_cancelled_pass_changes_nothing() {
    use std::sync::atomic::AtomicBool;

    use lueur::integrator::{Film, render_pass};

    let file = shipped("cornell-spheres");
    let mut settings = file.settings.clone();
    (settings.width, settings.height, settings.spp) = (16, 16, 4);
    let mut film = Film::new(16, 16);
    render_pass(
        &file.scene,
        &settings,
        &mut film,
        2,
        &AtomicBool::new(false),
        &|_| {},
    )
    .unwrap()
    .unwrap();
    let before = film.clone();
    let cancelled = render_pass(
        &file.scene,
        &settings,
        &mut film,
        4,
        &AtomicBool::new(true),
        &|_| {},
    )
    .unwrap();
    assert!(cancelled.is_none());
    assert!(film == before && film.spp() == 2);
    // A pass that adds nothing, or overshoots the render's spp, is refused.
    let never = AtomicBool::new(false);
    assert!(render_pass(&file.scene, &settings, &mut film, 2, &never, &|_| {}).is_err());
    assert!(render_pass(&file.scene, &settings, &mut film, 5, &never, &|_| {}).is_err());
}
