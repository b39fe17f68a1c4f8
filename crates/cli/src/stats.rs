//! `lueur render --stats`: what a render measured about itself, as a table.

use lueur_integrator::{RenderOutput, STEP_BUCKETS, Stage};

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
    if let Some(level) = s.simd {
        println!(
            "ray streams on   {:>14}  ({} lanes)",
            level.name(),
            level.lanes()
        );
    }
    println!(
        "paths kept as    {:>14}",
        if s.lane_wave { "lanes" } else { "records" }
    );
    // Shares of the threads' time: tracing measured per stream of rays, the
    // film merge measured, the rest (camera rays, shading, sampling, the
    // point set, scheduling) by difference.
    let threads = s.threads.max(1);
    let tracing = s.rays.camera.tracing_seconds()
        + s.rays.bounce.tracing_seconds()
        + s.rays.shadow.tracing_seconds();
    let film = s.film_time.as_secs_f64();
    let shares = time_shares(secs * threads as f64, tracing, film);
    println!(
        "time on {threads} thread{}: tracing {:.0}%  shading, normals and sampling {:.0}%  film {:.1}%  (tracing timed per stream of rays)",
        if threads == 1 { "" } else { "s" },
        shares[0],
        shares[1],
        shares[2],
    );
    // The wave's stages, as shares of the same threads' time: the rest is tiles' setup
    // and the film.
    if s.stages.total_seconds() > 0.0 {
        let thread_secs = (secs * threads as f64).max(s.stages.total_seconds());
        let mut line = String::from("wave stages:");
        for stage in Stage::ALL {
            // As below: no shadow rays where the strategy casts none (`mixture`).
            if stage == Stage::ShadowRays && s.rays.shadow.rays == 0 {
                continue;
            }
            let share = 100.0 * s.stages.seconds(stage) / thread_secs;
            line.push_str(&format!("  {} {share:.1}%", stage.name()));
        }
        println!("{line}");
    }
    for (name, c) in [
        ("camera", &s.rays.camera),
        ("bounce", &s.rays.bounce),
        ("shadow", &s.rays.shadow),
    ] {
        // A strategy that never casts a kind of ray (no shadow rays under
        // `mixture`) gets no row of zeros.
        if c.rays == 0 {
            continue;
        }
        let rays = c.rays as f64;
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

/// The shares, in percent, of the threads' time spent tracing, on the rest
/// (by difference) and merging into the film, as printed (whole percents,
/// tenths for the film): they add up to 100 and none is negative. Tracing
/// is estimated from a sample of timed rays, so it can come out above the
/// time the threads had; the shares are then of the larger total.
fn time_shares(thread_secs: f64, tracing: f64, film: f64) -> [f64; 3] {
    let total = thread_secs.max(tracing + film).max(1e-12);
    let film = (1000.0 * film / total).round() / 10.0;
    let tracing = (100.0 * tracing / total).round().min(100.0 - film);
    [tracing, (100.0 - tracing - film).max(0.0), film]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_shares_add_to_100_and_never_exceed_it() {
        for (threads, tracing, film) in [
            (1.0, 1.19, 0.0),
            (1.0, 0.5, 0.25),
            (2.0, 0.0, 0.0),
            (1.0, 0.3333, 0.3333),
            (1.0, 0.996, 0.004),
        ] {
            let s = time_shares(threads, tracing, film);
            let sum: f64 = s.iter().sum();
            assert!((sum - 100.0).abs() < 1e-9, "{s:?}");
            assert!(s.iter().all(|&x| (0.0..=100.0).contains(&x)), "{s:?}");
        }
        assert_eq!(time_shares(1.0, 1.19, 0.0), [100.0, 0.0, 0.0]);
    }
}
