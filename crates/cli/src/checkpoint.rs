//! Checkpoints and shards: a film's full state in an EXR file, so a render
//! can stop and later continue to the same or a higher spp, and shards
//! rendered apart can be merged, ending bit-identical to one uninterrupted
//! render.
//!
//! Layout: one layer per dyadic block of samples the film holds (see
//! `lueur_integrator::film`; one block after a render of `0..2^k`), named
//! `lueur-samples-START-END`, with channels `n` (u32, finite samples per
//! pixel), `mean.R/G/B` and `m2.R/G/B` (f32: mean and sum of squared
//! deviations, stored exactly, so that continuing merges the very same
//! numbers). Attributes of every layer record its sample range and what the
//! film is a render *of*: the scene file's full text and the settings that
//! decide a sample's value. A resume or merge whose scene or settings differ
//! is refused with a message saying which.

use std::path::Path;

use anyhow::{Context, Result, bail};
use exr::prelude::*;
use lueur_integrator::{Film, PixelStats, RenderSettings};

const LAYER_PREFIX: &str = "lueur-samples-";
const ATTR_START: &str = "lueur.samples.start";
const ATTR_END: &str = "lueur.samples.end";
const ATTR_SCENE: &str = "lueur.scene";
const ATTR_SETTINGS: &str = "lueur.settings";

/// What, besides the scene text, must match for samples to add up: every
/// setting that changes a sample's value. The spp target is not among them,
/// so a render can be resumed to more samples, except with the samplers
/// whose patterns are laid out over the total spp.
pub fn settings_fingerprint(s: &RenderSettings, naive: bool) -> String {
    let spp = if s.sampler.depends_on_spp() {
        format!(" spp={}", s.spp)
    } else {
        String::new()
    };
    format!(
        "width={} height={} strategy={} sampler={} seed={} max_depth={} roulette_depth={} max_steps={} \
         pixel_epsilon={} epsilon={} epsilon_abs={} naive={naive}{spp}",
        s.width,
        s.height,
        s.strategy,
        s.sampler,
        s.seed,
        s.max_depth,
        s.roulette_depth,
        s.max_steps,
        s.pixel_epsilon,
        s.epsilon_rel,
        s.epsilon_abs,
    )
}

/// Writes `film` to `path` as a checkpoint, atomically (temporary file,
/// then rename).
pub fn save(path: &Path, film: &Film, scene_text: &str, fingerprint: &str) -> Result<()> {
    if film.spp() == 0 {
        bail!("an empty film has nothing to save");
    }
    let size = (film.width() as usize, film.height() as usize);
    let mut layers = Vec::new();
    for (samples, px) in film.blocks()? {
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
        let name = format!("{LAYER_PREFIX}{}-{}", samples.start, samples.end);
        let mut attributes = LayerAttributes::named(name.as_str());
        let index = |v: u32| i32::try_from(v).context("sample index too large for a checkpoint");
        let other = &mut attributes.other;
        other.insert(
            Text::from(ATTR_START),
            AttributeValue::I32(index(samples.start)?),
        );
        other.insert(
            Text::from(ATTR_END),
            AttributeValue::I32(index(samples.end)?),
        );
        other.insert(
            Text::from(ATTR_SCENE),
            AttributeValue::Text(text(scene_text)?),
        );
        other.insert(
            Text::from(ATTR_SETTINGS),
            AttributeValue::Text(text(fingerprint)?),
        );
        layers.push(Layer::new(
            size,
            attributes,
            Encoding::SMALL_LOSSLESS,
            channels,
        ));
    }
    let image = Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions(size)),
        layers,
    );
    crate::output::write_atomically(path, |tmp| {
        image.write().to_file(tmp)?;
        Ok(())
    })
}

fn text(s: &str) -> Result<Text> {
    Text::new_or_none(s).context("the checkpoint's text must be ASCII (Latin-1)")
}

/// A film read back from a checkpoint, with what it is a render of.
pub struct Saved {
    pub film: Film,
    pub scene_text: String,
    pub fingerprint: String,
}

/// Reads a checkpoint and checks it is a render of `scene_text` with
/// settings `fingerprint`.
pub fn load(path: &Path, scene_text: &str, fingerprint: &str) -> Result<Film> {
    let name = path.display();
    let saved = read_film(path)?;
    if saved.scene_text != scene_text {
        bail!("{name} is a render of a different scene file (its text differs); cannot resume");
    }
    if saved.fingerprint != fingerprint {
        bail!(
            "{name} was rendered with other settings; cannot resume.\n  checkpoint: {}\n  now:        {fingerprint}",
            saved.fingerprint
        );
    }
    Ok(saved.film)
}

/// Reads a checkpoint or shard.
pub fn read_film(path: &Path) -> Result<Saved> {
    let name = path.display();
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_file(path)
        .with_context(|| format!("cannot read checkpoint {name}"))?;
    let mut blocks = Vec::new();
    let mut about: Option<(String, String)> = None;
    let mut size = None;
    for layer in &image.layer_data {
        let is_block = layer
            .attributes
            .layer_name
            .as_ref()
            .is_some_and(|n| n.to_string().starts_with(LAYER_PREFIX));
        if !is_block {
            continue;
        }
        let attr = |key: &str| layer.attributes.other.get(&Text::from(key));
        let index = |key: &str| match attr(key) {
            Some(AttributeValue::I32(v)) if *v >= 0 => Ok(*v as u32),
            _ => bail!("{name}: missing or bad `{key}`"),
        };
        let samples = index(ATTR_START)?..index(ATTR_END)?;
        let read_text = |key: &str| match attr(key) {
            Some(AttributeValue::Text(t)) => Ok(t.to_string()),
            _ => bail!("{name}: missing `{key}`"),
        };
        let this = (read_text(ATTR_SCENE)?, read_text(ATTR_SETTINGS)?);
        if about.as_ref().is_some_and(|a| *a != this) {
            bail!("{name}: its layers disagree on the scene or settings");
        }
        about = Some(this);
        let layer_size = (layer.size.0 as u32, layer.size.1 as u32);
        if size.is_some_and(|s| s != layer_size) {
            bail!("{name}: its layers differ in size");
        }
        size = Some(layer_size);
        let channel = |n: &str| {
            layer
                .channel_data
                .list
                .iter()
                .find(|c| c.name.to_string() == n)
                .map(|c| &c.sample_data)
        };
        let f32s = |n: &str| -> Result<&Vec<f32>> {
            match channel(n) {
                Some(FlatSamples::F32(v)) => Ok(v),
                _ => bail!("{name}: missing f32 channel `{n}`"),
            }
        };
        let counts = match channel("n") {
            Some(FlatSamples::U32(v)) => v,
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
        blocks.push((samples, pixels));
    }
    let (Some((scene_text, fingerprint)), Some((w, h))) = (about, size) else {
        bail!("{name} is not a lueur checkpoint (no `{LAYER_PREFIX}*` layer)");
    };
    blocks.sort_by_key(|b: &(std::ops::Range<u32>, Vec<PixelStats>)| b.0.start);
    let start = blocks[0].0.start;
    let film = Film::from_blocks(w, h, start, blocks)
        .with_context(|| format!("{name}: inconsistent checkpoint data"))?;
    Ok(Saved {
        film,
        scene_text,
        fingerprint,
    })
}
