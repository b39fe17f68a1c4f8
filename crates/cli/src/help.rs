//! The text of `lueur render --help` below the flags: the strategies and
//! samplers, one line each, as a pbrt or Mitsuba user looks for them.
//! The matches are exhaustive, so a new kind cannot be left out.

use lueur_sampling::SamplerKind;
use lueur_scene::Strategy;

fn strategy_line(s: Strategy) -> &'static str {
    match s {
        Strategy::Uniform => "uniform hemisphere directions; lights counted when hit",
        Strategy::Cosine => "cosine-weighted hemisphere directions; lights counted when hit",
        Strategy::Light => "directions toward the lights only (biased: misses indirect light)",
        Strategy::Mixture => "one-sample MIS: hemisphere or light with probability 1/2 each",
        Strategy::Mis => "next-event estimation + cosine BSDF sampling, power heuristic (default)",
    }
}

fn sampler_line(s: SamplerKind) -> &'static str {
    match s {
        SamplerKind::Independent => "independent uniform random numbers (PCG32)",
        SamplerKind::Stratified => "jittered strata over the total spp",
        SamplerKind::Lhs => "Latin hypercube over the total spp",
        SamplerKind::Cmj => "correlated multi-jittered (Kensler 2013) over the total spp",
        SamplerKind::Halton => "plain Halton sequence, unrandomized (to measure, not to use)",
        SamplerKind::HaltonOwen => "Halton sequence, Owen-scrambled per pixel",
        SamplerKind::Sobol => "plain Sobol' sequence, unrandomized (to measure, not to use)",
        SamplerKind::SobolXor => "Sobol' sequence, random digital shift (default)",
        SamplerKind::SobolOwen => "padded Owen-scrambled Sobol' (Burley 2020)",
        SamplerKind::ZSobol => "pbrt-v4's ZSobol: blue-noise error across pixels; total spp fixed",
        SamplerKind::R2 => "R2 Kronecker sequence, rotated per pixel",
        SamplerKind::Pmj02 => "progressive multi-jittered (0,2) sequences",
    }
}

/// The strategies and samplers, for `render --help`.
pub fn render_after_help() -> String {
    let mut text = String::from("Strategies (--strategy, [render] strategy):\n");
    for s in Strategy::ALL {
        text.push_str(&format!("  {:<12} {}\n", s.name(), strategy_line(s)));
    }
    text.push_str("\nSamplers (--sampler, [render] sampler):\n");
    for &s in SamplerKind::ALL {
        text.push_str(&format!("  {:<12} {}\n", s.name(), sampler_line(s)));
    }
    text.push_str(
        "\nSamplers laid out over the total spp (stratified, lhs, cmj, zsobol) resume and \
         shard only at that total.",
    );
    text
}
