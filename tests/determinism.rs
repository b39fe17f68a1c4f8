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
