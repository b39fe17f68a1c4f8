//! Mitsuba 3, run through `xtask/peers/mitsuba_render.py` with the machine's `python3`:
//! whether it is installed, its version, one render of a lueur scene file, and a cached
//! reference of many. A peer for the reports (`peers`, `speed`) only, never a dependency
//! of lueur.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use lueur::scene::SceneFile;

use crate::project_root;

const LLVM19: &str = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1";

/// `python3` (or `$LUEUR_PYTHON`), with `DRJIT_LIBLLVM_PATH` pointing at
/// Debian's libLLVM 19 when it is there and the variable is unset.
pub fn python() -> Command {
    let mut c = Command::new(std::env::var("LUEUR_PYTHON").unwrap_or_else(|_| "python3".into()));
    if std::env::var_os("DRJIT_LIBLLVM_PATH").is_none() && Path::new(LLVM19).exists() {
        c.env("DRJIT_LIBLLVM_PATH", LLVM19);
    }
    c
}

fn script() -> PathBuf {
    project_root()
        .join("xtask")
        .join("peers")
        .join("mitsuba_render.py")
}

/// Runs the Mitsuba script on the scene file at `path`, parsed as `file`.
pub fn run_script(path: &Path, file: &SceneFile, args: &[String]) -> Result<HashMap<String, f64>> {
    // Mitsuba's `rr_depth` and lueur's `roulette_depth` both count scattering events
    // before roulette may end a path: the same number runs the same estimator. One
    // bounce more of full survival costs Mitsuba 5-7% more time and saves it about a
    // sixth of its MSE (docs/PERFORMANCE.md, "Where the MSE gap is").
    let roulette_depth = file.settings.roulette_depth;
    let out = python()
        .arg(script())
        .arg(path)
        .args(args)
        .args(["--rr-depth".to_owned(), roulette_depth.to_string()])
        .output()
        .context("cannot run python3")?;
    if !out.status.success() {
        bail!(
            "mitsuba_render.py {} {}: {}",
            path.display(),
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    Ok(String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|line| {
            let (key, value) = line.split_once(' ')?;
            Some((key.to_owned(), value.trim().parse().ok()?))
        })
        .collect())
}

/// A Mitsuba reference of a scene file: `passes` renders of `pass_spp` at `size` squared.
pub struct Shot {
    pub path: PathBuf,
    pub size: u32,
    pub passes: u32,
    pub pass_spp: u32,
}

impl Shot {
    /// Renders the reference into `reference_path` (and its variance beside it) unless a
    /// render of the same scene text, plan and Mitsuba version is there; returns the path
    /// and the seconds it took (NaN when cached).
    pub fn reference(&self, file: &SceneFile, reference_path: &Path) -> Result<(PathBuf, f64)> {
        eprintln!(
            "reference: Mitsuba llvm_ad_rgb, {} passes of {} spp, {}",
            self.passes,
            self.pass_spp,
            self.path.display()
        );
        let args: Vec<String> = vec![
            "llvm_ad_rgb".into(),
            self.pass_spp.to_string(),
            reference_path.display().to_string(),
            "--passes".into(),
            self.passes.to_string(),
            "--seed".into(),
            "100000".into(),
            "--width".into(),
            self.size.to_string(),
            "--height".into(),
            self.size.to_string(),
        ];
        let key = format!(
            "{}\n{} {} {}\n{}",
            std::fs::read_to_string(&self.path)?,
            self.size,
            self.passes,
            self.pass_spp,
            version()
        );
        let key_path = reference_path.with_extension("key");
        let cached = std::fs::read_to_string(&key_path).is_ok_and(|k| k == key)
            && reference_path.with_extension("var.exr").exists();
        let reference_time = if cached {
            eprintln!("reference: cached in {}", reference_path.display());
            f64::NAN
        } else {
            let t = (run_script(&self.path, file, &args)?.get("total_s"))
                .copied()
                .unwrap_or(f64::NAN);
            std::fs::write(&key_path, &key)?;
            t
        };
        Ok((reference_path.to_path_buf(), reference_time))
    }
}

/// Whether `python()` can import Mitsuba 3, and numpy, which `mitsuba_render.py`'s
/// multi-pass renders need.
pub fn installed() -> Result<bool> {
    let check = python()
        .args(["-c", "import mitsuba, numpy"])
        .output()
        .context("cannot run python3")?;
    Ok(check.status.success())
}

/// Mitsuba's version as Python reports it ("3" when it cannot say).
pub fn version() -> String {
    python()
        .args(["-c", "import mitsuba; print(mitsuba.__version__)"])
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
        .unwrap_or_else(|| "3".into())
}
