//! The strategies against each other on the shipped scenes. Means are
//! compared with a z-test at Z = 4 on their combined standard error
//! (two-sided p ~ 6e-5 per comparison for normal means).

use lueur::integrator::Film;
use lueur::sampling::SamplerKind;
use lueur::scene::{RenderSettings, Strategy};

use crate::common::{SHIPPED, run, shipped};

fn render(name: &str, strategy: Strategy, size: u32, spp: u32) -> Film {
    let file = shipped(name);
    let settings = RenderSettings {
        sampler: SamplerKind::Independent,
        width: size,
        height: size,
        spp,
        strategy,
        seed: 7,
        ..file.settings.clone()
    };
    run(&file.scene, &settings).film
}

#[test]
fn every_strategy_renders_every_shipped_scene_without_nan() {
    for name in SHIPPED {
        for strategy in Strategy::ALL {
            let film = render(name, strategy, 16, 4);
            assert!(film.image_mean().0 > 0.0, "{name} with {strategy} is black");
        }
    }
}

#[test]
fn unbiased_strategies_agree_and_light_sampling_misses_indirect_light() {
    for name in ["cornell-spheres", "donut-mirrors"] {
        let means: Vec<(Strategy, f64, f64)> = Strategy::ALL
            .into_iter()
            .map(|s| {
                let (m, se) = render(name, s, 24, 512).image_mean();
                (s, m, se)
            })
            .collect();
        let unbiased: Vec<_> = means.iter().filter(|m| m.0.is_unbiased()).collect();
        for a in &unbiased {
            for b in &unbiased {
                let z = (a.1 - b.1).abs() / (a.2 * a.2 + b.2 * b.2).sqrt();
                assert!(
                    z < 4.0,
                    "{name}: {} {:.5}+-{:.5} vs {} {:.5}+-{:.5}",
                    a.0,
                    a.1,
                    a.2,
                    b.0,
                    b.1,
                    b.2
                );
            }
        }
        let light = means.iter().find(|m| m.0 == Strategy::Light).unwrap();
        let mis = means.iter().find(|m| m.0 == Strategy::Mis).unwrap();
        let z = (mis.1 - light.1) / (mis.2 * mis.2 + light.2 * light.2).sqrt();
        assert!(
            z > 4.0,
            "{name}: light sampling ({:.5}) should be darker than mis ({:.5})",
            light.1,
            mis.1
        );
    }
}

/// The report's claim (its Figure 6): at equal samples, the mixture has
/// less variance than uniform sampling; and MIS does at least as well.
#[test]
fn mixture_beats_uniform_and_mis_beats_mixture_on_the_donut() {
    let var = |s| render("donut-mirrors", s, 24, 256).mean_sample_variance();
    let (uniform, mixture, mis) = (
        var(Strategy::Uniform),
        var(Strategy::Mixture),
        var(Strategy::Mis),
    );
    assert!(mixture < uniform, "mixture {mixture} vs uniform {uniform}");
    assert!(mis <= mixture, "mis {mis} vs mixture {mixture}");
}
