//! `[[objects]]` shapes: primitives, CSG and the transforms around them.

use glam::{Quat, Vec3};
use lueur_sdf_math::Sdf;
use toml::Spanned;
use toml::de::DeValue;

use crate::parse::{Check, Result, Source, Table, as_table, did_you_mean};

/// Nesting depth of CSG shapes beyond which a file is rejected: evaluation
/// recurses through the tree, and no scene needs more.
const MAX_SHAPE_DEPTH: usize = 64;

const TRANSFORM_KEYS: [&str; 3] = ["translate", "rotate", "scale"];

const SHAPE_TYPES: [&str; 14] = [
    "sphere",
    "box",
    "round_box",
    "plane",
    "torus",
    "capped_cylinder",
    "capsule",
    "death_star",
    "union",
    "intersection",
    "difference",
    "smooth_union",
    "smooth_intersection",
    "smooth_difference",
];

/// The shape of table `value` (at `path`, `depth` CSG levels down).
pub(crate) fn parse_shape(
    src: &Source<'_>,
    value: &Spanned<DeValue<'_>>,
    path: String,
    depth: usize,
) -> Result<Sdf> {
    let t = as_table(src, value, path)?;
    if depth > MAX_SHAPE_DEPTH {
        return Err(src.error(
            t.span.clone(),
            &t.path,
            format!("shapes nest deeper than {MAX_SHAPE_DEPTH} levels"),
        ));
    }
    let (kind, span) = t.req_str(src, "type", "the shape's type")?;
    let (sdf, center) = match kind {
        "union"
        | "intersection"
        | "difference"
        | "smooth_union"
        | "smooth_intersection"
        | "smooth_difference" => (parse_csg(src, &t, kind, depth)?, Vec3::ZERO),
        _ => match parse_primitive(src, &t, kind)? {
            Some(shape) => shape,
            None => {
                return Err(src.error(
                    span,
                    &t.key_path("type"),
                    format!(
                        "unknown shape type `{kind}`{}; expected one of {}",
                        did_you_mean(kind, SHAPE_TYPES),
                        SHAPE_TYPES.join(", ")
                    ),
                ));
            }
        },
    };
    transform(src, &t, sdf, center)
}

/// Refuses keys of shape table `t` other than `type`, `keys` and the
/// transforms.
fn allow(src: &Source<'_>, t: &Table<'_, '_>, keys: &[&str]) -> Result<()> {
    let mut all: Vec<&str> = vec!["type"];
    all.extend_from_slice(keys);
    all.extend_from_slice(&TRANSFORM_KEYS);
    t.deny_unknown(src, &all)
}

/// A primitive of type `kind` and its centre; `None` for a type that is no
/// primitive.
fn parse_primitive(src: &Source<'_>, t: &Table<'_, '_>, kind: &str) -> Result<Option<(Sdf, Vec3)>> {
    let allow = |keys: &[&str]| allow(src, t, keys);
    let center = |t: &Table<'_, '_>| t.opt_vec3(src, "center", Check::Any, Vec3::ZERO);
    let shape = match kind {
        "sphere" => {
            allow(&["center", "radius"])?;
            (
                Sdf::sphere(t.req_f32(src, "radius", Check::Positive)?),
                center(t)?,
            )
        }
        "box" => {
            allow(&["center", "half_extents"])?;
            (
                Sdf::cuboid(t.req_vec3(src, "half_extents", Check::Positive)?),
                center(t)?,
            )
        }
        "round_box" => {
            allow(&["center", "half_extents", "radius"])?;
            let half_extents = t.req_vec3(src, "half_extents", Check::Positive)?;
            let radius = t.req_f32(src, "radius", Check::NonNegative)?;
            if radius > half_extents.min_element() {
                let span = t.get("radius").map_or(t.span.clone(), |v| v.span());
                return Err(src.error(
                    span,
                    &t.key_path("radius"),
                    "must not exceed the smallest half extent",
                ));
            }
            (Sdf::round_box(half_extents, radius), center(t)?)
        }
        "plane" => {
            allow(&["normal", "height"])?;
            let normal = t.req_vec3(src, "normal", Check::NonZeroVector)?;
            let height = t.opt_f32(src, "height", Check::Any, 0.0)?;
            (Sdf::plane(normal, height), Vec3::ZERO)
        }
        "torus" => {
            allow(&["center", "major_radius", "minor_radius"])?;
            let major_radius = t.req_f32(src, "major_radius", Check::Positive)?;
            let minor_radius = t.req_f32(src, "minor_radius", Check::Positive)?;
            (Sdf::torus(major_radius, minor_radius), center(t)?)
        }
        "capped_cylinder" => {
            allow(&["center", "radius", "half_height"])?;
            let radius = t.req_f32(src, "radius", Check::Positive)?;
            let half_height = t.req_f32(src, "half_height", Check::Positive)?;
            (Sdf::capped_cylinder(radius, half_height), center(t)?)
        }
        "capsule" => {
            allow(&["a", "b", "radius"])?;
            let a = t.req_vec3(src, "a", Check::Any)?;
            let b = t.req_vec3(src, "b", Check::Any)?;
            (
                Sdf::capsule(a, b, t.req_f32(src, "radius", Check::Positive)?),
                Vec3::ZERO,
            )
        }
        "death_star" => {
            allow(&["center", "ra", "rb", "d"])?;
            let ra = t.req_f32(src, "ra", Check::Positive)?;
            let rb = t.req_f32(src, "rb", Check::Positive)?;
            let d = t.req_f32(src, "d", Check::Positive)?;
            (Sdf::death_star(ra, rb, d), center(t)?)
        }
        _ => return Ok(None),
    };
    Ok(Some(shape))
}

/// A CSG node of type `kind`, its children parsed one level down.
fn parse_csg(src: &Source<'_>, t: &Table<'_, '_>, kind: &str, depth: usize) -> Result<Sdf> {
    let allow = |keys: &[&str]| allow(src, t, keys);
    let smooth = kind.starts_with("smooth_");
    if smooth {
        allow(&["shapes", "k"])?
    } else {
        allow(&["shapes"])?
    }
    let list = t
        .get("shapes")
        .ok_or_else(|| t.missing(src, "shapes", "an array of shapes"))?;
    let DeValue::Array(items) = list.get_ref() else {
        return Err(src.error(
            list.span(),
            &t.key_path("shapes"),
            "expected an array of shape tables",
        ));
    };
    let min = if kind.ends_with("difference") { 2 } else { 1 };
    if items.len() < min {
        return Err(src.error(
            list.span(),
            &t.key_path("shapes"),
            format!("needs at least {min} shape(s)"),
        ));
    }
    let children = items
        .iter()
        .enumerate()
        .map(|(i, item)| {
            parse_shape(
                src,
                item,
                format!("{}[{i}]", t.key_path("shapes")),
                depth + 1,
            )
        })
        .collect::<Result<Vec<_>>>()?;
    let sdf = if smooth {
        let k = t.req_f32(src, "k", Check::Positive)?;
        match kind {
            "smooth_union" => Sdf::SmoothUnion { k, children },
            "smooth_intersection" => Sdf::SmoothIntersection { k, children },
            _ => Sdf::SmoothDifference { k, children },
        }
    } else {
        match kind {
            "union" => Sdf::Union(children),
            "intersection" => Sdf::Intersection(children),
            _ => Sdf::Difference(children),
        }
    };
    Ok(sdf)
}

/// `sdf` under the transforms of table `t`, in the order: centre, scale,
/// rotate, translate.
fn transform(src: &Source<'_>, t: &Table<'_, '_>, sdf: Sdf, center: Vec3) -> Result<Sdf> {
    let mut sdf = sdf;
    if center != Vec3::ZERO {
        sdf = Sdf::Translate {
            offset: center,
            child: Box::new(sdf),
        };
    }
    if let Some(factor) = t
        .f32(src, "scale")?
        .map(|_| t.req_f32(src, "scale", Check::Positive))
        .transpose()?
    {
        sdf = Sdf::Scale {
            factor,
            child: Box::new(sdf),
        };
    }
    if let Some((degrees, _)) = t.vec3(src, "rotate")? {
        let r = degrees * std::f32::consts::PI / 180.0;
        // About the fixed x, then y, then z axes.
        let rotation =
            Quat::from_rotation_z(r.z) * Quat::from_rotation_y(r.y) * Quat::from_rotation_x(r.x);
        sdf = Sdf::Rotate {
            rotation,
            child: Box::new(sdf),
        };
    }
    if let Some((offset, _)) = t.vec3(src, "translate")? {
        sdf = Sdf::Translate {
            offset,
            child: Box::new(sdf),
        };
    }
    Ok(sdf)
}
