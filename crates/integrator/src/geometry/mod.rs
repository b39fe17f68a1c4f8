//! Acceleration: the union of the objects as the tracer marches it, with
//! what makes that cheap (per-object bounds a ray is clipped against, the
//! per-ray field of candidate objects, bounding-sphere culling) and the
//! plain union every speed-up is checked against.

use std::ops::Range;

use glam::Vec3;
use lueur_sdf_math::{
    Aabb, BoundingSphere, DistanceField, HalfSpace, Lane, LaneDistance, LaneGroups, LaneVec3,
    MAX_LANES, OVER_RELAXATION, PreparedSdf, Primitive, Ray, RayClipLanes, Sdf, SimdLevel,
    TraceOutcome, TraceParams, sphere_trace, sphere_trace_relaxed_stream_of,
};

use lueur_scene::{Marching, Object};

mod group;
mod stream;

use group::GroupMarch;
use stream::{CandidateLanes, Clip};

/// The union of the objects, as a field the tracer marches.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Geometry {
    sdfs: Vec<Sdf>,
    lipschitz: f32,
    /// Per object: its place in [`Geometry::order`], which holds its prepared field.
    position: Vec<u32>,
    /// Objects evaluated at every point: those without a bounding sphere (planes) and
    /// those no dearer than their bound (spheres), first, so that the running minimum is
    /// small before the culled objects are reached.
    always: Vec<usize>,
    /// The other objects with their bounding spheres, in scene order.
    culled: Vec<Bounded>,
    /// The order fast marching evaluates a ray's candidates in, the same for every ray
    /// (so that a ray's march does not depend on the rays beside it in a vector): the
    /// objects checked without their box first, so that the running minimum is small
    /// when the boxes are checked, then the others, each group in scene order.
    order: Vec<Ordered>,
    /// How fast marching schedules a stream's rays on the vectors.
    schedule: Schedule,
}

/// How [`Geometry::march`] puts a stream's rays on the vectors; both give each ray the
/// same outcome, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Schedule {
    /// Each lane takes the next ray as soon as its own ends ([`sphere_trace_relaxed_stream_of`]):
    /// full vectors whatever the mix of short and long marches, for the price of each ray's
    /// state written into its lane and its candidates listed.
    Stream,
    /// A vector of rays clipped and marched together until the last ends, the candidates
    /// as lane masks, the state in registers ([`sphere_trace_relaxed_group`]): no per-ray
    /// work, but a lane whose ray ends early idles. For scenes of at most
    /// [`MAX_GROUP_OBJECTS`] objects whose bounds are the objects themselves or close to
    /// them (boxes, spheres, planes), where the rays of a vector take about as many
    /// steps.
    Groups,
}

/// The most objects a scene marched in [`Schedule::Groups`] may have: each keeps a lane
/// mask in the kernel.
const MAX_GROUP_OBJECTS: usize = 32;

/// An object at its place in [`Geometry::order`], with what the vector kernels read of
/// it there, so that they walk one array.
#[derive(Clone, Debug, PartialEq)]
struct Ordered {
    object: u32,
    /// Its transforms folded into one affine map, for fast marching.
    prepared: PreparedSdf,
    /// `object` as [`CandidateLanes`] holds it in its lanes (exact in `f32`).
    id: f32,
    /// What a ray is clipped against before it is marched.
    bound: ObjectBound,
}

/// What a ray is clipped against for one object (see [`Marching::Fast`]).
#[derive(Clone, Copy, Debug, PartialEq)]
enum ObjectBound {
    /// The object's bounding box; `cull` when checking the box is cheaper than evaluating
    /// the object (not for boxes, whose box check costs as much as they do).
    Box {
        aabb: Aabb,
        cull: bool,
        /// The object's bounding sphere too, where it has one: the ray is kept where both
        /// keep it (the box leaves the sphere's flanks out, the sphere the box's corners).
        sphere: Option<BoundingSphere>,
    },
    /// A sphere's own sphere: its box holds the rays that pass near its silhouette, and
    /// those are the long marches (docs/PERFORMANCE.md, "Spheres clipped by their
    /// sphere").
    Sphere(BoundingSphere),
    /// Planes and what is cut from them.
    HalfSpace(HalfSpace),
    /// Nothing known: the object takes part in every march.
    Everywhere,
}

impl ObjectBound {
    fn of(sdf: &Sdf) -> ObjectBound {
        let sphere =
            (sdf.bounding_sphere()).map(|(center, radius)| BoundingSphere { center, radius });
        if let (true, Some(sphere)) = (is_sphere(sdf), sphere) {
            ObjectBound::Sphere(sphere)
        } else if let Some(aabb) = sdf.bounding_box() {
            let cull = !is_sphere(sdf) && !is_box(sdf);
            let sphere = sphere.filter(|_| cull);
            ObjectBound::Box { aabb, cull, sphere }
        } else if let Some(h) = sdf.bounding_half_space() {
            ObjectBound::HalfSpace(h)
        } else {
            ObjectBound::Everywhere
        }
    }
}

/// The rays of one stream that fast marching marches, each with the objects its bounds
/// let it meet ([`Marching::Fast`]): the union of those objects is the field its march
/// evaluates, and the object that field last found nearest is the one hit.
///
/// Sphere tracing that union finds the same surface as tracing the whole union: an object
/// left out has no point within the hit threshold on the marched range (its bound's
/// contract, [`Aabb::hit_interval`]), so the whole union's march could not stop on it
/// either, and the objects kept are evaluated exactly. Steps are longer, since the objects
/// left out no longer shorten them: that is the point.
///
/// Buffers are kept from one stream to the next, so that a thread allocates them once.
#[derive(Debug, Default)]
pub(crate) struct MarchBatch {
    /// The caller's tag for each ray queued.
    queued: Vec<usize>,
    /// The rays queued and their parameters, as rows of lanes ([`MarchBatch::queue`]).
    rows: LaneGroups<RAY_ROWS>,
    /// The tags of the queued rays that meet no candidate: misses in zero steps. Only the
    /// stream lists them here; groups keep them among the marched rays, with that outcome.
    misses: Vec<usize>,
    /// Per marched ray: the ray, its parameters clipped to the range its candidates
    /// cover, and its tag.
    rays: Vec<Ray>,
    params: Vec<TraceParams>,
    tags: Vec<usize>,
    /// Per marched ray, its candidates: `spans[i]` indexes `candidates`, which holds
    /// positions in [`Geometry::order`].
    spans: Vec<(u32, u32)>,
    candidates: Vec<u32>,
    /// Per marched ray, after [`Geometry::march`]: the outcome, and the object nearest
    /// at its last evaluation.
    outcomes: Vec<TraceOutcome>,
    nearest: Vec<u32>,
    /// While clipping, per group of [`OBJECTS_PER_MASK`] positions in the order, the
    /// candidates of each lane among them: position `j` of the group as `2^j`, summed.
    kept: Vec<[f32; MAX_LANES]>,
    /// While marching, [`CandidateLanes`]'s `member` and `members`.
    member: Vec<[f32; MAX_LANES]>,
    members: Vec<u32>,
}

impl MarchBatch {
    /// Empties the batch for a new stream.
    pub fn clear(&mut self) {
        self.queued.clear();
        self.rows.clear();
        self.misses.clear();
        self.rays.clear();
        self.params.clear();
        self.tags.clear();
        self.spans.clear();
        self.candidates.clear();
        self.outcomes.clear();
        self.nearest.clear();
    }

    /// Queues `ray`, traced with `params`, under `tag`: written in place as rows of lanes,
    /// which the clipping kernels load a vector at a time, rather than kept as a record
    /// and copied into rows when the stream is full.
    #[inline(always)]
    pub fn queue(&mut self, tag: usize, ray: Ray, params: TraceParams) {
        self.queued.push(tag);
        // A step cap past 2^24 rounds as an f32, but every march caps it at 2^24 (which
        // an f32 holds exactly) first, so the march is the same.
        self.rows.push([
            ray.origin.x,
            ray.origin.y,
            ray.origin.z,
            ray.dir.x,
            ray.dir.y,
            ray.dir.z,
            params.eps_abs,
            params.eps_rel,
            params.t_min,
            params.t_max,
            params.max_steps as f32,
        ]);
    }

    /// The queued rays a vector of `lanes` at a time (`lanes` divides [`MAX_LANES`]): each
    /// vector's range of queue indices, its group of rows, and the lane of the group its
    /// first ray stands in. Lanes past the last ray hold earlier rays or zeros (finite),
    /// for the kernel to ignore.
    fn vectors(
        queued: usize,
        rows: &LaneGroups<RAY_ROWS>,
        lanes: usize,
    ) -> impl Iterator<Item = (Range<usize>, &[[f32; MAX_LANES]; RAY_ROWS], usize)> {
        (0..queued).step_by(lanes).map(move |start| {
            let group = &rows.groups()[start / MAX_LANES];
            (start..(start + lanes).min(queued), group, start % MAX_LANES)
        })
    }

    /// After [`Geometry::march`], each queued ray's tag, outcome and object hit (`None` on
    /// a miss), in an order of the schedule's (the callers index by tag).
    pub fn results(&self) -> impl Iterator<Item = (usize, TraceOutcome, Option<usize>)> + '_ {
        let misses = (self.misses.iter()).map(|&tag| (tag, TraceOutcome::Miss { steps: 0 }, None));
        let marched = self.tags.iter().zip(&self.outcomes).zip(&self.nearest).map(
            |((&tag, &outcome), &nearest)| {
                let object = match outcome {
                    TraceOutcome::Miss { .. } => None,
                    TraceOutcome::Hit { .. } | TraceOutcome::GaveUp { .. } => {
                        Some(nearest as usize)
                    }
                };
                (tag, outcome, object)
            },
        );
        misses.chain(marched)
    }
}

/// Rows of a group of rays in [`MarchBatch::rows`]: the origin, the direction, then the
/// parameters `eps_abs`, `eps_rel`, `t_min`, `t_max` and the step cap.
const RAY_ROWS: usize = 11;

/// Objects per row of [`MarchBatch::kept`]: sums of distinct powers of two are exact in
/// `f32` below `2^24`.
const OBJECTS_PER_MASK: usize = 24;

/// Each lane's ray of `clip` against `entry`'s bound: the interval kept and the lanes
/// that keep it, or `None` where a box keeps none of the lanes in `live` (lane `i` in bit
/// `i`).
#[inline(always)]
fn clip_entry<L: Lane>(
    entry: &Ordered,
    clip: &RayClipLanes<L>,
    live: u32,
    (t_min, t_max): (L, L),
) -> Option<(L, L, L::Mask)> {
    Some(match &entry.bound {
        ObjectBound::Box { aabb, sphere, .. } => {
            let (t0, t1, keep) = clip.clip_box_lanes_in(aabb, live)?;
            match sphere {
                Some(sphere) => {
                    let (s0, s1, inside) = clip.clip_sphere_lanes(sphere);
                    let (t0, t1) = (t0.max(s0), t1.min(s1));
                    (t0, t1, L::and(L::and(keep, inside), L::not(t0.gt(t1))))
                }
                None => (t0, t1, keep),
            }
        }
        ObjectBound::Sphere(sphere) => clip.clip_sphere_lanes(sphere),
        ObjectBound::HalfSpace(h) => clip.clip_half_space_lanes(h),
        ObjectBound::Everywhere => (t_min, t_max, L::splat(0.0).lt(L::splat(1.0))),
    })
}

/// The range each lane's kept objects cover so far: the first kept object's interval,
/// then each one's union with it, as `f32::min` and `f32::max` take it; valid where
/// `seen`.
struct Covered<L: Lane> {
    lo: L,
    hi: L,
    seen: L::Mask,
}

impl<L: Lane> Covered<L> {
    #[inline(always)]
    fn new() -> Covered<L> {
        let zero = L::splat(0.0);
        Covered {
            lo: zero,
            hi: zero,
            seen: zero.gt(zero),
        }
    }

    #[inline(always)]
    fn add(&mut self, (t0, t1, keep): (L, L, L::Mask)) {
        self.lo = L::select(keep, L::select(self.seen, self.lo.min(t0), t0), self.lo);
        self.hi = L::select(keep, L::select(self.seen, self.hi.max(t1), t1), self.hi);
        self.seen = L::or(self.seen, keep);
    }
}

/// One object's part in the union of each lane's candidates at `p` (the lanes of
/// `active`): the running minimum `d` and the object it came from, `nearest`. A culled
/// box is checked first: at most as far as its object (its contract), where it is already
/// farther than the running minimum the object cannot lower it.
#[inline(always)]
fn lower_by<L: Lane>(
    entry: &Ordered,
    mut active: L::Mask,
    p: LaneVec3<L>,
    d: &mut L,
    nearest: &mut L,
) {
    if let ObjectBound::Box {
        aabb, cull: true, ..
    } = &entry.bound
    {
        let beyond = L::and(
            d.gt(L::splat(0.0)),
            aabb.distance_squared_lanes(p).ge(*d * *d),
        );
        active = L::and(active, L::not(beyond));
        if !L::any(active) {
            return;
        }
    }
    let f = entry.prepared.distance_lanes(p);
    let lower = L::and(active, f.lt(*d));
    *d = L::select(lower, f, *d);
    *nearest = L::select(lower, L::splat(entry.id), *nearest);
}

/// An object with its bounding sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bounded {
    center: Vec3,
    radius: f32,
    object: usize,
}

impl Geometry {
    pub fn new(objects: &[Object]) -> Geometry {
        let lipschitz = objects
            .iter()
            .map(|o| o.sdf.lipschitz())
            .fold(1.0f32, f32::max);
        let mut always = Vec::new();
        let mut culled = Vec::new();
        for (object, o) in objects.iter().enumerate() {
            match o.sdf.bounding_sphere() {
                Some((center, radius)) if !is_sphere(&o.sdf) => culled.push(Bounded {
                    center,
                    radius,
                    object,
                }),
                _ => always.push(object),
            }
        }
        let bounds: Vec<ObjectBound> = objects.iter().map(|o| ObjectBound::of(&o.sdf)).collect();
        let boxed = |b: &ObjectBound| matches!(b, ObjectBound::Box { cull: true, .. });
        let ordered = |object: u32| Ordered {
            object,
            prepared: PreparedSdf::new(&objects[object as usize].sdf),
            id: object as f32,
            bound: bounds[object as usize],
        };
        let order = (0..objects.len() as u32)
            .filter(|&i| !boxed(&bounds[i as usize]))
            .chain((0..objects.len() as u32).filter(|&i| boxed(&bounds[i as usize])))
            .map(ordered)
            .collect::<Vec<_>>();
        let mut position = vec![0; objects.len()];
        for (k, entry) in order.iter().enumerate() {
            position[entry.object as usize] = k as u32;
        }
        let close_bounds = order.iter().all(|entry| {
            matches!(
                entry.bound,
                ObjectBound::Box { cull: false, .. }
                    | ObjectBound::Sphere(_)
                    | ObjectBound::HalfSpace(_)
            )
        });
        let schedule = if close_bounds && order.len() <= MAX_GROUP_OBJECTS {
            Schedule::Groups
        } else {
            Schedule::Stream
        };
        Geometry {
            sdfs: objects.iter().map(|o| o.sdf.clone()).collect(),
            lipschitz,
            position,
            always,
            culled,
            order,
            schedule,
        }
    }

    /// This geometry marched on `schedule` (when [`Schedule::Groups`], only for at most
    /// [`MAX_GROUP_OBJECTS`] objects), for the tests that hold the two to the same
    /// outcomes.
    #[cfg(test)]
    fn with_schedule(self, schedule: Schedule) -> Geometry {
        assert!(schedule == Schedule::Stream || self.order.len() <= MAX_GROUP_OBJECTS);
        Geometry { schedule, ..self }
    }

    /// The plain union: every object, every time.
    #[inline]
    fn distance_naive(&self, p: Vec3) -> f32 {
        let mut d = f32::INFINITY;
        for sdf in &self.sdfs {
            d = d.min(sdf.distance(p));
        }
        d
    }

    /// The same value with bounding-sphere culling. Every `Sdf` honours its bounding
    /// sphere (`f(p) >= |p - c| - r`, a conformance test of `lueur-sdf-math`), so an object
    /// with `|p - c| - r >= d`, the running minimum, cannot lower it and is skipped: the
    /// result is the plain union's minimum, not an approximation of it, and therefore
    /// Lipschitz with the same bound.
    #[inline]
    fn distance_culled(&self, p: Vec3) -> f32 {
        let mut d = f32::INFINITY;
        for &i in &self.always {
            d = d.min(self.sdfs[i].distance(p));
        }
        for b in &self.culled {
            // |p - c| - r >= d without a square root: always true when r + d <= 0.
            let reach = b.radius + d;
            if reach <= 0.0 || (p - b.center).length_squared() >= reach * reach {
                continue;
            }
            d = d.min(self.sdfs[b.object].distance(p));
        }
        d
    }

    /// The union as a distance field, evaluated as `marching` says (both modes give the
    /// same value).
    pub fn distance(&self, p: Vec3, marching: Marching) -> f32 {
        match marching {
            Marching::Naive => self.distance_naive(p),
            Marching::Fast => self.distance_culled(p),
        }
    }

    /// The negated union, marched by rays that start inside a solid.
    pub fn inside(&self) -> Inside<'_> {
        Inside(self)
    }

    /// Marches `ray` through the plain union ([`Marching::Naive`]); with a hit, the
    /// object hit. Fast marching marches streams ([`Geometry::march`]).
    pub fn trace_naive(&self, ray: &Ray, params: &TraceParams) -> (TraceOutcome, Option<usize>) {
        let outcome = sphere_trace(&Naive(self), ray, params);
        let object = outcome.hit_t().map(|t| self.closest_object(ray.at(t)));
        (outcome, object)
    }

    /// Clips every ray queued in `batch` against the objects' bounds and marches those
    /// that meet a candidate through their candidates by over-relaxed sphere tracing, on
    /// `level`'s vectors (a level this CPU lacks runs on the widest it has): the same
    /// outcome and object for each ray on every level and in any company.
    pub fn march(&self, level: SimdLevel, batch: &mut MarchBatch) {
        let level = level.or_widest();
        if self.schedule == Schedule::Groups {
            // The level is available: `or_widest` says so.
            let _ = level.dispatch(GroupMarch {
                geometry: self,
                batch,
            });
            return;
        }
        // The level is available: `or_widest` says so.
        let _ = level.dispatch(Clip {
            geometry: self,
            batch,
        });
        let (mut field, rays, params, outcomes) = CandidateLanes::new(self, batch);
        // The level is available: `or_widest` says so.
        let _ = sphere_trace_relaxed_stream_of(
            level,
            &mut field,
            rays,
            params,
            OVER_RELAXATION,
            outcomes,
        );
    }

    /// Whether fast marching marches this scene's rays in groups ([`Schedule::Groups`]),
    /// a vector at a time ([`Geometry::march_vector`]).
    pub fn marches_in_groups(&self) -> bool {
        self.schedule == Schedule::Groups
    }

    /// Object `i`'s field as fast marching evaluates it (its transforms folded).
    pub fn prepared(&self, i: usize) -> &PreparedSdf {
        &self.order[self.position[i] as usize].prepared
    }

    /// The object closest to `p` (after a hit, the one that was hit).
    pub fn closest_object(&self, p: Vec3) -> usize {
        let mut best = (f32::INFINITY, 0);
        for (i, sdf) in self.sdfs.iter().enumerate() {
            let d = sdf.distance(p);
            if d < best.0 {
                best = (d, i);
            }
        }
        best.1
    }
}

/// Whether the shape is a sphere, possibly moved: its bounding sphere is the shape itself,
/// so checking the bound would cost as much as evaluating it.
fn is_sphere(sdf: &Sdf) -> bool {
    match sdf {
        Sdf::Primitive(Primitive::Sphere { .. }) => true,
        Sdf::Translate { child, .. } => is_sphere(child),
        _ => false,
    }
}

/// Whether the shape is a box, possibly moved: its bounding box is the shape itself.
fn is_box(sdf: &Sdf) -> bool {
    match sdf {
        Sdf::Primitive(Primitive::Box { .. }) => true,
        Sdf::Translate { child, .. } => is_box(child),
        _ => false,
    }
}

/// [`Geometry`] as the plain union, for naive marching.
struct Naive<'a>(&'a Geometry);

impl DistanceField for Naive<'_> {
    #[inline]
    fn distance(&self, p: Vec3) -> f32 {
        self.0.distance_naive(p)
    }

    fn lipschitz(&self) -> f32 {
        self.0.lipschitz
    }
}

/// The inside of [`Geometry`]: the negated field, whose zero set is the
/// same surface and which is positive inside objects, so the tracer can
/// march a ray that starts inside a solid to the wall it leaves through.
pub(crate) struct Inside<'a>(&'a Geometry);

impl DistanceField for Inside<'_> {
    #[inline]
    fn distance(&self, p: Vec3) -> f32 {
        -self.0.distance_naive(p)
    }

    fn lipschitz(&self) -> f32 {
        self.0.lipschitz
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A union of thin and far shapes, a plane among them, as the integrator sees it.
    pub(crate) fn crowd() -> Vec<Object> {
        use lueur_sdf_math::Quat;
        let sdfs = vec![
            Sdf::plane(Vec3::Y, 1.0),
            Sdf::torus(1.0, 1e-3).rotate(Quat::from_rotation_x(0.7)),
            Sdf::cuboid(Vec3::new(1.0, 1.0, 1e-3)).translate(Vec3::new(3.0, 0.0, 0.0)),
            Sdf::sphere(0.5).translate(Vec3::new(-2.0, 0.5, -1.0)),
            Sdf::death_star(1.0, 1.0, 0.02).translate(Vec3::new(0.0, 0.0, -40.0)),
            Sdf::torus(0.5, 0.2).translate(Vec3::new(0.0, 30.0, 0.0)),
        ];
        sdfs.into_iter()
            .map(|sdf| Object { sdf, material: 0 })
            .collect()
    }
    /// A deterministic spread of points in a cube of half-side 50.
    pub(crate) fn points() -> impl Iterator<Item = Vec3> {
        (0..20_000u32).map(|i| {
            let f = |k: u32| ((i.wrapping_mul(k) % 10_007) as f32 / 10_007.0 - 0.5) * 100.0;
            let p = Vec3::new(f(7919), f(104_729), f(1_299_709));
            // Half of them near the origin, where the shapes are.
            if i % 2 == 0 { p * 0.05 } else { p }
        })
    }

    /// A ray's outcome and object as bits, so that equality is bitwise.
    fn bits((outcome, object): (TraceOutcome, Option<usize>)) -> (u8, u32, u32, Option<usize>) {
        match outcome {
            TraceOutcome::Hit { t, steps } => (0, t.to_bits(), steps, object),
            TraceOutcome::Miss { steps } => (1, 0, steps, object),
            TraceOutcome::GaveUp { t, steps } => (2, t.to_bits(), steps, object),
        }
    }

    /// Fast marching's streams: every ray of a stream, in any lane of any vector width
    /// and next to any rays, ends as it ends when marched alone, and names the same object.
    #[test]
    fn a_stream_marches_each_ray_as_it_marches_alone() {
        // The crowd, and a lattice of small spheres that most rays pass near without
        // meeting their boxes: the objects nearest a ray are then often not its
        // candidates, which its lane must not see.
        let lattice: Vec<Object> = (0..27)
            .map(|i| Object {
                sdf: Sdf::torus(0.12, 0.04)
                    .translate(Vec3::new((i % 3) as f32, (i / 3 % 3) as f32, (i / 9) as f32) * 0.6),
                material: 0,
            })
            .collect();
        for objects in [crowd(), lattice, room()] {
            let geometry = Geometry::new(&objects);
            let alone = check_streams(&geometry);
            let other = match geometry.schedule {
                Schedule::Stream => Schedule::Groups,
                Schedule::Groups => Schedule::Stream,
            };
            assert_eq!(
                check_streams(&geometry.with_schedule(other)),
                alone,
                "{other:?}"
            );
        }
    }

    /// A room of boxes with spheres and a plane in it, marched in groups by default.
    #[test]
    fn rooms_are_marched_in_groups_and_crowds_in_streams() {
        assert_eq!(Geometry::new(&room()).schedule, Schedule::Groups);
        assert_eq!(Geometry::new(&crowd()).schedule, Schedule::Stream);
        // A lane mask per object: past that many, the stream.
        let spheres = |n: usize| -> Vec<Object> {
            (0..n)
                .map(|i| Object {
                    sdf: Sdf::sphere(0.1).translate(Vec3::X * i as f32),
                    material: 0,
                })
                .collect()
        };
        assert_eq!(
            Geometry::new(&spheres(MAX_GROUP_OBJECTS)).schedule,
            Schedule::Groups
        );
        assert_eq!(
            Geometry::new(&spheres(MAX_GROUP_OBJECTS + 1)).schedule,
            Schedule::Stream
        );
    }

    /// Boxes, spheres and a plane, thin and far ones among them.
    fn room() -> Vec<Object> {
        let sdfs = vec![
            Sdf::cuboid(Vec3::new(3.0, 0.05, 3.0)).translate(Vec3::new(0.0, -1.0, 0.0)),
            Sdf::cuboid(Vec3::new(0.05, 3.0, 3.0)).translate(Vec3::new(-3.0, 0.0, 0.0)),
            Sdf::cuboid(Vec3::new(3.0, 3.0, 1e-3)).translate(Vec3::new(0.0, 0.0, -3.0)),
            Sdf::sphere(0.5).translate(Vec3::new(-0.5, 0.0, 0.0)),
            Sdf::sphere(1e-3).translate(Vec3::new(0.3, 0.2, 0.1)),
            Sdf::sphere(0.4).translate(Vec3::new(0.0, 0.0, -60.0)),
            Sdf::plane(Vec3::X, -40.0),
        ];
        sdfs.into_iter()
            .map(|sdf| Object { sdf, material: 0 })
            .collect()
    }

    /// Each ray's outcome in a stream of 1, 7, 16 and 600 rays on every level is what it is
    /// alone on the scalar level; those outcomes, as bits.
    fn check_streams(geometry: &Geometry) -> Vec<(u8, u32, u32, Option<usize>)> {
        let (mut rays, mut params) = (Vec::new(), Vec::new());
        for (i, p) in points().take(600).enumerate() {
            let origin =
                Vec3::new(0.0, 0.5, 6.0) + Vec3::Y * (i % 3) as f32 - Vec3::Z * (i % 5) as f32;
            rays.push(Ray::new(origin, p * 0.1 - origin));
            params.push(TraceParams {
                t_min: if i % 11 == 0 { 0.5 } else { 0.0 },
                t_max: if i % 7 == 0 { 4.0 } else { 200.0 },
                max_steps: if i % 13 == 0 {
                    1 + (i % 3) as u32
                } else {
                    10_000
                },
                eps_abs: 1e-6,
                eps_rel: 1e-5,
            });
        }
        let alone: Vec<_> = rays
            .iter()
            .zip(&params)
            .map(|(r, p)| {
                let mut batch = MarchBatch::default();
                batch.queue(0, *r, *p);
                geometry.march(SimdLevel::Scalar, &mut batch);
                let (_, outcome, object) = batch.results().next().unwrap();
                bits((outcome, object))
            })
            .collect();
        for kind in 0..3 {
            assert!(
                alone.iter().any(|b| b.0 == kind),
                "no outcome of kind {kind}"
            );
        }
        for level in SimdLevel::available() {
            for stream in [1, 7, 16, 600] {
                let mut got = vec![None; rays.len()];
                let mut batch = MarchBatch::default();
                for start in (0..rays.len()).step_by(stream) {
                    batch.clear();
                    for i in start..(start + stream).min(rays.len()) {
                        batch.queue(i, rays[i], params[i]);
                    }
                    geometry.march(level, &mut batch);
                    for (i, outcome, object) in batch.results() {
                        got[i] = Some(bits((outcome, object)));
                    }
                }
                let got: Vec<_> = got.into_iter().map(Option::unwrap).collect();
                assert!(got == alone, "{level:?}, streams of {stream}");
            }
        }
        alone
    }

    #[test]
    fn culling_gives_the_plain_union() {
        let geometry = Geometry::new(&crowd());
        for p in points() {
            let (plain, culled) = (geometry.distance_naive(p), geometry.distance_culled(p));
            assert_eq!(plain, culled, "at {p}");
        }
    }

    #[test]
    fn culled_union_is_lipschitz() {
        let geometry = Geometry::new(&crowd());
        let l = geometry.lipschitz;
        let mut previous = Vec3::ZERO;
        for p in points() {
            for q in [previous, p + Vec3::splat(1e-3), p * 1.01] {
                let (fp, fq) = (geometry.distance_culled(p), geometry.distance_culled(q));
                let tol = 1e-5 * (1.0 + p.length() + q.length());
                assert!(
                    (fp - fq).abs() <= l * (p - q).length() + tol,
                    "|f({p}) - f({q})| = |{fp} - {fq}| > {l} |p - q|"
                );
            }
            previous = p;
        }
    }
}
