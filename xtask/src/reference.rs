//! High-spp reference images, rendered once and cached in `target/xtask/`.
//!
//! The cache key hashes the scene file's text, the image size, the spp and
//! every source file and manifest under `crates/`, so a reference is rebuilt
//! when the scene or the renderer changes, and never silently reused across
//! a change that could move the answer.

use std::hash::{DefaultHasher, Hash, Hasher};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use lueur::integrator::{Film, PreparedScene, render};
use lueur::sampling::SamplerKind;
use lueur::scene::SceneFile;
use lueur::scene::{RenderSettings, Strategy};

use crate::project_root;

/// A reference image: per-pixel mean and variance of the mean, RGB
/// interleaved, row-major.
pub struct Reference {
    pub mean: Vec<f32>,
    pub var_of_mean: Vec<f32>,
}

impl Reference {
    /// The reference's own noise: its variance of the mean averaged over
    /// pixels and channels. It adds to every squared error measured against
    /// the reference (its samples are independent of the image's), so
    /// [`Reference::mse`] takes it off.
    pub fn noise(&self) -> f64 {
        self.var_of_mean.iter().map(|&v| f64::from(v)).sum::<f64>() / self.var_of_mean.len() as f64
    }

    /// The mean squared error of `image` (RGB interleaved, the reference's
    /// size) against the reference, less the reference's own noise.
    pub fn mse(&self, image: &[f32]) -> f64 {
        squared_error(image, &self.mean) / image.len() as f64 - self.noise()
    }

    /// Mean over pixels and channels.
    pub fn image_mean(&self) -> f64 {
        self.mean.iter().map(|&v| f64::from(v)).sum::<f64>() / self.mean.len() as f64
    }
}

/// Where cached references and measurement files go.
pub fn cache_dir() -> Result<PathBuf> {
    let dir = project_root().join("target").join("xtask");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    Ok(dir)
}

/// Renders quietly; any NaN or infinite sample is an error here.
pub fn render_film(file: &SceneFile, settings: &RenderSettings) -> Result<(Film, f64)> {
    let out = render(&PreparedScene::new(file.scene.clone()), settings, &|_| {})?;
    anyhow::ensure!(
        out.stats.dropped_samples == 0,
        "{} NaN/Inf samples",
        out.stats.dropped_samples
    );
    Ok((out.film, out.stats.elapsed.as_secs_f64()))
}

/// The sum over pixels and channels of the squared difference of two
/// images, in `f64`.
pub fn squared_error(a: &[f32], b: &[f32]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(&x, &y)| (f64::from(x) - f64::from(y)).powi(2))
        .sum::<f64>()
}

/// RGB values of a film's mean image, interleaved.
pub fn flatten(img: &[glam::Vec3]) -> Vec<f32> {
    img.iter().flat_map(|c| c.to_array()).collect()
}

/// The `mis` reference of `scene` at `size` x `size` and `spp`, seed 0,
/// from the cache when its key matches.
pub fn reference(scene: &str, file: &SceneFile, size: u32, spp: u32) -> Result<Reference> {
    let text =
        std::fs::read_to_string(project_root().join("scenes").join(format!("{scene}.toml")))?;
    let mut h = DefaultHasher::new();
    (text, size, spp, source_fingerprint()?).hash(&mut h);
    let path = cache_dir()?.join(format!(
        "reference-{scene}-{size}px-{spp}spp-{:016x}.bin",
        h.finish()
    ));
    if let Ok(bytes) = std::fs::read(&path)
        && let Some(r) = decode(&bytes, size)
    {
        eprintln!("{scene}: reference from {}", path.display());
        return Ok(r);
    }
    eprintln!("{scene}: rendering the reference ({size}x{size}, {spp} spp)...");
    let settings = RenderSettings {
        width: size,
        height: size,
        spp,
        strategy: Strategy::Mis,
        sampler: SamplerKind::Independent,
        seed: 0,
        ..file.settings.clone()
    };
    let (film, secs) = render_film(file, &settings)?;
    eprintln!("{scene}: reference took {secs:.1} s");
    let r = Reference {
        mean: flatten(&film.mean_image()),
        var_of_mean: flatten(&film.variance_image()),
    };
    let bytes: Vec<u8> = r
        .mean
        .iter()
        .chain(&r.var_of_mean)
        .flat_map(|v| v.to_le_bytes())
        .collect();
    // Written whole then renamed, so an interrupted run leaves no torn cache.
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, &path)?;
    Ok(r)
}

fn decode(bytes: &[u8], size: u32) -> Option<Reference> {
    let n = 3 * size as usize * size as usize;
    if bytes.len() != 2 * 4 * n {
        return None;
    }
    let values: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    let (mean, var) = values.split_at(n);
    Some(Reference {
        mean: mean.to_vec(),
        var_of_mean: var.to_vec(),
    })
}

/// A hash of every source file and manifest of the renderer's crates.
fn source_fingerprint() -> Result<u64> {
    fn walk(dir: &Path, files: &mut Vec<PathBuf>) -> std::io::Result<()> {
        for entry in std::fs::read_dir(dir)? {
            let path = entry?.path();
            if path.is_dir() {
                walk(&path, files)?;
            } else if path
                .extension()
                .is_some_and(|e| e == "rs" || e == "toml" || e == "txt")
            {
                files.push(path);
            }
        }
        Ok(())
    }
    let mut files = Vec::new();
    walk(&project_root().join("crates"), &mut files)?;
    files.sort();
    let mut h = DefaultHasher::new();
    for f in files {
        f.strip_prefix(project_root()).unwrap_or(&f).hash(&mut h);
        std::fs::read(&f)?.hash(&mut h);
    }
    Ok(h.finish())
}
