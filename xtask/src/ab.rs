//! `cargo xtask ab`: is this tree faster than another build, and by how much? The
//! measurement a speed change is judged by before it is taken (docs/PERFORMANCE.md):
//! both binaries render the same scenes in issue 18's configuration, one thread by
//! default (the other core stays free for the machine's noise), alternating within each
//! round and in the opposite order every other round (old-new, new-old), so that a
//! machine that slows down over the run slows both alike.
//!
//! Each round gives a paired ratio, new time over old. The report gives, per scene, the
//! median ratio and a distribution-free 95% interval for it (order statistics of the
//! paired ratios, Conover, "Practical Nonparametric Statistics", 3rd ed., sec. 3.2: no
//! assumption on how times are spread), and says "faster" or "slower" only when the
//! interval leaves 1. (A build whose code only moved, the renderer unchanged, can be
//! "slower" or "faster" by a few tenths of a percent: code layout. Read the median too.)
//! It also says whether the two builds' images are the same bits, so a
//! change meant only as a speed-up shows at once if it moved the image. Prints its
//! table; writes no report, unlike `speed`, whose figures are the ones the docs quote.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, bail};

use crate::identical::compare;
use crate::memory::{Build, build_lueur_as};
use crate::old;
use crate::reference::cache_dir;
use crate::speed::{commit, cpu_model, issue_18_render, simd_features, spread};
use crate::{run_lueur, shipped_scenes};

/// What `cargo xtask ab` measures.
pub struct Plan<'a> {
    pub scenes: &'a [String],
    pub rounds: u32,
    pub threads: u32,
    pub size: u32,
    pub spp: u32,
    pub sampler: &'a str,
}

pub fn run(
    old_path: Option<&Path>,
    old_rev: Option<&str>,
    build: Build,
    plan: &Plan<'_>,
) -> Result<()> {
    let Some(old) = old::resolve(old_path, old_rev, build)? else {
        bail!("name the other build: --old PATH or --old-rev REV");
    };
    let new = build_lueur_as(build)?;
    let shipped = shipped_scenes()?;
    let scenes: Vec<String> = if plan.scenes.is_empty() {
        shipped
    } else {
        for scene in plan.scenes {
            if !shipped.contains(scene) {
                bail!(
                    "--scene {scene}: not a shipped scene (scenes/*.toml: {})",
                    shipped.join(", ")
                );
            }
        }
        plan.scenes.to_vec()
    };
    let work = cache_dir()?.join("ab");
    std::fs::create_dir_all(&work).with_context(|| format!("creating {}", work.display()))?;
    // Per scene: the old and new times of each round, and whether the images matched.
    let mut times: Vec<[Vec<f64>; 2]> = scenes.iter().map(|_| [Vec::new(), Vec::new()]).collect();
    let mut bits: Vec<Option<String>> = vec![None; scenes.len()];
    for round in 0..plan.rounds {
        for (i, scene) in scenes.iter().enumerate() {
            let mut line = format!("round {}/{} {scene:<16}", round + 1, plan.rounds);
            for which in order(round) {
                let (binary, name) = [(&old.binary, "old"), (&new, "new")][which];
                let out = work.join(format!("{name}.exr"));
                let seconds = time_render(binary, &render_args(scene, plan, &out))?;
                write!(line, "  {name} {seconds:.3} s")?;
                times[i][which].push(seconds);
            }
            if round == 0 {
                bits[i] = compare(&work.join("old.exr"), &work.join("new.exr"))?;
            }
            eprintln!("{line}");
        }
    }
    let _ = std::fs::remove_dir_all(&work);
    println!(
        "`cargo xtask ab`: new ({}) against old ({}); {}",
        commit(),
        old.description,
        build.describe()
    );
    println!(
        "threads: {}; {}x{}, {} spp, `--sampler {}`; {} rounds; CPU: {} ({})\n",
        plan.threads,
        plan.size,
        plan.size,
        plan.spp,
        plan.sampler,
        plan.rounds,
        cpu_model(),
        simd_features()
    );
    println!("{}", table(&scenes, &times, &bits)?);
    Ok(())
}

/// Which binary runs first in `round` (0 old, 1 new): old first in even rounds.
fn order(round: u32) -> [usize; 2] {
    if round.is_multiple_of(2) {
        [0, 1]
    } else {
        [1, 0]
    }
}

/// The `lueur render` arguments of one timed render of `scene` to `out`.
fn render_args(scene: &str, plan: &Plan<'_>, out: &Path) -> Vec<String> {
    let mut args = issue_18_render(scene, plan.size, plan.spp, plan.threads);
    if let Some(at) = args.iter().position(|a| a == "--sampler") {
        args[at + 1] = plan.sampler.to_owned();
    }
    args.extend(["-q".into(), "-o".into(), out.display().to_string()]);
    args
}

/// The wall time of one `binary` process with `args`.
fn time_render(binary: &Path, args: &[String]) -> Result<f64> {
    let start = Instant::now();
    run_lueur(binary, args)?;
    Ok(start.elapsed().as_secs_f64())
}

fn table(scenes: &[String], times: &[[Vec<f64>; 2]], bits: &[Option<String>]) -> Result<String> {
    let mut t = String::new();
    writeln!(
        t,
        "| scene | old (s) | new (s) | new / old: median (min-max) | 95% interval | verdict | images |"
    )?;
    writeln!(t, "|---|---|---|---|---|---|---|")?;
    for ((scene, [old, new]), bits) in scenes.iter().zip(times).zip(bits) {
        let ratios: Vec<f64> = new.iter().zip(old).map(|(n, o)| n / o).collect();
        let cell = |xs: &[f64]| match spread(xs) {
            Some((median, lo, hi)) => format!("{median:.4} ({lo:.4}-{hi:.4})"),
            None => "-".into(),
        };
        let median = |xs: &[f64]| spread(xs).map_or(f64::NAN, |(m, _, _)| m);
        let (interval, verdict) = match median_interval(&ratios, 0.95) {
            Some((lo, hi)) => (
                format!("{lo:.4}-{hi:.4}"),
                if hi < 1.0 {
                    "faster"
                } else if lo > 1.0 {
                    "slower"
                } else {
                    "no difference shown"
                },
            ),
            None => ("-".into(), "too few rounds (6 at least)"),
        };
        writeln!(
            t,
            "| {scene} | {:.3} | {:.3} | {} | {interval} | {verdict} | {} |",
            median(old),
            median(new),
            cell(&ratios),
            match bits {
                None => "same bits".to_owned(),
                Some(why) => format!("differ: {why}"),
            }
        )?;
    }
    Ok(t)
}

/// A distribution-free interval of confidence at least `confidence` for the median of
/// the distribution `xs` are drawn from: `[x_(k), x_(n+1-k)]` of the sorted sample, with
/// the largest `k` for which `P(k - 1 or fewer of n fall below the median) <= (1 -
/// confidence) / 2`, that count being binomial(n, 1/2). `None` where even `k = 1` (the
/// whole range) falls short: fewer than 6 values for 95%.
pub fn median_interval(xs: &[f64], confidence: f64) -> Option<(f64, f64)> {
    let n = xs.len();
    let tail = (1.0 - confidence) / 2.0;
    // P(Bin(n, 1/2) <= j), summed term by term.
    let mut below = 0.0;
    let mut term = 0.5f64.powi(n as i32);
    let mut k = 0;
    for j in 0..n {
        below += term;
        if below > tail {
            break;
        }
        k = j + 1;
        term *= (n - j) as f64 / (j + 1) as f64;
    }
    if k == 0 {
        return None;
    }
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    Some((v[k - 1], v[n - k]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The order statistics of Conover's table A3 (two-sided 95%): n = 6 uses the whole
    /// range; n = 9 the 2nd and 8th; n = 11 the 2nd and 10th; n = 20 the 6th and 15th.
    #[test]
    fn the_median_interval_takes_the_tabulated_order_statistics() {
        let ranks = |n: usize| {
            let xs: Vec<f64> = (1..=n).map(|i| i as f64).collect();
            median_interval(&xs, 0.95).map(|(lo, hi)| (lo as usize, hi as usize))
        };
        assert_eq!(ranks(5), None);
        assert_eq!(ranks(6), Some((1, 6)));
        assert_eq!(ranks(9), Some((2, 8)));
        assert_eq!(ranks(11), Some((2, 10)));
        assert_eq!(ranks(20), Some((6, 15)));
    }

    /// The interval covers the median at least as often as it claims: ratios drawn
    /// around a known median, many times over (a fixed seed).
    #[test]
    fn the_median_interval_covers_as_claimed() {
        use lueur::sampling::{Sampler, SamplerKind};
        let mut sampler = Sampler::for_render(SamplerKind::Independent, 18, [1, 1], 1, 1);
        let (trials, mut covered) = (4000, 0);
        for trial in 0..trials {
            sampler.start_pixel_sample([0, 0], trial, 0);
            let xs: Vec<f64> = (0..11)
                .map(|_| 1.0 + 0.05 * (f64::from(sampler.next_1d()) - 0.5).powi(3))
                .collect();
            let (lo, hi) = median_interval(&xs, 0.95).expect("11 values");
            covered += usize::from(lo <= 1.0 && 1.0 <= hi);
        }
        // The claim is at least 95% (98.8% for n = 11); 3 standard errors below 95%.
        let rate = covered as f64 / trials as f64;
        assert!(
            rate > 0.95 - 3.0 * (0.95f64 * 0.05 / trials as f64).sqrt(),
            "{rate}"
        );
    }

    #[test]
    fn rounds_alternate_which_build_runs_first() {
        assert_eq!(order(0), [0, 1]);
        assert_eq!(order(1), [1, 0]);
        assert_eq!(order(2), [0, 1]);
    }
}
