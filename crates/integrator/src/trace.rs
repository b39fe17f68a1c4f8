//! Tracing: where a ray first meets an object or a light, whether a shadow
//! ray is free, and the counters and timing of every ray traced.

use std::time::Instant;

use glam::Vec3;

use lueur_sdf_math::{DistanceField, Ray, TraceOutcome, TraceParams, sphere_trace};

use lueur_scene::Marching;

use crate::PreparedScene;

/// What a ray found first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hit {
    /// An object's surface at distance `t`.
    Surface {
        /// Ray parameter.
        t: f32,
        /// Index into `Scene::objects`.
        object: usize,
        /// How thick the shell the tracer stopped in is: the hit threshold in
        /// force at that distance, or, for a ray that gave up at the step cap,
        /// the field's value where it stopped if that is larger. The hit lies
        /// within it of the surface.
        epsilon: f32,
        /// Whether the ray was marched inside the solid, so that it meets the
        /// surface from inside whatever the sign of a normal estimated at a
        /// grazing hit.
        inside: bool,
    },
    /// A light's surface at distance `t`.
    Light {
        /// Ray parameter.
        t: f32,
        /// Index into `Scene::lights`.
        light: usize,
    },
}

/// Counters of one trace, for statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraceCounters {
    /// Rays traced.
    pub rays: u64,
    /// Scene evaluations (sphere-tracing steps).
    pub steps: u64,
    /// Rays that hit a surface.
    pub hits: u64,
    /// Rays that escaped.
    pub misses: u64,
    /// Rays stopped by the step cap, taken as hits where they stopped.
    pub gave_up: u64,
    /// Rays by steps taken, in powers of two: bucket `i` counts rays of
    /// `2^i ..= 2^(i+1) - 1` steps (bucket 0 also counts rays of 0 steps,
    /// the last one every ray of 512 steps or more).
    pub steps_histogram: [u64; STEP_BUCKETS],
    /// Rays whose tracing was timed: one in [`TIMED_EVERY`], so that the
    /// clock (tens of nanoseconds a reading) costs well under 1% of a render.
    pub timed_rays: u64,
    /// Wall time spent tracing the timed rays (bounds, marching, lights), in
    /// nanoseconds. Never affects the image.
    pub timed_nanos: u64,
}

/// One ray in this many is timed (see [`TraceCounters::timed_nanos`]); a
/// power of two.
pub const TIMED_EVERY: u64 = 16;

/// Buckets of [`TraceCounters::steps_histogram`].
pub const STEP_BUCKETS: usize = 10;

impl TraceCounters {
    fn record(&mut self, outcome: &TraceOutcome) {
        self.rays += 1;
        let steps = outcome.steps() as u64;
        self.steps += steps;
        let bucket = (u64::BITS - 1).saturating_sub(steps.max(1).leading_zeros()) as usize;
        self.steps_histogram[bucket.min(STEP_BUCKETS - 1)] += 1;
        match outcome {
            TraceOutcome::Hit { .. } => self.hits += 1,
            TraceOutcome::Miss { .. } => self.misses += 1,
            TraceOutcome::GaveUp { .. } => self.gave_up += 1,
        }
    }

    /// Estimated wall time spent tracing every ray: the timed rays' time
    /// scaled by the share they are of all rays.
    pub fn tracing_seconds(&self) -> f64 {
        if self.timed_rays == 0 {
            return 0.0;
        }
        self.timed_nanos as f64 * 1e-9 * self.rays as f64 / self.timed_rays as f64
    }

    /// Starts the clock if this ray is one of the timed ones (decided by
    /// the ray count, so deterministically and evenly spread).
    #[inline]
    fn clock(&self) -> Option<Instant> {
        // A mask, not `is_multiple_of` (Rust 1.87; the workspace supports 1.85).
        (self.rays & (TIMED_EVERY - 1) == 0).then(Instant::now)
    }

    #[inline]
    fn stop(&mut self, clock: Option<Instant>) {
        if let Some(start) = clock {
            self.timed_rays += 1;
            self.timed_nanos += start.elapsed().as_nanos() as u64;
        }
    }

    /// Adds another set of counters.
    pub fn merge(&mut self, o: &TraceCounters) {
        self.rays += o.rays;
        self.timed_rays += o.timed_rays;
        self.timed_nanos += o.timed_nanos;
        self.steps += o.steps;
        self.hits += o.hits;
        self.misses += o.misses;
        self.gave_up += o.gave_up;
        for (a, b) in self.steps_histogram.iter_mut().zip(&o.steps_histogram) {
            *a += b;
        }
    }
}

impl PreparedScene {
    /// Finds the first object or light along `ray`.
    pub fn intersect(
        &self,
        ray: &Ray,
        params: &TraceParams,
        marching: Marching,
        counters: &mut TraceCounters,
    ) -> Option<Hit> {
        self.intersect_leaving(ray, ray.origin, params, marching, counters, false)
    }

    /// [`PreparedScene::intersect`] for a ray that may start inside a solid: a
    /// camera ray, or a ray leaving a surface that was shaded on its inside.
    /// If its origin is below a surface (not merely in its shell), the ray
    /// is marched by the negated field to the wall it leaves through, so
    /// that a camera inside an object sees the inner wall and paths there
    /// stay inside. Costs one field evaluation.
    ///
    /// Other rays never do this: a secondary origin a hair under a surface
    /// is rounding, which the projection at the next vertex repairs.
    pub fn intersect_maybe_inside(
        &self,
        ray: &Ray,
        params: &TraceParams,
        marching: Marching,
        counters: &mut TraceCounters,
    ) -> Option<Hit> {
        self.intersect_leaving(ray, ray.origin, params, marching, counters, true)
    }

    /// [`PreparedScene::intersect`] (or, with `maybe_inside`, [`PreparedScene::intersect_maybe_inside`])
    /// for a ray leaving the surface point `from`: the objects are marched from
    /// `ray.origin`, lifted off the surface so that the march does not stop on it at once,
    /// but the lights, which are exact, are intersected from `from` itself. So a light is
    /// seen under the solid angle it has from the point that was shaded, the one next-event
    /// estimation and the MIS weights use, however far the origin had to be lifted; light
    /// hits' `t` are measured from `from`.
    pub(crate) fn intersect_leaving(
        &self,
        ray: &Ray,
        from: Vec3,
        params: &TraceParams,
        marching: Marching,
        counters: &mut TraceCounters,
        maybe_inside: bool,
    ) -> Option<Hit> {
        let clock = counters.clock();
        let params = params.resolving(ray.origin);
        let light_ray = Ray {
            origin: from,
            dir: ray.dir,
        };
        let light_hit = self.intersect_lights(&light_ray, params.t_max, None);
        let t_max = light_hit.map_or(params.t_max, |(t, _)| t);
        let mut surface = None;
        if !self.scene().objects.is_empty() {
            let p = TraceParams { t_max, ..params };
            let start = ray.at(p.t_min);
            let inside = maybe_inside
                && self.distance(start, marching) < -p.eps_abs.max(p.eps_rel * p.t_min);
            let (outcome, object) = if inside {
                (sphere_trace(&self.geometry.inside(), ray, &p), None)
            } else {
                self.geometry.trace(ray, &p, marching)
            };
            counters.record(&outcome);
            let (t_hit, gave_up) = match outcome {
                // A ray that reaches the step cap without a decision is crawling along a
                // surface it is about to meet (inside a closed solid, its wall), so it
                // stops where it is. Measured on the shipped scenes against a cap 64 times
                // higher (`cargo xtask scale`, docs/SCALE.md): this changes the Death
                // Star's image mean by -0.002%, taking it as a miss by -0.23% (it sees the
                // sky through a wall) and ending the path by -0.37%.
                TraceOutcome::GaveUp { t, steps } if steps > 0 => (Some(t), true),
                _ => (outcome.hit_t(), false),
            };
            if let Some(t) = t_hit {
                let object = object.unwrap_or_else(|| self.closest_object(ray.at(t)));
                let mut epsilon = p.eps_abs.max(p.eps_rel * t);
                if gave_up {
                    // One evaluation, on the rare ray that gave up: where it stopped
                    // may be farther from the surface than a hit threshold.
                    let f = self.geometry.prepared(object).distance(ray.at(t)).abs();
                    if f.is_finite() {
                        epsilon = epsilon.max(f);
                    }
                }
                surface = Some(Hit::Surface {
                    t,
                    object,
                    epsilon,
                    inside,
                });
            }
        } else {
            counters.rays += 1;
        }
        counters.stop(clock);
        surface.or(light_hit.map(|(t, light)| Hit::Light { t, light }))
    }

    /// Whether the segment from `ray.origin` along `ray.dir` is free of
    /// objects and of lights other than `target` up to `distance`.
    pub(crate) fn unoccluded(
        &self,
        ray: &Ray,
        distance: f32,
        target: Option<usize>,
        params: &TraceParams,
        marching: Marching,
        counters: &mut TraceCounters,
    ) -> bool {
        let clock = counters.clock();
        let params = &params.resolving(ray.origin);
        let free = 'free: {
            // Stop short of the light's surface so that its own geometry (for
            // lights that are objects too) does not occlude it.
            let t_max = (distance * (1.0 - 1e-4) - params.eps_abs).min(params.t_max);
            if let Some((_, l)) = self.intersect_lights(ray, t_max, target)
                && Some(l) != target
            {
                break 'free false;
            }
            if self.scene().objects.is_empty() || t_max <= params.t_min {
                break 'free true;
            }
            let (outcome, _) =
                self.geometry
                    .trace(ray, &TraceParams { t_max, ..*params }, marching);
            counters.record(&outcome);
            // A shadow ray that gives up is taken as a hit too (see `intersect_leaving`).
            matches!(outcome, TraceOutcome::Miss { .. })
        };
        counters.stop(clock);
        free
    }

    fn intersect_lights(&self, ray: &Ray, t_max: f32, skip: Option<usize>) -> Option<(f32, usize)> {
        let mut best: Option<(f32, usize)> = None;
        for (i, l) in self.scene().lights.iter().enumerate() {
            if Some(i) == skip {
                continue;
            }
            let t = l.intersect(ray);
            if let Some(t) = t
                && t < t_max
                && best.is_none_or(|(bt, _)| t < bt)
            {
                best = Some((t, i));
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::tests::{crowd, points};
    use lueur_materials::Material;
    use lueur_scene::{Camera, Scene};

    /// [`crate::geometry::tests::crowd`] as a scene.
    fn crowd_scene() -> PreparedScene {
        let camera = Camera::new(Vec3::new(0.0, 0.5, 6.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap();
        let white = Material::Lambertian { albedo: Vec3::ONE };
        Scene::new(crowd(), vec![white], vec![], None, camera)
            .unwrap()
            .into()
    }

    #[test]
    fn fast_marching_finds_the_naive_hits() {
        let scene = crowd_scene();
        let params = TraceParams {
            t_max: 200.0,
            max_steps: 100_000,
            eps_abs: 1e-6,
            eps_rel: 1e-5,
            ..TraceParams::default()
        };
        let (mut naive_steps, mut fast_steps) =
            (TraceCounters::default(), TraceCounters::default());
        for (i, p) in points().enumerate() {
            let origin = Vec3::new(0.0, 0.5, 6.0) + Vec3::Y * (i % 3) as f32;
            let ray = Ray::new(origin, p * 0.1 - origin);
            let a = scene.intersect(&ray, &params, Marching::Naive, &mut naive_steps);
            let b = scene.intersect(&ray, &params, Marching::Fast, &mut fast_steps);
            match (a, b) {
                (None, None) => {}
                (
                    Some(Hit::Surface {
                        t: ta, object: oa, ..
                    }),
                    Some(Hit::Surface {
                        t: tb, object: ob, ..
                    }),
                ) => {
                    assert_eq!(oa, ob, "ray {ray:?}: objects {oa} and {ob} at {ta}, {tb}");
                    assert!(
                        (ta - tb).abs() <= 1e-3 * ta,
                        "ray {ray:?}: naive {ta}, fast {tb}"
                    );
                }
                _ => panic!("ray {ray:?}: naive {a:?}, fast {b:?}"),
            }
        }
        assert!(fast_steps.steps < naive_steps.steps);
    }
}
