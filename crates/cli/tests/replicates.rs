//! Replicates and error targets from the command line: bad counts are
//! refused before rendering, and every end of a render says the error it
//! reached.

mod common;

use common::{lueur, scene, stderr};

use std::path::Path;
use std::process::Output;

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

/// The `lueur.*` attributes of an EXR's first layer.
fn exr_provenance(path: &Path) -> std::collections::BTreeMap<String, String> {
    use exr::meta::attribute::AttributeValue;
    let meta = exr::meta::MetaData::read_from_file(path, false).unwrap();
    meta.headers[0]
        .own_attributes
        .other
        .iter()
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
            _ => None,
        })
        .filter(|(k, _)| k.starts_with("lueur."))
        .collect()
}

fn png_provenance(path: &Path) -> std::collections::BTreeMap<String, String> {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let reader = decoder.read_info().unwrap();
    reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect()
}

#[test]
fn every_image_says_how_it_was_made() {
    let dir = tempfile::tempdir().unwrap();
    let settings = [
        "--spp",
        "8",
        "--sampler",
        "cmj",
        "--replicates",
        "4",
        "--seed",
        "9",
        "--max-depth",
        "3",
        "--strategy",
        "mixture",
    ];
    let text = std::fs::read_to_string(scene("cornell-spheres")).unwrap();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    let hash = format!("fnv1a64:{h:016x}");
    for out in ["out.exr", "out.png"] {
        let o = render(&[&settings[..], &["-o", out]].concat(), dir.path());
        assert!(o.status.success(), "{}", stderr(&o));
        let path = dir.path().join(out);
        let p = if out.ends_with(".exr") {
            exr_provenance(&path)
        } else {
            png_provenance(&path)
        };
        let get = |k: &str| p.get(&format!("lueur.{k}")).cloned().unwrap_or_default();
        for (key, value) in [
            ("version", env!("CARGO_PKG_VERSION")),
            ("scene", scene("cornell-spheres").as_str()),
            ("scene_hash", hash.as_str()),
            ("spp", "8"),
            ("strategy", "mixture"),
            ("sampler", "cmj"),
            ("replicates", "4"),
            ("seed", "9"),
            ("max_depth", "3"),
        ] {
            assert_eq!(get(key), value, "{out}: lueur.{key} in {p:?}");
        }
        assert!(get("render_seconds").parse::<f64>().unwrap() > 0.0, "{p:?}");
        assert!(get("relative_error").parse::<f64>().unwrap() > 0.0, "{p:?}");
        assert!(!p.contains_key("lueur.samples"), "not a shard: {p:?}");
    }
    let o = render(
        &[
            &settings[..],
            &[
                "--sample-range",
                "2..6",
                "--checkpoint",
                "c.exr",
                "-o",
                "s.exr",
            ],
        ]
        .concat(),
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let p = exr_provenance(&dir.path().join("s.exr"));
    assert_eq!(p["lueur.samples"], "2..6");
    assert_eq!(
        (p["lueur.spp"].as_str(), p["lueur.total_spp"].as_str()),
        ("4", "8")
    );
}
