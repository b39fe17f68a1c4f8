//! `cargo xtask memory`: peak resident memory of the `lueur` program on a
//! 4K render, as a user runs it, for each way the film is kept: a plain
//! render (EXR and PNG), a render whose spp has two one-bits (two dyadic
//! blocks, folded on the last pass), a render saving checkpoints, a resume
//! from one, and a merge of four shards. Writes `docs/MEMORY.md` and fails
//! unless every render stays under the 400 MB target.
//!
//! Each run is measured in a process of its own: this program re-runs
//! itself as a probe (`xtask memory-probe -- PROGRAM ARGS`) that starts the
//! command, waits for it and prints `getrusage(RUSAGE_CHILDREN)`'s maximum
//! resident set size, which is then that one command's peak (what
//! `/usr/bin/time -v` reports, without depending on it being installed).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result, bail, ensure};

use crate::project_root;
use crate::report::write_report;

/// The target for a 4K render, film included.
const TARGET_MB: f64 = 400.0;
const SCENE: &str = "scenes/donut-mirrors.toml";

/// One measured command.
struct Run {
    what: &'static str,
    args: Vec<String>,
    /// Whether the 400 MB target applies (a merge of shards is reported,
    /// not held to it).
    held_to_target: bool,
}

/// Runs `program args` as a child, waits, and prints its peak resident set
/// in kilobytes on stdout: the probe side of [`peak_rss_mb`].
pub fn probe(command: &[String]) -> Result<()> {
    let (program, args) = command.split_first().context("no command to probe")?;
    let status = Command::new(program)
        .args(args)
        .status()
        .with_context(|| format!("cannot run {program}"))?;
    ensure!(status.success(), "{program} failed: {status}");
    let usage = nix::sys::resource::getrusage(nix::sys::resource::UsageWho::RUSAGE_CHILDREN)
        .context("getrusage")?;
    // Linux reports ru_maxrss in kilobytes.
    println!("{}", usage.max_rss());
    Ok(())
}

/// Peak resident set of `program args` in MB (10^6 bytes), and its wall
/// time in seconds.
fn peak_rss_mb(program: &Path, args: &[String]) -> Result<(f64, f64)> {
    let start = Instant::now();
    let out = Command::new(std::env::current_exe()?)
        .arg("memory-probe")
        .arg("--")
        .arg(program)
        .args(args)
        .output()
        .context("cannot run the probe")?;
    let secs = start.elapsed().as_secs_f64();
    if !out.status.success() {
        bail!(
            "{} {}: {}",
            program.display(),
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let kb: f64 = String::from_utf8_lossy(&out.stdout)
        .trim()
        .parse()
        .context("the probe's output")?;
    Ok((kb * 1024.0 / 1e6, secs))
}

/// The optimisation a report's `lueur` is built with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Build {
    /// `cargo build --release`: what the README's render command runs.
    Release,
    /// The `dist` profile, what `cargo install --profile dist` installs: link-time
    /// optimisation in one codegen unit. An older tree without that profile gets the
    /// same settings from [`DIST_SETTINGS`].
    Dist,
}

/// The workspace Cargo.toml's `[profile.dist]`, as `cargo --config` values, so that a
/// tree of a commit before the profile existed builds the same way
/// (`dist_settings_match_the_manifest` checks they agree).
pub const DIST_SETTINGS: [&str; 3] = [
    "profile.dist.inherits=\"release\"",
    "profile.dist.lto=\"fat\"",
    "profile.dist.codegen-units=1",
];

impl Build {
    /// Its directory under a target directory.
    pub fn dir(self) -> &'static str {
        match self {
            Build::Release => "release",
            Build::Dist => "dist",
        }
    }

    /// The arguments of `cargo build` that select it.
    fn args(self) -> Vec<&'static str> {
        match self {
            Build::Release => vec!["--release"],
            Build::Dist => {
                let mut args = vec!["--profile", "dist"];
                for setting in DIST_SETTINGS {
                    args.extend(["--config", setting]);
                }
                args
            }
        }
    }

    /// How a report names it.
    pub fn describe(self) -> &'static str {
        match self {
            Build::Release => "`cargo build --release`",
            Build::Dist => "`cargo build --profile dist` (fat LTO, one codegen unit)",
        }
    }
}

/// How this xtask was built, from the directory its binary is in (cargo's
/// `target/PROFILE/`): a report that renders with lueur's crates inside xtask
/// (`peers`) measures that build. `cargo xtask` is `release`; `cargo xtask-dist`
/// is `dist`.
pub fn this_build() -> String {
    let exe = std::env::current_exe().ok();
    let profile = (exe.as_deref())
        .and_then(Path::parent)
        .and_then(Path::file_name)
        .and_then(|dir| dir.to_str());
    let known = <Build as clap::ValueEnum>::value_variants()
        .iter()
        .find(|b| Some(b.dir()) == profile);
    match (known, profile) {
        (Some(build), _) => build.describe().to_owned(),
        (None, Some(other)) => format!("the `{other}` profile"),
        (None, None) => "an unknown profile".to_owned(),
    }
}

/// Builds this tree's release `lueur` (`cargo build --release -p lueur-cli`)
/// and returns its path, under `$CARGO_TARGET_DIR` when that is set.
pub fn build_lueur() -> Result<PathBuf> {
    build_lueur_as(Build::Release)
}

/// [`build_lueur`] with the optimisation `build`.
pub fn build_lueur_as(build: Build) -> Result<PathBuf> {
    build_lueur_from(&project_root(), &target_dir(), build, &[])
}

/// This workspace's target directory: `$CARGO_TARGET_DIR` when that is set.
pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map_or_else(|| project_root().join("target"), PathBuf::from)
}

/// The cargo that runs xtask (`$CARGO`), or the one on the path.
pub fn cargo() -> Command {
    Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
}

/// Builds `lueur` of the workspace at `root` into the target directory `target`
/// (`cargo build -p lueur-cli` as `build` says, then `extra`) and returns its path.
pub fn build_lueur_from(
    root: &Path,
    target: &Path,
    build: Build,
    extra: &[&str],
) -> Result<PathBuf> {
    let mut args = vec!["build"];
    args.extend(build.args());
    args.extend(["-p", "lueur-cli"]);
    args.extend(extra);
    let shown = format!("cargo {} in {}", args.join(" "), root.display());
    let status = cargo()
        .args(&args)
        .current_dir(root)
        .env("CARGO_TARGET_DIR", target)
        .status()
        .with_context(|| format!("cannot run {shown}"))?;
    ensure!(status.success(), "{shown} failed");
    let binary = target.join(build.dir()).join("lueur");
    ensure!(binary.is_file(), "{shown} made no {}", binary.display());
    Ok(binary)
}

pub fn run(quick: bool) -> Result<()> {
    let lueur = build_lueur()?;
    let (w, h) = if quick { (480, 270) } else { (3840, 2160) };
    let work = scratch_dir()?;
    let runs = runs(&lueur, w, h, &work)?;

    // The scene's sampler (sobol-xor) deals its samples into the default
    // number of replicates: per pixel, a count and a mean (16 bytes) per
    // replicate, and the sum of squared deviations (12 more) only with one
    // (crates/integrator/src/film/image.rs).
    let replicates = lueur::scene::DEFAULT_REPLICATES;
    let bytes_per_pixel = if replicates == 1 {
        28.0
    } else {
        16.0 * f64::from(replicates)
    };
    let film_mb = bytes_per_pixel * f64::from(w) * f64::from(h) / 1e6;
    let mut table = String::new();
    let mut over = Vec::new();
    writeln!(
        table,
        "| run | peak resident | in films of {film_mb:.0} MB | wall time |"
    )?;
    writeln!(table, "|---|---|---|---|")?;
    std::env::set_current_dir(project_root())?;
    for run in &runs {
        let (mb, secs) = peak_rss_mb(&lueur, &run.args)?;
        println!("{:<45} {mb:>7.0} MB  ({secs:.1} s)", run.what);
        writeln!(
            table,
            "| {} | {mb:.0} MB | {:.2} | {secs:.1} s |",
            run.what,
            mb / film_mb
        )?;
        if run.held_to_target && mb > TARGET_MB && !quick {
            over.push(format!("{}: {mb:.0} MB", run.what));
        }
    }
    let _ = std::fs::remove_dir_all(&work);

    {
        let md = format!(
            "# Memory\n\n\
             Peak resident memory of `lueur` (release build) on \
             `{SCENE}` at {w}x{h}, each run in a process of its own \
             (`getrusage`, as `/usr/bin/time -v` reports it). One film image \
             holds per pixel a count and a mean (16 bytes) per replicate, \
             and the sum of squared deviations (12 bytes more) only with one \
             replicate; the scene's sampler deals its samples into \
             {replicates} (the default): {bytes_per_pixel:.0} bytes per pixel, \
             {film_mb:.0} MB. Regenerate with \
             `cargo xtask memory` (about 4 minutes on 2 cores); it fails if \
             a render passes {TARGET_MB:.0} MB.\n\n{table}\n\
             The merge holds the merged film, one image per one-bit of its \
             sample count so far; a shard's blocks are decoded straight into \
             it (merged into its last block where they are that block's later \
             half), so with shards of one sample the third waits beside \
             `0..2` and the fourth merges into it as it is read: two images.\n"
        );
        write_report(quick, "MEMORY.md", &md)?;
    }
    if !over.is_empty() {
        bail!("over the {TARGET_MB:.0} MB target: {}", over.join("; "));
    }
    Ok(())
}

/// The measured runs at `w` x `h`, files in `work`: plain renders, a
/// checkpoint and its resume, and the merge of four shards (rendered here,
/// unmeasured, so that the merge has them).
fn runs(lueur: &Path, w: u32, h: u32, work: &Path) -> Result<Vec<Run>> {
    let file = |name: &str| work.join(name).display().to_string();
    let size = |spp: u32| {
        vec![
            "--width".to_string(),
            w.to_string(),
            "--height".into(),
            h.to_string(),
            "--spp".into(),
            spp.to_string(),
        ]
    };
    let render = |spp: u32, extra: &[String]| {
        let mut a = vec!["render".to_string(), SCENE.into()];
        a.extend(size(spp));
        a.extend_from_slice(extra);
        a
    };
    let mut runs = vec![
        Run {
            what: "render, 2 spp, EXR",
            args: render(2, &["-o".into(), file("a.exr")]),
            held_to_target: true,
        },
        Run {
            what: "render, 2 spp, PNG",
            args: render(2, &["-o".into(), file("a.png")]),
            held_to_target: true,
        },
        Run {
            what: "render, 3 spp (two blocks, folded), EXR",
            args: render(3, &["-o".into(), file("b.exr")]),
            held_to_target: true,
        },
        Run {
            what: "render, 2 spp, --checkpoint",
            args: render(
                2,
                &[
                    "-o".into(),
                    file("c.exr"),
                    "--checkpoint".into(),
                    file("c.ckpt.exr"),
                ],
            ),
            held_to_target: true,
        },
        Run {
            what: "resume that checkpoint to 3 spp",
            args: render(
                3,
                &[
                    "-o".into(),
                    file("d.exr"),
                    "--resume".into(),
                    file("c.ckpt.exr"),
                ],
            ),
            held_to_target: true,
        },
    ];
    // Four shards of one sample each, then their merge (the measured run).
    for k in 0..4 {
        let shard = Command::new(lueur)
            .current_dir(project_root())
            .args(render(
                4,
                &[
                    "--sample-range".into(),
                    format!("{k}..{}", k + 1),
                    "--checkpoint".into(),
                    file(&format!("shard{k}.exr")),
                ],
            ))
            .output()
            .context("cannot run lueur")?;
        ensure!(
            shard.status.success(),
            "shard {k} failed: {}",
            String::from_utf8_lossy(&shard.stderr)
        );
    }
    let mut merge = vec!["merge".to_string()];
    merge.extend((0..4).map(|k| file(&format!("shard{k}.exr"))));
    merge.extend(["--out".into(), file("m.exr")]);
    runs.push(Run {
        what: "merge of 4 shards of 1 spp",
        args: merge,
        held_to_target: false,
    });

    Ok(runs)
}

/// A scratch directory under the target directory (4K checkpoints are
/// 150 MB each; /tmp may be small).
fn scratch_dir() -> Result<PathBuf> {
    let dir = crate::reference::cache_dir()?.join("memory");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    Ok(dir)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`DIST_SETTINGS`] are the workspace's `[profile.dist]`, key for key, so that an old
    /// commit built with them is built as this tree's `dist` is.
    #[test]
    fn dist_settings_match_the_manifest() {
        let manifest = std::fs::read_to_string(project_root().join("Cargo.toml")).unwrap();
        let section = manifest
            .split("\n[")
            .find(|s| s.starts_with("profile.dist]"))
            .expect("the workspace Cargo.toml has a [profile.dist]");
        let mut keys: Vec<String> = (section.lines().skip(1))
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with('#'))
            .map(|l| format!("profile.dist.{}", l.replace(' ', "")))
            .collect();
        let mut settings: Vec<String> = DIST_SETTINGS.iter().map(|s| s.to_string()).collect();
        keys.sort();
        settings.sort();
        assert_eq!(keys, settings);
    }
}
