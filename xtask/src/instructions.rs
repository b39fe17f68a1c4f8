//! `cargo xtask instructions`: the instructions lueur executes per sample on
//! every shipped scene, counted by valgrind's callgrind, against another
//! build where given, with where they go. Writes `docs/INSTRUCTIONS.md`.
//!
//! Counts are the same in every run, where `cargo xtask speed`'s times move
//! by 15% from one round to the next on a shared machine: a change of a few
//! percent, which the clock cannot resolve there, shows here. But a count is
//! not a time. A division counts as much as an addition, and a stage bound by
//! latency (a scalar chain of square roots) runs slower than its count says;
//! so a speed-up is claimed from `speed`, and this report says where the
//! work is and whether a change removed any.
//!
//! Each binary renders issue 18's configuration (`mis`, independent
//! samples, max_depth 8) on one thread, once at 1 spp and once at
//! `1 + extra` spp. callgrind counts only inside the render's passes
//! ([`RENDER`]): the start, the scene parse, the image write and the thread
//! pool's waits (which vary with the scheduler) are left out, and what is
//! left repeats to the instruction. The difference between the two runs
//! over the extra samples is what one sample costs; the same difference per
//! function (its own instructions, inlined code included, calls left to the
//! callee) says where they go.
//!
//! Each scene is also counted with its own sampler (what its file says, as
//! a user's render runs it), the rest of the configuration unchanged: the
//! sampler's cost never shows with independent samples, and the default one
//! once took a sixth of a render.
//!
//! valgrind runs the program on its own model of the CPU, which has AVX2 and
//! no AVX-512: the counts are those of the AVX2 path (or narrower) whatever
//! the machine; the report names the level the streams ran on.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::memory::{Build, build_lueur};
use crate::old::{self, Old};
use crate::reference::cache_dir;
use crate::report::{Plans, quick_flag, write_report};
use crate::speed::{MAX_DEPTH, commit, cpu_model, issue_18_render};
use crate::{project_root, shipped_scenes};

struct Plan {
    size: u32,
    /// Samples per pixel beyond the first.
    extra: u32,
    /// Functions listed per scene.
    top: usize,
}

const PLANS: Plans<Plan> = Plans {
    full: Plan {
        size: 32,
        extra: 8,
        top: 12,
    },
    quick: Plan {
        size: 16,
        extra: 2,
        top: 5,
    },
};

/// The function callgrind counts inside (`--toggle-collect`): the render's
/// passes, with their tiles, paths and film merges, and not the start, the
/// parse, the image write or the thread pool's waits, which vary from run
/// to run with the scheduler.
const RENDER: &str = "lueur_integrator::render::render_pass_in";

/// What callgrind counted in one run, inside [`RENDER`].
#[derive(Debug, Default, PartialEq)]
struct Profile {
    total: u64,
    /// Each function's own instructions.
    by_function: HashMap<String, u64>,
}

/// Which sampler a count renders with.
#[derive(Clone, Copy, PartialEq)]
enum Sampling {
    /// Issue 18's: independent samples.
    Independent,
    /// The scene file's own.
    Scene,
}

/// One binary's counts on one scene.
struct Counted {
    /// Instructions per sample beyond the first spp.
    per_sample: f64,
    /// The same with the scene's own sampler, and that sampler's name.
    own_sampler: (f64, String),
    /// Per function, its own instructions per sample beyond the first spp,
    /// the kernels merged, most first.
    by_function: Vec<(String, f64)>,
    /// The instruction set the streams ran on, as `--stats` names it.
    streams: String,
}

pub fn run(quick: bool, old_path: Option<&Path>, old_rev: Option<&str>) -> Result<()> {
    let plan = PLANS.pick(quick);
    let valgrind = valgrind_version()?;
    let old = old::resolve(old_path, old_rev, Build::Release)?;
    let new = build_lueur()?;
    let work = cache_dir()?.join("instructions");
    std::fs::create_dir_all(&work).with_context(|| format!("creating {}", work.display()))?;
    let mut rows = Vec::new();
    for scene in shipped_scenes()? {
        let counted_new = count(&new, &scene, plan, &work)?;
        let counted_old = match &old {
            Some(old) => Some(count(&old.binary, &scene, plan, &work)?),
            None => None,
        };
        let against = |new: f64, old: Option<f64>| {
            old.map_or(String::new(), |o| {
                format!(", old {o:.0} (new/old {:.3})", new / o)
            })
        };
        eprintln!(
            "{scene}: {:.0} instructions per sample{}; with {}: {:.0}{}",
            counted_new.per_sample,
            against(
                counted_new.per_sample,
                counted_old.as_ref().map(|o| o.per_sample)
            ),
            counted_new.own_sampler.1,
            counted_new.own_sampler.0,
            against(
                counted_new.own_sampler.0,
                counted_old.as_ref().map(|o| o.own_sampler.0)
            ),
        );
        rows.push((scene, counted_new, counted_old));
    }
    let _ = std::fs::remove_dir_all(&work);
    let mut command = format!("cargo xtask instructions{}", quick_flag(quick));
    if let Some(old) = &old {
        write!(command, " {}", old.flag)?;
    }
    let md = report(plan, &rows, old.as_ref(), &valgrind, &command)?;
    write_report(quick, "INSTRUCTIONS.md", &md)?;
    Ok(())
}

/// valgrind's version line, or why this report cannot run.
fn valgrind_version() -> Result<String> {
    let out = Command::new("valgrind").arg("--version").output();
    match out {
        Ok(o) if o.status.success() => Ok(String::from_utf8_lossy(&o.stdout).trim().to_owned()),
        _ => bail!(
            "`cargo xtask instructions` counts with valgrind, which is not installed \
             (Debian: `apt install valgrind`)"
        ),
    }
}

/// Counts `binary` on `scene` at 1 and at `1 + plan.extra` spp.
fn count(binary: &Path, scene: &str, plan: &Plan, work: &Path) -> Result<Counted> {
    let run = |spp, sampling| callgrind(binary, scene, (plan.size, spp), sampling, work);
    let (short, _) = run(1, Sampling::Independent)?;
    let (long, rendered) = run(1 + plan.extra, Sampling::Independent)?;
    let (own_short, _) = run(1, Sampling::Scene)?;
    let (own_long, own_rendered) = run(1 + plan.extra, Sampling::Scene)?;
    let samples = f64::from(plan.size) * f64::from(plan.size) * f64::from(plan.extra);
    let extra =
        |short: &Profile, long: &Profile| long.total.saturating_sub(short.total) as f64 / samples;
    Ok(Counted {
        per_sample: extra(&short, &long),
        own_sampler: (extra(&own_short, &own_long), own_rendered.sampler),
        by_function: breakdown(&short, &long)
            .into_iter()
            .map(|(f, n)| (f, n as f64 / samples))
            .collect(),
        streams: rendered.streams,
    })
}

/// What a render said of itself on its standard output.
struct Rendered {
    /// The instruction set of the streams, from `--stats`.
    streams: String,
    /// The sampler, from the first line (`rendered ... (strategy, sampler) ...`).
    sampler: String,
}

/// One render under callgrind: what it counted, and what the render said.
fn callgrind(
    binary: &Path,
    scene: &str,
    (size, spp): (u32, u32),
    sampling: Sampling,
    work: &Path,
) -> Result<(Profile, Rendered)> {
    let counts = work.join("callgrind.out");
    let image = work.join("image.exr");
    let mut lueur_args = issue_18_render(scene, size, spp, 1);
    if sampling == Sampling::Scene {
        let at = (lueur_args.iter())
            .position(|a| a == "--sampler")
            .context("issue 18's render names a sampler")?;
        lueur_args.drain(at..at + 2);
    }
    lueur_args.extend(["--stats".into(), "-o".into(), image.display().to_string()]);
    let out = Command::new("valgrind")
        .args([
            "--tool=callgrind",
            "--compress-strings=no",
            "--compress-pos=no",
        ])
        .arg(format!("--toggle-collect={RENDER}"))
        .arg(format!("--callgrind-out-file={}", counts.display()))
        .arg(binary)
        .args(&lueur_args)
        .current_dir(project_root())
        .output()
        .with_context(|| format!("cannot run valgrind on {}", binary.display()))?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    anyhow::ensure!(
        out.status.success(),
        "valgrind {} {}: {}\n{stderr}",
        binary.display(),
        lueur_args.join(" "),
        out.status
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let streams = (stdout.lines())
        .find_map(|l| l.trim().strip_prefix("ray streams on"))
        .map_or_else(
            || "not reported".to_owned(),
            |s| s.split_whitespace().collect::<Vec<_>>().join(" "),
        );
    // The render's own status line goes to standard error, beside valgrind's.
    let sampler = rendered_sampler(&stderr)
        .unwrap_or("not reported")
        .to_owned();
    let text = std::fs::read_to_string(&counts)
        .with_context(|| format!("reading {}", counts.display()))?;
    let profile = parse(&text)?;
    anyhow::ensure!(
        profile.total > 0,
        "callgrind counted nothing inside `{RENDER}`: renamed, or inlined?"
    );
    Ok((profile, Rendered { streams, sampler }))
}

/// The sampler a render's status line names: `rendered WxH at N spp (strategy, sampler) ...`.
fn rendered_sampler(output: &str) -> Option<&str> {
    let line = output.lines().find_map(|l| l.strip_prefix("rendered "))?;
    let (inside, _) = line.split_once('(')?.1.split_once(')')?;
    Some(inside.split_once(", ")?.1)
}

/// The total and each function's own instructions in a callgrind output
/// file (`--compress-strings=no --compress-pos=no`; compressed names are
/// understood too). A cost line after `calls=` is the call's inclusive
/// cost, which belongs to the callee, so it is skipped.
fn parse(text: &str) -> Result<Profile> {
    let mut profile = Profile::default();
    let mut names: HashMap<String, String> = HashMap::new();
    let mut function: Option<String> = None;
    let mut call_cost_next = false;
    let mut totals = None;
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("fn=") {
            function = Some(name(rest, &mut names));
            continue;
        }
        if line.starts_with("calls=") {
            call_cost_next = true;
            continue;
        }
        if let Some(rest) = line
            .strip_prefix("totals:")
            .or_else(|| line.strip_prefix("summary:"))
        {
            totals = Some(first_number(rest)?);
            continue;
        }
        let Some(first) = line.chars().next() else {
            continue;
        };
        if !(first.is_ascii_digit() || matches!(first, '+' | '-' | '*')) {
            continue;
        }
        // Positions, then the cost (one event: instructions).
        let cost: u64 = match line.split_whitespace().last() {
            Some(c) => c
                .parse()
                .with_context(|| format!("callgrind cost line `{line}`"))?,
            None => continue,
        };
        if call_cost_next {
            call_cost_next = false;
        } else if let Some(f) = &function {
            *profile.by_function.entry(f.clone()).or_default() += cost;
        }
    }
    profile.total = match totals {
        Some(t) => t,
        None => bail!("the callgrind output has no totals line"),
    };
    Ok(profile)
}

/// A function's name from `fn=`'s value: `NAME`, `(ID) NAME` (which also
/// defines `ID`) or `(ID)`.
fn name(value: &str, names: &mut HashMap<String, String>) -> String {
    let Some(rest) = value.strip_prefix('(') else {
        return value.to_owned();
    };
    let Some((id, name)) = rest.split_once(')') else {
        return value.to_owned();
    };
    let name = name.trim();
    if name.is_empty() {
        names.get(id).cloned().unwrap_or_else(|| value.to_owned())
    } else {
        names.insert(id.to_owned(), name.to_owned());
        name.to_owned()
    }
}

fn first_number(text: &str) -> Result<u64> {
    let word = text.split_whitespace().next().unwrap_or_default();
    word.parse()
        .with_context(|| format!("callgrind totals `{text}`"))
}

/// The name a report shows: every level's copy of the vector kernels (pulp
/// names each `imp_fastcall`) as one entry.
fn shown(function: &str) -> String {
    if function.contains("vectorize::imp_fastcall") {
        "the vector kernels (ray clipping and marching, every level)".to_owned()
    } else {
        function.to_owned()
    }
}

/// Each function's own instructions in `long` beyond those in `short` (what
/// the extra samples cost it; none for a function that did less), the
/// kernels merged, most first.
fn breakdown(short: &Profile, long: &Profile) -> Vec<(String, u64)> {
    let mut merged: HashMap<String, i128> = HashMap::new();
    for (profile, sign) in [(long, 1), (short, -1)] {
        for (f, &n) in &profile.by_function {
            *merged.entry(shown(f)).or_default() += sign * i128::from(n);
        }
    }
    let mut list: Vec<(String, u64)> = merged
        .into_iter()
        .filter_map(|(f, n)| u64::try_from(n).ok().filter(|&n| n > 0).map(|n| (f, n)))
        .collect();
    list.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    list
}

fn report(
    plan: &Plan,
    rows: &[(String, Counted, Option<Counted>)],
    old: Option<&Old>,
    valgrind: &str,
    command: &str,
) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "# Instructions per sample\n")?;
    writeln!(
        md,
        "Generated by `{command}`. Counted by {valgrind} (callgrind) on one thread: \
         `mis`, independent samples, max_depth {MAX_DEPTH}, {0}x{0}; only inside `{RENDER}` \
         (not the start, the parse, the image write), the difference between {1} spp and \
         1 spp over {2} samples per pixel. The counts repeat exactly from run to run; they \
         are not times (see `xtask/src/instructions.rs`).\n",
        plan.size,
        1 + plan.extra,
        plan.extra
    )?;
    writeln!(md, "- CPU: {} (as valgrind models it)", cpu_model())?;
    writeln!(md, "- commit: {}", commit())?;
    if let Some(old) = old {
        writeln!(md, "- old: {}", old.description)?;
    }
    writeln!(md)?;
    let with_old = old.is_some();
    count_table(
        &mut md,
        "streams on",
        (rows.iter()).map(|(scene, new, old)| {
            let old = old.as_ref().map(|o| o.per_sample);
            (scene.as_str(), new.streams.as_str(), new.per_sample, old)
        }),
        with_old,
    )?;
    writeln!(
        md,
        "\nWith each scene's own sampler (its file's, as a user's render runs it), the rest \
         unchanged:\n"
    )?;
    count_table(
        &mut md,
        "sampler",
        (rows.iter()).map(|(scene, new, old)| {
            let old = old.as_ref().map(|o| o.own_sampler.0);
            (
                scene.as_str(),
                new.own_sampler.1.as_str(),
                new.own_sampler.0,
                old,
            )
        }),
        with_old,
    )?;
    for (scene, new, _) in rows {
        writeln!(
            md,
            "\n## {scene}: where a sample's instructions go\n\nEach function's own \
             instructions (inlined code included, calls left to the callee) per extra \
             sample, the {} largest:\n",
            plan.top
        )?;
        writeln!(md, "| per sample | share | function |")?;
        writeln!(md, "|---|---|---|")?;
        for (f, n) in new.by_function.iter().take(plan.top) {
            writeln!(
                md,
                "| {n:.0} | {:.1}% | `{f}` |",
                100.0 * n / new.per_sample
            )?;
        }
    }
    Ok(md)
}

/// A table of instructions per sample, a row per scene: `(scene, label, count, old count)`,
/// the label in a column called `column`, and with an old build its count and the ratio.
fn count_table<'a>(
    md: &mut String,
    column: &str,
    rows: impl Iterator<Item = (&'a str, &'a str, f64, Option<f64>)>,
    with_old: bool,
) -> Result<()> {
    if with_old {
        writeln!(
            md,
            "| scene | {column} | instructions per sample | old | new / old |"
        )?;
        writeln!(md, "|---|---|---|---|---|")?;
    } else {
        writeln!(md, "| scene | {column} | instructions per sample |")?;
        writeln!(md, "|---|---|---|")?;
    }
    for (scene, label, new, old) in rows {
        write!(md, "| {scene} | {label} | {new:.0} |")?;
        if let Some(old) = old {
            write!(md, " {old:.0} | {:.3} |", new / old)?;
        }
        writeln!(md)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sampler_is_read_from_the_render_line() {
        let out = "rendered 32x32 at 9 spp (mis, sobol-xor) in 0.10 s, 0.09 M samples/s -> a.exr\n\
                   samples 9216\n";
        assert_eq!(rendered_sampler(out), Some("sobol-xor"));
        assert_eq!(rendered_sampler("samples 9216\n"), None);
    }

    /// A call's inclusive cost belongs to the callee, not to the caller's own
    /// count; compressed names resolve to
    /// the name their id was given; the total is the file's; a breakdown
    /// counts what the longer run did beyond the shorter.
    #[test]
    fn own_counts_leave_out_the_calls() {
        let text = |extra: u64| {
            format!(
                "\
version: 1
positions: line
events: Ir
fl=(1) /src/a.rs
fn=(1) caller
3 10
+1 5
cfn=(2) callee
calls=2 7
7 {}
fn=(2) callee
7 {}
fn=(1)
9 1
fn=plain name with spaces
1 2
totals: {}
",
                400 + extra,
                300 + extra,
                318 + extra
            )
        };
        let p = parse(&text(0)).unwrap();
        assert_eq!(p.total, 318);
        assert_eq!(p.by_function["caller"], 16);
        assert_eq!(p.by_function["callee"], 300);
        assert_eq!(p.by_function["plain name with spaces"], 2);
        assert_eq!(p.by_function.len(), 3);
        let longer = parse(&text(50)).unwrap();
        assert_eq!(breakdown(&p, &longer), vec![("callee".to_owned(), 50)]);
        assert!(parse("fn=x\n1 2\n").is_err(), "no totals line");
    }
}
