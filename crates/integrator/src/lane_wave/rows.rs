//! The lane wave's state: blocks of [`LANES`] paths, each field a row of the block, so that
//! a kernel loads and stores a field of a vector of paths at once.

use lueur_sdf_math::{Lane, LaneVec3, MAX_LANES};

/// Paths per block: the widest vector, on every level, so that a block's paths are the
/// same whatever the level (a narrower level takes a block in several vectors).
pub(super) const LANES: usize = MAX_LANES;

/// A block: [`COUNT`] rows of [`LANES`] paths.
pub(super) type Block = [[f32; LANES]; COUNT];

/// The path (a vector's first coordinate; the others follow).
/// - `O`, `D`: the ray it traces next (its origin lifted off the last surface);
/// - `FROM`, `FROM_N`: the last vertex's point and normal (the camera and zero at first),
///   from which lights are intersected and emission weighed;
/// - `BETA`, `L`: its throughput and estimate; `DEPTH`: scattering events so far;
/// - `EMIT_MIS`, `EMIT_PDF`: how emission found along `D` counts (1 and the BSDF's pdf
///   for the power heuristic, 0 for in full);
/// - `ALIVE`: the lane holds a path.
pub(super) const O: usize = 0;
pub(super) const D: usize = 3;
pub(super) const FROM: usize = 6;
pub(super) const FROM_N: usize = 9;
pub(super) const BETA: usize = 12;
pub(super) const L: usize = 15;
pub(super) const DEPTH: usize = 18;
pub(super) const EMIT_MIS: usize = 19;
pub(super) const EMIT_PDF: usize = 20;
pub(super) const ALIVE: usize = 21;

/// What the path ray found: the march's end `T`, whether it hit (`HIT`) or gave up
/// (`GAVE_UP`), its `STEPS`, the object `NEAR` where it ended, the hit thresholds it was
/// marched with (`EPS_ABS`, `EPS_REL`); the nearest light it meets (`LIGHT`, its index or
/// -1) at `LIGHT_T`.
pub(super) const T: usize = 22;
pub(super) const HIT: usize = 23;
pub(super) const GAVE_UP: usize = 24;
pub(super) const STEPS: usize = 25;
pub(super) const NEAR: usize = 26;
pub(super) const EPS_ABS: usize = 27;
pub(super) const LIGHT: usize = 28;
pub(super) const LIGHT_T: usize = 29;

/// The vertex: whether the lane shades one this round (`SHADE`) and is diffuse
/// (`DIFFUSE`), its albedo, its shading point `P`, normal `N` and the `ORIGIN` rays leave
/// from, and its numbers (`U_EMITTER`, two; `U_BSDF`, two; `U_ROULETTE`).
pub(super) const SHADE: usize = 30;
pub(super) const DIFFUSE: usize = 31;
pub(super) const ALBEDO: usize = 32;
pub(super) const P: usize = 35;
pub(super) const N: usize = 38;
pub(super) const ORIGIN: usize = 41;
pub(super) const U_EMITTER: usize = 44;
pub(super) const U_BSDF: usize = 46;
pub(super) const U_ROULETTE: usize = 48;

/// Next-event estimation: `NEE` is 0 (nothing), 1 (a shadow ray along `SD` to `SDIST`
/// that brings `C` if free, `FREE` once traced) or 2 (the estimate made again alone, its
/// aim not at its point).
pub(super) const NEE: usize = 49;
pub(super) const SD: usize = 50;
pub(super) const SDIST: usize = 53;
pub(super) const C: usize = 54;
pub(super) const FREE: usize = 57;

/// The scatter: its direction `WI`, weight `WEIGHT` and pdf `WPDF`, whether it carries
/// any (`WVALID`); `ENDED`: the path ended this round.
pub(super) const WI: usize = 58;
pub(super) const WEIGHT: usize = 61;
pub(super) const WPDF: usize = 64;
pub(super) const WVALID: usize = 65;
pub(super) const ENDED: usize = 66;
pub(super) const EPS_REL: usize = 67;

/// The shell of the surface hit (`SurfaceHit::epsilon`).
pub(super) const SHELL: usize = 68;

/// Rows per block.
pub(super) const COUNT: usize = 69;

/// A block in its first state: no path, every value finite.
pub(super) const EMPTY: Block = [[0.0; LANES]; COUNT];

#[inline(always)]
pub(super) fn ld<V: Lane>(b: &Block, row: usize, at: usize) -> V {
    V::load(&b[row][at..at + V::LANES])
}

#[inline(always)]
pub(super) fn st<V: Lane>(v: V, b: &mut Block, row: usize, at: usize) {
    v.store(&mut b[row][at..at + V::LANES]);
}

/// A row of 0 and 1 as a mask.
#[inline(always)]
pub(super) fn ld_mask<V: Lane>(b: &Block, row: usize, at: usize) -> V::Mask {
    ld::<V>(b, row, at).gt(V::splat(0.0))
}

#[inline(always)]
pub(super) fn st_mask<V: Lane>(m: V::Mask, b: &mut Block, row: usize, at: usize) {
    st(V::select(m, V::splat(1.0), V::splat(0.0)), b, row, at);
}

#[inline(always)]
pub(super) fn ld3<V: Lane>(b: &Block, row: usize, at: usize) -> LaneVec3<V> {
    LaneVec3::new(ld(b, row, at), ld(b, row + 1, at), ld(b, row + 2, at))
}

#[inline(always)]
pub(super) fn st3<V: Lane>(v: LaneVec3<V>, b: &mut Block, row: usize, at: usize) {
    st(v.x, b, row, at);
    st(v.y, b, row + 1, at);
    st(v.z, b, row + 2, at);
}

/// Per coordinate, `a` where `m`, else `b`.
#[inline(always)]
pub(super) fn select3<V: Lane>(m: V::Mask, a: LaneVec3<V>, b: LaneVec3<V>) -> LaneVec3<V> {
    LaneVec3::new(
        V::select(m, a.x, b.x),
        V::select(m, a.y, b.y),
        V::select(m, a.z, b.z),
    )
}

/// A lane's vector from its block, in scalar code.
#[inline(always)]
pub(super) fn get3(b: &Block, row: usize, lane: usize) -> glam::Vec3 {
    glam::Vec3::new(b[row][lane], b[row + 1][lane], b[row + 2][lane])
}

/// Writes a lane's vector into its block, in scalar code.
#[inline(always)]
pub(super) fn set3(b: &mut Block, row: usize, lane: usize, v: glam::Vec3) {
    b[row][lane] = v.x;
    b[row + 1][lane] = v.y;
    b[row + 2][lane] = v.z;
}
