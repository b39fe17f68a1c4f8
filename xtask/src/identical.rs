//! `cargo xtask identical`: whether this tree's renderer gives another
//! build's images bit for bit. A change meant only to make lueur faster
//! (a vectorised stage, a new SIMD level) runs it against the commit before
//! it and must find every image the same.
//!
//! It renders every shipped scene with `mis` and `mixture`, streamed and
//! `--naive`, small (48x48, 8 spp, 2 threads), with the scene's own sampler
//! and with `--sampler independent`, by both binaries, and compares every
//! channel of every layer of the two EXR files sample by sample as bits.
//! The headers are not compared: their provenance names the binary and the
//! time. Prints one line per render and fails if any differs.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result, bail};
use exr::prelude::{FlatSamples, read_all_flat_layers_from_file};

use crate::memory::{Build, build_lueur};
use crate::old;
use crate::reference::cache_dir;
use crate::{run_lueur, shipped_scenes};

const SIZE: u32 = 48;
const SPP: u32 = 8;
const THREADS: u32 = 2;
const STRATEGIES: [&str; 2] = ["mis", "mixture"];
/// `None` is the scene's own sampler.
const SAMPLERS: [Option<&str>; 2] = [None, Some("independent")];

pub fn run(old_path: Option<&Path>, old_rev: Option<&str>) -> Result<()> {
    let Some(old) = old::resolve(old_path, old_rev, Build::Release)? else {
        bail!("name the other build: --old PATH or --old-rev REV");
    };
    let new = build_lueur()?;
    let work = cache_dir()?.join("identical");
    let (same, differ) = compare_builds(&old.binary, &new, &[&[]], &work)?;
    let total = same + differ;
    println!(
        "{same} of {total} renders identical to the old renderer ({})",
        old.description
    );
    if differ > 0 {
        bail!("{differ} of {total} renders differ from `{}`", old.flag);
    }
    Ok(())
}

/// Renders every configuration (each shipped scene; `mis` and `mixture`; streamed and
/// naive; the scene's sampler and independent) with `reference`, then with `other` once
/// per entry of `variants` (flags added to its command line), and compares each of
/// `other`'s images with `reference`'s as bits, in the scratch folder `work`. Prints a
/// line per comparison; returns how many were the same and how many differed.
pub fn compare_builds(
    reference: &Path,
    other: &Path,
    variants: &[&[&str]],
    work: &Path,
) -> Result<(usize, usize)> {
    std::fs::create_dir_all(work).with_context(|| format!("creating {}", work.display()))?;
    let (reference_exr, other_exr) = (work.join("reference.exr"), work.join("other.exr"));
    let (mut same, mut differ) = (0, 0);
    for scene in shipped_scenes()? {
        for strategy in STRATEGIES {
            for naive in [false, true] {
                for sampler in SAMPLERS {
                    let args = render_args(&scene, strategy, naive, sampler);
                    render(reference, &args, &reference_exr)?;
                    for variant in variants {
                        let mut args = args.clone();
                        args.extend(variant.iter().map(|s| s.to_string()));
                        render(other, &args, &other_exr)?;
                        let shown = args.join(" ");
                        match compare(&reference_exr, &other_exr)? {
                            None => {
                                same += 1;
                                println!("same     {shown}");
                            }
                            Some(why) => {
                                println!("DIFFERS  {shown}: {why}");
                                differ += 1;
                            }
                        }
                    }
                }
            }
        }
    }
    let _ = std::fs::remove_dir_all(work);
    Ok((same, differ))
}

/// The `lueur render` arguments of one comparison, without the output.
fn render_args(scene: &str, strategy: &str, naive: bool, sampler: Option<&str>) -> Vec<String> {
    let mut args: Vec<String> = vec!["render".into(), format!("scenes/{scene}.toml")];
    for (flag, value) in [
        ("--width", SIZE.to_string()),
        ("--height", SIZE.to_string()),
        ("--spp", SPP.to_string()),
        ("--strategy", strategy.into()),
        ("-t", THREADS.to_string()),
    ] {
        args.extend([flag.into(), value]);
    }
    if naive {
        args.push("--naive".into());
    }
    if let Some(sampler) = sampler {
        args.extend(["--sampler".into(), sampler.into()]);
    }
    args.push("-q".into());
    args
}

fn render(binary: &Path, args: &[String], out: &Path) -> Result<()> {
    let mut args = args.to_vec();
    args.extend(["-o".into(), out.display().to_string()]);
    run_lueur(binary, &args)
}

/// `None` when every channel of every layer of the two files holds the same
/// bits; otherwise what differs.
pub(crate) fn compare(a: &Path, b: &Path) -> Result<Option<String>> {
    let (a, b) = (channels(a)?, channels(b)?);
    if a.keys().ne(b.keys()) {
        return Ok(Some(format!(
            "channels differ: {:?} against {:?}",
            a.keys().collect::<Vec<_>>(),
            b.keys().collect::<Vec<_>>()
        )));
    }
    let mut why = String::new();
    for (name, x) in &a {
        let y = &b[name];
        if x.len() != y.len() {
            write!(why, "{name}: {} samples against {}; ", x.len(), y.len())?;
            continue;
        }
        let count = x.iter().zip(y).filter(|(x, y)| x != y).count();
        if count > 0 {
            write!(why, "{name}: {count} of {} samples; ", x.len())?;
        }
    }
    Ok((!why.is_empty()).then(|| why.trim_end_matches("; ").to_owned()))
}

/// Every channel of the file as its samples' bits, keyed by `layer.channel`.
fn channels(path: &Path) -> Result<BTreeMap<String, Vec<u32>>> {
    let image = read_all_flat_layers_from_file(path)
        .with_context(|| format!("reading {}", path.display()))?;
    let mut out = BTreeMap::new();
    for layer in &image.layer_data {
        let layer_name = layer
            .attributes
            .layer_name
            .as_ref()
            .map_or_else(String::new, ToString::to_string);
        for channel in &layer.channel_data.list {
            let bits: Vec<u32> = match &channel.sample_data {
                FlatSamples::F16(v) => v.iter().map(|s| u32::from(s.to_bits())).collect(),
                FlatSamples::F32(v) => v.iter().map(|s| s.to_bits()).collect(),
                FlatSamples::U32(v) => v.clone(),
            };
            out.insert(format!("{layer_name}.{}", channel.name), bits);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use exr::prelude::*;

    fn write(path: &Path, red: &[f32]) {
        let size = Vec2(2, 2);
        let channels = AnyChannels::sort(SmallVec::from_vec(vec![
            AnyChannel::new("R", FlatSamples::F32(red.to_vec())),
            AnyChannel::new("G", FlatSamples::F32(vec![0.5; 4])),
        ]));
        Image::from_layer(Layer::new(
            size,
            LayerAttributes::named("beauty"),
            Encoding::FAST_LOSSLESS,
            channels,
        ))
        .write()
        .to_file(path)
        .unwrap();
    }

    #[test]
    fn a_single_changed_bit_is_a_difference_and_nothing_else_is() {
        let dir = std::env::temp_dir().join(format!("lueur-identical-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b, c) = (dir.join("a.exr"), dir.join("b.exr"), dir.join("c.exr"));
        let red = [0.0, 1.0, 2.0, 3.0];
        write(&a, &red);
        write(&b, &red);
        // -0.0 equals 0.0 as a float but not as bits: the comparison must see it.
        write(&c, &[-0.0, 1.0, 2.0, 3.0]);
        assert_eq!(compare(&a, &b).unwrap(), None);
        let why = compare(&a, &c).unwrap().expect("a sign bit differs");
        assert!(why.contains("beauty.R: 1 of 4"), "{why}");
        assert!(!why.contains(".G"), "{why}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
