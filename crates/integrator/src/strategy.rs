//! The ways a path chooses its next direction.

use std::fmt;

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
