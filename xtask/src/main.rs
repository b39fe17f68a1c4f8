//! `cargo xtask`: lueur's lab bench. Each subcommand regenerates something
//! under `docs/` from the scene files, deterministically (fixed seeds).

mod aarch64;
mod ab;
mod codegen;
mod compose;
mod figures;
mod identical;
mod instructions;
mod memory;
mod mitsuba;
mod old;
mod peers;
mod plot;
mod pointset_figures;
mod properties;
mod reference;
mod replicates;
mod report;
mod samplers;
mod scale;
mod spectrum;
mod speed;
mod tradeoff;
mod variance;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use lueur::integrator::{Film, PreparedScene, render};
use lueur::scene::{RenderSettings, Scene};
use lueur::scene::{SceneFile, parse_scene};

#[derive(Parser)]
#[command(name = "xtask", about = "Regenerate lueur's figures and measurements")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render the shipped scenes and the strategy comparisons to docs/figures/.
    Figures {
        /// Smaller images and fewer samples, for CI.
        #[arg(long)]
        quick: bool,
    },
    /// Measure each strategy's per-pixel variance on the shipped scenes and
    /// check the report's claims; writes docs/VARIANCE.md.
    Variance {
        /// Smaller images and fewer samples, for CI.
        #[arg(long)]
        quick: bool,
    },
    /// Measure each sampler's image error at 4 to 256 spp on two scenes, with
    /// the convergence slope; checks the default sampler; writes
    /// docs/SAMPLERS.md.
    Samplers {
        /// Smaller images and fewer samples, for CI.
        #[arg(long)]
        quick: bool,
        /// Rewrite the report from the last measurement's CSV in
        /// target/xtask/ without rendering (after a change of the default
        /// sampler, say).
        #[arg(long)]
        report_only: bool,
    },
    /// Measure error against time for each strategy and sampler, and what
    /// the marching knobs and max_depth cost and buy; writes docs/TRADEOFF.md.
    Tradeoff {
        /// Smaller images and fewer samples, for CI.
        #[arg(long)]
        quick: bool,
    },
    /// Measure the peak resident memory of `lueur` on 4K renders (plain,
    /// with checkpoints, resumed, merged from shards); writes
    /// docs/MEMORY.md and fails if a render passes 400 MB.
    Memory {
        /// A 480x270 image, for CI (no target applies).
        #[arg(long)]
        quick: bool,
    },
    /// Compare lueur with Mitsuba 3 on cornell-spheres (correctness against
    /// a Mitsuba reference, speed and MSE x time); needs `pip install
    /// mitsuba numpy`; writes docs/PEERS.md.
    Peers {
        /// 64x64 and few samples, to check the pipeline.
        #[arg(long)]
        quick: bool,
    },
    /// Check that a small light's answer does not depend on the size of the
    /// floor under it, nor on the scene's scale or distance from the origin;
    /// writes docs/SCALE.md.
    Scale {
        /// Fewer sizes and samples, for CI.
        #[arg(long)]
        quick: bool,
    },
    /// Measure what replicates cost and buy (MSE at equal spp, calibration,
    /// noise of the per-pixel variance) for K = 1 to 16 on the shipped
    /// scenes; checks the default; writes docs/REPLICATES.md.
    Replicates {
        /// Smaller images, fewer seeds, one sampler, for CI.
        #[arg(long)]
        quick: bool,
    },
    /// Measure lueur's samples per second on the shipped scenes (issue 18's
    /// configuration), against an older lueur binary and Mitsuba 3 where
    /// there are; writes docs/SPEED.md.
    Speed {
        /// 32x32, 4 spp, one round, no Mitsuba: checks the pipeline.
        #[arg(long)]
        quick: bool,
        /// Interleaved rounds (default 5; 1 with --quick).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        rounds: Option<u32>,
        /// Another lueur binary (an older commit's, say), run before the
        /// new one in every round.
        #[arg(long, value_name = "PATH")]
        old: Option<PathBuf>,
        /// The old binary built from this commit (once; it is kept under
        /// target/xtask/old/), so the report can be rerun from a clean clone.
        #[arg(long, value_name = "REV", conflicts_with = "old")]
        old_rev: Option<String>,
        /// How lueur is built: `release` (what the README's render command
        /// runs) or `dist` (what `cargo install --profile dist` installs: LTO);
        /// an `--old-rev` commit is built the same way.
        #[arg(long, value_enum, default_value = "release")]
        profile: memory::Build,
    },
    /// Check that this tree renders every shipped scene bit for bit as
    /// another build does (mis and mixture, streamed and naive, both
    /// samplers, 48x48 at 8 spp); fails on any difference. For changes
    /// meant only as speed-ups.
    Identical {
        /// The other lueur binary.
        #[arg(long, value_name = "PATH", required_unless_present = "old_rev")]
        old: Option<PathBuf>,
        /// The other binary built from this commit (kept under
        /// target/xtask/old/).
        #[arg(long, value_name = "REV", conflicts_with = "old")]
        old_rev: Option<String>,
    },
    /// Check that lueur built for aarch64 renders every shipped scene bit for
    /// bit as this machine's build does, with NEON and scalar streams, under
    /// qemu (needs the target, gcc-aarch64-linux-gnu and qemu-user); fails
    /// on any difference.
    Aarch64 {
        /// Also run the library tests built for aarch64 under qemu (slow).
        #[arg(long)]
        tests: bool,
    },
    /// Time this tree against another build on the shipped scenes (issue 18's
    /// configuration, one thread by default), alternating within each round, and print
    /// the median ratio of the paired times with a 95% interval and whether the images
    /// are the same bits. For judging a speed change; writes no report.
    Ab {
        /// The other lueur binary.
        #[arg(long, value_name = "PATH", required_unless_present = "old_rev")]
        old: Option<PathBuf>,
        /// The other binary built from this commit (kept under
        /// target/xtask/old/).
        #[arg(long, value_name = "REV", conflicts_with = "old")]
        old_rev: Option<String>,
        /// A shipped scene to time (repeatable; default: all of them).
        #[arg(long = "scene", value_name = "NAME")]
        scenes: Vec<String>,
        /// Rounds (each times both builds on every scene); 6 at least for an interval.
        #[arg(long, default_value_t = 11, value_parser = clap::value_parser!(u32).range(1..))]
        rounds: u32,
        /// Render threads.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
        threads: u32,
        /// Image width and height.
        #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u32).range(1..))]
        size: u32,
        /// Samples per pixel.
        #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..))]
        spp: u32,
        /// The point set (`lueur render --sampler`).
        #[arg(long, default_value = "independent")]
        sampler: String,
        /// How both are built, as for `speed`.
        #[arg(long, value_enum, default_value = "release")]
        profile: memory::Build,
    },
    /// Count the instructions lueur executes per sample on each shipped
    /// scene with valgrind's callgrind (the same in every run, unlike times),
    /// against another build where given, and where they go; writes
    /// docs/INSTRUCTIONS.md. Needs valgrind.
    Instructions {
        /// 16x16 at 3 spp: checks the pipeline.
        #[arg(long)]
        quick: bool,
        /// Another lueur binary, counted the same way.
        #[arg(long, value_name = "PATH")]
        old: Option<PathBuf>,
        /// The other binary built from this commit (kept under
        /// target/xtask/old/).
        #[arg(long, value_name = "REV", conflicts_with = "old")]
        old_rev: Option<String>,
    },
    /// Check that the compiler made lueur's lane kernels of full-width vector
    /// instructions (zmm for AVX-512, ymm for AVX2), counted in the disassembly;
    /// writes docs/CODEGEN.md and fails below the floor. x86-64 only; needs objdump.
    Codegen {
        /// Another lueur binary to check, instead of building this tree's (no
        /// report is written then).
        #[arg(long, value_name = "PATH")]
        binary: Option<PathBuf>,
        /// The smallest share of each level's packed arithmetic at its full
        /// width that passes.
        #[arg(long, default_value_t = 0.9)]
        floor: f64,
    },
    /// Run the workspace's property tests under other seeds than their own
    /// (`PROPTEST_RNG_SEED` = FIRST, FIRST + 1, ...), to find claims that fail on cases
    /// their fixed seeds never draw; prints each failure with its seed and minimal input,
    /// and fails if there is one. Writes no report.
    Properties {
        /// The first seed.
        #[arg(long, default_value_t = 1)]
        first: u64,
        /// How many seeds, each a run of every property test (about 10 s).
        #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u64).range(1..))]
        count: u64,
    },
    /// Run a command and print its peak resident set in kB (used by
    /// `memory`, one process per measurement).
    #[command(hide = true)]
    MemoryProbe {
        #[arg(trailing_var_arg = true, allow_hyphen_values = true, required = true)]
        command: Vec<String>,
    },
}

fn main() -> Result<()> {
    let command = Cli::parse().command;
    // The probe runs inside a `memory` report, which holds the lock.
    let _lock = match command {
        Command::MemoryProbe { .. } => None,
        _ => Some(report_lock()?),
    };
    match command {
        Command::Figures { quick } => figures::run(quick),
        Command::Variance { quick } => variance::run(quick),
        Command::Tradeoff { quick } => tradeoff::run(quick),
        Command::Samplers { quick, report_only } => samplers::run(quick, report_only),
        Command::Memory { quick } => memory::run(quick),
        Command::Peers { quick } => peers::run(quick),
        Command::Scale { quick } => scale::run(quick),
        Command::Replicates { quick } => replicates::run(quick),
        Command::Speed {
            quick,
            rounds,
            old,
            old_rev,
            profile,
        } => speed::run(quick, rounds, old.as_deref(), old_rev.as_deref(), profile),
        Command::Identical { old, old_rev } => identical::run(old.as_deref(), old_rev.as_deref()),
        Command::Aarch64 { tests } => aarch64::run(tests),
        Command::Ab {
            old,
            old_rev,
            scenes,
            rounds,
            threads,
            size,
            spp,
            sampler,
            profile,
        } => ab::run(
            old.as_deref(),
            old_rev.as_deref(),
            profile,
            &ab::Plan {
                scenes: &scenes,
                rounds,
                threads,
                size,
                spp,
                sampler: &sampler,
            },
        ),
        Command::Instructions {
            quick,
            old,
            old_rev,
        } => instructions::run(quick, old.as_deref(), old_rev.as_deref()),
        Command::Codegen { binary, floor } => codegen::run(binary.as_deref(), floor),
        Command::Properties { first, count } => properties::run(first, count),
        Command::MemoryProbe { command } => memory::probe(&command),
    }
}

/// An exclusive lock on `target/xtask/.lock`, held while a report runs. Two reports at
/// once would share the machine's cores, each timing the other, and share the cache
/// directories under `target/xtask` (two `memory` runs once met on one file there). The
/// system releases the lock when the process ends, however it ends.
fn report_lock() -> Result<std::fs::File> {
    let path = reference::cache_dir()?.join(".lock");
    let file = std::fs::File::options()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .with_context(|| format!("opening {}", path.display()))?;
    match file.try_lock() {
        Ok(()) => Ok(file),
        Err(std::fs::TryLockError::WouldBlock) => anyhow::bail!(
            "another `cargo xtask` report is running in this project (it holds {}): two at \
             once would time each other and share their files under target/xtask; wait for \
             it to finish",
            path.display()
        ),
        Err(std::fs::TryLockError::Error(e)) => {
            Err(e).with_context(|| format!("locking {}", path.display()))
        }
    }
}

/// The workspace root (the parent of this crate's manifest directory).
pub fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

/// Where a command writes its documents: `docs/` for full runs, which are
/// committed, and `target/xtask/quick/` (same layout) for `--quick` runs, so
/// that CI and quick checks never overwrite the committed figures.
pub fn docs_dir(quick: bool) -> PathBuf {
    if quick {
        project_root().join("target").join("xtask").join("quick")
    } else {
        project_root().join("docs")
    }
}

/// The names of `scenes/*.toml`, sorted.
pub fn shipped_scenes() -> Result<Vec<String>> {
    let dir = project_root().join("scenes");
    let mut names = Vec::new();
    for entry in std::fs::read_dir(&dir).with_context(|| format!("reading {}", dir.display()))? {
        let path = entry?.path();
        if path.extension().is_some_and(|e| e == "toml")
            && let Some(stem) = path.file_stem()
        {
            names.push(stem.to_string_lossy().into_owned());
        }
    }
    names.sort();
    Ok(names)
}

/// Runs `binary` (a `lueur`) with `args` from the project root; its stderr is
/// the error if it fails.
pub fn run_lueur(binary: &Path, args: &[String]) -> Result<()> {
    let shown = format!("{} {}", binary.display(), args.join(" "));
    let out = std::process::Command::new(binary)
        .args(args)
        .current_dir(project_root())
        .output()
        .with_context(|| format!("cannot run {shown}"))?;
    anyhow::ensure!(
        out.status.success(),
        "{shown}: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    Ok(())
}

/// Loads `scenes/NAME.toml`.
pub fn load_scene(name: &str) -> Result<SceneFile> {
    load_scene_at(&format!("scenes/{name}.toml"))
}

/// Loads the scene file at `relative`, a path from the project root (which its errors name).
pub fn load_scene_at(relative: &str) -> Result<SceneFile> {
    let path = project_root().join(relative);
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    Ok(parse_scene(&text, relative)?)
}

/// Renders with a progress bar labelled `label`.
pub fn render_with_bar(scene: &Scene, settings: &RenderSettings, label: &str) -> Result<Film> {
    let bar = indicatif::ProgressBar::new(
        u64::from(settings.width) * u64::from(settings.height) * u64::from(settings.spp),
    );
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg:>32} {wide_bar} {percent:>3}% ETA {eta}")
            .expect("valid template"),
    );
    bar.set_message(label.to_owned());
    let out = render(&PreparedScene::new(scene.clone()), settings, &|n| {
        bar.inc(n)
    })?;
    bar.finish_and_clear();
    anyhow::ensure!(
        out.stats.dropped_samples == 0,
        "{label}: {} NaN/Inf samples",
        out.stats.dropped_samples
    );
    Ok(out.film)
}
