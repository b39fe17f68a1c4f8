//! What a checkpoint is a render *of*, besides the scene text: every
//! setting that decides a sample's value, by name, so that a resume can
//! restore them and a refusal can list each one that differs.
//!
//! Stored as one line of `name=value` fields (the checkpoint's
//! `lueur.settings` attribute); the scene overrides (`--set`) come last,
//! as a TOML array of strings, since they may hold spaces.

use lueur_integrator::PixelBounds;
use lueur_scene::{Marching, RenderSettings};

/// The settings of a render, as named text fields in a fixed order.
#[derive(Clone, Debug, PartialEq)]
pub struct Fingerprint {
    fields: Vec<(String, String)>,
}

/// Fields that do not change a sample's value: the total spp (unless the
/// sampler lays its pattern out over it), and the shard's range.
const TARGETS: &[&str] = &["spp", "shard"];

impl Fingerprint {
    /// The fingerprint of a render of `settings` (its `spp` the render's
    /// total), of the pixels `crop` (the whole image if `None`), of the
    /// sample range `shard` when it is one, with the scene overrides `set`.
    pub fn of(
        s: &RenderSettings,
        crop: Option<PixelBounds>,
        shard: Option<&std::ops::Range<u32>>,
        set: &[String],
    ) -> Fingerprint {
        let crop = crop.map_or_else(
            || "none".to_owned(),
            |c| format!("{},{},{},{}", c.x0, c.x1, c.y0, c.y1),
        );
        let shard = shard.map_or_else(|| "none".to_owned(), |r| format!("{}..{}", r.start, r.end));
        let set = toml::Value::Array(set.iter().cloned().map(toml::Value::String).collect());
        let fields = [
            ("width", s.width.to_string()),
            ("height", s.height.to_string()),
            ("strategy", s.strategy.to_string()),
            ("sampler", s.sampler.to_string()),
            ("sampler_revision", s.sampler.revision().to_string()),
            ("seed", s.seed.to_string()),
            ("max_depth", s.max_depth.to_string()),
            ("roulette_depth", s.roulette_depth.to_string()),
            ("max_steps", s.max_steps.to_string()),
            ("pixel_epsilon", s.pixel_epsilon.to_string()),
            ("epsilon", s.epsilon_rel.to_string()),
            ("naive", (s.marching == Marching::Naive).to_string()),
            ("replicates", s.replicate_count().to_string()),
            ("spp", s.spp.to_string()),
            ("crop", crop),
            ("shard", shard),
            ("set", set.to_string()),
        ];
        Fingerprint {
            fields: fields.into_iter().map(|(k, v)| (k.to_owned(), v)).collect(),
        }
    }

    /// Reads a stored fingerprint back. Fields it lacks (a checkpoint of an
    /// older lueur) read as absent.
    pub fn parse(text: &str) -> Fingerprint {
        let (plain, set) = match text.find("set=") {
            Some(i) if i == 0 || text.as_bytes()[i - 1] == b' ' => {
                (&text[..i], Some(&text[i + 4..]))
            }
            _ => (text, None),
        };
        let mut fields: Vec<(String, String)> = plain
            .split_whitespace()
            .filter_map(|f| f.split_once('='))
            .map(|(k, v)| (k.to_owned(), v.to_owned()))
            .collect();
        if let Some(set) = set {
            fields.push(("set".to_owned(), set.trim().to_owned()));
        }
        Fingerprint { fields }
    }

    /// The value of field `name`.
    pub fn get(&self, name: &str) -> Option<&str> {
        self.fields
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// Whether the total spp is part of what a sample's value depends on:
    /// for the samplers that lay their patterns out over it.
    pub fn spp_matters(&self) -> bool {
        self.get("sampler")
            .and_then(lueur_sampling::SamplerKind::from_name)
            .is_some_and(|s| s.depends_on_spp())
    }

    /// Sets field `name` (appended if absent).
    pub fn set(&mut self, name: &str, value: String) {
        match self.fields.iter_mut().find(|(k, _)| k == name) {
            Some((_, v)) => *v = value,
            None => self.fields.push((name.to_owned(), value)),
        }
    }

    /// The scene overrides recorded (`--set KEY=VALUE`, in order).
    pub fn overrides(&self) -> Vec<String> {
        let Some(text) = self.get("set") else {
            return Vec::new();
        };
        let parsed: Result<toml::Table, _> = format!("set = {text}").parse();
        parsed
            .ok()
            .and_then(|t| t.get("set").and_then(|v| v.as_array()).cloned())
            .unwrap_or_default()
            .into_iter()
            .filter_map(|v| v.as_str().map(str::to_owned))
            .collect()
    }

    /// Each setting that differs between `self` (`mine`) and `other`, as
    /// "name: mine, other", skipping the render's targets (its spp and
    /// shard range) unless `spp_matters`.
    pub fn differences(&self, other: &Fingerprint, spp_matters: bool) -> Vec<String> {
        let mut names: Vec<&str> = self.fields.iter().map(|(k, _)| k.as_str()).collect();
        for (k, _) in &other.fields {
            if !names.contains(&k.as_str()) {
                names.push(k);
            }
        }
        names
            .into_iter()
            .filter(|n| !TARGETS.contains(n) || (spp_matters && *n == "spp"))
            .filter_map(|n| {
                // Fields added later read, where a checkpoint lacks them, as
                // the value every older render had.
                let old = match n {
                    "crop" | "shard" => Some("none"),
                    "set" => Some("[]"),
                    "sampler_revision" => Some("1"),
                    _ => None,
                };
                let (a, b) = (self.get(n).or(old), other.get(n).or(old));
                (a != b).then(|| {
                    format!(
                        "{n}: {}, {}",
                        a.unwrap_or("(not recorded)"),
                        b.unwrap_or("(not recorded)")
                    )
                })
            })
            .collect()
    }
}

impl std::fmt::Display for Fingerprint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (i, (k, v)) in self.fields.iter().enumerate() {
            if i > 0 {
                f.write_str(" ")?;
            }
            write!(f, "{k}={v}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fingerprint_reads_back_with_its_overrides() {
        let set = vec![
            "lights[0].radiance=[1, 1, 1]".to_owned(),
            "render.strategy=\"mis\"".to_owned(),
        ];
        let crop = PixelBounds {
            x0: 1,
            x1: 5,
            y0: 2,
            y1: 3,
        };
        let naive = RenderSettings {
            marching: Marching::Naive,
            ..Default::default()
        };
        let fp = Fingerprint::of(&naive, Some(crop), Some(&(4..8)), &set);
        let back = Fingerprint::parse(&fp.to_string());
        assert_eq!(back, fp);
        assert_eq!(back.overrides(), set);
        assert_eq!(back.get("crop"), Some("1,5,2,3"));
        assert_eq!(back.get("naive"), Some("true"));
        let other = Fingerprint::of(
            &RenderSettings {
                seed: 3,
                spp: 7,
                ..naive.clone()
            },
            Some(crop),
            None,
            &set,
        );
        assert_eq!(fp.differences(&other, false), vec!["seed: 0, 3"]);
        assert_eq!(
            fp.differences(&other, true),
            vec!["seed: 0, 3", "spp: 64, 7"]
        );
    }

    /// Checkpoints written before fields had names read as such.
    #[test]
    fn an_older_fingerprint_reads_with_fields_missing() {
        let old = Fingerprint::parse("width=8 height=4 strategy=mis naive=false");
        assert_eq!(old.get("width"), Some("8"));
        assert_eq!(old.get("crop"), None);
        assert!(old.overrides().is_empty());
        // A checkpoint of an older lueur had no crop, shard or overrides.
        let now = Fingerprint::parse("width=8 height=4 strategy=mis naive=false crop=none set=[]");
        assert!(old.differences(&now, false).is_empty());
        let cropped = Fingerprint::parse("width=8 height=4 strategy=mis naive=false crop=1,2,1,2");
        assert_eq!(
            old.differences(&cropped, false),
            vec!["crop: none, 1,2,1,2"]
        );
    }

    /// A checkpoint made before a fix raised its sampler's revision is not resumed
    /// with the new values; one of a sampler the fix left alone still is.
    #[test]
    fn a_sampler_s_fixed_values_are_not_mixed_with_its_old_ones() {
        use lueur_sampling::SamplerKind;
        let now = |sampler: SamplerKind| {
            let settings = RenderSettings {
                sampler,
                ..Default::default()
            };
            Fingerprint::of(&settings, None, None, &[])
        };
        // As an older lueur wrote it: no revision recorded.
        let before = |fp: &Fingerprint| {
            let kind = fp.get("sampler").and_then(SamplerKind::from_name);
            let revision = kind.expect("a sampler").revision();
            Fingerprint::parse(
                &fp.to_string()
                    .replace(&format!(" sampler_revision={revision}"), ""),
            )
        };
        let sobol = now(SamplerKind::SobolXor);
        assert_eq!(before(&sobol).get("sampler_revision"), None);
        assert!(before(&sobol).differences(&sobol, false).is_empty());
        let pmj02 = now(SamplerKind::Pmj02);
        assert_eq!(
            before(&pmj02).differences(&pmj02, false),
            vec!["sampler_revision: 1, 2"]
        );
    }
}
