//! `cargo xtask scale`: does a small light's answer depend on how big the rest of the scene
//! is? A Lambertian floor (albedo 0.5) under a sphere light or a square quad light, with
//! the floor's half-extent from 1 to 10^4, an unbounded plane with one object 2000 away,
//! and the same scenes scaled by 1e-3 and 1e3 and moved 1e4 from the origin. The camera
//! sees a small patch right below the light, where the closed form holds; every
//! strategy's patch mean is compared with it. Then how far that holds (floors to 1e7, the
//! scene moved to 1e6), thin features far from their own frame (a mirror tube on rings of
//! radius 1 to 1e4), a floor seen at grazing angles out to the horizon, and what giving up
//! at the step cap costs. Writes docs/SCALE.md.

use std::fmt::Write as _;

use anyhow::{Context, Result};
use lueur::sampling::SamplerKind;
use lueur::scene::parse_scene;
use lueur::scene::{Marching, RenderSettings, Strategy};

use crate::{docs_dir, load_scene, render_with_bar};
use lueur::integrator::{PreparedScene, RenderStats, render};

/// The floor's albedo, the lights' radiance, and where they are (issue 14's scene).
const ALBEDO: f64 = 0.5;
const RADIANCE: f64 = 16.0;
const HEIGHT: f64 = 1.0;
const SPHERE_RADIUS: f64 = 0.25;
/// Half the side of the square light.
const QUAD_HALF: f64 = 0.25;

#[derive(Clone, Copy, PartialEq)]
enum LightKind {
    Sphere,
    Quad,
}

impl LightKind {
    fn name(self) -> &'static str {
        match self {
            LightKind::Sphere => "sphere",
            LightKind::Quad => "quad",
        }
    }

    /// Radiance leaving the floor right below the light, in closed form.
    fn expected(self) -> f64 {
        match self {
            // Irradiance pi L sin^2(theta) with sin(theta) = r / h, times albedo / pi.
            LightKind::Sphere => ALBEDO * RADIANCE * SPHERE_RADIUS.powi(2) / HEIGHT.powi(2),
            // The view factor to a parallel square of side 2a at height c, four quadrants
            // (Howell's catalogue, B-3), as in tests/analytic.rs.
            LightKind::Quad => {
                let x = QUAD_HALF / HEIGHT;
                let s = (1.0 + x * x).sqrt();
                let f = 4.0 / (2.0 * std::f64::consts::PI) * 2.0 * (x / s * (x / s).atan());
                ALBEDO * RADIANCE * f
            }
        }
    }
}

/// What lies under the light.
#[derive(Clone, Copy)]
enum Ground {
    /// A box 0.1 thick whose top face is the floor, of this half-extent.
    Floor(f64),
    /// An unbounded plane, and a unit sphere 2000 away.
    PlaneAndFarObject,
}

impl Ground {
    fn label(self) -> String {
        match self {
            Ground::Floor(h) => format!("floor half-extent {h}"),
            Ground::PlaneAndFarObject => "plane + object 2000 away".into(),
        }
    }
}

/// `p -> scale p + offset`, applied to every position and length.
#[derive(Clone, Copy)]
struct Frame {
    scale: f64,
    offset: f64,
    label: &'static str,
}

const FRAMES: [Frame; 4] = [
    Frame {
        scale: 1.0,
        offset: 0.0,
        label: "as is",
    },
    Frame {
        scale: 1e-3,
        offset: 0.0,
        label: "scaled 1e-3",
    },
    Frame {
        scale: 1e3,
        offset: 0.0,
        label: "scaled 1e3",
    },
    Frame {
        scale: 1.0,
        // 1e4 from the origin along the diagonal.
        offset: 1e4 / 1.732_050_8,
        label: "moved 1e4",
    },
];

impl Frame {
    fn point(&self, x: f64, y: f64, z: f64) -> String {
        let f = |v: f64| v * self.scale + self.offset;
        format!("[{:e}, {:e}, {:e}]", f(x), f(y), f(z))
    }

    fn vector(&self, x: f64, y: f64, z: f64) -> String {
        let f = |v: f64| v * self.scale;
        format!("[{:e}, {:e}, {:e}]", f(x), f(y), f(z))
    }
}

/// The scene's text: the floor's top at y = 0, the light above the origin, a camera with
/// a field of view of 0.05 degrees looking at the origin from 3.2 away.
fn scene_text(light: LightKind, ground: Ground, frame: Frame) -> String {
    let ground = match ground {
        Ground::Floor(h) => format!(
            "[[objects]]\nmaterial = \"floor\"\nshape = {{ type = \"box\", center = {}, half_extents = {} }}\n",
            frame.point(0.0, -0.05, 0.0),
            frame.vector(h, 0.05, h),
        ),
        Ground::PlaneAndFarObject => {
            // The plane y = offset, through the frame's image of the origin.
            let height = frame.offset;
            format!(
                "[[objects]]\nmaterial = \"floor\"\nshape = {{ type = \"plane\", normal = [0.0, 1.0, 0.0], height = {height:e} }}\n\
                 [[objects]]\nmaterial = \"floor\"\nshape = {{ type = \"sphere\", center = {}, radius = {:e} }}\n",
                frame.point(2000.0, 1.0, 0.0),
                frame.scale,
            )
        }
    };
    let light = match light {
        LightKind::Sphere => format!(
            "[[lights]]\ntype = \"sphere\"\ncenter = {}\nradius = {:e}\nradiance = [{RADIANCE}, {RADIANCE}, {RADIANCE}]\n",
            frame.point(0.0, HEIGHT, 0.0),
            SPHERE_RADIUS * frame.scale,
        ),
        LightKind::Quad => format!(
            "[[lights]]\ntype = \"quad\"\ncorner = {}\nedge_u = {}\nedge_v = {}\nradiance = [{RADIANCE}, {RADIANCE}, {RADIANCE}]\n",
            frame.point(-QUAD_HALF, HEIGHT, -QUAD_HALF),
            // edge_u x edge_v points down: the side that emits.
            frame.vector(2.0 * QUAD_HALF, 0.0, 0.0),
            frame.vector(0.0, 0.0, 2.0 * QUAD_HALF),
        ),
    };
    format!(
        "[camera]\nposition = {}\nlook_at = {}\nvfov = 0.05\n\
         [materials]\nfloor = {{ type = \"lambertian\", albedo = [{ALBEDO}, {ALBEDO}, {ALBEDO}] }}\n\
         {ground}{light}",
        frame.point(0.0, 1.0, 3.0),
        frame.point(0.0, 0.0, 0.0),
    )
}

/// One measurement: the patch's mean radiance (green channel) and its standard error.
struct Measured {
    mean: f64,
    stderr: f64,
}

fn measure(
    light: LightKind,
    ground: Ground,
    frame: Frame,
    strategy: Strategy,
    spp: u32,
) -> Result<Measured> {
    let text = scene_text(light, ground, frame);
    let file = parse_scene(&text, "scale.toml").context("the generated scene")?;
    let settings = RenderSettings {
        width: 8,
        height: 8,
        spp,
        strategy,
        sampler: SamplerKind::Independent,
        max_depth: 1,
        seed: 14,
        ..file.settings.clone()
    };
    let label = format!("{} {} {strategy}", light.name(), ground.label());
    let film = render_with_bar(&file.scene, &settings, &label)?;
    // One channel: the three are the same numbers here, so averaging them would claim a
    // standard error sqrt(3) too small.
    let n = film.pixels().len() as f64;
    let mean = film.pixels().map(|p| f64::from(p.mean.y)).sum::<f64>() / n;
    let var = film
        .pixels()
        .map(|p| f64::from(p.variance_of_mean().y))
        .sum::<f64>()
        / (n * n);
    Ok(Measured {
        mean,
        stderr: var.sqrt(),
    })
}

const STRATEGIES: [Strategy; 5] = [
    Strategy::Uniform,
    Strategy::Cosine,
    Strategy::Light,
    Strategy::Mixture,
    Strategy::Mis,
];

/// One row: every strategy's relative error (and z) on one scene.
fn row(out: &mut String, label: &str, light: LightKind, cases: &[Measured]) {
    let expected = light.expected();
    let cells: Vec<String> = cases
        .iter()
        .map(|m| {
            let rel = (m.mean - expected) / expected;
            if m.stderr > 0.0 {
                let z = (m.mean - expected) / m.stderr;
                format!("{:+.2}% (z {:+.1})", 100.0 * rel, z)
            } else {
                format!("{:+.2}% (no variance)", 100.0 * rel)
            }
        })
        .collect();
    let _ = writeln!(out, "| {label} | {} |", cells.join(" | "));
}

pub fn run(quick: bool) -> Result<()> {
    let spp = if quick { 1024 } else { 16384 };
    let sizes: &[f64] = if quick {
        &[1.0, 1000.0]
    } else {
        &[1.0, 10.0, 100.0, 1000.0, 10000.0]
    };
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Scale-free tracing\n\nGenerated by `cargo xtask scale`. A Lambertian floor \
         (albedo {ALBEDO}) under a light of radiance {RADIANCE} at height {HEIGHT} (a sphere of \
         radius {SPHERE_RADIUS}, or a square of side {}), `max_depth = 1`, 8x8 pixels of a \
         0.05-degree camera looking at the point below the light, {spp} spp, independent \
         samples, seed 14. Each cell is the patch mean's relative error against the closed \
         form, and its z-score (green channel). `light` sees everything at depth 1, so every \
         strategy is unbiased here.\n",
        2.0 * QUAD_HALF
    );
    let header = format!(
        "| scene | {} |\n|---|{}",
        STRATEGIES.map(|s| s.to_string()).join(" | "),
        "---|".repeat(STRATEGIES.len())
    );
    for light in [LightKind::Sphere, LightKind::Quad] {
        let _ = writeln!(
            out,
            "## {} light (closed form {:.5})\n\n{header}",
            light.name(),
            light.expected()
        );
        let mut grounds: Vec<Ground> = sizes.iter().map(|&h| Ground::Floor(h)).collect();
        grounds.push(Ground::PlaneAndFarObject);
        for ground in grounds {
            let frames: &[Frame] = if quick { &FRAMES[..1] } else { &FRAMES };
            for frame in frames {
                let cases = STRATEGIES
                    .iter()
                    .map(|&s| measure(light, ground, *frame, s, spp))
                    .collect::<Result<Vec<_>>>()?;
                let label = format!("{}, {}", ground.label(), frame.label);
                row(&mut out, &label, light, &cases);
            }
        }
        out.push('\n');
    }
    if !quick {
        range(&mut out, spp)?;
    }
    curved(&mut out, quick)?;
    horizon(&mut out, quick)?;
    give_ups(&mut out, quick)?;
    let dir = docs_dir(quick);
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("SCALE.md");
    std::fs::write(&path, &out).with_context(|| format!("writing {}", path.display()))?;
    print!("{out}");
    println!("wrote {}", path.display());
    Ok(())
}

/// How far the answer holds: floors far larger than the light's height, and the scene far
/// from the origin (where f32 positions are coarse), for `cosine` (BSDF sampling only)
/// and `mis`, sphere light.
fn range(out: &mut String, spp: u32) -> Result<()> {
    let _ = writeln!(
        out,
        "## Range\n\nThe sphere light's scene beyond the tested range: floors up to 1e7 \
         times the light's height, and the whole scene moved up to 1e6 from the origin \
         (along the diagonal; the spacing of f32 positions there is in the second column).\n\n\
         | scene | f32 spacing | cosine | mis |\n|---|---|---|---|"
    );
    let light = LightKind::Sphere;
    let cases: Vec<(Ground, Frame, String)> = [1e5, 1e6, 1e7]
        .into_iter()
        .map(|h| {
            (
                Ground::Floor(h),
                FRAMES[0],
                format!("floor half-extent {h:e}"),
            )
        })
        .chain([3e4, 1e5, 3e5, 1e6].into_iter().map(|d: f64| {
            let frame = Frame {
                scale: 1.0,
                offset: d / 1.732_050_8,
                label: "moved",
            };
            (Ground::Floor(10.0), frame, format!("floor 10, moved {d:e}"))
        }))
        .collect();
    for (ground, frame, label) in cases {
        let spacing = f64::from(f32::EPSILON) * (frame.offset.abs() + 1.0);
        let cells = [Strategy::Cosine, Strategy::Mis]
            .into_iter()
            .map(|s| {
                let m = measure(light, ground, frame, s, spp)?;
                let rel = (m.mean - light.expected()) / light.expected();
                Ok(format!("{:+.2}%", 100.0 * rel))
            })
            .collect::<Result<Vec<_>>>()?;
        let _ = writeln!(out, "| {label} | {spacing:.1e} | {} |", cells.join(" | "));
    }
    out.push('\n');
    Ok(())
}

/// Thin features far from their own frame's origin, where the field rounds at the frame's
/// size and that sets the difference step of normals: a mirror tube 0.1 thick on rings of
/// radius 1 to 1e4 (the near side under the camera), against a straight tube of the same
/// thickness (a capsule 6 long, whose field rounds at its own size), under a small sphere
/// light. The scene is symmetric about x = 0, so the light's reflection is centred; on
/// large rings its energy tends to the straight tube's.
fn curved(out: &mut String, quick: bool) -> Result<()> {
    let (size, spp) = (128u32, if quick { 16 } else { 256 });
    let radii: &[f64] = if quick {
        &[1e3]
    } else {
        &[1.0, 10.0, 100.0, 1e3, 1e4]
    };
    let _ = writeln!(
        out,
        "## Thin features far from their frame\n\nA mirror tube 0.1 thick on a ring of \
         radius R (its near side where the camera looks, 3 away), under a \
         sphere light of radius 0.1 above it; {size}x{size}, {spp} spp, `mis`, \
         `stratified`, `max_depth = 1`, seed 0. Near the tube the ring's field rounds at R \
         (second column), which sets the difference step of normals. The scene is \
         symmetric about x = 0: the light's reflection should be centred (its centroid's \
         offset from the centre column, in pixels) and, on large rings, carry what it does \
         on a straight tube (a capsule 6 long, rounding at its own size; same seed).\n\n\
         | tube | field rounding | fast: offset | fast: energy / straight | naive: offset \
         | naive: energy / straight |\n|---|---|---|---|---|---|"
    );
    let straight =
        "{ type = \"capsule\", a = [-3.0, 0.2, 0.0], b = [3.0, 0.2, 0.0], radius = 0.1 }";
    let reflection = |shape: &str, marching: Marching| -> Result<(f64, f64)> {
        let text = format!(
            "[camera]\nposition = [0.0, 0.5, 3.0]\nlook_at = [0.0, 0.2, 0.0]\nvfov = 40.0\n\
             [materials]\nchrome = {{ type = \"mirror\", reflectance = [0.9, 0.9, 0.9] }}\n\
             [[objects]]\nmaterial = \"chrome\"\nshape = {shape}\n\
             [[lights]]\ntype = \"sphere\"\ncenter = [0.0, 2.0, 0.5]\nradius = 0.1\n\
             radiance = [100.0, 100.0, 100.0]\n"
        );
        let file = parse_scene(&text, "tube.toml").context("the generated scene")?;
        let settings = RenderSettings {
            width: size,
            height: size,
            spp,
            strategy: Strategy::Mis,
            sampler: SamplerKind::Stratified,
            max_depth: 1,
            seed: 0,
            marching,
            ..file.settings.clone()
        };
        let film = render_with_bar(&file.scene, &settings, &format!("tube {marching:?}"))?;
        let (mut sum, mut moment) = (0.0f64, 0.0f64);
        for y in 0..size {
            for x in 0..size {
                let v = f64::from(film.pixel(x, y).mean.y);
                sum += v;
                moment += v * (f64::from(x) + 0.5);
            }
        }
        Ok((moment / sum - f64::from(size) / 2.0, sum))
    };
    let marchings = [Marching::Fast, Marching::Naive];
    let straight = marchings
        .map(|m| reflection(straight, m).map(|(_, energy)| energy))
        .into_iter()
        .collect::<Result<Vec<_>>>()?;
    for &r in radii {
        let ring = format!(
            "{{ type = \"torus\", center = [0.0, 0.2, {:e}], major_radius = {r:e}, minor_radius = 0.1 }}",
            -r
        );
        let mut cells = Vec::new();
        for (m, expected) in marchings.into_iter().zip(&straight) {
            let (offset, energy) = reflection(&ring, m)?;
            cells.push(format!("{offset:+.2}"));
            cells.push(format!("{:.3}", energy / expected));
        }
        let rounding = f64::from(f32::EPSILON) * r;
        let _ = writeln!(
            out,
            "| ring of radius {r:e} | {rounding:.1e} | {} |",
            cells.join(" | ")
        );
    }
    out.push('\n');
    Ok(())
}

/// A floor 2 km wide seen from half a metre above it out to the horizon, under a sphere
/// light 0.1 in radius, against the closed form `albedo L (r / d)^2 (h / d)` integrated
/// over each pixel: camera rays meet the floor at slopes down to the horizon's, where the
/// tracer stops `1/s` shells before the crossing, and the shading point must still be
/// there. A floor 0.1 thick, and one 1 mm thick, thinner than the difference step of
/// normals far out.
fn horizon(out: &mut String, quick: bool) -> Result<()> {
    let (size, spp) = (128u32, if quick { 16 } else { 256 });
    let _ = writeln!(
        out,
        "## A floor to the horizon\n\nA Lambertian floor (albedo {ALBEDO}) 2 km wide, its \
         top at y = 0, seen from 0.5 above it (looking 5.7 degrees down, 40-degree field, \
         the horizon 17 rows above the centre) under a sphere light of radius 0.1 and \
         radiance 100 at height 2; {size}x{size}, {spp} spp, `light`, `stratified`, \
         `max_depth = 1`, seed 0. A camera ray meets the floor at slope `s` (the sine of its \
         angle to it, 0.1 at 5 m, 0.01 at 50 m); the tracer stops where it enters its \
         shell, `pixel_epsilon` (1/256) of a pixel's footprint above the floor, `1/s` \
         shells before it crosses. Each cell: the mean over the rows whose footprints lie in the distance \
         band, relative to the closed form integrated over each pixel (16x16 points), and \
         its z-score. Naive marching takes every step the field allows, with no bounds to \
         clip to: its camera rays past 40 m crawl toward the floor, and at a cap of 256 \
         steps gave up short of it (-95% on the thick floor); it takes 16 times \
         `max_steps`.\n\n| floor | distance | closed form | fast | naive |\n|---|---|---|---|---|"
    );
    let bands = [
        (3.5, 5.0),
        (5.0, 10.0),
        (10.0, 20.0),
        (20.0, 40.0),
        (40.0, 1000.0),
    ];
    let (eye, look_at) = ([0.0f32, 0.5, 3.0], [0.0f32, 0.2, 0.0]);
    let (center, radius, radiance) = ([0.0f64, 2.0, 0.5], 0.1f64, 100.0f64);
    for (label, thickness) in [("0.1 thick", 0.1f64), ("1 mm thick", 1e-3)] {
        let text = format!(
            "[camera]\nposition = {eye:?}\nlook_at = {look_at:?}\nvfov = 40.0\n\
             [materials]\nwhite = {{ type = \"lambertian\", albedo = [{ALBEDO:?}, {ALBEDO:?}, {ALBEDO:?}] }}\n\
             [[objects]]\nmaterial = \"white\"\nshape = {{ type = \"box\", center = [0.0, {:e}, 0.0], \
             half_extents = [1000.0, {:e}, 1000.0] }}\n\
             [[lights]]\ntype = \"sphere\"\ncenter = {center:?}\nradius = {radius:?}\n\
             radiance = [{radiance:?}, {radiance:?}, {radiance:?}]\n",
            -thickness / 2.0,
            thickness / 2.0
        );
        let file = parse_scene(&text, "horizon.toml").context("the generated scene")?;
        let camera = file.scene.camera;
        let films = [Marching::Fast, Marching::Naive]
            .into_iter()
            .map(|marching| {
                let settings = RenderSettings {
                    width: size,
                    height: size,
                    spp,
                    strategy: Strategy::Light,
                    sampler: SamplerKind::Stratified,
                    max_depth: 1,
                    seed: 0,
                    marching,
                    ..file.settings.clone()
                };
                render_with_bar(&file.scene, &settings, &format!("horizon {marching:?}"))
            })
            .collect::<Result<Vec<_>>>()?;
        // Where a camera ray through `film` meets the floor, if it does.
        let floor_t = |x: f32, y: f32| {
            let ray = camera.generate_ray(glam::Vec2::new(x, y), size, size);
            let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3().normalize());
            (d.y < 0.0).then(|| (-o.y / d.y, o + d * (-o.y / d.y)))
        };
        let closed_form = |p: glam::DVec3| {
            let to_light = glam::DVec3::from_array(center) - p;
            let d = to_light.length();
            ALBEDO * radiance * (radius / d).powi(2) * (to_light.y / d)
        };
        for (near, far) in bands {
            let rows: Vec<u32> = (0..size)
                .filter(|&y| {
                    let top = floor_t(0.0, y as f32).map(|(t, _)| t);
                    let bottom = floor_t(0.0, y as f32 + 1.0).map(|(t, _)| t);
                    matches!((bottom, top), (Some(b), Some(t)) if b >= near && t <= far)
                })
                .collect();
            if rows.is_empty() {
                continue;
            }
            let grid = 16u32;
            let mut expected = 0.0;
            for &y in &rows {
                for x in 0..size {
                    for i in 0..grid * grid {
                        let (u, v) = ((i % grid) as f32 + 0.5, (i / grid) as f32 + 0.5);
                        let (fx, fy) = (x as f32 + u / grid as f32, y as f32 + v / grid as f32);
                        expected += floor_t(fx, fy).map_or(0.0, |(_, p)| closed_form(p));
                    }
                }
            }
            let n = (rows.len() * size as usize) as f64;
            expected /= n * f64::from(grid * grid);
            let cells = films
                .iter()
                .map(|film| {
                    let (mut mean, mut var) = (0.0, 0.0);
                    for &y in &rows {
                        for x in 0..size {
                            let p = film.pixel(x, y);
                            mean += f64::from(p.mean.y);
                            var += f64::from(p.variance_of_mean().y);
                        }
                    }
                    let (mean, stderr) = (mean / n, var.sqrt() / n);
                    format!(
                        "{:+.3}% (z {:+.1})",
                        100.0 * (mean / expected - 1.0),
                        (mean - expected) / stderr
                    )
                })
                .collect::<Vec<_>>();
            let _ = writeln!(
                out,
                "| {label} | {near}-{far} m ({} rows) | {expected:.4e} | {} |",
                rows.len(),
                cells.join(" | ")
            );
        }
    }
    out.push('\n');
    Ok(())
}

/// What a ray that reaches the step cap outside a solid is taken to be costs this much:
/// each shipped scene at the default cap against the same render with a cap 64 times
/// higher (where almost no ray gives up), same seed, so the difference is the give-ups'.
fn give_ups(out: &mut String, quick: bool) -> Result<()> {
    let (size, spp) = if quick { (32, 16) } else { (128, 64) };
    let _ = writeln!(
        out,
        "## Give-ups\n\nA ray that reaches the step cap (`max_steps`) outside a solid is \
         taken as a hit where it stopped (it is crawling along a surface it is about to \
         meet). Each shipped scene at {size}x{size}, {spp} spp, `mis`, independent samples, \
         seed 0, at the default cap against a cap 64 times higher; image means over all \
         channels.\n\n| scene | secondary rays given up | at 64x the cap | image mean | at 64x \
         the cap | difference |\n|---|---|---|---|---|---|"
    );
    for name in ["cornell-spheres", "death-star", "donut-mirrors"] {
        let file = load_scene(name)?;
        let settings = RenderSettings {
            width: size,
            height: size,
            spp,
            strategy: Strategy::Mis,
            sampler: SamplerKind::Independent,
            ..file.settings.clone()
        };
        let capped = render(&PreparedScene::new(file.scene.clone()), &settings, &|_| {})?;
        let generous = RenderSettings {
            max_steps: settings.max_steps * 64,
            ..settings.clone()
        };
        let reference = render(&PreparedScene::new(file.scene.clone()), &generous, &|_| {})?;
        let share = |stats: &RenderStats| {
            let b = &stats.rays.bounce;
            let s = &stats.rays.shadow;
            100.0 * (b.gave_up + s.gave_up) as f64 / (b.rays + s.rays).max(1) as f64
        };
        let (m, _) = capped.film.image_mean();
        let (r, _) = reference.film.image_mean();
        let _ = writeln!(
            out,
            "| {name} | {:.3}% | {:.4}% | {m:.5} | {r:.5} | {:+.3}% |",
            share(&capped.stats),
            share(&reference.stats),
            100.0 * (m - r) / r
        );
    }
    out.push('\n');
    Ok(())
}
