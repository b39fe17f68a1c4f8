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
//! numbers). A film of several replicates has one such layer per block and
//! replicate, `lueur-samples-START-END-rR`, with its replicate in
//! `lueur.replicate`. Attributes of every layer record its sample range and what the
//! film is a render *of*: the scene file's full text and the settings that
//! decide a sample's value (`crate::fingerprint`). A resume or merge whose
//! scene or settings differ is refused with a message saying which.

use std::path::Path;

use anyhow::{Context, Result, bail};
use exr::prelude::*;
use lueur_integrator::{Film, PixelStats};

const LAYER_PREFIX: &str = "lueur-samples-";
const ATTR_START: &str = "lueur.samples.start";
const ATTR_END: &str = "lueur.samples.end";
const ATTR_SCENE: &str = "lueur.scene";
const ATTR_SETTINGS: &str = "lueur.settings";
const ATTR_REPLICATE: &str = "lueur.replicate";

/// One pixel as a checkpoint stores it, channels in the file's
/// (alphabetical) order.
type StoredPixel = (f32, f32, f32, f32, f32, f32, u32);

fn stored(p: &PixelStats) -> StoredPixel {
    (p.m2.z, p.m2.y, p.m2.x, p.mean.z, p.mean.y, p.mean.x, p.n)
}

fn from_stored((m2b, m2g, m2r, mb, mg, mr, n): StoredPixel) -> PixelStats {
    PixelStats {
        n,
        mean: glam::Vec3::new(mr, mg, mb),
        m2: glam::Vec3::new(m2r, m2g, m2b),
    }
}

/// One replicate of a block's pixels as the EXR writer asks for them (one
/// closure type for every layer): slot `replicate` of `replicates` per
/// pixel.
fn block_pixels(
    px: &[PixelStats],
    width: usize,
    replicates: usize,
    replicate: usize,
) -> impl Fn(Vec2<usize>) -> StoredPixel + Sync + '_ {
    move |pos| stored(&px[(pos.y() * width + pos.x()) * replicates + replicate])
}

/// Writes `film` to `path` as a checkpoint, atomically (temporary file,
/// then rename). Pixels go from the film to the encoder as it asks for
/// them: saving a 4K film does not copy it.
pub fn save(path: &Path, film: &Film, scene_text: &str, fingerprint: &str) -> Result<()> {
    if film.spp() == 0 {
        bail!("an empty film has nothing to save");
    }
    let size = (film.width() as usize, film.height() as usize);
    let mut layers = Vec::new();
    let replicates = film.replicates() as usize;
    for ((samples, px), r) in film
        .blocks()?
        .flat_map(|b| (0..replicates).map(move |r| (b.clone(), r)))
    {
        let channels = SpecificChannels::build()
            .with_channel("m2.B")
            .with_channel("m2.G")
            .with_channel("m2.R")
            .with_channel("mean.B")
            .with_channel("mean.G")
            .with_channel("mean.R")
            .with_channel("n")
            .with_pixel_fn(block_pixels(px, size.0, replicates, r));
        let mut name = format!("{LAYER_PREFIX}{}-{}", samples.start, samples.end);
        if replicates > 1 {
            name += &format!("-r{r}");
        }
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
        if replicates > 1 {
            other.insert(Text::from(ATTR_REPLICATE), AttributeValue::I32(r as i32));
        }
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

/// A film read back from a checkpoint (what it is a render of is in its
/// [`Header`]).
pub struct Saved {
    pub film: Film,
}

/// What a checkpoint's headers say, read without its pixels.
pub struct Header {
    /// The sample indices it holds.
    pub samples: std::ops::Range<u32>,
    pub scene_text: String,
    pub fingerprint: String,
    /// Per layer, in the file's order: its block and replicate.
    ranges: Vec<(std::ops::Range<u32>, u32)>,
    size: (u32, u32),
}

/// Reads a checkpoint's headers: is it a checkpoint, of one scene and
/// settings, of one size?
pub fn read_header(path: &Path) -> Result<Header> {
    let name = path.display();
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .with_context(|| format!("cannot read checkpoint {name}"))?;
    let mut about: Option<(String, String)> = None;
    let mut size = None;
    let mut ranges = Vec::new();
    for header in &meta.headers {
        let layer = &header.own_attributes;
        let is_block = layer
            .layer_name
            .as_ref()
            .is_some_and(|n| n.to_string().starts_with(LAYER_PREFIX));
        if !is_block {
            bail!("{name} is not a lueur checkpoint (a layer is not a `{LAYER_PREFIX}*` layer)");
        }
        let attr = |key: &str| layer.other.get(&Text::from(key));
        let index = |key: &str| match attr(key) {
            Some(AttributeValue::I32(v)) if *v >= 0 => Ok(*v as u32),
            _ => bail!("{name}: missing or bad `{key}`"),
        };
        let replicate = match attr(ATTR_REPLICATE) {
            None => 0,
            Some(_) => index(ATTR_REPLICATE)?,
        };
        ranges.push((index(ATTR_START)?..index(ATTR_END)?, replicate));
        let read_text = |key: &str| match attr(key) {
            Some(AttributeValue::Text(t)) => Ok(t.to_string()),
            _ => bail!("{name}: missing `{key}`"),
        };
        let this = (read_text(ATTR_SCENE)?, read_text(ATTR_SETTINGS)?);
        if about.as_ref().is_some_and(|a| *a != this) {
            bail!("{name}: its layers disagree on the scene or settings");
        }
        about = Some(this);
        let layer_size = (header.layer_size.0 as u32, header.layer_size.1 as u32);
        if size.is_some_and(|s| s != layer_size) {
            bail!("{name}: its layers differ in size");
        }
        size = Some(layer_size);
    }
    let (Some((scene_text, fingerprint)), Some(size)) = (about, size) else {
        bail!("{name} is not a lueur checkpoint (no `{LAYER_PREFIX}*` layer)");
    };
    let start = ranges.iter().map(|r| r.0.start).min().unwrap_or(0);
    let end = ranges.iter().map(|r| r.0.end).max().unwrap_or(0);
    Ok(Header {
        samples: start..end,
        scene_text,
        fingerprint,
        ranges,
        size,
    })
}

/// Reads a checkpoint or shard: its headers first, then the pixels,
/// decoded straight into the film's blocks.
pub fn read_film(path: &Path) -> Result<Saved> {
    let header = read_header(path)?;
    let name = path.display();
    let (w, h) = header.size;

    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .specific_channels()
        .required::<f32>("m2.B")
        .required::<f32>("m2.G")
        .required::<f32>("m2.R")
        .required::<f32>("mean.B")
        .required::<f32>("mean.G")
        .required::<f32>("mean.R")
        .required::<u32>("n")
        .collect_pixels(
            |size: Vec2<usize>, _| (size.0, vec![PixelStats::default(); size.area()]),
            |(width, pixels): &mut (usize, Vec<PixelStats>), pos: Vec2<usize>, p: StoredPixel| {
                pixels[pos.y() * *width + pos.x()] = from_stored(p);
            },
        )
        .all_layers()
        .all_attributes()
        .from_file(path)
        .with_context(|| format!("cannot read checkpoint {name}"))?;
    // Layers come back in the file's order, the headers'.
    let layers: Vec<_> = header
        .ranges
        .into_iter()
        .zip(image.layer_data)
        .map(|(samples, layer)| (samples, layer.channel_data.pixels.1))
        .collect();
    let (replicates, blocks) = interleave_replicates(layers)
        .with_context(|| format!("{name}: inconsistent replicate layers"))?;
    let start = blocks[0].0.start;
    let film = Film::from_blocks(w, h, start, replicates, blocks)
        .with_context(|| format!("{name}: inconsistent checkpoint data"))?;
    Ok(Saved { film })
}

type Block = (std::ops::Range<u32>, Vec<PixelStats>);
/// A layer as read: its block, its replicate, its pixels.
type ReplicateLayer = ((std::ops::Range<u32>, u32), Vec<PixelStats>);

/// The film's blocks from one layer per (block, replicate): each block's
/// pixels with their replicates' slots side by side, blocks in order.
fn interleave_replicates(mut layers: Vec<ReplicateLayer>) -> Result<(u32, Vec<Block>)> {
    layers.sort_by_key(|((samples, r), _)| (samples.start, *r));
    let replicates = layers.iter().map(|((_, r), _)| r + 1).max().unwrap_or(1);
    if replicates == 1 {
        // One layer per block: its pixels are the block's, moved, not copied.
        return Ok((1, layers.into_iter().map(|((s, _), px)| (s, px)).collect()));
    }
    let mut blocks = Vec::new();
    for group in layers.chunks(replicates as usize) {
        let samples = group[0].0.0.clone();
        let whole = group.len() == replicates as usize
            && group
                .iter()
                .zip(0..)
                .all(|(((s, r), _), k)| *s == samples && *r == k);
        if !whole {
            bail!("block {samples:?} does not have one layer per replicate 0..{replicates}");
        }
        let pixels = (0..group[0].1.len())
            .flat_map(|i| group.iter().map(move |(_, px)| px[i]))
            .collect();
        blocks.push((samples, pixels));
    }
    Ok((replicates, blocks))
}
