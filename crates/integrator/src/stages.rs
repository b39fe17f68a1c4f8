//! Where a wave of paths spends its time: the clock, read between the stages of
//! [`crate::path`]'s wave, adds each stage's thread time to a [`StageTimes`]. It is read
//! about ten times per vertex of a wave of hundreds of paths, tens of nanoseconds a reading,
//! and never affects the image.

use std::time::Instant;

/// A stage of the wave, in the order a vertex goes through them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Paths started in vacant slots (each sample's point in the pixel, its camera ray and
    /// its copy of the sampler), and every path's next ray gathered for the stream.
    StartPaths,
    /// The paths' rays traced as one stream: light tests, clipping, marching.
    PathRays,
    /// The shading points of the hits, a vector of hits at a time per object.
    ShadingPoints,
    /// Emission found on a miss or a light, and each vertex's numbers and requests for
    /// light and BSDF samples.
    VertexNumbers,
    /// The light and BSDF samples the vertices asked for, drawn as batches in lanes.
    Draws,
    /// Each vertex shaded: next-event estimation and the direction it scatters in.
    Shading,
    /// The shadow rays traced as one stream.
    ShadowRays,
    /// What each vertex's shadow rays bring, its scattering and Russian roulette.
    Scattering,
    /// Finished estimates handed on, in order, to the tile.
    Estimates,
}

impl Stage {
    /// Every stage, in order.
    pub const ALL: [Stage; 9] = [
        Stage::StartPaths,
        Stage::PathRays,
        Stage::ShadingPoints,
        Stage::VertexNumbers,
        Stage::Draws,
        Stage::Shading,
        Stage::ShadowRays,
        Stage::Scattering,
        Stage::Estimates,
    ];

    /// The stage's name, as `--stats` prints it.
    pub fn name(self) -> &'static str {
        match self {
            Stage::StartPaths => "start paths",
            Stage::PathRays => "path rays",
            Stage::ShadingPoints => "shading points",
            Stage::VertexNumbers => "vertex numbers",
            Stage::Draws => "light and BSDF draws",
            Stage::Shading => "shading",
            Stage::ShadowRays => "shadow rays",
            Stage::Scattering => "scattering",
            Stage::Estimates => "estimates",
        }
    }
}

/// Thread time per [`Stage`], summed over threads. Never affects the image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StageTimes {
    nanos: [u64; Stage::ALL.len()],
}

impl StageTimes {
    /// The time spent in `stage`, in seconds.
    pub fn seconds(&self, stage: Stage) -> f64 {
        self.nanos[stage as usize] as f64 * 1e-9
    }

    /// The time spent in every stage, in seconds.
    pub fn total_seconds(&self) -> f64 {
        self.nanos.iter().sum::<u64>() as f64 * 1e-9
    }

    /// Adds another set of times.
    pub fn merge(&mut self, other: &StageTimes) {
        for (a, b) in self.nanos.iter_mut().zip(&other.nanos) {
            *a += b;
        }
    }
}

/// The clock between stages: each [`StageClock::lap`] adds the time since the last lap
/// (or the start) to a stage.
pub(crate) struct StageClock<'a> {
    times: &'a mut StageTimes,
    last: Instant,
}

impl<'a> StageClock<'a> {
    /// A clock that starts now.
    pub fn start(times: &'a mut StageTimes) -> StageClock<'a> {
        StageClock {
            times,
            last: Instant::now(),
        }
    }

    /// Ends `stage`: the time since the last lap is its.
    #[inline]
    pub fn lap(&mut self, stage: Stage) {
        let now = Instant::now();
        self.times.nanos[stage as usize] += (now - self.last).as_nanos() as u64;
        self.last = now;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{PreparedScene, render};
    use glam::Vec3;
    use lueur_materials::Material;
    use lueur_scene::{Camera, Light, Object, RenderSettings, Scene, Strategy};
    use lueur_sdf_math::Sdf;

    /// A render under `mis` goes through every stage: each is timed, and together they
    /// take no more than the thread's time.
    #[test]
    fn every_stage_of_a_render_is_timed_within_its_time() {
        let camera = Camera::new(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 30.0).unwrap();
        let scene = Scene::new(
            vec![Object {
                sdf: Sdf::sphere(0.5),
                material: 0,
            }],
            vec![Material::Lambertian {
                albedo: Vec3::splat(0.5),
            }],
            vec![Light::Sphere {
                center: Vec3::new(0.0, 2.0, 1.0),
                radius: 0.3,
                radiance: Vec3::splat(5.0),
            }],
            Some(Vec3::splat(0.2)),
            camera,
        )
        .unwrap();
        let settings = RenderSettings {
            width: 16,
            height: 16,
            spp: 16,
            strategy: Strategy::Mis,
            ..Default::default()
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let out = pool.install(|| render(&PreparedScene::new(scene), &settings, &|_| {}).unwrap());
        let stages = &out.stats.stages;
        for stage in Stage::ALL {
            assert!(stages.seconds(stage) > 0.0, "{} not timed", stage.name());
        }
        let elapsed = out.stats.elapsed.as_secs_f64();
        assert!(
            stages.total_seconds() <= elapsed,
            "stages {} s in a render of {elapsed} s on one thread",
            stages.total_seconds()
        );
    }
}
