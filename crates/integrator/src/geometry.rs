//! Acceleration: the union of the objects as the tracer marches it, with
//! what makes that cheap (per-object bounds a ray is clipped against, the
//! per-ray field of candidate objects, bounding-sphere culling) and the
//! plain union every speed-up is checked against.

use std::cell::Cell;

use glam::Vec3;
use lueur_sdf_math::{
    Aabb, DistanceField, HalfSpace, OVER_RELAXATION, PreparedSdf, Primitive, Ray, RayClip, Sdf,
    TraceOutcome, TraceParams, sphere_trace, sphere_trace_relaxed,
};
use smallvec::SmallVec;

use lueur_scene::{Marching, Object};

/// The union of the objects, as a field the tracer marches.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Geometry {
    sdfs: Vec<Sdf>,
    lipschitz: f32,
    /// Per object: what a ray is clipped against before it is marched.
    bounds: Vec<ObjectBound>,
    /// Per object: its transforms folded into one affine map, for fast marching.
    prepared: Vec<PreparedSdf>,
    /// Objects evaluated at every point: those without a bounding sphere (planes) and
    /// those no dearer than their bound (spheres), first, so that the running minimum is
    /// small before the culled objects are reached.
    always: Vec<usize>,
    /// The other objects with their bounding spheres, in scene order.
    culled: Vec<Bounded>,
}

/// What a ray is clipped against for one object (see [`Marching::Fast`]).
#[derive(Clone, Copy, Debug, PartialEq)]
enum ObjectBound {
    /// The object's bounding box; `cull` when checking the box is cheaper than evaluating
    /// the object (not for boxes and spheres, whose box check costs as much as they do).
    Box { aabb: Aabb, cull: bool },
    /// Planes and what is cut from them.
    HalfSpace(HalfSpace),
    /// Nothing known: the object takes part in every march.
    Everywhere,
}

impl ObjectBound {
    fn of(sdf: &Sdf) -> ObjectBound {
        if let Some(aabb) = sdf.bounding_box() {
            let cull = !is_sphere(sdf) && !is_box(sdf);
            ObjectBound::Box { aabb, cull }
        } else if let Some(h) = sdf.bounding_half_space() {
            ObjectBound::HalfSpace(h)
        } else {
            ObjectBound::Everywhere
        }
    }
}

/// One object a ray may hit, and from where along it. Small, so that a ray's list is
/// cheap to build, sort and move.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    object: u32,
    t0: f32,
}

/// The union of the objects one ray can hit ([`Marching::Fast`]), nearest entry first, and
/// which of them the last evaluation found nearest.
///
/// Sphere tracing this field finds the same surface as tracing the whole union: an object
/// left out has no point within the hit threshold on the marched range (its bound's
/// contract, [`Aabb::hit_interval`]), so the whole union's march could not stop on it
/// either, and the objects kept are evaluated exactly. Steps are longer, since the objects
/// left out no longer shorten them: that is the point.
struct RayField<'a> {
    geometry: &'a Geometry,
    candidates: SmallVec<[Candidate; 16]>,
    nearest: Cell<u32>,
}

impl<'a> RayField<'a> {
    /// The candidates of `ray` and the range of `t` to march, `None` when no object can be
    /// hit.
    fn new(geometry: &'a Geometry, ray: &Ray, params: &TraceParams) -> (Self, Option<(f32, f32)>) {
        let mut candidates = SmallVec::new();
        let mut range: Option<(f32, f32)> = None;
        let clip = RayClip::new(ray, params);
        for (object, bound) in geometry.bounds.iter().enumerate() {
            let interval = match bound {
                ObjectBound::Box { aabb, .. } => clip.clip_box(aabb),
                ObjectBound::HalfSpace(h) => clip.clip_half_space(h),
                ObjectBound::Everywhere => Some((params.t_min, params.t_max)),
            };
            let Some((t0, t1)) = interval else {
                continue;
            };
            range = Some(range.map_or((t0, t1), |(a, b)| (a.min(t0), b.max(t1))));
            candidates.push(Candidate {
                object: object as u32,
                t0,
            });
        }
        // Nearest first: the running minimum is small early, so later boxes cull.
        candidates.sort_unstable_by(|a: &Candidate, b: &Candidate| a.t0.total_cmp(&b.t0));
        let field = RayField {
            geometry,
            candidates,
            nearest: Cell::new(0),
        };
        (field, range)
    }

    /// The object the last evaluation found nearest: after a hit, the one that was hit.
    fn nearest(&self) -> usize {
        self.nearest.get() as usize
    }
}

impl DistanceField for RayField<'_> {
    #[inline]
    fn distance(&self, p: Vec3) -> f32 {
        let mut d = f32::INFINITY;
        let mut nearest = self.candidates.first().map_or(0, |c| c.object);
        for c in &self.candidates {
            // The box is at most as far as the object (its contract): when it is already
            // farther than the running minimum, the object cannot lower it.
            if let ObjectBound::Box { aabb, cull: true } = &self.geometry.bounds[c.object as usize]
                && d > 0.0
                && aabb.distance_squared(p) >= d * d
            {
                continue;
            }
            let f = self.geometry.prepared[c.object as usize].distance(p);
            if f < d {
                d = f;
                nearest = c.object;
            }
        }
        self.nearest.set(nearest);
        d
    }

    fn lipschitz(&self) -> f32 {
        self.geometry.lipschitz
    }
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
        Geometry {
            sdfs: objects.iter().map(|o| o.sdf.clone()).collect(),
            lipschitz,
            bounds: objects.iter().map(|o| ObjectBound::of(&o.sdf)).collect(),
            prepared: objects.iter().map(|o| PreparedSdf::new(&o.sdf)).collect(),
            always,
            culled,
        }
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

    /// Marches `ray` through the objects as `marching` says; with a hit, the object hit.
    pub fn trace(
        &self,
        ray: &Ray,
        params: &TraceParams,
        marching: Marching,
    ) -> (TraceOutcome, Option<usize>) {
        match marching {
            Marching::Naive => {
                let outcome = sphere_trace(&Naive(self), ray, params);
                let object = outcome.hit_t().map(|t| self.closest_object(ray.at(t)));
                (outcome, object)
            }
            Marching::Fast => {
                let (field, range) = RayField::new(self, ray, params);
                let Some((t_min, t_max)) = range else {
                    return (TraceOutcome::Miss { steps: 0 }, None);
                };
                let clipped = TraceParams {
                    t_min,
                    t_max,
                    ..*params
                };
                let outcome = sphere_trace_relaxed(&field, ray, &clipped, OVER_RELAXATION);
                let object = match outcome {
                    TraceOutcome::Miss { .. } => None,
                    TraceOutcome::Hit { .. } | TraceOutcome::GaveUp { .. } => Some(field.nearest()),
                };
                (outcome, object)
            }
        }
    }

    /// Object `i`'s field as fast marching evaluates it (its transforms folded).
    pub fn prepared(&self, i: usize) -> &PreparedSdf {
        &self.prepared[i]
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
