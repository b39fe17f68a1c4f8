//! Warps from the unit square to disks, hemispheres, spheres and cones, with
//! their pdfs (solid angle for directions, area for the disk) and, where they
//! are cheap, their inverses. Directions are in the local z-up frame.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI, TAU};

use glam::{Vec2, Vec3};

use lueur_sdf_math::{Lane, LaneVec3};

use crate::math::{
    ONE_MINUS_EPSILON, clamp_u, clamp_u_lanes, clamp_u2, safe_sqrt, safe_sqrt_lanes, sin_cos_turns,
};

/// Azimuth of `(x, y)` in `[0, 2pi)`.
#[inline]
fn azimuth(x: f32, y: f32) -> f32 {
    let phi = y.atan2(x);
    if phi < 0.0 { phi + TAU } else { phi }
}

/// `phi / 2pi` as a uniform number in `[0, 1)`.
#[inline]
fn azimuth_to_u(x: f32, y: f32) -> f32 {
    clamp_u(azimuth(x, y) / TAU)
}

/// Maps the unit square onto the unit disk with Shirley and Chiu's concentric
/// mapping (pbrt-v4 §A.5.1, `SampleUniformDiskConcentric`), which keeps
/// strata compact and is continuous, unlike the polar mapping.
pub fn sample_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let [x, y] = sample_uniform_disk_concentric_lanes([u.x, u.y]);
    Vec2::new(x, y)
}

/// [`sample_uniform_disk_concentric`] per lane, its one definition: the wedge chosen by
/// selects and the angle's sine and cosine by the polynomial of `math.rs`, so that a wave
/// of BSDF samples is drawn in lanes with the bits one sample alone gets.
#[inline(always)]
fn sample_uniform_disk_concentric_lanes<L: Lane>([u0, u1]: [L; 2]) -> [L; 2] {
    let (zero, one, two) = (L::splat(0.0), L::splat(1.0), L::splat(2.0));
    let x = two * clamp_u_lanes(u0) - one;
    let y = two * clamp_u_lanes(u1) - one;
    // The wedge of the larger coordinate, which is the radius; the angle in turns
    // (pi/4 is 1/8) from the ratio of the smaller to it, folded into [0, 1).
    let x_wedge = x.abs().gt(y.abs());
    let r = L::select(x_wedge, x, y);
    let ratio = L::select(x_wedge, y, x) / r;
    let eighth = L::splat(0.125);
    let turns = L::select(x_wedge, eighth * ratio, L::splat(0.25) - eighth * ratio);
    let (sin, cos) = sin_cos_turns(L::select(turns.lt(zero), turns + one, turns));
    // The centre (0 / 0 above) maps to itself.
    let centre = L::not(r.abs().gt(zero));
    [
        L::select(centre, zero, r * cos),
        L::select(centre, zero, r * sin),
    ]
}

/// Inverse of [`sample_uniform_disk_concentric`] (pbrt-v4 §A.5.1,
/// `InvertUniformDiskConcentricSample`). `p` must lie in the unit disk.
pub fn invert_uniform_disk_concentric(p: Vec2) -> Vec2 {
    let theta = p.y.atan2(p.x); // in [-pi, pi]
    let mut r = p.length();
    let (ux, uy);
    if theta.abs() < FRAC_PI_4 || theta.abs() > 3.0 * FRAC_PI_4 {
        r = r.copysign(p.x);
        ux = r;
        uy = if p.x < 0.0 {
            if p.y < 0.0 {
                (PI + theta) * r / FRAC_PI_4
            } else {
                (theta - PI) * r / FRAC_PI_4
            }
        } else {
            theta * r / FRAC_PI_4
        };
    } else {
        r = r.copysign(p.y);
        uy = r;
        ux = if p.y < 0.0 {
            -(FRAC_PI_2 + theta) * r / FRAC_PI_4
        } else {
            (FRAC_PI_2 - theta) * r / FRAC_PI_4
        };
    }
    Vec2::new(clamp_u((ux + 1.0) / 2.0), clamp_u((uy + 1.0) / 2.0))
}

/// Area pdf of the uniform disk warps: `1 / pi`.
pub fn uniform_disk_pdf() -> f32 {
    FRAC_1_PI
}

/// Uniform direction on the `z >= 0` hemisphere (pbrt-v4 §A.5.2):
/// `z = u0`, `phi = 2pi u1`.
pub fn sample_uniform_hemisphere(u: Vec2) -> Vec3 {
    let u = clamp_u2(u);
    let z = u.x;
    let r = safe_sqrt(1.0 - z * z);
    let phi = TAU * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Solid-angle pdf of [`sample_uniform_hemisphere`]: `1 / 2pi` (pbrt-v4 §A.5.2).
pub fn uniform_hemisphere_pdf() -> f32 {
    0.5 * FRAC_1_PI
}

/// Inverse of [`sample_uniform_hemisphere`] for a unit `w` with `w.z >= 0`.
pub fn invert_uniform_hemisphere(w: Vec3) -> Vec2 {
    Vec2::new(clamp_u(w.z), azimuth_to_u(w.x, w.y))
}

/// Cosine-weighted direction on the `z >= 0` hemisphere by Malley's method:
/// lift a concentric disk sample onto the hemisphere (pbrt-v4 §A.5.3). The
/// sample can land exactly on the horizon (`z = 0`), where the pdf is 0.
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    sample_cosine_hemisphere_lanes([u.x, u.y]).into()
}

/// [`sample_cosine_hemisphere`] per lane, its one definition.
#[inline(always)]
pub fn sample_cosine_hemisphere_lanes<L: Lane>(u: [L; 2]) -> LaneVec3<L> {
    let [x, y] = sample_uniform_disk_concentric_lanes(u);
    let z = safe_sqrt_lanes(L::splat(1.0) - x * x - y * y);
    LaneVec3::new(x, y, z)
}

/// Solid-angle pdf of [`sample_cosine_hemisphere`]: `max(cos_theta, 0) / pi`
/// (pbrt-v4 §A.5.3). NaN input gives 0.
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cosine_hemisphere_pdf_lanes(cos_theta)
}

/// [`cosine_hemisphere_pdf`] per lane, its one definition.
#[inline(always)]
pub fn cosine_hemisphere_pdf_lanes<L: Lane>(cos_theta: L) -> L {
    cos_theta.max(L::splat(0.0)) * L::splat(FRAC_1_PI)
}

/// Inverse of [`sample_cosine_hemisphere`]: the concentric inverse of the
/// projection of `w` onto the disk (pbrt-v4 §A.5.3,
/// `InvertCosineHemisphereSample`).
pub fn invert_cosine_hemisphere(w: Vec3) -> Vec2 {
    invert_uniform_disk_concentric(Vec2::new(w.x, w.y))
}

/// Uniform direction on the unit sphere (pbrt-v4 §A.5.2):
/// `z = 1 - 2 u0`, `phi = 2pi u1`.
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    sample_uniform_sphere_lanes([u.x, u.y]).into()
}

/// [`sample_uniform_sphere`] per lane, its one definition.
#[inline(always)]
pub(crate) fn sample_uniform_sphere_lanes<L: Lane>([u0, u1]: [L; 2]) -> LaneVec3<L> {
    let one = L::splat(1.0);
    let z = one - L::splat(2.0) * clamp_u_lanes(u0);
    let r = safe_sqrt_lanes(one - z * z);
    let (sin, cos) = sin_cos_turns(clamp_u_lanes(u1));
    LaneVec3::new(r * cos, r * sin, z)
}

/// Solid-angle pdf of [`sample_uniform_sphere`]: `1 / 4pi` (pbrt-v4 §A.5.2).
pub fn uniform_sphere_pdf() -> f32 {
    0.25 * FRAC_1_PI
}

/// Inverse of [`sample_uniform_sphere`] for a unit `w`.
pub fn invert_uniform_sphere(w: Vec3) -> Vec2 {
    Vec2::new(clamp_u((1.0 - w.z) / 2.0), azimuth_to_u(w.x, w.y))
}

/// `1 - cos_theta_max` for a clamped cone, computed so that it stays exact
/// where `cos_theta_max` rounds to 1.
#[inline]
fn cone_one_minus_cos(cos_theta_max: f32) -> f32 {
    1.0 - cos_theta_max.clamp(-1.0, 1.0)
}

/// Uniform direction in the cone of half-angle `acos(cos_theta_max)` around
/// `+z` (pbrt-v4 §A.5.4): `cos_theta = (1 - u0) + u0 cos_theta_max`. The sine
/// is computed as `sqrt((1 - cos)(1 + cos))` from `1 - cos = u0 (1 -
/// cos_theta_max)`, which keeps narrow cones accurate. `cos_theta_max` is
/// clamped to `[-1, 1]`; a cone of zero width returns `+z`.
pub fn sample_uniform_cone(u: Vec2, cos_theta_max: f32) -> Vec3 {
    let u = clamp_u2(u);
    let one_minus_cos_max = if cos_theta_max.is_nan() {
        0.0
    } else {
        cone_one_minus_cos(cos_theta_max)
    };
    let one_minus_cos = u.x * one_minus_cos_max;
    let cos_theta = 1.0 - one_minus_cos;
    let sin_theta = safe_sqrt(one_minus_cos * (2.0 - one_minus_cos));
    let phi = TAU * u.y;
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// Solid-angle pdf of [`sample_uniform_cone`] for directions inside the cone:
/// `1 / (2pi (1 - cos_theta_max))` (pbrt-v4 §A.5.4). A cone of zero width
/// (`cos_theta_max >= 1`, or NaN) is a Dirac delta, reported as 0: "no
/// weight", never infinity.
pub fn uniform_cone_pdf(cos_theta_max: f32) -> f32 {
    if cos_theta_max.is_nan() {
        return 0.0;
    }
    let one_minus_cos_max = cone_one_minus_cos(cos_theta_max);
    if one_minus_cos_max > 0.0 {
        1.0 / (TAU * one_minus_cos_max)
    } else {
        0.0
    }
}

/// Inverse of [`sample_uniform_cone`] for a unit `w` inside the cone.
pub fn invert_uniform_cone(w: Vec3, cos_theta_max: f32) -> Vec2 {
    let one_minus_cos_max = cone_one_minus_cos(cos_theta_max);
    let u0 = if one_minus_cos_max > 0.0 {
        (1.0 - w.z) / one_minus_cos_max
    } else {
        0.0
    };
    Vec2::new(u0.clamp(0.0, ONE_MINUS_EPSILON), azimuth_to_u(w.x, w.y))
}

#[cfg(test)]
mod tests {
    use super::*;

    const CORNERS: [f32; 4] = [0.0, 0.25, 0.5, ONE_MINUS_EPSILON];

    fn grid() -> impl Iterator<Item = Vec2> {
        let n = 17;
        (0..n * n).map(move |i| {
            Vec2::new(
                (i % n) as f32 / n as f32 + 0.013,
                (i / n) as f32 / n as f32 + 0.021,
            )
        })
    }

    fn check_round_trip(name: &str, warp: impl Fn(Vec2) -> Vec3, invert: impl Fn(Vec3) -> Vec2) {
        for u in grid() {
            let back = invert(warp(u));
            assert!((back - u).length() < 2e-4, "{name}: {u} -> {back}");
        }
    }

    #[test]
    fn inverses_round_trip() {
        check_round_trip(
            "uniform hemisphere",
            sample_uniform_hemisphere,
            invert_uniform_hemisphere,
        );
        check_round_trip(
            "cosine hemisphere",
            sample_cosine_hemisphere,
            invert_cosine_hemisphere,
        );
        check_round_trip(
            "uniform sphere",
            sample_uniform_sphere,
            invert_uniform_sphere,
        );
        check_round_trip(
            "cone",
            |u| sample_uniform_cone(u, 0.3),
            |w| invert_uniform_cone(w, 0.3),
        );
        for u in grid() {
            let back = invert_uniform_disk_concentric(sample_uniform_disk_concentric(u));
            assert!((back - u).length() < 2e-4, "disk: {u} -> {back}");
        }
    }

    #[test]
    fn unit_length_and_in_domain_at_corners() {
        for &a in &CORNERS {
            for &b in &CORNERS {
                let u = Vec2::new(a, b);
                for (name, w) in [
                    ("uniform hemisphere", sample_uniform_hemisphere(u)),
                    ("cosine hemisphere", sample_cosine_hemisphere(u)),
                    ("uniform sphere", sample_uniform_sphere(u)),
                    ("cone", sample_uniform_cone(u, 0.5)),
                    ("narrow cone", sample_uniform_cone(u, 1.0 - 1e-7)),
                    ("full cone", sample_uniform_cone(u, -1.0)),
                ] {
                    assert!(
                        w.is_finite() && (w.length() - 1.0).abs() < 1e-5,
                        "{name} at {u}: {w}"
                    );
                }
                assert!(sample_uniform_hemisphere(u).z >= 0.0);
                assert!(sample_cosine_hemisphere(u).z >= 0.0);
                assert!(sample_uniform_cone(u, 0.5).z >= 0.5 - 1e-6);
                assert!(sample_uniform_disk_concentric(u).length() <= 1.0 + 1e-6);
            }
        }
    }

    #[test]
    fn pdfs_are_guarded() {
        assert_eq!(cosine_hemisphere_pdf(-0.5), 0.0);
        assert_eq!(cosine_hemisphere_pdf(f32::NAN), 0.0);
        assert_eq!(uniform_cone_pdf(1.0), 0.0);
        assert_eq!(uniform_cone_pdf(f32::NAN), 0.0);
        assert!(uniform_cone_pdf(ONE_MINUS_EPSILON).is_finite());
        assert!((uniform_cone_pdf(-1.0) - uniform_sphere_pdf()).abs() < 1e-7);
        assert!((uniform_cone_pdf(0.0) - uniform_hemisphere_pdf()).abs() < 1e-7);
        assert_eq!(sample_uniform_cone(Vec2::splat(0.7), 1.0), Vec3::Z);
    }
}
