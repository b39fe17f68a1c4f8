//! Everything that decides an image besides the scene: image size, samples,
//! the strategy, the sampler and its replicates, and how rays are marched,
//! with the limits a render is held to.

use std::fmt;

use lueur_sampling::SamplerKind;

use crate::QuadSampling;

/// Largest image side accepted.
pub const MAX_IMAGE_SIDE: u32 = 65_536;
/// Largest number of pixels accepted (the film holds 28 bytes per pixel).
pub const MAX_PIXELS: u64 = 1 << 28;
/// Largest spp accepted: beyond 2^24 a pixel's sample count would no longer
/// be exact in the f32 arithmetic of its running mean.
pub const MAX_SPP: u32 = 1 << 24;

/// Everything that decides an image besides the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// How directions are chosen.
    pub strategy: Strategy,
    /// Which point set feeds the estimator.
    pub sampler: SamplerKind,
    /// Independent randomizations the samples are dealt into, whose spread
    /// is the error bar of each pixel (see `replicates.rs`); `None`
    /// for the sampler's default ([`default_replicates`]).
    pub replicates: Option<u32>,
    /// Maximum number of scattering events (0: emitters seen directly).
    pub max_depth: u32,
    /// Scattering events after which Russian roulette may end a path (on
    /// the throughput's largest component; unbiased, it trades noise for
    /// time). At `max_depth` or above it never plays.
    pub roulette_depth: u32,
    /// Seed of every random number of the render.
    pub seed: u64,
    /// Step cap of the sphere tracer; naive marching takes 16 times it (rays crawling
    /// away from a large plane need many steps without bounds to clip them).
    pub max_steps: u32,
    /// Camera rays hit when closer than this many pixel footprints.
    pub pixel_epsilon: f32,
    /// Secondary rays hit when closer than this fraction of the distance
    /// travelled.
    pub epsilon_rel: f32,
    /// How rays are marched through the objects (both modes find the same
    /// surfaces; `Naive` is the reference of the speed-ups).
    pub marching: Marching,
    /// How quad lights are sampled toward a shading point.
    pub quad_sampling: QuadSampling,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 256,
            height: 256,
            spp: 64,
            strategy: Strategy::default(),
            sampler: SamplerKind::default(),
            replicates: None,
            max_depth: 8,
            roulette_depth: 3,
            seed: 0,
            max_steps: 256,
            // A 256th of a pixel: a ray that passes this close to a surface
            // is a hit, so silhouettes and convex creases grow by this
            // much. At a quarter pixel they grew visibly against Mitsuba's
            // exact intersections (24 of 3072 8x8-pixel region-channels
            // beyond 4 sigma at 1024 spp, all on silhouettes and grazing
            // corners; none at a sixteenth: docs/PEERS.md). At a sixteenth
            // the Death Star's rim pixels were still up to 2.6 times too
            // bright against a shell of 1/1000 (333 of 16384 pixels beyond
            // 2%, the image mean +0.086%); at a 64th, 66 pixels and +0.021%;
            // at a 256th, 7 pixels and +0.005% (the bias is linear in the
            // shell). At a 64th, `xtask/peers/open-air.toml` still showed its
            // silhouettes against Mitsuba (RMS z 1.13 over 768 region-channels
            // at 4096 spp, 2 beyond 4 sigma); at a 256th RMS z 1.01, none, as
            // at a 1024th (docs/PEERS.md). Time against a 64th: Death Star
            // 1.016 (95% interval 1.002-1.032), Cornell 1.014 and donut 0.978
            // (intervals holding 1; `cargo xtask ab`, 11 rounds, 2 threads).
            pixel_epsilon: 0.00390625,
            epsilon_rel: 1e-4,
            marching: Marching::default(),
            quad_sampling: QuadSampling::default(),
        }
    }
}

impl RenderSettings {
    /// Checks what a render cannot proceed without.
    pub fn validate(&self) -> Result<(), RenderError> {
        if self.width == 0 || self.height == 0 {
            return Err(RenderError::EmptyImage {
                width: self.width,
                height: self.height,
            });
        }
        if self.spp == 0 {
            return Err(RenderError::NoSamples);
        }
        // The same bounds as scene files, so flags cannot go around them;
        // and a film beyond 2^28 pixels (28 bytes each: 7.5 GB) is refused
        // here rather than failing to allocate halfway.
        if self.width > MAX_IMAGE_SIDE || self.height > MAX_IMAGE_SIDE {
            return Err(RenderError::InvalidSetting(
                "width and height must be at most 65536",
            ));
        }
        if u64::from(self.width) * u64::from(self.height) > MAX_PIXELS {
            return Err(RenderError::InvalidSetting(
                "the image has more than 2^28 pixels (its film would take over 7.5 GB)",
            ));
        }
        if self.spp > MAX_SPP {
            return Err(RenderError::InvalidSetting("spp must be at most 2^24"));
        }
        if let Some(k) = self.replicates {
            self.validate_replicates(k)?;
        }
        if self.max_steps == 0 {
            return Err(RenderError::InvalidSetting("max_steps must be at least 1"));
        }
        for (v, what) in [
            (
                self.pixel_epsilon,
                "pixel_epsilon must be positive and finite",
            ),
            (self.epsilon_rel, "epsilon_rel must be positive and finite"),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(RenderError::InvalidSetting(what));
            }
        }
        Ok(())
    }
}

impl RenderSettings {
    /// The replicates the render deals its samples into: the settings' or
    /// the sampler's default.
    pub fn replicate_count(&self) -> u32 {
        self.replicates
            .unwrap_or_else(|| default_replicates(self.sampler, self.spp))
    }

    fn validate_replicates(&self, k: u32) -> Result<(), RenderError> {
        if k == 0 {
            return Err(RenderError::Replicates("must be at least 1, got 0".into()));
        }
        if k > self.spp {
            return Err(RenderError::Replicates(format!(
                "{k} replicates need at least {k} spp, got {}",
                self.spp
            )));
        }
        if k > 1 && !self.sampler.is_randomized() {
            return Err(RenderError::Replicates(format!(
                "the {} sampler is not randomized: it has no independent replicates \
                 (use 1, or a randomized sampler such as {}-owen)",
                self.sampler,
                if self.sampler == SamplerKind::Halton {
                    "halton"
                } else {
                    "sobol"
                }
            )));
        }
        Ok(())
    }
}

/// Replicates of a randomized sampler when the settings do not say: the
/// smallest count whose error bars are calibrated, as measured in
/// `cargo xtask replicates` (docs/REPLICATES.md). Each further replicate
/// costs stratification (a smaller point set each) and film memory.
pub const DEFAULT_REPLICATES: u32 = 2;

/// The replicates a render of `spp` samples with `sampler` uses by
/// default: one for the independent sampler, whose per-sample variance is
/// already valid (and less noisy than a spread of replicates), and for the
/// plain sequences, which have no randomization to replicate; otherwise
/// [`DEFAULT_REPLICATES`], at most `spp`.
pub fn default_replicates(sampler: SamplerKind, spp: u32) -> u32 {
    if sampler == SamplerKind::Independent || !sampler.is_randomized() {
        1
    } else {
        DEFAULT_REPLICATES.min(spp.max(1))
    }
}

/// How directions are chosen at a diffuse vertex: the knob lueur exists to
/// measure. All strategies handle mirrors as delta events and directional
/// lights by a shadow ray (a delta light can be reached no other way).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Strategy {
    /// Uniform hemisphere directions (pdf 1/2pi); emission counted when a
    /// path hits a light. The report's Figure 3.
    Uniform,
    /// Cosine-weighted hemisphere directions (pdf cos/pi), otherwise as
    /// `Uniform`.
    Cosine,
    /// Directions toward the lights only (the report's Figure 4). Biased:
    /// a direction that no light subtends has zero density, so light that
    /// arrives only indirectly is never seen.
    Light,
    /// One-sample MIS (the report's Figure 5): the uniform hemisphere or a
    /// light with probability 1/2 each, weighted by the mixture pdf (the
    /// average of both). Unbiased.
    Mixture,
    /// Next-event estimation plus cosine BSDF sampling, combined with the
    /// power heuristic (Veach 1997), as pbrt and Mitsuba do.
    #[default]
    Mis,
}

impl Strategy {
    /// Every strategy, in the order the report introduces them.
    pub const ALL: [Strategy; 5] = [
        Strategy::Uniform,
        Strategy::Cosine,
        Strategy::Light,
        Strategy::Mixture,
        Strategy::Mis,
    ];

    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Uniform => "uniform",
            Strategy::Cosine => "cosine",
            Strategy::Light => "light",
            Strategy::Mixture => "mixture",
            Strategy::Mis => "mis",
        }
    }

    /// Parses a name given by [`Strategy::name`].
    pub fn from_name(name: &str) -> Option<Strategy> {
        Strategy::ALL.into_iter().find(|s| s.name() == name)
    }

    /// One line on what the strategy does, for `--help`.
    pub fn summary(self) -> &'static str {
        match self {
            Strategy::Uniform => "uniform hemisphere directions; lights counted when hit",
            Strategy::Cosine => "cosine-weighted hemisphere directions; lights counted when hit",
            Strategy::Light => "directions toward the lights only (biased: misses indirect light)",
            Strategy::Mixture => "one-sample MIS: hemisphere or light with probability 1/2 each",
            Strategy::Mis => {
                "next-event estimation + cosine BSDF sampling, power heuristic (default)"
            }
        }
    }

    /// Whether the estimator converges to the true radiance.
    pub fn is_unbiased(self) -> bool {
        self != Strategy::Light
    }
}

impl fmt::Display for Strategy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How rays are marched through the objects.
///
/// Both modes find the same surfaces (tests hold them to it); `Naive` is kept as the
/// reference every speed-up is measured against, in the same run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Marching {
    /// Plain Hart sphere tracing on the plain union of the objects: every step evaluates
    /// every object; normals by central differences.
    Naive,
    /// Each ray first clipped against every object's bound (a box, or a half-space for
    /// planes): objects whose bound the ray never comes within the hit threshold of are left
    /// out of its march altogether, and the march runs only over the part of the ray some
    /// bound covers. Then over-relaxed sphere tracing (Keinert et al. 2014) on the union of
    /// what is left, where an object whose box is farther than the nearest object found so
    /// far costs one distance to a box, not its own evaluation. The object hit is the one
    /// the last step found nearest (no second pass over the scene); normals by the
    /// tetrahedron (4 evaluations, not 6).
    #[default]
    Fast,
}

/// Settings a render cannot proceed with.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RenderError {
    /// Zero width or height.
    #[error("the image is empty ({width}x{height})")]
    EmptyImage {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// Zero samples per pixel.
    #[error("spp must be at least 1")]
    NoSamples,
    /// Another setting out of its range.
    #[error("{0}")]
    InvalidSetting(&'static str),
    /// Replicates that are zero, more than the spp, or asked of a sampler
    /// without randomization.
    #[error("replicates: {0}")]
    Replicates(String),
}
