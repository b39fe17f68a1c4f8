//! `cargo xtask peers`: lueur against Mitsuba 3 on the shipped scene both
//! can express (`cornell-spheres.toml`: boxes, spheres, Lambertian and
//! mirror, a sphere light), for correctness and for speed.
//!
//! Mitsuba is a peer for measurement only, never a dependency: this report
//! runs `xtask/peers/mitsuba_render.py` with the machine's `python3` where
//! `pip install mitsuba numpy` was done (for `llvm_ad_rgb`, also Debian's
//! `libllvm19`; `DRJIT_LIBLLVM_PATH` is set to it when found), and refuses
//! to run otherwise. CI does not run it.
//!
//! 1. **Correctness**: lueur's `mis` with independent samples at the
//!    highest spp against a Mitsuba reference (`llvm_ad_rgb`, independent,
//!    many passes with other seeds): per-channel image means and a z-map
//!    over 8x8-pixel regions, each z using both images' standard errors. The
//!    same on `xtask/peers/open-air.toml`, a scene made for this report with
//!    every kind of light and shape both express (a plane, transformed boxes,
//!    rectangle and directional lights, a sky), at the default camera shell
//!    and at a thin one.
//! 2. **Speed and efficiency**: every configuration at 4 to 256 spp, MSE
//!    against the reference (less the reference's own variance) and the
//!    render time (lueur: its own measured render; Mitsuba: the warm
//!    render, the kernel compile of the JIT variant reported apart), so
//!    samples per second and MSE x time (lower is better: the time needed
//!    for a given error is proportional to it) compare in one run. Times
//!    are medians over rounds that interleave the configurations, and
//!    lueur's ratios to Mitsuba are taken within each round: on a shared
//!    machine a median of one configuration's renders in a row moved by
//!    10-25% between runs, and a slow spell fell on whichever ran in it.
//!    Writes `docs/PEERS.md`.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, ensure};
use lueur::sampling::SamplerKind;
use lueur::scene::SceneFile;
use lueur::scene::{RenderSettings, Strategy};

use crate::memory::this_build;
use crate::mitsuba::{Shot, installed, run_script, version};
use crate::reference::{Reference, cache_dir, flatten, render_film};
use crate::report::{Plans, write_report};
use crate::{load_scene, load_scene_at, project_root};

/// The one shipped scene Mitsuba can express as it is.
pub const SCENE: &str = "cornell-spheres";
/// A scene file made for this report, from the project root: a plane, boxes turned and scaled by the
/// transform keys, a rectangle light, a light at infinity and a sky, which the shipped
/// scene Mitsuba can express has none of.
const OPEN_AIR: &str = "xtask/peers/open-air.toml";
/// The camera hit threshold, in pixel footprints, of the second render of [`OPEN_AIR`]:
/// thin enough that the silhouettes the default threshold grows are no longer seen.
const THIN_SHELL: f32 = 1.0 / 1024.0;

struct Plan {
    size: u32,
    spps: &'static [u32],
    /// Rounds of renders, each of every configuration at every spp, interleaved: a time is
    /// the median over rounds, and a ratio is taken within each round before its median,
    /// so that a slow spell of a shared machine falls on every configuration alike.
    rounds: u32,
    reference_passes: u32,
    reference_pass_spp: u32,
    /// lueur's render for the correctness z-map.
    correctness_spp: u32,
    /// [`OPEN_AIR`]'s image size, its reference's passes and spp per pass, and lueur's
    /// spp.
    open_air: [u32; 4],
}

const PLANS: Plans<Plan> = Plans {
    full: Plan {
        size: 256,
        spps: &[4, 16, 64, 256],
        rounds: 3,
        reference_passes: 16,
        reference_pass_spp: 256,
        correctness_spp: 1024,
        open_air: [128, 16, 1024, 4096],
    },
    quick: Plan {
        size: 64,
        spps: &[4, 16],
        rounds: 1,
        reference_passes: 4,
        reference_pass_spp: 64,
        correctness_spp: 64,
        open_air: [32, 4, 64, 64],
    },
};

#[derive(Clone, Copy)]
enum Config {
    /// lueur's `mis` with a sampler, and a replicate count other than the default where
    /// given: one replicate gives up per-pixel error bars for the stratification of one
    /// point set of the whole spp (docs/REPLICATES.md).
    Lueur(SamplerKind, Option<u32>),
    Mitsuba {
        variant: &'static str,
        sampler: &'static str,
    },
}

impl Config {
    fn name(&self) -> String {
        match self {
            Config::Lueur(s, None) => format!("lueur mis, {}", s.name()),
            Config::Lueur(s, Some(k)) => format!(
                "lueur mis, {}, {k} replicate{}",
                s.name(),
                if *k == 1 { "" } else { "s" }
            ),
            Config::Mitsuba { variant, sampler } => format!("Mitsuba {variant}, {sampler}"),
        }
    }
}

/// One configuration's figures at one spp.
struct Measured {
    spp: u32,
    /// One render's time, then, once every round has run, the median of `round_seconds`.
    seconds: f64,
    /// Its render time in each round, in round order.
    round_seconds: Vec<f64>,
    /// Mitsuba's JIT variants: the first render, kernel compile included.
    first_seconds: Option<f64>,
    mse: f64,
}

/// An RGB image, interleaved, with its size.
struct Rgb {
    width: usize,
    pixels: Vec<f32>,
}

fn read_rgb(path: &Path) -> Result<Rgb> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![0f32; 3 * res.width() * res.height()]),
        |(w, px): &mut (usize, Vec<f32>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let i = 3 * (pos.y() * *w + pos.x());
            px[i..i + 3].copy_from_slice(&[r, g, b]);
        },
    )
    .with_context(|| format!("reading {}", path.display()))?;
    let (width, pixels) = image.layer_data.channel_data.pixels;
    Ok(Rgb { width, pixels })
}

fn scene_path() -> PathBuf {
    project_root().join("scenes").join(format!("{SCENE}.toml"))
}

/// Runs the Mitsuba script on [`SCENE`]; returns the numbers it prints,
/// one `key value` line each.
pub fn mitsuba(args: &[String]) -> Result<HashMap<String, f64>> {
    run_script(&scene_path(), &load_scene(SCENE)?, args)
}

pub fn run(quick: bool) -> Result<()> {
    let plan = PLANS.pick(quick);
    ensure!(
        installed()?,
        "Mitsuba 3 (with numpy, which its multi-pass renders use) is not installed for \
         python3: `pip install mitsuba numpy` (and, for llvm_ad_rgb, Debian's libllvm19). It is \
         a peer for this report only, never a dependency of lueur."
    );
    let work = cache_dir()?.join("peers");
    std::fs::create_dir_all(&work)?;
    let (reference_path, reference_time) = mitsuba_reference(plan, &work)?;
    let reference = read_rgb(&reference_path)?;
    let reference_var = read_rgb(&reference_path.with_extension("var.exr"))?;
    let file = load_scene(SCENE)?;
    let correctness = correctness(
        &file,
        [plan.size, plan.correctness_spp],
        file.settings.pixel_epsilon,
        &reference,
        &reference_var,
    )?;
    let open_air = open_air(plan, &work)?;
    let against = Reference {
        mean: reference.pixels,
        var_of_mean: reference_var.pixels,
    };
    let configs = [
        Config::Lueur(SamplerKind::Independent, None),
        Config::Lueur(SamplerKind::default(), None),
        Config::Lueur(SamplerKind::default(), Some(1)),
        Config::Mitsuba {
            variant: "scalar_rgb",
            sampler: "independent",
        },
        Config::Mitsuba {
            variant: "llvm_ad_rgb",
            sampler: "independent",
        },
        Config::Mitsuba {
            variant: "llvm_ad_rgb",
            sampler: "multijitter",
        },
        Config::Mitsuba {
            variant: "llvm_ad_rgb",
            sampler: "ldsampler",
        },
    ];
    // Every configuration at one spp, then the next spp; the configurations' order reversed
    // every other round, so that none always runs right after the same one.
    let mut rows: Vec<Vec<Option<Measured>>> = (configs.iter())
        .map(|_| plan.spps.iter().map(|_| None).collect())
        .collect();
    for round in 0..plan.rounds {
        for (s, &spp) in plan.spps.iter().enumerate() {
            let mut order: Vec<usize> = (0..configs.len()).collect();
            if round % 2 == 1 {
                order.reverse();
            }
            for k in order {
                let m = measure(plan, &file, &work, &against, configs[k], spp)?;
                eprintln!(
                    "round {}/{}: {:<36} {:>4} spp  {:>7.2} s  MSE {:.3e}",
                    round + 1,
                    plan.rounds,
                    configs[k].name(),
                    spp,
                    m.seconds,
                    m.mse
                );
                let seconds = m.seconds;
                rows[k][s].get_or_insert(m).round_seconds.push(seconds);
            }
        }
    }
    let results: Vec<(Config, Vec<Measured>)> = configs
        .into_iter()
        .zip(rows)
        .map(|(c, r)| {
            (
                c,
                r.into_iter()
                    .map(|m| {
                        let mut m = m.expect("every round measures every spp");
                        m.seconds = median(m.round_seconds.clone());
                        m
                    })
                    .collect(),
            )
        })
        .collect();
    let md = report(plan, &results, &correctness, &open_air, reference_time)?;
    write_report(quick, "PEERS.md", &md)?;
    Ok(())
}

/// The reference: Mitsuba's fastest variant, independent samples, seeds far
/// from the measured renders'. Cached: it takes minutes, and is a function
/// of the scene text, the plan and Mitsuba's version only. Returns its path
/// and how long it took (NaN when cached).
fn mitsuba_reference(plan: &Plan, work: &Path) -> Result<(PathBuf, f64)> {
    let shot = Shot {
        path: scene_path(),
        size: plan.size,
        passes: plan.reference_passes,
        pass_spp: plan.reference_pass_spp,
    };
    shot.reference(
        &load_scene(SCENE)?,
        &work.join(format!("reference-{}px.exr", plan.size)),
    )
}

/// Correctness first: independent samples (their standard errors are
/// honest; a QMC film's overstate the error) at more spp than the speed
/// series, with another seed, at `size` squared and with the camera shell
/// `pixel_epsilon`: the table [`compare`] makes against the reference.
fn correctness(
    file: &SceneFile,
    [size, spp]: [u32; 2],
    pixel_epsilon: f32,
    reference: &Rgb,
    reference_var: &Rgb,
) -> Result<String> {
    eprintln!("correctness: lueur mis, independent, {spp} spp, shell {pixel_epsilon}");
    let settings = RenderSettings {
        width: size,
        height: size,
        spp,
        strategy: Strategy::Mis,
        sampler: SamplerKind::Independent,
        seed: 7,
        pixel_epsilon,
        ..file.settings.clone()
    };
    let (film, _) = render_film(file, &settings)?;
    compare(
        &flatten(&film.mean_image()),
        &film.variance_image(),
        reference,
        reference_var,
        size,
    )
}

/// Correctness on [`OPEN_AIR`]: lueur at the default camera shell and at [`THIN_SHELL`],
/// each against a Mitsuba reference, in a section of the report.
fn open_air(plan: &Plan, work: &Path) -> Result<String> {
    let [size, passes, pass_spp, spp] = plan.open_air;
    let file = load_scene_at(OPEN_AIR)?;
    let shot = Shot {
        path: project_root().join(OPEN_AIR),
        size,
        passes,
        pass_spp,
    };
    let (reference_path, seconds) =
        shot.reference(&file, &work.join(format!("open-air-{size}px.exr")))?;
    let reference = read_rgb(&reference_path)?;
    let reference_var = read_rgb(&reference_path.with_extension("var.exr"))?;
    let mut md = String::new();
    writeln!(
        md,
        "## Correctness on every kind of light\n\n`{OPEN_AIR}`, made for \
         this report: a plane (Mitsuba's twin is a square 2e4 wide, whose edge no ray the \
         image sees reaches), a diffuse and a mirror sphere, boxes turned, scaled and moved by \
         the transform keys, a rectangle light facing down, a light at infinity and a sky; \
         {size}x{size}, max_depth {}. lueur (`mis`, independent samples, {spp} spp, seed 7) \
         against a Mitsuba reference (`llvm_ad_rgb`, {passes} x {pass_spp} spp{}), twice: \
         with the default camera shell, and with a shell of {} pixel. A camera ray that passes \
         within the shell of a silhouette is a hit, so silhouettes grow by the shell's width; \
         Mitsuba's intersections are exact. The thin shell shows what is left once that is \
         gone.\n",
        file.settings.max_depth,
        if seconds.is_finite() {
            format!("; {seconds:.0} s")
        } else {
            String::new()
        },
        fraction(THIN_SHELL),
    )?;
    for (label, pixel_epsilon) in [
        (
            format!(
                "default shell ({} pixel)",
                fraction(file.settings.pixel_epsilon)
            ),
            file.settings.pixel_epsilon,
        ),
        (
            format!("shell of {} pixel", fraction(THIN_SHELL)),
            THIN_SHELL,
        ),
    ] {
        let table = correctness(
            &file,
            [size, spp],
            pixel_epsilon,
            &reference,
            &reference_var,
        )?;
        writeln!(md, "**{label}**\n\n{table}")?;
    }
    Ok(md)
}

/// `x` as `1/n` where it is the inverse of a whole number.
fn fraction(x: f32) -> String {
    let n = 1.0 / x;
    if n.fract() == 0.0 {
        format!("1/{n}")
    } else {
        format!("{x}")
    }
}

/// One render of a configuration at `spp`: its time and its MSE against the reference
/// (the images are the same in every round, so the first round's figures are kept).
fn measure(
    plan: &Plan,
    file: &SceneFile,
    work: &Path,
    reference: &Reference,
    config: Config,
    spp: u32,
) -> Result<Measured> {
    Ok(match config {
        Config::Lueur(sampler, replicates) => {
            let settings = RenderSettings {
                width: plan.size,
                height: plan.size,
                spp,
                strategy: Strategy::Mis,
                sampler,
                replicates: replicates.or(file.settings.replicates),
                ..file.settings.clone()
            };
            let (film, seconds) = render_film(file, &settings)?;
            let img = flatten(&film.mean_image());
            Measured {
                spp,
                seconds,
                round_seconds: Vec::new(),
                first_seconds: None,
                mse: reference.mse(&img),
            }
        }
        Config::Mitsuba { variant, sampler } => {
            let out = work.join(format!("{variant}-{sampler}-{spp}.exr"));
            let mut args = vec![
                variant.to_string(),
                spp.to_string(),
                out.display().to_string(),
                "--sampler".into(),
                sampler.into(),
                "--repeats".into(),
                "1".into(),
                "--width".into(),
                plan.size.to_string(),
                "--height".into(),
                plan.size.to_string(),
            ];
            args.extend(["--seed".into(), "0".into()]);
            let numbers = mitsuba(&args)?;
            let img = read_rgb(&out)?;
            Measured {
                spp,
                seconds: *numbers
                    .get("warm_s")
                    .context("no warm_s from mitsuba_render.py")?,
                round_seconds: Vec::new(),
                first_seconds: numbers.get("first_s").copied(),
                mse: reference.mse(&img.pixels),
            }
        }
    })
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// lueur's image against the reference: per-channel means and a z-map
/// over 8x8 regions.
fn compare(
    img: &[f32],
    var: &[glam::Vec3],
    reference: &Rgb,
    reference_var: &Rgb,
    size: u32,
) -> Result<String> {
    let size = size as usize;
    ensure!(reference.width == size, "reference size");
    let var = flatten(var);
    let mut out = String::new();
    let n = (size * size) as f64;
    writeln!(
        out,
        "| channel | lueur | Mitsuba reference | difference | z |"
    )?;
    writeln!(out, "|---|---|---|---|---|")?;
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        let ch = |v: &[f32]| {
            v.iter()
                .skip(c)
                .step_by(3)
                .map(|&x| f64::from(x))
                .sum::<f64>()
        };
        let (a, b) = (ch(img) / n, ch(&reference.pixels) / n);
        let se = ((ch(&var) + ch(&reference_var.pixels)) / (n * n)).sqrt();
        writeln!(
            out,
            "| {name} | {a:.5} | {b:.5} | {:+.3}% | {:+.1} |",
            100.0 * (a - b) / b,
            (a - b) / se
        )?;
    }
    let region = 8;
    let mut zs = Vec::new();
    for ry in 0..size / region {
        for rx in 0..size / region {
            for c in 0..3 {
                let (mut d, mut v) = (0.0, 0.0);
                for y in ry * region..(ry + 1) * region {
                    for x in rx * region..(rx + 1) * region {
                        let i = 3 * (y * size + x) + c;
                        d += f64::from(img[i]) - f64::from(reference.pixels[i]);
                        v += f64::from(var[i]) + f64::from(reference_var.pixels[i]);
                    }
                }
                if v > 0.0 {
                    zs.push(d / v.sqrt());
                }
            }
        }
    }
    let max = zs.iter().fold(0.0f64, |m, z| m.max(z.abs()));
    let over4 = zs.iter().filter(|z| z.abs() > 4.0).count();
    let below4 = zs.iter().filter(|z| **z < -4.0).count();
    let rms = (zs.iter().map(|z| z * z).sum::<f64>() / zs.len() as f64).sqrt();
    writeln!(
        out,
        "\nOver {} regions of {region}x{region} pixels x RGB: RMS z {rms:.2} (1 if the \
         images differ by noise alone), max |z| {max:.1}, {over4} beyond 4, {below4} of them below -4 (for {} independent \
         normals the largest |z| is about {:.1}).",
        zs.len(),
        zs.len(),
        expected_max_z(zs.len())
    )?;
    Ok(out)
}

/// Roughly the median of the largest |z| among `k` standard normals.
fn expected_max_z(k: usize) -> f64 {
    (2.0 * (k as f64).ln()).sqrt()
}

fn report(
    plan: &Plan,
    results: &[(Config, Vec<Measured>)],
    correctness: &str,
    open_air: &str,
    reference_time: f64,
) -> Result<String> {
    let mut md = String::new();
    let size = plan.size;
    writeln!(md, "# lueur and Mitsuba 3\n")?;
    writeln!(
        md,
        "`cargo xtask peers` on `scenes/{SCENE}.toml` ({size}x{size}, max_depth 8, \
         Russian roulette on), the shipped scene Mitsuba can express as it is: boxes, spheres, \
         Lambertian and mirror materials, a sphere light. Mitsuba {} runs \
         `xtask/peers/mitsuba_render.py`, which translates the scene file (its `path` \
         integrator combines BSDF and emitter sampling by the power heuristic, as lueur's \
         `mis` does), with roulette from the same depth as lueur's (`rr_depth` = \
         `roulette_depth` = {}, scattering events). Both on this machine's 2 cores, in one \
         run. Mitsuba is a peer for this report, never a dependency: the report refuses to \
         run without it.\n",
        version(),
        load_scene(SCENE)?.settings.roulette_depth,
    )?;
    writeln!(md, "## Correctness\n")?;
    writeln!(
        md,
        "lueur (`mis`, independent samples, {} spp, seed 7) against a Mitsuba reference \
         (`llvm_ad_rgb`, {} x {} spp, other seeds{}). The standard errors are both images' \
         own. A systematic difference shows as regions beyond 4 sigma of both signs or of \
         one sign in one kind of place (silhouettes, before the camera hit threshold was \
         lowered to a sixteenth of a pixel); the caustics' heavy tail (light reflected by the \
         mirror sphere, found by BSDF sampling only) shows at lower spp as regions only \
         *below* -4, where the rare bright samples have not been drawn yet.\n",
        plan.correctness_spp,
        plan.reference_passes,
        plan.reference_pass_spp,
        if reference_time.is_finite() {
            format!("; {reference_time:.0} s")
        } else {
            String::new()
        }
    )?;
    writeln!(md, "{correctness}")?;
    writeln!(md, "{open_air}")?;
    writeln!(md, "## Speed and error\n")?;
    writeln!(
        md,
        "Render time (lueur: its own measured render, in xtask's process, built by {}; Mitsuba: \
         the render after a first one, so a JIT variant's kernel compile, shown apart with the \
         first round's, is not counted), \
         median of {} rounds in which every configuration renders at every spp, interleaved \
         (their order reversed every other round). \
         MSE against the reference, less the reference's own variance. **MSE x time** is what \
         a given error costs: the time to reach an error is proportional to it (lower is \
         better). lueur's default sampler runs twice: with its default replicates, which give \
         each pixel an error bar, and with 1, which gives that up for one point set of the \
         whole spp per pixel (docs/REPLICATES.md).\n",
        this_build(),
        plan.rounds
    )?;
    writeln!(
        md,
        "Machine: {}, {} cores ({}); commit {}.\n",
        crate::speed::cpu_model(),
        std::thread::available_parallelism().map_or(0, std::num::NonZero::get),
        crate::speed::simd_features(),
        crate::speed::commit()
    )?;
    writeln!(
        md,
        "| configuration | spp | time | M samples/s | MSE | MSE x time |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|")?;
    let pixels = f64::from(size * size);
    for (config, rows) in results {
        for m in rows {
            let first = match m.first_seconds {
                Some(f) if matches!(config, Config::Mitsuba { variant, .. } if variant.starts_with("llvm")) =>
                {
                    format!(" (first: {f:.2} s)")
                }
                _ => String::new(),
            };
            writeln!(
                md,
                "| {} | {} | {:.2} s{first} | {:.2} | {:.3e} | {:.3e} |",
                config.name(),
                m.spp,
                m.seconds,
                pixels * f64::from(m.spp) / m.seconds / 1e6,
                m.mse,
                m.mse * m.seconds
            )?;
        }
    }
    summary(&mut md, plan, results)?;
    Ok(md)
}

/// The headline: lueur's default against Mitsuba's fastest, at every spp of the series;
/// then the same for the default sampler with one replicate, which gives up per-pixel
/// error bars for lower MSE.
fn summary(md: &mut String, plan: &Plan, results: &[(Config, Vec<Measured>)]) -> Result<()> {
    let best_mitsuba = results
        .iter()
        .filter(|(c, _)| matches!(c, Config::Mitsuba { .. }))
        .min_by(|a, b| {
            let last = |r: &Vec<Measured>| {
                let m = r.last().expect("rows");
                m.mse * m.seconds
            };
            last(&a.1).total_cmp(&last(&b.1))
        });
    let Some((mc, mr)) = best_mitsuba else {
        return Ok(());
    };
    let lueurs = results
        .iter()
        .filter(|(c, _)| matches!(c, Config::Lueur(s, _) if *s == SamplerKind::default()));
    for (lc, lr) in lueurs {
        writeln!(
            md,
            "\n**Summary**, {} against {} (the Mitsuba configuration with the lowest MSE x time at {} spp); \
             time ratios taken within each round, then their median (min-max over rounds):\n",
            lc.name(),
            mc.name(),
            plan.spps.last().unwrap()
        )?;
        for &spp in plan.spps {
            if let (Some(l), Some(m)) = (at(lr, spp), at(mr, spp)) {
                let ratios: Vec<f64> = (l.round_seconds.iter().zip(&m.round_seconds))
                    .map(|(lt, mt)| lt / mt)
                    .collect();
                let (lo, hi) = (ratios.iter())
                    .fold((f64::INFINITY, 0f64), |(lo, hi), &r| (lo.min(r), hi.max(r)));
                let time = median(ratios);
                let mse = l.mse / m.mse;
                writeln!(
                    md,
                    "- {spp} spp: lueur takes {time:.2}x Mitsuba's time per sample ({lo:.2}-{hi:.2}); \
                     its MSE is {mse:.2}x Mitsuba's, its MSE x time {:.2}x ({:.2}-{:.2}).",
                    mse * time,
                    mse * lo,
                    mse * hi
                )?;
            }
        }
    }
    Ok(())
}

/// A configuration's figures at `spp`.
fn at(rows: &[Measured], spp: u32) -> Option<&Measured> {
    rows.iter().find(|m| m.spp == spp)
}
