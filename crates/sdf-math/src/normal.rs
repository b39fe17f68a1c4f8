//! Surface normals as normalised finite-difference gradients of a distance field.

use glam::Vec3;

use crate::DistanceField;
use crate::lanes::{Lane, LaneDistance, LaneVec3, Portable, Wide};

/// The direction returned where the gradient estimate vanishes or is not finite (the centre
/// of a sphere, the axis of a torus, a NaN field). Any fixed unit vector would do; what
/// matters is that callers never receive NaN and that images stay deterministic.
pub const FALLBACK_NORMAL: Vec3 = Vec3::Y;

/// Normal by the tetrahedron technique (4 evaluations, iq "normalsSDF"), with step `h`.
///
/// Always finite and unit length, even where the gradient vanishes (centre of a sphere,
/// axis of a torus): falls back to [`FALLBACK_NORMAL`] there.
///
/// `h` is made non-negative and raised to a few ulps of `p`'s largest coordinate, because
/// below that `p + h` rounds back to `p` and every sample would be the same number.
pub fn normal<F: DistanceField + ?Sized>(field: &F, p: Vec3, h: f32) -> Vec3 {
    unit_or_fallback(gradient(field, p, h))
}

/// The gradient of the field at `p` by the same tetrahedron (4 evaluations), not
/// normalised: its length is the local Lipschitz ratio, 1 for exact distances, which lets
/// a caller move a point onto the surface (`p - grad f(p) / |grad|^2`).
///
/// Unlike [`normal`] this may be zero or non-finite; callers must check.
pub fn gradient<F: DistanceField + ?Sized>(field: &F, p: Vec3, h: f32) -> Vec3 {
    let q = Tetrahedron::around(LaneVec3::from(p), h);
    Vec3::from(q.gradient(q.points().map(|x| field.distance(Vec3::from(x)))))
}

/// [`gradient`] with the four evaluations made as one vector of four lanes: the same
/// bits, since each lane gives the scalar value.
pub fn gradient_lanes<F: LaneDistance + ?Sized>(field: &F, p: Vec3, h: f32) -> Vec3 {
    let q = Tetrahedron::around(LaneVec3::from(p), h);
    let lanes = |c: fn(LaneVec3<f32>) -> f32| Wide::<4, Portable>::from_array(q.points().map(c));
    let f = field.distance_lanes(LaneVec3::new(
        lanes(|v| v.x),
        lanes(|v| v.y),
        lanes(|v| v.z),
    ));
    Vec3::from(q.gradient(f.to_array()))
}

/// The four points [`gradient`] samples around a point (one per lane: `L` is `f32` or a
/// vector), and the gradient of the linear function through the field's values there. A
/// caller that evaluates many points in batches (a stream of hits) takes the points,
/// evaluates them as it likes, and gets the bits of [`gradient`] for the same values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tetrahedron<L = f32>([LaneVec3<L>; 4]);

impl<L: Lane> Tetrahedron<L> {
    /// The tetrahedron around `p` at the step `h`, made usable there (see [`normal`]).
    #[inline(always)]
    pub fn around(p: LaneVec3<L>, h: L) -> Tetrahedron<L> {
        // iq, "normalsSDF": the vertices of a tetrahedron around p, one evaluation fewer
        // than central differences.
        const K: [Vec3; 4] = [
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(1.0, 1.0, 1.0),
        ];
        let h = usable_step(p, h);
        // Not `K.map`: a closure would be compiled apart from a vector kernel's features.
        Tetrahedron([
            p + LaneVec3::splat(K[0]) * h,
            p + LaneVec3::splat(K[1]) * h,
            p + LaneVec3::splat(K[2]) * h,
            p + LaneVec3::splat(K[3]) * h,
        ])
    }

    /// The points to evaluate the field at, in the order [`Tetrahedron::gradient`] takes
    /// their values.
    #[inline(always)]
    pub fn points(&self) -> [LaneVec3<L>; 4] {
        self.0
    }

    /// The gradient of the linear function through the field's values `f` at the points:
    /// glam's `Mat3::inverse` of the offsets times the rises, written out in its order.
    /// Not normalised, and it may be zero or non-finite (see [`gradient`]).
    #[inline(always)]
    pub fn gradient(&self, f: [L; 4]) -> LaneVec3<L> {
        let q = self.0;
        // The points actually sampled are p + h k rounded to f32, which far from the
        // origin differ from p + h k by up to half an ulp of p: as much as 6% of h at the
        // smallest step. Their differences are exact (they are close to each other), so
        // the gradient of the linear function through the four samples, solved with the
        // real offsets, carries only the field's own rounding. With exact offsets it is
        // iq's sum_i k_i f(p + h k_i) / (4 h).
        let (a, b, c) = (q[0] - q[3], q[1] - q[3], q[2] - q[3]);
        // The offsets as the rows of a matrix; its columns:
        let x = LaneVec3::new(a.x, b.x, c.x);
        let y = LaneVec3::new(a.y, b.y, c.y);
        let z = LaneVec3::new(a.z, b.z, c.z);
        let rises = LaneVec3::new(f[0] - f[3], f[1] - f[3], f[2] - f[3]);
        let (t0, t1, t2) = (y.cross(z), z.cross(x), x.cross(y));
        let inv_det = L::splat(1.0) / x.dot(t0);
        let (t0, t1, t2) = (t0 * inv_det, t1 * inv_det, t2 * inv_det);
        // The inverse is (t0 t1 t2) transposed: its columns are (t0.x, t1.x, t2.x), ...
        let c0 = LaneVec3::new(t0.x, t1.x, t2.x);
        let c1 = LaneVec3::new(t0.y, t1.y, t2.y);
        let c2 = LaneVec3::new(t0.z, t1.z, t2.z);
        c0 * rises.x + c1 * rises.y + c2 * rises.z
    }

    /// The field's Laplacian from the values `f` at the points and `centre` at `p`:
    /// `sum_i f(p + h k_i) - 4 f(p) = 2 h^2 (Laplacian) + O(h^3)`, since the `k_i` sum to 0
    /// and `sum_i k_i k_i^T = 4 I`. A rough estimate (`h` from the points' spread), for
    /// telling where the surface curves on the scale of the step.
    #[inline(always)]
    pub fn laplacian(&self, f: [L; 4], centre: L) -> L {
        // |k_0 - k_3|^2 = 8.
        let h2 = (self.0[0] - self.0[3]).length_squared() * L::splat(0.125);
        (f[0] + f[1] + f[2] + f[3] - L::splat(4.0) * centre) / (L::splat(2.0) * h2)
    }
}

/// The gradient by central differences (6 evaluations), not normalised: the naive
/// reference for [`gradient`], with the same treatment of `h` and the same caveat.
pub fn gradient_central<F: DistanceField + ?Sized>(field: &F, p: Vec3, h: f32) -> Vec3 {
    let c = Central::around(LaneVec3::from(p), h);
    Vec3::from(c.gradient(c.points().map(|x| field.distance(Vec3::from(x)))))
}

/// The six points central differences sample around a point (one per lane), and the
/// gradient and Laplacian they give: the stencil of [`gradient_central`], for a caller
/// that evaluates the points as it likes (see [`Tetrahedron`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Central<L = f32>([LaneVec3<L>; 6]);

impl<L: Lane> Central<L> {
    /// The points `p +- h e` for each axis `e`, with `h` made usable at `p`.
    #[inline(always)]
    pub fn around(p: LaneVec3<L>, h: L) -> Central<L> {
        let h = usable_step(p, h);
        let (x, y, z) = (
            LaneVec3::splat(Vec3::X) * h,
            LaneVec3::splat(Vec3::Y) * h,
            LaneVec3::splat(Vec3::Z) * h,
        );
        Central([p + x, p - x, p + y, p - y, p + z, p - z])
    }

    /// The points to evaluate the field at: `+x, -x, +y, -y, +z, -z`.
    #[inline(always)]
    pub fn points(&self) -> [LaneVec3<L>; 6] {
        self.0
    }

    /// Each axis's difference of the values `f` at the points, over the distance between
    /// the points actually sampled (see [`Tetrahedron::gradient`]).
    #[inline(always)]
    pub fn gradient(&self, f: [L; 6]) -> LaneVec3<L> {
        let q = self.0;
        LaneVec3::new(
            (f[0] - f[1]) / (q[0].x - q[1].x),
            (f[2] - f[3]) / (q[2].y - q[3].y),
            (f[4] - f[5]) / (q[4].z - q[5].z),
        )
    }

    /// The field's Laplacian from the values `f` at the points and `centre` at `p`: the
    /// second differences along the three axes, summed.
    #[inline(always)]
    pub fn laplacian(&self, f: [L; 6], centre: L) -> L {
        let q = self.0;
        second_difference(f[0], f[1], centre, q[0].x - q[1].x)
            + second_difference(f[2], f[3], centre, q[2].y - q[3].y)
            + second_difference(f[4], f[5], centre, q[4].z - q[5].z)
    }
}

/// `(f(p + s/2) + f(p - s/2) - 2 f(p)) / (s/2)^2` from the values and the span `s`. Not a
/// closure: it would be compiled apart from a vector kernel's features.
#[inline(always)]
fn second_difference<L: Lane>(plus: L, minus: L, centre: L, span: L) -> L {
    let half = span * L::splat(0.5);
    (plus + minus - L::splat(2.0) * centre) / (half * half)
}

/// Central differences (6 evaluations), kept as the naive reference for [`normal`].
///
/// Same guarantees and the same treatment of `h` as [`normal`].
pub fn normal_central<F: DistanceField + ?Sized>(field: &F, p: Vec3, h: f32) -> Vec3 {
    unit_or_fallback(gradient_central(field, p, h))
}

/// `|h|`, but at least two ulps of the largest coordinate of `p` (and 0 for a NaN `h` at
/// the origin, which then takes the fallback path rather than producing NaN): below that
/// `p + h` may round back to `p`. No more is needed, since the estimators use the offsets
/// their samples really have.
#[inline(always)]
fn usable_step<L: Lane>(p: LaneVec3<L>, h: L) -> L {
    let floor = p.abs().max_element() * L::splat(2.0 * f32::EPSILON);
    let h = h.abs();
    L::select(h.ge(floor), h, floor)
}

/// Normalises without overflow or underflow: dividing by the largest component first keeps
/// the squared length in [1, 3] whatever the magnitude of the raw difference vector.
#[inline]
fn unit_or_fallback(v: Vec3) -> Vec3 {
    if !v.is_finite() {
        return FALLBACK_NORMAL;
    }
    let largest = v.abs().max_element();
    if largest > 0.0 {
        let v = v / largest;
        v / v.length()
    } else {
        FALLBACK_NORMAL
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Constant(f32);

    impl DistanceField for Constant {
        fn distance(&self, _: Vec3) -> f32 {
            self.0
        }
        fn lipschitz(&self) -> f32 {
            0.0
        }
    }

    /// `p . gradient`: the same gradient everywhere.
    struct Linear(Vec3);

    impl DistanceField for Linear {
        fn distance(&self, p: Vec3) -> f32 {
            p.dot(self.0)
        }
        fn lipschitz(&self) -> f32 {
            self.0.length()
        }
    }

    #[test]
    fn degenerate_fields_fall_back() {
        for f in [0.0, 1.0, f32::NAN, f32::INFINITY] {
            assert_eq!(normal(&Constant(f), Vec3::ONE, 1e-3), FALLBACK_NORMAL);
            assert_eq!(
                normal_central(&Constant(f), Vec3::ONE, 1e-3),
                FALLBACK_NORMAL
            );
        }
    }

    #[test]
    fn tiny_and_huge_gradients_normalise() {
        for scale in [1e-30, 1.0, 1e30] {
            let field = Linear(Vec3::new(3.0, 0.0, 4.0) * scale);
            let expected = Vec3::new(0.6, 0.0, 0.8);
            assert!((normal(&field, Vec3::ONE, 1e-2) - expected).length() < 1e-3);
            assert!((normal_central(&field, Vec3::ONE, 1e-2) - expected).length() < 1e-3);
        }
    }

    #[test]
    fn both_gradients_are_exact_on_linear_fields_at_any_offset() {
        // A linear field has the same gradient everywhere: both difference
        // schemes must return it, not a multiple, near and far from the
        // origin (where h is raised to a few ulps of p).
        let g = Vec3::new(0.36, -0.48, 0.8);
        for p in [Vec3::ZERO, Vec3::ONE, Vec3::splat(1e3)] {
            for grad in [
                gradient(&Linear(g), p, 1e-2),
                gradient_central(&Linear(g), p, 1e-2),
            ] {
                assert!(
                    (grad - g).length() < 1e-3 * (1.0 + p.length() * 1e-2),
                    "{p}: {grad}"
                );
            }
        }
    }

    /// Both stencils' Laplacians: 0 on a linear field, and `2 / r` on a sphere's field at
    /// its surface (the sum of its principal curvatures), for radii 1e-2 to 1e2 at a step
    /// of 1e-2 of the radius.
    #[test]
    fn both_laplacians_read_a_spheres_curvature_and_a_planes_none() {
        struct Ball(f32);
        impl DistanceField for Ball {
            fn distance(&self, p: Vec3) -> f32 {
                p.length() - self.0
            }
            fn lipschitz(&self) -> f32 {
                1.0
            }
        }
        fn laplacians<F: DistanceField>(field: &F, p: Vec3, h: f32) -> [f32; 2] {
            let at = LaneVec3::from(p);
            let centre = field.distance(p);
            let values = |q: LaneVec3<f32>| field.distance(Vec3::from(q));
            let t = Tetrahedron::around(at, h);
            let c = Central::around(at, h);
            [
                t.laplacian(t.points().map(values), centre),
                c.laplacian(c.points().map(values), centre),
            ]
        }
        let plane = Linear(Vec3::new(0.36, -0.48, 0.8));
        for lap in laplacians(&plane, Vec3::new(0.3, 0.2, 0.1), 1e-2) {
            assert!(lap.abs() < 1e-2, "plane: {lap}");
        }
        for r in [1e-2f32, 1.0, 1e2] {
            let p = Vec3::new(0.48, 0.6, 0.64) * r;
            for lap in laplacians(&Ball(r), p, 1e-2 * r) {
                assert!((lap * r / 2.0 - 1.0).abs() < 0.01, "radius {r}: {lap}");
            }
        }
    }

    /// A sphere of radius 50 about 1e4 from the origin, where f32 positions are 1e-3 apart:
    /// at a step of eight roundings the sample points are off their intended offsets by up
    /// to 6% of the step, which dividing by the intended offsets turns into a normal off
    /// by about as much. Solved with the real offsets, both schemes stay within 1e-3.
    #[test]
    fn far_from_the_origin_the_rounding_of_positions_does_not_tilt_normals() {
        struct Ball(Vec3);
        impl DistanceField for Ball {
            fn distance(&self, p: Vec3) -> f32 {
                (p - self.0).length() - 50.0
            }
            fn lipschitz(&self) -> f32 {
                1.0
            }
        }
        // Coordinates in three binades, so that each axis rounds its offsets differently.
        let center = Vec3::new(1e4, 6e3, 3e3);
        let ball = Ball(center);
        // Eight roundings of the largest coordinate: small enough that the rounding of the
        // sample points matters, large enough that the field's own rounding does not.
        let h = 8.0 * f32::EPSILON * 1e4;
        for i in 0..200 {
            let a = i as f32 * 0.618_034 * std::f32::consts::TAU;
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / 200.0;
            let r = (1.0 - z * z).sqrt();
            let n = Vec3::new(r * a.cos(), r * a.sin(), z);
            let p = center + n * 50.0;
            for (name, got) in [
                ("tetrahedron", normal(&ball, p, h)),
                ("central", normal_central(&ball, p, h)),
            ] {
                let exact = (p - center).normalize();
                let angle = got.dot(exact).clamp(-1.0, 1.0).acos();
                assert!(angle < 1e-3, "{name} at {p}: off by {angle}");
            }
        }
    }

    #[test]
    fn step_is_raised_to_representable() {
        assert_eq!(usable_step(LaneVec3::from(Vec3::ZERO), -2.0), 2.0);
        assert!(usable_step(LaneVec3::from(Vec3::splat(1e4)), 1e-9) > 0.0);
        assert_eq!(usable_step(LaneVec3::from(Vec3::ZERO), f32::NAN), 0.0);
    }
}
