//! Fast marching as a stream ([`Schedule::Stream`]): the `Clip` kernel lists each queued
//! ray's candidates and the range they cover, and `CandidateLanes` is the field a lane's
//! ray marches through them, a lane taking the next ray as soon as its own ends.

use glam::Vec3;
use lueur_sdf_math::{
    Lane, LaneKernel, LaneVec3, MAX_LANES, Ray, RayClipLanes, StreamField, TraceOutcome,
    TraceParams,
};

#[cfg(doc)]
use super::Schedule;
use super::{Covered, Geometry, MarchBatch, OBJECTS_PER_MASK, clip_entry, lower_by};

/// The kernel that clips the queued rays of a [`MarchBatch`] against every object's bound,
/// a ray per lane, and keeps each ray's candidates and the range they cover.
pub(super) struct Clip<'a> {
    pub geometry: &'a Geometry,
    pub batch: &'a mut MarchBatch,
}

impl LaneKernel for Clip<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(self) {
        let Clip { geometry, batch } = self;
        let lanes = L::LANES.min(MAX_LANES);
        let mut kept_rows = std::mem::take(&mut batch.kept);
        kept_rows.resize(
            geometry.order.len().div_ceil(OBJECTS_PER_MASK),
            [0.0; MAX_LANES],
        );
        let (queued, rows) = (
            std::mem::take(&mut batch.queued),
            std::mem::take(&mut batch.rows),
        );
        // Lanes past the last ray are never read (`live`).
        for (group, v, lane0) in MarchBatch::vectors(queued.len(), &rows, lanes) {
            let row = |i: usize| -> &[f32] { &v[i][lane0..lane0 + lanes] };
            let (t_min, t_max) = (L::load(row(8)), L::load(row(9)));
            let clip = RayClipLanes::from_lanes(
                LaneVec3::new(L::load(row(0)), L::load(row(1)), L::load(row(2))),
                LaneVec3::new(L::load(row(3)), L::load(row(4)), L::load(row(5))),
                [L::load(row(6)), L::load(row(7)), t_min, t_max],
            );
            // Per lane: the range the kept objects cover, and the candidates kept, in order.
            let live = u32::MAX >> (32 - group.len());
            let mut covered = Covered::<L>::new();
            let chunks = geometry.order.chunks(OBJECTS_PER_MASK);
            for (entries, row) in chunks.zip(kept_rows.iter_mut()) {
                // Each lane's candidates among these objects, in two vector operations per
                // object: no per-lane work, whose branches would be as random as the rays.
                let mut kept = L::splat(0.0);
                for (j, entry) in entries.iter().enumerate() {
                    let Some(interval) = clip_entry(entry, &clip, live, (t_min, t_max)) else {
                        // No ray of the group keeps the object.
                        continue;
                    };
                    kept = L::select(interval.2, kept + L::splat((1u32 << j) as f32), kept);
                    covered.add(interval);
                }
                kept.store(&mut row[..lanes]);
            }
            let Covered { lo, hi, seen } = covered;
            let (mut los, mut his) = ([0f32; MAX_LANES], [0f32; MAX_LANES]);
            lo.store(&mut los[..lanes]);
            hi.store(&mut his[..lanes]);
            let seen = L::bits(seen);
            for (lane, &tag) in queued[group].iter().enumerate() {
                if seen >> lane & 1 == 0 {
                    batch.misses.push(tag);
                    continue;
                }
                let at = |i: usize| v[i][lane0 + lane];
                let (t_min, t_max) = (los[lane], his[lane]);
                let first = batch.candidates.len() as u32;
                for (chunk, row) in kept_rows.iter().enumerate() {
                    let base = (chunk * OBJECTS_PER_MASK) as u32;
                    let mut kept = row[lane] as u32;
                    while kept != 0 {
                        batch.candidates.push(base + kept.trailing_zeros());
                        kept &= kept - 1;
                    }
                }
                batch.spans.push((first, batch.candidates.len() as u32));
                batch.rays.push(Ray {
                    origin: Vec3::new(at(0), at(1), at(2)),
                    dir: Vec3::new(at(3), at(4), at(5)),
                });
                batch.params.push(TraceParams {
                    t_min,
                    t_max,
                    // As queued, but for a cap past 2^24, which every march caps at 2^24
                    // (`MarchBatch::queue`).
                    max_steps: at(10) as u32,
                    eps_abs: at(6),
                    eps_rel: at(7),
                });
                batch.tags.push(tag);
            }
        }
        batch.kept = kept_rows;
        (batch.queued, batch.rows) = (queued, rows);
    }
}

/// The field of each lane's ray in a [`MarchBatch`]: per lane, the union of its ray's
/// candidates, evaluated in the fixed order [`Geometry::order`] whatever the ray, so that
/// a lane's value and nearest object do not depend on the other lanes; an object is
/// evaluated for the whole vector when any lane needs it, and counts only in those.
pub(super) struct CandidateLanes<'a> {
    geometry: &'a Geometry,
    spans: &'a [(u32, u32)],
    candidates: &'a [u32],
    nearest: &'a mut [u32],
    /// Per lane, the ray it marches.
    lane_ray: [Option<usize>; MAX_LANES],
    /// Per position in the order: which lanes' rays have that object as a candidate (1 or
    /// 0, loaded as a vector), and how many.
    member: &'a mut [[f32; MAX_LANES]],
    members: &'a mut [u32],
    /// Per lane: its ray's first candidate, the nearest object before any is evaluated,
    /// and the nearest object at its last evaluation (object indices, exact in f32).
    first: [f32; MAX_LANES],
    last: [f32; MAX_LANES],
}

impl<'a> CandidateLanes<'a> {
    pub fn new(
        geometry: &'a Geometry,
        batch: &'a mut MarchBatch,
    ) -> (Self, &'a [Ray], &'a [TraceParams], &'a mut [TraceOutcome]) {
        let n = batch.rays.len();
        batch.outcomes.clear();
        batch.outcomes.resize(n, TraceOutcome::Miss { steps: 0 });
        batch.nearest.clear();
        batch.nearest.resize(n, 0);
        batch.member.clear();
        batch.member.resize(geometry.order.len(), [0.0; MAX_LANES]);
        batch.members.clear();
        batch.members.resize(geometry.order.len(), 0);
        let lanes = CandidateLanes {
            geometry,
            spans: &batch.spans,
            candidates: &batch.candidates,
            nearest: &mut batch.nearest,
            lane_ray: [None; MAX_LANES],
            member: &mut batch.member,
            members: &mut batch.members,
            first: [0.0; MAX_LANES],
            last: [0.0; MAX_LANES],
        };
        (lanes, &batch.rays, &batch.params, &mut batch.outcomes)
    }

    fn ray_candidates(&self, ray: usize) -> &'a [u32] {
        let (a, b) = self.spans[ray];
        &self.candidates[a as usize..b as usize]
    }
}

impl StreamField for CandidateLanes<'_> {
    fn lipschitz(&self) -> f32 {
        self.geometry.lipschitz
    }

    fn assign(&mut self, lane: usize, ray: Option<usize>) {
        if let Some(old) = self.lane_ray[lane] {
            self.nearest[old] = self.last[lane] as u32;
            for &k in self.ray_candidates(old) {
                self.member[k as usize][lane] = 0.0;
                self.members[k as usize] -= 1;
            }
        }
        self.lane_ray[lane] = ray;
        if let Some(ray) = ray {
            let candidates = self.ray_candidates(ray);
            for &k in candidates {
                self.member[k as usize][lane] = 1.0;
                self.members[k as usize] += 1;
            }
            // A marched ray has at least one candidate.
            self.first[lane] = self.geometry.order[candidates[0] as usize].id;
        }
    }

    #[inline(always)]
    fn distance_lanes<L: Lane>(&mut self, p: LaneVec3<L>) -> L {
        let lanes = L::LANES.min(MAX_LANES);
        let zero = L::splat(0.0);
        let mut d = L::splat(f32::INFINITY);
        let mut nearest = L::load(&self.first[..lanes]);
        let order = self.geometry.order.iter();
        for ((entry, &members), member) in order.zip(&*self.members).zip(&*self.member) {
            if members == 0 {
                continue;
            }
            lower_by(
                entry,
                L::load(&member[..lanes]).gt(zero),
                p,
                &mut d,
                &mut nearest,
            );
        }
        nearest.store(&mut self.last[..lanes]);
        d
    }
}
