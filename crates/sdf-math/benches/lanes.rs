//! Points per second of the lane paths: a few representative fields, prepared as the
//! tracer prepares objects, evaluated at 4096 points on every path this CPU has, so that
//! each path reads as a ratio to `Scalar` in one run; and rays per second of the stream
//! tracer on the same fields, against `sphere_trace` one ray at a time, and of the relaxed
//! march in groups (a vector of rays marched to its last ray's end, no refill).
//!
//! `cargo bench -p lueur-sdf-math --bench lanes`; the first line says which CPU features
//! the run had.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use lueur_sdf_math::{
    LaneDistance, OVER_RELAXATION, PreparedSdf, Quat, Ray, Sdf, SimdLevel, TraceOutcome,
    TraceParams, UnavailableLevel, Vec3, sphere_trace, sphere_trace_relaxed,
    sphere_trace_relaxed_groups_at, sphere_trace_relaxed_stream_at, sphere_trace_stream_at,
};

const POINTS: usize = 4096;

fn fields() -> Vec<(&'static str, PreparedSdf)> {
    let moved_round_box = Sdf::round_box(Vec3::new(0.6, 0.3, 0.4), 0.1)
        .rotate(Quat::from_rotation_y(0.7))
        .translate(Vec3::new(0.2, -0.1, 0.3));
    let spheres = (0..8)
        .map(|i| {
            let a = i as f32 * std::f32::consts::FRAC_PI_4;
            Sdf::sphere(0.3).translate(Vec3::new(a.cos(), 0.2 * i as f32 - 0.7, a.sin()))
        })
        .collect();
    [
        ("moved_round_box", moved_round_box),
        ("torus", Sdf::torus(1.0, 0.25)),
        ("death_star", Sdf::death_star(1.0, 0.7, 1.1)),
        ("union_of_8_spheres", Sdf::union(spheres)),
    ]
    .into_iter()
    .map(|(name, sdf)| (name, PreparedSdf::new(&sdf)))
    .collect()
}

/// Points spread over `[-2, 2]^3` by a fixed linear congruential sequence.
fn points() -> [Vec<f32>; 3] {
    let mut state = 0x2545_f491_u32;
    let mut next = move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 24) as f32 * 4.0 - 2.0
    };
    let mut coords = [vec![], vec![], vec![]];
    for _ in 0..POINTS {
        for c in &mut coords {
            c.push(next());
        }
    }
    coords
}

fn cpu_features() -> String {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    {
        let mut have = vec![];
        macro_rules! probe {
            ($($f:tt),*) => {$(
                if std::arch::is_x86_feature_detected!($f) {
                    have.push($f);
                }
            )*};
        }
        probe!(
            "sse4.2", "avx", "avx2", "fma", "avx512f", "avx512bw", "avx512dq", "avx512vl"
        );
        have.join(" ")
    }
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    {
        std::env::consts::ARCH.to_string()
    }
}

fn lanes(c: &mut Criterion) {
    println!(
        "CPU features: {}; lane paths: {:?}; detected: {:?}",
        cpu_features(),
        SimdLevel::available(),
        SimdLevel::detect()
    );
    let [xs, ys, zs] = points();
    let mut out = vec![0.0; POINTS];
    for (name, field) in fields() {
        let mut group = c.benchmark_group(format!("lanes/{name}"));
        group.throughput(Throughput::Elements(POINTS as u64));
        for level in SimdLevel::available() {
            group.bench_function(BenchmarkId::from_parameter(format!("{level:?}")), |b| {
                b.iter(|| {
                    field
                        .distance_batch_at(level, black_box(&xs), &ys, &zs, &mut out)
                        .unwrap();
                    black_box(&out);
                })
            });
        }
        group.finish();
    }
}

/// 4096 rays from a sphere of radius 4 toward points near the origin (most hit, some
/// graze or miss), with the parameters a secondary ray gets.
fn rays() -> (Vec<Ray>, Vec<TraceParams>) {
    let [xs, ys, zs] = points();
    let rays: Vec<Ray> = (0..POINTS)
        .map(|i| {
            let j = (i * 7 + 3) % POINTS;
            let origin = Vec3::new(xs[i], ys[i], zs[i]).normalize_or(Vec3::X) * 4.0;
            let aim = Vec3::new(xs[j], ys[j], zs[j]) * 0.5;
            Ray::new(origin, (aim - origin).normalize())
        })
        .collect();
    let params = vec![TraceParams::default(); POINTS];
    (rays, params)
}

fn stream(c: &mut Criterion) {
    let (rays, params) = rays();
    let mut out = vec![TraceOutcome::Miss { steps: 0 }; POINTS];
    for (name, field) in fields() {
        let mut group = c.benchmark_group(format!("stream/{name}"));
        group.throughput(Throughput::Elements(POINTS as u64));
        group.bench_function(BenchmarkId::from_parameter("sphere_trace"), |b| {
            b.iter(|| {
                for ((ray, p), o) in rays.iter().zip(&params).zip(out.iter_mut()) {
                    *o = sphere_trace(&field, black_box(ray), p);
                }
                black_box(&out);
            })
        });
        for level in SimdLevel::available() {
            group.bench_function(BenchmarkId::from_parameter(format!("{level:?}")), |b| {
                b.iter(|| {
                    sphere_trace_stream_at(level, &field, black_box(&rays), &params, &mut out)
                        .unwrap();
                    black_box(&out);
                })
            });
        }
        group.bench_function(BenchmarkId::from_parameter("sphere_trace_relaxed"), |b| {
            b.iter(|| {
                for ((ray, p), o) in rays.iter().zip(&params).zip(out.iter_mut()) {
                    *o = sphere_trace_relaxed(&field, black_box(ray), p, OVER_RELAXATION);
                }
                black_box(&out);
            })
        });
        type March = fn(
            SimdLevel,
            &PreparedSdf,
            &[Ray],
            &[TraceParams],
            f32,
            &mut [TraceOutcome],
        ) -> Result<(), UnavailableLevel>;
        let marches: [(&str, March); 2] = [
            ("relaxed", sphere_trace_relaxed_stream_at),
            ("relaxed groups", sphere_trace_relaxed_groups_at),
        ];
        for (kind, march) in marches {
            for level in SimdLevel::available() {
                let id = format!("{kind} {level:?}");
                group.bench_function(BenchmarkId::from_parameter(id), |b| {
                    b.iter(|| {
                        let rays = black_box(&rays);
                        march(level, &field, rays, &params, OVER_RELAXATION, &mut out).unwrap();
                        black_box(&out);
                    })
                });
            }
        }
        group.finish();
    }
}

criterion_group!(benches, lanes, stream);
criterion_main!(benches);
