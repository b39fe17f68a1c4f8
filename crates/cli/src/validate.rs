//! Checks on the files a command will write, made before the first sample:
//! a render that can only fail at its end (a missing directory, an unknown
//! extension) must fail at once, naming the flag, not after hours of work.

use std::path::{Path, PathBuf};

use crate::output::{self, Format};
use crate::{BadInput, RenderArgs};

/// The image a render writes and its format, and its checkpoint, all
/// checked: a shard's image is optional (`--out`); a whole render always
/// writes one, by default `SCENE_NAME.png` in the current directory.
pub fn render_outputs(args: &RenderArgs) -> Result<(Option<PathBuf>, Option<Format>), BadInput> {
    let out = match (&args.out, &args.sample_range) {
        (Some(p), _) => Some(p.clone()),
        (None, Some(_)) => None,
        (None, None) => Some(default_output(&args.scene)),
    };
    let format = out
        .as_deref()
        .map(|p| image_output("--out", p))
        .transpose()?;
    if let Some(path) = &args.checkpoint {
        checkpoint_output("--checkpoint", path)?;
        if let Some(out) = &out {
            distinct(("--out", out), ("--checkpoint", path))?;
        }
    }
    if let (Some(out), Some(resume)) = (&out, &args.resume) {
        distinct(("--out", out), ("--resume", resume))?;
    }
    Ok((out, format))
}

fn default_output(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "render".into(), |s| s.to_string_lossy().into_owned());
    PathBuf::from(format!("{stem}.png"))
}

/// Checks that `path`, given to `flag`, can receive an image: a `.png` or
/// `.exr` name in a directory that exists and accepts new files. Returns
/// its format.
pub fn image_output(flag: &str, path: &Path) -> Result<Format, BadInput> {
    not_a_directory(flag, path)?;
    let format = Format::from_path(path).map_err(|_| {
        BadInput(format!(
            "{flag} {}: unknown image format; use a .png or .exr extension",
            path.display()
        ))
    })?;
    writable(flag, path)?;
    Ok(format)
}

/// Checks that `path`, given to `flag`, can receive a checkpoint: an
/// OpenEXR file (`.exr`), in a directory that exists and accepts new files.
pub fn checkpoint_output(flag: &str, path: &Path) -> Result<(), BadInput> {
    not_a_directory(flag, path)?;
    if Format::from_path(path).ok() != Some(Format::Exr) {
        return Err(BadInput(format!(
            "{flag} {}: a checkpoint is an OpenEXR file; use a .exr extension",
            path.display()
        )));
    }
    writable(flag, path)
}

/// Checks that a file to read, given to `flag`, exists.
pub fn input(flag: &str, path: &Path) -> Result<(), BadInput> {
    if path.is_file() {
        Ok(())
    } else {
        Err(BadInput(format!("{flag} {}: no such file", path.display())))
    }
}

/// Refuses two flags that name one file: the second write would replace
/// the first.
pub fn distinct(a: (&str, &Path), b: (&str, &Path)) -> Result<(), BadInput> {
    let resolve = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    if resolve(a.1) == resolve(b.1) {
        return Err(BadInput(format!(
            "{} and {} both name {}: each needs its own file",
            a.0,
            b.0,
            a.1.display()
        )));
    }
    Ok(())
}

/// The directory exists, `path` is not a directory, and a file can be
/// created there: the very temporary file the write will use is created
/// and removed.
fn not_a_directory(flag: &str, path: &Path) -> Result<(), BadInput> {
    if path.is_dir() {
        return Err(BadInput(format!(
            "{flag} {}: is a directory",
            path.display()
        )));
    }
    Ok(())
}

fn writable(flag: &str, path: &Path) -> Result<(), BadInput> {
    let shown = path.display();
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(BadInput(format!(
            "{flag} {shown}: the directory {} does not exist",
            dir.display()
        )));
    }
    let probe = output::temporary_path(path);
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(BadInput(format!(
            "{flag} {shown}: cannot create files in {}: {e}",
            dir.display()
        ))),
    }
}

/// An error's message and its causes, each written once: an I/O error
/// wrapped by a library that repeats it in its own message is not printed
/// twice.
pub fn error_chain(e: &anyhow::Error) -> String {
    let mut message = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if message.contains(&text) {
            continue;
        }
        if !message.is_empty() {
            message.push_str(": ");
        }
        message.push_str(&text);
    }
    message
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_repeated_cause_is_written_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file");
        let e = anyhow::Error::new(io)
            .context("No such file")
            .context("cannot write x.exr");
        assert_eq!(error_chain(&e), "cannot write x.exr: No such file");
    }

    #[test]
    fn outputs_are_refused_by_flag_before_anything_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("no/such/dir/x.png");
        let e = image_output("--out", &missing).unwrap_err().0;
        assert!(
            e.starts_with("--out ") && e.contains("does not exist"),
            "{e}"
        );
        let e = image_output("--out", &dir.path().join("x.jpg"))
            .unwrap_err()
            .0;
        assert!(e.contains("use a .png or .exr"), "{e}");
        let e = checkpoint_output("--checkpoint", &dir.path().join("c.png"))
            .unwrap_err()
            .0;
        assert!(e.starts_with("--checkpoint") && e.contains(".exr"), "{e}");
        let e = image_output("--out", dir.path()).unwrap_err().0;
        assert!(e.contains("is a directory"), "{e}");
        assert_eq!(
            image_output("--out", &dir.path().join("x.EXR")).unwrap(),
            Format::Exr
        );
        checkpoint_output("--checkpoint", &dir.path().join("c.exr")).unwrap();
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "probes removed"
        );
    }
}
