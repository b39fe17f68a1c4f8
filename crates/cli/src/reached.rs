//! What a render reached, in words: every way a render ends (the spp cap,
//! the time budget, the error target, a signal) says the estimated relative
//! error it got to, and whether an error target was met.

use lueur_integrator::Film;

use crate::progressive::{Limits, Stop};

/// The lines to print once a render has stopped with `film` at `stop`;
/// `total` is the spp it was asked for (of its shard).
pub fn stop_report(stop: Stop, film: &Film, limits: &Limits, total: u32) -> Vec<String> {
    let error = film.relative_error();
    let spp = film.spp();
    let reached = if error.is_finite() {
        format!("estimated relative error {error:.4} at {spp} of {total} spp")
    } else {
        format!(
            "no relative error estimate at {spp} spp (it takes at least {} spp, one per replicate and two in all)",
            2.max(film.replicates())
        )
    };
    let mut lines = Vec::new();
    let why = match stop {
        Stop::TargetError(_) => {
            lines.push(format!(
                "target error reached: {reached} (target {})",
                limits.target_error.unwrap_or_default()
            ));
            return lines;
        }
        Stop::Complete => "the spp cap was reached",
        // The summary has said how much of the budget was used.
        Stop::TimeBudget => "the time budget ran out",
        Stop::Interrupted => {
            lines.push(format!("interrupted: {reached}"));
            "the render was interrupted"
        }
    };
    match limits.target_error {
        Some(target) => lines.push(format!(
            "target error {target} not reached: {reached}; {why}"
        )),
        None if matches!(stop, Stop::Complete | Stop::TimeBudget) => lines.push(reached),
        None => {}
    }
    lines
}
