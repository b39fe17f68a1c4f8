//! The shading points of a stream of hits, a vector of hits at a time on one object:
//! [`SurfacePoint::at_hits`], the stages of [`SurfacePoint::new`] over lanes, with the bits
//! of each hit shaded alone.

use glam::Vec3;
use lueur_scene::Marching;
use lueur_sdf_math::{
    Lane, LaneDistance, LaneKernel, LaneVec3, MAX_LANES, PreparedSdf, Ray, SimdLevel, Tetrahedron,
};

use super::{Approach, HitPrecision, March, Newton, Projection, SurfaceHit, SurfacePoint};
use crate::PreparedScene;

impl SurfacePoint {
    /// The shading points of `hits` (each with the ray that found it) into `out`
    /// (cleared first), in order: with fast marching, object by object, a vector of hits
    /// at a time on `level`, with the bits of [`SurfacePoint::at_hit`] for each hit
    /// alone. Naive marching shades one hit at a time, the plain reference.
    pub fn at_hits(
        scene: &PreparedScene,
        march: &March,
        level: SimdLevel,
        hits: &[(Ray, SurfaceHit)],
        scratch: &mut SurfaceScratch,
        out: &mut Vec<SurfacePoint>,
    ) {
        out.clear();
        if march.marching == Marching::Naive {
            out.extend(
                hits.iter()
                    .map(|(ray, hit)| SurfacePoint::at_hit(scene, march, ray, *hit)),
            );
            return;
        }
        out.resize(hits.len(), SurfacePoint::UNSET);
        SurfacePoint::at_source(scene, march, level, &mut HitList { hits, out }, scratch);
    }

    /// [`SurfacePoint::at_hits`] in fast marching, for hits kept anywhere: each of
    /// `source`'s hits shaded, object by object, a vector of hits at a time on `level`,
    /// and its point handed back to `source`.
    pub(crate) fn at_source<H: HitSource>(
        scene: &PreparedScene,
        march: &March,
        level: SimdLevel,
        source: &mut H,
        scratch: &mut SurfaceScratch,
    ) {
        debug_assert_eq!(march.marching, Marching::Fast);
        let level = level.or_widest();
        scratch.group_by_object(source, scene.scene().objects.len());
        for (object, group) in scratch.groups.windows(2).enumerate() {
            let group = &scratch.order[group[0] as usize..group[1] as usize];
            if group.is_empty() {
                continue;
            }
            // The level is available: `or_widest` says so.
            let _ = level.dispatch(HitsOnObject {
                sdf: scene.prepared(object),
                march,
                group,
                source: &mut *source,
            });
        }
    }
}

/// Where [`SurfacePoint::at_source`] finds its hits and puts their shading points: hit
/// `k` of `0..len()`.
pub(crate) trait HitSource {
    /// How many hits.
    fn len(&self) -> usize;
    /// The object hit `k` lies on.
    fn object(&self, k: usize) -> usize;
    /// Hit `k`, with the ray that found it.
    fn hit(&self, k: usize) -> (Ray, SurfaceHit);
    /// Hit `k`'s shading point.
    fn put(&mut self, k: usize, point: SurfacePoint);
}

/// The hits of [`SurfacePoint::at_hits`], each with its ray, and their points, in order.
struct HitList<'a> {
    hits: &'a [(Ray, SurfaceHit)],
    out: &'a mut [SurfacePoint],
}

impl HitSource for HitList<'_> {
    #[inline(always)]
    fn len(&self) -> usize {
        self.hits.len()
    }

    #[inline(always)]
    fn object(&self, k: usize) -> usize {
        self.hits[k].1.object
    }

    #[inline(always)]
    fn hit(&self, k: usize) -> (Ray, SurfaceHit) {
        self.hits[k]
    }

    #[inline(always)]
    fn put(&mut self, k: usize, point: SurfacePoint) {
        self.out[k] = point;
    }
}

/// A thread's buffers for [`SurfacePoint::at_hits`], kept from one wave to the next.
#[derive(Debug, Default)]
pub(crate) struct SurfaceScratch {
    /// The hits' indices, grouped by object.
    order: Vec<u32>,
    /// Where each object's group starts in `order`, and where the last ends.
    groups: Vec<u32>,
}

impl SurfaceScratch {
    /// Fills `order` and `groups` with the hits grouped by object (a counting sort, which
    /// keeps each object's hits in their order).
    fn group_by_object<H: HitSource>(&mut self, hits: &H, objects: usize) {
        let groups = &mut self.groups;
        groups.clear();
        groups.resize(objects + 1, 0);
        for k in 0..hits.len() {
            groups[hits.object(k) + 1] += 1;
        }
        for i in 1..groups.len() {
            groups[i] += groups[i - 1];
        }
        self.order.clear();
        self.order.resize(hits.len(), 0);
        // `groups[object]` walks through the object's slots, then is put back.
        for k in 0..hits.len() {
            let slot = &mut groups[hits.object(k)];
            self.order[*slot as usize] = k as u32;
            *slot += 1;
        }
        for i in (1..groups.len()).rev() {
            groups[i] = groups[i - 1];
        }
        groups[0] = 0;
    }
}

/// Which of the field evaluations of [`HitsOnObject`] a round of its loop has just made.
enum Round<L: Lane> {
    /// At the hit and ahead of it.
    Start,
    /// Around the Newton step's candidate, for its normal, and at the candidate; the
    /// field at the hit.
    Normal(Newton<L>, Tetrahedron<L>, L),
    /// At the point projected along the normal.
    Projection(Projection<L>),
}

/// The kernel of [`SurfacePoint::at_hits`] for the hits on one object: the stages of
/// [`SurfacePoint::new`] on a vector of hits at a time, a hit per lane, with the field
/// values they ask for evaluated as vectors (7, and an 8th where some lane's point
/// moves along the normal). A hit whose surface curves on the scale of the step
/// ([`Approach::curved`]), or whose grazing Newton step the field or the gradient refused
/// ([`Approach::start`], [`Approach::stencil_refuses`]), is shaded again alone.
struct HitsOnObject<'a, H> {
    sdf: &'a PreparedSdf,
    march: &'a March,
    /// The indices in `source` of the hits on this object.
    group: &'a [u32],
    source: &'a mut H,
}

impl<H: HitSource> LaneKernel for HitsOnObject<'_, H> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(self) {
        let sdf = self.sdf;
        let lanes = L::LANES;
        for chunk in self.group.chunks(lanes) {
            // Each lane's hit; lanes past the chunk repeat its first hit, so that every
            // lane computes something finite.
            let mut rows = [[0.0; MAX_LANES]; 8];
            for j in 0..lanes {
                let k = if j < chunk.len() { chunk[j] } else { chunk[0] };
                let (ray, hit) = self.source.hit(k as usize);
                let at = ray.at(hit.t);
                let row = [
                    at.x,
                    at.y,
                    at.z,
                    -ray.dir.x,
                    -ray.dir.y,
                    -ray.dir.z,
                    hit.epsilon,
                    if hit.inside { 1.0 } else { 0.0 },
                ];
                for (r, value) in rows.iter_mut().zip(row) {
                    r[j] = value;
                }
            }
            // Not a closure: it would be compiled apart from the kernel's features.
            let [x, y, z, wx, wy, wz, epsilon, inside] = &rows;
            let hit = LaneVec3::new(
                L::load(&x[..lanes]),
                L::load(&y[..lanes]),
                L::load(&z[..lanes]),
            );
            let wo = LaneVec3::new(
                L::load(&wx[..lanes]),
                L::load(&wy[..lanes]),
                L::load(&wz[..lanes]),
            );
            let from_inside = L::load(&inside[..lanes]).gt(L::splat(0.5));
            let precision =
                HitPrecision::at_lanes(sdf, hit, L::load(&epsilon[..lanes]), from_inside);
            let approach = Approach::new(hit, wo, precision);
            // The field is evaluated at one place in the loop below, in rounds of 2, 5, 6
            // (where some lane's surface curves on the scale of the step), then 1 point
            // (where some lane moves along the normal): each evaluation inlines the whole
            // primitive, and the 8 inlined copies per SIMD level of straight-line code
            // took LLVM over four minutes to compile.
            let mut points = [hit, approach.ahead, hit, hit, hit];
            let mut values = [L::splat(0.0); 5];
            let mut count = 2;
            let mut round = Round::Start;
            // The lanes whose surface curves on the scale of the step, or whose grazing
            // Newton step was refused: shaded again alone below (`SurfacePoint::new`, the
            // same bits), so that the rare cases cost the vector loop no state.
            let mut redo = 0;
            let (projection, f_p) = loop {
                for (value, &point) in values.iter_mut().zip(&points).take(count) {
                    *value = sdf.distance_lanes(point);
                }
                round = match round {
                    Round::Start => {
                        let newton = approach.newton(values[0], values[1]);
                        let tetrahedron = Tetrahedron::around(newton.point, approach.h);
                        let [q0, q1, q2, q3] = tetrahedron.points();
                        points = [q0, q1, q2, q3, newton.point];
                        count = 5;
                        Round::Normal(newton, tetrahedron, values[0])
                    }
                    Round::Normal(newton, tetrahedron, f_hit) => {
                        // The candidate is the start in every lane but those whose grazing
                        // step the field or the gradient refused, which are shaded again
                        // alone.
                        let (start, f_start, grazing) = approach.start(&newton, f_hit, values[4]);
                        let f = [values[0], values[1], values[2], values[3]];
                        let grad = tetrahedron.gradient(f);
                        let (is_curved, _) = approach.curved(tetrahedron.laplacian(f, f_start));
                        let refused = L::or(
                            L::and(newton.grazing, L::not(grazing)),
                            approach.stencil_refuses(&newton, grazing, grad),
                        );
                        redo = L::bits(L::or(is_curved, refused));
                        let projection = approach.project(start, grad, f_start);
                        if !L::any(projection.moved) {
                            break (projection, f_start);
                        }
                        // A lane that did not move has its start as `p`, and evaluating it
                        // again gives `f_start`'s bits.
                        points[0] = projection.p;
                        count = 1;
                        Round::Projection(projection)
                    }
                    Round::Projection(projection) => break (projection, values[0]),
                };
            };
            let s = approach.finish(&projection, f_p);
            let mut out = [[0.0; MAX_LANES]; 9];
            for (o, v) in out.iter_mut().zip([
                s.p.x, s.p.y, s.p.z, s.n.x, s.n.y, s.n.z, s.origin.x, s.origin.y, s.origin.z,
            ]) {
                v.store(&mut o[..lanes]);
            }
            let inside = L::bits(s.inside);
            for (j, &k) in chunk.iter().enumerate() {
                if redo >> j & 1 != 0 {
                    let (ray, hit) = self.source.hit(k as usize);
                    let point = SurfacePoint::shaded_alone(sdf, &ray, &hit, self.march);
                    self.source.put(k as usize, point);
                    continue;
                }
                let v = |r: usize| Vec3::new(out[r][j], out[r + 1][j], out[r + 2][j]);
                let point = SurfacePoint {
                    p: v(0),
                    n: v(3),
                    origin: v(6),
                    inside: inside >> j & 1 != 0,
                };
                self.source.put(k as usize, point);
            }
        }
    }
}
