//! `cargo xtask speed`: lueur's samples per second on every shipped scene,
//! against another `lueur` binary (an older commit's, `--old`) and against
//! Mitsuba 3, in issue 18's configuration: 128x128, 64 spp, max_depth 8,
//! `mis`, independent samples, 2 threads. Writes `docs/SPEED.md`.
//!
//! lueur is timed as a user runs it: the wall time of the whole `lueur
//! render` process (start, scene parse, render, EXR write), so that a cost
//! anywhere on that path shows. Mitsuba is timed as `cargo xtask peers`
//! times it, by `xtask/peers/mitsuba_render.py`: its render after a first
//! one (`warm_s`), on `cornell-spheres` only, the scene both can express.
//!
//! A round runs old, new, `scalar_rgb` and `llvm_ad_rgb` one after the
//! other on each scene, so that a slow spell of a shared machine falls on
//! all of them alike; ratios are taken within a round, and every cell is the
//! median of the rounds with their min and max.

use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result};
use lueur::integrator::Execution;
use lueur::sdf_math::SimdLevel;

use crate::memory::{Build, build_lueur_as};
use crate::mitsuba::{installed as mitsuba_installed, version as mitsuba_version};
use crate::old::{self, Old};
use crate::peers::{SCENE as MITSUBA_SCENE, mitsuba};
use crate::reference::cache_dir;
use crate::report::{Plans, quick_flag, write_report};
use crate::{project_root, run_lueur, shipped_scenes};

struct Plan {
    size: u32,
    spp: u32,
    rounds: u32,
    mitsuba: bool,
}

const PLANS: Plans<Plan> = Plans {
    full: Plan {
        size: 128,
        spp: 64,
        rounds: 5,
        mitsuba: true,
    },
    quick: Plan {
        size: 32,
        spp: 4,
        rounds: 1,
        mitsuba: false,
    },
};

pub(crate) const MAX_DEPTH: u32 = 8;
const THREADS: u32 = 2;
const VARIANTS: [&str; 2] = ["scalar_rgb", "llvm_ad_rgb"];

/// Whether Mitsuba is measured in this run, and if not, why.
enum Peer {
    Measured(String),
    Skipped(&'static str),
}

/// One scene's speeds in M samples/s, one entry per round.
#[derive(Default)]
struct Speeds {
    new: Vec<f64>,
    old: Vec<f64>,
    /// One list per entry of `VARIANTS`.
    mitsuba: [Vec<f64>; 2],
}

pub fn run(
    quick: bool,
    rounds: Option<u32>,
    old_path: Option<&Path>,
    old_rev: Option<&str>,
    build: Build,
) -> Result<()> {
    let plan = PLANS.pick(quick);
    let rounds = rounds.unwrap_or(plan.rounds);
    let old = old::resolve(old_path, old_rev, build)?;
    let new = build_lueur_as(build)?;
    let peer = if !plan.mitsuba {
        Peer::Skipped("not run with --quick")
    } else if mitsuba_installed()? {
        Peer::Measured(mitsuba_version())
    } else {
        Peer::Skipped("not installed for python3 (`pip install mitsuba numpy`): lueur only")
    };
    if let Peer::Skipped(why) = &peer {
        eprintln!("Mitsuba 3: {why}");
    }
    let scenes = shipped_scenes()?;
    let work = cache_dir()?.join("speed");
    std::fs::create_dir_all(&work).with_context(|| format!("creating {}", work.display()))?;
    let mut speeds: Vec<Speeds> = scenes.iter().map(|_| Speeds::default()).collect();
    // Every level this CPU runs, each forced with `--simd`, on the scene Mitsuba also
    // renders: a default slower than a narrower level (as on AVX2 before its masks were
    // fixed) shows in every report.
    let levels = SimdLevel::available();
    let mut by_level: Vec<Vec<f64>> = levels.iter().map(|_| Vec::new()).collect();
    for round in 1..=rounds {
        for (scene, s) in scenes.iter().zip(&mut speeds) {
            let mut line = format!("round {round}/{rounds} {scene:<16}");
            if let Some(old) = &old {
                let speed = time_lueur(&old.binary, scene, plan, &work, None)?;
                write!(line, "  old {speed:.2}")?;
                s.old.push(speed);
            }
            let speed = time_lueur(&new, scene, plan, &work, None)?;
            write!(line, "  new {speed:.2}")?;
            s.new.push(speed);
            if scene == MITSUBA_SCENE {
                for (&level, speeds) in levels.iter().zip(&mut by_level) {
                    let speed = time_lueur(&new, scene, plan, &work, Some(level))?;
                    write!(line, "  {} {speed:.2}", level.name())?;
                    speeds.push(speed);
                }
            }
            if matches!(peer, Peer::Measured(_)) && scene == MITSUBA_SCENE {
                for (variant, speeds) in VARIANTS.iter().zip(&mut s.mitsuba) {
                    let speed = time_mitsuba(variant, plan, &work)?;
                    write!(line, "  {variant} {speed:.2}")?;
                    speeds.push(speed);
                }
            }
            eprintln!("{line}  M samples/s");
        }
    }
    let _ = std::fs::remove_dir_all(&work);
    let mut table = table(&scenes, &speeds)?;
    if let Some(i) = scenes.iter().position(|s| s == MITSUBA_SCENE) {
        table.push('\n');
        table.push_str(&level_table(&levels, &by_level, &speeds[i].new, !quick)?);
    }
    println!("{table}");
    let mut command = format!("cargo xtask speed{} --rounds {rounds}", quick_flag(quick));
    if let Some(old) = &old {
        write!(command, " {}", old.flag)?;
    }
    if build == Build::Dist {
        command.push_str(" --profile dist");
    }
    let md = report(plan, rounds, &peer, (old.as_ref(), build), &command, &table)?;
    write_report(quick, "SPEED.md", &md)?;
    Ok(())
}

/// Millions of samples per second of a render that took `seconds`.
fn m_samples_per_s(plan: &Plan, seconds: f64) -> f64 {
    f64::from(plan.size * plan.size * plan.spp) / seconds / 1e6
}

/// The `lueur` arguments of one measured render, run from the project root.
fn lueur_args(scene: &str, plan: &Plan, out: &Path) -> Vec<String> {
    let mut args = issue_18_render(scene, plan.size, plan.spp, THREADS);
    args.extend(["-q".into(), "-o".into(), out.display().to_string()]);
    args
}

/// `lueur render` of shipped scene `scene` in issue 18's configuration (`mis`,
/// independent samples, max_depth [`MAX_DEPTH`]) at `size` x `size` and `spp`, on
/// `threads` threads, run from the project root; the output flags are the caller's.
pub(crate) fn issue_18_render(scene: &str, size: u32, spp: u32, threads: u32) -> Vec<String> {
    let mut args: Vec<String> = vec!["render".into(), format!("scenes/{scene}.toml")];
    for (flag, value) in [
        ("--width", size.to_string()),
        ("--height", size.to_string()),
        ("--spp", spp.to_string()),
        ("--max-depth", MAX_DEPTH.to_string()),
        ("--strategy", "mis".into()),
        ("--sampler", "independent".into()),
        ("-t", threads.to_string()),
    ] {
        args.extend([flag.into(), value]);
    }
    args
}

/// Runs `bin render` on `scene`, on SIMD level `simd` if one is given, and
/// returns its speed from the process's wall time.
fn time_lueur(
    bin: &Path,
    scene: &str,
    plan: &Plan,
    work: &Path,
    simd: Option<SimdLevel>,
) -> Result<f64> {
    let mut args = lueur_args(scene, plan, &work.join("lueur.exr"));
    if let Some(level) = simd {
        args.extend(["--simd".into(), level.name().into()]);
    }
    let start = Instant::now();
    run_lueur(bin, &args)?;
    Ok(m_samples_per_s(plan, start.elapsed().as_secs_f64()))
}

/// Runs Mitsuba's `variant` on its scene as `cargo xtask peers` does and
/// returns its speed from the warm render's time.
fn time_mitsuba(variant: &str, plan: &Plan, work: &Path) -> Result<f64> {
    let mut args = vec![
        variant.to_string(),
        plan.spp.to_string(),
        work.join("mitsuba.exr").display().to_string(),
    ];
    for (flag, value) in [
        ("--width", plan.size),
        ("--height", plan.size),
        ("--max-depth", MAX_DEPTH),
        ("--repeats", 1),
    ] {
        args.extend([flag.to_string(), value.to_string()]);
    }
    let numbers = mitsuba(&args)?;
    let warm = numbers
        .get("warm_s")
        .with_context(|| format!("mitsuba_render.py {}: no warm_s", args.join(" ")))?;
    Ok(m_samples_per_s(plan, *warm))
}

/// The median, min and max of `xs`, or `None` for none.
pub(crate) fn spread(xs: &[f64]) -> Option<(f64, f64, f64)> {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let median = match n {
        0 => return None,
        _ if n % 2 == 1 => v[n / 2],
        _ => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    };
    Some((median, v[0], v[n - 1]))
}

/// A table cell: the median, then the min and max when there are several.
fn cell(xs: &[f64], unit: &str) -> String {
    match spread(xs) {
        None => "-".into(),
        Some((median, _, _)) if xs.len() == 1 => format!("{median:.2}{unit}"),
        Some((median, lo, hi)) => format!("{median:.2}{unit} ({lo:.2}-{hi:.2})"),
    }
}

/// `a[r] / b[r]` for each round `r` both were measured in.
fn ratios(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x / y).collect()
}

fn table(scenes: &[String], speeds: &[Speeds]) -> Result<String> {
    let mut t = String::new();
    writeln!(
        t,
        "| scene | lueur new (M samples/s) | old | new/old | Mitsuba scalar_rgb | llvm_ad_rgb | \
         lueur/scalar_rgb | lueur/llvm_ad_rgb |"
    )?;
    writeln!(t, "|---|---|---|---|---|---|---|---|")?;
    for (scene, s) in scenes.iter().zip(speeds) {
        let [scalar, llvm] = &s.mitsuba;
        writeln!(
            t,
            "| {scene} | {} | {} | {} | {} | {} | {} | {} |",
            cell(&s.new, ""),
            cell(&s.old, ""),
            cell(&ratios(&s.new, &s.old), "x"),
            cell(scalar, ""),
            cell(llvm, ""),
            cell(&ratios(&s.new, scalar), "x"),
            cell(&ratios(&s.new, llvm), "x"),
        )?;
    }
    Ok(t)
}

/// The speed of each forced level on `MITSUBA_SCENE` against the default's in
/// the same round, flagging a level faster than the default where `flag` (not
/// in `--quick` runs, whose renders are too short to rank levels).
fn level_table(
    levels: &[SimdLevel],
    speeds: &[Vec<f64>],
    default: &[f64],
    flag: bool,
) -> Result<String> {
    let mut t = String::new();
    let detected = Execution::default().simd;
    writeln!(
        t,
        "By SIMD level, `{MITSUBA_SCENE}` (`--simd LEVEL`; the default is `{}`):\n",
        detected.name()
    )?;
    writeln!(t, "| level | lanes | M samples/s | level/default |")?;
    writeln!(t, "|---|---|---|---|")?;
    let mut faster = Vec::new();
    for (level, s) in levels.iter().zip(speeds) {
        let ratio = ratios(s, default);
        if flag && *level != detected && spread(&ratio).is_some_and(|(median, _, _)| median > 1.05)
        {
            faster.push(level.name());
        }
        writeln!(
            t,
            "| {} | {} | {} | {} |",
            level.name(),
            level.lanes(),
            cell(s, ""),
            cell(&ratio, "x")
        )?;
    }
    if !faster.is_empty() {
        writeln!(
            t,
            "\n**The default level is not the fastest here**: {} beat it by more than 5%.",
            faster.join(", ")
        )?;
        eprintln!(
            "warning: on this machine {} ran faster than the default level {}",
            faster.join(", "),
            detected.name()
        );
    }
    Ok(t)
}

fn report(
    plan: &Plan,
    rounds: u32,
    peer: &Peer,
    (old, build): (Option<&Old>, Build),
    command: &str,
    table: &str,
) -> Result<String> {
    let (size, spp) = (plan.size, plan.spp);
    let args = lueur_args("NAME", plan, Path::new("out.exr")).join(" ");
    let mut md = String::new();
    writeln!(md, "# Speed\n")?;
    writeln!(
        md,
        "Samples per second of `lueur` on every shipped scene, {size}x{size}, {spp} spp, \
         max_depth {MAX_DEPTH}, `mis`, independent samples, {THREADS} threads (issue 18's \
         configuration{}). Higher is faster. Regenerate with `{command}` on a quiet machine.\n",
        if size == 128 && spp == 64 {
            ""
        } else {
            ", reduced"
        }
    )?;
    writeln!(md, "{table}")?;
    writeln!(md, "## How it was measured\n")?;
    writeln!(
        md,
        "lueur: the wall time of the whole process, `lueur {args}` from the project root \
         (start, scene parse, render and EXR write), as a user runs it; M samples/s = \
         {size} x {size} x {spp} / seconds / 10^6. *new* is this workspace's `lueur-cli`, \
         built by {}; *old* {}. {} Rounds: {rounds}, each \
         running on each scene, of old, new, `scalar_rgb` and `llvm_ad_rgb`, those measured, \
         in turn; a cell is the median of the rounds (min-max), and a ratio is taken within each round before \
         its median. The table by SIMD level runs the new binary once more per level in each round, \
         right after its default run on `{MITSUBA_SCENE}`; a level more than 5% faster than the \
         default is flagged.\n",
        build.describe(),
        old.map_or("was not given (`--old PATH` or `--old-rev REV`)", |o| o
            .description
            .as_str()),
        mitsuba_paragraph(peer),
    )?;
    writeln!(md, "## Machine\n")?;
    machine(&mut md, peer, command)?;
    Ok(md)
}

fn mitsuba_paragraph(peer: &Peer) -> String {
    match peer {
        Peer::Measured(version) => format!(
            "Mitsuba {version}: `xtask/peers/mitsuba_render.py` as `cargo xtask peers` runs it, \
             on `{MITSUBA_SCENE}` only (the shipped scene it can express), its `path` \
             integrator at max_depth {MAX_DEPTH} with independent samples, Russian \
             roulette from lueur's `roulette_depth`, and all the machine's cores, timed by \
             its render after a first one (`warm_s`): Python's start, the scene load and a \
             JIT variant's kernel compile are not counted, which favours Mitsuba."
        ),
        Peer::Skipped(why) => format!("Mitsuba 3: {why}."),
    }
}

/// The machine's CPU, its SIMD features, lueur's lane path, the threads,
/// the commit and the command, as a list.
fn machine(md: &mut String, peer: &Peer, command: &str) -> Result<()> {
    let cores = std::thread::available_parallelism().map_or(0, std::num::NonZero::get);
    let level = Execution::default().simd;
    let mitsuba = match peer {
        Peer::Measured(version) => format!("{version}, every core ({cores})"),
        Peer::Skipped(why) => (*why).to_owned(),
    };
    writeln!(md, "- CPU: {}, {cores} cores", cpu_model())?;
    writeln!(md, "- SIMD features: {}", simd_features())?;
    writeln!(
        md,
        "- lueur's lane path (`Execution::default().simd`): {level:?}, {} lanes",
        level.lanes()
    )?;
    writeln!(md, "- threads: lueur {THREADS} (`-t {THREADS}`)")?;
    writeln!(md, "- Mitsuba: {mitsuba}")?;
    writeln!(md, "- commit: {}", commit())?;
    writeln!(md, "- command: `{command}`")?;
    Ok(())
}

/// The first `model name` of `/proc/cpuinfo`, where there is one.
pub(crate) fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, model)| model.trim().to_owned())
        })
        .unwrap_or_else(|| format!("unknown ({})", std::env::consts::ARCH))
}

#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
pub(crate) fn simd_features() -> String {
    let features = [
        ("sse4.2", std::arch::is_x86_feature_detected!("sse4.2")),
        ("avx2", std::arch::is_x86_feature_detected!("avx2")),
        ("fma", std::arch::is_x86_feature_detected!("fma")),
        ("avx512f", std::arch::is_x86_feature_detected!("avx512f")),
        ("avx512bw", std::arch::is_x86_feature_detected!("avx512bw")),
        ("avx512dq", std::arch::is_x86_feature_detected!("avx512dq")),
        ("avx512vl", std::arch::is_x86_feature_detected!("avx512vl")),
    ];
    let named: Vec<String> = features
        .iter()
        .map(|&(name, on)| format!("{}{name}", if on { "" } else { "no " }))
        .collect();
    named.join(", ")
}

#[cfg(target_arch = "aarch64")]
pub(crate) fn simd_features() -> String {
    let neon = std::arch::is_aarch64_feature_detected!("neon");
    format!("aarch64, NEON {}", if neon { "present" } else { "absent" })
}

#[cfg(not(any(target_arch = "x86", target_arch = "x86_64", target_arch = "aarch64")))]
pub(crate) fn simd_features() -> String {
    format!("not probed on {}", std::env::consts::ARCH)
}

/// `git describe --always --dirty` of the project, or "unknown".
pub(crate) fn commit() -> String {
    Command::new("git")
        .args(["describe", "--always", "--dirty"])
        .current_dir(project_root())
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map_or("unknown".into(), |o| {
            String::from_utf8_lossy(&o.stdout).trim().to_owned()
        })
}
