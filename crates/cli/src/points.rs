//! `lueur points`: generate a point set of the sampling library, write it as
//! CSV or plot it as a PNG, and print its quality measures (discrepancies,
//! integration error as UTK measures it).

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Parser;
use lueur_pointsets::{
    IntegrandFamily, PointSet, PointSetKind, centered_l2_discrepancy, generate, integration_mse,
    l2_star_discrepancy, star_discrepancy_2d, wraparound_l2_discrepancy,
};

use crate::{BadInput, plot};

/// The exact star discrepancy is `O(n^2 log n)`: computed up to this `n`.
const MAX_EXACT_STAR: usize = 4096;
/// The L2 discrepancies are `O(n^2 d)`: computed up to this `n`.
const MAX_L2: usize = 1 << 16;

#[derive(Parser)]
pub struct PointsArgs {
    /// The generator: independent, stratified, lhs, cmj, halton,
    /// halton-owen, sobol, sobol-xor, sobol-owen, r2, poisson-disk or pmj02.
    #[arg(long, default_value = "sobol-owen", value_parser = parse_kind)]
    sampler: PointSetKind,
    /// Number of points.
    #[arg(short = 'n', long = "count", default_value_t = 1024)]
    count: usize,
    /// Dimensions per point.
    #[arg(short = 'd', long = "dim", default_value_t = 2)]
    dim: usize,
    /// Seed of the randomization (ignored by plain halton and sobol).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output file: .csv (a header, then one point per line) or .png (a
    /// plot of two dimensions, --dims). Without it and without --metrics,
    /// CSV goes to standard output.
    #[arg(long, short)]
    out: Option<PathBuf>,
    /// Print the discrepancies and the integration MSE of the Gaussian,
    /// Heaviside and disk integrands (2D, over randomizations seeded by
    /// --seed, at the same n).
    #[arg(long)]
    metrics: bool,
    /// The two dimensions the PNG plots, across and up.
    #[arg(long, num_args = 2, value_names = ["I", "J"], default_values_t = [0, 1])]
    dims: Vec<usize>,
    /// Randomizations averaged by the integration MSE.
    #[arg(long, default_value_t = 64)]
    randomizations: usize,
}

fn parse_kind(s: &str) -> Result<PointSetKind, String> {
    let kind = PointSetKind::from_name(s).filter(PointSetKind::is_point_set);
    kind.ok_or_else(|| {
        let all: Vec<_> = PointSetKind::point_sets().map(|k| k.name()).collect();
        let hint = if s.eq_ignore_ascii_case("zsobol") {
            " (zsobol orders samples across pixels: it exists only in the renderer)"
        } else {
            ""
        };
        format!(
            "unknown point set `{s}`{hint}; expected one of {}",
            all.join(", ")
        )
    })
}

/// What `--out` asks for, from its extension.
enum OutputFormat {
    Csv,
    Png,
}

fn output_format(path: &Path) -> Result<OutputFormat, BadInput> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("csv") => Ok(OutputFormat::Csv),
        Some("png") => Ok(OutputFormat::Png),
        _ => Err(BadInput(format!(
            "cannot tell the output format of {}: use a .csv or .png extension",
            path.display()
        ))),
    }
}

pub fn run_points(args: PointsArgs) -> Result<()> {
    if args.count == 0 {
        return Err(BadInput("-n must be at least 1".into()).into());
    }
    let format = args.out.as_deref().map(output_format).transpose()?;
    let (i, j) = (args.dims[0], args.dims[1]);
    if matches!(format, Some(OutputFormat::Png)) && args.dim < 2 {
        return Err(BadInput("a PNG plot needs at least 2 dimensions (-d 2)".into()).into());
    }
    if i == j || i.max(j) >= args.dim {
        return Err(BadInput(format!(
            "--dims {i} {j}: two different dimensions below -d {}",
            args.dim
        ))
        .into());
    }
    let points = generate(args.sampler, args.count, args.dim, args.seed)
        .map_err(|e| BadInput(e.to_string()))?;

    match (&args.out, format) {
        (Some(path), Some(OutputFormat::Csv)) => {
            write_atomically(path, |tmp| write_csv(tmp, &points))?;
            eprintln!(
                "wrote {} {} points of {} dimensions -> {}",
                points.len(),
                args.sampler,
                points.dim(),
                path.display()
            );
        }
        (Some(path), Some(OutputFormat::Png)) => {
            write_atomically(path, |tmp| plot::write_png(tmp, &points, i, j))?;
            eprintln!(
                "plotted dimensions {i} and {j} of {} {} points -> {}",
                points.len(),
                args.sampler,
                path.display()
            );
        }
        _ if !args.metrics => {
            let stdout = std::io::stdout();
            let mut out = std::io::BufWriter::new(stdout.lock());
            csv_lines(&mut out, &points).context("cannot write to standard output")?;
        }
        _ => {}
    }
    if args.metrics {
        print_metrics(&args, &points)?;
    }
    Ok(())
}

/// A header naming the dimensions (`x0,x1,...`), then one point per line,
/// coordinates separated by commas, each printed with the shortest decimal
/// that reads back to the same `f64`.
fn csv_lines(out: &mut impl Write, points: &PointSet) -> std::io::Result<()> {
    let header: Vec<String> = (0..points.dim()).map(|d| format!("x{d}")).collect();
    writeln!(out, "{}", header.join(","))?;
    for p in points.points() {
        let line: Vec<String> = p.iter().map(|x| x.to_string()).collect();
        writeln!(out, "{}", line.join(","))?;
    }
    out.flush()
}

fn write_csv(path: &Path, points: &PointSet) -> Result<()> {
    let file = std::fs::File::create(path)?;
    csv_lines(&mut std::io::BufWriter::new(file), points)?;
    Ok(())
}

/// Writes `path` as [`crate::output::write_atomically`] does (a failed write never leaves
/// a partial file under the asked name, nor a temporary one on an interrupt), naming the
/// file in the error.
fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    crate::output::write_atomically(path, write)
        .with_context(|| format!("cannot write {}", path.display()))
}

fn print_metrics(args: &PointsArgs, points: &PointSet) -> Result<()> {
    let (n, d) = (points.len(), points.dim());
    println!(
        "{} points, n = {n}, d = {d}, seed {}",
        args.sampler, args.seed
    );
    if n <= MAX_L2 {
        println!(
            "  L2-star discrepancy        {:.6e}",
            l2_star_discrepancy(points)
        );
        println!(
            "  centered L2 discrepancy    {:.6e}",
            centered_l2_discrepancy(points)
        );
        println!(
            "  wrap-around L2 discrepancy {:.6e}",
            wraparound_l2_discrepancy(points)
        );
    } else {
        println!("  L2 discrepancies           skipped (n > {MAX_L2}: O(n^2 d))");
    }
    if d == 2 && n <= MAX_EXACT_STAR {
        let star = star_discrepancy_2d(points).map_err(|e| BadInput(e.to_string()))?;
        println!("  star discrepancy (exact)   {star:.6e}");
    }
    println!(
        "integration MSE, 2D, n = {n}, {} randomizations:",
        args.randomizations
    );
    for &family in IntegrandFamily::ALL {
        let mse = integration_mse(args.sampler, family, n, args.randomizations, args.seed)
            .map_err(|e| BadInput(e.to_string()))?;
        println!("  {:<10} {mse:.6e}", family.name());
    }
    Ok(())
}
