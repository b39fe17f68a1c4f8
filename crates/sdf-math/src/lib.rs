//! Signed distance functions (SDFs) and sphere tracing: the geometry of lueur.
//!
//! The primary type is [`Sdf`], a closed enum tree of primitives, CSG operators, smooth
//! blends and rigid transforms. The design decision that shapes the crate: a scene's
//! geometry is a *value* evaluated by `match`, never a trait object, so the hot loop of the
//! tracer has no virtual calls and no allocation. Anything else that wants to be traced
//! implements the two-method [`DistanceField`] trait. The tree's leaves are
//! [`Primitive`]s, each with its distance, Lipschitz bound, exactness and bounds in one
//! place; the operators and transforms delegate to them and never name one.
//!
//! Around the tree: bounds a tracer can clip rays against before marching them
//! ([`Sdf::bounding_box`], [`Sdf::bounding_half_space`], with [`RayClip`] giving the
//! range of a ray where a hit is possible, without square roots), and [`PreparedSdf`], the same field with its
//! transforms folded into one affine map for hot loops.
//!
//! Contract: **every `Sdf` is Lipschitz with the bound it reports**,
//! `|f(p) - f(q)| <= lipschitz() * |p - q|`, for every finite parameter value. That is
//! what makes [`sphere_trace`] (Hart 1996) safe. Where a node's value is also the exact
//! Euclidean distance, [`Sdf::is_exact`] says so; elsewhere it is only a bound.
//!
//! What this crate deliberately is not: no materials, no lights, no cameras, no I/O and no
//! printing. It never panics on finite input and uses `f32` throughout (glam [`Vec3`],
//! [`Quat`]). Its `unsafe`, the workspace's only, makes pulp's AVX2 and AVX-512 tokens
//! without a check the dispatch has already made (`lanes/x86.rs` argues why). Formulas follow Inigo Quilez's articles at iquilezles.org
//! ("distfunctions", "smin", "normalsSDF") and Hart's "Sphere tracing" (1996).
//!
//! Tracing a ray against a torus, with no integrator in sight:
//!
//! ```
//! use lueur_sdf_math::{normal, sphere_trace, Ray, Sdf, TraceParams, Vec3};
//!
//! // A ring of radius 1 in the XZ plane, tube radius 0.25.
//! let torus = Sdf::torus(1.0, 0.25);
//! // Straight down onto the tube at x = 1: its top is at y = 0.25.
//! let ray = Ray::new(Vec3::new(1.0, 5.0, 0.0), Vec3::NEG_Y);
//! let outcome = sphere_trace(&torus, &ray, &TraceParams::default());
//! let t = outcome.hit_t().expect("the ray points at the tube");
//! assert!((t - 4.75).abs() < 1e-3);
//! assert!(outcome.steps() < 10);
//!
//! let n = normal(&torus, ray.at(t), 1e-4);
//! assert!((n - Vec3::Y).length() < 1e-3);
//!
//! // Down the axis, through the hole: nothing there.
//! let through = Ray::new(Vec3::new(0.0, 5.0, 0.0), Vec3::NEG_Y);
//! assert_eq!(sphere_trace(&torus, &through, &TraceParams::default()).hit_t(), None);
//! ```
#![deny(missing_docs)]

mod blend;
mod bound;
mod field;
mod group;
mod lanes;
mod normal;
mod prepared;
mod primitives;
mod ray;
mod relaxed;
mod sdf;
mod sdf_bounds;
mod stream;
mod trace;

pub use glam::{Quat, Vec3};

pub use crate::blend::{smooth_max, smooth_min};
pub use crate::bound::{Aabb, BoundingSphere, HalfSpace, RayClip, RayClipLanes};
pub use crate::field::DistanceField;
pub use crate::group::{
    GroupEnds, GroupField, GroupRays, sphere_trace_relaxed_group, sphere_trace_relaxed_groups_at,
};
pub use crate::lanes::{
    Avx2, Avx512, BitMask, Isa, Lane, LaneDistance, LaneKernel, LaneMask, LaneVec3, Mask, MaskLane,
    Neon, Portable, SimdLevel, Sse, Task, UnavailableLevel, Wide,
};
pub use crate::normal::{
    Central, FALLBACK_NORMAL, Tetrahedron, gradient, gradient_central, gradient_lanes, normal,
    normal_central,
};
pub use crate::prepared::PreparedSdf;
pub use crate::primitives::Primitive;
pub use crate::ray::Ray;
pub use crate::sdf::Sdf;
pub use crate::stream::{
    LaneGroups, MAX_LANES, StreamField, fill_lane_groups, sphere_trace_relaxed_stream,
    sphere_trace_relaxed_stream_at, sphere_trace_relaxed_stream_of, sphere_trace_stream,
    sphere_trace_stream_at, write_lane,
};
pub use crate::trace::{
    HIT_ULPS, OVER_RELAXATION, TraceOutcome, TraceParams, position_rounding,
    position_rounding_lanes, resolving_lanes, sphere_trace, sphere_trace_relaxed,
};
