//! Progressive rendering for the CLI: passes of 1, 1, 2, 4, ... samples per
//! pixel (pbrt's schedule), none after the first shorter than
//! [`SHORTEST_PASS_SECONDS`] where a render is fast, cut shorter to fit a time budget
//! or a partial-image interval (the dyadic film adds any range of samples
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
    /// Whether the film is read after every pass (`--target-error`, `--reference`,
    /// `--checkpoint`): the passes then keep pbrt's schedule, each doubling the film,
    /// rather than merging those too short to pay for themselves.
    pub watched: bool,
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
    // one doubles it (or takes at least `SHORTEST_PASS_SECONDS`).
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
        let rest = end - film.samples().end;
        let Some(size) = next_pass(done, rest, per_spp, elapsed, limits) else {
            return Ok((RenderOutput { film, stats }, Stop::TimeBudget));
        };
        if let Some(target) = limits.target_error {
            let reached = film.relative_error();
            if reached <= target {
                return Ok((RenderOutput { film, stats }, Stop::TargetError(reached)));
            }
        }
        until = film.samples().end + size;
    }
}

/// The spp of the next pass, after `done` spp per pixel with `rest` to go, at `per_spp`
/// seconds each, `elapsed` seconds into the render; `None` where the time budget has no
/// room for another. The schedule doubles the film, takes at least
/// [`shortest_pass`] (and all that is left where less than that would be), and is cut to
/// the time budget's room and to the partial-image interval.
fn next_pass(done: u32, rest: u32, per_spp: f64, elapsed: f64, limits: Limits) -> Option<u32> {
    let shortest = shortest_pass(limits, per_spp);
    let mut size = done.max(1).max(shortest).min(rest);
    if rest - size < shortest {
        // What would be left is shorter than a pass worth its costs: take it now.
        size = rest;
    }
    if let Some(budget) = limits.time {
        // The dyadic film takes passes of any size exactly: the last
        // one is cut to what is left of the budget.
        let fits = passes_that_fit(budget - elapsed, per_spp);
        if fits == 0 {
            return None;
        }
        size = size.min(fits);
    }
    if let Some(seconds) = limits.pass_seconds {
        size = size.min(passes_that_fit(seconds, per_spp).max(1));
    }
    Some(size)
}

/// The shortest pass worth its fixed costs, in seconds. A pass ends when its last tile
/// does, its tiles are committed to the film one by one, and a tile of a pass of a few
/// spp holds a wave or two of paths, whose streams run thin as they drain. At 128x128 on
/// 2 threads, 64 spp in the passes 1, 1, 2, 4, 8, 16, 32 took about 2-3% longer than in
/// 1 and 63; a floor of 0.1 s (passes 1, 12, 17, 34) bought nothing measurable
/// (docs/PERFORMANCE.md, "Passes too short to pay for themselves").
const SHORTEST_PASS_SECONDS: f64 = 0.3;

/// The fewest spp the next pass takes, at `per_spp` seconds each: as many as fill
/// [`SHORTEST_PASS_SECONDS`], so that a fast render is not cut into passes of a few
/// milliseconds; none where the film is read between passes ([`Limits::watched`]), which
/// wants them as the schedule has them. A render longer than that per spp keeps the
/// schedule.
fn shortest_pass(limits: Limits, per_spp: f64) -> u32 {
    if limits.watched {
        return 0;
    }
    passes_that_fit(SHORTEST_PASS_SECONDS, per_spp)
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

#[cfg(test)]
mod tests {
    use super::*;

    const NONE: Limits = Limits {
        time: None,
        target_error: None,
        pass_seconds: None,
        watched: false,
    };

    /// A render whose spp take milliseconds is not cut into passes of milliseconds; one
    /// whose spp take a second keeps pbrt's doubling.
    #[test]
    fn fast_renders_take_passes_worth_their_costs() {
        // 5 ms an spp: what is left after the first pass is shorter than a pass.
        assert_eq!(next_pass(1, 63, 0.005, 0.005, NONE), Some(63));
        // 3/128 s an spp (exact in binary, so the floor of 0.3 / it is not a rounding
        // away from another count): 12 spp fill the shortest pass.
        assert_eq!(next_pass(1, 63, 0.0234375, 0.0234375, NONE), Some(12));
        assert_eq!(next_pass(11, 53, 0.03, 0.33, NONE), Some(11));
        // What a doubling would leave (5 spp, 0.15 s) is taken with it.
        assert_eq!(next_pass(20, 25, 0.03, 0.6, NONE), Some(25));
        // A second an spp: the schedule as it was.
        assert_eq!(next_pass(1, 63, 1.0, 1.0, NONE), Some(1));
        assert_eq!(next_pass(4, 60, 1.0, 4.0, NONE), Some(4));
        assert_eq!(next_pass(32, 32, 1.0, 32.0, NONE), Some(32));
    }

    /// A film read between passes (a target error, a reference, a checkpoint) keeps them
    /// as the schedule has them.
    #[test]
    fn a_watched_film_keeps_the_doubling() {
        let limits = Limits {
            watched: true,
            ..NONE
        };
        assert_eq!(next_pass(1, 63, 0.005, 0.005, limits), Some(1));
        assert_eq!(next_pass(8, 56, 0.005, 0.04, limits), Some(8));
    }

    /// The time budget and the partial-image interval cut the pass; a budget spent stops.
    #[test]
    fn limits_cut_the_pass() {
        let budget = Limits {
            time: Some(0.1),
            ..NONE
        };
        // 0.05 s left at 5 ms an spp: 10 spp.
        assert_eq!(next_pass(1, 63, 0.005, 0.05, budget), Some(10));
        assert_eq!(next_pass(1, 63, 0.005, 0.1, budget), None);
        let partial = Limits {
            pass_seconds: Some(0.02),
            ..NONE
        };
        assert_eq!(next_pass(1, 63, 0.005, 0.005, partial), Some(4));
        // At least one spp, however long one takes.
        assert_eq!(next_pass(1, 63, 1.0, 1.0, partial), Some(1));
    }
}
