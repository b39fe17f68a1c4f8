//! Renders cut into shards, by hand and by the scripts in `scripts/`, merge
//! into the bit-identical image of one render.

mod common;

use common::{exr_pixels, stderr};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const LUEUR: &str = env!("CARGO_BIN_EXE_lueur");

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn donut() -> String {
    repo()
        .join("scenes/donut-mirrors.toml")
        .display()
        .to_string()
}

/// A small image, odd-sized so tiles are cut at the edges.
const SMALL: [&str; 4] = ["--width", "13", "--height", "9"];

fn lueur(args: &[&str], dir: &Path) -> Output {
    Command::new(LUEUR)
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn render(dir: &Path, extra: &[&str]) {
    let scene = donut();
    let mut args = vec!["render", scene.as_str()];
    args.extend_from_slice(&SMALL);
    args.extend_from_slice(extra);
    let o = lueur(&args, dir);
    assert!(o.status.success(), "{:?}: {}", args, stderr(&o));
}

fn read(dir: &Path, name: &str) -> Vec<u8> {
    std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Shards at any cut (not only powers of two), merged in any order, give
/// the EXR (mean and variance, f32) of one render byte for byte; and the
/// merged film, resumed, still follows the uninterrupted render exactly.
#[test]
fn shards_merge_into_the_bit_identical_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(d, &["--spp", "24", "--out", "whole.exr"]);
    render(d, &["--spp", "13", "--out", "whole13.exr"]);
    for (range, file) in [("0..5", "a.exr"), ("5..13", "b.exr"), ("13..24", "c.exr")] {
        render(
            d,
            &["--spp", "24", "--sample-range", range, "--checkpoint", file],
        );
    }
    let o = lueur(
        &["merge", "c.exr", "a.exr", "b.exr", "--out", "merged.exr"],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("merged 3 shards: samples 0..24"),
        "{}",
        stderr(&o)
    );
    assert!(exr_pixels(&d.join("whole.exr")) == exr_pixels(&d.join("merged.exr")));

    // Two shards of the three are refused, naming the missing samples...
    let o = lueur(&["merge", "a.exr", "b.exr", "-o", "ab.png"], d);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("missing 13..24"), "{}", stderr(&o));
    assert!(!d.join("ab.png").exists());
    // ... unless asked for: merged and saved, then resumed past them.
    let o = lueur(
        &[
            "merge",
            "a.exr",
            "b.exr",
            "--allow-partial",
            "-o",
            "ab.png",
            "--checkpoint",
            "ab.exr",
        ],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    render(
        d,
        &["--spp", "13", "--out", "ab13.exr", "--resume", "ab.exr"],
    );
    assert!(exr_pixels(&d.join("whole13.exr")) == exr_pixels(&d.join("ab13.exr")));
    render(
        d,
        &["--spp", "24", "--out", "ab24.exr", "--resume", "ab.exr"],
    );
    assert!(exr_pixels(&d.join("whole.exr")) == exr_pixels(&d.join("ab24.exr")));
}

#[test]
fn bad_shards_are_refused_with_the_files_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(
        d,
        &[
            "--spp",
            "8",
            "--sample-range",
            "0..4",
            "--checkpoint",
            "a.exr",
        ],
    );
    render(
        d,
        &[
            "--spp",
            "8",
            "--sample-range",
            "5..8",
            "--checkpoint",
            "gap.exr",
        ],
    );
    render(
        d,
        &[
            "--spp",
            "8",
            "--sample-range",
            "4..8",
            "--seed",
            "9",
            "--checkpoint",
            "seed.exr",
        ],
    );
    let refused = |args: &[&str], says: &str| {
        let o = lueur(args, d);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
        assert!(!d.join("m.png").exists(), "nothing written");
    };
    refused(
        &["merge", "a.exr", "gap.exr", "-o", "m.png"],
        "a.exr holds samples 0..4",
    );
    refused(
        &["merge", "a.exr", "a.exr", "-o", "m.png"],
        "without gap or overlap",
    );
    refused(
        &["merge", "a.exr", "seed.exr", "-o", "m.png"],
        "different settings",
    );
    refused(
        &["merge", "a.exr", "nowhere.exr", "-o", "m.png"],
        "nowhere.exr",
    );
    // An image is not a film state; neither is a file that is not an EXR.
    render(d, &["--spp", "8", "--out", "image.exr"]);
    refused(
        &["merge", "a.exr", "image.exr", "-o", "m.png"],
        "not a lueur checkpoint",
    );
    std::fs::write(d.join("junk.exr"), b"not an exr").unwrap();
    refused(
        &["merge", "junk.exr", "-o", "m.png"],
        "cannot read checkpoint junk.exr",
    );
    let scene = donut();
    refused(
        &[
            "render",
            &scene,
            "--spp",
            "8",
            "--sample-range",
            "0..9",
            "--checkpoint",
            "x.exr",
        ],
        "ends past the render's 8 spp",
    );
    refused(
        &["render", &scene, "--spp", "8", "--sample-range", "0..4"],
        "--checkpoint",
    );
    // A stratified pattern is laid out over the total spp, so shards of
    // different totals do not add up.
    for (spp, file) in [("8", "s8.exr"), ("16", "s16.exr")] {
        render(
            d,
            &[
                "--spp",
                spp,
                "--sampler",
                "stratified",
                "--sample-range",
                "0..4",
                "--checkpoint",
                file,
            ],
        );
    }
    render(
        d,
        &[
            "--spp",
            "16",
            "--sampler",
            "stratified",
            "--sample-range",
            "4..8",
            "--checkpoint",
            "t.exr",
        ],
    );
    refused(
        &["merge", "s8.exr", "t.exr", "-o", "m.png"],
        "different settings",
    );
    let o = lueur(
        &[
            "merge",
            "s16.exr",
            "t.exr",
            "--allow-partial",
            "-o",
            "ok.png",
        ],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Runs `scripts/SCRIPT ARGS` in `dir` with `LUEUR` set to the binary
/// under test and `bin` (if any) first on PATH.
fn bash(script: &str, args: &[&str], dir: &Path, bin: Option<&Path>) -> Output {
    let mut cmd = Command::new("bash");
    cmd.arg(repo().join("scripts").join(script))
        .args(args)
        .env("LUEUR", LUEUR)
        .env("SBATCH_LOG", dir.join("sbatch.log"))
        .current_dir(dir);
    if let Some(bin) = bin {
        let old = std::env::var("PATH").unwrap_or_default();
        cmd.env("PATH", format!("{}:{old}", bin.display()));
    }
    cmd.output().unwrap()
}

/// The documented one-machine recipe, run as the README shows it.
#[test]
fn the_local_shard_script_gives_the_one_render_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(d, &["--spp", "12", "--out", "whole.exr"]);
    let scene = donut();
    let mut args = vec![scene.as_str(), "12", "3", "sharded.exr"];
    args.extend_from_slice(&SMALL);
    let o = bash("render-shards.sh", &args, d, None);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(exr_pixels(&d.join("whole.exr")) == exr_pixels(&d.join("sharded.exr")));
    assert!(!d.join("sharded.exr.shards").exists(), "shards cleaned up");
}

/// The documented Slurm recipe, with a stand-in `sbatch` that runs each job
/// at once (an array job once per index, with SLURM_ARRAY_TASK_ID set), so
/// the script's submit, task and merge modes all run as on a cluster.
#[cfg(unix)]
#[test]
fn the_slurm_script_gives_the_one_render_image() {
    use std::os::unix::fs::PermissionsExt;

    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bin = d.join("bin");
    std::fs::create_dir(&bin).unwrap();
    let sbatch = bin.join("sbatch");
    std::fs::write(
        &sbatch,
        r#"#!/usr/bin/env bash
# Stand-in for Slurm's sbatch: runs the job now, an array once per index.
set -e
array="" job=()
# Options come before the script; everything from the script on is the job.
for a in "$@"; do
    if [[ ${#job[@]} -gt 0 ]]; then
        job+=("$a")
        continue
    fi
    case $a in
    --array=*) array=${a#--array=} ;;
    --*) echo "$a" >> "$SBATCH_LOG" ;;
    *) job+=("$a") ;;
    esac
done
if [[ -n $array ]]; then
    for ((i = ${array%-*}; i <= ${array#*-}; i++)); do
        SLURM_ARRAY_TASK_ID=$i bash "${job[@]}" >&2
    done
else
    bash "${job[@]}" >&2
fi
echo "$RANDOM"
"#,
    )
    .unwrap();
    std::fs::set_permissions(&sbatch, std::fs::Permissions::from_mode(0o755)).unwrap();

    render(d, &["--spp", "12", "--out", "whole.exr"]);
    let scene = donut();
    let mut args = vec!["submit", scene.as_str(), "12", "4", "cluster.exr"];
    args.extend_from_slice(&SMALL);
    let o = bash("slurm-shards.sh", &args, d, Some(&bin));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(exr_pixels(&d.join("whole.exr")) == exr_pixels(&d.join("cluster.exr")));
    let log = String::from_utf8(read(d, "sbatch.log")).unwrap();
    assert!(log.contains("--dependency=afterok:"), "{log}");
}
