//! Integration tests of lueur-pointsets, one binary (ripgrep's layout).
//! Every measure uses fixed seeds, so a failure is reproducible.

/// The generators in [0, 1), nets and strata, published Sobol' and Halton
/// points, discrepancies against closed forms and SciPy.
mod pointsets;

/// Integration error as UTK measures it: MSE over randomizations for
/// Gaussian, half-plane and disk integrands, convergence slopes per kind,
/// and UTK's published magnitudes for jittered points.
mod integration_error;

/// The radially averaged power spectrum: flat for independent points, blue
/// for jittered and Poisson-disk points.
mod spectrum;

/// pmj02 sequences: power-of-two prefixes are (0, m, 2)-nets, power-of-four
/// prefixes jittered grids.
mod pmj02;
