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
//! numbers). A film of several replicates has one layer per block and
//! replicate, `lueur-samples-START-END-rR`, with its replicate in
//! `lueur.replicate`, and channels `n` and `mean.R/G/B` only: such a film
//! keeps no `m2` (its variance is the replicates' spread), and the `m2` of
//! one saved before it stopped keeping them is not read. Blocks are decoded
//! straight into the film, one chunk of rows at a time. Attributes of every
//! layer record its sample range and what the film is a render *of*: the scene file's full text and the settings that
//! decide a sample's value (`crate::fingerprint`). A resume or merge whose
//! scene or settings differ is refused with a message saying which.

use std::ops::Range;
use std::path::Path;

use anyhow::{Context, Result, bail};
use exr::prelude::*;
use lueur_integrator::{BlockSlots, Film, PixelStats, SlotFill};

const LAYER_PREFIX: &str = "lueur-samples-";
const ATTR_START: &str = "lueur.samples.start";
const ATTR_END: &str = "lueur.samples.end";
const ATTR_SCENE: &str = "lueur.scene";
const ATTR_SETTINGS: &str = "lueur.settings";
const ATTR_REPLICATE: &str = "lueur.replicate";

/// One pixel as a checkpoint of one replicate stores it, channels in the
/// file's (alphabetical) order.
type StoredPixel = (f32, f32, f32, f32, f32, f32, u32);
/// One slot as a checkpoint of several replicates stores it: no `m2`.
type StoredMean = (f32, f32, f32, u32);

/// Writes `film` to `path` as a checkpoint, atomically (temporary file,
/// then rename). Pixels go from the film to the encoder as it asks for
/// them: saving a 4K film does not copy it.
pub fn save(path: &Path, film: &Film, scene_text: &str, fingerprint: &str) -> Result<()> {
    if film.spp() == 0 {
        bail!("an empty film has nothing to save");
    }
    let size = (film.width() as usize, film.height() as usize);
    let replicates = film.replicates() as usize;
    let slot = move |px: BlockSlots<'_>, r: usize, pos: Vec2<usize>| {
        px.slot((pos.y() * size.0 + pos.x()) * replicates + r)
    };
    let mut layers = Vec::new();
    let mut mean_layers = Vec::new();
    for ((samples, px), r) in film
        .blocks()?
        .flat_map(|b| (0..replicates).map(move |r| (b.clone(), r)))
    {
        let attributes = layer_attributes(&samples, r, replicates, scene_text, fingerprint)?;
        let channels = SpecificChannels::build();
        if replicates == 1 {
            let channels = channels
                .with_channel("m2.B")
                .with_channel("m2.G")
                .with_channel("m2.R")
                .with_channel("mean.B")
                .with_channel("mean.G")
                .with_channel("mean.R")
                .with_channel("n")
                .with_pixel_fn(move |pos| -> StoredPixel {
                    let p = slot(px, r, pos);
                    (p.m2.z, p.m2.y, p.m2.x, p.mean.z, p.mean.y, p.mean.x, p.n)
                });
            layers.push(Layer::new(
                size,
                attributes,
                Encoding::SMALL_LOSSLESS,
                channels,
            ));
        } else {
            let channels = channels
                .with_channel("mean.B")
                .with_channel("mean.G")
                .with_channel("mean.R")
                .with_channel("n")
                .with_pixel_fn(move |pos| -> StoredMean {
                    let p = slot(px, r, pos);
                    (p.mean.z, p.mean.y, p.mean.x, p.n)
                });
            mean_layers.push(Layer::new(
                size,
                attributes,
                Encoding::SMALL_LOSSLESS,
                channels,
            ));
        }
    }
    let attributes = ImageAttributes::new(IntegerBounds::from_dimensions(size));
    crate::output::write_atomically(path, |tmp| {
        if layers.is_empty() {
            Image::from_layers(attributes.clone(), mean_layers)
                .write()
                .to_file(tmp)?;
        } else {
            Image::from_layers(attributes.clone(), layers)
                .write()
                .to_file(tmp)?;
        }
        Ok(())
    })
}

/// The attributes of the layer of block `samples`, replicate `r`.
fn layer_attributes(
    samples: &Range<u32>,
    r: usize,
    replicates: usize,
    scene_text: &str,
    fingerprint: &str,
) -> Result<LayerAttributes> {
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
    Ok(attributes)
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
        let replicate_attr = attr(ATTR_REPLICATE);
        let replicate = match replicate_attr {
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
        check_channels(header, replicate_attr.is_none())
            .with_context(|| format!("{name}: layer {}", layer_name(header)))?;
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

fn layer_name(header: &exr::meta::header::Header) -> String {
    header
        .own_attributes
        .layer_name
        .as_ref()
        .map_or_else(String::new, ToString::to_string)
}

/// What a stored channel holds.
#[derive(Clone, Copy)]
enum Role {
    Count,
    Mean(usize),
    M2(usize),
}

fn role(channel: &str) -> Option<Role> {
    let rgb = |c: &str| ["R", "G", "B"].iter().position(|x| *x == c);
    match channel.split_once('.') {
        None if channel == "n" => Some(Role::Count),
        Some(("mean", c)) => rgb(c).map(Role::Mean),
        Some(("m2", c)) => rgb(c).map(Role::M2),
        _ => None,
    }
}

/// Whether a layer has the channels of a block, of the right types: `n`
/// (u32) and `mean.*` (f32), and `m2.*` (f32) when the film has one
/// replicate (a film of several keeps none; one saved before that has
/// them, and they are not read).
fn check_channels(header: &exr::meta::header::Header, one_replicate: bool) -> Result<()> {
    let mut wanted: Vec<&str> = vec!["mean.B", "mean.G", "mean.R", "n"];
    if one_replicate {
        wanted.extend(["m2.B", "m2.G", "m2.R"]);
    }
    for want in wanted {
        let Some(channel) = header
            .channels
            .list
            .iter()
            .find(|c| c.name.to_string() == want)
        else {
            bail!("no channel `{want}` (not a checkpoint of this version of lueur?)");
        };
        let ty = if want == "n" {
            SampleType::U32
        } else {
            SampleType::F32
        };
        if channel.sample_type != ty || channel.sampling != Vec2(1, 1) {
            bail!("channel `{want}` is not {ty:?} at full resolution");
        }
    }
    Ok(())
}

/// Reads a checkpoint (to resume): its headers first, then each block's
/// pixels, decoded straight into the film's image.
pub fn read_film(path: &Path) -> Result<Saved> {
    let header = read_header(path)?;
    let (w, h) = header.size;
    let film = Film::starting_at(w, h, header.samples.start);
    Ok(Saved {
        film: decode_into(path, &header, film)?,
    })
}

/// Reads a shard into `film`, whose samples it follows: each block is
/// decoded into the film as it is read, merged into the film's last block
/// where it is its later half, so the shard is never held beside the film.
pub fn merge_into(path: &Path, film: Option<Film>) -> Result<Film> {
    let header = read_header(path)?;
    let (w, h) = header.size;
    let film = match film {
        None => Film::starting_at(w, h, header.samples.start),
        Some(f) if (f.width(), f.height()) == (w, h) => f,
        Some(f) => bail!(
            "{}: {w}x{h} pixels, the shards before it {}x{}",
            path.display(),
            f.width(),
            f.height()
        ),
    };
    decode_into(path, &header, film)
}

/// Decodes every block of the checkpoint `path` (with headers `header`)
/// into `film`, in order.
fn decode_into(path: &Path, header: &Header, mut film: Film) -> Result<Film> {
    let name = path.display();
    let replicates = header.ranges.iter().map(|(_, r)| r + 1).max().unwrap_or(1);
    let mut blocks: Vec<Range<u32>> = header.ranges.iter().map(|(s, _)| s.clone()).collect();
    blocks.sort_by_key(|s| (s.start, s.end));
    blocks.dedup();
    if header.ranges.len() != blocks.len() * replicates as usize {
        bail!("{name}: inconsistent replicate layers: a block has a layer twice");
    }
    for samples in blocks {
        // The layer of each replicate of this block, in replicate order.
        let layers: Vec<usize> = (0..replicates)
            .map(|r| {
                header
                    .ranges
                    .iter()
                    .position(|l| *l == (samples.clone(), r))
            })
            .collect::<Option<_>>()
            .with_context(|| {
                format!(
                    "{name}: inconsistent replicate layers: block {samples:?} does not have one \
                     layer per replicate 0..{replicates}"
                )
            })?;
        film = film
            .append_decoded(samples, replicates, |fill| {
                decode_block(path, &layers, fill)
            })
            .with_context(|| format!("{name}: inconsistent checkpoint data"))?;
    }
    Ok(film)
}

/// Decodes the layers `layers` (one block, its replicates in order) of the
/// checkpoint `path` into `fill`, one chunk of rows at a time.
fn decode_block(path: &Path, layers: &[usize], fill: &mut SlotFill<'_>) -> Result<()> {
    use exr::block::reader::ChunksReader;
    let file = std::io::BufReader::new(std::fs::File::open(path)?);
    let reader = exr::block::read(file, true)?;
    let roles: Vec<Vec<Option<Role>>> = reader
        .headers()
        .iter()
        .map(|h| {
            h.channels
                .list
                .iter()
                .map(|c| role(&c.name.to_string()))
                .collect()
        })
        .collect();
    let width = reader.headers()[layers[0]].layer_size.0;
    let replicates = layers.len();
    let chunks = reader.filter_chunks(true, |_, tile, block| {
        layers.contains(&block.layer) && tile.is_largest_resolution_level()
    })?;
    let mut pixels: Vec<PixelStats> = Vec::new();
    let mut refused: Option<anyhow::Error> = None;
    let decoded = chunks.decompress_parallel(true, |meta, block| {
        let index = block.index;
        let (x0, y0) = (index.pixel_position.x(), index.pixel_position.y());
        let bw = index.pixel_size.width();
        pixels.clear();
        pixels.resize(index.pixel_size.area(), PixelStats::default());
        for line in block.lines(&meta.headers[index.layer].channels) {
            let row = line.location.position.y() - y0;
            let row = &mut pixels[row * bw..(row + 1) * bw];
            match roles[index.layer][line.location.channel] {
                Some(Role::Count) => {
                    for (p, v) in row.iter_mut().zip(line.read_samples::<u32>()) {
                        p.n = v?;
                    }
                }
                Some(Role::Mean(c)) => {
                    for (p, v) in row.iter_mut().zip(line.read_samples::<f32>()) {
                        p.mean[c] = v?;
                    }
                }
                Some(Role::M2(c)) => {
                    for (p, v) in row.iter_mut().zip(line.read_samples::<f32>()) {
                        p.m2[c] = v?;
                    }
                }
                None => {}
            }
        }
        let r = layers
            .iter()
            .position(|&l| l == index.layer)
            .expect("a filtered layer");
        for (k, p) in pixels.iter().enumerate() {
            let pixel = (y0 + k / bw) * width + x0 + k % bw;
            if let Err(e) = fill.put(pixel * replicates + r, *p) {
                refused = Some(e.into());
                return Err(exr::error::Error::Aborted);
            }
        }
        Ok(())
    });
    match (decoded, refused) {
        (_, Some(e)) => Err(e),
        (Err(e), None) => {
            Err(e).with_context(|| format!("cannot read checkpoint {}", path.display()))
        }
        (Ok(()), None) => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    /// A film of 3x2 pixels over `0..2`, and its slots: replicate `r` of
    /// pixel `i` holds one sample, unless it is the dropped one.
    fn film(replicates: u32) -> (Film, Vec<PixelStats>) {
        let slots: Vec<PixelStats> = (0..6 * replicates)
            .map(|i| {
                let x = i as f32 * 0.37 + 1.0;
                let mut s = PixelStats::of_sample(Vec3::new(x, 2.0 * x, x * x));
                if i == 4 {
                    s = PixelStats::default();
                } else {
                    s.m2 = Vec3::splat(x);
                }
                s
            })
            .collect();
        let film = Film::starting_at(3, 2, 0)
            .append_decoded(0..2, replicates, |fill| {
                slots
                    .iter()
                    .enumerate()
                    .try_for_each(|(i, s)| fill.put(i, *s))
            })
            .unwrap();
        (film, slots)
    }

    #[test]
    fn a_checkpoint_reads_back_the_film_it_saved() {
        let dir = tempfile::tempdir().unwrap();
        for k in [1, 2, 3] {
            let (film, _) = film(k);
            let path = dir.path().join(format!("k{k}.exr"));
            save(&path, &film, "scene", "fp").unwrap();
            assert!(read_film(&path).unwrap().film == film, "{k} replicates");
        }
    }

    /// A checkpoint of several replicates saved with `m2` channels, as
    /// lueur wrote them before it stopped keeping them: still read, its
    /// counts and means exactly, its `m2` ignored.
    #[test]
    fn an_older_checkpoint_of_replicates_with_m2_is_still_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("old.exr");
        let (film, slots) = film(2);
        let slots = &slots;
        let layers: Vec<_> = (0..2)
            .map(|r| {
                let channels = SpecificChannels::build()
                    .with_channel("m2.B")
                    .with_channel("m2.G")
                    .with_channel("m2.R")
                    .with_channel("mean.B")
                    .with_channel("mean.G")
                    .with_channel("mean.R")
                    .with_channel("n")
                    .with_pixel_fn(move |pos: Vec2<usize>| -> StoredPixel {
                        let p = slots[(pos.y() * 3 + pos.x()) * 2 + r];
                        (p.m2.z, p.m2.y, p.m2.x, p.mean.z, p.mean.y, p.mean.x, p.n)
                    });
                let attributes = layer_attributes(&(0..2), r, 2, "scene", "fp").unwrap();
                Layer::new((3, 2), attributes, Encoding::SMALL_LOSSLESS, channels)
            })
            .collect();
        let attributes = ImageAttributes::new(IntegerBounds::from_dimensions((3, 2)));
        Image::from_layers(attributes, layers)
            .write()
            .to_file(&path)
            .unwrap();
        let read = read_film(&path).unwrap().film;
        assert!(read == film);
        assert!(read.pixels().eq(film.pixels()));
    }

    /// One replicate needs its `m2`: a checkpoint without it is refused,
    /// naming the channel, before any pixel is read.
    #[test]
    fn a_checkpoint_of_one_replicate_without_m2_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("k1.exr");
        let (film, _) = film(2);
        save(&path, &film, "scene", "fp").unwrap();
        // Relabel the file as one replicate: drop its replicate attributes.
        let mut meta = exr::meta::MetaData::read_from_file(&path, false).unwrap();
        meta.headers.truncate(1);
        let header = &mut meta.headers[0];
        header
            .own_attributes
            .other
            .remove(&Text::from(ATTR_REPLICATE));
        assert!(
            check_channels(header, true)
                .unwrap_err()
                .to_string()
                .contains("m2")
        );
        assert!(check_channels(header, false).is_ok());
    }
}
