//! The command line a pbrt-v4 or Mitsuba 3 user expects: refusals before
//! any rendering, resume without repeating flags, crops, scene overrides,
//! partial images, complete merges.

use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

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

fn entries(dir: &Path) -> usize {
    std::fs::read_dir(dir).unwrap().count()
}

/// Every bad output path is refused with exit 2, naming the flag, before
/// the first sample: at 2^24 spp of 256x256 any rendering would take
/// hours, so a refusal within seconds can only come before it.
#[test]
fn bad_output_paths_are_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell-spheres");
    let cases: &[(&[&str], &str)] = &[
        (
            &["--out", "missing/x.png"],
            "--out missing/x.png: the directory",
        ),
        (&["--out", "x.jpg"], "--out x.jpg: unknown image format"),
        (
            &["--checkpoint", "ck.png"],
            "--checkpoint ck.png: a checkpoint is an OpenEXR",
        ),
        (
            &["--checkpoint", "missing/ck.exr"],
            "--checkpoint missing/ck.exr: the directory",
        ),
        (
            &["--out", "a.exr", "--checkpoint", "a.exr"],
            "both name a.exr",
        ),
        (
            &["--resume", "missing.exr"],
            "--resume missing.exr: no such file",
        ),
    ];
    for (extra, message) in cases {
        let mut args = vec!["render", cornell.as_str(), "--spp", "16777216"];
        args.extend_from_slice(extra);
        let start = Instant::now();
        let o = lueur(&args, dir.path());
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "{extra:?}: refused only after {:?}",
            start.elapsed()
        );
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(err.contains(message), "{extra:?}: {err}");
        assert_eq!(err.lines().count(), 1, "one line, no repeated cause: {err}");
    }
    assert_eq!(entries(dir.path()), 0, "nothing written, no probe left");
}
