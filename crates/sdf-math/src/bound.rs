//! Bounds a ray can be clipped against before it is marched: an axis-aligned box (for
//! bounded shapes), a sphere (for spheres, whose box is loose) and a half-space (for
//! planes and what is cut from them).
//!
//! A bound is only useful with its contract, stronger than containment: the shape's
//! *field* never undercuts the distance to the bound ([`Sdf::bounding_box`],
//! [`Sdf::bounding_sphere`], [`Sdf::bounding_half_space`]). Then the parameters along a
//! ray where a tracer could declare a hit on the shape (field below `max(eps_abs, eps_rel
//! t)`) lie inside the interval [`Aabb::hit_interval`], [`BoundingSphere::hit_interval`] or
//! [`HalfSpace::hit_interval`] returns, and a tracer may ignore the shape outside it, or
//! altogether when it is empty, without changing which surface the ray finds.
//!
//! [`Sdf::bounding_box`]: crate::Sdf::bounding_box
//! [`Sdf::bounding_sphere`]: crate::Sdf::bounding_sphere
//! [`Sdf::bounding_half_space`]: crate::Sdf::bounding_half_space

use glam::Vec3;

use crate::lanes::{Lane, LaneVec3};
use crate::{Ray, TraceParams};

/// Relative widening of every interval end: covers the rounding of the slab test itself.
const WIDEN: f32 = 1e-5;

/// An axis-aligned box `min..=max` (every `min` component <= its `max` component).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lowest corner.
    pub min: Vec3,
    /// Highest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The box with this centre and (non-negative) half extents.
    #[inline]
    pub fn from_center(center: Vec3, half_extents: Vec3) -> Aabb {
        Aabb {
            min: center - half_extents,
            max: center + half_extents,
        }
    }

    /// Centre of the box.
    #[inline]
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Half the side lengths.
    #[inline]
    pub fn half_extents(&self) -> Vec3 {
        (self.max - self.min) * 0.5
    }

    /// The smallest box holding both.
    #[inline]
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// This box grown by `margin` on every side.
    #[inline]
    pub fn inflate(&self, margin: f32) -> Aabb {
        Aabb {
            min: self.min - Vec3::splat(margin),
            max: self.max + Vec3::splat(margin),
        }
    }

    /// Squared Euclidean distance from `p` to the box (0 inside): cheap enough to decide,
    /// before evaluating a shape, whether it can be nearer than what was already found.
    #[inline]
    pub fn distance_squared(&self, p: Vec3) -> f32 {
        self.distance_squared_lanes(LaneVec3::<f32>::from(p))
    }

    /// [`Aabb::distance_squared`] of each lane's point: the same formula, so each lane
    /// gives the scalar bits.
    #[inline(always)]
    pub fn distance_squared_lanes<L: Lane>(&self, p: LaneVec3<L>) -> L {
        let outside = (LaneVec3::splat(self.min) - p)
            .max(p - LaneVec3::splat(self.max))
            .max(LaneVec3::splat(Vec3::ZERO));
        outside.length_squared()
    }

    /// Whether every coordinate is finite.
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }

    /// The part of `[params.t_min, params.t_max]` where a field honouring this box (at
    /// least the distance to the box, outside it) can fall below the tracer's hit
    /// threshold `max(eps_abs, eps_rel t)`, as the box grown by `eps_abs + eps_rel t`
    /// gives it (at most one threshold too wide); `None` where there is no such part. See
    /// [`RayClip::clip_box`]; when clipping one ray against many boxes, make the
    /// [`RayClip`] once.
    pub fn hit_interval(&self, ray: &Ray, params: &TraceParams) -> Option<(f32, f32)> {
        RayClip::new(ray, params).clip_box(self)
    }
}

/// One ray prepared for clipping against many bounds: what every clip shares (the
/// reciprocals of the slopes, the thresholds) computed once.
///
/// Every bound is treated as an intersection of half-spaces (a box is six), and the field
/// is at least the distance to the bound, so at least the signed distance to each of its
/// planes (`dot(p, n) - h`, with unit `n` for a box). Along the ray each of those is
/// linear in `t`, `a + b t`, and it can be below the hit threshold `max(eps_abs,
/// eps_rel t)` only on `{a - eps_abs + b t < 0} ∪ {a + (b - eps_rel) t < 0}`: two
/// half-lines. A hit is possible only where every plane allows it, so the interval is
/// the intersection over the planes of those sets. A half-space's one plane takes the two
/// half-lines exactly. A box's six take, each, the one half-line `{a - eps_abs + (b -
/// eps_rel) t < 0}` that holds both (the threshold is at most `eps_abs + eps_rel t`): a
/// set wider by at most one threshold, for half the work of the clip, which every ray
/// does against every box. No square root, no margin guessed from the ray's length: a ray
/// leaving a wall is never a candidate for that wall (the plane it leaves grows faster
/// than `eps_rel t`), however close it starts.
///
/// Written once over [`Lane`]s, a ray per lane ([`RayClipLanes`]); [`RayClip`] is the
/// one-ray case, and every lane of a vector gives that ray's bits.
#[derive(Clone, Copy, Debug)]
pub struct RayClipLanes<L: Lane> {
    origin: LaneVec3<L>,
    dir: LaneVec3<L>,
    /// The two families of box planes, per axis: faces facing + (value `o - max`, slope
    /// `d`) and facing - (value `min - o`, slope `-d`), each against the sum of the
    /// thresholds (slope less `eps_rel`). Slopes are per ray, so their reciprocals and
    /// signs are too.
    families: [Slope<L>; 2],
    /// A non-finite origin or direction: every clip keeps the whole range.
    degenerate: L::Mask,
    eps_abs: L,
    eps_rel: L,
    t_min: L,
    t_max: L,
}

/// One ray prepared for clipping: [`RayClipLanes`] with one lane.
pub type RayClip = RayClipLanes<f32>;

/// The slope of one family of planes along the ray, per axis.
#[derive(Clone, Copy, Debug)]
struct Slope<L: Lane> {
    /// `-1 / slope` (negated once here rather than each root's numerator at every box,
    /// which is the same product), with a zero slope replaced by a tiny positive one, so
    /// that `a + 0 t < 0` comes out as "every t" for negative `a` and "none" for positive
    /// `a` with no special case.
    neg_inv: LaneVec3<L>,
    /// Where the slope is positive: the set is `t < root`; elsewhere `t > root`.
    rising: [L::Mask; 3],
}

impl<L: Lane> Slope<L> {
    #[inline(always)]
    fn new(slope: LaneVec3<L>) -> Slope<L> {
        // Not closures: a vector kernel inlines only what is marked to be inlined.
        #[inline(always)]
        fn per_axis<L: Lane>(s: L) -> (L, L::Mask) {
            let zero = L::splat(0.0);
            let s = L::select(L::and(s.ge(zero), L::not(s.gt(zero))), L::splat(1e-30), s);
            (-(L::splat(1.0) / s), s.gt(zero))
        }
        let ((x, rx), (y, ry), (z, rz)) = (per_axis(slope.x), per_axis(slope.y), per_axis(slope.z));
        Slope {
            neg_inv: LaneVec3::new(x, y, z),
            rising: [rx, ry, rz],
        }
    }

    /// On axis `axis`, the half-line `{t : alpha + slope t < 0}` as `(lo, hi)`, the other
    /// end infinite. A NaN root bounds nothing: [`box_axis`] folds each end in with
    /// `max_cmp` or `min_cmp`, which drop a NaN in either place. Neither clipped to the
    /// trace's range nor tested for emptiness here: the box intersects it with the other
    /// face's half-line and then clips once, the same interval for half the work (an
    /// empty half-line leaves the intersection empty).
    #[inline(always)]
    fn below(&self, axis: usize, alpha: L) -> (L, L) {
        let (neg_inv, rising) = (component(self.neg_inv, axis), self.rising[axis]);
        let root = alpha * neg_inv;
        (
            L::select(rising, L::splat(f32::NEG_INFINITY), root),
            L::select(rising, root, L::splat(f32::INFINITY)),
        )
    }
}

/// Whether every lane of `lanes` is empty and finite in `(lo, hi)` (`lo > hi` holds for
/// no NaN): [`RayClipLanes::clip_box_lanes_in`]'s early answer. Not a closure: a vector
/// kernel inlines only what is marked to be inlined.
#[inline(always)]
fn box_misses<L: Lane>(clip: &RayClipLanes<L>, (lo, hi): (L, L), lanes: u32) -> bool {
    let empty = L::and(lo.gt(hi), L::not(clip.degenerate));
    lanes != 0 && L::bits(empty) & lanes == lanes
}

/// The interval of each lane's ray within the box's slab on `axis`.
#[inline(always)]
fn box_axis<L: Lane>(clip: &RayClipLanes<L>, aabb: &Aabb, axis: usize) -> (L, L) {
    let [up, down] = &clip.families;
    let (t_min, t_max) = (clip.t_min, clip.t_max);
    let o = component(clip.origin, axis);
    let (min, max) = (L::splat(aabb.min[axis]), L::splat(aabb.max[axis]));
    // Taken off every plane value: the f32 rounding of the numbers that decide it, per
    // axis (the origin's coordinate and the box's faces on that axis). Per axis, not the
    // largest coordinate of all, so that a ray leaving the top of a floor 1e4 wide is not
    // a candidate for it however close above it starts.
    let faces = aabb.min[axis].abs().max_cmp(aabb.max[axis].abs());
    let scale = o.abs().max_cmp(L::splat(faces));
    let slack = L::splat(4.0 * f32::EPSILON) * scale + clip.eps_abs;
    let (lo_up, hi_up) = up.below(axis, o - max - slack);
    let (lo_down, hi_down) = down.below(axis, min - o - slack);
    (
        lo_up.max_cmp(lo_down.max_cmp(t_min)),
        hi_up.min_cmp(hi_down.min_cmp(t_max)),
    )
}

/// Coordinate `axis` (0, 1 or 2) of `v`.
#[inline(always)]
fn component<L: Lane>(v: LaneVec3<L>, axis: usize) -> L {
    match axis {
        0 => v.x,
        1 => v.y,
        _ => v.z,
    }
}

/// `{t : alpha + beta t < 0}`, given `inv = 1 / beta`, as an interval (possibly infinite,
/// possibly empty as `(inf, -inf)`). A NaN anywhere gives every `t`: keep what is not
/// understood.
#[inline(always)]
fn half_line<L: Lane>(alpha: L, beta: L, inv: L) -> (L, L) {
    let (inf, zero) = (L::splat(f32::INFINITY), L::splat(0.0));
    let root = -alpha * inv;
    let all = L::or(
        L::or(root.is_nan(), beta.is_nan()),
        L::and(
            L::not(beta.gt(zero)),
            L::and(L::not(beta.lt(zero)), alpha.lt(zero)),
        ),
    );
    let lo = L::select(beta.gt(zero), -inf, L::select(beta.lt(zero), root, inf));
    let hi = L::select(beta.gt(zero), root, L::select(beta.lt(zero), inf, -inf));
    (L::select(all, -inf, lo), L::select(all, inf, hi))
}

/// The hull, within `range`, of the `t` where a plane value `a + b t` is below
/// `max(eps_abs, eps_rel t)`; empty (`(inf, -inf)`) if there are none. Each set is
/// clipped to the range before the hull is taken, so that a half-line at negative `t`
/// does not drag it to everything.
#[inline(always)]
fn below_threshold<L: Lane>(
    a: L,
    eps_abs: L,
    (b, inv): (L, L),
    (b_rel, inv_rel): (L, L),
    (t_min, t_max): (L, L),
) -> (L, L) {
    #[inline(always)]
    fn clip<L: Lane>((lo, hi): (L, L), t_min: L, t_max: L) -> (L, L) {
        let (lo, hi) = (lo.max(t_min), hi.min(t_max));
        let kept = hi.ge(lo);
        (
            L::select(kept, lo, L::splat(f32::INFINITY)),
            L::select(kept, hi, L::splat(f32::NEG_INFINITY)),
        )
    }
    let (lo_abs, hi_abs) = clip(half_line(a - eps_abs, b, inv), t_min, t_max);
    let (lo_rel, hi_rel) = clip(half_line(a, b_rel, inv_rel), t_min, t_max);
    (lo_abs.min(lo_rel), hi_abs.max(hi_rel))
}

/// Widens `[t0, t1]` by a relative [`WIDEN`] and clips it to `[t_min, t_max]`: the
/// interval, and whether it is not empty.
#[inline(always)]
fn widen<L: Lane>(t0: L, t1: L, t_min: L, t_max: L) -> (L, L, L::Mask) {
    let widen = L::splat(WIDEN);
    let nan = L::or(t0.is_nan(), t1.is_nan());
    let w0 = (t0 - widen * t0.abs()).max(t_min);
    let w1 = (t1 + widen * t1.abs()).min(t_max);
    let kept = L::and(L::not(t0.gt(t1)), w1.ge(w0));
    (
        L::select(nan, t_min, w0),
        L::select(nan, t_max, w1),
        L::or(nan, kept),
    )
}

/// A ball `|p - center| <= radius`, as [`Sdf::bounding_sphere`](crate::Sdf::bounding_sphere)
/// gives it: the field is at least `|p - center| - radius`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere {
    /// Centre.
    pub center: Vec3,
    /// Radius (at least 0).
    pub radius: f32,
}

impl BoundingSphere {
    /// The part of `[params.t_min, params.t_max]` where a field honouring this sphere can
    /// fall below the hit threshold `max(eps_abs, eps_rel t)`: where the ray is within
    /// `radius + eps_abs + eps_rel t` of the centre, and some rounding more; `None` where
    /// there is no such part. See [`RayClip::clip_sphere`].
    pub fn hit_interval(&self, ray: &Ray, params: &TraceParams) -> Option<(f32, f32)> {
        RayClip::new(ray, params).clip_sphere(self)
    }
}

impl RayClip {
    /// Prepares `ray` for clipping with the hit thresholds and range of `params`.
    #[inline]
    pub fn new(ray: &Ray, params: &TraceParams) -> RayClip {
        RayClipLanes::from_lanes(
            ray.origin.into(),
            ray.dir.into(),
            [params.eps_abs, params.eps_rel, params.t_min, params.t_max],
        )
    }

    /// [`Aabb::hit_interval`] for this ray: the six faces' intervals intersected (see the
    /// type), clipped to the trace's range, its ends widened by a relative `1e-5`.
    #[inline]
    pub fn clip_box(&self, aabb: &Aabb) -> Option<(f32, f32)> {
        let (t0, t1, kept) = self.clip_box_lanes(aabb);
        kept.then_some((t0, t1))
    }

    /// [`BoundingSphere::hit_interval`] for this ray: the ray within the sphere grown by
    /// the threshold, a quadratic in `t` solved about the ray's closest approach to the
    /// centre (see [`RayClipLanes::clip_sphere_lanes`]), its ends widened by a relative
    /// `1e-5`.
    #[inline]
    pub fn clip_sphere(&self, sphere: &BoundingSphere) -> Option<(f32, f32)> {
        let (t0, t1, kept) = self.clip_sphere_lanes(sphere);
        kept.then_some((t0, t1))
    }

    /// [`HalfSpace::hit_interval`] for this ray: one plane, whose normal need not be unit
    /// (the field is at least the plane's value, whatever its scale).
    #[inline]
    pub fn clip_half_space(&self, h: &HalfSpace) -> Option<(f32, f32)> {
        let (t0, t1, kept) = self.clip_half_space_lanes(h);
        kept.then_some((t0, t1))
    }
}

impl<L: Lane> RayClipLanes<L> {
    /// Prepares a ray per lane for clipping, from their origins, directions and
    /// `[eps_abs, eps_rel, t_min, t_max]`.
    #[inline(always)]
    pub fn from_lanes(
        origin: LaneVec3<L>,
        dir: LaneVec3<L>,
        [eps_abs, eps_rel, t_min, t_max]: [L; 4],
    ) -> Self {
        let zero = L::splat(0.0);
        let eps_rel = eps_rel.max(zero);
        let rel = LaneVec3::new(eps_rel, eps_rel, eps_rel);
        RayClipLanes {
            origin,
            dir,
            families: [Slope::new(dir - rel), Slope::new(-dir - rel)],
            degenerate: L::not(L::and(origin.finite(), dir.finite())),
            eps_abs: eps_abs.max(zero),
            eps_rel,
            t_min,
            t_max,
        }
    }

    /// [`RayClip::clip_box`] for each lane's ray: `(t0, t1, kept)`, the interval
    /// meaningful where `kept`.
    #[inline(always)]
    pub fn clip_box_lanes(&self, aabb: &Aabb) -> (L, L, L::Mask) {
        // No lane asked about, none found missing: always `Some`.
        let everything = (self.t_min, self.t_max, L::splat(0.0).lt(L::splat(1.0)));
        self.clip_box_lanes_in(aabb, 0).unwrap_or(everything)
    }

    /// [`RayClipLanes::clip_box_lanes`], or `None` where it would keep none of the lanes
    /// in `lanes` (lane `i` in bit `i`; never for none): as soon as the axes seen so far
    /// leave each of those lanes' rays an empty interval, the other axes are not
    /// computed. Exact: such a lane is not kept whatever the other axes give (the
    /// intersection is empty and neither bound is NaN), and a ray that is not finite is
    /// never found empty. Most boxes miss every ray of a vector (two thirds of them in
    /// the Cornell box), and one axis often says so: the box's thinnest, first. A wall's
    /// thin axis alone drops every ray that leaves it behind, where a long axis drops
    /// none of the rays that start within its span (every ray inside a room).
    #[inline(always)]
    pub fn clip_box_lanes_in(&self, aabb: &Aabb, lanes: u32) -> Option<(L, L, L::Mask)> {
        let e = aabb.max - aabb.min;
        if e.x < e.y && e.x < e.z {
            self.clip_box_lanes_from::<0>(aabb, lanes)
        } else if e.y < e.z {
            self.clip_box_lanes_from::<1>(aabb, lanes)
        } else {
            self.clip_box_lanes_from::<2>(aabb, lanes)
        }
    }

    /// [`RayClipLanes::clip_box_lanes_in`], testing axis `FIRST` alone, then with the
    /// next, then the third. The interval is the same bits in any order: the axes'
    /// bounds are never NaN for a ray that is kept by them (finite, non-degenerate), so
    /// their maximum and minimum do not depend on the order taken; it is still taken as
    /// `max_element` and `min_element` take it, `x` with `(y, z)`.
    #[inline(always)]
    fn clip_box_lanes_from<const FIRST: usize>(
        &self,
        aabb: &Aabb,
        lanes: u32,
    ) -> Option<(L, L, L::Mask)> {
        let (t_min, t_max) = (self.t_min, self.t_max);
        // One axis at a time, each folded into the intersection before it is tested, so
        // that what is live at once fits the vector registers (all three axes' sets
        // computed at once did not, and were spilled and reloaded).
        let (second, third) = match FIRST {
            0 => (2, 1),
            1 => (2, 0),
            _ => (1, 0),
        };
        let a = box_axis(self, aabb, FIRST);
        if box_misses(self, a, lanes) {
            return None;
        }
        let b = box_axis(self, aabb, second);
        if box_misses(self, (a.0.max_cmp(b.0), a.1.min_cmp(b.1)), lanes) {
            return None;
        }
        let c = box_axis(self, aabb, third);
        let ((lo_x, hi_x), (lo_y, hi_y), (lo_z, hi_z)) = match FIRST {
            0 => (a, c, b),
            1 => (c, a, b),
            _ => (c, b, a),
        };
        let (lo_yz, hi_yz) = (lo_y.max_cmp(lo_z), hi_y.min_cmp(hi_z));
        let t0 = lo_x.max_cmp(lo_yz).max(t_min);
        let t1 = hi_x.min_cmp(hi_yz).min(t_max);
        let (t0, t1, kept) = widen(t0, t1, t_min, t_max);
        Some((
            L::select(self.degenerate, t_min, t0),
            L::select(self.degenerate, t_max, t1),
            L::or(self.degenerate, kept),
        ))
    }

    /// [`RayClip::clip_sphere`] for each lane's ray, as [`RayClipLanes::clip_box_lanes`].
    ///
    /// A hit at `t` needs `|m + t d| < R(t)`, with `m` the origin less the centre and
    /// `R(t) = R0 + eps_rel t`, `R0` the radius grown by `eps_abs` and the rounding slack
    /// (the threshold `max(eps_abs, eps_rel t)` is at most `eps_abs + eps_rel t`). About
    /// the closest approach `t_c = -(m . d) / (d . d)`, with `q = m + t_c d` (orthogonal
    /// to `d`) and `u = t - t_c`, that is `q . q + u^2 (d . d) < (A + eps_rel u)^2` with
    /// `A = R0 + eps_rel t_c`: a quadratic in `u` whose discriminant (over four) is `A^2
    /// (d . d) - (d . d - eps_rel^2) (q . q)`. Solved about `t_c` rather than from the
    /// origin, as Haines et al. advise ("Precise Ray/Sphere Intersection", Ray Tracing
    /// Gems, ch. 7): `q` is computed, not found as a difference of two large squares, so a
    /// millimetre sphere a kilometre away is still told from a miss. Where `d . d` is not
    /// above `eps_rel^2` (a threshold growing as fast as the ray), every lane keeps the
    /// whole range.
    #[inline(always)]
    pub fn clip_sphere_lanes(&self, sphere: &BoundingSphere) -> (L, L, L::Mask) {
        let (t_min, t_max) = (self.t_min, self.t_max);
        let c = sphere.center;
        let m = self.origin - LaneVec3::splat(c);
        let d = self.dir;
        let dd = d.dot(d);
        let t_c = -(m.dot(d) / dd);
        let q = m + d * t_c;
        let qq = q.dot(q);
        // The f32 rounding of `m`, `t_c` and `q` (a few ulps of the coordinates that make
        // them) and of the tracer's own point and field near the sphere. No more: a ray
        // leaves a surface from 32 roundings of the hit above it (the integrator's spawn
        // offset, which covers this slack, at most about 23 such roundings), and a wider
        // slack would keep the sphere it leaves as a candidate, whose small values near the
        // origin make the march crawl away from it.
        let scale =
            self.origin.abs().max_element() + L::splat(c.abs().max_element() + sphere.radius);
        let slack = L::splat(4.0 * f32::EPSILON) * scale;
        let e = self.eps_rel;
        let a = dd - e * e;
        let big_a = L::splat(sphere.radius) + slack + self.eps_abs + e * t_c;
        let disc = big_a * big_a * dd - a * qq;
        let root = disc.max(L::splat(0.0)).sqrt();
        let (u0, u1) = ((big_a * e - root) / a, (big_a * e + root) / a);
        let (t0, t1) = ((t_c + u0).max(t_min), (t_c + u1).min(t_max));
        // No real root: the ray stays outside the grown sphere (a NaN `disc` is kept).
        let outside = disc.lt(L::splat(0.0));
        let t0 = L::select(outside, L::splat(f32::INFINITY), t0);
        let t1 = L::select(outside, L::splat(f32::NEG_INFINITY), t1);
        let (t0, t1, kept) = widen(t0, t1, t_min, t_max);
        let everything = L::or(self.degenerate, L::not(a.gt(L::splat(0.0))));
        (
            L::select(everything, t_min, t0),
            L::select(everything, t_max, t1),
            L::or(everything, kept),
        )
    }

    /// [`RayClip::clip_half_space`] for each lane's ray, as [`RayClipLanes::clip_box_lanes`].
    #[inline(always)]
    pub fn clip_half_space_lanes(&self, h: &HalfSpace) -> (L, L, L::Mask) {
        let normal = LaneVec3::splat(h.normal);
        let o = self.origin.abs();
        let n = h.normal.abs();
        let terms = L::splat(n.x) * o.x + L::splat(n.y) * o.y + L::splat(n.z) * o.z;
        let rounding = L::splat(4.0 * f32::EPSILON) * (terms + L::splat(h.height.abs()));
        let a = self.origin.dot(normal) - L::splat(h.height) - rounding;
        let b = self.dir.dot(normal);
        let b_rel = b - self.eps_rel;
        let one = L::splat(1.0);
        let (t0, t1) = below_threshold(
            a,
            self.eps_abs,
            (b, one / b),
            (b_rel, one / b_rel),
            (self.t_min, self.t_max),
        );
        widen(t0, t1, self.t_min, self.t_max)
    }
}

/// The half-space `dot(p, normal) <= height`, with a normal of any positive length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfSpace {
    /// Outward normal (not necessarily unit).
    pub normal: Vec3,
    /// Offset: the boundary is `dot(p, normal) = height`.
    pub height: f32,
}

impl HalfSpace {
    /// `dot(p, normal) - height`: what a field honouring this half-space is at least.
    #[inline]
    pub fn value(&self, p: Vec3) -> f32 {
        p.dot(self.normal) - self.height
    }

    /// The part of `[params.t_min, params.t_max]` where a field at least
    /// [`HalfSpace::value`] can fall below the hit threshold `max(eps_abs, eps_rel t)`.
    ///
    /// Along the ray the bound is linear, `a + b t`, so the set where it is below either
    /// threshold is a union of two half-lines, solved exactly (then widened for rounding).
    /// A ray parallel to a plane does reach it: `eps_rel t` grows until it exceeds the
    /// ray's height, as it does for a tracer marching that ray.
    pub fn hit_interval(&self, ray: &Ray, params: &TraceParams) -> Option<(f32, f32)> {
        RayClip::new(ray, params).clip_half_space(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A number in `[-0.5, 0.5)` for case `i` and stream `k`: a cheap, fixed
    /// spread of test cases (distinct primes `k` give unrelated streams).
    fn spread(i: u32, k: u32) -> f32 {
        (i.wrapping_mul(k) % 10_007) as f32 / 10_007.0 - 0.5
    }

    fn params() -> TraceParams {
        TraceParams {
            t_min: 0.0,
            t_max: 100.0,
            max_steps: 512,
            eps_abs: 1e-4,
            eps_rel: 1e-3,
        }
    }

    /// The early answer of `clip_box_lanes_in` is exact: where it says no lane keeps the
    /// box, the whole computation keeps none of them; elsewhere it gives the same bits,
    /// as does testing any axis first.
    /// Over rays near, inside, along and far from boxes from 1e-4 to 1e4 wide, at
    /// coordinates up to 1e4, with degenerate rays and ranges among them.
    #[test]
    fn early_miss_of_a_box_is_exact() {
        let (mut early, mut checked) = (0, 0);
        for i in 0..40_000u32 {
            let scale = [1e-4, 1e-2, 1.0, 1e2, 1e4][(i % 5) as usize];
            let center = Vec3::new(spread(i, 7919), spread(i, 104_729), spread(i, 15_485_863))
                * [0.0, 1.0, 1e4][(i / 5 % 3) as usize];
            let half = Vec3::new(1.0, spread(i, 31) + 0.51, 1e-3 + spread(i, 37).abs()) * scale;
            let aabb = Aabb::from_center(center, half);
            let origin = center
                + Vec3::new(spread(i, 611_953), spread(i, 3571), spread(i, 2_750_159))
                    * scale
                    * 8.0;
            let mut dir = Vec3::new(spread(i, 1009), spread(i, 7_368_787), spread(i, 4099));
            match i % 17 {
                0 => dir = Vec3::ZERO,
                1 => dir.x = 0.0,
                2 => dir = Vec3::new(f32::NAN, 0.0, 1.0),
                _ => {}
            }
            let origin = if i % 19 == 0 {
                Vec3::splat(f32::INFINITY)
            } else {
                origin
            };
            let params = TraceParams {
                t_min: [0.0, 1e-3 * scale, 2.0 * scale][(i % 3) as usize],
                t_max: [100.0 * scale, 1e4, f32::INFINITY][(i / 3 % 3) as usize],
                max_steps: 512,
                eps_abs: [1e-6, 1e-3 * scale][(i % 2) as usize],
                eps_rel: [1e-5, 1e-3][(i / 2 % 2) as usize],
            };
            let clip = RayClip::new(&Ray::new(origin, dir), &params);
            let whole = clip.clip_box_lanes(&aabb);
            let bits = |(a, b, k): (f32, f32, bool)| (a.to_bits(), b.to_bits(), k);
            // Whichever axis is tested first, the same bits.
            for from in [
                clip.clip_box_lanes_from::<0>(&aabb, 0),
                clip.clip_box_lanes_from::<1>(&aabb, 0),
                clip.clip_box_lanes_from::<2>(&aabb, 0),
            ] {
                assert_eq!(from.map(bits), Some(bits(whole)), "ray {i}");
            }
            match clip.clip_box_lanes_in(&aabb, 1) {
                None => {
                    early += 1;
                    assert!(!whole.2, "ray {i}: kept by the whole clip");
                }
                Some(got) => {
                    assert_eq!(bits(got), bits(whole), "ray {i}");
                }
            }
            checked += usize::from(!whole.2);
        }
        // The early answer is taken for most of the boxes the rays miss.
        assert!(early * 2 > checked, "{early} early of {checked} misses");
    }

    #[test]
    fn box_interval_clips_and_grows_by_the_threshold() {
        let b = Aabb::from_center(Vec3::ZERO, Vec3::ONE);
        let hit = Ray::new(Vec3::new(0.0, 0.0, -10.0), Vec3::Z);
        let (t0, t1) = b.hit_interval(&hit, &params()).unwrap();
        // Grown by eps_rel * ~11.7 = ~0.012 on each side.
        assert!(t0 < 9.0 && t0 > 8.98, "{t0}");
        assert!(t1 > 11.0 && t1 < 11.02, "{t1}");
        // Passing 0.005 above the top: within the grown box, so kept.
        let graze = Ray::new(Vec3::new(0.0, 1.005, -10.0), Vec3::Z);
        assert!(b.hit_interval(&graze, &params()).is_some());
        // Passing 0.5 above it: nothing to march.
        let over = Ray::new(Vec3::new(0.0, 1.5, -10.0), Vec3::Z);
        assert_eq!(b.hit_interval(&over, &params()), None);
        // Behind the ray, or beyond t_max.
        let away = Ray::new(Vec3::new(0.0, 0.0, -10.0), -Vec3::Z);
        assert_eq!(b.hit_interval(&away, &params()), None);
        let short = TraceParams {
            t_max: 5.0,
            ..params()
        };
        assert_eq!(b.hit_interval(&hit, &short), None);
        // From inside, the interval starts at t_min.
        let inside = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(b.hit_interval(&inside, &params()).unwrap().0, 0.0);
    }

    #[test]
    fn a_ray_leaving_a_wall_is_not_a_candidate_for_it() {
        // The floor slab y in [-0.1, 0]; rays start 1e-3 above it (ten hit thresholds).
        let floor = Aabb {
            min: Vec3::new(-1.0, -0.1, -1.0),
            max: Vec3::new(1.0, 0.0, 1.0),
        };
        let p = params();
        for dir in [
            Vec3::Y,
            Vec3::new(1.0, 0.1, 0.0),
            Vec3::new(0.3, 0.01, -0.2),
        ] {
            let ray = Ray::new(Vec3::new(0.2, 1e-3, 0.3), dir);
            assert_eq!(floor.hit_interval(&ray, &p), None, "{dir}");
        }
        // Nearly parallel (slope below eps_rel = 1e-3): the threshold catches up at
        // t = 1e-3 / (1e-3 - 1e-4) ~ 1.1, still over the floor, so it is kept.
        let creeping = Ray::new(Vec3::new(-0.9, 1e-3, 0.3), Vec3::new(1.0, 1e-4, 0.0));
        assert!(floor.hit_interval(&creeping, &p).is_some());
    }

    #[test]
    fn sphere_interval_is_the_grown_sphere() {
        let b = BoundingSphere {
            center: Vec3::ZERO,
            radius: 1.0,
        };
        let p = params();
        let hit = Ray::new(Vec3::new(0.0, 0.0, -10.0), Vec3::Z);
        let (t0, t1) = b.hit_interval(&hit, &p).unwrap();
        // Radius 1 + 1e-4 + 1e-3 t: enters at t0 (1 + 1e-4 + 1e-3 t0 = 10 - t0), leaves at
        // t1 (t1 - 10 = 1 + 1e-4 + 1e-3 t1).
        let want0 = (10.0 - 1.0 - 1e-4) / (1.0 + 1e-3);
        let want1 = (10.0 + 1.0 + 1e-4) / (1.0 - 1e-3);
        assert!((t0 - want0).abs() < 1e-3 && t0 <= want0, "{t0} {want0}");
        assert!((t1 - want1).abs() < 1e-3 && t1 >= want1, "{t1} {want1}");
        // Passing 0.005 from the surface at t = 10 (threshold ~0.0101): kept, with the
        // interval about the closest approach.
        let graze = Ray::new(Vec3::new(0.0, 1.005, -10.0), Vec3::Z);
        let (g0, g1) = b.hit_interval(&graze, &p).unwrap();
        assert!(g0 < 10.0 && 10.0 < g1 && g1 - g0 < 1.0, "{g0} {g1}");
        // Passing 0.05 from it, inside its box: nothing to march.
        let near = Ray::new(Vec3::new(0.0, 0.7, -10.0), Vec3::new(0.0, 0.07, 1.0));
        assert_eq!(b.hit_interval(&near, &p), None);
        // Behind the ray, beyond t_max, or before t_min.
        let away = Ray::new(Vec3::new(0.0, 0.0, -10.0), -Vec3::Z);
        assert_eq!(b.hit_interval(&away, &p), None);
        let short = TraceParams { t_max: 5.0, ..p };
        assert_eq!(b.hit_interval(&hit, &short), None);
        // From inside, the interval starts at t_min.
        let inside = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(b.hit_interval(&inside, &p).unwrap().0, 0.0);
    }

    /// Scale-free: a 1 mm sphere 1 km from the ray's origin, and a 1 km sphere seen from 1
    /// mm off its surface, each with rays that graze it by a tenth of the threshold (kept,
    /// holding the closest point) and that pass wide of it (left out): a hundred
    /// thresholds for the small one, 1 cm for the large one, whose coordinates round to
    /// 0.06 mm in `f32`.
    #[test]
    fn sphere_interval_at_the_extremes_of_scale() {
        for (center, radius, from, wide) in [
            (Vec3::new(1000.0, 3.0, -2.0), 1e-3, Vec3::ZERO, 0.1),
            (
                Vec3::new(0.0, -1000.0, 0.0),
                1000.0,
                Vec3::new(0.0, 1e-3, 0.0),
                1e-2,
            ),
        ] {
            let b = BoundingSphere { center, radius };
            let p = TraceParams {
                t_min: 0.0,
                t_max: 1e5,
                max_steps: 512,
                eps_abs: 1e-6,
                eps_rel: 1e-6,
            };
            // A point on the sphere, and a tangent direction there.
            let normal = (from - center).normalize();
            let tangent = normal.cross(Vec3::Z).normalize();
            let surface = center + normal * radius;
            let distance = (surface - from).length().max(1.0);
            let threshold = p.eps_abs.max(p.eps_rel * distance);
            for (offset, kept) in [(0.1 * threshold, true), (wide, false)] {
                let at = surface + normal * offset;
                let origin = at - tangent * distance;
                let ray = Ray::new(origin, tangent);
                let got = b.hit_interval(&ray, &p);
                assert_eq!(got.is_some(), kept, "{radius}: {offset} off, {got:?}");
                if let Some((t0, t1)) = got {
                    assert!(t0 <= distance && distance <= t1, "{t0} {distance} {t1}");
                }
            }
        }
    }

    /// Every point a tracer would call a hit on a moved sphere, with the field as the
    /// tracer evaluates it (`PreparedSdf`, in `f32` at the rounded point), lies in the
    /// interval: rays that graze, cross or leave spheres of radius 1e-3 to 1e3 whose centres
    /// are up to 1e4 from the origin, with the thresholds of camera and bounce rays.
    #[test]
    fn sphere_interval_holds_every_hit_of_the_tracer() {
        use crate::{DistanceField, PreparedSdf, Primitive, Sdf};
        let mut hits = 0;
        for i in 0..20_000u32 {
            let radius = [1e-3, 1e-1, 1.0, 1e1, 1e3][(i % 5) as usize];
            let far = [0.0, 1.0, 1e2, 1e4][(i / 5 % 4) as usize];
            let center =
                Vec3::new(spread(i, 7919), spread(i, 104_729), spread(i, 15_485_863)) * far;
            let sdf = PreparedSdf::new(&Sdf::from(Primitive::Sphere { radius }).translate(center));
            let sphere = BoundingSphere { center, radius };
            // Aim at a point near the surface, from a distance of 1e-5 to 10 radii.
            let toward = Vec3::new(spread(i, 611_953), spread(i, 3571), spread(i, 2_750_159))
                .normalize_or(Vec3::X);
            let target = center + toward * radius * (1.0 + 0.02 * spread(i, 31));
            let dir = Vec3::new(spread(i, 1009), spread(i, 7_368_787), spread(i, 4099))
                .normalize_or(Vec3::Y);
            let back = radius * [1e-5, 1e-2, 1.0, 10.0][(i / 20 % 4) as usize];
            let ray = Ray::new(target - dir * back, dir);
            let params = TraceParams {
                t_min: 0.0,
                t_max: 1e6,
                max_steps: 512,
                eps_abs: [0.0, 1e-6][(i % 2) as usize],
                eps_rel: [1e-4, 1e-3][(i / 2 % 2) as usize],
            }
            .resolving(ray.origin);
            let interval = sphere.hit_interval(&ray, &params);
            for k in 0..64 {
                let t = back * 2.0 * k as f32 / 63.0;
                let f = sdf.distance(ray.at(t));
                if f < params.eps_abs.max(params.eps_rel * t) {
                    hits += 1;
                    assert!(
                        interval.is_some_and(|(t0, t1)| t0 <= t && t <= t1),
                        "case {i}: f = {f} at t = {t}, interval {interval:?}"
                    );
                }
            }
        }
        assert!(hits > 10_000, "{hits} hits checked");
    }

    #[test]
    fn box_interval_axis_parallel_rays() {
        let b = Aabb::from_center(Vec3::ZERO, Vec3::ONE);
        // dir has zero y and z components: the slabs in y and z are tested by position.
        let inside_slab = Ray::new(Vec3::new(-5.0, 0.99, 0.0), Vec3::X);
        assert!(b.hit_interval(&inside_slab, &params()).is_some());
        let outside_slab = Ray::new(Vec3::new(-5.0, 1.5, 0.0), Vec3::X);
        assert_eq!(b.hit_interval(&outside_slab, &params()), None);
    }

    #[test]
    fn half_space_interval_is_exact_for_planes() {
        // The floor y <= 0, seen from y = 1.
        let floor = HalfSpace {
            normal: Vec3::Y,
            height: 0.0,
        };
        let p = params();
        let down = Ray::new(Vec3::Y, -Vec3::Y);
        let (t0, t1) = floor.hit_interval(&down, &p).unwrap();
        // The bound 1 - t meets the threshold 1e-3 t at t = 1 / 1.001.
        assert!((t0 - 1.0 / 1.001).abs() < 1e-4, "{t0}");
        assert_eq!(t1, p.t_max);
        // Leaving the floor: never within the threshold.
        let up = Ray::new(Vec3::Y * 0.01, Vec3::Y);
        assert_eq!(floor.hit_interval(&up, &p), None);
        // Parallel at height 0.05: eps_rel t reaches 0.05 at t = 50.
        let level = Ray::new(Vec3::Y * 0.05, Vec3::X);
        let (t0, _) = floor.hit_interval(&level, &p).unwrap();
        assert!((t0 - 50.0).abs() < 1e-2, "{t0}");
        // Parallel at height 0.5: not before t_max = 100.
        let high = Ray::new(Vec3::Y * 0.5, Vec3::X);
        assert_eq!(floor.hit_interval(&high, &p), None);
    }

    #[test]
    fn degenerate_inputs_keep_everything_or_nothing_never_panic() {
        let b = Aabb::from_center(Vec3::ZERO, Vec3::ONE);
        let p = params();
        let nan = Ray {
            origin: Vec3::ZERO,
            dir: Vec3::NAN,
        };
        assert_eq!(b.hit_interval(&nan, &p), Some((p.t_min, p.t_max)));
        let h = HalfSpace {
            normal: Vec3::Y,
            height: 0.0,
        };
        assert!(h.hit_interval(&nan, &p).is_some());
        // A threshold growing faster than the ray: at t = 50 the box is ~69 away and the
        // threshold is 100, so that point must be kept.
        let wild = TraceParams { eps_rel: 2.0, ..p };
        let far = Ray::new(Vec3::new(0.0, 50.0, 0.0), Vec3::X);
        let (t0, t1) = b.hit_interval(&far, &wild).unwrap();
        assert!(t0 <= 50.0 && 50.0 <= t1, "{t0} {t1}");
    }
}
