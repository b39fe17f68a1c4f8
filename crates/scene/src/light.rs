//! Light sources, one unit: every kind answers here whether it is valid, where a ray meets
//! it, what it emits toward a ray, how a direction toward it is sampled and with what pdf,
//! and the box it occupies. [`Light`] is matched in this module and nowhere else, so a new
//! kind of light is written here (and parsed in `file.rs`).

use glam::{Vec2, Vec3};
use lueur_sampling::{
    DirectionSample, RectangleFrame, quad_area_pdf, quad_solid_angle_pdf, sample_quad_area,
    sample_quad_solid_angle, sample_sphere_light, sphere_light_pdf,
};
use lueur_sdf_math::{Lane, LaneVec3, Ray};

/// A light source. Sphere and quad lights are also visible geometry (they
/// are intersected analytically, which is exact and cheaper than marching a
/// zero-thickness quad); directional lights are not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// A sphere emitting `radiance` outward from its surface.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius (> 0).
        radius: f32,
        /// Emitted radiance.
        radiance: Vec3,
    },
    /// A parallelogram `corner + s edge_u + t edge_v`, emitting on the side
    /// of `edge_u x edge_v`.
    Quad {
        /// One corner.
        corner: Vec3,
        /// First edge.
        edge_u: Vec3,
        /// Second edge.
        edge_v: Vec3,
        /// Emitted radiance.
        radiance: Vec3,
    },
    /// A light at infinity: parallel rays travelling along `direction`.
    Directional {
        /// Unit direction in which the light travels.
        direction: Vec3,
        /// Irradiance received by a surface facing the light.
        irradiance: Vec3,
    },
}

/// How quad lights are sampled toward a shading point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum QuadSampling {
    /// Uniform on the area, converted to solid angle (pdf d^2 / (cos a * A)),
    /// as in the student report.
    Area,
    /// Uniform in the solid angle the rectangle subtends (Urena et al.
    /// 2013); falls back to area sampling for non-rectangular parallelograms.
    #[default]
    SolidAngle,
}

/// A direction toward a light (or the sky) with the radiance it brings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmitterSample {
    /// Unit direction from the shading point toward the emitter.
    pub wi: Vec3,
    /// Distance to the emitter along `wi` (infinite for the sky and lights
    /// at infinity).
    pub distance: f32,
    /// Radiance arriving along `-wi`.
    pub radiance: Vec3,
    /// Solid-angle pdf of `wi` (including, once chosen by the light
    /// sampler, the probability of choosing this emitter).
    pub pdf: f32,
}

impl Light {
    /// Whether the light is a delta distribution in direction, reachable only
    /// by next-event estimation.
    pub fn is_delta(&self) -> bool {
        matches!(self, Light::Directional { .. })
    }

    /// Whether the light can be rendered: a positive size, finite position
    /// and non-negative radiance.
    pub fn is_valid(&self) -> bool {
        match *self {
            Light::Sphere {
                center,
                radius,
                radiance,
            } => center.is_finite() && radius > 0.0 && radius.is_finite() && valid_rgb(radiance),
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                radiance,
            } => corner.is_finite() && edge_u.cross(edge_v).length() > 0.0 && valid_rgb(radiance),
            Light::Directional {
                direction,
                irradiance,
            } => {
                direction.is_finite()
                    && (direction.length() - 1.0).abs() < 1e-3
                    && valid_rgb(irradiance)
            }
        }
    }

    /// The corners of a box around the light, `None` for a light at
    /// infinity.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        match *self {
            Light::Sphere { center, radius, .. } => {
                Some((center - Vec3::splat(radius), center + Vec3::splat(radius)))
            }
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                ..
            } => {
                let far = corner + edge_u + edge_v;
                Some((corner.min(far), corner.max(far)))
            }
            Light::Directional { .. } => None,
        }
    }

    /// Where `ray` first meets the light's surface (lights at infinity are
    /// never met).
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        match *self {
            Light::Sphere { center, radius, .. } => ray_sphere(ray, center, radius),
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                ..
            } => ray_quad(ray, corner, edge_u, edge_v),
            Light::Directional { .. } => None,
        }
    }

    /// [`Light::intersect`] for each lane's ray `origin + t dir`: its `t` and the lanes
    /// that meet the light, bit for bit the scalar answer in each lane.
    #[inline(always)]
    pub fn intersect_lanes<L: Lane>(&self, origin: LaneVec3<L>, dir: LaneVec3<L>) -> (L, L::Mask) {
        match *self {
            Light::Sphere { center, radius, .. } => ray_sphere_lanes(origin, dir, center, radius),
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                ..
            } => ray_quad_lanes(origin, dir, corner, edge_u, edge_v),
            Light::Directional { .. } => {
                let zero = L::splat(0.0);
                (zero, zero.gt(zero))
            }
        }
    }

    /// Radiance emitted toward `-ray.dir` from the point at `t` along `ray`.
    pub fn emitted(&self, ray: &Ray, t: f32) -> Vec3 {
        match *self {
            Light::Sphere {
                center, radiance, ..
            } => {
                // Emits outward only: a ray from inside sees the back face.
                if (ray.at(t) - center).dot(ray.dir) < 0.0 {
                    radiance
                } else {
                    Vec3::ZERO
                }
            }
            Light::Quad {
                edge_u,
                edge_v,
                radiance,
                ..
            } => {
                if edge_u.cross(edge_v).dot(ray.dir) < 0.0 {
                    radiance
                } else {
                    Vec3::ZERO
                }
            }
            Light::Directional { .. } => Vec3::ZERO,
        }
    }

    /// For a delta light, the one direction its light arrives from and the
    /// irradiance it brings there.
    pub fn delta_arrival(&self) -> Option<(Vec3, Vec3)> {
        match *self {
            Light::Directional {
                direction,
                irradiance,
            } => Some((-direction, irradiance)),
            Light::Sphere { .. } | Light::Quad { .. } => None,
        }
    }

    /// A direction from `p` toward the light's emitting surface, with its
    /// solid-angle pdf; `None` where the sample has no weight (a back face,
    /// a delta light).
    pub fn sample(&self, p: Vec3, u: Vec2, quad_sampling: QuadSampling) -> Option<EmitterSample> {
        self.sample_drawn(p, u, quad_sampling, None)
    }

    /// A sphere light's centre, radius and radiance: what a renderer needs to draw its
    /// direction samples in batches ([`lueur_sampling::sample_sphere_light_lanes`]) and
    /// weigh them as [`Light::sample_drawn`] does ([`sphere_emits_along_lanes`],
    /// [`usable_pdf_lanes`]).
    pub fn as_sphere(&self) -> Option<SphereLight> {
        match *self {
            Light::Sphere {
                center,
                radius,
                radiance,
            } => Some(SphereLight {
                center,
                radius,
                radiance,
            }),
            Light::Quad { .. } | Light::Directional { .. } => None,
        }
    }

    /// A rectangular quad light's [`RectangleFrame`]: the part of its solid-angle sampling
    /// that does not depend on the shading point, for a renderer to make once. Under
    /// [`QuadSampling::SolidAngle`], its [`RectangleFrame::sample`] and
    /// [`RectangleFrame::pdf`] give what [`Light::sample`] and [`Light::pdf`] do. `None`
    /// for any other light.
    pub fn rectangle_frame(&self) -> Option<RectangleFrame> {
        match *self {
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                ..
            } if is_rectangle(edge_u, edge_v) => RectangleFrame::new(corner, edge_u, edge_v),
            Light::Quad { .. } | Light::Sphere { .. } | Light::Directional { .. } => None,
        }
    }

    /// [`Light::sample`], where the direction sample may have been `drawn` already from
    /// `p` with `u`: a sphere light's by [`lueur_sampling::sample_sphere_light`] or its
    /// batch form, a rectangle's by its [`Light::rectangle_frame`] (`None`: draw it here;
    /// a delta light has none).
    #[inline]
    pub fn sample_drawn(
        &self,
        p: Vec3,
        u: Vec2,
        quad_sampling: QuadSampling,
        drawn: Option<&Option<DirectionSample>>,
    ) -> Option<EmitterSample> {
        let (s, radiance): (DirectionSample, Vec3) = match *self {
            Light::Sphere {
                center,
                radius,
                radiance,
            } => {
                let s = match drawn {
                    Some(s) => (*s)?,
                    None => sample_sphere_light(p, center, radius, u)?,
                };
                if !sphere_emits_along_lanes::<f32>(s.normal.into(), s.wi.into()) {
                    return None;
                }
                (s, radiance)
            }
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                radiance,
            } => {
                let s = match (drawn, quad_sampling) {
                    (Some(s), _) => (*s)?,
                    (None, QuadSampling::SolidAngle) if is_rectangle(edge_u, edge_v) => {
                        // Falls back to area sampling where the spherical
                        // rectangle cannot be sampled accurately (its solid angle
                        // too small, or too near 2pi).
                        sample_quad_solid_angle(p, corner, edge_u, edge_v, u)?
                    }
                    (None, _) => sample_quad_area(p, corner, edge_u, edge_v, u)?,
                };
                (s, radiance)
            }
            Light::Directional { .. } => return None,
        };
        if !usable_pdf_lanes(s.pdf) {
            return None;
        }
        Some(EmitterSample {
            wi: s.wi,
            distance: s.distance,
            radiance,
            pdf: s.pdf,
        })
    }

    /// Solid-angle pdf with which [`Light::sample`] picks `wi` from `p`.
    pub fn pdf(&self, p: Vec3, wi: Vec3, quad_sampling: QuadSampling) -> f32 {
        match *self {
            Light::Sphere { center, radius, .. } => {
                // Directions that reach the sphere from inside hit its
                // back face: the sampler rejects those, so they have
                // zero density.
                if (p - center).length_squared() <= radius * radius {
                    let Some(t) = ray_sphere(&Ray::new(p, wi), center, radius) else {
                        return 0.0;
                    };
                    if (p + wi * t - center).dot(wi) >= 0.0 {
                        return 0.0;
                    }
                }
                sphere_light_pdf(p, center, radius, wi)
            }
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                ..
            } => match quad_sampling {
                QuadSampling::SolidAngle if is_rectangle(edge_u, edge_v) => {
                    quad_solid_angle_pdf(p, corner, edge_u, edge_v, wi)
                }
                _ => quad_area_pdf(p, corner, edge_u, edge_v, wi),
            },
            Light::Directional { .. } => 0.0,
        }
    }
}

/// Whether a colour is a valid radiance: finite and non-negative.
pub(crate) fn valid_rgb(c: Vec3) -> bool {
    c.is_finite() && c.min_element() >= 0.0
}

fn is_rectangle(edge_u: Vec3, edge_v: Vec3) -> bool {
    edge_u.dot(edge_v).abs() <= 1e-4 * edge_u.length() * edge_v.length()
}

/// Where a ray first meets the sphere (`t > 0`), if it does: [`ray_sphere_lanes`]'s
/// one-lane instance.
#[inline]
pub(crate) fn ray_sphere(ray: &Ray, center: Vec3, radius: f32) -> Option<f32> {
    let (t, hit) = ray_sphere_lanes::<f32>(ray.origin.into(), ray.dir.into(), center, radius);
    hit.then_some(t)
}

/// Where each lane's ray `origin + t dir` first meets the sphere (`t > 0`, from outside
/// or inside), and the lanes that meet it; written once over lanes, so that a vector of
/// rays gets the scalar test's bits. The numerically stable form of pbrt-v4 (section
/// 6.8.1): the discriminant from `|o - c - (b) d|` avoids cancellation far away.
#[inline(always)]
pub(crate) fn ray_sphere_lanes<L: Lane>(
    origin: LaneVec3<L>,
    dir: LaneVec3<L>,
    center: Vec3,
    radius: f32,
) -> (L, L::Mask) {
    let zero = L::splat(0.0);
    let oc = origin - LaneVec3::splat(center);
    let b = oc.dot(dir);
    let perp = oc - dir * b;
    let disc = L::splat(radius * radius) - perp.length_squared();
    // Computed whether or not the ray meets the sphere, and tested once at the end:
    // a branch on the discriminant is mispredicted for every ray that sees the light
    // among many that do not, and costs more than the arithmetic it would skip.
    let root = disc.max(zero).sqrt();
    let q = -b + L::select(b.gt(zero), -root, root);
    let q_zero = L::and(q.ge(zero), zero.ge(q));
    let other = L::select(
        q_zero,
        q,
        (oc.length_squared() - L::splat(radius * radius)) / q,
    );
    let (near, far) = (
        L::select(q.gt(other), other, q),
        L::select(q.gt(other), q, other),
    );
    let t = L::select(near.gt(zero), near, far);
    (t, L::and(L::not(disc.lt(zero)), t.gt(zero)))
}

/// Intersection of a ray with the parallelogram `corner + s eu + t ev`:
/// [`ray_quad_lanes`]'s one-lane instance.
#[inline]
pub(crate) fn ray_quad(ray: &Ray, corner: Vec3, edge_u: Vec3, edge_v: Vec3) -> Option<f32> {
    let (t, hit) = ray_quad_lanes::<f32>(ray.origin.into(), ray.dir.into(), corner, edge_u, edge_v);
    hit.then_some(t)
}

/// Where each lane's ray meets the parallelogram `corner + s eu + t ev` (`t > 0`), and
/// the lanes that meet it; written once over lanes, as [`ray_sphere_lanes`].
#[inline(always)]
pub(crate) fn ray_quad_lanes<L: Lane>(
    origin: LaneVec3<L>,
    dir: LaneVec3<L>,
    corner: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
) -> (L, L::Mask) {
    let zero = L::splat(0.0);
    let n = edge_u.cross(edge_v);
    let lanes_n = LaneVec3::splat(n);
    let denom = lanes_n.dot(dir);
    // Not finite where the ray runs parallel to the plane (`denom` is 0).
    let t = lanes_n.dot(LaneVec3::splat(corner) - origin) / denom;
    let q = origin + dir * t - LaneVec3::splat(corner);
    // Coordinates in the (edge_u, edge_v) basis by Cramer's rule with the
    // plane normal (works for any parallelogram), each times |n|^2: compared
    // with [0, |n|^2] rather than divided by it, which would put two
    // divisions on the chain every path ray waits on.
    let nn = L::splat(n.length_squared());
    let s = lanes_n.dot(q.cross(LaneVec3::splat(edge_v)));
    let r = lanes_n.dot(LaneVec3::splat(edge_u).cross(q));
    // One test, on the whole: a branch on the sign of `t` alone would be a coin toss
    // for rays leaving a surface, and its mispredictions cost more than the arithmetic
    // it would skip.
    let within = L::and(L::and(s.ge(zero), nn.ge(s)), L::and(r.ge(zero), nn.ge(r)));
    (t, L::and(L::and(t.gt(zero), t.finite()), within))
}

/// A sphere light's fields ([`Light::as_sphere`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereLight {
    /// Centre.
    pub center: Vec3,
    /// Radius.
    pub radius: f32,
    /// Emitted radiance, from the outward face.
    pub radiance: Vec3,
}

/// Where a sphere light's direction sample `wi` meets the sphere on its emitting face (the
/// outward one, whose normal there is `normal`), per lane: the one definition of
/// [`Light::sample_drawn`]'s test, which runs it at `f32`.
#[inline(always)]
pub fn sphere_emits_along_lanes<L: Lane>(normal: LaneVec3<L>, wi: LaneVec3<L>) -> L::Mask {
    L::not(normal.dot(wi).ge(L::splat(0.0)))
}

/// Where a light sample's pdf can weigh it (positive and finite), per lane: the one
/// definition of [`Light::sample_drawn`]'s test, which runs it at `f32`.
#[inline(always)]
pub fn usable_pdf_lanes<L: Lane>(pdf: L) -> L::Mask {
    L::and(pdf.gt(L::splat(0.0)), pdf.finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_sphere_from_outside_and_inside() {
        let r = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        assert!((ray_sphere(&r, Vec3::ZERO, 1.0).unwrap() - 4.0).abs() < 1e-5);
        let inside = Ray::new(Vec3::ZERO, Vec3::Z);
        assert!((ray_sphere(&inside, Vec3::ZERO, 1.0).unwrap() - 1.0).abs() < 1e-5);
        let away = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z);
        assert!(ray_sphere(&away, Vec3::ZERO, 1.0).is_none());
        let far = Ray::new(Vec3::new(0.0, 0.0, -1e4), Vec3::Z);
        assert!((ray_sphere(&far, Vec3::ZERO, 1.0).unwrap() - (1e4 - 1.0)).abs() < 1e-2);
    }

    /// Every light's test over a vector of rays, on every level, gives each lane what the
    /// scalar test gives its ray, bit for bit: rays from near and far (1e4 away), toward,
    /// along and away from each light, from inside the sphere, parallel to the quad.
    #[test]
    fn a_vector_of_rays_meets_each_light_as_each_ray_alone() {
        use lueur_sdf_math::{LaneKernel, MAX_LANES, SimdLevel};

        struct Tests<'a> {
            light: &'a Light,
            rays: &'a [Ray],
        }

        impl LaneKernel for Tests<'_> {
            type Output = Vec<Option<u32>>;

            fn run<L: Lane>(self) -> Vec<Option<u32>> {
                let lanes = L::LANES.min(MAX_LANES);
                let mut out = Vec::new();
                for rays in self.rays.chunks(lanes) {
                    let mut rows = [[0f32; MAX_LANES]; 6];
                    for (lane, r) in rays.iter().enumerate() {
                        let values = [
                            r.origin.x, r.origin.y, r.origin.z, r.dir.x, r.dir.y, r.dir.z,
                        ];
                        for (row, v) in rows.iter_mut().zip(values) {
                            row[lane] = v;
                        }
                    }
                    let row = |i: usize| L::load(&rows[i][..lanes]);
                    let origin = LaneVec3::new(row(0), row(1), row(2));
                    let dir = LaneVec3::new(row(3), row(4), row(5));
                    let (t, meets) = self.light.intersect_lanes(origin, dir);
                    let mut ts = [0f32; MAX_LANES];
                    t.store(&mut ts[..lanes]);
                    let meets = L::bits(meets);
                    out.extend(
                        (0..rays.len())
                            .map(|lane| (meets >> lane & 1 == 1).then(|| ts[lane].to_bits())),
                    );
                }
                out
            }
        }

        let lights = [
            Light::Sphere {
                center: Vec3::new(0.3, 2.0, -0.4),
                radius: 0.25,
                radiance: Vec3::ONE,
            },
            Light::Sphere {
                center: Vec3::new(1e4, 0.0, 0.0),
                radius: 0.3,
                radiance: Vec3::ONE,
            },
            Light::Quad {
                corner: Vec3::new(-0.5, 1.9, -0.5),
                edge_u: Vec3::new(1.0, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 0.1, 1.0),
                radiance: Vec3::ONE,
            },
            Light::Directional {
                direction: -Vec3::Y,
                irradiance: Vec3::ONE,
            },
        ];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 - 0.5
        };
        for light in &lights {
            let mut rays = Vec::new();
            for i in 0..300 {
                let origin = match i % 4 {
                    0 => Vec3::new(uniform(), uniform(), uniform()) * 4.0,
                    1 => Vec3::new(-1e4, uniform(), uniform()),
                    2 => {
                        Vec3::new(0.3, 2.0, -0.4) + Vec3::new(uniform(), uniform(), uniform()) * 0.1
                    }
                    _ => Vec3::new(uniform(), 1.9, uniform()),
                };
                let target = match i % 3 {
                    0 => Vec3::new(0.3, 2.0, -0.4),
                    1 => Vec3::new(1e4, 0.0, 0.0),
                    _ => Vec3::new(0.0, 1.95, 0.0),
                } + Vec3::new(uniform(), uniform(), uniform()) * 0.6;
                let dir = match i % 7 {
                    0 => Vec3::new(1.0, 0.0, uniform()),
                    1 => origin - target,
                    _ => target - origin,
                };
                rays.push(Ray::new(origin, dir));
            }
            let alone: Vec<_> = rays
                .iter()
                .map(|r| light.intersect(r).map(f32::to_bits))
                .collect();
            if !matches!(light, Light::Directional { .. }) {
                assert!(alone.iter().any(Option::is_some) && alone.iter().any(Option::is_none));
            }
            for level in SimdLevel::available() {
                let got = level.dispatch(Tests { light, rays: &rays }).unwrap();
                assert_eq!(got, alone, "{light:?}, {level:?}");
            }
        }
    }

    #[test]
    fn ray_quad_hits_inside_only() {
        let (c, u, v) = (
            Vec3::new(-1.0, 2.0, -1.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 2.0),
        );
        let up = Ray::new(Vec3::ZERO, Vec3::Y);
        assert!((ray_quad(&up, c, u, v).unwrap() - 2.0).abs() < 1e-6);
        let off = Ray::new(Vec3::new(1.5, 0.0, 0.0), Vec3::Y);
        assert!(ray_quad(&off, c, u, v).is_none());
        let down = Ray::new(Vec3::ZERO, -Vec3::Y);
        assert!(ray_quad(&down, c, u, v).is_none());
    }

    /// A renderer that makes each rectangle's frame once and draws through it gets what
    /// the light itself gives, bit for bit: the same samples, the same pdfs, and, where it
    /// passes the drawn sample back, the same emitter samples. Lights that are not
    /// rectangles (sampled by area) have no frame.
    #[test]
    fn rectangle_frames_sample_as_their_lights_do() {
        let quad = |corner: Vec3, edge_u: Vec3, edge_v: Vec3| Light::Quad {
            corner,
            edge_u,
            edge_v,
            radiance: Vec3::ONE,
        };
        let rectangles = [
            quad(
                Vec3::new(-0.3, 2.2, -0.3),
                Vec3::new(0.6, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 0.6),
            ),
            // Tilted, long and thin, a 1 mm light 1 km away from some points.
            quad(
                Vec3::new(1.0, 3.0, 2.0),
                Vec3::new(0.0, 0.6, 0.8),
                Vec3::new(-5.0, 0.0, 0.0),
            ),
            quad(
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(1e-3, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -1e-3),
            ),
        ];
        let points = [
            Vec3::ZERO,
            Vec3::new(0.1, 2.2 - 1e-6, 0.05),
            Vec3::new(0.0, 2.2, 0.0),
            Vec3::new(3.0, 5.0, -1.0),
            Vec3::new(-1e3, -1e3, 1e3),
            Vec3::new(0.0, -1e3, 0.0),
        ];
        let us = [Vec2::ZERO, Vec2::new(0.3, 0.7), Vec2::new(0.999_999_9, 0.5)];
        let mut framed = 0;
        for light in rectangles {
            let frame = light.rectangle_frame().expect("a rectangle has a frame");
            for p in points {
                for u in us {
                    let drawn = frame.sample(p, u);
                    let sample = light.sample(p, u, QuadSampling::SolidAngle);
                    let through = light.sample_drawn(p, u, QuadSampling::SolidAngle, Some(&drawn));
                    assert_eq!(sample, through, "{light:?} from {p} with {u}");
                    assert_eq!(drawn.map(|d| d.wi), sample.map(|s| s.wi));
                    let wi = drawn.map_or(Vec3::Y, |d| d.wi);
                    let pdf = light.pdf(p, wi, QuadSampling::SolidAngle);
                    assert_eq!(
                        frame.pdf(p, wi).to_bits(),
                        pdf.to_bits(),
                        "{light:?} {p} {wi}"
                    );
                    framed += usize::from(sample.is_some());
                }
            }
        }
        assert!(framed > 20, "only {framed} samples had weight");
        let parallelogram = quad(Vec3::ZERO, Vec3::X, Vec3::new(0.5, 0.0, 1.0));
        assert!(parallelogram.rectangle_frame().is_none());
        let sphere = Light::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
            radiance: Vec3::ONE,
        };
        assert!(sphere.rectangle_frame().is_none());
    }
}
