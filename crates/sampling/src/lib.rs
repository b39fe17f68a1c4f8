//! Monte Carlo sampling for lueur: warps from uniform numbers to directions
//! with their pdfs, light-sampling geometry (sphere and quad lights), MIS
//! weights, discrete distributions for light selection, the renderer-side
//! deterministic [`Sampler`]. The chi-square machinery that checks all of
//! the above is the dev-only crate `lueur-stats`; the point sets the sampler
//! draws from are `lueur-pointsets`.
//!
//! The design decision that shapes it (from pbrt-v4): every routine takes
//! uniform numbers `u` in `[0, 1)`, never a random number generator, and
//! returns a named struct. Where `u` comes from (independent, stratified or
//! low-discrepancy points) is the [`Sampler`]'s business alone, and a sample
//! is a pure function of `u`, so the statistical tests can drive every warp
//! with the same fixed seeds the renderer uses.
//!
//! What it deliberately is not: no scene, no BSDF, no I/O, no printing. It
//! knows lights only as geometry (a centre and radius, a corner and two
//! edges); it works in `f32` with [`glam`] vectors, and directions are in a
//! local z-up [`Frame`] unless stated otherwise.
//!
//! **Lanes.** Where a renderer draws many samples of one kind together, the
//! routine is written once over `lueur-sdf-math`'s `Lane` number type (one
//! `f32`, or a SIMD vector of them), and the scalar function is its one-lane
//! instance: [`sample_sphere_light_lanes`] gives, in every lane, the bits
//! [`sample_sphere_light`] gives, and [`sample_cosine_hemisphere_lanes`] those of
//! [`sample_cosine_hemisphere`]. Their sines and cosines are our own polynomial
//! (`math.rs`), not libm's, which has no vector form to match. The spherical
//! rectangle is written once over four `f64` lanes ([`SphericalRectangles`], `wide`'s
//! `f64x4`, with its `atan2` and `sin_cos`), and [`SphericalRectangle`] is one lane of
//! it. `wide` chooses its instructions when it is compiled, so every dispatch level of a
//! binary gives the same bits; a build for another CPU (`-C target-cpu`, where `wide`
//! then fuses multiply-adds) or another architecture may round differently. The
//! sampler's numbers for a vector of paths at once are arrays stepped by one loop, which
//! a caller compiled for a SIMD level vectorizes: the independent kind's generators
//! ([`PcgLanes`]) and the default kind's pixel samples ([`SobolXorLanes`], through the
//! same `padded_sobol` function the [`Sampler`] calls), each lane the bits of its path's
//! sampler.
//!
//! **Contract.** Every warp's samples follow its pdf (checked by chi-square
//! goodness-of-fit tests); every pdf is finite and `>= 0`; no NaN or infinity
//! ever leaves a warp; a zero pdf means "no weight". Every `u` is accepted in
//! `[0, 1)` and is clamped internally, so `u = 0` and `u = 1 - ulp` (see
//! [`ONE_MINUS_EPSILON`]) are safe. A light sampler that cannot produce a
//! sample with a finite, positive pdf returns `None`.
//!
//! ```
//! use lueur_sampling::{
//!     Frame, Sampler, SamplerKind, Vec3, cosine_hemisphere_pdf, power_heuristic,
//!     sample_cosine_hemisphere, sample_sphere_light, sphere_light_pdf,
//! };
//!
//! let mut sampler = Sampler::new(SamplerKind::Independent, 42);
//! sampler.start_pixel_sample([10, 20], 0, 0);
//!
//! // A shading point on the ground facing up, a spherical light above it.
//! let (p, n) = (Vec3::ZERO, Vec3::Z);
//! let (center, radius) = (Vec3::new(0.0, 0.0, 4.0), 1.0);
//!
//! // Light sampling, weighted against cosine-weighted BSDF sampling.
//! let light = sample_sphere_light(p, center, radius, sampler.next_2d()).unwrap();
//! assert!((light.wi.length() - 1.0).abs() < 1e-5 && light.pdf > 0.0);
//! let bsdf_pdf = cosine_hemisphere_pdf(light.wi.dot(n));
//! let weight = power_heuristic(1.0, light.pdf, 1.0, bsdf_pdf);
//! assert!((0.0..=1.0).contains(&weight));
//!
//! // BSDF sampling: a local direction moved to world space by the frame.
//! let wi = Frame::from_normal(n).to_world(sample_cosine_hemisphere(sampler.next_2d()));
//! let light_pdf = sphere_light_pdf(p, center, radius, wi); // 0 if wi misses
//! assert!(light_pdf.is_finite() && light_pdf >= 0.0);
//!
//! // A given (pixel, sample index, dimension) always yields the same number.
//! sampler.start_pixel_sample([10, 20], 0, 0);
//! let first = sampler.next_1d();
//! sampler.start_pixel_sample([10, 20], 0, 0);
//! assert_eq!(sampler.next_1d(), first);
//! ```

#![deny(missing_docs)]

mod discrete;
mod frame;
mod light;
mod math;
mod mis;
mod padded_sobol;
mod pcg_lanes;
mod quad_light;
mod sampler;
mod sampler_kind;
mod sphere_light;
mod warp;

pub use glam::{Vec2, Vec3};

pub use discrete::DiscreteDistribution;
pub use frame::{Frame, FrameLanes};
pub use light::{DirectionSample, DirectionSampleLanes};
pub use math::ONE_MINUS_EPSILON;
pub use mis::{balance_heuristic, power_heuristic, power_heuristic_lanes};
pub use padded_sobol::SobolXorLanes;
pub use pcg_lanes::PcgLanes;
pub use quad_light::{
    RECTANGLE_LANES, RectangleFrame, SphericalRectangle, SphericalRectangles, polygon_irradiance,
    quad_area_pdf, quad_solid_angle_pdf, sample_quad_area, sample_quad_solid_angle,
};
pub use sampler::{DIMENSIONS_PER_SAMPLE, Sampler};
pub use sampler_kind::SamplerKind;
pub use sphere_light::{
    sample_sphere_light, sample_sphere_light_lanes, sphere_light_pdf, sphere_solid_angle,
};
pub use warp::{
    cosine_hemisphere_pdf, cosine_hemisphere_pdf_lanes, invert_cosine_hemisphere,
    invert_uniform_cone, invert_uniform_disk_concentric, invert_uniform_hemisphere,
    invert_uniform_sphere, sample_cosine_hemisphere, sample_cosine_hemisphere_lanes,
    sample_uniform_cone, sample_uniform_disk_concentric, sample_uniform_hemisphere,
    sample_uniform_sphere, uniform_cone_pdf, uniform_disk_pdf, uniform_hemisphere_pdf,
    uniform_sphere_pdf,
};
