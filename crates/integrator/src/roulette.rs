//! Russian roulette (pbrt-v4 style), written once over lanes: the wave of records runs
//! it at `f32` (`roulette`), the lane wave on its vectors (`roulette_lanes`).

use glam::Vec3;
use lueur_sdf_math::{Lane, LaneVec3};

/// Whether Russian roulette may end a path that has scattered `depth` times (and so
/// whether its last vertex's roulette number is read).
pub(crate) fn roulette_applies(depth: u32, roulette_depth: u32) -> bool {
    depth >= roulette_depth
}

/// Russian roulette (pbrt-v4 style) after `roulette_depth` scattering
/// events, on the throughput's largest component: the surviving throughput,
/// reweighted by `1 / (1 - q)` so that the estimate stays unbiased, or
/// `None` where the path ends. [`roulette_lanes`] at one lane.
pub(crate) fn roulette(beta: Vec3, depth: u32, roulette_depth: u32, u: f32) -> Option<Vec3> {
    let (survivor, ends) = roulette_lanes(beta.into(), roulette_applies(depth, roulette_depth), u);
    (!ends).then(|| survivor.into())
}

/// Russian roulette per lane, where it `applies`: the throughput `beta` that survives
/// (unchanged where roulette does not play), and the lanes where the path ends. The one
/// definition: the scalar [`roulette`] is this at `f32`, and the lane wave runs it on its
/// vectors.
#[inline(always)]
pub(crate) fn roulette_lanes<L: Lane>(
    beta: LaneVec3<L>,
    applies: L::Mask,
    u: L,
) -> (LaneVec3<L>, L::Mask) {
    let one = L::splat(1.0);
    let max_beta = beta.max_element();
    let plays = L::and(applies, max_beta.lt(one));
    // At one lane, a path that roulette does not play skips the division.
    if !L::any(plays) {
        return (beta, plays);
    }
    let q = (one - max_beta).max(L::splat(0.0));
    let survivor = beta / (one - q);
    let kept = LaneVec3::new(
        L::select(plays, survivor.x, beta.x),
        L::select(plays, survivor.y, beta.y),
        L::select(plays, survivor.z, beta.z),
    );
    (kept, L::and(plays, u.lt(q)))
}
