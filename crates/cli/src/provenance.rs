//! Provenance: what an image is a render of, written into its header (EXR
//! attributes, PNG tEXt chunks), so that a file says how it was made:
//! lueur's version, the scene file and a hash of its text, the samples,
//! the settings that decide the image, the render time and the estimated
//! relative error.

use std::ops::Range;

use lueur_scene::RenderSettings;

/// Key-value pairs, keys prefixed `lueur.`, in a fixed order.
#[derive(Clone, Debug, Default)]
pub struct Provenance(pub Vec<(String, String)>);

/// FNV-1a (64-bit) of `text`: a hash that is the same on every platform
/// and release, unlike `std`'s.
pub fn text_hash(text: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    format!("fnv1a64:{h:016x}")
}

/// What a render was: `scene_file` and its text, the settings, the sample
/// indices it holds (a shard's range, or `0..spp`), its seconds and its
/// estimated relative error.
pub fn of_render(
    scene_file: &str,
    scene_text: &str,
    settings: &RenderSettings,
    samples: Range<u32>,
    seconds: f64,
    relative_error: f64,
) -> Provenance {
    let mut p = vec![
        ("version", env!("CARGO_PKG_VERSION").to_string()),
        ("scene", scene_file.to_string()),
        ("scene_hash", text_hash(scene_text)),
        ("spp", (samples.end - samples.start).to_string()),
        ("samples", format!("{}..{}", samples.start, samples.end)),
        ("total_spp", settings.spp.to_string()),
        ("strategy", settings.strategy.to_string()),
        ("sampler", settings.sampler.to_string()),
        ("replicates", settings.replicate_count().to_string()),
        ("seed", settings.seed.to_string()),
        ("max_depth", settings.max_depth.to_string()),
        ("render_seconds", format!("{seconds:.3}")),
        ("relative_error", format!("{relative_error:.6}")),
    ];
    if samples.start == 0 && samples.end == settings.spp {
        // Not a shard: the range says nothing the spp does not.
        p.retain(|(k, _)| *k != "samples");
    }
    Provenance(
        p.into_iter()
            .map(|(k, v)| (format!("lueur.{k}"), ascii(&v)))
            .collect(),
    )
}

/// `s` with every character outside printable ASCII as `?`: EXR text is
/// Latin-1 and PNG tEXt chunks are Latin-1 too.
fn ascii(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii() && !c.is_ascii_control() {
                c
            } else {
                '?'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hash_is_fnv1a() {
        // The published FNV-1a 64 test vectors.
        assert_eq!(text_hash(""), "fnv1a64:cbf29ce484222325");
        assert_eq!(text_hash("a"), "fnv1a64:af63dc4c8601ec8c");
    }
}
