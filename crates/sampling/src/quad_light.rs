//! Sampling directions toward a one-sided parallelogram light
//! `corner + s edge_u + t edge_v`, `(s, t)` in `[0, 1]^2`, emitting on the side
//! of `edge_u x edge_v`.
//!
//! Two strategies: uniform area sampling with its pdf converted to solid
//! angle, and Ureña et al.'s spherical-rectangle sampling, whose pdf is
//! constant in solid angle (for rectangles only). A shading point behind the
//! emitting side, or on the light's plane, gets no sample and pdf 0.

use std::f64::consts::TAU;

use glam::{DVec3, Vec2, Vec3};
use wide::f64x4;

use crate::light::DirectionSample;
use crate::math::{clamp_u2, normalize_with_length};
use crate::sphere_light::finite_pdf;

/// Unit emitting normal and area of the parallelogram, or `None` if it is
/// degenerate or not finite.
#[inline]
fn normal_and_area(edge_u: Vec3, edge_v: Vec3) -> Option<(Vec3, f32)> {
    normalize_with_length(edge_u.cross(edge_v))
}

/// True when `p` is strictly on the emitting side of the plane.
#[inline]
fn faces(p: Vec3, corner: Vec3, normal: Vec3) -> bool {
    p.is_finite() && corner.is_finite() && (p - corner).dot(normal) > 0.0
}

/// Samples a point uniformly on the parallelogram and returns the direction
/// to it with the area pdf converted to solid angle,
/// `pdf = d^2 / (cos(alpha) area)`, where `alpha` is the angle between the
/// light's normal and `-wi` (pbrt-v4 §4.2.3: `d omega = cos(alpha) dA / d^2`).
/// `None` when `p` is behind or on the light's plane, or the light is
/// degenerate.
pub fn sample_quad_area(
    p: Vec3,
    corner: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    u: Vec2,
) -> Option<DirectionSample> {
    let (normal, area) = normal_and_area(edge_u, edge_v)?;
    if !faces(p, corner, normal) {
        return None;
    }
    let u = clamp_u2(u);
    let point = corner + u.x * edge_u + u.y * edge_v;
    DirectionSample::toward_with(p, point, normal, |wi, distance| {
        let cos_alpha = -wi.dot(normal);
        if cos_alpha > 0.0 {
            distance * distance / (cos_alpha * area)
        } else {
            0.0
        }
    })
}

/// Where the ray `(p, wi)` meets the front face of the parallelogram:
/// `(t, cos_alpha, area)` in f64, or `None` on a miss. The bounds get a
/// slack of 1e-5 of the edges plus a few f32 ulps of the coordinates'
/// magnitude, so that a sample on an edge counts as a hit even for a light
/// 1e-4 wide, whose sampled directions the f32 grid rounds by 1e-3 of its
/// width (the same reasoning as for the sphere light).
fn hit_front(
    p: Vec3,
    corner: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    wi: Vec3,
) -> Option<(f64, f64, f64)> {
    let (normal32, _) = normal_and_area(edge_u, edge_v)?;
    if !faces(p, corner, normal32) || !wi.is_finite() {
        return None;
    }
    let (eu, ev) = (edge_u.as_dvec3(), edge_v.as_dvec3());
    let n_raw = eu.cross(ev);
    let area2 = n_raw.length_squared();
    let area = area2.sqrt();
    let normal = n_raw / area;
    let wi = wi.as_dvec3();
    let len = wi.length();
    if len <= 0.0 {
        return None;
    }
    let wi = wi / len;
    let denom = wi.dot(normal);
    if denom >= 0.0 {
        return None;
    }
    let o = p.as_dvec3();
    let c = corner.as_dvec3();
    let t = (c - o).dot(normal) / denom;
    if t.is_nan() || t <= 0.0 {
        return None;
    }
    let q = o + t * wi - c;
    // q = a edge_u + b edge_v; cross with the other edge to isolate each.
    let a = q.cross(ev).dot(n_raw) / area2;
    let b = eu.cross(q).dot(n_raw) / area2;
    // A world-space error `e` moves `a` by at most `e |edge_v| / area`.
    let magnitude = t + f64::from(p.abs().max_element().max(corner.abs().max_element()));
    let error = 2e-7 * magnitude / area;
    let inside = |x: f64, slack: f64| (-slack..=1.0 + slack).contains(&x);
    (inside(a, 1e-5 + error * ev.length()) && inside(b, 1e-5 + error * eu.length()))
        .then_some((t, -denom, area))
}

/// Solid-angle pdf with which [`sample_quad_area`] produces `wi` from `p`:
/// `d^2 / (cos(alpha) area)` at the point where the ray meets the light; 0
/// when the ray misses, hits the back, or `p` is behind the emitting side.
pub fn quad_area_pdf(p: Vec3, corner: Vec3, edge_u: Vec3, edge_v: Vec3, wi: Vec3) -> f32 {
    match hit_front(p, corner, edge_u, edge_v, wi) {
        Some((t, cos_alpha, area)) => finite_pdf(t * t / (cos_alpha * area)),
        None => 0.0,
    }
}

/// The spherical rectangle subtended by a rectangular light from a point, for
/// sampling with a constant solid-angle pdf.
///
/// Ureña, Fajardo and King 2013, "An Area-Preserving Parametrization for
/// Spherical Rectangles", EGSR, Algorithm 1 (also pbrt-v4
/// `SampleSphericalRectangle`). Computed in f64: the solid angle is
/// `g0 + g1 + g2 + g3 - 2pi`, a sum of interior angles that cancels badly for
/// small rectangles. Each interior angle is the argument of a complex number
/// (accurate near 0 and pi, where the paper's `acos` is not), so their sum is
/// the argument of the product: one `atan2` for the solid angle, and `k` (the
/// angle the sampling starts from) kept as its cosine and sine, which the product
/// of the last two gives without trigonometry.
#[derive(Clone, Copy, Debug)]
pub struct SphericalRectangle {
    /// The rectangle in every lane: the scalar functions are the lanes' in one lane.
    lanes: SphericalRectangles,
}

/// Four [`SphericalRectangle`]s, a lane of `f64x4` each, from
/// [`RectangleFrame::seen_from_lanes`]: the lanes where [`SphericalRectangles::exists`]
/// is false hold values to be ignored.
#[derive(Clone, Copy, Debug)]
pub struct SphericalRectangles {
    o: DVec3Lanes,
    x: DVec3Lanes,
    y: DVec3Lanes,
    z: DVec3Lanes,
    z0: f64x4,
    x0: f64x4,
    y0: f64x4,
    x1: f64x4,
    y1: f64x4,
    b0: f64x4,
    b1: f64x4,
    /// `1 - b0^2`, in a form that does not cancel.
    one_minus_b0_squared: f64x4,
    /// `cos k` and `sin k` of the paper's `k = 2pi - g2 - g3`.
    cos_k: f64x4,
    sin_k: f64x4,
    solid_angle: f64x4,
    normal: [Vec3; RECTANGLE_LANES],
    /// Bit `i`: lane `i` holds a rectangle.
    exists: u8,
}

/// A complex number as `(re, im)`.
type Complex = (f64x4, f64x4);

#[inline(always)]
fn times((a, b): Complex, (c, d): Complex) -> Complex {
    (a * c - b * d, a * d + b * c)
}

impl SphericalRectangle {
    /// Below this solid angle (steradians) [`SphericalRectangle::new`] declines:
    /// the f64 cancellation in the interior-angle sum would reach 1e-6 of the
    /// result. Area sampling is near-optimal there anyway: the light is so small
    /// or far that its area-to-solid-angle factor is nearly constant.
    pub const MIN_SOLID_ANGLE: f32 = 1e-9;

    /// Largest `|cos|` of the angle between the edges accepted as a rectangle.
    pub const RECTANGLE_TOLERANCE: f32 = 1e-4;

    /// The spherical rectangle of the light seen from `p`. `None` when the
    /// edges are not perpendicular (within [`Self::RECTANGLE_TOLERANCE`]) or
    /// degenerate, when `p` is behind or on the light's plane, or when the
    /// solid angle is below [`Self::MIN_SOLID_ANGLE`] or within 1e-6 of `2pi`,
    /// where the interior angles' sum cannot tell the two apart (use
    /// [`sample_quad_area`] then; [`sample_quad_solid_angle`] does this
    /// fallback for you). [`RectangleFrame::seen_from`] gives the same, for a
    /// frame made once per light.
    pub fn new(p: Vec3, corner: Vec3, edge_u: Vec3, edge_v: Vec3) -> Option<Self> {
        RectangleFrame::new(corner, edge_u, edge_v)?.seen_from(p)
    }

    /// Solid angle of the rectangle seen from the shading point, in sr.
    pub fn solid_angle(&self) -> f32 {
        self.lanes.solid_angle.as_array()[0] as f32
    }

    /// The constant solid-angle pdf `1 / solid_angle` of [`Self::sample`] for
    /// directions that hit the rectangle (finite: the solid angle is at least
    /// [`Self::MIN_SOLID_ANGLE`]).
    pub fn pdf(&self) -> f32 {
        (1.0 / self.lanes.solid_angle.as_array()[0]) as f32
    }

    /// Samples a direction uniformly in solid angle over the rectangle
    /// (Ureña et al. 2013, Algorithm 1, "sample"): `u.x` picks the
    /// sub-rectangle `[x0, xu]` with solid angle `u.x S`, `u.y` picks the
    /// height along the resulting vertical edge uniformly in the projected
    /// coordinate `h`. `None` only if rounding defeats the invariant of
    /// [`DirectionSample`]. The one-lane instance of
    /// [`SphericalRectangles::sample`], bit for bit.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<DirectionSample> {
        let [sample, ..] = self.lanes.sample([u; RECTANGLE_LANES]);
        sample
    }
}

impl SphericalRectangles {
    /// Whether lane `i` holds a rectangle: what [`RectangleFrame::seen_from`] gives
    /// for its light and point is not `None`.
    #[inline]
    pub fn exists(&self, i: usize) -> bool {
        self.exists >> i & 1 == 1
    }

    /// [`SphericalRectangle::sample`] in each lane, with that lane's `u`: every lane
    /// gives the bits the one-lane call gives for it, whatever the other lanes hold.
    /// Lanes without a rectangle give values to be ignored.
    #[inline]
    pub fn sample(&self, u: [Vec2; RECTANGLE_LANES]) -> [Option<DirectionSample>; RECTANGLE_LANES] {
        let mut out = [None; RECTANGLE_LANES];
        self.sample_into(u, &mut out);
        out
    }

    /// [`SphericalRectangles::sample`] written into `out`, each lane's sample stored into
    /// its slot as it is made: for a caller that keeps the samples in memory, since an
    /// array of them returned whole is stored in pieces and copied out a vector at a
    /// time, and each load waits for its stores to retire.
    #[inline]
    pub fn sample_into(
        &self,
        u: [Vec2; RECTANGLE_LANES],
        out: &mut [Option<DirectionSample>; RECTANGLE_LANES],
    ) {
        let (solid_angle, cos_k, sin_k) = (self.solid_angle, self.cos_k, self.sin_k);
        let (z0, x0, x1, y0, y1) = (self.z0, self.x0, self.x1, self.y0, self.y1);
        let u = u.map(clamp_u2);
        let (ux, uy) = (lanes(|i| f64::from(u[i].x)), lanes(|i| f64::from(u[i].y)));
        // au = u.x S + k, by the angle-sum formulas.
        let (sin_us, cos_us) = (ux * solid_angle).sin_cos();
        let cos_au = cos_us * cos_k - sin_us * sin_k;
        let sin_au = sin_us * cos_k + cos_us * sin_k;
        let fu = (cos_au * self.b0 - self.b1) / sin_au;
        // The paper's xu = -cu z0 / sqrt(1 - cu^2) with cu = sign(fu) / sqrt(fu^2 +
        // b0^2) is sign(fu) |z0| / sqrt(fu^2 - (1 - b0^2)): one square root and one
        // division fewer on the chain, and no cancellation in 1 - cu^2. Where the
        // root is 0 or rounding makes it imaginary, cu is +-1 and xu is the edge
        // of the rectangle on fu's side (pbrt-v4 keeps cu off +-1 for the same
        // end); then xu is clamped into the rectangle.
        let g = fu * fu - self.one_minus_b0_squared;
        let sign = fu & f64x4::splat(-0.0);
        let xu = g
            .simd_gt(f64x4::ZERO)
            .select((-z0 | sign) / g.sqrt(), f64x4::splat(f64::INFINITY) | sign);
        let xu = xu.max(x0).min(x1);
        let d2 = xu * xu + z0 * z0;
        let d = d2.sqrt();
        let h0 = y0 / (d2 + y0 * y0).sqrt();
        let h1 = y1 / (d2 + y1 * y1).sqrt();
        let hv = h0 + uy * (h1 - h0);
        let hv2 = hv * hv;
        let yv = hv2
            .simd_lt(f64x4::splat(1.0 - 1e-12))
            .select((hv * d / (f64x4::ONE - hv2).sqrt()).max(y0).min(y1), y1);
        let local = self.x * xu + self.y * yv + self.z * z0;
        let distance = local.dot(local).sqrt();
        let wi = local * (f64x4::ONE / distance);
        let point = self.o + local;
        let (pdf, distance) = ((f64x4::ONE / solid_angle).to_array(), distance.to_array());
        for (i, out) in out.iter_mut().enumerate() {
            let sample = DirectionSample {
                wi: wi.lane(i).as_vec3(),
                distance: distance[i] as f32,
                pdf: pdf[i] as f32,
                point: point.lane(i).as_vec3(),
                normal: self.normal[i],
            };
            let ok = sample.wi.is_finite()
                && sample.point.is_finite()
                && sample.distance.is_finite()
                && sample.distance > 0.0
                && sample.pdf.is_finite()
                && sample.pdf > 0.0;
            *out = ok.then_some(sample);
        }
    }
}

/// The lanes the spherical rectangle is computed in: `f64x4`'s.
pub const RECTANGLE_LANES: usize = 4;

/// An `f64x4` whose lane `i` is `f(i)`.
#[inline(always)]
fn lanes(f: impl Fn(usize) -> f64) -> f64x4 {
    f64x4::new(std::array::from_fn(f))
}

/// Four `DVec3`, a lane each.
#[derive(Clone, Copy, Debug)]
struct DVec3Lanes {
    x: f64x4,
    y: f64x4,
    z: f64x4,
}

impl DVec3Lanes {
    #[inline(always)]
    fn gather(f: impl Fn(usize) -> DVec3) -> Self {
        let v: [DVec3; RECTANGLE_LANES] = std::array::from_fn(f);
        Self {
            x: lanes(|i| v[i].x),
            y: lanes(|i| v[i].y),
            z: lanes(|i| v[i].z),
        }
    }

    #[inline(always)]
    fn dot(self, o: Self) -> f64x4 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    fn lane(self, i: usize) -> DVec3 {
        DVec3::new(
            self.x.as_array()[i],
            self.y.as_array()[i],
            self.z.as_array()[i],
        )
    }
}

impl std::ops::Add for DVec3Lanes {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl std::ops::Sub for DVec3Lanes {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl std::ops::Mul<f64x4> for DVec3Lanes {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: f64x4) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

/// What of a rectangular light's [`SphericalRectangle`] does not depend on the point it
/// is seen from: its frame, its sides and its normal, made once per light. Its
/// [`RectangleFrame::sample`] and [`RectangleFrame::pdf`] are
/// [`sample_quad_solid_angle`] and [`quad_solid_angle_pdf`], bit for bit, for a third
/// less work a shading point.
#[derive(Clone, Copy, Debug)]
pub struct RectangleFrame {
    corner: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    /// The unit edges and the emitting normal, in f64.
    x: DVec3,
    y: DVec3,
    z: DVec3,
    /// The sides' lengths along `x` and `y`.
    width: f64,
    height: f64,
    normal: Vec3,
}

impl RectangleFrame {
    /// The frame of the parallelogram light `(corner, edge_u, edge_v)`. `None` when the
    /// edges are not perpendicular (within [`SphericalRectangle::RECTANGLE_TOLERANCE`]),
    /// degenerate or not finite: such a light is sampled by area.
    pub fn new(corner: Vec3, edge_u: Vec3, edge_v: Vec3) -> Option<Self> {
        if !(corner.is_finite() && edge_u.is_finite() && edge_v.is_finite()) {
            return None;
        }
        let (normal, _) = normal_and_area(edge_u, edge_v)?;
        let (ex, ey) = (edge_u.as_dvec3(), edge_v.as_dvec3());
        let (exl, eyl) = (ex.length(), ey.length());
        if !(exl > 0.0 && eyl > 0.0) {
            return None;
        }
        let x = ex / exl;
        let y = ey / eyl;
        if x.dot(y).abs() > f64::from(SphericalRectangle::RECTANGLE_TOLERANCE) {
            return None;
        }
        let z = x.cross(y).normalize();
        let y = z.cross(x);
        Some(Self {
            corner,
            edge_u,
            edge_v,
            x,
            y,
            z,
            width: exl,
            height: ey.dot(y),
            normal,
        })
    }

    /// The spherical rectangle of the light seen from `p`: [`SphericalRectangle::new`],
    /// which says when there is none. The one-lane instance of
    /// [`RectangleFrame::seen_from_lanes`], bit for bit.
    #[inline]
    pub fn seen_from(&self, p: Vec3) -> Option<SphericalRectangle> {
        let lanes = Self::seen_from_lanes([self; RECTANGLE_LANES], [p; RECTANGLE_LANES]);
        lanes.exists(0).then_some(SphericalRectangle { lanes })
    }

    /// [`RectangleFrame::seen_from`] for four lights and four points at once, a lane
    /// each: every lane gives the bits the one-lane call gives for it, whatever the
    /// other lanes hold.
    #[inline]
    pub fn seen_from_lanes(
        frames: [&RectangleFrame; RECTANGLE_LANES],
        points: [Vec3; RECTANGLE_LANES],
    ) -> SphericalRectangles {
        let o = DVec3Lanes::gather(|i| points[i].as_dvec3());
        let (x, y, z) = (
            DVec3Lanes::gather(|i| frames[i].x),
            DVec3Lanes::gather(|i| frames[i].y),
            DVec3Lanes::gather(|i| frames[i].z),
        );
        let d = DVec3Lanes::gather(|i| frames[i].corner.as_dvec3()) - o;
        // The emitting side is +z; p must be strictly in front, i.e. the
        // rectangle lies at z0 < 0 in the local frame, as the paper requires.
        let z0 = d.dot(z);
        let x0 = d.dot(x);
        let y0 = d.dot(y);
        let x1 = x0 + lanes(|i| frames[i].width);
        let y1 = y0 + lanes(|i| frames[i].height);
        // The paper's great-circle normals through consecutive vertices
        // `(x_i, y_j, z0)` are, up to positive factors, n0 = (0, z0, -y0),
        // n1 = (-z0, 0, x1), n2 = (0, -z0, y1), n3 = (z0, 0, -x0). The interior
        // angle between n_i and n_j is the argument of (-n_i . n_j, |n_i x n_j|),
        // and the cross product's length is |z0| times the distance to the vertex
        // the two circles share. In units of the largest coordinate, so that the
        // product of four stays far from overflow and underflow.
        let unit = f64x4::ONE / x0.abs().max(x1.abs()).max(y0.abs()).max(y1.abs()).max(-z0);
        let (a0, a1, b0, b1, c) = (x0 * unit, x1 * unit, y0 * unit, y1 * unit, -z0 * unit);
        let c2 = c * c;
        let to = |a: f64x4, b: f64x4| c * (a * a + b * b + c2).sqrt();
        let g0 = (b0 * a1, to(a1, b0));
        let g1 = (-a1 * b1, to(a1, b1));
        let g2 = (a0 * b1, to(a0, b1));
        let g3 = (-a0 * b0, to(a0, b0));
        let g23 = times(g2, g3);
        let (re, im) = times(times(g0, g1), g23);
        // The argument of the product is the solid angle modulo 2pi. Every
        // interior angle is in (0, pi), so the sum is in (2pi, 6pi) and the solid
        // angle in (0, 2pi): a negative argument is the solid angle less 2pi,
        // unless it is a rounding of a solid angle near 0 or near 2pi, which
        // cannot be told apart and are declined.
        let angle = im.atan2(re);
        let turned = angle.simd_lt(f64x4::ZERO);
        let solid_angle = turned.select(angle + f64x4::splat(TAU), angle);
        let told_apart = !turned | angle.simd_lt(f64x4::splat(-1e-6));
        // k = 2pi - (g2 + g3): cos k = cos(g2 + g3), sin k = -sin(g2 + g3).
        // Not `hypot`: the turns are in units of the largest coordinate, far from
        // overflow.
        let length = (g23.0 * g23.0 + g23.1 * g23.1).sqrt();
        let (cos_k, sin_k) = (g23.0 / length, -g23.1 / length);
        // The z components of the unit n0 and n2.
        let b0_c2 = b0 * b0 + c2;
        let (b0, b1) = (-b0 / b0_c2.sqrt(), b1 / (b1 * b1 + c2).sqrt());
        let one_minus_b0_squared = c2 / b0_c2;
        let valid = z0.simd_lt(f64x4::ZERO)
            & told_apart
            & solid_angle.is_finite()
            & solid_angle.simd_ge(f64x4::splat(f64::from(SphericalRectangle::MIN_SOLID_ANGLE)))
            & cos_k.is_finite()
            & sin_k.is_finite();
        let finite = (0..RECTANGLE_LANES).filter(|&i| points[i].is_finite());
        SphericalRectangles {
            o,
            x,
            y,
            z,
            z0,
            x0,
            y0,
            x1,
            y1,
            b0,
            b1,
            one_minus_b0_squared,
            cos_k,
            sin_k,
            solid_angle,
            normal: frames.map(|frame| frame.normal),
            exists: valid.to_bitmask() as u8 & finite.fold(0, |bits, i| bits | 1 << i),
        }
    }

    /// [`sample_quad_solid_angle`] for this light: by solid angle where the
    /// rectangle seen from `p` exists, else by area.
    #[inline]
    pub fn sample(&self, p: Vec3, u: Vec2) -> Option<DirectionSample> {
        self.sample_seen(self.seen_from(p).as_ref(), p, u)
    }

    /// [`RectangleFrame::sample`], given the light's `rectangle` seen from `p`
    /// ([`RectangleFrame::seen_from`]): for a renderer that makes the rectangles of many
    /// points before it samples any.
    #[inline]
    pub fn sample_seen(
        &self,
        rectangle: Option<&SphericalRectangle>,
        p: Vec3,
        u: Vec2,
    ) -> Option<DirectionSample> {
        match rectangle {
            Some(rectangle) => rectangle.sample(u),
            None => sample_quad_area(p, self.corner, self.edge_u, self.edge_v, u),
        }
    }

    /// [`quad_solid_angle_pdf`] for this light.
    pub fn pdf(&self, p: Vec3, wi: Vec3) -> f32 {
        let (corner, edge_u, edge_v) = (self.corner, self.edge_u, self.edge_v);
        match self.seen_from(p) {
            Some(rectangle) => {
                if hit_front(p, corner, edge_u, edge_v, wi).is_some() {
                    rectangle.pdf()
                } else {
                    0.0
                }
            }
            None => quad_area_pdf(p, corner, edge_u, edge_v, wi),
        }
    }
}

/// Samples a quad light by solid angle where that is possible and accurate
/// (a rectangle whose [`SphericalRectangle`] exists), else by area
/// ([`sample_quad_area`]). Pair it with [`quad_solid_angle_pdf`].
pub fn sample_quad_solid_angle(
    p: Vec3,
    corner: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    u: Vec2,
) -> Option<DirectionSample> {
    match RectangleFrame::new(corner, edge_u, edge_v) {
        Some(frame) => frame.sample(p, u),
        None => sample_quad_area(p, corner, edge_u, edge_v, u),
    }
}

/// Solid-angle pdf with which [`sample_quad_solid_angle`] produces `wi`: the
/// same choice of strategy, and 0 when the ray misses the front of the light.
pub fn quad_solid_angle_pdf(p: Vec3, corner: Vec3, edge_u: Vec3, edge_v: Vec3, wi: Vec3) -> f32 {
    match RectangleFrame::new(corner, edge_u, edge_v) {
        Some(frame) => frame.pdf(p, wi),
        None => quad_area_pdf(p, corner, edge_u, edge_v, wi),
    }
}

/// Irradiance at `p` with unit normal `n` from a polygon of unit radiance
/// (vertices in order, all above the shading plane), by Lambert's formula
/// `E = 1/2 sum_i Theta_i (gamma_i . n)`, where `Theta_i` is the angle edge `i`
/// subtends at `p` and `gamma_i` the unit normal of the plane through `p` and
/// that edge (Arvo 1995, "Applications of Irradiance Tensors to the
/// Simulation of Non-Lambertian Phenomena", SIGGRAPH). A light covering the
/// whole hemisphere gives `pi`; divide by `pi` for the form factor. A
/// closed-form reference for tests of light sampling.
pub fn polygon_irradiance(p: Vec3, n: Vec3, vertices: &[Vec3]) -> f32 {
    let n = n.as_dvec3();
    let o = p.as_dvec3();
    let mut sum = 0.0;
    for (i, a) in vertices.iter().enumerate() {
        let b = vertices[(i + 1) % vertices.len()];
        let va = (a.as_dvec3() - o).normalize();
        let vb = (b.as_dvec3() - o).normalize();
        let c = va.cross(vb);
        let length = c.length();
        if length > 0.0 {
            let angle = length.atan2(va.dot(vb));
            sum += angle * (c / length).dot(n);
        }
    }
    // The sign depends on the winding; irradiance is non-negative.
    (0.5 * sum).abs() as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::ONE_MINUS_EPSILON;

    const CORNER: Vec3 = Vec3::new(-0.5, -0.25, 1.0);
    const EU: Vec3 = Vec3::new(1.0, 0.0, 0.0);
    // edge_u x edge_v = -z: the light faces down toward the origin.
    const EV: Vec3 = Vec3::new(0.0, -0.75, 0.0);

    #[test]
    fn area_and_solid_angle_samples_hit_the_light_with_consistent_pdfs() {
        let p = Vec3::new(0.1, 0.2, -0.3);
        let rect = SphericalRectangle::new(p, CORNER, EU, EV).unwrap();
        for &a in &[0.0, 0.3, 0.77, ONE_MINUS_EPSILON] {
            for &b in &[0.0, 0.5, ONE_MINUS_EPSILON] {
                let u = Vec2::new(a, b);
                let s = sample_quad_area(p, CORNER, EU, EV, u).unwrap();
                let pdf = quad_area_pdf(p, CORNER, EU, EV, s.wi);
                assert!((pdf - s.pdf).abs() <= 1e-4 * s.pdf, "{pdf} vs {}", s.pdf);
                let s = rect.sample(u).unwrap();
                assert!((s.point.z - 1.0).abs() < 1e-6);
                assert!((-0.5 - 1e-5..=0.5 + 1e-5).contains(&s.point.x));
                assert!((-1.0 - 1e-5..=-0.25 + 1e-5).contains(&s.point.y));
                assert_eq!(quad_solid_angle_pdf(p, CORNER, EU, EV, s.wi), rect.pdf());
            }
        }
    }

    /// A lane's rectangle and sample are the one-lane call's, bit for bit, whatever the
    /// other lanes hold: other lights, points behind the light or not finite, lights too
    /// small to see. The renderer groups requests as its waves come, so an image would
    /// otherwise depend on the grouping.
    #[test]
    fn every_lane_gives_the_one_lane_bits_whatever_its_company() {
        let frames = [
            RectangleFrame::new(CORNER, EU, EV).unwrap(),
            RectangleFrame::new(Vec3::new(-0.3, 2.2, -0.3), 0.6 * Vec3::X, 0.6 * Vec3::Z).unwrap(),
            RectangleFrame::new(Vec3::new(5e3, 0.0, 1.0), 1e-5 * Vec3::X, -1e-5 * Vec3::Y).unwrap(),
        ];
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let (mut with_rectangle, mut without) = (0, 0);
        for round in 0..4000 {
            let picks: [usize; RECTANGLE_LANES] = std::array::from_fn(|_| (next() * 3.0) as usize);
            let points: [Vec3; RECTANGLE_LANES] = std::array::from_fn(|i| match (round + i) % 23 {
                0 => Vec3::new(f32::NAN, 0.0, 0.0),
                1 => Vec3::new(0.0, f32::INFINITY, 0.0),
                _ => Vec3::new(next() - 0.5, next() * 3.0 - 0.5, next() * 2.0 - 1.0) * 4.0,
            });
            let u: [Vec2; RECTANGLE_LANES] = std::array::from_fn(|_| Vec2::new(next(), next()));
            let seen = RectangleFrame::seen_from_lanes(picks.map(|k| &frames[k]), points);
            let drawn = seen.sample(u);
            for i in 0..RECTANGLE_LANES {
                let frame = &frames[picks[i]];
                let alone = frame.seen_from(points[i]);
                assert_eq!(seen.exists(i), alone.is_some(), "round {round} lane {i}");
                if let Some(alone) = alone {
                    assert_eq!(drawn[i], alone.sample(u[i]), "round {round} lane {i}");
                    with_rectangle += 1;
                } else {
                    without += 1;
                }
            }
        }
        assert!(
            with_rectangle > 4000 && without > 4000,
            "{with_rectangle} {without}"
        );
    }

    #[test]
    fn back_facing_and_coplanar_points_get_nothing() {
        let u = Vec2::splat(0.5);
        for p in [Vec3::new(0.0, 0.0, 2.0), Vec3::new(3.0, 0.0, 1.0)] {
            assert!(sample_quad_area(p, CORNER, EU, EV, u).is_none());
            assert!(SphericalRectangle::new(p, CORNER, EU, EV).is_none());
            assert_eq!(quad_area_pdf(p, CORNER, EU, EV, -Vec3::Z), 0.0);
        }
        // The ray misses, or leaves the front side away from the light.
        assert_eq!(quad_area_pdf(Vec3::ZERO, CORNER, EU, EV, Vec3::X), 0.0);
        assert_eq!(quad_area_pdf(Vec3::ZERO, CORNER, EU, EV, -Vec3::Z), 0.0);
    }

    #[test]
    fn tiny_solid_angles_fall_back_to_area_sampling() {
        // 1e-5 x 1e-5 at distance ~1: about 1e-10 sr, below the threshold.
        let (corner, eu, ev) = (Vec3::new(0.0, 0.0, 1.0), 1e-5 * Vec3::X, -1e-5 * Vec3::Y);
        assert!(SphericalRectangle::new(Vec3::ZERO, corner, eu, ev).is_none());
        let s = sample_quad_solid_angle(Vec3::ZERO, corner, eu, ev, Vec2::splat(0.5)).unwrap();
        let area = sample_quad_area(Vec3::ZERO, corner, eu, ev, Vec2::splat(0.5)).unwrap();
        assert_eq!(s, area);
        assert_eq!(
            quad_solid_angle_pdf(Vec3::ZERO, corner, eu, ev, s.wi),
            quad_area_pdf(Vec3::ZERO, corner, eu, ev, s.wi)
        );
        // Just above the threshold the spherical rectangle exists.
        let (eu, ev) = (1e-4 * Vec3::X, -1e-4 * Vec3::Y);
        let rect = SphericalRectangle::new(Vec3::ZERO, corner, eu, ev).unwrap();
        assert!((rect.solid_angle() - 1e-8).abs() < 1e-11);
    }

    #[test]
    fn non_rectangles_are_declined() {
        let skew = Vec3::new(0.3, -0.75, 0.0);
        assert!(SphericalRectangle::new(Vec3::ZERO, CORNER, EU, skew).is_none());
        // The combined sampler falls back to area sampling.
        let s = sample_quad_solid_angle(Vec3::ZERO, CORNER, EU, skew, Vec2::splat(0.3)).unwrap();
        assert_eq!(
            quad_solid_angle_pdf(Vec3::ZERO, CORNER, EU, skew, s.wi),
            quad_area_pdf(Vec3::ZERO, CORNER, EU, skew, s.wi)
        );
    }

    #[test]
    fn solid_angle_matches_closed_form_for_a_square_overhead() {
        // A unit square at height 1 centred above p: solid angle is
        // 4 asin(1/5) (closed form for a rectangle 2a x 2b at distance d:
        // 4 asin(ab / sqrt((a^2 + d^2)(b^2 + d^2)))).
        let rect =
            SphericalRectangle::new(Vec3::ZERO, Vec3::new(-0.5, 0.5, 1.0), Vec3::X, -Vec3::Y)
                .unwrap();
        let expected = 4.0 * (0.25f64 / 1.25).asin();
        assert!((f64::from(rect.solid_angle()) - expected).abs() < 1e-6);
    }

    /// Near the light's plane, under it, the solid angle nears `2pi`, and the sum of the
    /// interior angles, taken modulo `2pi`, nears 0 from below: those solid angles come
    /// out right down to 1e-6 from `2pi`, and closer ones are declined (area sampling
    /// takes over), never taken as solid angles near 0.
    #[test]
    fn solid_angles_near_two_pi_are_right_or_declined() {
        let corner = Vec3::new(-0.5, 0.5, 0.0);
        let mut exact = 0;
        for k in 0..=60 {
            let height = 10f32.powf(-0.1 * k as f32);
            let p = Vec3::new(0.1, -0.05, -height);
            let (a, b) = (DVec3::new(0.6, 0.55, 0.0), DVec3::new(0.4, 0.45, 0.0));
            let h = f64::from(height);
            // A rectangle seen from a point over its inside: four rectangles with a
            // corner over the point, each `atan(xy / (h sqrt(x^2 + y^2 + h^2)))`.
            let expected: f64 = [(a.x, a.y), (a.x, b.y), (b.x, a.y), (b.x, b.y)]
                .iter()
                .map(|&(x, y)| (x * y / (h * (x * x + y * y + h * h).sqrt())).atan())
                .sum();
            match SphericalRectangle::new(p, corner, Vec3::X, -Vec3::Y) {
                Some(rect) => {
                    let got = f64::from(rect.solid_angle());
                    assert!(
                        (got - expected).abs() <= 1e-6,
                        "height {height}: {got} vs {expected}"
                    );
                    exact += 1;
                }
                None => assert!(
                    TAU - expected < 2e-6,
                    "height {height} declined at {expected}"
                ),
            }
            let s = sample_quad_solid_angle(p, corner, Vec3::X, -Vec3::Y, Vec2::splat(0.4));
            assert!(s.is_some_and(|s| s.wi.z > 0.0), "height {height}");
        }
        assert!(exact >= 50, "{exact}");
    }

    /// The solid angle against an independent formula, two triangles by Van
    /// Oosterom and Strackee (1983), `tan(omega / 2) = |a.(b x c)| / (abc +
    /// (a.b)c + (a.c)b + (b.c)a)`, over rectangles seen from overhead, from
    /// grazing heights (solid angle near 2 pi), tiny and far away.
    #[test]
    fn solid_angle_matches_two_triangles_everywhere() {
        let triangle = |a: DVec3, b: DVec3, c: DVec3| {
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let numerator = a.dot(b.cross(c)).abs();
            let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
            2.0 * numerator.atan2(denominator)
        };
        let mut checked = 0;
        for (size, height) in [
            (1.0f32, 1.0f32),
            (1.0, 1e-3),
            (1.0, 0.05),
            (1e-2, 1.0),
            (1.0, 30.0),
            (4.0, 0.5),
        ] {
            for (dx, dy) in [(0.0f32, 0.0f32), (0.3, -0.2), (2.0, 1.5), (-5.0, 0.1)] {
                let p = Vec3::new(dx * size, dy * size, 0.0);
                let corner = Vec3::new(-0.5 * size, 0.5 * size, height);
                let (eu, ev) = (Vec3::X * size, -Vec3::Y * 1.5 * size);
                let Some(rect) = SphericalRectangle::new(p, corner, eu, ev) else {
                    continue;
                };
                let v = |s: f32, t: f32| (corner + s * eu + t * ev - p).as_dvec3();
                let expected = triangle(v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0))
                    + triangle(v(0.0, 0.0), v(1.0, 1.0), v(0.0, 1.0));
                let got = f64::from(rect.solid_angle());
                assert!(
                    (got - expected).abs() <= 1e-6 * expected.max(1e-3),
                    "size {size} height {height} offset ({dx}, {dy}): {got} vs {expected}"
                );
                checked += 1;
            }
        }
        assert!(checked >= 20, "{checked}");
    }
}
