//! The other renderer of the reports that compare two builds (`speed`,
//! `identical`): a `lueur` binary given as `--old PATH`, or one built from a
//! commit, `--old-rev REV`, so that a comparison can be rerun from a clean
//! clone.
//!
//! A revision is exported with `git archive` rather than checked out as a
//! worktree, so the repository's own state (its worktree list, its index) is
//! left alone, and it is built with its own lockfile (`--locked`) in its own
//! target directory: the old build never shares artifacts, features or
//! dependency versions with this tree's. The binary is kept under
//! `target/xtask/old/COMMIT/`, so a second report against the same commit
//! builds nothing.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use anyhow::{Context, Result, bail, ensure};

use crate::memory::{Build, build_lueur_from};
use crate::project_root;
use crate::reference::cache_dir;

/// The old renderer and how a report names it.
pub struct Old {
    pub binary: PathBuf,
    /// The flag that reproduces it: `--old PATH` or `--old-rev REV`.
    pub flag: String,
    /// What it is, for a report: the path, or the commit it was built from.
    pub description: String,
}

/// The old renderer of `--old PATH` or `--old-rev REV` (at most one is
/// given; clap enforces it), built as `build` says if it is a revision.
pub fn resolve(path: Option<&Path>, rev: Option<&str>, build: Build) -> Result<Option<Old>> {
    match (path, rev) {
        (Some(path), _) => {
            let binary = std::fs::canonicalize(path)
                .with_context(|| format!("--old {}: no such binary", path.display()))?;
            Ok(Some(Old {
                flag: format!("--old {}", binary.display()),
                description: format!("`{}`", binary.display()),
                binary,
            }))
        }
        (None, Some(rev)) => {
            let commit = commit_of(rev)?;
            let binary = build_at(&commit, build)?;
            Ok(Some(Old {
                binary,
                flag: format!("--old-rev {rev}"),
                description: format!(
                    "built from `{rev}` (commit {}) by `--old-rev`, with {}",
                    &commit[..12],
                    build.describe()
                ),
            }))
        }
        (None, None) => Ok(None),
    }
}

/// The full hash of the commit `rev` names.
fn commit_of(rev: &str) -> Result<String> {
    let out = Command::new("git")
        .args([
            "rev-parse",
            "--verify",
            "--quiet",
            &format!("{rev}^{{commit}}"),
        ])
        .current_dir(project_root())
        .output()
        .context("cannot run git")?;
    ensure!(
        out.status.success(),
        "--old-rev {rev}: not a commit of this repository"
    );
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_owned())
}

/// Builds `lueur` at `commit` as `build` says (once; later calls find the binary) and
/// returns its path.
fn build_at(commit: &str, build: Build) -> Result<PathBuf> {
    let dir = cache_dir()?.join("old").join(&commit[..12]);
    let binary = dir.join("target").join(build.dir()).join("lueur");
    if binary.is_file() {
        eprintln!("old renderer: {} (built before)", binary.display());
        return Ok(binary);
    }
    let source = dir.join("source");
    if source.exists() {
        std::fs::remove_dir_all(&source)
            .with_context(|| format!("removing {}", source.display()))?;
    }
    std::fs::create_dir_all(&source).with_context(|| format!("creating {}", source.display()))?;
    export(commit, &source)?;
    eprintln!(
        "old renderer: building commit {} in {} (a full build, {})",
        &commit[..12],
        dir.display(),
        build.describe()
    );
    build_lueur_from(&source, &dir.join("target"), build, &["--locked"])
        .with_context(|| format!("building commit {commit}"))
}

/// Writes the tree of `commit` into `into`: `git archive` piped to `tar`.
fn export(commit: &str, into: &Path) -> Result<()> {
    let mut archive = Command::new("git")
        .args(["archive", "--format=tar", commit])
        .current_dir(project_root())
        .stdout(Stdio::piped())
        .spawn()
        .context("cannot run git archive")?;
    let stdout = archive.stdout.take().context("git archive's output")?;
    let tar = Command::new("tar")
        .args(["-x", "-f", "-", "-C"])
        .arg(into)
        .stdin(stdout)
        .status()
        .context("cannot run tar")?;
    let archived = archive.wait().context("git archive")?;
    if !archived.success() || !tar.success() {
        bail!(
            "exporting commit {commit} into {} failed (git archive: {archived}, tar: {tar})",
            into.display()
        );
    }
    Ok(())
}
