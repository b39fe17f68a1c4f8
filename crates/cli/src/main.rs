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
mod render;
mod resume;
mod stats;
mod summary;
mod validate;

use std::ops::Range;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use lueur_integrator::Film;
use lueur_sampling::SamplerKind;
use lueur_scene::SceneFileError;
use lueur_scene::Strategy;

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
    /// The instruction set the ray streams run on: scalar, portable, sse, avx2,
    /// avx512 or neon (default: the widest this CPU has). The image does not depend
    /// on it; for measuring and testing.
    #[arg(long, value_name = "LEVEL")]
    simd: Option<String>,
    /// Paths in flight together, whose rays are traced as one stream; a path
    /// that ends gives its place to the next sample (default 512). The image
    /// does not depend on it; for measuring and testing.
    #[arg(long, value_name = "PATHS")]
    wave: Option<usize>,
    /// Keep each path as a record between the wave's stages, even where the lane
    /// wave could keep it in a lane of the vectors (mis, one sphere light, boxes,
    /// spheres and planes). The image does not depend on it; for measuring and
    /// testing.
    #[arg(long)]
    no_lane_wave: bool,
    /// Stop at this wall-clock budget in seconds: passes of 1, 1, 2, 4, ...
    /// spp (none after the first shorter than 0.3 s), the last ones cut to what
    /// is left (the first always runs).
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
        Command::Render(args) => render::run(*args),
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
