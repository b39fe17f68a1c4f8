//! `--partial-every SECONDS`: the output image written while the render
//! runs (as pbrt-v4's `--write-partial-images`), so that a viewer that
//! reloads it (tev, most image viewers) shows the render progress. Each
//! write is atomic, so a viewer never reads a torn file.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use lueur_integrator::Film;

use crate::output::{self, Format};
use crate::provenance::Provenance;

/// When and where the partial images go.
pub struct Partial {
    every: Duration,
    last: Instant,
    out: PathBuf,
    format: Format,
    exposure: f32,
}

impl Partial {
    /// Writes to `out` at most every `seconds` (the first write one
    /// interval after the start).
    pub fn new(seconds: f64, out: PathBuf, format: Format, exposure: f32) -> Partial {
        Partial {
            every: Duration::from_secs_f64(seconds),
            last: Instant::now(),
            out,
            format,
            exposure,
        }
    }

    /// Called after every complete pass: writes the image if the interval
    /// has passed since the last write.
    pub fn after_pass(
        &mut self,
        film: &Film,
        provenance: impl FnOnce() -> Provenance,
    ) -> Result<()> {
        if self.last.elapsed() < self.every {
            return Ok(());
        }
        output::write_image(&self.out, self.format, film, self.exposure, &provenance())
            .with_context(|| format!("cannot write {}", self.out.display()))?;
        self.last = Instant::now();
        Ok(())
    }
}
