//! Every bad input names the right line and key. Most tests are data: a
//! scene text, the line and the key the error must point at.

use super::*;

const BASE: &str = r#"[image]
width = 32
height = 24

[render]
spp = 4
strategy = "mis"

[camera]
position = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]
vfov = 40.0

[materials]
white = { type = "lambertian", albedo = [0.7, 0.7, 0.7] }
chrome = { type = "mirror", reflectance = [0.9, 0.9, 0.9] }

[[objects]]
material = "white"
shape = { type = "sphere", center = [0.0, 0.5, 0.0], radius = 0.5 }

[[objects]]
material = "chrome"
shape = { type = "difference", shapes = [
  { type = "box", half_extents = [1.0, 1.0, 1.0] },
  { type = "sphere", radius = 1.2, translate = [0.5, 0.0, 0.0] },
], translate = [2.0, 0.0, 0.0] }

[[lights]]
type = "sphere"
center = [0.0, 3.0, 0.0]
radius = 0.2
radiance = [10.0, 10.0, 10.0]
"#;

/// Parses `BASE` with `from` replaced by `to` and checks that the error
/// points at `line` and `key`, and that its message contains `needle`.
#[track_caller]
fn check(from: &str, to: &str, line: usize, key: &str, needle: &str) {
    assert!(BASE.contains(from), "{from:?} is not in the base scene");
    let text = BASE.replacen(from, to, 1);
    let err = parse_scene(&text, "scene.toml").expect_err("the scene should be rejected");
    assert_eq!(
        (err.line, err.key.as_str()),
        (line, key),
        "wrong place; error was:\n{err}"
    );
    assert!(
        err.message.contains(needle),
        "message {:?} lacks {needle:?}",
        err.message
    );
    let shown = err.to_string();
    assert!(
        shown.contains(&format!("scene.toml:{line}:")),
        "rendering lacks file:line: {shown}"
    );
}

#[test]
fn base_scene_parses() {
    let file = parse_scene(BASE, "scene.toml").unwrap();
    assert_eq!(
        (file.settings.width, file.settings.height, file.settings.spp),
        (32, 24, 4)
    );
    assert_eq!(file.scene.objects.len(), 2);
    assert_eq!(file.scene.objects[1].material, 1);
}

#[test]
fn unknown_keys_are_named_where_they_stand() {
    check(
        "spp = 4",
        "spp = 4\nsamples = 3",
        7,
        "render.samples",
        "unknown key `samples`",
    );
    check("vfov = 40.0", "fov = 40.0", 12, "camera.fov", "unknown key");
    check(
        "radius = 0.5 }",
        "radius = 0.5, colour = 1 }",
        20,
        "objects[0].shape.colour",
        "unknown key",
    );
    check(
        "{ type = \"box\", half_extents",
        "{ type = \"box\", size = 2, half_extents",
        25,
        "objects[1].shape.shapes[0].size",
        "unknown key",
    );
    check("[render]", "[rendr]", 5, "rendr", "unknown key");
    check(
        "radius = 0.2\n",
        "radius = 0.2\nintensity = 3\n",
        33,
        "lights[0].intensity",
        "unknown key",
    );
}

#[test]
fn wrong_types_and_values_are_named() {
    check(
        "width = 32",
        "width = \"32\"",
        2,
        "image.width",
        "expected a non-negative integer",
    );
    check("width = 32", "width = 0", 2, "image.width", "between 1 and");
    check(
        "radius = 0.5 }",
        "radius = -0.5 }",
        20,
        "objects[0].shape.radius",
        "positive",
    );
    check(
        "radius = 1.2",
        "radius = nan",
        26,
        "objects[1].shape.shapes[1].radius",
        "finite",
    );
    check(
        "radius = 1.2",
        "radius = inf",
        26,
        "objects[1].shape.shapes[1].radius",
        "finite",
    );
    check(
        "radius = 1.2",
        "radius = 1e39",
        26,
        "objects[1].shape.shapes[1].radius",
        "finite",
    );
    check(
        "albedo = [0.7, 0.7, 0.7]",
        "albedo = [0.7, 1.7, 0.7]",
        15,
        "materials.white.albedo",
        "between 0 and 1",
    );
    check(
        "albedo = [0.7, 0.7, 0.7]",
        "albedo = [0.7, 0.7]",
        15,
        "materials.white.albedo",
        "expected 3 numbers",
    );
    check(
        "strategy = \"mis\"",
        "strategy = \"magic\"",
        7,
        "render.strategy",
        "unknown strategy",
    );
    check(
        "radiance = [10.0, 10.0, 10.0]",
        "radiance = [10.0, -1.0, 10.0]",
        33,
        "lights[0].radiance",
        "non-negative",
    );
    check("vfov = 40.0", "vfov = 0.0", 12, "camera.vfov", "positive");
}

#[test]
fn references_and_structure_are_checked() {
    check(
        "material = \"white\"",
        "material = \"black\"",
        19,
        "objects[0].material",
        "unknown material `black`",
    );
    check(
        "type = \"sphere\", center = [0.0, 0.5",
        "type = \"blob\", center = [0.0, 0.5",
        20,
        "objects[0].shape.type",
        "unknown shape type",
    );
    check(
        "type = \"mirror\"",
        "type = \"glass\"",
        16,
        "materials.chrome.type",
        "unknown material type",
    );
    check(
        "type = \"sphere\"\ncenter = [0.0, 3.0",
        "type = \"spot\"\ncenter = [0.0, 3.0",
        30,
        "lights[0].type",
        "unknown light type",
    );
    check(
        "look_at = [0.0, 1.0, 0.0]",
        "look_at = [0.0, 1.0, 0.0]\nup = [0.0, 0.0, 0.0]",
        12,
        "camera.up",
        "non-zero",
    );
    check(
        "look_at = [0.0, 1.0, 0.0]",
        "look_at = [0.0, 5.0, 3.0]\nup = [0.0, 1.0, 0.0]",
        12,
        "camera.up",
        "parallel",
    );
}

#[test]
fn syntax_errors_point_at_the_line() {
    let err = parse_scene(&BASE.replace("spp = 4", "spp = = 4"), "scene.toml").unwrap_err();
    assert_eq!(err.line, 6);
    assert!(err.to_string().contains("invalid TOML"));
}

#[test]
fn missing_keys_are_named() {
    let err = parse_scene(&BASE.replace(", radius = 0.5 }", " }"), "scene.toml").unwrap_err();
    assert_eq!(
        (err.line, err.key.as_str()),
        (20, "objects[0].shape.radius")
    );
    let err = parse_scene("[image]\nwidth = 4\n", "scene.toml").unwrap_err();
    assert_eq!(err.key, "camera");
}

#[test]
fn deep_nesting_is_refused_not_overflowed() {
    let nested = |depth: usize| {
        let mut shape = "{ type = \"sphere\", radius = 1.0 }".to_string();
        for _ in 0..depth {
            shape = format!("{{ type = \"union\", shapes = [{shape}] }}");
        }
        BASE.replace(
            "{ type = \"sphere\", center = [0.0, 0.5, 0.0], radius = 0.5 }",
            &shape,
        )
    };
    // The TOML parser's recursion limit (about 40 nested inline shapes) is
    // below lueur's own (64), which stays as a guard should the parser ever
    // allow more. Within both: a valid scene.
    assert!(parse_scene(&nested(30), "scene.toml").is_ok());
    // Past the TOML parser's recursion limit: its message, on the right line.
    let err = parse_scene(&nested(400), "scene.toml").unwrap_err();
    assert!(err.message.contains("recursion"), "{err}");
    assert_eq!(err.line, 20);
}

#[test]
fn replicates_are_checked_against_spp_and_sampler() {
    let with = |extra: &str| format!("strategy = \"mis\"\n{extra}");
    check(
        "strategy = \"mis\"",
        &with("replicates = 0"),
        8,
        "render.replicates",
        "at least 1",
    );
    check(
        "strategy = \"mis\"",
        &with("replicates = 5"),
        8,
        "render.replicates",
        "at least 5 spp",
    );
    check(
        "strategy = \"mis\"",
        &with("sampler = \"halton\"\nreplicates = 2"),
        9,
        "render.replicates",
        "not randomized",
    );
    let text = BASE.replacen("strategy = \"mis\"", &with("replicates = 4"), 1);
    let file = parse_scene(&text, "scene.toml").unwrap();
    assert_eq!(file.settings.replicates, Some(4));
    assert_eq!(file.settings.replicate_count(), 4);
}
