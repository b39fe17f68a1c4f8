//! `cargo xtask samplers`: what each point set does to images. For the
//! scenes below, `mis`, every sampler at 4, 16, 64 and 256 spp, K seeds
//! each: the image MSE against a high-spp reference and the fitted slope of
//! log MSE against log spp (independent samples: -1; better point sets are
//! steeper until the integrand's discontinuities cap them).
//!
//! The reference's own noise is subtracted from each MSE (it is the same
//! for every sampler, but at 256 spp a good sampler's error comes within a
//! factor of a few of it). Writes docs/SAMPLERS.md and
//! target/xtask/samplers.csv, and checks the claim the default sampler rests
//! on: at 64 spp, the best sampler's MSE is at least 2x below independent's
//! on every scene, and it is the default.

use std::fmt::Write as _;

use anyhow::{Context, Result, bail};
use lueur::pointsets::least_squares_slope;
use lueur::sampling::SamplerKind;
use lueur::scene::{RenderSettings, Strategy};

use crate::load_scene;
use crate::reference::{cache_dir, flatten, reference, render_film, squared_error};
use crate::report::{Plans, quick_flag, write_report};

const SCENES: [&str; 2] = ["cornell-spheres", "donut-mirrors"];

struct Plan {
    size: u32,
    spps: &'static [u32],
    k: u32,
    ref_spp: u32,
}

const PLANS: Plans<Plan> = Plans {
    full: Plan {
        size: 64,
        spps: &[4, 16, 64, 256],
        k: 4,
        ref_spp: 4096,
    },
    quick: Plan {
        size: 24,
        spps: &[4, 16, 64],
        k: 3,
        ref_spp: 1024,
    },
};

/// A sampler, its MSE at each spp of the plan, and seconds per render at
/// the highest.
type SamplerRow = (SamplerKind, Vec<f64>, f64);

/// The spp the default is chosen at.
const CHOSEN_AT: u32 = 64;

/// Measures (or, with `report_only`, reads the last measurement's CSV) and
/// writes the report.
pub fn run(quick: bool, report_only: bool) -> Result<()> {
    let plan = PLANS.pick(quick);
    let csv_path = cache_dir()?.join(if quick {
        "samplers-quick.csv"
    } else {
        "samplers.csv"
    });
    let table = if report_only {
        let text = std::fs::read_to_string(&csv_path).with_context(|| {
            format!(
                "reading {} (run `cargo xtask samplers` once first)",
                csv_path.display()
            )
        })?;
        from_csv(plan, &text)?
    } else {
        let (table, csv) = measure(plan)?;
        std::fs::write(&csv_path, csv)
            .with_context(|| format!("writing {}", csv_path.display()))?;
        table
    };
    report(plan, quick, &table)
}

/// A measured table: per scene, its samplers' rows.
type Table = Vec<(&'static str, Vec<SamplerRow>)>;

/// The table of a measurement read back from its CSV.
fn from_csv(plan: &Plan, text: &str) -> Result<Table> {
    let mut table = Vec::new();
    for scene in SCENES {
        let mut rows = Vec::new();
        for &sampler in SamplerKind::ALL {
            let mut mses = Vec::new();
            let mut seconds = 0.0;
            for &spp in plan.spps {
                let prefix = format!("{scene},{sampler},{spp},");
                let line = text
                    .lines()
                    .find(|l| l.starts_with(&prefix))
                    .with_context(|| format!("no `{prefix}` row in the CSV"))?;
                let mut fields = line[prefix.len()..].split(',');
                let mut next =
                    || -> Result<f64> { Ok(fields.next().context("a short CSV row")?.parse()?) };
                mses.push(next()?);
                seconds = next()?;
            }
            rows.push((sampler, mses, seconds));
        }
        table.push((scene, rows));
    }
    Ok(table)
}

/// Renders every configuration; the table and its CSV.
fn measure(plan: &Plan) -> Result<(Table, String)> {
    // Per scene, per sampler: MSE at each spp, and seconds per render at the
    // highest.
    let mut table: Table = Vec::new();
    let mut csv = String::from("scene,sampler,spp,mse,seconds\n");
    for scene in SCENES {
        let file = load_scene(scene)?;
        let reference = reference(scene, &file, plan.size, plan.ref_spp)?;
        let n = reference.mean.len() as f64;
        let ref_noise = reference.noise();
        let mut rows = Vec::new();
        for &sampler in SamplerKind::ALL {
            let mut mses = Vec::new();
            let mut seconds = 0.0;
            for &spp in plan.spps {
                let mut sq_err = 0.0;
                let mut times = Vec::new();
                for i in 0..plan.k {
                    let settings = RenderSettings {
                        width: plan.size,
                        height: plan.size,
                        spp,
                        strategy: Strategy::Mis,
                        sampler,
                        // The point sets as point sets: one randomization
                        // of all the spp. What dealing them into replicates
                        // for honest error bars costs is docs/REPLICATES.md.
                        replicates: Some(1),
                        seed: 2000 + u64::from(i),
                        ..file.settings.clone()
                    };
                    let (film, secs) = render_film(&file, &settings)?;
                    times.push(secs);
                    let img = flatten(&film.mean_image());
                    sq_err += squared_error(&img, &reference.mean);
                }
                let mse = sq_err / (n * f64::from(plan.k)) - ref_noise;
                times.sort_by(f64::total_cmp);
                seconds = times[times.len() / 2];
                eprintln!("{scene:>16} {sampler:>12} {spp:>4} spp: MSE {mse:.3e} ({seconds:.2} s)");
                writeln!(csv, "{scene},{sampler},{spp},{mse:e},{seconds}")?;
                mses.push(mse);
            }
            rows.push((sampler, mses, seconds));
        }
        table.push((scene, rows));
    }
    Ok((table, csv))
}

/// Writes docs/SAMPLERS.md and checks the default sampler's claim.
fn report(plan: &Plan, quick: bool, table: &Table) -> Result<()> {
    let chosen_index = plan
        .spps
        .iter()
        .position(|&s| s == CHOSEN_AT)
        .context("the plan measures the spp the default is chosen at")?;
    let mut failures = Vec::new();
    let mut md = String::new();
    writeln!(
        md,
        "# Point sets in images\n\nGenerated by `cargo xtask samplers{}` ({}x{} pixels, `mis`, {} renders \
         per configuration with seeds 2000.., reference: `mis` with independent samples at {} spp, seed 0). \
         MSE is the mean over pixels and RGB channels of the squared error against the reference, \
         averaged over the renders, less the reference's own variance. Slope: least-squares slope of \
         log MSE against log spp (independent sampling: -1). Ratio: independent's MSE over the \
         sampler's at {CHOSEN_AT} spp. Times are medians on this machine, shared with whatever else \
         ran: compare them within one run only. Each render is one randomization of its point set \
         (`--replicates 1`): the point sets themselves; dealing the samples into replicates for \
         honest error bars (the default) costs some of the gain, measured in REPLICATES.md.\n",
        quick_flag(quick),
        plan.size,
        plan.size,
        plan.k,
        plan.ref_spp
    )?;
    let default = SamplerKind::default();
    for (scene, rows) in table {
        writeln!(md, "## {scene}\n")?;
        let mut header = String::from("| sampler |");
        let mut rule = String::from("|---|");
        for spp in plan.spps {
            write!(header, " MSE {spp} spp |")?;
            rule.push_str("---|");
        }
        writeln!(
            md,
            "{header} slope | ratio at {CHOSEN_AT} spp | s / render at {} spp |",
            plan.spps.last().unwrap()
        )?;
        writeln!(md, "{rule}---|---|---|")?;
        let independent = rows
            .iter()
            .find(|r| r.0 == SamplerKind::Independent)
            .map(|r| r.1[chosen_index])
            .context("independent is measured")?;
        for (sampler, mses, seconds) in rows {
            let mut line = format!("| {sampler} |");
            for m in mses {
                write!(line, " {m:.2e} |")?;
            }
            let slope = slope(plan.spps, mses);
            writeln!(
                md,
                "{line} {slope:.2} | {:.1} | {seconds:.2} |",
                independent / mses[chosen_index]
            )?;
        }
        let best = rows
            .iter()
            .min_by(|a, b| a.1[chosen_index].total_cmp(&b.1[chosen_index]))
            .expect("samplers were measured");
        let default_mse = rows
            .iter()
            .find(|r| r.0 == default)
            .map(|r| r.1[chosen_index])
            .context("the default is measured")?;
        writeln!(
            md,
            "\nBest at {CHOSEN_AT} spp: `{}` ({:.1}x below independent); the default `{default}`: {:.1}x.\n",
            best.0,
            independent / best.1[chosen_index],
            independent / default_mse
        )?;
        if !(independent / default_mse >= 2.0) {
            failures.push(format!(
                "{scene}: the default sampler `{default}` is only {:.2}x below independent at {CHOSEN_AT} spp",
                independent / default_mse
            ));
        }
    }
    if failures.is_empty() {
        writeln!(
            md,
            "The claim checked by the command holds: at {CHOSEN_AT} spp the default sampler's MSE is at least 2x below independent's on every scene."
        )?;
    } else {
        writeln!(md, "**Failed claims:**\n")?;
        for f in &failures {
            writeln!(md, "- {f}")?;
        }
    }
    write_report(quick, "SAMPLERS.md", &md)?;
    if !failures.is_empty() {
        bail!(
            "{} claim(s) failed:\n{}",
            failures.len(),
            failures.join("\n")
        );
    }
    Ok(())
}

/// Least-squares slope of log MSE against log spp (non-positive MSEs, noise
/// below the reference's, are left out).
fn slope(spps: &[u32], mses: &[f64]) -> f64 {
    let (xs, ys): (Vec<f64>, Vec<f64>) = spps
        .iter()
        .zip(mses)
        .filter(|(_, m)| **m > 0.0)
        .map(|(&s, &m)| (f64::from(s).ln(), m.ln()))
        .unzip();
    least_squares_slope(&xs, &ys)
}
