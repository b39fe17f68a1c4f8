//! The command line a pbrt-v4 or Mitsuba 3 user expects: refusals before
//! any rendering, resume without repeating flags, crops, scene overrides,
//! partial images, complete merges.

mod common;

use common::{lueur, scene, stderr};

use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

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

/// Renders the donut at 24x20 with `extra` flags in `dir`, asserting success.
fn render(dir: &Path, extra: &[&str]) -> Output {
    let donut = scene("donut-mirrors");
    let mut args = vec!["render", donut.as_str(), "--width", "24", "--height", "20"];
    args.extend_from_slice(extra);
    let o = lueur(&args, dir);
    assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
    o
}

/// A file's content to compare: an EXR's pixels (its header has the render's
/// provenance, the time among it), any other file's bytes.
fn read(dir: &Path, name: &str) -> Vec<u8> {
    let path = dir.join(name);
    if name.ends_with(".exr") {
        let pixels = common::exr_pixels(&path);
        return format!("{pixels:?}").into_bytes();
    }
    std::fs::read(path).unwrap()
}

/// A checkpoint restores size and every setting: a render stopped after
/// its first pass (a time budget too short for a second) and resumed
/// with no flag at all ends byte-identical to the direct render.
#[test]
fn resume_without_flags_equals_the_direct_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let settings = [
        "--spp",
        "12",
        "--seed",
        "5",
        "--strategy",
        "mixture",
        "--max-depth",
        "3",
    ];
    render(d, &[&settings[..], &["-o", "whole.exr"]].concat());
    let o = render(
        d,
        &[
            &settings[..],
            &["--time", "1e-9", "--checkpoint", "ck.exr", "-o", "cut.exr"],
        ]
        .concat(),
    );
    assert!(
        stderr(&o).contains("stopped at 1 of 12 spp"),
        "{}",
        stderr(&o)
    );
    let donut = scene("donut-mirrors");
    let o = lueur(
        &["render", &donut, "--resume", "ck.exr", "-o", "resumed.exr"],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(read(d, "resumed.exr") == read(d, "whole.exr"));

    // Flags may repeat the checkpoint's settings, not change them: each
    // difference is listed by name, the checkpoint's value first.
    let o = lueur(
        &[
            "render", &donut, "--resume", "ck.exr", "--seed", "6", "--width", "30",
        ],
        d,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("\n  width: 24, 30\n  seed: 5, 6"), "{err}");
    // And a target below what the checkpoint holds is refused.
    let four = [
        "--seed",
        "5",
        "--spp",
        "4",
        "--checkpoint",
        "four.exr",
        "-o",
        "f.exr",
    ];
    render(d, &four);
    let o = lueur(&["render", &donut, "--resume", "four.exr", "--spp", "2"], d);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("already holds 4 spp"), "{}", stderr(&o));
}

/// Shards covering 0..12 of a 32-spp render are refused, the missing
/// samples named, unless --allow-partial.
#[test]
fn a_partial_merge_is_refused_unless_allowed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (range, file) in [("0..4", "a.exr"), ("4..12", "b.exr")] {
        render(
            d,
            &["--spp", "32", "--sample-range", range, "--checkpoint", file],
        );
    }
    let o = lueur(&["merge", "a.exr", "b.exr", "-o", "m.png"], d);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("samples 0..12 of the render's 32 spp: missing 12..32"),
        "{err}"
    );
    assert!(!d.join("m.png").exists());
    let o = lueur(
        &["merge", "a.exr", "b.exr", "--allow-partial", "-o", "m.png"],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(d.join("m.png").exists());
}

/// The (R, G, B, variance) values of every pixel of an EXR written by
/// lueur, row-major, with its size.
fn exr_pixels(path: &Path) -> (usize, usize, Vec<[u32; 6]>) {
    use exr::prelude::*;
    let image = read_all_flat_layers_from_file(path).unwrap();
    let layer = &image.layer_data[0];
    let (w, h) = (layer.size.0, layer.size.1);
    let channel = |name: &str| {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap();
        c.sample_data
            .values_as_f32()
            .map(f32::to_bits)
            .collect::<Vec<_>>()
    };
    let names = ["R", "G", "B", "variance.R", "variance.G", "variance.B"];
    let channels: Vec<Vec<u32>> = names.iter().map(|n| channel(n)).collect();
    let pixels = (0..w * h)
        .map(|i| std::array::from_fn(|c| channels[c][i]))
        .collect();
    (w, h, pixels)
}

/// A crop is the same pixels as the full render, bit for bit, whether
/// given as a crop window or as pixel bounds, and rendered at once, as
/// shards merged, or resumed from a checkpoint.
#[test]
fn a_crop_is_bit_identical_to_the_same_pixels_of_the_full_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(d, &["--spp", "6", "-o", "full.exr"]);
    let (fw, _, full) = exr_pixels(&d.join("full.exr"));
    // pbrt-v4: pixels from ceil(0.2 * 24) = 5 to ceil(0.7 * 24) = 17, rows
    // from ceil(0.1 * 20) = 2 to ceil(0.6 * 20) = 12.
    render(
        d,
        &[
            "--spp",
            "6",
            "--crop-window",
            "0.2",
            "0.7",
            "0.1",
            "0.6",
            "-o",
            "window.exr",
        ],
    );
    render(
        d,
        &[
            "--spp",
            "6",
            "--pixel-bounds",
            "5",
            "17",
            "2",
            "12",
            "-o",
            "bounds.exr",
        ],
    );
    let crop = ["--pixel-bounds", "5", "17", "2", "12"];
    for (range, file) in [("0..2", "s0.exr"), ("2..6", "s1.exr")] {
        let shard = ["--spp", "6", "--sample-range", range, "--checkpoint", file];
        render(d, &[&crop[..], &shard].concat());
    }
    let o = lueur(&["merge", "s1.exr", "s0.exr", "-o", "merged.exr"], d);
    assert!(o.status.success(), "{}", stderr(&o));
    render(
        d,
        &[
            &crop[..],
            &["--spp", "3", "--checkpoint", "c3.exr", "-o", "c3.png"],
        ]
        .concat(),
    );
    let donut = scene("donut-mirrors");
    let o = lueur(
        &[
            "render",
            &donut,
            "--resume",
            "c3.exr",
            "--spp",
            "6",
            "-o",
            "resumed.exr",
        ],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    for name in ["window.exr", "bounds.exr", "merged.exr", "resumed.exr"] {
        let (w, h, pixels) = exr_pixels(&d.join(name));
        assert_eq!((w, h), (12, 10), "{name}: the crop's size");
        for y in 0..h {
            for x in 0..w {
                assert_eq!(
                    pixels[y * w + x],
                    full[(y + 2) * fw + x + 5],
                    "{name}: pixel ({x}, {y}) of the crop"
                );
            }
        }
    }
}

/// `--set` reaches the scene (the image changes, and is the same as the
/// file edited by hand), and a bad key is refused naming it, exit 2.
#[test]
fn set_overrides_a_scene_key_and_refuses_a_bad_one() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(d, &["--spp", "2", "-o", "plain.exr"]);
    render(
        d,
        &["--spp", "2", "--set", "camera.vfov=25", "-o", "set.exr"],
    );
    assert!(
        read(d, "plain.exr") != read(d, "set.exr"),
        "the override changes the image"
    );
    let text = std::fs::read_to_string(scene("donut-mirrors")).unwrap();
    assert!(text.contains("vfov = "), "the scene sets vfov");
    let edited: String = text
        .lines()
        .map(|l| {
            if l.starts_with("vfov") {
                "vfov = 25".to_owned()
            } else {
                l.to_owned()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(d.join("edited.toml"), edited).unwrap();
    let o = lueur(
        &[
            "render",
            "edited.toml",
            "--width",
            "24",
            "--height",
            "20",
            "--spp",
            "2",
            "-o",
            "edited.exr",
        ],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        read(d, "edited.exr") == read(d, "set.exr"),
        "same as editing the file"
    );

    let donut = scene("donut-mirrors");
    let o = lueur(
        &["render", &donut, "--set", "camera.vfvo=25", "-o", "bad.png"],
        d,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("`camera.vfvo`") && err.contains("--set"),
        "{err}"
    );
    assert!(err.contains("did you mean `vfov`?"), "{err}");
    assert!(!d.join("bad.png").exists());
}

/// With --partial-every, the output image exists, whole, while the render
/// is still running (then it is interrupted).
#[cfg(unix)]
#[test]
fn a_partial_image_exists_while_the_render_runs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut child = Command::new(env!("CARGO_BIN_EXE_lueur"))
        .args([
            "render",
            &scene("donut-mirrors"),
            "--width",
            "32",
            "--height",
            "32",
            "--spp",
            "1000000",
            "--partial-every",
            "0.05",
            "-o",
            "p.png",
        ])
        .current_dir(d)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let image = d.join("p.png");
    while !image.exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(
        child.try_wait().unwrap().is_none(),
        "the render is still running"
    );
    assert!(
        image.exists(),
        "no partial image after {:?}",
        start.elapsed()
    );
    let img = image::open(&image).expect("a whole PNG");
    assert_eq!((img.width(), img.height()), (32, 32));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
}

/// `render --help` lists every strategy and sampler with a line each, and
/// completions are generated for the usual shells.
#[test]
fn help_lists_strategies_and_samplers_and_completions_are_generated() {
    let dir = tempfile::tempdir().unwrap();
    let o = lueur(&["render", "--help"], dir.path());
    assert!(o.status.success());
    let help = String::from_utf8(o.stdout).unwrap();
    for name in [
        "uniform",
        "cosine",
        "light",
        "mixture",
        "mis",
        "independent",
        "sobol-owen",
        "zsobol",
        "pmj02",
    ] {
        assert!(
            help.lines()
                .any(|l| l.trim_start().starts_with(&format!("{name} "))),
            "{name} missing from {help}"
        );
    }
    assert!(
        help.contains("-t, --threads") && help.contains("-o, --out"),
        "{help}"
    );
    for shell in ["bash", "zsh", "fish"] {
        let o = lueur(&["completions", shell], dir.path());
        assert!(o.status.success(), "{shell}");
        let script = String::from_utf8(o.stdout).unwrap();
        assert!(script.contains("crop-window"), "{shell}: {script}");
    }
}

/// `--stats` on one thread says "1 thread", and shows no row, nor stage, for
/// the shadow rays that `mixture` never casts; it shows the other stages.
#[test]
fn stats_speak_of_one_thread_and_skip_rays_never_cast() {
    let dir = tempfile::tempdir().unwrap();
    let o = render(
        dir.path(),
        &[
            "--spp",
            "2",
            "--strategy",
            "mixture",
            "--stats",
            "-t",
            "1",
            "-o",
            "s.png",
        ],
    );
    let out = String::from_utf8(o.stdout).unwrap();
    assert!(out.contains("time on 1 thread:"), "{out}");
    assert!(
        out.contains("camera  rays") && out.contains("bounce  rays"),
        "{out}"
    );
    assert!(!out.contains("shadow"), "{out}");
    assert!(
        out.contains("wave stages:") && out.contains("path rays"),
        "{out}"
    );
}

/// The points plot has a frame (a grey column of pixels as tall as the
/// square's side), and --dims chooses the pair of dimensions shown.
#[test]
fn the_points_plot_has_a_frame_and_plots_the_dimensions_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let plot = |dims: &[&str], out: &str| {
        let mut args = vec![
            "points",
            "--sampler",
            "sobol-owen",
            "-n",
            "64",
            "-d",
            "4",
            "-o",
            out,
        ];
        args.extend_from_slice(dims);
        let o = lueur(&args, d);
        assert!(o.status.success(), "{}", stderr(&o));
        image::open(d.join(out)).unwrap().to_luma8()
    };
    let first = plot(&[], "a.png");
    let other = plot(&["--dims", "2", "3"], "b.png");
    assert_ne!(first, other, "another pair of dimensions");
    let tallest_grey_column = (0..first.width())
        .map(|x| {
            (0..first.height())
                .filter(|&y| first.get_pixel(x, y).0[0] == 96)
                .count()
        })
        .max()
        .unwrap();
    assert!(tallest_grey_column > 400, "a frame: {tallest_grey_column}");
    let o = lueur(&["points", "-d", "2", "--dims", "0", "2", "-o", "c.png"], d);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}
