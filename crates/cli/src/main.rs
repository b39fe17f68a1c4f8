//! `lueur`: the command-line renderer. A thin shell over the library
//! crates: it reads scene files, draws the progress bar and writes images;
//! every decision about light lives in `lueur-integrator`.

mod checkpoint;
mod output;
mod points;
mod progressive;
mod provenance;
mod reached;
mod reference;
mod stats;

use std::ops::Range;
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
    /// Combine the shards of one render (saved by `render --sample-range
    /// A..B --checkpoint FILE`) into the image of all their samples,
    /// bit-identical to rendering them at once.
    Merge(MergeArgs),
}

#[derive(Parser)]
struct MergeArgs {
    /// The shards' checkpoint files, in any order.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Output image; the extension picks the format (.png or .exr).
    #[arg(long, short)]
    out: PathBuf,
    /// Also save the merged film as a checkpoint, to resume or merge again.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Exposure in stops applied before PNG encoding (EXR stays linear).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
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
    /// Independent randomizations of the point set whose spread gives each
    /// pixel's error bar (default: 2 for the randomized QMC samplers, 1 for
    /// independent sampling; at most --spp).
    #[arg(long, value_name = "K")]
    replicates: Option<u32>,
    /// Seed of all random numbers.
    #[arg(long)]
    seed: Option<u64>,
    /// Maximum number of scattering events (0: only emitters seen directly).
    #[arg(long)]
    max_depth: Option<u32>,
    /// Scattering events after which Russian roulette may end paths
    /// (default 3; at max_depth or above, never).
    #[arg(long)]
    roulette_depth: Option<u32>,
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
    /// Render only sample indices START..END of the --spp total: one shard
    /// of a render split across processes or machines. Needs --checkpoint,
    /// where the shard is saved for `lueur merge`; --out is then optional.
    #[arg(long, value_name = "START..END", value_parser = parse_sample_range)]
    sample_range: Option<Range<u32>>,
    /// A converged image of the same size (EXR): after every pass, print
    /// the MSE and relative MSE against it beside lueur's own estimate.
    #[arg(long, value_name = "REF.exr")]
    reference: Option<PathBuf>,
    /// With --reference: write one CSV row per pass (spp, seconds, MSE,
    /// relative MSE, estimated MSE, estimated relative error).
    #[arg(long, value_name = "FILE.csv", requires = "reference")]
    reference_out: Option<PathBuf>,
}

fn parse_sample_range(s: &str) -> Result<Range<u32>, String> {
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| format!("expected START..END (e.g. 0..64), got `{s}`"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|e| format!("`{v}` in `{s}` is not a sample index: {e}"))
    };
    let (a, b) = (parse(a)?, parse(b)?);
    if a >= b {
        return Err(format!("the range {a}..{b} is empty"));
    }
    Ok(a..b)
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
struct Interrupted {
    /// Samples per pixel that every pixel has.
    spp: u32,
    /// The interrupted pass's end and the share of pixels that reached it.
    unfinished: Option<(u32, f64)>,
    /// The checkpoint, which holds the last complete pass.
    checkpoint: Option<PathBuf>,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.spp == 0 {
            return write!(
                f,
                "interrupted before the first pass completed; nothing written"
            );
        }
        write!(
            f,
            "interrupted: wrote the {} spp completed before the signal",
            self.spp
        )?;
        if let Some((end, share)) = self.unfinished {
            write!(
                f,
                ", and {end} spp in the {:.0}% of the pixels whose tiles finished the pass in \
                 progress",
                100.0 * share
            )?;
        }
        if let Some(path) = &self.checkpoint {
            write!(
                f,
                "; {} holds the {} spp (resume from it)",
                path.display(),
                self.spp
            )?;
        }
        Ok(())
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
        Command::Merge(args) => run_merge(args),
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
    let range = match &args.sample_range {
        Some(r) if r.end > settings.spp => {
            return Err(BadInput(format!(
                "--sample-range {}..{} ends past the render's {} spp (set the total with --spp)",
                r.start, r.end, settings.spp
            ))
            .into());
        }
        Some(_) if args.checkpoint.is_none() => {
            return Err(BadInput(
                "--sample-range renders a shard: save it with --checkpoint FILE, for `lueur merge`"
                    .into(),
            )
            .into());
        }
        Some(r) => r.clone(),
        None => 0..settings.spp,
    };
    // A shard's image is optional; a whole render always writes one.
    let out = match (&args.out, &args.sample_range) {
        (Some(p), _) => Some(p.clone()),
        (None, Some(_)) => None,
        (None, None) => Some(default_output(&args.scene)),
    };
    let format = out
        .as_deref()
        .map(output::Format::from_path)
        .transpose()
        .map_err(|e| BadInput(e.to_string()))?;

    let limits = progressive::Limits {
        time: positive(args.time, "--time")?,
        target_error: positive(args.target_error, "--target-error")?,
    };
    let mut reference = args
        .reference
        .as_deref()
        .map(|p| {
            reference::load(
                p,
                settings.width,
                settings.height,
                args.reference_out.clone(),
            )
        })
        .transpose()
        .map_err(|e| BadInput(format!("{e:#}")))?;
    progressive::install_signal_handler()?;

    let pixels = u64::from(settings.width) * u64::from(settings.height);
    let bar = ProgressBar::new(pixels * u64::from(range.end - range.start));
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
            let film = checkpoint::load(path, &text, &fingerprint)
                .map_err(|e| BadInput(format!("{e:#}")))?;
            if film.samples().start != range.start {
                return Err(BadInput(format!(
                    "{} holds samples {:?}, which do not start at {}",
                    path.display(),
                    film.samples(),
                    range.start
                ))
                .into());
            }
            film
        }
        None => Film::starting_at(settings.width, settings.height, range.start),
    };
    // Without a checkpoint nobody will extend the film: it can keep one
    // image instead of one per dyadic block (two at 24 spp, three at 100).
    let film = match args.checkpoint {
        Some(_) => film,
        None => film.sealed_at(range.end),
    };
    bar.inc(pixels * u64::from(film.spp().min(range.end - range.start)));
    let mut after_pass = |film: &Film| {
        if let Some(r) = reference.as_mut() {
            let e = r.after_pass(film)?;
            bar.suspend(|| {
                eprintln!(
                    "{} spp: MSE {:.4e} against the reference, estimated {:.4e}; relative MSE {:.4e}",
                    film.spp(),
                    e.mse,
                    e.estimated_mse,
                    e.rel_mse
                )
            });
        }
        match &args.checkpoint {
            Some(path) => checkpoint::save(path, film, &text, &fingerprint)
                .with_context(|| format!("cannot write checkpoint {}", path.display())),
            None => Ok(()),
        }
    };
    let end = range.end;
    let run = || {
        progressive::render(
            &scene,
            &settings,
            film,
            end,
            limits,
            &progress,
            &mut after_pass,
        )
    };
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
    let interrupted = || Interrupted {
        spp: output.film.spp(),
        unfinished: output
            .film
            .unfinished_pass()
            .map(|(samples, share)| (samples.end - output.film.samples().start, share)),
        checkpoint: args.checkpoint.clone(),
    };
    if output.film.spp() == 0 {
        // Interrupted during the first pass: a partly black image is of no
        // use to anyone.
        return Err(interrupted().into());
    }

    if let (Some(out), Some(format)) = (&out, format) {
        let provenance = provenance::of_render(
            &file,
            &text,
            &settings,
            output.film.samples(),
            output.stats.elapsed.as_secs_f64(),
            output.film.relative_error(),
        );
        output::write_image(out, format, &output.film, args.exposure, &provenance)
            .with_context(|| format!("cannot write {}", out.display()))?;
    }

    let stats = &output.stats;
    let secs = stats.elapsed.as_secs_f64();
    let samples = match args.sample_range {
        Some(_) => format!("samples {:?} of {}", output.film.samples(), settings.spp),
        None => format!("{} spp", output.film.spp()),
    };
    let samples = match output.film.unfinished_pass() {
        Some((pass, share)) => format!(
            "{samples} ({:.0}% of the pixels at {})",
            100.0 * share,
            pass.end - output.film.samples().start
        ),
        None => samples,
    };
    let destination = out.as_ref().or(args.checkpoint.as_ref());
    eprintln!(
        "rendered {}x{} at {samples} ({}, {}) in {:.2} s, {:.2} M samples/s -> {}",
        settings.width,
        settings.height,
        settings.strategy,
        settings.sampler.name(),
        secs,
        stats.samples as f64 / secs.max(1e-9) / 1e6,
        destination.map_or_else(String::new, |p| p.display().to_string())
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
    for line in reached::stop_report(stop, &output.film, &limits, range.end - range.start) {
        eprintln!("{line}");
    }
    if stop == progressive::Stop::Interrupted {
        return Err(interrupted().into());
    }
    Ok(())
}

fn run_merge(args: MergeArgs) -> Result<()> {
    let format = output::Format::from_path(&args.out).map_err(|e| BadInput(e.to_string()))?;
    if !args.exposure.is_finite() {
        bail!(BadInput("--exposure must be finite".into()));
    }
    // Headers first: every refusal comes before any pixel is read, and the
    // shards are then loaded one at a time, in order, each merged into the
    // film and dropped (8 shards of a 4K render never sit in memory at once).
    let mut shards = Vec::new();
    let mut first: Option<(PathBuf, String, String)> = None;
    for path in &args.shards {
        let header = checkpoint::read_header(path).map_err(|e| BadInput(format!("{e:#}")))?;
        match &first {
            None => {
                first = Some((
                    path.clone(),
                    header.scene_text.clone(),
                    header.fingerprint.clone(),
                ))
            }
            Some((p, scene, _)) if *scene != header.scene_text => bail!(BadInput(format!(
                "{} and {} are renders of different scene files; cannot merge",
                p.display(),
                path.display()
            ))),
            Some((p, _, settings)) if *settings != header.fingerprint => {
                bail!(BadInput(format!(
                    "{} and {} were rendered with different settings; cannot merge.\n  {}: {settings}\n  {}: {}",
                    p.display(),
                    path.display(),
                    p.display(),
                    path.display(),
                    header.fingerprint
                )))
            }
            Some(_) => {}
        }
        shards.push((path.clone(), header.samples));
    }
    let (_, scene_text, fingerprint) = first.expect("clap requires one shard");
    // Name the files on either side of a gap or an overlap.
    shards.sort_by_key(|(_, samples)| samples.start);
    for pair in shards.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if a.1.end != b.1.start {
            bail!(BadInput(format!(
                "{} holds samples {:?} and {} holds {:?}: shards must follow each other \
                 without gap or overlap",
                a.0.display(),
                a.1,
                b.0.display(),
                b.1
            )));
        }
    }
    let count = shards.len();
    let mut film: Option<Film> = None;
    for (path, _) in &shards {
        let shard = checkpoint::read_film(path)
            .map_err(|e| BadInput(format!("{e:#}")))?
            .film;
        let merged = match film.take() {
            None => shard,
            Some(f) => Film::merge(vec![f, shard])
                .map_err(|e| BadInput(format!("cannot merge {}: {e}", path.display())))?,
        };
        film = Some(merged);
    }
    let film = film.expect("clap requires one shard");
    let provenance = provenance::Provenance(vec![
        ("lueur.version".into(), env!("CARGO_PKG_VERSION").into()),
        (
            "lueur.scene_hash".into(),
            provenance::text_hash(&scene_text),
        ),
        (
            "lueur.samples".into(),
            format!("{}..{}", film.samples().start, film.samples().end),
        ),
        ("lueur.merged_shards".into(), count.to_string()),
        ("lueur.settings".into(), fingerprint.clone()),
        (
            "lueur.relative_error".into(),
            format!("{:.6}", film.relative_error()),
        ),
    ]);
    output::write_image(&args.out, format, &film, args.exposure, &provenance)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    if let Some(path) = &args.checkpoint {
        checkpoint::save(path, &film, &scene_text, &fingerprint)
            .with_context(|| format!("cannot write checkpoint {}", path.display()))?;
    }
    eprintln!(
        "merged {count} shards: samples {:?} ({} spp) -> {}",
        film.samples(),
        film.spp(),
        args.out.display()
    );
    if film.samples().start != 0 {
        eprintln!(
            "warning: the shards start at sample {}, not 0: the image is valid, \
             but not the first samples of the render",
            film.samples().start
        );
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
    if let Some(v) = a.roulette_depth {
        s.roulette_depth = v;
    }
    if let Some(v) = a.width {
        s.width = v;
    }
    if let Some(v) = a.height {
        s.height = v;
    }
    if let Some(v) = a.replicates {
        s.replicates = Some(v);
    }
    if !a.exposure.is_finite() {
        bail!(BadInput("--exposure must be finite".into()));
    }
    s.validate().map_err(|e| match e {
        lueur_integrator::RenderError::Replicates(why) => match a.replicates {
            Some(_) => BadInput(format!("--replicates: {why}")),
            None => BadInput(format!(
                "render.replicates of {}: {why} (override it with --replicates)",
                a.scene.display()
            )),
        },
        e => BadInput(e.to_string()),
    })?;
    Ok(s)
}

fn default_output(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "render".into(), |s| s.to_string_lossy().into_owned());
    PathBuf::from(format!("{stem}.png"))
}
