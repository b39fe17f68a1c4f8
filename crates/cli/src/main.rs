//! `lueur`: the command-line renderer. A thin shell over the library
//! crates: it reads scene files, draws the progress bar and writes images;
//! every decision about light lives in `lueur-integrator`.

mod checkpoint;
mod output;
mod points;
mod progressive;
mod stats;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use lueur_integrator::{Film, Marching, RenderOutput, RenderSettings, Strategy};
use lueur_sampling::SamplerKind;
use lueur_scene::{SceneFileError, parse_scene};

/// Exit status for input the user must fix (scene files, flags), as clap
/// does for usage errors.
const EXIT_BAD_INPUT: u8 = 2;

#[derive(Parser)]
#[command(
    name = "lueur",
    version,
    about = "A physically based SDF renderer with measured Monte Carlo"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file to an image (.png: 8-bit sRGB; .exr: linear float
    /// RGB plus the per-pixel variance of the mean).
    Render(RenderArgs),
    /// Generate a point set (CSV or PNG plot) and measure it: discrepancies
    /// and integration error.
    Points(points::PointsArgs),
}

#[derive(Parser)]
struct RenderArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Output image; the extension picks the format. Default: SCENE_NAME.png.
    #[arg(long, short)]
    out: Option<PathBuf>,
    /// Samples per pixel.
    #[arg(long)]
    spp: Option<u32>,
    /// How directions are chosen: uniform, cosine, light, mixture or mis.
    #[arg(long, value_parser = parse_strategy)]
    strategy: Option<Strategy>,
    /// Which point set feeds the estimator.
    #[arg(long, value_parser = parse_sampler)]
    sampler: Option<SamplerKind>,
    /// Seed of all random numbers.
    #[arg(long)]
    seed: Option<u64>,
    /// Maximum number of scattering events (0: only emitters seen directly).
    #[arg(long)]
    max_depth: Option<u32>,
    /// Image width in pixels.
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels.
    #[arg(long)]
    height: Option<u32>,
    /// Worker threads (default: one per core). The image does not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Exposure in stops applied before PNG encoding (EXR stays linear).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
    /// Print statistics after the render: rays, steps per ray, hit shares.
    #[arg(long)]
    stats: bool,
    /// March rays the naive way (plain sphere tracing, no bounding spheres): the
    /// reference that speed-ups are measured against.
    #[arg(long)]
    naive: bool,
    /// Stop at this wall-clock budget in seconds, after the last whole pass
    /// that fits (passes of 1, 1, 2, 4, ... spp; the first always runs).
    #[arg(long, value_name = "SECONDS")]
    time: Option<f64>,
    /// Stop once the image's relative standard error (RMS pixel standard
    /// error over mean radiance) is at most this, e.g. 0.01.
    #[arg(long, value_name = "E")]
    target_error: Option<f64>,
    /// Save the film's full state to this EXR after every pass, so the
    /// render can be continued later with --resume.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Continue from a checkpoint of the same scene and settings, up to
    /// --spp; the result is bit-identical to one uninterrupted render.
    #[arg(long, value_name = "FILE")]
    resume: Option<PathBuf>,
}

fn parse_strategy(s: &str) -> Result<Strategy, String> {
    Strategy::from_name(s).ok_or_else(|| {
        let all: Vec<_> = Strategy::ALL.iter().map(|s| s.name()).collect();
        format!("unknown strategy `{s}`; expected one of {}", all.join(", "))
    })
}

fn parse_sampler(s: &str) -> Result<SamplerKind, String> {
    SamplerKind::from_name(s).ok_or_else(|| {
        let all: Vec<_> = SamplerKind::ALL.iter().map(|s| s.name()).collect();
        format!("unknown sampler `{s}`; expected one of {}", all.join(", "))
    })
}

/// The render was stopped by a signal; what was complete has been written.
#[derive(Debug)]
struct Interrupted(u32);

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0 == 0 {
            write!(
                f,
                "interrupted before the first pass completed; nothing written"
            )
        } else {
            write!(
                f,
                "interrupted: wrote the {} spp completed before the signal",
                self.0
            )
        }
    }
}

impl std::error::Error for Interrupted {}

/// `Some(v)` if `v` is positive and finite, a usage error otherwise.
fn positive(v: Option<f64>, flag: &str) -> Result<Option<f64>> {
    match v {
        Some(x) if !(x > 0.0 && x.is_finite()) => {
            Err(BadInput(format!("{flag} must be positive and finite, got {x}")).into())
        }
        _ => Ok(v),
    }
}

/// An error the user caused and can fix; exits with status 2.
#[derive(Debug)]
struct BadInput(String);

impl std::fmt::Display for BadInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BadInput {}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => run_render(args),
        Command::Points(args) => points::run_points(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if let Some(scene_error) = e.downcast_ref::<SceneFileError>() {
                eprint!("{scene_error}");
                if !scene_error.to_string().ends_with('\n') {
                    eprintln!();
                }
                return ExitCode::from(EXIT_BAD_INPUT);
            }
            eprintln!("error: {e:#}");
            if e.downcast_ref::<Interrupted>().is_some() {
                return ExitCode::from(progressive::EXIT_INTERRUPTED);
            }
            if e.downcast_ref::<BadInput>().is_some() {
                ExitCode::from(EXIT_BAD_INPUT)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}

fn run_render(args: RenderArgs) -> Result<()> {
    let file = args.scene.display().to_string();
    let text = std::fs::read_to_string(&args.scene)
        .map_err(|e| BadInput(format!("cannot read scene file {file}: {e}")))?;
    let parsed = parse_scene(&text, &file)?;
    let mut scene = parsed.scene;
    if args.naive {
        scene.marching = Marching::Naive;
    }
    let settings = apply_flags(parsed.settings, &args)?;
    let out = match &args.out {
        Some(p) => p.clone(),
        None => default_output(&args.scene),
    };
    let format = output::Format::from_path(&out).map_err(|e| BadInput(e.to_string()))?;

    let limits = progressive::Limits {
        time: positive(args.time, "--time")?,
        target_error: positive(args.target_error, "--target-error")?,
    };
    progressive::install_signal_handler()?;

    let bar = ProgressBar::new(
        u64::from(settings.width) * u64::from(settings.height) * u64::from(settings.spp),
    );
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent}% ETA {eta}",
        )
        .expect("the template is valid"),
    );
    let progress = |n: u64| bar.inc(n);
    let fingerprint = checkpoint::settings_fingerprint(&settings, args.naive);
    let film = match &args.resume {
        Some(path) => {
            checkpoint::load(path, &text, &fingerprint).map_err(|e| BadInput(format!("{e:#}")))?
        }
        None => Film::new(settings.width, settings.height),
    };
    bar.inc(
        u64::from(settings.width)
            * u64::from(settings.height)
            * u64::from(film.spp().min(settings.spp)),
    );
    let mut after_pass = |film: &Film| match &args.checkpoint {
        Some(path) => checkpoint::save(path, film, &text, &fingerprint)
            .with_context(|| format!("cannot write checkpoint {}", path.display())),
        None => Ok(()),
    };
    let run = || progressive::render(&scene, &settings, film, limits, &progress, &mut after_pass);
    let (output, stop) = match args.threads {
        Some(0) => return Err(BadInput("--threads must be at least 1".into()).into()),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .context("cannot start the worker threads")?
            .install(run),
        None => run(),
    }?;
    bar.finish_and_clear();
    let output: RenderOutput = output;
    if output.film.spp() == 0 {
        // Interrupted during the first pass: nothing whole to write.
        return Err(Interrupted(0).into());
    }

    output::write_image(&out, format, &output.film, args.exposure)
        .with_context(|| format!("cannot write {}", out.display()))?;

    let stats = &output.stats;
    let secs = stats.elapsed.as_secs_f64();
    eprintln!(
        "rendered {}x{} at {} spp ({}, {}) in {:.2} s, {:.2} M samples/s -> {}",
        settings.width,
        settings.height,
        output.film.spp(),
        settings.strategy,
        settings.sampler.name(),
        secs,
        stats.samples as f64 / secs.max(1e-9) / 1e6,
        out.display()
    );
    if stats.dropped_samples > 0 {
        eprintln!(
            "warning: {} NaN or infinite samples were dropped",
            stats.dropped_samples
        );
    }
    if args.stats {
        stats::print_stats(&output);
    }
    match stop {
        progressive::Stop::Complete => {}
        progressive::Stop::TimeBudget => eprintln!(
            "time budget of {} s reached: stopped at {} of {} spp",
            args.time.unwrap_or_default(),
            output.film.spp(),
            settings.spp
        ),
        progressive::Stop::TargetError(e) => eprintln!(
            "target error reached: relative error {e:.4} at {} of {} spp",
            output.film.spp(),
            settings.spp
        ),
        progressive::Stop::Interrupted => return Err(Interrupted(output.film.spp()).into()),
    }
    Ok(())
}

fn apply_flags(mut s: RenderSettings, a: &RenderArgs) -> Result<RenderSettings> {
    if let Some(v) = a.spp {
        s.spp = v;
    }
    if let Some(v) = a.strategy {
        s.strategy = v;
    }
    if let Some(v) = a.sampler {
        s.sampler = v;
    }
    if let Some(v) = a.seed {
        s.seed = v;
    }
    if let Some(v) = a.max_depth {
        s.max_depth = v;
    }
    if let Some(v) = a.width {
        s.width = v;
    }
    if let Some(v) = a.height {
        s.height = v;
    }
    if !a.exposure.is_finite() {
        bail!(BadInput("--exposure must be finite".into()));
    }
    s.validate().map_err(|e| BadInput(e.to_string()))?;
    Ok(s)
}

fn default_output(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "render".into(), |s| s.to_string_lossy().into_owned());
    PathBuf::from(format!("{stem}.png"))
}
