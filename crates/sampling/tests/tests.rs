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

/// The point-set library: generators in [0, 1), nets and strata, published
/// Sobol' and Halton points, discrepancies against closed forms and SciPy.
mod pointsets;

/// Every kind of the renderer's sampler: determinism in any order, nets and
/// strata per pixel, decorrelated dimensions, ZSobol's complementary pixels.
mod sampler_kinds;

/// Integration error as UTK measures it: MSE over randomizations for
/// Gaussian, half-plane and disk integrands, convergence slopes per kind,
/// and UTK's published magnitudes for jittered points.
mod integration_error;

/// The radially averaged power spectrum: flat for independent points, blue
/// for jittered and Poisson-disk points.
mod spectrum;

/// pmj02 sequences: power-of-two prefixes are (0, m, 2)-nets, power-of-four
/// prefixes jittered grids, per pixel in the sampler too.
mod pmj02;
