//! Checkpoints: the film's full state in an EXR file, so a render can stop
//! and later continue to the same or a higher spp, ending bit-identical to
//! one uninterrupted render.
//!
//! Layout: one layer named `lueur-checkpoint` with channels `n` (u32,
//! finite samples per pixel), `mean.R/G/B` and `m2.R/G/B` (f32, Welford's
//! running mean and sum of squared deviations: stored exactly, so resuming
//! adds the next samples to the very same numbers). Attributes record what
//! the film is a render *of*: `lueur.spp` (whole samples per pixel), the
//! scene file's full text and the settings that decide the image. A resume
//! whose scene or settings differ is refused with a message saying which.

use std::path::Path;

use anyhow::{Context, Result, bail};
use exr::prelude::*;
use lueur_integrator::{Film, PixelStats, RenderSettings};
use lueur_sampling::SamplerKind;

const LAYER: &str = "lueur-checkpoint";
const ATTR_SPP: &str = "lueur.spp";
const ATTR_SCENE: &str = "lueur.scene";
const ATTR_SETTINGS: &str = "lueur.settings";

/// What, besides the scene text, must match for samples to add up: every
/// setting that changes a sample's value. The spp target is not among them,
/// so a render can be resumed to more samples, except with `zsobol`, whose
/// sample order depends on the total spp.
pub fn settings_fingerprint(s: &RenderSettings, naive: bool) -> String {
    let spp = if s.sampler == SamplerKind::ZSobol {
        format!(" spp={}", s.spp)
    } else {
        String::new()
    };
    format!(
        "width={} height={} strategy={} sampler={} seed={} max_depth={} max_steps={} \
         pixel_epsilon={} epsilon={} epsilon_abs={} naive={naive}{spp}",
        s.width,
        s.height,
        s.strategy,
        s.sampler,
        s.seed,
        s.max_depth,
        s.max_steps,
        s.pixel_epsilon,
        s.epsilon_rel,
        s.epsilon_abs,
    )
}

/// Writes `film` to `path` as a checkpoint, atomically (temporary file,
/// then rename).
pub fn save(path: &Path, film: &Film, scene_text: &str, fingerprint: &str) -> Result<()> {
    let px = film.pixels();
    let f32_channel = |name: &str, f: &dyn Fn(&PixelStats) -> f32| {
        AnyChannel::new(name, FlatSamples::F32(px.iter().map(f).collect()))
    };
    let channels = AnyChannels::sort(SmallVec::from_vec(vec![
        AnyChannel::new("n", FlatSamples::U32(px.iter().map(|p| p.n).collect())),
        f32_channel("mean.R", &|p| p.mean.x),
        f32_channel("mean.G", &|p| p.mean.y),
        f32_channel("mean.B", &|p| p.mean.z),
        f32_channel("m2.R", &|p| p.m2.x),
        f32_channel("m2.G", &|p| p.m2.y),
        f32_channel("m2.B", &|p| p.m2.z),
    ]));
    let mut attributes = LayerAttributes::named(LAYER);
    attributes.other.insert(
        Text::from(ATTR_SPP),
        AttributeValue::I32(i32::try_from(film.spp()).context("spp too large for a checkpoint")?),
    );
    attributes.other.insert(
        Text::from(ATTR_SCENE),
        AttributeValue::Text(text(scene_text)?),
    );
    attributes.other.insert(
        Text::from(ATTR_SETTINGS),
        AttributeValue::Text(text(fingerprint)?),
    );
    let layer = Layer::new(
        (film.width() as usize, film.height() as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    crate::output::write_atomically(path, |tmp| {
        Image::from_layer(layer).write().to_file(tmp)?;
        Ok(())
    })
}

fn text(s: &str) -> Result<Text> {
    Text::new_or_none(s).context("the checkpoint's text must be ASCII (Latin-1)")
}

/// Reads a checkpoint and checks it is a render of `scene_text` with
/// settings `fingerprint`.
pub fn load(path: &Path, scene_text: &str, fingerprint: &str) -> Result<Film> {
    let name = path.display();
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_file(path)
        .with_context(|| format!("cannot read checkpoint {name}"))?;
    let Some(layer) = image
        .layer_data
        .iter()
        .find(|l| l.attributes.layer_name.as_ref().is_some_and(|n| n == LAYER))
    else {
        bail!("{name} is not a lueur checkpoint (no `{LAYER}` layer)");
    };
    let attr = |key: &str| layer.attributes.other.get(&Text::from(key));
    let spp = match attr(ATTR_SPP) {
        Some(AttributeValue::I32(v)) if *v >= 0 => *v as u32,
        _ => bail!("{name}: missing or bad `{ATTR_SPP}`"),
    };
    let read_text = |key: &str| match attr(key) {
        Some(AttributeValue::Text(t)) => Ok(t.to_string()),
        _ => bail!("{name}: missing `{key}`"),
    };
    if read_text(ATTR_SCENE)? != scene_text {
        bail!("{name} is a render of a different scene file (its text differs); cannot resume");
    }
    let saved = read_text(ATTR_SETTINGS)?;
    if saved != fingerprint {
        bail!(
            "{name} was rendered with other settings; cannot resume.\n  checkpoint: {saved}\n  now:        {fingerprint}"
        );
    }
    let size = layer.size;
    let channel = |n: &str| {
        layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == n)
            .map(|c| &c.sample_data)
    };
    let f32s = |n: &str| -> Result<Vec<f32>> {
        match channel(n) {
            Some(FlatSamples::F32(v)) => Ok(v.clone()),
            _ => bail!("{name}: missing f32 channel `{n}`"),
        }
    };
    let counts = match channel("n") {
        Some(FlatSamples::U32(v)) => v.clone(),
        _ => bail!("{name}: missing u32 channel `n`"),
    };
    let (mr, mg, mb) = (f32s("mean.R")?, f32s("mean.G")?, f32s("mean.B")?);
    let (sr, sg, sb) = (f32s("m2.R")?, f32s("m2.G")?, f32s("m2.B")?);
    let pixels = (0..counts.len())
        .map(|i| PixelStats {
            n: counts[i],
            mean: glam::Vec3::new(mr[i], mg[i], mb[i]),
            m2: glam::Vec3::new(sr[i], sg[i], sb[i]),
        })
        .collect();
    Film::from_parts(size.0 as u32, size.1 as u32, spp, pixels)
        .with_context(|| format!("{name}: inconsistent checkpoint data"))
}
