//! Progressive rendering for the CLI: passes of 1, 1, 2, 4, ... samples per
//! pixel (pbrt's schedule), cut shorter to fit a time budget or a
//! partial-image interval (the dyadic film adds any range of samples
//! exactly), so the film holds a whole number of samples per pixel after
//! every pass and a render can stop there, on a time budget or an error
//! target. A signal stops it sooner, after the tiles in flight:
//! every finished tile is kept, so it loses no more than a tile per thread.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

use lueur_integrator::{
    Film, PixelBounds, PreparedScene, RenderOutput, RenderStats, render_pass_in,
};
use lueur_scene::RenderSettings;

/// Set by SIGINT, SIGTERM or SIGHUP: the current pass stops after the
/// tiles it finished.
static CANCEL: AtomicBool = AtomicBool::new(false);
/// Signals received so far; the second one exits at once.
static SIGNALS: AtomicUsize = AtomicUsize::new(0);

/// Exit status after an interrupt, as shells report SIGINT (128 + 2).
pub const EXIT_INTERRUPTED: u8 = 130;

/// Routes SIGINT, SIGTERM and SIGHUP to [`CANCEL`]; a second signal exits
/// immediately. Images are written to a temporary file and renamed, so even
/// that exit cannot leave a truncated image behind.
pub fn install_signal_handler() -> anyhow::Result<()> {
    ctrlc::set_handler(|| {
        if SIGNALS.fetch_add(1, Ordering::SeqCst) >= 1 {
            crate::bar::message("second interrupt: exiting without writing");
            crate::output::remove_temporaries();
            std::process::exit(i32::from(EXIT_INTERRUPTED));
        }
        CANCEL.store(true, Ordering::SeqCst);
        crate::bar::message("interrupt: writing the tiles rendered so far (again to exit now)");
    })?;
    Ok(())
}

/// When to stop before `spp` is reached.
#[derive(Clone, Copy, Debug, Default)]
pub struct Limits {
    /// Wall-clock budget in seconds: no pass starts that is predicted to
    /// end past it (the first pass always runs).
    pub time: Option<f64>,
    /// Stop once [`Film::relative_error`] is at most this.
    pub target_error: Option<f64>,
    /// Passes are cut to take about this long (for `--partial-every`,
    /// which writes the image between passes).
    pub pass_seconds: Option<f64>,
}

/// Why a render stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stop {
    /// All `spp` samples per pixel were rendered.
    Complete,
    /// A signal arrived; the film holds the passes completed before it, and
    /// the tiles of the next one that finished (it may be unfinished).
    Interrupted,
    /// The next pass would have ended past the time budget.
    TimeBudget,
    /// The relative error reached the target (the value reached).
    TargetError(f64),
}

/// Renders in passes until sample index `end` (`settings.spp`, or a
/// shard's end), a signal or a limit, the pixels `bounds` only.
///
/// Starts from `film` (empty, a resumed checkpoint, or an empty shard that
/// starts past 0) and calls `after_pass` with the film after every complete
/// pass (to checkpoint it).
#[allow(clippy::too_many_arguments)]
pub fn render(
    scene: &PreparedScene,
    settings: &RenderSettings,
    bounds: PixelBounds,
    mut film: Film,
    end: u32,
    limits: Limits,
    progress: &(dyn Fn(u64) + Sync),
    after_pass: &mut dyn FnMut(&Film) -> anyhow::Result<()>,
) -> anyhow::Result<(RenderOutput, Stop)> {
    let start = Instant::now();
    let mut stats = RenderStats::default();
    if film.samples().end >= end {
        return Ok((RenderOutput { film, stats }, Stop::Complete));
    }
    let resumed_at = film.spp();
    // pbrt's schedule: the first pass brings the film to 1 spp, each next
    // one doubles it.
    let mut until = film.samples().end + 1;
    loop {
        let pass_start = Instant::now();
        let pass_spp = f64::from(until - film.samples().end);
        let pass = render_pass_in(scene, settings, bounds, &mut film, until, &CANCEL, progress)?;
        stats.merge(&pass.stats);
        if !pass.complete {
            return Ok((RenderOutput { film, stats }, Stop::Interrupted));
        }
        let pass_secs = pass_start.elapsed().as_secs_f64();
        after_pass(&film)?;
        if film.samples().end >= end {
            return Ok((RenderOutput { film, stats }, Stop::Complete));
        }
        let done = film.spp();
        let elapsed = start.elapsed().as_secs_f64();
        // Seconds per spp: the render's average, or the last pass's if that
        // was slower (what the next pass is likeliest to cost).
        let per_spp = (elapsed / f64::from(done - resumed_at)).max(pass_secs / pass_spp);
        let mut size = done.max(1).min(end - film.samples().end);
        if let Some(budget) = limits.time {
            // The dyadic film takes passes of any size exactly: the last
            // one is cut to what is left of the budget.
            let fits = passes_that_fit(budget - elapsed, per_spp);
            if fits == 0 {
                return Ok((RenderOutput { film, stats }, Stop::TimeBudget));
            }
            size = size.min(fits);
        }
        if let Some(seconds) = limits.pass_seconds {
            size = size.min(passes_that_fit(seconds, per_spp).max(1));
        }
        if let Some(target) = limits.target_error {
            let reached = film.relative_error();
            if reached <= target {
                return Ok((RenderOutput { film, stats }, Stop::TargetError(reached)));
            }
        }
        until = film.samples().end + size;
    }
}

/// How many spp at `per_spp` seconds each fit in `seconds`.
fn passes_that_fit(seconds: f64, per_spp: f64) -> u32 {
    if !(seconds > 0.0) {
        return 0;
    }
    if !(per_spp > 0.0) {
        return u32::MAX;
    }
    (seconds / per_spp).floor().min(f64::from(u32::MAX)) as u32
}
