//! The `lueur` binary as a user meets it: exit codes, messages, files.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn lueur(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lueur"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn scene(name: &str) -> String {
    format!("{}/../../scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn files_in(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect()
}

#[test]
fn renders_png_by_default_next_to_the_user() {
    let dir = tempfile::tempdir().unwrap();
    let o = lueur(
        &[
            "render",
            &scene("cornell-spheres"),
            "--width",
            "16",
            "--height",
            "12",
            "--spp",
            "2",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let out = dir.path().join("cornell-spheres.png");
    let img = image::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (16, 12));
    assert!(
        stderr(&o).contains("cornell-spheres.png"),
        "the output path is printed"
    );
    assert_eq!(
        files_in(dir.path()).len(),
        1,
        "no temporary file is left behind"
    );
}

#[test]
fn exr_holds_mean_and_variance() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let o = lueur(
        &[
            "render",
            &scene("donut-mirrors"),
            "--out",
            "d.exr",
            "--width",
            "8",
            "--height",
            "8",
            "--spp",
            "4",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let image = read_all_flat_layers_from_file(dir.path().join("d.exr")).unwrap();
    let names: Vec<String> = image.layer_data[0]
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    for name in ["R", "G", "B", "variance.R", "variance.G", "variance.B"] {
        assert!(
            names.iter().any(|n| n == name),
            "channel {name} missing from {names:?}"
        );
    }
}

#[test]
fn a_bad_scene_exits_2_names_line_and_key_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(scene("cornell-spheres"))
        .unwrap()
        .replace("radius = 0.35", "radius = -0.35");
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, text).unwrap();
    let o = lueur(&["render", bad.to_str().unwrap()], dir.path());
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(err.contains("bad.toml:43:"), "{err}");
    assert!(err.contains("objects[5].shape.radius"), "{err}");
    assert!(err.contains('^'), "a caret points at the value: {err}");
    assert_eq!(files_in(dir.path()), vec![bad], "no output file");
}

#[test]
fn bad_flags_and_missing_files_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let o = lueur(
        &["render", &scene("cornell-spheres"), "--strategy", "magic"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("unknown strategy"));
    let o = lueur(&["render", "no-such-scene.toml"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no-such-scene.toml"));
    let o = lueur(
        &["render", &scene("cornell-spheres"), "--out", "x.jpg"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    let o = lueur(
        &["render", &scene("cornell-spheres"), "--spp", "0"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(files_in(dir.path()).is_empty());
}

#[test]
fn an_unwritable_output_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let o = lueur(
        &[
            "render",
            &scene("cornell-spheres"),
            "--width",
            "4",
            "--height",
            "4",
            "--spp",
            "1",
            "--out",
            "missing/dir/x.png",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("cannot write"));
    assert!(files_in(dir.path()).is_empty());
}
