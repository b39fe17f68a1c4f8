//! Property tests for `lueur-sdf-math`, one binary with one module per concern.
//!
//! Every proptest runs from a fixed seed with no regression files, so a failure reproduces
//! on every machine.

use lueur_sdf_math::{
    BoundingSphere, DistanceField, LaneDistance, PreparedSdf, Primitive, Quat, Ray, Sdf, SimdLevel,
    TraceOutcome, TraceParams, Vec3, normal, normal_central, sphere_trace,
};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        rng_seed: RngSeed::Fixed(0x006c_7565_7572),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// Generators of shapes, points and rays.
mod strategies {
    use super::*;

    /// `10^e` for `e` uniform in `[lo, hi]`: sizes spread evenly over orders of magnitude.
    pub fn log_uniform(lo: f32, hi: f32) -> impl Strategy<Value = f32> + Clone {
        (lo..=hi).prop_map(|e| 10f32.powf(e))
    }

    pub fn unit() -> impl Strategy<Value = Vec3> + Clone {
        (-1f32..1.0, -1f32..1.0, -1f32..1.0)
            .prop_map(|(x, y, z)| Vec3::new(x, y, z).normalize_or(Vec3::X))
    }

    pub fn in_cube(half: f32) -> impl Strategy<Value = Vec3> + Clone {
        (-half..half, -half..half, -half..half).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    pub fn rotation() -> impl Strategy<Value = Quat> + Clone {
        (unit(), -4f32..4.0).prop_map(|(axis, angle)| Quat::from_axis_angle(axis, angle))
    }

    /// Declares the primitive kinds and their list together, so that no kind can be left
    /// out of the conformance runs.
    macro_rules! kinds {
        ($($kind:ident),* $(,)?) => {
            /// Which primitive, so that each gets its own conformance run.
            #[derive(Clone, Copy, Debug, PartialEq, Eq)]
            pub enum Kind {
                $($kind,)*
            }

            /// Every kind, each once.
            pub const KINDS: &[Kind] = &[$(Kind::$kind,)*];
        };
    }

    kinds!(
        Sphere,
        Box,
        RoundBox,
        Plane,
        Torus,
        CappedCylinder,
        Capsule,
        DeathStar,
    );

    /// The kind of a primitive node, `None` for combinations and transforms. The matches
    /// have no wildcard: a new `Primitive` (or `Sdf`) variant does not compile until it is
    /// given a kind here, and with it a conformance run.
    pub fn kind_of(sdf: &Sdf) -> Option<Kind> {
        match sdf {
            Sdf::Primitive(shape) => Some(match shape {
                Primitive::Sphere { .. } => Kind::Sphere,
                Primitive::Box { .. } => Kind::Box,
                Primitive::RoundBox { .. } => Kind::RoundBox,
                Primitive::Plane { .. } => Kind::Plane,
                Primitive::Torus { .. } => Kind::Torus,
                Primitive::CappedCylinder { .. } => Kind::CappedCylinder,
                Primitive::Capsule { .. } => Kind::Capsule,
                Primitive::DeathStar { .. } => Kind::DeathStar,
            }),
            Sdf::Union { .. }
            | Sdf::Intersection { .. }
            | Sdf::Difference { .. }
            | Sdf::SmoothUnion { .. }
            | Sdf::SmoothIntersection { .. }
            | Sdf::SmoothDifference { .. }
            | Sdf::Translate { .. }
            | Sdf::Rotate { .. }
            | Sdf::Scale { .. } => None,
        }
    }

    /// Primitives of roughly unit size, including degenerate parameters (a round box
    /// radius past the smallest extent, a spindle torus, an empty Death Star).
    pub fn unit_primitive_of(kind: Kind) -> BoxedStrategy<Sdf> {
        match kind {
            Kind::Sphere => (0f32..2.0).prop_map(Sdf::sphere).boxed(),
            Kind::Box => in_cube(2.0).prop_map(|b| Sdf::cuboid(b.abs())).boxed(),
            Kind::RoundBox => (in_cube(2.0), 0f32..1.5)
                .prop_map(|(b, r)| Sdf::round_box(b.abs(), r))
                .boxed(),
            Kind::Plane => (unit(), -1f32..1.0)
                .prop_map(|(n, h)| Sdf::plane(n, h))
                .boxed(),
            Kind::Torus => (0f32..2.0, 0f32..1.0)
                .prop_map(|(big, small)| Sdf::torus(big, small))
                .boxed(),
            Kind::CappedCylinder => (0f32..2.0, 0f32..2.0)
                .prop_map(|(r, h)| Sdf::capped_cylinder(r, h))
                .boxed(),
            Kind::Capsule => (in_cube(2.0), in_cube(2.0), 0f32..1.0)
                .prop_map(|(a, b, r)| Sdf::capsule(a, b, r))
                .boxed(),
            Kind::DeathStar => (0.1f32..2.0, 0.05f32..2.0, -2.5f32..2.5)
                .prop_map(|(ra, rb, d)| Sdf::death_star(ra, rb, d))
                .boxed(),
        }
    }

    pub fn unit_primitive() -> BoxedStrategy<Sdf> {
        prop::strategy::Union::new(
            KINDS
                .iter()
                .map(|&k| unit_primitive_of(k))
                .collect::<Vec<_>>(),
        )
        .boxed()
    }

    /// A unit primitive scaled by `size` (by editing its parameters, not with `Scale`).
    pub fn sized(shape: Sdf, size: f32) -> Sdf {
        let Sdf::Primitive(shape) = shape else {
            return shape;
        };
        match shape {
            Primitive::Sphere { radius } => Sdf::sphere(radius * size),
            Primitive::Box { half_extents } => Sdf::cuboid(half_extents * size),
            Primitive::RoundBox {
                half_extents,
                radius,
            } => Sdf::round_box(half_extents * size, radius * size),
            Primitive::Plane { normal, height } => Sdf::from(Primitive::Plane {
                normal,
                height: height * size,
            }),
            Primitive::Torus {
                major_radius,
                minor_radius,
            } => Sdf::torus(major_radius * size, minor_radius * size),
            Primitive::CappedCylinder {
                radius,
                half_height,
            } => Sdf::capped_cylinder(radius * size, half_height * size),
            Primitive::Capsule { a, b, radius } => Sdf::capsule(a * size, b * size, radius * size),
            Primitive::DeathStar { ra, rb, d } => Sdf::death_star(ra * size, rb * size, d * size),
        }
    }

    /// Primitives of one kind from tiny (1e-4) to huge (1e4), half of them turned and moved
    /// up to 1e3 away.
    pub fn primitive_of(kind: Kind) -> BoxedStrategy<Sdf> {
        let placement = prop_oneof![
            Just(None),
            (rotation(), unit(), log_uniform(-4.0, 3.0)).prop_map(|(q, d, far)| Some((q, d * far))),
        ];
        (unit_primitive_of(kind), log_uniform(-4.0, 4.0), placement)
            .prop_map(|(shape, size, placement)| {
                let shape = sized(shape, size);
                match placement {
                    None => shape,
                    Some((q, offset)) => shape.rotate(q).translate(offset),
                }
            })
            .boxed()
    }

    /// Primitives whose own parameters span six orders of magnitude (1e-3 to 1e3, each
    /// drawn apart): a plate 1e3 wide and 1e-3 thick, a ring 1e3 across with a 1e-3 tube,
    /// a star 1e-3 across carved by a sphere 1e3 across whose surface crosses it. Their
    /// fields must still round at the shape's own size and the point's, not at the largest
    /// parameter (`checks::magnitude`).
    pub fn lopsided_of(kind: Kind) -> BoxedStrategy<Sdf> {
        let size = || log_uniform(-3.0, 3.0);
        let sizes = || (size(), size(), size()).prop_map(|(x, y, z)| Vec3::new(x, y, z));
        match kind {
            Kind::Sphere => size().prop_map(Sdf::sphere).boxed(),
            Kind::Box => sizes().prop_map(Sdf::cuboid).boxed(),
            Kind::RoundBox => (sizes(), size())
                .prop_map(|(b, r)| Sdf::round_box(b, r))
                .boxed(),
            Kind::Plane => (unit(), size(), any::<bool>())
                .prop_map(|(n, h, below)| Sdf::plane(n, if below { -h } else { h }))
                .boxed(),
            Kind::Torus => (size(), size())
                .prop_map(|(big, small)| Sdf::torus(big, small))
                .boxed(),
            Kind::CappedCylinder => (size(), size())
                .prop_map(|(r, h)| Sdf::capped_cylinder(r, h))
                .boxed(),
            Kind::Capsule => (unit(), size(), unit(), size(), size())
                .prop_map(|(a, la, b, lb, r)| Sdf::capsule(a * la, b * lb, r))
                .boxed(),
            // The bite's surface crosses the star (`across` in -1..1) or misses it.
            Kind::DeathStar => (size(), size(), -1.5f32..1.5, any::<bool>())
                .prop_map(|(ra, rb, across, mirrored)| {
                    let d = rb + across * ra;
                    Sdf::death_star(ra, rb, if mirrored { -d } else { d })
                })
                .boxed(),
        }
    }

    /// Any primitive, as [`lopsided_of`].
    pub fn lopsided() -> BoxedStrategy<Sdf> {
        prop::strategy::Union::new(KINDS.iter().map(|&k| lopsided_of(k)).collect::<Vec<_>>())
            .boxed()
    }

    /// Any primitive, as [`primitive_of`].
    pub fn primitive() -> BoxedStrategy<Sdf> {
        prop::strategy::Union::new(KINDS.iter().map(|&k| primitive_of(k)).collect::<Vec<_>>())
            .boxed()
    }

    pub fn children() -> impl Strategy<Value = Vec<Sdf>> {
        prop::collection::vec(primitive(), 1..4)
    }

    pub fn blend() -> impl Strategy<Value = f32> + Clone {
        log_uniform(-4.0, 3.0)
    }

    /// Random trees mixing every operator, at sizes within a few orders of magnitude.
    pub fn nested() -> BoxedStrategy<Sdf> {
        let leaf = (unit_primitive(), log_uniform(-2.0, 2.0)).prop_map(|(s, size)| sized(s, size));
        leaf.prop_recursive(4, 24, 3, |inner| {
            let kids = prop::collection::vec(inner.clone(), 1..4);
            prop_oneof![
                kids.clone().prop_map(Sdf::union),
                kids.clone().prop_map(Sdf::intersection),
                kids.clone().prop_map(Sdf::difference),
                (blend(), kids.clone()).prop_map(|(k, c)| Sdf::smooth_union(k, c)),
                (blend(), kids.clone()).prop_map(|(k, c)| Sdf::smooth_intersection(k, c)),
                (blend(), kids).prop_map(|(k, c)| Sdf::smooth_difference(k, c)),
                (inner.clone(), in_cube(100.0)).prop_map(|(s, v)| s.translate(v)),
                (inner.clone(), rotation()).prop_map(|(s, q)| s.rotate(q)),
                (inner, log_uniform(-3.0, 3.0), any::<bool>())
                    .prop_map(|(s, f, flip)| s.scale(if flip { -f } else { f })),
            ]
        })
        .boxed()
    }

    /// Random numbers from which [`points`] builds a pair of nearby points.
    #[derive(Clone, Debug)]
    pub struct Probe {
        mode: u8,
        far: Vec3,
        dir_p: Vec3,
        dir_q: Vec3,
        e_p: f32,
        e_q: f32,
        u: f32,
    }

    pub fn probe() -> impl Strategy<Value = Probe> {
        (
            0u8..3,
            prop_oneof![Just(Vec3::ZERO), unit().prop_map(|v| v * 1e3)],
            unit(),
            unit(),
            -4f32..4.0,
            -4f32..4.0,
            0f32..1.0,
        )
            .prop_map(|(mode, far, dir_p, dir_q, e_p, e_q, u)| Probe {
                mode,
                far,
                dir_p,
                dir_q,
                e_p,
                e_q,
                u,
            })
    }

    /// Two points: anywhere at absolute scales 1e-4..1e4 (possibly 1e3 from the origin),
    /// or inside the shape's bounding sphere, or pulled onto its surface, where kinks and
    /// blends are.
    pub fn points(sdf: &Sdf, probe: &Probe) -> (Vec3, Vec3) {
        let (c, r) = sdf.bounding_sphere().unwrap_or((Vec3::ZERO, 1.0));
        let r = if r > 0.0 { r } else { 1.0 };
        match probe.mode {
            0 => {
                let p = probe.far + probe.dir_p * 10f32.powf(probe.e_p);
                (p, p + probe.dir_q * 10f32.powf(probe.e_q))
            }
            1 => {
                let p = c + probe.dir_p * (r * 1.5 * probe.u);
                (p, p + probe.dir_q * (r * 10f32.powf(0.75 * probe.e_q)))
            }
            _ => {
                let p = c + probe.dir_p * (r * 1.5 * probe.u);
                let n = normal(sdf, p, r * 1e-4);
                let p = p - n * (sdf.distance(p) / sdf.lipschitz());
                let p = if p.is_finite() { p } else { c };
                (p, p + probe.dir_q * (r * 10f32.powf(probe.e_q - 4.0)))
            }
        }
    }
}

use strategies::*;

/// A case a run under seed 2 found (`PROPTEST_RNG_SEED=2`): a plane 1.7 from the origin,
/// moved 580 away and back. At the origin its field rounds by 4e-5 below its half-space's value, which a
/// slack scaled by the half-space's height and the point alone did not allow.
#[test]
fn a_plane_moved_far_and_back_rounds_at_its_offsets() {
    let plane = Sdf::Primitive(Primitive::Plane {
        normal: Vec3::new(0.86374885, -0.21962026, -0.45354715),
        height: 0.0,
    });
    let rotated = Sdf::Rotate {
        rotation: Quat::from_xyzw(0.6713946, 0.5610534, 0.21021976, 0.43618345),
        child: Box::new(plane),
    };
    let sdf = rotated
        .translate(Vec3::new(-499.22858, -87.39879, 285.44565))
        .translate(Vec3::new(0.0, 0.8828201, -0.4697113));
    checks::bounding_box(&sdf, Vec3::ZERO).unwrap();
}

/// A case `cargo xtask properties` found under seed 54: a Death Star 2277 in radius,
/// carved by a sphere 1507 in radius 1506 from its centre, intersected with a small one.
/// Near the small one, 1.17 from the bite's surface, the field steps by 1.2e-4 (a rounding
/// at 1500) over 6.8e-5. That is the star's own precision: a slack from the points and
/// values alone did not allow it, one that counts how far each shape reaches does.
#[test]
fn a_large_death_star_rounds_at_its_size() {
    let large = Sdf::Primitive(Primitive::DeathStar {
        ra: 2277.0903,
        rb: 1507.1467,
        d: -1505.8832,
    });
    let small = Sdf::Rotate {
        rotation: Quat::from_xyzw(0.0, 0.0, 0.0, 1.0),
        child: Box::new(Sdf::Primitive(Primitive::DeathStar {
            ra: 0.12378609,
            rb: 0.0058048693,
            d: 0.0,
        })),
    }
    .translate(Vec3::new(0.09334472, 0.69622767, 0.71172595));
    let sdf = Sdf::Intersection(vec![large, small]);
    let p = Vec3::new(0.09334472, -0.47357213, 0.71172595);
    let q = Vec3::new(0.09327717, -0.47357213, 0.71172595);
    checks::lipschitz(&sdf, p, q).unwrap();
}

/// The checks every shape runs.
mod checks {
    use super::*;

    /// The largest magnitude, in world units, that evaluating `sdf` passes through besides
    /// the point's own: how far its translations move the point on the way to a primitive,
    /// plus how far the primitive's shape reaches. The field rounds relative to these,
    /// which neither the point nor the value shows when they cancel: a plane 1.7 from the
    /// origin through two translations of 500 rounds its value by 4e-5 at the origin, and
    /// a Death Star 2277 across, carved by a sphere 1507 in radius 1506 from its centre,
    /// steps by 1.2e-4 there. A parameter larger than the shape is not counted: a star
    /// carved by a sphere 1e4 times its size must keep the star's precision (`lopsided`).
    pub fn magnitude(sdf: &Sdf) -> f32 {
        let most = |children: &[Sdf]| children.iter().map(magnitude).fold(0.0, f32::max);
        match sdf {
            Sdf::Primitive(p) => parameter_magnitude(p),
            Sdf::Translate { offset, child } => offset.length() + magnitude(child),
            Sdf::Rotate { child, .. } => magnitude(child),
            Sdf::Scale { factor, child } => factor.abs() * magnitude(child),
            Sdf::Union(children) | Sdf::Intersection(children) | Sdf::Difference(children) => {
                most(children)
            }
            Sdf::SmoothUnion { k, children }
            | Sdf::SmoothIntersection { k, children }
            | Sdf::SmoothDifference { k, children } => most(children).max(k.abs()),
        }
    }

    /// How far the primitive's shape reaches from its frame's origin (its bounding
    /// sphere's centre plus radius; none for a plane). Not its parameters: a Death Star
    /// carved by a sphere 1e4 across still rounds at the star's own size.
    fn parameter_magnitude(p: &Primitive) -> f32 {
        Sdf::Primitive(*p)
            .bounding_sphere()
            .map_or(0.0, |(c, r)| c.length() + r)
    }

    /// Rounding slack for values computed from `p` and `q`: a few dozen ulps of the
    /// largest magnitude involved.
    pub fn slack(values: &[f32]) -> f32 {
        64.0 * f32::EPSILON * values.iter().map(|v| v.abs()).sum::<f32>() + 1e-30
    }

    pub fn lipschitz(sdf: &Sdf, p: Vec3, q: Vec3) -> Result<(), TestCaseError> {
        let (fp, fq) = (sdf.distance(p), sdf.distance(q));
        prop_assert!(!fp.is_nan() && !fq.is_nan(), "NaN at {p} or {q}");
        if fp == fq {
            return Ok(()); // also covers two equal infinities
        }
        let l = sdf.lipschitz();
        let gap = (p - q).length();
        let tol = slack(&[p.length(), q.length(), fp, fq, magnitude(sdf)]);
        prop_assert!(
            (fp - fq).abs() <= l * gap + tol,
            "|f(p) - f(q)| = {} > L |p - q| = {} * {gap} (+{tol}); f(p) = {fp}, f(q) = {fq}, p = {p}, q = {q}",
            (fp - fq).abs(),
            l
        );
        Ok(())
    }

    pub fn unit_normals(sdf: &Sdf, p: Vec3, h: f32) -> Result<(), TestCaseError> {
        for n in [normal(sdf, p, h), normal_central(sdf, p, h)] {
            prop_assert!(
                n.is_finite() && (n.length() - 1.0).abs() < 1e-5,
                "normal {n} at {p}"
            );
        }
        Ok(())
    }

    pub fn bounding_sphere(sdf: &Sdf, p: Vec3) -> Result<(), TestCaseError> {
        let Some((c, r)) = sdf.bounding_sphere() else {
            return Ok(());
        };
        prop_assert!(c.is_finite() && r >= 0.0 && r.is_finite());
        let f = sdf.distance(p);
        let outside = (p - c).length() - r;
        let tol = slack(&[p.length(), c.length(), r, f]);
        prop_assert!(
            f >= outside - tol,
            "f = {f} < |p - c| - r = {outside} at {p}"
        );
        Ok(())
    }

    pub fn bounding_box(sdf: &Sdf, p: Vec3) -> Result<(), TestCaseError> {
        if let Some(b) = sdf.bounding_box() {
            prop_assert!(b.is_finite() && b.min.cmple(b.max).all(), "{b:?}");
            let f = sdf.distance(p);
            let outside = b.distance_squared(p).sqrt();
            let tol = slack(&[p.length(), b.min.length(), b.max.length(), f]);
            // Inside the box the contract says nothing (the field may be negative there).
            prop_assert!(
                outside == 0.0 || f >= outside - tol,
                "f = {f} < distance to the box {b:?} = {outside} at {p}"
            );
        }
        if let Some(h) = sdf.bounding_half_space() {
            let f = sdf.distance(p);
            let below = h.value(p);
            let tol = slack(&[p.length() * h.normal.length(), h.height, f, magnitude(sdf)]);
            prop_assert!(
                f >= below - tol,
                "f = {f} < half-space {h:?} = {below} at {p}"
            );
        }
        Ok(())
    }
    /// Every lane path the CPU has gives, for batches of 1, 7, 16 and 100 points (whole
    /// vectors, tails, both), the bits of the scalar `distance` at each point. So the
    /// contracts the other checks prove of the scalar field hold for the lanes too.
    pub fn lanes_are_scalar<F: LaneDistance + DistanceField>(
        field: &F,
        points: &[Vec3],
    ) -> Result<(), TestCaseError> {
        let xs: Vec<f32> = points.iter().map(|p| p.x).collect();
        let ys: Vec<f32> = points.iter().map(|p| p.y).collect();
        let zs: Vec<f32> = points.iter().map(|p| p.z).collect();
        for level in SimdLevel::available() {
            for n in [1, 7, 16, 100].into_iter().filter(|&n| n <= points.len()) {
                let mut out = vec![f32::NAN; n];
                field
                    .distance_batch_at(level, &xs[..n], &ys[..n], &zs[..n], &mut out)
                    .unwrap();
                for (p, got) in points.iter().zip(&out) {
                    let want = field.distance(*p);
                    prop_assert!(
                        got.to_bits() == want.to_bits(),
                        "{level:?}, batch of {n}: {got} ({:#x}) != scalar {want} ({:#x}) at {p}",
                        got.to_bits(),
                        want.to_bits()
                    );
                }
            }
        }
        Ok(())
    }

    /// A ray that reaches `p` at `t = back`: if a tracer would call `p` a hit, the
    /// bounds' hit intervals must hold `back`.
    pub fn hit_interval(sdf: &Sdf, p: Vec3, dir: Vec3, back: f32) -> Result<(), TestCaseError> {
        let params = TraceParams {
            t_min: 0.0,
            t_max: 1e5,
            max_steps: 512,
            eps_abs: 1e-4,
            eps_rel: 1e-3,
        };
        let ray = Ray::new(p - dir * back, dir);
        // The point the tracer would evaluate, with its rounding.
        let at = ray.at(back);
        let f = sdf.distance(at);
        if !(f < params.eps_abs.max(params.eps_rel * back)) {
            return Ok(());
        }
        if let Some(b) = sdf.bounding_box() {
            let got = b.hit_interval(&ray, &params);
            prop_assert!(
                got.is_some_and(|(t0, t1)| t0 <= back && back <= t1),
                "f({at}) = {f} at t = {back}, but the box {b:?} gives {got:?} for {ray:?}"
            );
        }
        if let Some((center, radius)) = sdf.bounding_sphere() {
            let b = BoundingSphere { center, radius };
            let got = b.hit_interval(&ray, &params);
            prop_assert!(
                got.is_some_and(|(t0, t1)| t0 <= back && back <= t1),
                "f({at}) = {f} at t = {back}, but the sphere {b:?} gives {got:?} for {ray:?}"
            );
        }
        if let Some(h) = sdf.bounding_half_space() {
            let got = h.hit_interval(&ray, &params);
            prop_assert!(
                got.is_some_and(|(t0, t1)| t0 <= back && back <= t1),
                "f({at}) = {f} at t = {back}, but the half-space {h:?} gives {got:?} for {ray:?}"
            );
        }
        Ok(())
    }
}

/// Conformance: every shape is Lipschitz with its reported bound, has finite unit
/// normals everywhere, and honours its bounding sphere, box and half-space (after fidget's `point_tests!`).
macro_rules! conformance {
    ($($name:ident => $strategy:expr;)*) => {$(
        mod $name {
            use super::*;

            proptest! {
                #![proptest_config(config(256))]

                #[test]
                fn lipschitz(sdf in $strategy, probes in prop::collection::vec(probe(), 16)) {
                    for probe in &probes {
                        let (p, q) = points(&sdf, probe);
                        checks::lipschitz(&sdf, p, q)?;
                    }
                }

                #[test]
                fn normals_are_unit(sdf in $strategy, probes in prop::collection::vec(probe(), 4), h in log_uniform(-6.0, 0.0)) {
                    let centre = sdf.bounding_sphere().map_or(Vec3::ZERO, |(c, _)| c);
                    checks::unit_normals(&sdf, Vec3::ZERO, h)?;
                    checks::unit_normals(&sdf, centre, h)?;
                    for probe in &probes {
                        let (p, q) = points(&sdf, probe);
                        checks::unit_normals(&sdf, p, h)?;
                        checks::unit_normals(&sdf, q, h)?;
                    }
                }

                #[test]
                fn bounding_sphere_is_conservative(sdf in $strategy, probes in prop::collection::vec(probe(), 8)) {
                    for probe in &probes {
                        let (p, q) = points(&sdf, probe);
                        checks::bounding_sphere(&sdf, p)?;
                        checks::bounding_sphere(&sdf, q)?;
                    }
                }

                #[test]
                fn bounding_box_and_half_space_are_conservative(sdf in $strategy, probes in prop::collection::vec(probe(), 8)) {
                    for probe in &probes {
                        let (p, q) = points(&sdf, probe);
                        checks::bounding_box(&sdf, p)?;
                        checks::bounding_box(&sdf, q)?;
                    }
                }

                #[test]
                fn every_lane_path_gives_the_scalar_bits(sdf in $strategy, probes in prop::collection::vec(probe(), 50)) {
                    let points: Vec<Vec3> = probes
                        .iter()
                        .flat_map(|probe| <[Vec3; 2]>::from(points(&sdf, probe)))
                        .collect();
                    checks::lanes_are_scalar(&sdf, &points)?;
                    checks::lanes_are_scalar(&PreparedSdf::new(&sdf), &points)?;
                }

                #[test]
                fn hit_intervals_hold_every_point_below_the_threshold(
                    sdf in $strategy,
                    probes in prop::collection::vec(probe(), 8),
                    dirs in prop::collection::vec(unit(), 8),
                    back in prop::collection::vec(log_uniform(-3.0, 3.0), 8),
                ) {
                    for ((probe, dir), back) in probes.iter().zip(&dirs).zip(&back) {
                        let (p, q) = points(&sdf, probe);
                        checks::hit_interval(&sdf, p, *dir, *back)?;
                        checks::hit_interval(&sdf, q, -*dir, *back)?;
                    }
                }
            }
        }
    )*};
}

conformance! {
    sphere => primitive_of(Kind::Sphere);
    cuboid => primitive_of(Kind::Box);
    round_box => primitive_of(Kind::RoundBox);
    plane => primitive_of(Kind::Plane);
    torus => primitive_of(Kind::Torus);
    capped_cylinder => primitive_of(Kind::CappedCylinder);
    capsule => primitive_of(Kind::Capsule);
    death_star => primitive_of(Kind::DeathStar);
    lopsided => lopsided();
    union => children().prop_map(Sdf::union);
    intersection => children().prop_map(Sdf::intersection);
    difference => children().prop_map(Sdf::difference);
    smooth_union => (blend(), children()).prop_map(|(k, c)| Sdf::smooth_union(k, c));
    smooth_intersection => (blend(), children()).prop_map(|(k, c)| Sdf::smooth_intersection(k, c));
    smooth_difference => (blend(), children()).prop_map(|(k, c)| Sdf::smooth_difference(k, c));
    translate => (primitive(), unit(), log_uniform(-4.0, 4.0)).prop_map(|(s, d, m)| s.translate(d * m));
    rotate => (primitive(), rotation(), log_uniform(-2.0, 2.0)).prop_map(|(s, q, m)| Sdf::Rotate { rotation: q * m, child: Box::new(s) });
    scale => (primitive(), log_uniform(-4.0, 4.0), any::<bool>()).prop_map(|(s, f, flip)| s.scale(if flip { -f } else { f }));
    nested => nested();
}

/// Exact primitives against brute force: surface samples read ~0, and distances match a
/// dense sampling of the surface (in the profile half-plane for shapes of revolution) or a
/// closed form built differently, all in f64.
mod exact {
    use super::*;

    type P2 = [f64; 2];

    fn hypot(a: f64, b: f64) -> f64 {
        a.hypot(b)
    }

    /// Min distance from `pt` to the points `curve(i / n)`, `i = 0..=n`, skipping `None`.
    fn sampled(pt: P2, n: usize, curve: impl Fn(f64) -> Option<P2>) -> f64 {
        (0..=n)
            .filter_map(|i| curve(i as f64 / n as f64))
            .map(|c| hypot(pt[0] - c[0], pt[1] - c[1]))
            .fold(f64::INFINITY, f64::min)
    }

    /// (radial distance from the Y axis, y).
    fn profile_y(p: Vec3) -> P2 {
        [hypot(p.x as f64, p.z as f64), p.y as f64]
    }

    /// (x, radial distance from the X axis).
    fn profile_x(p: Vec3) -> P2 {
        [p.x as f64, hypot(p.y as f64, p.z as f64)]
    }

    const N: usize = 100_000;
    const PI: f64 = std::f64::consts::PI;

    /// Brute-force signed distance and the sampling error it may carry.
    fn brute(sdf: &Sdf, p: Vec3) -> (f64, f64) {
        let Sdf::Primitive(shape) = *sdf else {
            unreachable!("not a primitive: {sdf:?}")
        };
        match shape {
            Primitive::Sphere { radius } => {
                let r = radius as f64;
                let d = sampled(profile_y(p), N, |u| {
                    Some([r * (PI * u).sin(), r * (PI * u).cos()])
                });
                let inside = (p.as_dvec3().length()) < r;
                (if inside { -d } else { d }, PI * r / N as f64)
            }
            Primitive::Box { half_extents } => (box_by_faces(p, half_extents), 0.0),
            Primitive::RoundBox {
                half_extents,
                radius,
            } => {
                // The Minkowski sum of the inner box and a ball: outside the inner box the
                // distance is |p - inner| - r; inside it, r more than the inner box's.
                let r = radius.max(0.0).min(half_extents.min_element()) as f64;
                let inner = half_extents - Vec3::splat(r as f32);
                (box_by_faces(p, inner) - r, 0.0)
            }
            Primitive::Torus {
                major_radius,
                minor_radius,
            } => {
                let (big, small) = (major_radius as f64, minor_radius as f64);
                let d = sampled(profile_y(p), N, |u| {
                    Some([
                        big + small * (2.0 * PI * u).cos(),
                        small * (2.0 * PI * u).sin(),
                    ])
                });
                let q = profile_y(p);
                let inside = hypot(q[0] - big, q[1]) < small;
                (if inside { -d } else { d }, PI * small / N as f64)
            }
            Primitive::CappedCylinder {
                radius,
                half_height,
            } => {
                let (r, h) = (radius as f64, half_height as f64);
                let q = profile_y(p);
                let d = [
                    sampled(q, N, |u| Some([u * r, h])),
                    sampled(q, N, |u| Some([r, h * (2.0 * u - 1.0)])),
                    sampled(q, N, |u| Some([u * r, -h])),
                ]
                .into_iter()
                .fold(f64::INFINITY, f64::min);
                let inside = q[0] < r && q[1].abs() < h;
                (if inside { -d } else { d }, (r + 2.0 * h) / N as f64)
            }
            Primitive::Capsule { a, b, radius } => {
                let (p, a, b) = (p.as_dvec3(), a.as_dvec3(), b.as_dvec3());
                let core = (0..=N)
                    .map(|i| (p - a.lerp(b, i as f64 / N as f64)).length())
                    .fold(f64::INFINITY, f64::min);
                (core - radius as f64, (b - a).length() / N as f64)
            }
            Primitive::DeathStar { ra, rb, d } => {
                let (ra, rb, d) = (ra as f64, rb as f64, d as f64);
                let q = profile_x(p);
                // The big sphere's part outside the small one, then the small sphere's part
                // inside the big one.
                let big = sampled(q, N, |u| {
                    let c = [ra * (PI * u).cos(), ra * (PI * u).sin()];
                    (hypot(c[0] - d, c[1]) >= rb).then_some(c)
                });
                let small = sampled(q, N, |u| {
                    let c = [d + rb * (PI * u).cos(), rb * (PI * u).sin()];
                    (hypot(c[0], c[1]) <= ra).then_some(c)
                });
                let dist = big.min(small);
                let inside = hypot(q[0], q[1]) < ra && hypot(q[0] - d, q[1]) > rb;
                (
                    if inside { -dist } else { dist },
                    PI * ra.max(rb) / N as f64,
                )
            }
            _ => unreachable!("not a brute-forced primitive: {sdf:?}"),
        }
    }

    /// Signed distance to a box as the nearest of its six face rectangles.
    fn box_by_faces(p: Vec3, half: Vec3) -> f64 {
        let (p, b) = (p.as_dvec3(), half.as_dvec3());
        let mut nearest = f64::INFINITY;
        for axis in 0..3 {
            for sign in [-1.0, 1.0] {
                let mut on_face = p.clamp(-b, b);
                on_face[axis] = sign * b[axis];
                nearest = nearest.min((p - on_face).length());
            }
        }
        let inside = p.abs().cmplt(b).all();
        if inside { -nearest } else { nearest }
    }

    /// Exact primitives at unit size, then scaled by 1e-3..1e3.
    fn exact_primitive() -> impl Strategy<Value = (Sdf, f32)> {
        let shapes = prop_oneof![
            (0.1f32..2.0).prop_map(Sdf::sphere),
            in_cube(2.0).prop_map(|b| Sdf::cuboid(b.abs() + Vec3::splat(0.05))),
            (in_cube(2.0), 0f32..1.0).prop_map(|(b, r)| {
                let b = b.abs() + Vec3::splat(0.05);
                Sdf::round_box(b, r * b.min_element())
            }),
            (0.1f32..2.0, 0.05f32..1.0).prop_map(|(big, t)| Sdf::torus(big, big * t)),
            (0.05f32..2.0, 0.05f32..2.0).prop_map(|(r, h)| Sdf::capped_cylinder(r, h)),
            (in_cube(2.0), in_cube(2.0), 0.05f32..1.0).prop_map(|(a, b, r)| Sdf::capsule(a, b, r)),
            (0.2f32..2.0, 0.1f32..2.0, -2.5f32..2.5).prop_map(|(ra, t, d)| Sdf::death_star(
                ra,
                ra * t,
                ra * d
            )),
        ];
        // An empty Death Star (the small sphere swallowing the big one) is only a bound.
        (
            shapes.prop_filter("exact", Sdf::is_exact),
            log_uniform(-3.0, 3.0),
        )
            .prop_map(|(s, size)| (sized(s, size), size))
    }

    /// A point on the surface from two uniform numbers and a direction.
    fn on_surface(sdf: &Sdf, u: f32, v: f32, dir: Vec3) -> Option<Vec3> {
        use std::f32::consts::TAU;
        let ring = |r: f32, y: f32| Vec3::new(r * (TAU * u).cos(), y, r * (TAU * u).sin());
        let Sdf::Primitive(shape) = *sdf else {
            unreachable!("not a primitive: {sdf:?}")
        };
        Some(match shape {
            Primitive::Sphere { radius } => dir * radius,
            Primitive::Box { half_extents: b }
            | Primitive::RoundBox {
                half_extents: b,
                radius: _,
            } => {
                let r = match shape {
                    Primitive::RoundBox { radius, .. } => radius,
                    _ => 0.0,
                };
                // Nearest point of the inner box to a far point, pushed out by r.
                let inner = b - Vec3::splat(r);
                let far = dir * b.length() * 3.0;
                let c = far.clamp(-inner, inner);
                c + (far - c).normalize() * r
            }
            Primitive::Torus {
                major_radius,
                minor_radius,
            } => {
                let a = TAU * v;
                ring(
                    major_radius + minor_radius * a.cos(),
                    minor_radius * a.sin(),
                )
            }
            Primitive::CappedCylinder {
                radius,
                half_height,
            } => match (v * 3.0) as u32 {
                0 => ring(radius * u.sqrt(), half_height),
                1 => ring(radius * u.sqrt(), -half_height),
                _ => ring(radius, half_height * (2.0 * (v * 3.0).fract() - 1.0)),
            },
            Primitive::Capsule { a, b, radius } => {
                let axis = (b - a).normalize_or(Vec3::Y);
                let side = (dir - axis * dir.dot(axis)).normalize_or(axis.any_orthonormal_vector());
                match (v * 3.0) as u32 {
                    0 if dir.dot(axis) <= 0.0 => a + dir * radius,
                    1 if dir.dot(axis) >= 0.0 => b + dir * radius,
                    _ => a.lerp(b, u) + side * radius,
                }
            }
            Primitive::DeathStar { ra, rb, d } => {
                let small = Vec3::new(d, 0.0, 0.0);
                let big_point = dir * ra;
                let small_point = small + dir * rb;
                if v < 0.5 && (big_point - small).length() >= rb {
                    big_point
                } else if small_point.length() <= ra {
                    small_point
                } else {
                    return None;
                }
            }
            _ => unreachable!(),
        })
    }

    proptest! {
        #![proptest_config(config(128))]

        #[test]
        fn surface_reads_zero(
            (sdf, size) in exact_primitive(),
            samples in prop::collection::vec((0f32..1.0, 0f32..1.0, unit()), 16),
        ) {
            prop_assert!(sdf.is_exact());
            for (u, v, dir) in samples {
                let Some(p) = on_surface(&sdf, u, v, dir) else { continue };
                let f = sdf.distance(p);
                prop_assert!(f.abs() <= 1e-5 * (size + p.length()), "f = {f} at surface point {p} of {sdf:?}");
            }
        }

        #[test]
        fn distance_matches_brute_force(
            (sdf, size) in exact_primitive(),
            points in prop::collection::vec((in_cube(3.0), log_uniform(-1.0, 1.5)), 4),
        ) {
            for (p, spread) in points {
                let p = p * size * spread;
                let f = sdf.distance(p) as f64;
                let (expected, sampling) = brute(&sdf, p);
                let tol = sampling + 1e-5 * (size as f64 + p.length() as f64);
                prop_assert!(
                    (f - expected).abs() <= tol,
                    "f = {f}, brute force = {expected} (tol {tol}) at {p} for {sdf:?}"
                );
            }
        }

        /// A spindle torus is exact outside and a bound inside.
        #[test]
        fn spindle_torus_is_exact_outside(
            big in 0.05f32..1.0,
            small in 1f32..2.0,
            points in prop::collection::vec(in_cube(3.0), 8),
        ) {
            let sdf = Sdf::torus(big, small);
            prop_assert!(!sdf.is_exact() && sdf.is_exact_outside());
            for p in points {
                let f = sdf.distance(p);
                // The core circle, sampled: distance to the solid is that minus the tube.
                let core = (0..=20_000)
                    .map(|i| {
                        let a = std::f64::consts::TAU * i as f64 / 20_000.0;
                        (p.as_dvec3() - glam::DVec3::new(big as f64 * a.cos(), 0.0, big as f64 * a.sin())).length()
                    })
                    .fold(f64::INFINITY, f64::min)
                    - small as f64;
                if core > 0.0 {
                    prop_assert!((f as f64 - core).abs() <= 1e-4, "outside: {f} vs {core} at {p}");
                } else {
                    prop_assert!(f as f64 <= 1e-6, "inside must read inside: {f} at {p}");
                }
            }
        }
    }

    #[test]
    fn empty_death_star_is_positive_everywhere() {
        let sdf = Sdf::death_star(0.5, 1.0, 0.25);
        assert!(!sdf.is_exact());
        for i in 0..1000 {
            let p = Vec3::new(
                (i as f32 * 0.37).sin(),
                (i as f32 * 0.73).cos(),
                (i as f32 * 0.11).sin(),
            ) * 2.0;
            assert!(sdf.distance(p) > 0.0, "{p}");
        }
    }
}

/// Normals: finite and unit where the gradient vanishes, correct where it is known.
mod normals {
    use super::*;

    #[test]
    fn degenerate_points_give_unit_normals() {
        let torus = Sdf::torus(1.0, 0.25);
        let cases = [
            (Sdf::sphere(1.0), Vec3::ZERO),
            (
                Sdf::sphere(1.0).translate(Vec3::splat(1e3)),
                Vec3::splat(1e3),
            ),
            (torus.clone(), Vec3::ZERO),
            (torus.clone(), Vec3::new(0.0, 0.5, 0.0)),
            (torus, Vec3::new(0.0, -3.0, 0.0)),
            (Sdf::cuboid(Vec3::ONE), Vec3::ZERO),
            (
                Sdf::capsule(Vec3::ZERO, Vec3::Y, 0.5),
                Vec3::new(0.0, 0.5, 0.0),
            ),
            (Sdf::capped_cylinder(1.0, 1.0), Vec3::ZERO),
        ];
        for (sdf, p) in cases {
            for h in [0.0, 1e-6, 1e-4, 1e-2, f32::NAN, -1e-3] {
                for n in [normal(&sdf, p, h), normal_central(&sdf, p, h)] {
                    assert!(
                        n.is_finite() && (n.length() - 1.0).abs() < 1e-5,
                        "{sdf:?} at {p}, h {h}: {n}"
                    );
                }
            }
        }
    }

    proptest! {
        #![proptest_config(config(256))]

        /// On and near a sphere of any size the normal is the radial direction.
        #[test]
        fn sphere_normal_is_radial(
            r in log_uniform(-3.0, 3.0),
            centre in in_cube(10.0),
            dir in unit(),
            shell in -0.5f32..0.5,
        ) {
            let centre = centre * r;
            let sdf = Sdf::sphere(r).translate(centre);
            let p = centre + dir * (r * (1.0 + shell));
            let h = 1e-3 * r;
            let expected = (p - centre).normalize();
            for n in [normal(&sdf, p, h), normal_central(&sdf, p, h)] {
                prop_assert!((n - expected).length() < 2e-3, "{n} vs {expected}");
            }
        }

        /// Away from edges the two estimators agree.
        #[test]
        fn tetrahedron_matches_central_on_a_torus(u in 0f32..1.0, v in 0f32..1.0) {
            use std::f32::consts::TAU;
            let sdf = Sdf::torus(1.0, 0.3);
            let (a, b) = (TAU * u, TAU * v);
            let radial = 1.0 + 0.3 * b.cos();
            let p = Vec3::new(radial * a.cos(), 0.3 * b.sin(), radial * a.sin());
            let expected = Vec3::new(b.cos() * a.cos(), b.sin(), b.cos() * a.sin());
            prop_assert!((normal(&sdf, p, 1e-4) - expected).length() < 1e-3);
            prop_assert!((normal_central(&sdf, p, 1e-4) - expected).length() < 1e-3);
        }
    }
}

/// The tracer: analytic hits, misses and give-ups, at several scales, and never a tunnel.
mod trace {
    use super::*;

    /// First intersection of the ray with a sphere, in f64.
    fn ray_sphere(ray: &Ray, centre: Vec3, r: f32) -> Option<f64> {
        let (o, d, c) = (ray.origin.as_dvec3(), ray.dir.as_dvec3(), centre.as_dvec3());
        let oc = o - c;
        let b = oc.dot(d);
        let disc = b * b - (oc.length_squared() - (r as f64).powi(2));
        (disc >= 0.0)
            .then(|| -b - disc.sqrt())
            .filter(|t| *t >= 0.0)
    }

    fn far_params() -> TraceParams {
        TraceParams {
            t_max: 1e7,
            ..TraceParams::default()
        }
    }

    proptest! {
        #![proptest_config(config(256))]

        /// A ray aimed well inside a sphere hits it at the analytic distance, within the hit
        /// threshold (scaled by the incidence), and never beyond it.
        #[test]
        fn hits_sphere_at_analytic_distance(
            r in log_uniform(-3.0, 3.0),
            centre in in_cube(10.0),
            from in unit(),
            distance in 1.5f32..50.0,
            aim in unit(),
            off_centre in 0f32..0.6,
        ) {
            let centre = centre * r;
            let sdf = Sdf::sphere(r).translate(centre);
            let origin = centre + from * r * distance;
            let ray = Ray::new(origin, centre + aim * (r * off_centre) - origin);
            let params = far_params();
            let exact = ray_sphere(&ray, centre, r).expect("aimed inside the sphere");
            let outcome = sphere_trace(&sdf, &ray, &params);
            let TraceOutcome::Hit { t, steps } = outcome else {
                return Err(TestCaseError::fail(format!("{outcome:?}, expected a hit at {exact}")));
            };
            prop_assert!(steps <= params.max_steps);
            let eps = params.eps_abs.max(params.eps_rel * t) as f64;
            // Passing within 0.6 r of the centre, the incidence cosine is at least 0.8, so
            // the surface along the ray is at most eps / 0.8 beyond the threshold.
            let slack = 2.0 * eps + 1e-5 * exact;
            prop_assert!((t as f64) <= exact + 1e-5 * exact, "tunnelled: {t} > {exact}");
            prop_assert!((t as f64 - exact).abs() <= slack, "t = {t}, exact {exact}, slack {slack}");
        }

        /// For any shape and ray: the march ends within the cap, a hit is below the
        /// threshold, and no sample of the ray before the hit is inside (no tunnelling).
        #[test]
        fn never_tunnels(sdf in nested(), from in unit(), aim in in_cube(1.0)) {
            let (c, r) = sdf.bounding_sphere().unwrap_or((Vec3::ZERO, 1.0));
            let r = r.max(1e-3);
            let origin = c + from * r * 3.0;
            let ray = Ray::new(origin, c + aim * r - origin);
            let params = TraceParams { t_max: 10.0 * r, ..TraceParams::default() };
            if sdf.distance(origin) < params.eps_abs {
                return Ok(()); // starts inside (a plane or a blend can reach this far)
            }
            let outcome = sphere_trace(&sdf, &ray, &params);
            prop_assert!(outcome.steps() <= params.max_steps);
            let end = match outcome {
                TraceOutcome::Hit { t, .. } => {
                    let f = sdf.distance(ray.at(t));
                    prop_assert!(f < params.eps_abs.max(params.eps_rel * t), "hit reads {f}");
                    t
                }
                TraceOutcome::Miss { .. } => params.t_max,
                TraceOutcome::GaveUp { t, .. } => t,
            };
            for i in 0..1000 {
                let s = end * (i as f32 / 1000.0);
                let f = sdf.distance(ray.at(s));
                let tol = checks::slack(&[ray.at(s).length(), f]);
                prop_assert!(f >= -tol, "inside at t = {s} < {end}: {f} ({outcome:?})");
            }
        }
    }

    #[test]
    fn scales() {
        for scale in [1e-3f32, 1.0, 1e3] {
            let sdf = Sdf::sphere(scale).translate(Vec3::new(0.0, 0.0, 5.0 * scale));
            let ray = Ray::new(Vec3::ZERO, Vec3::Z);
            let outcome = sphere_trace(&sdf, &ray, &far_params());
            let t = outcome.hit_t().unwrap_or(f32::NAN);
            assert!(
                (t - 4.0 * scale).abs() <= 1e-4 * 4.0 * scale + 1e-5,
                "scale {scale}: {outcome:?}"
            );
            // The analytic answer is reached in a couple of steps head-on.
            assert!(outcome.steps() <= 3, "{outcome:?}");
        }
    }

    #[test]
    fn miss_and_give_up() {
        let sdf = Sdf::sphere(1.0);
        let away = Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::NEG_Z);
        assert!(matches!(
            sphere_trace(&sdf, &away, &TraceParams::default()),
            TraceOutcome::Miss { .. }
        ));

        // Grazing 1e-3 above the sphere: steps shrink to ~1e-3 near the tangent point.
        let grazing = Ray::new(Vec3::new(-10.0, 1.001, 0.0), Vec3::X);
        let capped = TraceParams {
            max_steps: 8,
            ..TraceParams::default()
        };
        let outcome = sphere_trace(&sdf, &grazing, &capped);
        let TraceOutcome::GaveUp { t, steps } = outcome else {
            panic!("expected GaveUp, got {outcome:?}");
        };
        assert_eq!(steps, 8);
        assert!(t > 8.0 && t < 10.0, "stopped before the tangent point: {t}");
        // With the default budget the same ray slips past and misses.
        let full = sphere_trace(&sdf, &grazing, &TraceParams::default());
        assert!(matches!(full, TraceOutcome::Miss { .. }), "{full:?}");
    }

    #[test]
    fn secondary_rays_start_off_the_surface() {
        let sdf = Sdf::sphere(1.0);
        let params = TraceParams::default();
        let hit = Vec3::new(0.0, 1.0, 0.0);
        let n = normal(&sdf, hit, 1e-4);
        // From the surface itself: inside the epsilon shell, an immediate hit.
        let on = sphere_trace(&sdf, &Ray::new(hit, Vec3::X), &params);
        assert_eq!(on, TraceOutcome::Hit { t: 0.0, steps: 1 });
        // Offset along the normal by a few thresholds: the tangent ray escapes.
        let off = Ray::new(hit + n * (10.0 * params.eps_abs), Vec3::X);
        assert!(matches!(
            sphere_trace(&sdf, &off, &params),
            TraceOutcome::Miss { .. }
        ));
    }

    #[test]
    fn nan_field_gives_up() {
        struct Broken;
        impl DistanceField for Broken {
            fn distance(&self, p: Vec3) -> f32 {
                if p.z > 1.0 { f32::NAN } else { 0.75 }
            }
            fn lipschitz(&self) -> f32 {
                f32::NAN
            }
        }
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        let outcome = sphere_trace(&Broken, &ray, &TraceParams::default());
        assert_eq!(outcome, TraceOutcome::GaveUp { t: 1.5, steps: 3 });
    }
}

/// Any finite input, however extreme: no panic, normals stay unit, the tracer stops.
mod robustness {
    use super::*;

    fn finite() -> impl Strategy<Value = f32> + Clone {
        prop_oneof![
            any::<f32>().prop_filter("finite", |x| x.is_finite()),
            -10f32..10.0,
            Just(0.0),
        ]
    }

    fn finite_vec() -> impl Strategy<Value = Vec3> + Clone {
        (finite(), finite(), finite()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    fn wild() -> BoxedStrategy<Sdf> {
        let (f, v) = (finite(), finite_vec());
        let leaf = prop_oneof![
            f.clone().prop_map(Sdf::sphere),
            v.clone().prop_map(Sdf::cuboid),
            (v.clone(), f.clone()).prop_map(|(b, r)| Sdf::round_box(b, r)),
            (v.clone(), f.clone())
                .prop_map(|(normal, height)| Sdf::from(Primitive::Plane { normal, height })),
            (f.clone(), f.clone()).prop_map(|(a, b)| Sdf::torus(a, b)),
            (f.clone(), f.clone()).prop_map(|(a, b)| Sdf::capped_cylinder(a, b)),
            (v.clone(), v.clone(), f.clone()).prop_map(|(a, b, r)| Sdf::capsule(a, b, r)),
            (f.clone(), f.clone(), f.clone()).prop_map(|(a, b, d)| Sdf::death_star(a, b, d)),
        ];
        leaf.prop_recursive(3, 12, 3, move |inner| {
            let kids = prop::collection::vec(inner.clone(), 0..3);
            let (f, v) = (finite(), finite_vec());
            prop_oneof![
                kids.clone().prop_map(Sdf::union),
                kids.clone().prop_map(Sdf::intersection),
                kids.clone().prop_map(Sdf::difference),
                (f.clone(), kids.clone()).prop_map(|(k, c)| Sdf::smooth_union(k, c)),
                (f.clone(), kids.clone()).prop_map(|(k, c)| Sdf::smooth_intersection(k, c)),
                (f.clone(), kids).prop_map(|(k, c)| Sdf::smooth_difference(k, c)),
                (inner.clone(), v.clone()).prop_map(|(s, o)| s.translate(o)),
                (inner.clone(), v, f.clone()).prop_map(|(s, xyz, w)| Sdf::Rotate {
                    rotation: Quat::from_xyzw(xyz.x, xyz.y, xyz.z, w),
                    child: Box::new(s),
                }),
                (inner, f).prop_map(|(s, factor)| s.scale(factor)),
            ]
        })
        .boxed()
    }

    proptest! {
        #![proptest_config(config(512))]

        #[test]
        fn extreme_inputs_do_not_panic(
            sdf in wild(),
            p in finite_vec(),
            h in finite(),
            dir in finite_vec(),
            (t_min, t_max, eps_abs, eps_rel) in (finite(), finite(), finite(), finite()),
            max_steps in 0u32..64,
        ) {
            let _ = sdf.distance(p);
            let l = sdf.lipschitz();
            prop_assert!(l >= 1.0, "lipschitz {l}");
            let _ = (sdf.is_exact(), sdf.is_exact_outside());
            if let Some((c, r)) = sdf.bounding_sphere() {
                prop_assert!(c.is_finite() && r.is_finite() && r >= 0.0, "sphere {c} {r}");
            }
            for n in [normal(&sdf, p, h), normal_central(&sdf, p, h)] {
                prop_assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-5, "normal {n}");
            }
            let params = TraceParams { t_min, t_max, max_steps, eps_abs, eps_rel };
            let outcome = sphere_trace(&sdf, &Ray::new(p, dir), &params);
            prop_assert!(outcome.steps() <= max_steps);
        }
    }
}

/// Over-relaxed tracing (Keinert et al. 2014) against plain Hart tracing as the reference:
/// on thin shapes and unions, at scales 1e-4..1e4, it never passes a surface that plain
/// tracing stops at.
mod relaxed {
    use super::*;
    use lueur_sdf_math::{OVER_RELAXATION, sphere_trace_relaxed};

    /// A thin shape of unit size and a point inside it chosen by `(u, v)` in `[0, 1)^2`.
    fn thin(kind: u8, u: f32, v: f32) -> (Sdf, Vec3) {
        let tau = std::f32::consts::TAU;
        match kind {
            // A ring of radius 1 with a tube of radius 1e-3; the point is on its core.
            0 => (
                Sdf::torus(1.0, 1e-3),
                Vec3::new((tau * u).cos(), 0.0, (tau * u).sin()),
            ),
            // A plate 2e-3 thick.
            1 => (
                Sdf::cuboid(Vec3::new(1.0, 1.0, 1e-3)),
                Vec3::new(2.0 * u - 1.0, 2.0 * v - 1.0, 0.0) * 0.999,
            ),
            // Three parallel plates 1e-3 thick, 0.1 apart; the point is in the last one.
            2 => (
                Sdf::union(
                    [-0.1f32, 0.0, 0.1]
                        .map(|z| {
                            Sdf::cuboid(Vec3::new(1.0, 1.0, 5e-4)).translate(Vec3::new(0.0, 0.0, z))
                        })
                        .to_vec(),
                ),
                Vec3::new(2.0 * u - 1.0, 2.0 * v - 1.0, 0.0) * 0.999 + Vec3::new(0.0, 0.0, 0.1),
            ),
            // The Death Star's rim: a unit sphere bitten by an equal one 0.02 away leaves a
            // crescent whose thickness falls from 0.02 to 0 at the rim; the point is at
            // most 85 degrees from the pole, where it is still 1.7e-3 thick.
            _ => {
                let theta = (85f32 * u).to_radians();
                let phi = tau * v;
                let dir = Vec3::new(
                    -theta.cos(),
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                );
                let r = 1.0 - 0.02 * theta.cos() / 2.0;
                (Sdf::death_star(1.0, 1.0, 0.02), dir * r)
            }
        }
    }

    /// Tracing parameters for a shape of size `scale`, seen from about `3 scale`.
    fn params(scale: f32) -> TraceParams {
        TraceParams {
            t_min: 0.0,
            t_max: 20.0 * scale,
            max_steps: 100_000,
            eps_abs: 1e-6 * scale,
            eps_rel: 1e-5,
        }
    }

    /// Whether the two ends lie on one piece of surface: the field between them never
    /// rises above a few hit thresholds (it would between two separate surfaces).
    fn same_surface(sdf: &Sdf, ray: &Ray, a: f32, b: f32, p: &TraceParams) -> bool {
        let (lo, hi) = (a.min(b), a.max(b));
        let eps = p.eps_abs.max(p.eps_rel * hi);
        (0..=64).all(|i| {
            let t = lo + (hi - lo) * (i as f32 / 64.0);
            sdf.distance(ray.at(t)) <= 4.0 * eps * sdf.lipschitz()
        })
    }

    /// Whether the ray past `t` stays outside the surface at 4096 points up to `t_max`, so
    /// that a hit at `t` was only the hit threshold's.
    fn only_grazes(sdf: &Sdf, ray: &Ray, t: f32, p: &TraceParams) -> bool {
        (0..=4096).all(|i| sdf.distance(ray.at(t + (p.t_max - t) * (i as f32 / 4096.0))) > 0.0)
    }

    /// Both tracers agree: both hit on one piece of surface, or both miss, or the plain
    /// tracer hits where the ray only grazes a surface.
    fn agree(sdf: &Sdf, ray: &Ray, p: &TraceParams) -> Result<(), TestCaseError> {
        let plain = sphere_trace(sdf, ray, p);
        let relaxed = sphere_trace_relaxed(sdf, ray, p, OVER_RELAXATION);
        prop_assert!(relaxed.steps() <= p.max_steps);
        match (plain, relaxed) {
            (TraceOutcome::GaveUp { .. }, _) => {} // no reference
            (TraceOutcome::Hit { t: tp, .. }, TraceOutcome::Hit { t: tr, .. }) => {
                let f = sdf.distance(ray.at(tr));
                prop_assert!(f < p.eps_abs.max(p.eps_rel * tr), "relaxed hit reads {f}");
                prop_assert!(
                    same_surface(sdf, ray, tp, tr, p),
                    "plain hit at {tp}, relaxed at {tr}: different surfaces ({plain:?}, {relaxed:?})"
                );
            }
            (TraceOutcome::Miss { .. }, TraceOutcome::Miss { .. }) => {}
            // A ray that only grazes a surface, never going below it, is a hit where it
            // passes within the hit threshold, which grows with `t`: where the gap and the
            // threshold meet, one tracer may stop and the other, stepping to other points,
            // pass. A ray that goes below the surface may not be missed.
            (TraceOutcome::Hit { t: tp, .. }, TraceOutcome::Miss { .. })
                if only_grazes(sdf, ray, tp, p) => {}
            // Running out of steps is slow, not wrong, as long as it stopped short.
            (TraceOutcome::Hit { t: tp, .. }, TraceOutcome::GaveUp { t: tr, .. }) => {
                prop_assert!(
                    tr <= tp * (1.0 + 1e-5),
                    "gave up at {tr}, past the hit at {tp}"
                );
            }
            _ => prop_assert!(false, "plain {plain:?} but relaxed {relaxed:?}"),
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(config(512))]

        /// Rays aimed at a point inside a thin shape stop before reaching it, with either
        /// tracer, and on the same piece of surface.
        #[test]
        fn never_skips_thin_shapes(
            kind in 0u8..4,
            (u, v) in (0f32..1.0, 0f32..1.0),
            turn in rotation(),
            scale in log_uniform(-4.0, 4.0),
            offset in in_cube(1.0),
            from in unit(),
            distance in 1.5f32..6.0,
        ) {
            let (shape, inside) = thin(kind, u, v);
            let centre = offset * scale;
            let sdf = shape.rotate(turn).scale(scale).translate(centre);
            let inside = centre + turn * inside * scale;
            prop_assert!(sdf.distance(inside) < 0.0, "{inside} is not inside");
            let origin = centre + from * (distance * scale);
            prop_assume!(sdf.distance(origin) > 0.0);
            let ray = Ray::new(origin, inside - origin);
            let p = params(scale);
            let reach = (inside - origin).length();
            for outcome in [sphere_trace(&sdf, &ray, &p), sphere_trace_relaxed(&sdf, &ray, &p, OVER_RELAXATION)] {
                let t = outcome.hit_t();
                prop_assert!(
                    t.is_some_and(|t| t <= reach * (1.0 + 1e-5)),
                    "{outcome:?} passes the inside point at {reach}"
                );
            }
            agree(&sdf, &ray, &p)?;
        }

        /// Thin shapes seen edge-on: rays in the plane of a plate or a box face, or
        /// grazing them by less than their thickness.
        #[test]
        fn edge_on(
            kind in 1u8..3,
            turn in rotation(),
            scale in log_uniform(-4.0, 4.0),
            (x, y) in (-1.5f32..1.5, -1.5f32..1.5),
            lift in -2e-3f32..2e-3,
            angle in 0f32..std::f32::consts::TAU,
        ) {
            check_edge_on(kind, turn, scale, Vec3::new(x, y, lift), angle)?;
        }

        /// Random rays at random unions (the shapes an integrator traces).
        #[test]
        fn unions(
            children in children(),
            thin_kind in 0u8..4,
            turn in rotation(),
            from in unit(),
            aims in prop::collection::vec(in_cube(1.0), 8),
        ) {
            let mut children = children;
            children.push(thin(thin_kind, 0.0, 0.0).0.rotate(turn));
            let sdf = Sdf::union(children);
            let (c, r) = sdf.bounding_sphere().unwrap_or((Vec3::ZERO, 1.0));
            let r = r.max(1e-3);
            let origin = c + from * (3.0 * r);
            prop_assume!(sdf.distance(origin) > 0.0);
            for aim in aims {
                let ray = Ray::new(origin, c + aim * r - origin);
                agree(&sdf, &ray, &params(r))?;
            }
        }
    }

    /// The property of `edge_on`: a thin shape `kind` turned by `turn` and scaled, the ray
    /// in its plane at `angle` through `target` (its `z` the lift off the plane).
    fn check_edge_on(
        kind: u8,
        turn: Quat,
        scale: f32,
        target: Vec3,
        angle: f32,
    ) -> Result<(), TestCaseError> {
        let (shape, _) = thin(kind, 0.0, 0.0);
        let sdf = shape.rotate(turn).scale(scale);
        // Start outside, 3 units away in the plate's plane, heading through the target.
        let dir = Vec3::new(angle.cos(), angle.sin(), 0.0);
        let origin = target - dir * 3.0;
        let ray = Ray::new(turn * origin * scale, turn * dir);
        prop_assume!(sdf.distance(ray.origin) > 0.0);
        agree(&sdf, &ray, &params(scale))
    }

    /// A case `cargo xtask properties` found under seed 68: a plate 670 wide and 0.67
    /// thick, the ray 0.017 under its face along it. The hit threshold grows with `t`
    /// (1e-5 t) and meets the gap at t = 1684, where the plain tracer stops after 17940
    /// steps and the relaxed one, stepping to other points, passes and misses. The ray
    /// never goes below the surface, so both are right.
    #[test]
    fn a_ray_grazing_a_plate_where_the_threshold_meets_the_gap() {
        let turn = Quat::from_xyzw(-0.12222462, -0.05549896, -0.0063540847, 0.9909292);
        let target = Vec3::new(-1.2707547, -0.9616983, -0.0010502412);
        if let Err(TestCaseError::Fail(why)) = check_edge_on(1, turn, 335.41394, target, 1.3268073)
        {
            panic!("{why}");
        }
    }

    /// Over-relaxation earns its place: on rays that pass near surfaces (where plain
    /// tracing crawls), it spends fewer evaluations in total. A step count, not a timing.
    #[test]
    fn takes_fewer_steps_on_grazing_rays() {
        let sdf = Sdf::torus(1.0, 0.25).rotate(Quat::from_rotation_x(0.4));
        let p = params(1.0);
        let (mut plain, mut relaxed) = (0u64, 0u64);
        for i in 0..1000 {
            let a = i as f32 * 0.618_034 * std::f32::consts::TAU;
            let origin = Vec3::new(4.0 * a.cos(), 0.3 * a.sin(), 4.0 * a.sin());
            let aim = Vec3::new(0.0, (i % 7) as f32 * 0.1 - 0.3, 0.0);
            let ray = Ray::new(origin, aim - origin);
            plain += sphere_trace(&sdf, &ray, &p).steps() as u64;
            relaxed += sphere_trace_relaxed(&sdf, &ray, &p, OVER_RELAXATION).steps() as u64;
        }
        assert!(relaxed < plain, "relaxed {relaxed} >= plain {plain} steps");
    }
}

/// The conformance runs cover every primitive: each kind's generators make shapes of that
/// kind (so no run tests another primitive twice), and the list holds each kind once.
#[test]
fn every_primitive_kind_has_its_conformance_run() {
    use proptest::strategy::ValueTree;
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    for (i, &kind) in KINDS.iter().enumerate() {
        assert!(!KINDS[..i].contains(&kind), "{kind:?} listed twice");
        for generator in [unit_primitive_of(kind), primitive_of(kind)] {
            for _ in 0..8 {
                let shape = generator.new_tree(&mut runner).unwrap().current();
                // Through the transforms the generators put around a primitive.
                let mut node = &shape;
                while let Sdf::Translate { child, .. }
                | Sdf::Rotate { child, .. }
                | Sdf::Scale { child, .. } = node
                {
                    node = child;
                }
                assert_eq!(kind_of(node), Some(kind), "{shape:?}");
            }
        }
    }
}
