//! `lueur render --stats`: what a render measured about itself, as a table.

use lueur_integrator::{RenderOutput, STEP_BUCKETS};

/// Prints the statistics of a finished render to standard output.
pub fn print_stats(out: &RenderOutput) {
    let s = &out.stats;
    let secs = s.elapsed.as_secs_f64().max(1e-9);
    println!(
        "samples          {:>14}  ({:.3} M/s)",
        s.samples,
        s.samples as f64 / secs / 1e6
    );
    println!("dropped (NaN/Inf){:>14}", s.dropped_samples);
    // Shares of the threads' time: tracing estimated from every 16th ray
    // (timed), the film merge measured, the rest (camera rays, shading,
    // sampling, the point set, scheduling) by difference.
    let thread_secs = secs * s.threads.max(1) as f64;
    let tracing = s.rays.camera.tracing_seconds()
        + s.rays.bounce.tracing_seconds()
        + s.rays.shadow.tracing_seconds();
    let film = s.film_time.as_secs_f64();
    let share = |x: f64| 100.0 * x / thread_secs;
    println!(
        "time on {} threads: tracing {:.0}%  shading, normals and sampling {:.0}%  film {:.1}%  (tracing timed on 1 ray in {})",
        s.threads.max(1),
        share(tracing),
        share((thread_secs - tracing - film).max(0.0)),
        share(film),
        lueur_integrator::TIMED_EVERY,
    );
    for (name, c) in [
        ("camera", &s.rays.camera),
        ("bounce", &s.rays.bounce),
        ("shadow", &s.rays.shadow),
    ] {
        let rays = c.rays.max(1) as f64;
        println!(
            "{name:<7} rays {:>12}  ({:.3} M/s)  steps/ray {:>6.1}  hit {:>5.1}%  miss {:>5.1}%  gave up {:>5.2}%",
            c.rays,
            c.rays as f64 / secs / 1e6,
            c.steps as f64 / rays,
            100.0 * c.hits as f64 / rays,
            100.0 * c.misses as f64 / rays,
            100.0 * c.gave_up as f64 / rays,
        );
        // Steps per ray as a histogram in powers of two: where the marching
        // budget goes (a long tail means grazing rays near surfaces).
        let mut line = String::from("        steps/ray");
        for (i, &count) in c.steps_histogram.iter().enumerate() {
            let label = match i {
                0 => "1".to_string(),
                i if i == STEP_BUCKETS - 1 => format!("{}+", 1u32 << i),
                i => format!("{}-{}", 1u32 << i, (2u32 << i) - 1),
            };
            line.push_str(&format!("  {label}: {:.1}%", 100.0 * count as f64 / rays));
        }
        println!("{line}");
    }
}
