//! `lueur merge`: which shards make one render. Their headers are read
//! first, so that every refusal (other scenes or settings, overlaps, and
//! missing samples) comes before a pixel is read.

use std::ops::Range;
use std::path::PathBuf;

use crate::fingerprint::Fingerprint;
use crate::{BadInput, checkpoint};

/// The shards of one render, in sample order, with what they are a render
/// of (the merged film's checkpoint records the same).
pub struct Shards {
    pub shards: Vec<(PathBuf, Range<u32>)>,
    pub scene_text: String,
    pub fingerprint: Fingerprint,
}

/// Reads the shards' headers and checks they make one render: same scene
/// text and settings, no overlap, and every sample of `0..spp` held,
/// unless `allow_partial` (a gap between shards is always refused: their
/// samples would not follow each other).
pub fn plan(paths: &[PathBuf], allow_partial: bool) -> Result<Shards, BadInput> {
    let mut shards = Vec::new();
    let mut first: Option<(PathBuf, String, Fingerprint)> = None;
    let mut total: Option<u32> = None;
    for path in paths {
        let header = checkpoint::read_header(path).map_err(|e| BadInput(format!("{e:#}")))?;
        let fp = Fingerprint::parse(&header.fingerprint);
        if let Some(spp) = fp.get("spp").and_then(|v| v.parse::<u32>().ok()) {
            total = Some(total.map_or(spp, |t| t.max(spp)));
        }
        match &first {
            None => first = Some((path.clone(), header.scene_text.clone(), fp)),
            Some((p, scene, _)) if *scene != header.scene_text => {
                return Err(BadInput(format!(
                    "{} and {} are renders of different scene files; cannot merge",
                    p.display(),
                    path.display()
                )));
            }
            Some((p, _, settings)) => {
                let differences = settings.differences(&fp, settings.spp_matters());
                if !differences.is_empty() {
                    return Err(BadInput(format!(
                        "{} and {} were rendered with different settings; cannot merge. \
                         Differing (first, second):\n  {}",
                        p.display(),
                        path.display(),
                        differences.join("\n  ")
                    )));
                }
            }
        }
        shards.push((path.clone(), header.samples));
    }
    let (_, scene_text, mut fingerprint) = first.ok_or_else(|| BadInput("no shards".into()))?;
    shards.sort_by_key(|(_, samples)| samples.start);
    // Name the files on either side of a gap or an overlap.
    for pair in shards.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if a.1.end != b.1.start {
            return Err(BadInput(format!(
                "{} holds samples {:?} and {} holds {:?}: shards must follow each other \
                 without gap or overlap",
                a.0.display(),
                a.1,
                b.0.display(),
                b.1
            )));
        }
    }
    let missing = missing(&shards, total);
    if !missing.is_empty() && !allow_partial {
        let list: Vec<String> = missing.iter().map(|r| format!("{r:?}")).collect();
        return Err(BadInput(format!(
            "the shards hold samples {:?} of the render's {} spp: missing {}; render them, \
             or pass --allow-partial to merge what there is",
            shards[0].1.start..shards[shards.len() - 1].1.end,
            total.unwrap_or_default(),
            list.join(" and ")
        )));
    }
    let held = shards[0].1.start..shards[shards.len() - 1].1.end;
    let shard = if Some(held.end) == total && held.start == 0 {
        "none".to_owned()
    } else {
        format!("{}..{}", held.start, held.end)
    };
    fingerprint.set("shard", shard);
    Ok(Shards {
        shards,
        scene_text,
        fingerprint,
    })
}

/// The sample ranges of `0..total` before and after the shards (sorted,
/// contiguous); none when the total was not recorded (older checkpoints).
fn missing(shards: &[(PathBuf, Range<u32>)], total: Option<u32>) -> Vec<Range<u32>> {
    let Some(total) = total else {
        return Vec::new();
    };
    let (start, end) = (shards[0].1.start, shards[shards.len() - 1].1.end);
    [0..start, end..total]
        .into_iter()
        .filter(|r| r.start < r.end)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_ranges_are_the_head_and_the_tail() {
        let s = |r: Range<u32>| (PathBuf::new(), r);
        assert_eq!(missing(&[s(0..12)], Some(32)), vec![12..32]);
        assert_eq!(missing(&[s(4..8), s(8..12)], Some(16)), vec![0..4, 12..16]);
        assert!(missing(&[s(0..8), s(8..16)], Some(16)).is_empty());
        assert!(missing(&[s(4..8)], None).is_empty());
    }
}
