//! `--reference REF.exr`: the error of a render against a converged image
//! after every pass, beside lueur's own estimate of it (like pbrt-v4's
//! `--mse-reference-image`), and `--reference-out FILE.csv`, one row per
//! pass: the speed-accuracy trade of one render, from the command line.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use exr::prelude::*;
use glam::Vec3;
use lueur_integrator::Film;

/// Added to the reference's square in the relative MSE's denominator, so
/// that black pixels do not dominate it (as in Rousselle et al. 2011).
const REL_MSE_EPSILON: f64 = 1e-2;

/// A reference image and where each pass's row goes.
pub struct Reference {
    pixels: Vec<Vec3>,
    start: Instant,
    csv: Option<(PathBuf, Vec<String>)>,
}

/// One pass's error against the reference, and lueur's estimate.
#[derive(Clone, Copy, Debug)]
pub struct PassError {
    pub mse: f64,
    pub rel_mse: f64,
    /// The mean reported variance of the pixel means: lueur's estimate of
    /// the MSE.
    pub estimated_mse: f64,
    pub estimated_relative_error: f64,
}

/// Reads `path` (an EXR with R, G, B channels) as the reference of a
/// `width` x `height` render. Every refusal names the flag and the file.
pub fn load(path: &Path, width: u32, height: u32, csv: Option<PathBuf>) -> Result<Reference> {
    let name = path.display();
    if !path.is_file() {
        bail!("--reference {name}: no such file");
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .specific_channels()
        .required::<f32>("R")
        .required::<f32>("G")
        .required::<f32>("B")
        .collect_pixels(
            |size: Vec2<usize>, _| (size, vec![Vec3::ZERO; size.area()]),
            |(size, px): &mut (Vec2<usize>, Vec<Vec3>),
             pos: Vec2<usize>,
             (r, g, b): (f32, f32, f32)| {
                px[pos.y() * size.width() + pos.x()] = Vec3::new(r, g, b);
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| anyhow::anyhow!("--reference {name} is not an RGB EXR image: {e}"))?;
    let (size, pixels) = image.layer_data.channel_data.pixels;
    if (size.width(), size.height()) != (width as usize, height as usize) {
        bail!(
            "--reference {name} is {}x{}, the render {width}x{height}",
            size.width(),
            size.height()
        );
    }
    if !pixels.iter().all(|p| p.is_finite()) {
        bail!("--reference {name} has NaN or infinite pixels");
    }
    Ok(Reference {
        pixels,
        start: Instant::now(),
        csv: csv.map(|p| {
            let header = "spp,seconds,mse,rel_mse,estimated_mse,estimated_relative_error";
            (p, vec![header.to_string()])
        }),
    })
}

impl Reference {
    /// The error of `film` against the reference.
    pub fn error(&self, film: &Film) -> PassError {
        let (mut mse, mut rel, mut est) = (0.0, 0.0, 0.0);
        for (p, r) in film.pixels().zip(&self.pixels) {
            for c in 0..3 {
                let d = f64::from(p.mean[c]) - f64::from(r[c]);
                mse += d * d;
                rel += d * d / (f64::from(r[c]).powi(2) + REL_MSE_EPSILON);
                est += f64::from(p.variance_of_mean()[c]);
            }
        }
        let n = 3.0 * self.pixels.len() as f64;
        PassError {
            mse: mse / n,
            rel_mse: rel / n,
            estimated_mse: est / n,
            estimated_relative_error: film.relative_error(),
        }
    }

    /// Records the pass that brought `film` to its spp; rewrites the CSV
    /// (atomically) with every row so far.
    pub fn after_pass(&mut self, film: &Film) -> Result<PassError> {
        let e = self.error(film);
        let seconds = self.start.elapsed().as_secs_f64();
        if let Some((path, rows)) = &mut self.csv {
            rows.push(format!(
                "{},{seconds:.4},{:e},{:e},{:e},{:e}",
                film.spp(),
                e.mse,
                e.rel_mse,
                e.estimated_mse,
                e.estimated_relative_error
            ));
            let text = rows.join("\n") + "\n";
            crate::output::write_atomically(path, |tmp| {
                std::fs::File::create(tmp)?.write_all(text.as_bytes())?;
                Ok(())
            })
            .with_context(|| format!("cannot write {}", path.display()))?;
        }
        Ok(e)
    }
}
