//! `--resume`: a checkpoint knows what it is a render of, so resuming needs
//! no flag but the spp: the image size and every setting are restored from
//! it, flags may only repeat them (or change what does not alter a sample:
//! the spp target, threads, outputs, limits), and a refusal lists each
//! setting that differs.

use std::path::Path;

use lueur_integrator::Film;
use lueur_sampling::SamplerKind;

use crate::fingerprint::Fingerprint;
use crate::{BadInput, RenderArgs, checkpoint};

/// What a checkpoint says about itself, read before the scene is parsed.
pub struct Resumed {
    pub fingerprint: Fingerprint,
    pub scene_text: String,
    pub samples: std::ops::Range<u32>,
}

/// Reads the headers of the checkpoint `path` and fills every flag of
/// `args` that was not given with the checkpoint's value.
pub fn restore(path: &Path, args: &mut RenderArgs) -> Result<Resumed, BadInput> {
    let header = checkpoint::read_header(path).map_err(|e| BadInput(format!("--resume: {e:#}")))?;
    let fp = Fingerprint::parse(&header.fingerprint);
    let bad = |name: &str, value: &str| {
        BadInput(format!(
            "--resume {}: unreadable `{name}` in its settings: `{value}`",
            path.display()
        ))
    };
    // A shard resumed without a target continues to its own end; given a
    // target, the render is the one of that many spp.
    let restore_shard = args.spp.is_none() && args.sample_range.is_none();
    macro_rules! restore {
        ($field:ident, $name:literal, $parse:expr) => {
            if args.$field.is_none() {
                if let Some(v) = fp.get($name) {
                    args.$field = Some($parse(v).ok_or_else(|| bad($name, v))?);
                }
            }
        };
    }
    restore!(width, "width", |v: &str| v.parse().ok());
    restore!(height, "height", |v: &str| v.parse().ok());
    restore!(strategy, "strategy", lueur_scene::Strategy::from_name);
    restore!(sampler, "sampler", SamplerKind::from_name);
    restore!(seed, "seed", |v: &str| v.parse().ok());
    restore!(max_depth, "max_depth", |v: &str| v.parse().ok());
    restore!(roulette_depth, "roulette_depth", |v: &str| v.parse().ok());
    restore!(spp, "spp", |v: &str| v.parse().ok());
    if args.crop_window.is_none()
        && args.pixel_bounds.is_none()
        && let Some(v) = fp.get("crop").filter(|v| *v != "none")
    {
        let bounds: Option<Vec<u32>> = v.split(',').map(|x| x.parse().ok()).collect();
        let bounds = bounds.filter(|b| b.len() == 4);
        args.pixel_bounds = Some(bounds.ok_or_else(|| bad("crop", v))?);
    }
    if restore_shard && let Some(v) = fp.get("shard").filter(|v| *v != "none") {
        args.sample_range = Some(crate::parse_sample_range(v).map_err(|_| bad("shard", v))?);
    }
    if fp.get("naive") == Some("true") {
        args.naive = true;
    }
    if args.set.is_empty() {
        args.set = fp.overrides();
    }
    Ok(Resumed {
        fingerprint: fp,
        scene_text: header.scene_text,
        samples: header.samples,
    })
}

/// Checks that the render now asked for continues the checkpoint's, and
/// loads its film: the same scene text and settings, samples that start
/// where the render's do, no more samples than the render's target.
pub fn load(
    path: &Path,
    resumed: &Resumed,
    scene_text: &str,
    now: &Fingerprint,
    sampler: SamplerKind,
    range: &std::ops::Range<u32>,
) -> Result<Film, BadInput> {
    let name = path.display();
    if resumed.scene_text != scene_text {
        return Err(BadInput(format!(
            "--resume {name} is a render of a different scene file (its text differs); \
             cannot resume"
        )));
    }
    let differences = resumed
        .fingerprint
        .differences(now, sampler.depends_on_spp());
    if !differences.is_empty() {
        return Err(BadInput(format!(
            "--resume {name} was rendered with other settings; cannot resume. \
             Differing (checkpoint, now):\n  {}",
            differences.join("\n  ")
        )));
    }
    if resumed.samples.start != range.start {
        return Err(BadInput(format!(
            "--resume {name} holds samples {:?}, which do not start at {}",
            resumed.samples, range.start
        )));
    }
    if resumed.samples.end > range.end {
        return Err(BadInput(format!(
            "--resume {name} already holds {} spp, more than the {} asked for: resume to at \
             least {} spp (--spp)",
            resumed.samples.end - resumed.samples.start,
            range.end - range.start,
            resumed.samples.end
        )));
    }
    let saved = checkpoint::read_film(path).map_err(|e| BadInput(format!("--resume: {e:#}")))?;
    Ok(saved.film)
}
