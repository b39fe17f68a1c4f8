//! Integration tests of lueur-sampling, one binary (ripgrep's layout).
//! Every statistical test uses a fixed seed, so a failure is reproducible.

/// Shared helpers: fixed-seed uniform numbers, the significance level, and
/// chi-square binning over a quad light's parameter square.
mod common;

/// Chi-square goodness of fit and normalisation of the hemisphere, sphere and
/// cone warps.
mod warps;

/// Chi-square goodness of fit and normalisation of the light samplers (sphere
/// from outside and inside, quad by area, spherical rectangle), and the
/// variance of area versus solid-angle sampling of a quad.
mod lights;

/// The chi-square test has power: it rejects pdfs that are 10% off.
mod power;

/// proptest-driven extremes: corners of `u`, grazing angles, points on or
/// inside lights, tiny and huge lights far away.
mod extremes;

/// Discrete distributions: normalisation, frequencies, zero weights.
mod discrete;

/// MIS weights: partition of unity, zeros, infinities.
mod mis;

/// The renderer-side sampler: determinism, independence, uniformity, golden
/// values.
mod sampler;

/// Every kind of the renderer's sampler: determinism in any order, nets and
/// strata per pixel (pmj02's nets up to 2^10 spp), decorrelated dimensions,
/// ZSobol's complementary pixels.
mod sampler_kinds;
