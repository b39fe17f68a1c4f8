//! The text of `lueur render --help` below the flags: the strategies and
//! samplers, one line each, as a pbrt or Mitsuba user looks for them. The
//! lines are the kinds' own summaries, so a new kind cannot be left out.

use lueur_sampling::SamplerKind;
use lueur_scene::Strategy;

/// The strategies and samplers, for `render --help`.
pub fn render_after_help() -> String {
    let mut text = String::from("Strategies (--strategy, [render] strategy):\n");
    for s in Strategy::ALL {
        text.push_str(&format!("  {:<12} {}\n", s.name(), s.summary()));
    }
    text.push_str("\nSamplers (--sampler, [render] sampler):\n");
    for &s in SamplerKind::ALL {
        text.push_str(&format!("  {:<12} {}\n", s.name(), s.summary()));
    }
    text.push_str(
        "\nSamplers laid out over the total spp (stratified, lhs, cmj, zsobol) resume and \
         shard only at that total.",
    );
    text
}
