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

/// R, G, B of an EXR, row-major.
fn read_rgb(path: &Path) -> Vec<f32> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![0.0f32; 3 * size.area()]),
        |(w, px): &mut (usize, Vec<f32>), pos: Vec2<usize>, (r, g, b, _a): (f32, f32, f32, f32)| {
            let i = 3 * (pos.y() * *w + pos.x());
            px[i..i + 3].copy_from_slice(&[r, g, b]);
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels.1
}

#[test]
fn reference_out_writes_the_mse_of_every_pass() {
    let dir = tempfile::tempdir().unwrap();
    let o = render(
        &["--spp", "256", "--sampler", "independent", "-o", "ref.exr"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = render(
        &[
            "--spp",
            "64",
            "--seed",
            "3",
            "-o",
            "out.exr",
            "--reference",
            "ref.exr",
            "--reference-out",
            "passes.csv",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("against the reference, estimated"),
        "{}",
        stderr(&o)
    );
    let csv = std::fs::read_to_string(dir.path().join("passes.csv")).unwrap();
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let spp: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(spp, [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0]);
    let mse: Vec<f64> = rows.iter().map(|r| r[2]).collect();
    // Each doubling halves the variance part of the MSE; over six
    // doublings it must fall at least 4x even with the reference's noise.
    assert!(mse[6] * 4.0 < mse[0], "{mse:?}");
    assert!(mse.windows(3).all(|w| w[2] < w[0]), "{mse:?}");
    // The last row is the MSE of the image written.
    let (out, reference) = (
        read_rgb(&dir.path().join("out.exr")),
        read_rgb(&dir.path().join("ref.exr")),
    );
    let expected = out
        .iter()
        .zip(&reference)
        .map(|(a, b)| (f64::from(*a) - f64::from(*b)).powi(2))
        .sum::<f64>()
        / out.len() as f64;
    assert!(
        (mse[6] - expected).abs() <= 1e-6 * expected,
        "{} vs {expected}",
        mse[6]
    );
}

#[test]
fn bad_references_exit_2_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell-spheres");
    let small = [
        "render",
        &cornell,
        "--spp",
        "2",
        "-o",
        "small.exr",
        "--width",
        "8",
        "--height",
        "6",
    ];
    let o = lueur(&small, dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::write(dir.path().join("not.exr"), b"not an image").unwrap();
    for (reference, says) in [
        ("missing.exr", "no such file"),
        ("not.exr", "not an RGB EXR"),
        ("small.exr", "is 8x6, the render 16x12"),
    ] {
        let o = render(
            &["--spp", "2", "-o", "x.png", "--reference", reference],
            dir.path(),
        );
        assert_eq!(o.status.code(), Some(2), "{reference}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(err.contains("--reference") && err.contains(says), "{err}");
        assert!(!dir.path().join("x.png").exists());
    }
}
