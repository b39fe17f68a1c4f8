//! End-to-end tests of the whole pipeline: scene files in, films out.
//!
//! Statistical tests state their confidence next to their threshold and use
//! fixed seeds, so they are reproducible; each would fail on a real bias of
//! a few percent (see `analytic::a_wrong_answer_is_caught`). They render
//! with independent samples whatever the default sampler: a film's standard
//! error (sample variance / n) is the true error of the mean only for them;
//! for low-discrepancy points it overestimates it, and the z-tests would
//! lose their power.

mod common;

// Same scene, seed and spp give the same film bit for bit, whatever the
// thread count.
mod determinism;

// Closed-form radiance: furnaces, a sphere light and a quad light over a plane.
mod analytic;

// The strategies against each other on the shipped scenes, and the report's
// variance claim.
mod strategies;

// Degenerate but valid scenes, and the same scene scaled and moved far away.
mod degenerate;

// The fast marching against the naive reference: the same images.
mod marching;

// A small light's answer against its closed form, whatever the size of the floor under it,
// the scene's scale or its distance from the origin; a millimetre sphere's shadow on a
// ten-kilometre floor.
mod scale_free;

// Error bars against a converged reference, for every randomized sampler:
// the replicates' variance is the true error.
mod calibration;

// Hostile input for the scene parser: random and mutated files never panic
// or hang, errors name a line and key, and what parses renders.
mod fuzz;
