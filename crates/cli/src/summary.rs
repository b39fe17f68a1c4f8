//! The lines a finished (or stopped) render prints: what it rendered, at
//! what speed, where it went, and why it stopped early.

use std::path::Path;

use lueur_integrator::RenderOutput;
use lueur_scene::RenderSettings;

use crate::RenderArgs;
use crate::progressive::{Limits, Stop};

/// Prints the summary of a render of `samples_asked` spp that stopped on
/// `stop` (an interrupt's own message is printed by the caller).
pub fn report(
    args: &RenderArgs,
    settings: &RenderSettings,
    output: &RenderOutput,
    stop: Stop,
    out: Option<&Path>,
    samples_asked: u32,
    limits: &Limits,
) {
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
    let destination = out.or(args.checkpoint.as_deref());
    let say = |text: String| {
        if !args.quiet {
            eprintln!("{text}");
        }
    };
    say(format!(
        "rendered {}x{} at {samples} ({}, {}) in {:.2} s, {:.2} M samples/s -> {}",
        output.film.width(),
        output.film.height(),
        settings.strategy,
        settings.sampler.name(),
        secs,
        stats.samples as f64 / secs.max(1e-9) / 1e6,
        destination.map_or_else(String::new, |p| p.display().to_string())
    ));
    if stats.dropped_samples > 0 {
        eprintln!(
            "warning: {} NaN or infinite samples were dropped",
            stats.dropped_samples
        );
    }
    if args.stats {
        crate::stats::print_stats(output);
    }
    if stop == Stop::TimeBudget {
        let budget = args.time.unwrap_or_default();
        say(format!(
            "time budget of {budget} s: used {secs:.2} s ({:.0}%), stopped at {} of {} spp",
            100.0 * secs / budget,
            output.film.spp(),
            samples_asked
        ));
    }
    for line in crate::reached::stop_report(stop, &output.film, limits, samples_asked) {
        say(line);
    }
}
