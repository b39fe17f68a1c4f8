//! The scene file: TOML in, a validated [`Scene`] and its [`RenderSettings`]
//! out, every error naming the file, line and dotted key (see the crate
//! docs for why the file is dispatched by hand rather than by serde).

use std::collections::HashMap;

use glam::Vec3;
use lueur_materials::Material;
use lueur_sampling::SamplerKind;
use toml::de::{DeTable, DeValue};

use crate::overrides;
use crate::parse::{Check, Result, Source, Table, as_table, did_you_mean};
use crate::shape::parse_shape;
use crate::{
    Camera, Light, MAX_IMAGE_SIDE, MAX_SPP, Object, QuadSampling, RenderSettings, Scene,
    SceneError, SceneFileError, Strategy,
};

/// A parsed scene file: what to render and how.
#[derive(Clone, Debug)]
pub struct SceneFile {
    /// The scene.
    pub scene: Scene,
    /// Image size and render settings from `[image]` and `[render]`.
    pub settings: RenderSettings,
}

/// Parses a scene from `text`; `file` is the name used in error messages.
pub fn parse_scene(text: &str, file: &str) -> std::result::Result<SceneFile, SceneFileError> {
    parse_scene_with(text, file, &[])
}

/// Parses a scene from `text` with `overrides` applied, each `KEY=VALUE`
/// with a dotted key path (`camera.vfov=30`, `lights[0].radiance=[1,1,1]`)
/// and a TOML value, as the file would set it: the values go through the
/// file's own checks, and an error in one names it as `--set`, with its
/// key and a caret.
pub fn parse_scene_with(
    text: &str,
    file: &str,
    overrides: &[&str],
) -> std::result::Result<SceneFile, SceneFileError> {
    let src = Source {
        file,
        text,
        overrides,
        bases: overrides::bases(text, overrides),
    };
    let mut root = DeTable::parse(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        src.error(span, "", format!("invalid TOML: {}", e.message().trim()))
    })?;
    overrides::apply(&src, root.get_mut(), overrides)?;
    let top = Table::new(root.get_ref(), root.span(), String::new());
    top.deny_unknown(
        &src,
        &[
            "image",
            "render",
            "camera",
            "materials",
            "objects",
            "lights",
            "sky",
        ],
    )?;

    let mut settings = RenderSettings::default();
    if let Some(image) = top.table(&src, "image")? {
        image.deny_unknown(&src, &["width", "height"])?;
        if let Some(w) = image.u32_in(&src, "width", 1, MAX_IMAGE_SIDE)? {
            settings.width = w;
        }
        if let Some(h) = image.u32_in(&src, "height", 1, MAX_IMAGE_SIDE)? {
            settings.height = h;
        }
    }
    if let Some(render) = top.table(&src, "render")? {
        parse_render(&src, &render, &mut settings)?;
    }

    let camera_table = top
        .table(&src, "camera")?
        .ok_or_else(|| top.missing(&src, "camera", "a table"))?;
    let camera = parse_camera(&src, &camera_table)?;

    let mut material_index: HashMap<&str, usize> = HashMap::new();
    let mut materials = Vec::new();
    if let Some(table) = top.table(&src, "materials")? {
        let mut entries: Vec<_> = table.table.iter().collect();
        entries.sort_by_key(|(k, _)| k.span().start);
        for (name, value) in entries {
            let m = as_table(&src, value, table.key_path(name.get_ref()))?;
            materials.push(parse_material(&src, &m)?);
            material_index.insert(name.get_ref().as_ref(), materials.len() - 1);
        }
    }

    let mut objects = Vec::new();
    for entry in array_of_tables(&src, &top, "objects")? {
        objects.push(parse_object(&src, &entry, &material_index)?);
    }

    let mut lights = Vec::new();
    let mut light_places = Vec::new();
    for entry in array_of_tables(&src, &top, "lights")? {
        lights.push(parse_light(&src, &entry)?);
        light_places.push((entry.span.clone(), entry.path.clone()));
    }

    let mut sky = None;
    if let Some(table) = top.table(&src, "sky")? {
        table.deny_unknown(&src, &["radiance"])?;
        sky = Some(table.req_vec3(&src, "radiance", Check::Emission)?);
    }

    // The checks above should leave nothing for `Scene::new` to reject;
    // should they miss a case, the error still names the key to blame.
    let scene = Scene::new(objects, materials, lights, sky, camera).map_err(|e| {
        let (span, key) = match &e {
            SceneError::InvalidLight(i) => light_places
                .get(*i)
                .cloned()
                .unwrap_or((top.span.clone(), "lights".into())),
            SceneError::InvalidSky => (
                top.get("sky").map_or(top.span.clone(), |v| v.span()),
                "sky".into(),
            ),
            SceneError::Camera(_) => (camera_table.span.clone(), "camera".into()),
            _ => (top.span.clone(), "objects".into()),
        };
        src.error(span, &key, e.to_string())
    })?;
    Ok(SceneFile { scene, settings })
}

/// One `[[objects]]` entry: a shape and the name of its material.
fn parse_object(
    src: &Source<'_>,
    entry: &Table<'_, '_>,
    material_index: &HashMap<&str, usize>,
) -> Result<Object> {
    entry.deny_unknown(src, &["material", "shape"])?;
    let (name, span) = entry.req_str(src, "material", "the name of a material in [materials]")?;
    let Some(&material) = material_index.get(name) else {
        let known: Vec<_> = material_index.keys().map(|k| format!("`{k}`")).collect();
        return Err(src.error(
            span,
            &entry.key_path("material"),
            format!(
                "unknown material `{name}`; defined: {}",
                if known.is_empty() {
                    "none".into()
                } else {
                    known.join(", ")
                }
            ),
        ));
    };
    let shape = entry
        .get("shape")
        .ok_or_else(|| entry.missing(src, "shape", "a shape table"))?;
    let sdf = parse_shape(src, shape, entry.key_path("shape"), 0)?;
    Ok(Object { sdf, material })
}

fn parse_render(
    src: &Source<'_>,
    render: &Table<'_, '_>,
    settings: &mut RenderSettings,
) -> Result<()> {
    render.deny_unknown(
        src,
        &[
            "spp",
            "strategy",
            "sampler",
            "replicates",
            "max_depth",
            "roulette_depth",
            "seed",
            "max_steps",
            "pixel_epsilon",
            "epsilon",
            "quad_sampling",
        ],
    )?;
    if let Some(spp) = render.u32_in(src, "spp", 1, MAX_SPP)? {
        settings.spp = spp;
    }
    if let Some((name, span)) = render.str(src, "strategy")? {
        settings.strategy = Strategy::from_name(name).ok_or_else(|| {
            let all: Vec<_> = Strategy::ALL.iter().map(|s| s.name()).collect();
            src.error(
                span,
                &render.key_path("strategy"),
                format!(
                    "unknown strategy `{name}`{}; expected one of {}",
                    did_you_mean(name, all.iter().copied()),
                    all.join(", ")
                ),
            )
        })?;
    }
    if let Some((name, span)) = render.str(src, "sampler")? {
        settings.sampler = SamplerKind::from_name(name).ok_or_else(|| {
            let all: Vec<_> = SamplerKind::ALL.iter().map(|s| s.name()).collect();
            src.error(
                span,
                &render.key_path("sampler"),
                format!(
                    "unknown sampler `{name}`{}; expected one of {}",
                    did_you_mean(name, all.iter().copied()),
                    all.join(", ")
                ),
            )
        })?;
    }
    parse_replicates(src, render, settings)?;
    if let Some(d) = render.u32_in(src, "max_depth", 0, 10_000)? {
        settings.max_depth = d;
    }
    if let Some(d) = render.u32_in(src, "roulette_depth", 0, 10_000)? {
        settings.roulette_depth = d;
    }
    if let Some((seed, _)) = render.u64(src, "seed")? {
        settings.seed = seed;
    }
    if let Some(steps) = render.u32_in(src, "max_steps", 1, 1 << 20)? {
        settings.max_steps = steps;
    }
    settings.pixel_epsilon = render.opt_f32(
        src,
        "pixel_epsilon",
        Check::Positive,
        settings.pixel_epsilon,
    )?;
    settings.epsilon_rel = render.opt_f32(src, "epsilon", Check::Positive, settings.epsilon_rel)?;
    if let Some((name, span)) = render.str(src, "quad_sampling")? {
        settings.quad_sampling = match name {
            "area" => QuadSampling::Area,
            "solid-angle" => QuadSampling::SolidAngle,
            _ => {
                return Err(src.error(
                    span,
                    &render.key_path("quad_sampling"),
                    format!(
                        "unknown quad sampling `{name}`{}; expected `area` or `solid-angle`",
                        did_you_mean(name, ["area", "solid-angle"])
                    ),
                ));
            }
        };
    }
    Ok(())
}

/// `render.replicates`: at least 1, at most the file's spp, and 1 for the
/// plain (unrandomized) sequences. Read after `spp` and `sampler`.
fn parse_replicates(
    src: &Source<'_>,
    render: &Table<'_, '_>,
    settings: &mut RenderSettings,
) -> Result<()> {
    let Some((k, span)) = render.u64(src, "replicates")? else {
        return Ok(());
    };
    let why = if k == 0 {
        Some("must be at least 1, got 0".to_string())
    } else if k > u64::from(settings.spp) {
        Some(format!(
            "{k} replicates need at least {k} spp, and `spp` is {}",
            settings.spp
        ))
    } else if k > 1 && !settings.sampler.is_randomized() {
        Some(format!(
            "the {} sampler is not randomized: it has no independent replicates (use 1)",
            settings.sampler
        ))
    } else {
        None
    };
    if let Some(why) = why {
        return Err(src.error(span, &render.key_path("replicates"), why));
    }
    settings.replicates = Some(k as u32);
    Ok(())
}

fn parse_camera(src: &Source<'_>, t: &Table<'_, '_>) -> Result<Camera> {
    t.deny_unknown(src, &["position", "look_at", "up", "vfov"])?;
    let position = t.req_vec3(src, "position", Check::Any)?;
    let look_at = t.req_vec3(src, "look_at", Check::Any)?;
    let up = t.opt_vec3(src, "up", Check::NonZeroVector, Vec3::Y)?;
    let vfov = t.opt_f32(src, "vfov", Check::Positive, 40.0)?;
    Camera::new(position, look_at, up, vfov).map_err(|e| {
        // Point at the key most likely to blame.
        let key = if e.to_string().contains("up") {
            "up"
        } else if e.to_string().contains("vfov") {
            "vfov"
        } else {
            "look_at"
        };
        let span = t.get(key).map_or(t.span.clone(), |v| v.span());
        src.error(span, &t.key_path(key), e.to_string())
    })
}

fn parse_material(src: &Source<'_>, t: &Table<'_, '_>) -> Result<Material> {
    let (kind, span) = t.req_str(src, "type", "`lambertian` or `mirror`")?;
    match kind {
        "lambertian" => {
            t.deny_unknown(src, &["type", "albedo"])?;
            // Albedo above 1 creates energy: rejected, since Russian
            // roulette and convergence assume throughput never grows.
            Ok(Material::Lambertian {
                albedo: t.req_vec3(src, "albedo", Check::UnitInterval)?,
            })
        }
        "mirror" => {
            t.deny_unknown(src, &["type", "reflectance"])?;
            Ok(Material::Mirror {
                reflectance: t.opt_vec3(src, "reflectance", Check::UnitInterval, Vec3::ONE)?,
            })
        }
        other => Err(src.error(
            span,
            &t.key_path("type"),
            format!(
                "unknown material type `{other}`{}; expected `lambertian` or `mirror`",
                did_you_mean(other, ["lambertian", "mirror"])
            ),
        )),
    }
}

fn parse_light(src: &Source<'_>, t: &Table<'_, '_>) -> Result<Light> {
    let (kind, span) = t.req_str(src, "type", "`sphere`, `quad` or `directional`")?;
    match kind {
        "sphere" => {
            t.deny_unknown(src, &["type", "center", "radius", "radiance"])?;
            Ok(Light::Sphere {
                center: t.req_vec3(src, "center", Check::Any)?,
                radius: t.req_f32(src, "radius", Check::Positive)?,
                radiance: t.req_vec3(src, "radiance", Check::Emission)?,
            })
        }
        "quad" => {
            t.deny_unknown(src, &["type", "corner", "edge_u", "edge_v", "radiance"])?;
            let corner = t.req_vec3(src, "corner", Check::Any)?;
            let edge_u = t.req_vec3(src, "edge_u", Check::NonZeroVector)?;
            let edge_v = t.req_vec3(src, "edge_v", Check::NonZeroVector)?;
            if !(edge_u.cross(edge_v).length() > 0.0) {
                let span = t.get("edge_v").map_or(t.span.clone(), |v| v.span());
                return Err(src.error(
                    span,
                    &t.key_path("edge_v"),
                    "must not be parallel to `edge_u` (the quad has zero area)",
                ));
            }
            Ok(Light::Quad {
                corner,
                edge_u,
                edge_v,
                radiance: t.req_vec3(src, "radiance", Check::Emission)?,
            })
        }
        "directional" => {
            t.deny_unknown(src, &["type", "direction", "irradiance"])?;
            Ok(Light::Directional {
                direction: t
                    .req_vec3(src, "direction", Check::NonZeroVector)?
                    .normalize(),
                irradiance: t.req_vec3(src, "irradiance", Check::Emission)?,
            })
        }
        other => Err(src.error(
            span,
            &t.key_path("type"),
            format!(
                "unknown light type `{other}`{}; expected `sphere`, `quad` or `directional`",
                did_you_mean(other, ["sphere", "quad", "directional"])
            ),
        )),
    }
}

/// The tables of an array of tables (`[[objects]]`), or of an inline array.
fn array_of_tables<'a, 'i>(
    src: &Source<'_>,
    top: &Table<'a, 'i>,
    key: &str,
) -> Result<Vec<Table<'a, 'i>>> {
    let Some(v) = top.get(key) else {
        return Ok(Vec::new());
    };
    let DeValue::Array(items) = v.get_ref() else {
        return Err(src.error(
            v.span(),
            key,
            format!("expected an array of tables (`[[{key}]]`)"),
        ));
    };
    items
        .iter()
        .enumerate()
        .map(|(i, item)| as_table(src, item, format!("{key}[{i}]")))
        .collect()
}
