//! `cargo xtask figures`: the report's images, regenerated deterministically
//! (fixed seeds) into `docs/figures/`, with `docs/FIGURES.md` describing
//! each one and the command and scene that made it.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use image::RgbImage;
use lueur::integrator::Film;
use lueur::sampling::SamplerKind;
use lueur::scene::SceneFile;
use lueur::scene::{RenderSettings, Strategy};

use crate::compose::{color_bar, error_map, grid, stack};
use crate::pointset_figures::{ErrorSpectrumPlan, PointsPlan, pointsets_figure, zsobol_figure};
use crate::reference::{Reference, flatten, reference};
use crate::report::{Plans, output_dir, quick_flag, write_report};
use crate::{load_scene, render_with_bar};

/// The shipped scenes, in the order of the report's figures.
pub const SCENES: [&str; 3] = ["death-star", "donut-mirrors", "cornell-spheres"];

/// Image sizes and sample counts of one run of the command.
struct Plan {
    showcase_size: u32,
    showcase_spp: u32,
    compare_size: u32,
    compare_spp: [u32; 2],
    reference_spp: u32,
    /// Figure 8: points per set and seeds averaged in each spectrum.
    points: PointsPlan,
    /// Figure 10: spp of the two samplers' renders and seeds averaged.
    error_spp: u32,
    error_seeds: u64,
}

const PLANS: Plans<Plan> = Plans {
    full: Plan {
        showcase_size: 256,
        showcase_spp: 256,
        compare_size: 128,
        compare_spp: [4, 128],
        reference_spp: 4096,
        points: PointsPlan { n: 1024, seeds: 8 },
        error_spp: 4,
        error_seeds: 8,
    },
    quick: Plan {
        showcase_size: 64,
        showcase_spp: 8,
        compare_size: 48,
        compare_spp: [4, 32],
        reference_spp: 256,
        points: PointsPlan { n: 256, seeds: 2 },
        error_spp: 4,
        error_seeds: 4,
    },
};

/// Relative error shown as the top of the colour scale of error maps.
const ERROR_FULL_SCALE: f64 = 1.0;
/// Added to the reference in the relative error's denominator, so that
/// black pixels do not divide by zero (the usual relMSE guard).
const ERROR_EPSILON: f64 = 0.01;

pub fn run(quick: bool) -> Result<()> {
    let plan = PLANS.pick(quick);
    let dir = output_dir(quick, "figures")?;
    let mut md = String::new();
    let flag = quick_flag(quick);
    writeln!(
        md,
        "# Figures\n\nEvery image here is made by `cargo xtask figures{flag}` from the scene files in \
         `scenes/`, with fixed seeds, so running it again gives the same files. Error maps show the \
         per-pixel relative error |x - ref| / (ref + {ERROR_EPSILON}), averaged over RGB, against a \
         `mis` reference at {} spp; the colour scale runs from 0 (dark) to {ERROR_FULL_SCALE} and above \
         (yellow).\n",
        plan.reference_spp
    )?;

    showcase(&mut md, plan, &dir)?;

    // Figures 3 to 7: each strategy at two sample counts on the donut, with
    // error maps against a reference. Independent samples, as in the report:
    // the differences are then the strategies' alone.
    let scene = "donut-mirrors";
    let file = load_scene(scene)?;
    let size = plan.compare_size;
    let reference = reference(scene, &file, size, plan.reference_spp)?;
    let renders = strategy_renders(plan, &dir, &file, &reference)?;
    strategy_figures(&mut md, plan, &dir, scene, &renders)?;

    // Figure 8: the point sets of lueur-pointsets and their spectra.
    md.push_str(&pointsets_figure(&dir, &plan.points, flag)?);

    // Figure 10: the zsobol sampler's error is blue noise on screen. The
    // donut's reference above is reused (same scene and size).
    md.push_str(&zsobol_figure(
        &dir,
        scene,
        &file,
        &reference.mean,
        &ErrorSpectrumPlan {
            size,
            spp: plan.error_spp,
            seeds: plan.error_seeds,
            reference_spp: plan.reference_spp,
        },
        flag,
    )?);
    write_report(quick, "FIGURES.md", &md)?;
    Ok(())
}

/// Figures 1 and 2 (and the Cornell example): the shipped scenes with the
/// default strategy at enough samples to show the scene rather than the
/// noise; the comparisons show the noise.
fn showcase(md: &mut String, plan: &Plan, dir: &Path) -> Result<()> {
    for (i, name) in SCENES.iter().enumerate() {
        let file = load_scene(name)?;
        let settings = RenderSettings {
            width: plan.showcase_size,
            height: plan.showcase_size,
            strategy: Strategy::Mis,
            spp: plan.showcase_spp,
            ..file.settings.clone()
        };
        let film = render_with_bar(&file.scene, &settings, name)?;
        save(&to_rgb(&film), &dir.join(format!("{name}.png")))?;
        writeln!(
            md,
            "## {}\n\n![]({name}.png)\n\n`scenes/{name}.toml`, {}x{}, `mis`, `{}`, {} spp.\n",
            match i {
                0 => "Figure 1: the Death Star under a light at infinity",
                1 => "Figure 2: the donut between two mirror spheres",
                _ => "The Cornell box with a diffuse and a mirror sphere",
            },
            plan.showcase_size,
            plan.showcase_size,
            settings.sampler,
            plan.showcase_spp
        )?;
    }

    Ok(())
}

/// One strategy's render at one spp on the donut: its image, its error map
/// and its mean relative error.
type StrategyRender = (Strategy, u32, RgbImage, RgbImage, f64);

/// Each strategy at the plan's two sample counts on the donut, independent
/// samples, saved as PNG, with error maps against `reference`.
fn strategy_renders(
    plan: &Plan,
    dir: &Path,
    file: &SceneFile,
    reference: &Reference,
) -> Result<Vec<StrategyRender>> {
    let size = plan.compare_size;
    let mut renders: Vec<StrategyRender> = Vec::new();
    for strategy in [
        Strategy::Uniform,
        Strategy::Light,
        Strategy::Mixture,
        Strategy::Mis,
    ] {
        for spp in plan.compare_spp {
            let settings = RenderSettings {
                width: size,
                height: size,
                spp,
                strategy,
                sampler: SamplerKind::Independent,
                ..file.settings.clone()
            };
            let label = format!("donut {strategy} {spp} spp");
            let film = render_with_bar(&file.scene, &settings, &label)?;
            let img = to_rgb(&film);
            save(&img, &dir.join(format!("donut-{strategy}-{spp}spp.png")))?;
            let (errors, mean_error) = relative_errors(&film, &reference.mean);
            let map = error_map(size, size, &errors, ERROR_FULL_SCALE);
            renders.push((strategy, spp, img, map, mean_error));
        }
    }
    Ok(renders)
}

/// Figures 3 to 7 from the strategy renders: each strategy at two spp, and
/// all of them side by side at each spp.
fn strategy_figures(
    md: &mut String,
    plan: &Plan,
    dir: &Path,
    scene: &str,
    renders: &[StrategyRender],
) -> Result<()> {
    let size = plan.compare_size;
    let bar = color_bar(size, "0", &format!(">={ERROR_FULL_SCALE}"));
    let cell = |s: Strategy, spp: u32| {
        renders
            .iter()
            .find(|r| r.0 == s && r.1 == spp)
            .expect("rendered above")
    };
    let [low, high] = plan.compare_spp;
    for (number, strategy, what) in [
        (3, Strategy::Uniform, "uniform hemisphere sampling"),
        (
            4,
            Strategy::Light,
            "light sampling (biased: no light through the mirrors)",
        ),
        (5, Strategy::Mixture, "the mixture of both (one-sample MIS)"),
    ] {
        let (a, b) = (cell(strategy, low), cell(strategy, high));
        let fig = stack(&[
            grid(
                Some(&format!("Fig. {number}: {strategy}")),
                &[
                    vec![
                        (format!("{low} spp"), a.2.clone()),
                        (format!("{high} spp"), b.2.clone()),
                    ],
                    vec![
                        (format!("err {:.3}", a.4), a.3.clone()),
                        (format!("err {:.3}", b.4), b.3.clone()),
                    ],
                ],
            ),
            bar.clone(),
        ]);
        let file_name = format!("fig{number}-{strategy}.png");
        save(&fig, &dir.join(&file_name))?;
        writeln!(
            md,
            "## Figure {number}: {what}\n\n![]({file_name})\n\n`scenes/{scene}.toml` at {size}x{size}, \
             `--strategy {strategy} --sampler independent`, {low} and {high} spp; below each image its \
             error map and mean relative error.\n"
        )?;
    }
    for (number, spp) in [(6, high), (7, low)] {
        let strategies = [
            Strategy::Uniform,
            Strategy::Mixture,
            Strategy::Light,
            Strategy::Mis,
        ];
        let images = strategies
            .iter()
            .map(|&s| (s.to_string(), cell(s, spp).2.clone()))
            .collect();
        let maps = strategies
            .iter()
            .map(|&s| (format!("err {:.3}", cell(s, spp).4), cell(s, spp).3.clone()))
            .collect();
        let fig = stack(&[
            grid(
                Some(&format!("Fig. {number}: {spp} spp each")),
                &[images, maps],
            ),
            bar.clone(),
        ]);
        let file_name = format!("fig{number}-strategies-{spp}spp.png");
        save(&fig, &dir.join(&file_name))?;
        writeln!(
            md,
            "## Figure {number}: uniform, mixture, light and mis at {spp} spp\n\n![]({file_name})\n\n\
             The report's side-by-side comparison at equal samples (independent samples), with `mis` \
             added, and the error maps. \
             `light` looks smoothest but is wrong where light arrives through the mirrors: its error \
             does not fall with more samples.\n"
        )?;
    }

    Ok(())
}

/// Per-pixel relative error against the reference (RGB averaged), and its
/// mean over the image.
fn relative_errors(film: &Film, reference: &[f32]) -> (Vec<f64>, f64) {
    let img = flatten(&film.mean_image());
    let errors: Vec<f64> = img
        .chunks_exact(3)
        .zip(reference.chunks_exact(3))
        .map(|(x, r)| {
            x.iter()
                .zip(r)
                .map(|(&x, &r)| {
                    (f64::from(x) - f64::from(r)).abs() / (f64::from(r) + ERROR_EPSILON)
                })
                .sum::<f64>()
                / 3.0
        })
        .collect();
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    (errors, mean)
}

fn to_rgb(film: &Film) -> RgbImage {
    RgbImage::from_raw(film.width(), film.height(), film.srgb8(0.0)).expect("film size matches")
}

pub fn save(img: &RgbImage, path: &Path) -> Result<()> {
    img.save(path)
        .with_context(|| format!("writing {}", path.display()))
}
