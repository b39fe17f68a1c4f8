//! `cargo xtask aarch64`: whether lueur built for aarch64 renders every shipped scene
//! bit for bit as this machine's build does, on each of its instruction sets (NEON and
//! scalar), run under qemu's user-mode emulation. The SIMD levels of one machine are
//! compared by the tests (`every_simd_level_and_wave_size_gives_the_same_image`); this
//! checks the other architecture lueur supports, which no CI machine here runs. With
//! `--tests`, it also runs the library tests there (slow: about half an hour).
//!
//! Needs the target's standard library, a cross linker and qemu:
//! `rustup target add aarch64-unknown-linux-gnu` and, on Debian,
//! `apt-get install gcc-aarch64-linux-gnu qemu-user`.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail, ensure};

use crate::identical::compare_builds;
use crate::memory::{build_lueur, cargo, target_dir};
use crate::project_root;
use crate::reference::cache_dir;

const TARGET: &str = "aarch64-unknown-linux-gnu";
const LINKER: &str = "aarch64-linux-gnu-gcc";
const QEMU: &str = "qemu-aarch64";
/// Where Debian's cross toolchain keeps the target's C library, which qemu loads the
/// binary's dynamic dependencies from.
const SYSROOT: &str = "/usr/aarch64-linux-gnu";
/// Cargo's settings for the target: its linker, and how it runs the target's tests.
const LINKER_VAR: &str = "CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER";
const RUNNER_VAR: &str = "CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUNNER";
/// The aarch64 levels compared with this machine's default one.
const LEVELS: [&str; 2] = ["neon", "scalar"];

pub fn run(tests: bool) -> Result<()> {
    prerequisites()?;
    let native = build_lueur()?;
    let cross = build_cross()?;
    let work = cache_dir()?.join("aarch64");
    std::fs::create_dir_all(&work).with_context(|| format!("creating {}", work.display()))?;
    // The emulated binary behind a path, as `compare_builds` runs a binary.
    let wrapper = work.join("lueur-aarch64");
    std::fs::write(
        &wrapper,
        format!(
            "#!/bin/sh\nexec {QEMU} -L {SYSROOT} '{}' \"$@\"\n",
            cross.display()
        ),
    )
    .with_context(|| format!("writing {}", wrapper.display()))?;
    make_executable(&wrapper)?;
    let variants: Vec<[&str; 2]> = LEVELS.iter().map(|level| ["--simd", level]).collect();
    let variants: Vec<&[&str]> = variants.iter().map(|v| v.as_slice()).collect();
    let (same, differ) = compare_builds(&native, &wrapper, &variants, &work.join("renders"))?;
    let total = same + differ;
    println!(
        "{same} of {total} aarch64 renders ({}, under {QEMU}) identical to this machine's",
        LEVELS.join(" and ")
    );
    if differ > 0 {
        bail!("{differ} of {total} aarch64 renders differ from this machine's");
    }
    if tests {
        run_tests()?;
    }
    Ok(())
}

/// Says what to install for whatever of the target, its linker and qemu is missing.
fn prerequisites() -> Result<()> {
    let mut missing = Vec::new();
    let libdir = Command::new("rustc")
        .args(["--print", "target-libdir", "--target", TARGET])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()));
    if !libdir.is_some_and(|dir| dir.is_dir()) {
        missing.push(format!("the target: rustup target add {TARGET}"));
    }
    for (program, package) in [(LINKER, "gcc-aarch64-linux-gnu"), (QEMU, "qemu-user")] {
        let runs = Command::new(program)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success());
        if !runs {
            missing.push(format!("{program}: apt-get install {package} (Debian)"));
        }
    }
    if !missing.is_empty() {
        bail!(
            "cargo xtask aarch64 needs what is not here:\n  {}",
            missing.join("\n  ")
        );
    }
    Ok(())
}

/// Builds `lueur` for the target (release) and returns its path.
fn build_cross() -> Result<PathBuf> {
    let target_dir = target_dir();
    let args = [
        "build",
        "--release",
        "--locked",
        "-p",
        "lueur-cli",
        "--target",
        TARGET,
    ];
    let shown = format!("{LINKER_VAR}={LINKER} cargo {}", args.join(" "));
    let status = cargo()
        .args(args)
        .current_dir(project_root())
        .env("CARGO_TARGET_DIR", &target_dir)
        .env(LINKER_VAR, LINKER)
        .status()
        .with_context(|| format!("cannot run {shown}"))?;
    ensure!(status.success(), "{shown} failed");
    let binary = target_dir.join(TARGET).join("release").join("lueur");
    ensure!(binary.is_file(), "{shown} made no {}", binary.display());
    Ok(binary)
}

/// Runs the workspace's tests built for the target under qemu, but the command line's:
/// they start `lueur` as a child process, which the runner does not wrap.
fn run_tests() -> Result<()> {
    let args = [
        "test",
        "--release",
        "--locked",
        "--workspace",
        "--exclude",
        "lueur-cli",
        "--target",
        TARGET,
    ];
    let runner = format!("{QEMU} -L {SYSROOT}");
    let shown = format!("{RUNNER_VAR}='{runner}' cargo {}", args.join(" "));
    let status = cargo()
        .args(args)
        .current_dir(project_root())
        .env(LINKER_VAR, LINKER)
        .env(RUNNER_VAR, &runner)
        .status()
        .with_context(|| format!("cannot run {shown}"))?;
    ensure!(status.success(), "{shown} failed");
    println!("the library tests pass on aarch64 (under {QEMU})");
    Ok(())
}

#[cfg(unix)]
fn make_executable(path: &Path) -> Result<()> {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755))
        .with_context(|| format!("making {} executable", path.display()))
}

#[cfg(not(unix))]
fn make_executable(_: &Path) -> Result<()> {
    bail!("cargo xtask aarch64 runs qemu's user-mode emulation, which needs Linux")
}
