//! Fast marching in groups ([`Schedule::Groups`]): each vector of queued rays clipped
//! against every object's bound and marched through its candidates at once, the
//! candidates as lane masks and the march's state in registers.

use lueur_sdf_math::{
    GroupEnds, GroupField, GroupRays, Lane, LaneKernel, LaneVec3, MAX_LANES, OVER_RELAXATION,
    RayClipLanes, TraceOutcome, sphere_trace_relaxed_group,
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
            // Lanes past a short last group hold earlier rays: not marched.
            let in_group = L::load(&index[..lanes]).lt(L::splat(group.len() as f32));
            let rays = GroupRays {
                origin: LaneVec3::new(row(0), row(1), row(2)),
                dir: LaneVec3::new(row(3), row(4), row(5)),
                eps_abs: row(6),
                eps_rel: row(7),
                t_min: row(8),
                t_max: row(9),
                max_steps: row(10),
                live: in_group,
            };
            let (ends, last) = geometry.march_vector(&rays);
            ends.store(&mut outcomes);
            last.store(&mut nearest[..lanes]);
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

impl Geometry {
    /// A vector of rays, one per lane of `rays.live` (their `t_min` and `t_max` the range
    /// to clip), clipped against every object's bound and marched through its candidates
    /// to the end of its last ray: each lane's outcome, and the object nearest where it
    /// ended (valid where it hit or gave up). A lane that meets no candidate ends as a
    /// miss in no step. The same outcome for each ray, bit for bit, as the stream gives.
    #[inline(always)]
    pub(crate) fn march_vector<L: Lane>(&self, rays: &GroupRays<L>) -> (GroupEnds<L>, L) {
        let clip = RayClipLanes::from_lanes(
            rays.origin,
            rays.dir,
            [rays.eps_abs, rays.eps_rel, rays.t_min, rays.t_max],
        );
        let live = L::bits(rays.live);
        let mut field = GroupCandidates {
            geometry: self,
            keep: [L::splat(0.0).gt(L::splat(0.0)); MAX_GROUP_OBJECTS],
            first: L::splat(0.0),
            last: L::splat(0.0),
        };
        let mut covered = Covered::<L>::new();
        for (k, entry) in self.order.iter().enumerate() {
            if let Some(interval) = clip_entry(entry, &clip, live, (rays.t_min, rays.t_max)) {
                let first = L::and(interval.2, L::not(covered.seen));
                field.first = L::select(first, L::splat(entry.id), field.first);
                field.keep[k] = interval.2;
                covered.add(interval);
            }
        }
        let marched = GroupRays {
            t_min: covered.lo,
            t_max: covered.hi,
            live: L::and(covered.seen, rays.live),
            ..*rays
        };
        let ends =
            sphere_trace_relaxed_group(&mut field, self.lipschitz, &marched, OVER_RELAXATION);
        (ends, field.last)
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
