//! Replicates and error targets from the command line: bad counts are
//! refused before rendering, and every end of a render says the error it
//! reached.

use std::path::Path;
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

fn render(extra: &[&str], dir: &Path) -> Output {
    let cornell = scene("cornell-spheres");
    let mut args = vec!["render", &cornell, "--width", "16", "--height", "12"];
    args.extend_from_slice(extra);
    lueur(&args, dir)
}

#[test]
fn bad_replicate_counts_exit_2_naming_the_flag_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    for (extra, says) in [
        (&["--replicates", "0", "--spp", "8"][..], "at least 1"),
        (&["--replicates", "9", "--spp", "8"][..], "at least 9 spp"),
        (
            &["--replicates", "2", "--spp", "8", "--sampler", "sobol"][..],
            "not randomized",
        ),
    ] {
        let o = render(&[extra, &["-o", "x.exr"]].concat(), dir.path());
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(err.contains("--replicates") && err.contains(says), "{err}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}

#[test]
fn an_unreached_target_says_so_with_the_error_reached() {
    let dir = tempfile::tempdir().unwrap();
    let o = render(
        &["--spp", "4", "--target-error", "0.0001", "-o", "a.png"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("target error 0.0001 not reached: estimated relative error")
            && err.contains("the spp cap was reached"),
        "{err}"
    );
    // Without a target, a complete render still says what it reached.
    let o = render(&["--spp", "4", "-o", "b.png"], dir.path());
    assert!(
        stderr(&o).contains("estimated relative error"),
        "{}",
        stderr(&o)
    );
}
