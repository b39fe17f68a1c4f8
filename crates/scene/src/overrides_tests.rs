//! `--set`: overrides reach the scene through the file's own checks, and
//! their errors point at the override.

use glam::Vec3;

use super::*;

const BASE: &str = r#"[render]
spp = 4

[camera]
position = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]

[materials]
white = { type = "lambertian", albedo = [0.7, 0.7, 0.7] }

[[objects]]
material = "white"
shape = { type = "sphere", radius = 0.5 }

[[lights]]
type = "sphere"
center = [0.0, 3.0, 0.0]
radius = 0.2
radiance = [10.0, 10.0, 10.0]
"#;

fn with(overrides: &[&str]) -> std::result::Result<SceneFile, SceneFileError> {
    parse_scene_with(BASE, "s.toml", overrides)
}

#[test]
fn overrides_set_existing_and_new_keys_and_array_entries() {
    let f = with(&[
        "render.max_steps=64",
        "image.width=20",
        "lights[0].radiance=[1, 2, 3]",
        "render.strategy=\"cosine\"",
        "render.spp=9",
    ])
    .unwrap();
    assert_eq!(f.settings.max_steps, 64);
    assert_eq!(f.settings.width, 20);
    assert_eq!(f.settings.spp, 9);
    assert_eq!(f.settings.strategy, Strategy::Cosine);
    let Light::Sphere { radiance, .. } = &f.scene.lights[0] else {
        panic!("a sphere light");
    };
    assert_eq!(*radiance, Vec3::new(1.0, 2.0, 3.0));
    // The camera's field of view is checked as the file's would be.
    let near = with(&["camera.vfov=30"]).unwrap();
    let far = with(&["camera.vfov=60"]).unwrap();
    assert_ne!(near.scene.camera, far.scene.camera);
}

/// Each bad override is refused with the override shown, its key named
/// and the message the file would get.
#[test]
fn bad_overrides_name_the_override_and_the_key() {
    for (set, key, says) in [
        ("camera.vfvo=30", "camera.vfvo", "did you mean `vfov`?"),
        (
            "lights[0].radiance=[-1, 1, 1]",
            "lights[0].radiance",
            "non-negative",
        ),
        ("lights[3].radiance=[1, 1, 1]", "lights[3]", "out of range"),
        (
            "render.strategy=\"mixtur\"",
            "render.strategy",
            "did you mean `mixture`?",
        ),
        ("camera.vfov=", "camera.vfov", "invalid TOML value"),
        ("camera", "", "expected KEY=VALUE"),
        ("camera..vfov=3", "camera..vfov", "dotted key path"),
    ] {
        let e = with(&[set]).unwrap_err();
        assert_eq!(e.file, "--set", "{set}: {e}");
        assert_eq!(e.key, key, "{set}: {e}");
        assert!(e.message.contains(says), "{set}: {e}");
        assert!(e.to_string().contains(set), "the override is shown: {e}");
    }
}

#[test]
fn misspelt_values_and_keys_in_files_get_a_suggestion() {
    let e = parse_scene(&BASE.replace("spp = 4", "strategy = \"mixtur\""), "s.toml").unwrap_err();
    assert!(e.message.contains("did you mean `mixture`?"), "{e}");
    let e = parse_scene(&BASE.replace("radius = 0.5", "raduis = 0.5"), "s.toml").unwrap_err();
    assert!(e.message.contains("did you mean `radius`?"), "{e}");
    // Nothing is suggested for a name unlike any choice.
    let e = parse_scene(&BASE.replace("spp = 4", "strategy = \"magic\""), "s.toml").unwrap_err();
    assert!(!e.message.contains("did you mean"), "{e}");
}
