//! `lueur`: the command-line renderer. A thin shell over the library
//! crates: it reads scene files, draws the progress bar and writes images;
//! every decision about light lives in `lueur-integrator`.

mod bar;
mod checkpoint;
mod crop;
mod fingerprint;
mod help;
mod interrupt;
mod merge;
mod output;
mod partial;
mod plot;
mod points;
mod progressive;
mod provenance;
mod reached;
mod reference;
mod resume;
mod stats;
mod summary;
mod validate;

use std::ops::Range;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use lueur_integrator::{Film, Marching, PixelBounds, RenderOutput, RenderSettings, Strategy};
use lueur_sampling::SamplerKind;
use lueur_scene::{SceneFileError, parse_scene_with};

use fingerprint::Fingerprint;
use interrupt::Interrupted;

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
    #[command(after_help = help::render_after_help())]
    Render(Box<RenderArgs>),
    /// Generate a point set (CSV or PNG plot) and measure it: discrepancies
    /// and integration error.
    Points(points::PointsArgs),
    /// Combine the shards of one render (saved by `render --sample-range
    /// A..B --checkpoint FILE`) into the image of all their samples,
    /// bit-identical to rendering them at once.
    Merge(MergeArgs),
    /// Print a shell completion script, e.g. `lueur completions bash >
    /// ~/.local/share/bash-completion/completions/lueur`.
    Completions {
        /// The shell: bash, elvish, fish, powershell or zsh.
        shell: clap_complete::Shell,
    },
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
    /// Merge shards that do not hold every sample of the render (missing
    /// samples at its start or end); refused otherwise, listing them.
    #[arg(long)]
    allow_partial: bool,
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
    #[arg(long, short = 't')]
    threads: Option<usize>,
    /// Exposure in stops applied before PNG encoding (EXR stays linear).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
    /// Print nothing but errors and warnings: no progress bar, no summary.
    #[arg(long, short = 'q')]
    quiet: bool,
    /// Print statistics after the render: rays, steps per ray, hit shares.
    #[arg(long)]
    stats: bool,
    /// March rays the naive way (plain sphere tracing, no bounding spheres): the
    /// reference that speed-ups are measured against.
    #[arg(long)]
    naive: bool,
    /// Stop at this wall-clock budget in seconds: passes of 1, 1, 2, 4, ...
    /// spp, the last ones cut to what is left (the first always runs).
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
    /// Override a scene-file key by its dotted path, as the file would set
    /// it (repeatable): camera.vfov=30, render.max_steps=64,
    /// lights[0].radiance=[1,1,1].
    #[arg(long = "set", short = 'D', value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Render only this part of the image, in fractions of its width and
    /// height (pbrt-v4's --cropwindow; row 0 at the top); the image written
    /// is the crop's size, its pixels those of the full render.
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"], conflicts_with = "pixel_bounds")]
    crop_window: Option<Vec<f64>>,
    /// Render only pixels X0..X1 x Y0..Y1 of the image, ends excluded
    /// (pbrt-v4's --pixelbounds).
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"])]
    pixel_bounds: Option<Vec<u32>>,
    /// Write the output image every SECONDS while rendering (atomically,
    /// between passes), for a viewer that reloads it.
    #[arg(long, value_name = "SECONDS")]
    partial_every: Option<f64>,
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
        Command::Render(args) => run_render(*args),
        Command::Points(args) => points::run_points(args),
        Command::Merge(args) => run_merge(args),
        Command::Completions { shell } => {
            use clap::CommandFactory;
            let mut command = Cli::command();
            // Into memory first: the generator panics on a write error,
            // and a closed pipe (`| head`) is no reason to.
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut command, "lueur", &mut script);
            use std::io::Write;
            match std::io::stdout().write_all(&script) {
                Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
                _ => Ok(()),
            }
        }
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
            if let Some(interrupted) = e.downcast_ref::<Interrupted>() {
                eprintln!("{interrupted}");
                return ExitCode::from(progressive::EXIT_INTERRUPTED);
            }
            eprintln!("error: {}", validate::error_chain(&e));
            if e.downcast_ref::<BadInput>().is_some() {
                ExitCode::from(EXIT_BAD_INPUT)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}

fn run_render(mut args: RenderArgs) -> Result<()> {
    let file = args.scene.display().to_string();
    let text = std::fs::read_to_string(&args.scene)
        .map_err(|e| BadInput(format!("cannot read scene file {file}: {e}")))?;
    let resumed = match args.resume.clone() {
        Some(path) => {
            validate::input("--resume", &path)?;
            Some(resume::restore(&path, &mut args)?)
        }
        None => None,
    };
    let overrides: Vec<&str> = args.set.iter().map(String::as_str).collect();
    let parsed = parse_scene_with(&text, &file, &overrides)?;
    let mut scene = parsed.scene;
    if args.naive {
        scene.marching = Marching::Naive;
    }
    let settings = apply_flags(parsed.settings, &args)?;
    let range = render_range(&args, &settings)?;
    let (out, format) = validate::render_outputs(&args)?;
    let bounds = crop::bounds(
        args.crop_window.as_deref(),
        args.pixel_bounds.as_deref(),
        settings.width,
        settings.height,
    )?;
    let limits = render_limits(&args, out.is_some())?;
    let mut reference = reference_for(
        &args,
        bounds.map_or([settings.width, settings.height], |b| {
            [b.width(), b.height()]
        }),
    )?;
    progressive::install_signal_handler()?;

    let whole = PixelBounds::whole(settings.width, settings.height);
    let region = bounds.unwrap_or(whole);
    let pixels = u64::from(region.width()) * u64::from(region.height());
    let fingerprint = Fingerprint::of(
        &settings,
        args.naive,
        bounds,
        args.sample_range.as_ref(),
        &args.set,
    );
    let film = match (&args.resume, &resumed) {
        (Some(path), Some(resumed)) => {
            resume::load(path, resumed, &text, &fingerprint, settings.sampler, &range)?
        }
        _ => Film::starting_at(region.width(), region.height(), range.start),
    };
    let fingerprint = fingerprint.to_string();
    // Without a checkpoint nobody will extend the film: it can keep one
    // image instead of one per dyadic block (two at 24 spp, three at 100).
    let film = match args.checkpoint {
        Some(_) => film,
        None => film.sealed_at(range.end),
    };
    let bar = bar::Bar::new(
        pixels * u64::from(range.end - range.start),
        pixels * u64::from(film.spp().min(range.end - range.start)),
        limits.time,
        args.quiet,
    );
    let progress = |n: u64| bar.add(n);
    let mut partial = match (limits.pass_seconds, &out, format) {
        (Some(every), Some(out), Some(format)) => Some(partial::Partial::new(
            every,
            out.clone(),
            format,
            args.exposure,
        )),
        _ => None,
    };
    let started = std::time::Instant::now();
    let provenance_of = |film: &Film| {
        provenance::of_render(
            &file,
            &text,
            &settings,
            film.samples(),
            started.elapsed().as_secs_f64(),
            film.relative_error(),
        )
    };
    let mut after_pass = |film: &Film| {
        if let Some(r) = reference.as_mut() {
            let e = r.after_pass(film)?;
            bar::message(&format!(
                "{} spp: MSE {:.4e} against the reference, estimated {:.4e}; relative MSE {:.4e}",
                film.spp(),
                e.mse,
                e.estimated_mse,
                e.rel_mse
            ));
        }
        if let Some(path) = &args.checkpoint {
            checkpoint::save(path, film, &text, &fingerprint)
                .with_context(|| format!("cannot write checkpoint {}", path.display()))?;
        }
        partial
            .as_mut()
            .map_or(Ok(()), |p| p.after_pass(film, || provenance_of(film)))
    };
    let end = range.end;
    let run = || {
        progressive::render(
            &scene,
            &settings,
            region,
            film,
            end,
            limits,
            &progress,
            &mut after_pass,
        )
    };
    let (output, stop) = match args.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .context("cannot start the worker threads")?
            .install(run),
        None => run(),
    }?;
    bar.finish();
    let output: RenderOutput = output;
    let interrupted = || Interrupted {
        spp: output.film.spp(),
        unfinished: output
            .film
            .unfinished_pass()
            .map(|(samples, share)| (samples.end - output.film.samples().start, share)),
        out: out.clone().filter(|_| output.film.spp() > 0),
        checkpoint: args.checkpoint.clone(),
        scene: args.scene.clone(),
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

    summary::report(
        &args,
        &settings,
        &output,
        stop,
        out.as_deref(),
        range.end - range.start,
        &limits,
    );
    if stop == progressive::Stop::Interrupted {
        return Err(interrupted().into());
    }
    Ok(())
}

/// The converged image `--reference` names, checked against the size of what
/// is rendered (the crop's, where there is one) before the first sample.
fn reference_for(
    args: &RenderArgs,
    [width, height]: [u32; 2],
) -> Result<Option<reference::Reference>> {
    args.reference
        .as_deref()
        .map(|p| reference::load(p, width, height, args.reference_out.clone()))
        .transpose()
        .map_err(|e| BadInput(format!("{e:#}")).into())
}

/// The sample indices to render: a shard's (`--sample-range`, which needs
/// a checkpoint to save it in), or all of `0..spp`.
/// When to stop or cut passes short: --time, --target-error,
/// --partial-every (which needs an image to write, `has_out`).
fn render_limits(args: &RenderArgs, has_out: bool) -> Result<progressive::Limits> {
    if args.threads == Some(0) {
        bail!(BadInput("--threads must be at least 1".into()));
    }
    let limits = progressive::Limits {
        time: positive(args.time, "--time")?,
        target_error: positive(args.target_error, "--target-error")?,
        pass_seconds: positive(args.partial_every, "--partial-every")?,
    };
    if limits.pass_seconds.is_some() && !has_out {
        bail!(BadInput(
            "--partial-every writes the output image: give it with --out".into()
        ));
    }
    Ok(limits)
}

fn render_range(args: &RenderArgs, settings: &RenderSettings) -> Result<Range<u32>> {
    Ok(match &args.sample_range {
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
    })
}

fn run_merge(args: MergeArgs) -> Result<()> {
    let format = validate::image_output("--out", &args.out)?;
    if let Some(path) = &args.checkpoint {
        validate::checkpoint_output("--checkpoint", path)?;
        validate::distinct(("--out", &args.out), ("--checkpoint", path))?;
    }
    if !args.exposure.is_finite() {
        bail!(BadInput("--exposure must be finite".into()));
    }
    // Headers first: every refusal comes before any pixel is read, and the
    // shards are then read one at a time, in order, each block decoded
    // straight into the film (merged into its last block where it is that
    // block's later half), so no shard is held beside the film.
    let merge::Shards {
        shards,
        scene_text,
        fingerprint,
    } = merge::plan(&args.shards, args.allow_partial)?;
    let fingerprint = fingerprint.to_string();
    let count = shards.len();
    let mut film: Option<Film> = None;
    for (path, _) in &shards {
        let merged = checkpoint::merge_into(path, film.take())
            .map_err(|e| BadInput(format!("cannot merge {}: {e:#}", path.display())))?;
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
