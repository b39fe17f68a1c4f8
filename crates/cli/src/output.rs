//! Writing images: atomically, so an interrupted write never leaves a
//! truncated file behind.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{Context, Result, bail};
use lueur_integrator::{Film, PixelEstimate};

use crate::provenance::Provenance;

/// Image formats, chosen by the output's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// 8-bit sRGB, clamped.
    Png,
    /// Linear 32-bit float RGB plus the variance of each pixel's mean.
    Exr,
}

impl Format {
    pub fn from_path(path: &Path) -> Result<Format> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png") => Ok(Format::Png),
            Some("exr") => Ok(Format::Exr),
            _ => bail!(
                "cannot tell the image format of {}: use a .png or .exr extension",
                path.display()
            ),
        }
    }
}

/// Writes the film's mean (and for EXR its variance) to `path`, with
/// `provenance` in its header (EXR attributes, PNG tEXt chunks).
pub fn write_image(
    path: &Path,
    format: Format,
    film: &Film,
    exposure: f32,
    provenance: &Provenance,
) -> Result<()> {
    write_atomically(path, |tmp| match format {
        Format::Png => write_png(tmp, film, exposure, provenance),
        Format::Exr => write_exr(tmp, film, provenance),
    })
}

/// Temporary files being written, for [`remove_temporaries`].
static WRITING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Runs `write` on a temporary file beside `path`, then renames it into
/// place: readers see the old file or the whole new one, never a torn one.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    write_atomically_in(&WRITING, path, write)
}

/// [`write_atomically`], the temporary file listed in `writing`.
fn write_atomically_in(
    writing: &Mutex<Vec<PathBuf>>,
    path: &Path,
    write: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    let tmp = temporary_path(path);
    let writing = || writing.lock().unwrap_or_else(|e| e.into_inner());
    writing().push(tmp.clone());
    let result = write(&tmp).and_then(|()| {
        std::fs::rename(&tmp, path)
            .with_context(|| format!("cannot move {} into place", tmp.display()))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    writing().retain(|p| *p != tmp);
    result
}

/// Removes the temporary files being written: a second interrupt exits in
/// the middle of a write, and must not leave one behind. (A rename that
/// races with this finds no file, and the target is left as it was.)
pub fn remove_temporaries() {
    remove_temporaries_in(&WRITING);
}

fn remove_temporaries_in(writing: &Mutex<Vec<PathBuf>>) {
    let writing = writing.lock().unwrap_or_else(|e| e.into_inner());
    for tmp in writing.iter() {
        let _ = std::fs::remove_file(tmp);
    }
}

/// The temporary file beside `path` that a write of `path` goes to.
pub fn temporary_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(|| "image".into(), |n| n.to_string_lossy().into_owned());
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

fn write_png(path: &Path, film: &Film, exposure: f32, provenance: &Provenance) -> Result<()> {
    // Through `png` itself: `image`'s encoder writes no text chunks.
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, film.width(), film.height());
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    for (key, value) in &provenance.0 {
        encoder.add_text_chunk(key.clone(), value.clone())?;
    }
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&film.srgb8(exposure))?;
    writer.finish()?;
    Ok(())
}

fn write_exr(path: &Path, film: &Film, provenance: &Provenance) -> Result<()> {
    use exr::prelude::*;
    // Pixels are read straight from the film's statistics as the writer
    // asks for them, so a 4K film is not copied into channel images first.
    let channels = SpecificChannels::build()
        .with_channel("R")
        .with_channel("G")
        .with_channel("B")
        .with_channel("variance.R")
        .with_channel("variance.G")
        .with_channel("variance.B")
        .with_pixel_fn(|pos: Vec2<usize>| {
            let p: PixelEstimate = film.pixel(pos.x() as u32, pos.y() as u32);
            let v = p.variance_of_mean();
            (p.mean.x, p.mean.y, p.mean.z, v.x, v.y, v.z)
        });
    let size = (film.width() as usize, film.height() as usize);
    let mut attributes = LayerAttributes::named("lueur");
    for (key, value) in &provenance.0 {
        let value = Text::new_or_none(value).context("provenance text is ASCII")?;
        attributes
            .other
            .insert(Text::from(key.as_str()), AttributeValue::Text(value));
    }
    let layer = Layer::new(size, attributes, Encoding::SMALL_LOSSLESS, channels);
    Image::from_layer(layer).write().to_file(path)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What a second interrupt does in the middle of a write: the
    /// temporary file goes, and the target is not created from it. On a list
    /// of its own, so as not to remove the files other tests are writing.
    #[test]
    fn an_exit_mid_write_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("i.png");
        let writing = Mutex::new(Vec::new());
        let result = write_atomically_in(&writing, &target, |tmp| {
            std::fs::write(tmp, b"half an image")?;
            remove_temporaries_in(&writing);
            Ok(())
        });
        assert!(result.is_err(), "the rename finds no file");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "{left:?}");
        // And a write that is not interrupted is not affected by the list.
        write_atomically_in(&writing, &target, |tmp| Ok(std::fs::write(tmp, b"whole")?)).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"whole");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
