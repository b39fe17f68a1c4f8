//! The progress bar: the share of the samples rendered, or, under a time
//! budget, of the budget spent (whichever is further), so that the ETA is
//! the time the render will really take. Messages printed while it is
//! drawn (a signal's) go above it, and it is cleared at the end.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

/// Steps of the bar: its position is a share of the work in these units.
const STEPS: u64 = 10_000;

/// The bar being drawn, for [`message`] (the signal handler's thread has
/// no other way to it).
static DRAWN: OnceLock<ProgressBar> = OnceLock::new();

/// Progress of one render.
pub struct Bar {
    bar: ProgressBar,
    /// Pixel samples to render, and rendered so far.
    total: u64,
    done: AtomicU64,
    /// The time budget in seconds, counted from `start`.
    budget: Option<f64>,
    start: Instant,
}

impl Bar {
    /// A bar for `total` pixel samples, `already` of them done (a resume),
    /// under an optional time budget; drawn only on a terminal, never when
    /// `quiet`.
    pub fn new(total: u64, already: u64, budget: Option<f64>, quiet: bool) -> Bar {
        let bar = if quiet {
            ProgressBar::hidden()
        } else {
            ProgressBar::new(STEPS)
        };
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {wide_bar} {percent}% ETA {eta}",
            )
            .expect("the template is valid"),
        );
        if !quiet {
            let _ = DRAWN.set(bar.clone());
        }
        let b = Bar {
            bar,
            total: total.max(1),
            done: AtomicU64::new(already),
            budget,
            start: Instant::now(),
        };
        b.add(0);
        b
    }

    /// Counts `n` more pixel samples rendered.
    pub fn add(&self, n: u64) {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        let mut share = done as f64 / self.total as f64;
        if let Some(budget) = self.budget {
            share = share.max(self.start.elapsed().as_secs_f64() / budget);
        }
        self.bar
            .set_position((share.min(1.0) * STEPS as f64) as u64);
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// Prints `text` on standard error, above the bar if one is drawn.
pub fn message(text: &str) {
    match DRAWN.get() {
        Some(bar) if !bar.is_finished() => bar.suspend(|| eprintln!("{text}")),
        _ => eprintln!("{text}"),
    }
}
