//! Fast marching in groups ([`Schedule::Groups`]): each vector of queued rays clipped
//! against every object's bound and marched through its candidates at once, the
//! candidates as lane masks and the march's state in registers.

use lueur_sdf_math::{
    GroupField, GroupRays, Lane, LaneKernel, LaneVec3, MAX_LANES, OVER_RELAXATION, RayClipLanes,
    TraceOutcome, sphere_trace_relaxed_group,
};

#[cfg(doc)]
use super::{CandidateLanes, Schedule};
use super::{Covered, Geometry, MAX_GROUP_OBJECTS, MarchBatch, clip_entry, lower_by};

/// The kernel of [`Schedule::Groups`]: each vector of queued rays clipped against every
/// object's bound and marched through its candidates at once, to the end of its last ray.
pub(super) struct GroupMarch<'a> {
    pub geometry: &'a Geometry,
    pub batch: &'a mut MarchBatch,
}

impl LaneKernel for GroupMarch<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(self) {
        let GroupMarch { geometry, batch } = self;
        let lanes = L::LANES.min(MAX_LANES);
        let (queued, rows) = (
            std::mem::take(&mut batch.queued),
            std::mem::take(&mut batch.rows),
        );
        let index: [f32; MAX_LANES] = std::array::from_fn(|i| i as f32);
        let mut outcomes = [TraceOutcome::Miss { steps: 0 }; MAX_LANES];
        let mut nearest = [0f32; MAX_LANES];
        for (group, v, lane0) in MarchBatch::vectors(queued.len(), &rows, lanes) {
            let row = |i: usize| -> L { L::load(&v[i][lane0..lane0 + lanes]) };
            let (origin, dir) = (
                LaneVec3::new(row(0), row(1), row(2)),
                LaneVec3::new(row(3), row(4), row(5)),
            );
            let (eps_abs, eps_rel, t_min, t_max) = (row(6), row(7), row(8), row(9));
            let clip = RayClipLanes::from_lanes(origin, dir, [eps_abs, eps_rel, t_min, t_max]);
            let live = u32::MAX >> (32 - group.len());
            let mut field = GroupCandidates {
                geometry,
                keep: [L::splat(0.0).gt(L::splat(0.0)); MAX_GROUP_OBJECTS],
                first: L::splat(0.0),
                last: L::splat(0.0),
            };
            let mut covered = Covered::<L>::new();
            for (k, entry) in geometry.order.iter().enumerate() {
                if let Some(interval) = clip_entry(entry, &clip, live, (t_min, t_max)) {
                    let first = L::and(interval.2, L::not(covered.seen));
                    field.first = L::select(first, L::splat(entry.id), field.first);
                    field.keep[k] = interval.2;
                    covered.add(interval);
                }
            }
            // Lanes past a short last group hold earlier rays: not marched.
            let in_group = L::load(&index[..lanes]).lt(L::splat(group.len() as f32));
            let marched = L::and(covered.seen, in_group);
            let rays = GroupRays {
                origin,
                dir,
                t_min: covered.lo,
                t_max: covered.hi,
                max_steps: row(10),
                eps_abs,
                eps_rel,
                live: marched,
            };
            let ends =
                sphere_trace_relaxed_group(&mut field, geometry.lipschitz, &rays, OVER_RELAXATION);
            ends.store(&mut outcomes);
            field.last.store(&mut nearest[..lanes]);
            // Every ray of the group as marched, in bulk: a lane not marched holds a miss
            // in no step, which is what a ray that meets no candidate gets.
            let n = group.len();
            batch.tags.extend_from_slice(&queued[group]);
            batch.outcomes.extend_from_slice(&outcomes[..n]);
            batch.nearest.extend(nearest[..n].iter().map(|&k| k as u32));
        }
        (batch.queued, batch.rows) = (queued, rows);
    }
}

/// The field of each lane's ray in a group: the union of its candidates, in the fixed
/// order [`Geometry::order`], as [`CandidateLanes`] evaluates it for a stream.
struct GroupCandidates<'a, L: Lane> {
    geometry: &'a Geometry,
    /// Per position in the order, the lanes whose ray has that object as a candidate.
    keep: [L::Mask; MAX_GROUP_OBJECTS],
    /// Per lane: its ray's first candidate, the nearest object before any is evaluated,
    /// and the nearest object at its last evaluation (object indices, exact in f32).
    first: L,
    last: L,
}

impl<L: Lane> GroupField<L> for GroupCandidates<'_, L> {
    #[inline(always)]
    fn distance_lanes(&mut self, p: LaneVec3<L>, going: L::Mask) -> L {
        let mut d = L::splat(f32::INFINITY);
        let mut nearest = self.first;
        for (entry, &keep) in self.geometry.order.iter().zip(&self.keep) {
            let active = L::and(keep, going);
            if L::any(active) {
                lower_by(entry, active, p, &mut d, &mut nearest);
            }
        }
        self.last = L::select(going, nearest, self.last);
        d
    }
}
