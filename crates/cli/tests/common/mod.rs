//! Helpers shared by the CLI's test binaries (each uses some of them).
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// Runs the `lueur` binary in `dir`.
pub fn lueur(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lueur"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// The path of a shipped scene.
pub fn scene(name: &str) -> String {
    format!("{}/../../scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"))
}

/// What a run printed on standard error.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// An EXR's pixels, every channel of every layer as bits: what must be
/// bit-identical between two renders of one image, whose headers differ
/// (their provenance has the render time).
pub fn exr_pixels(path: &std::path::Path) -> Vec<(String, Vec<u32>)> {
    use exr::prelude::{FlatSamples, read_all_flat_layers_from_file};
    let image = read_all_flat_layers_from_file(path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    image
        .layer_data
        .iter()
        .flat_map(|layer| layer.channel_data.list.iter())
        .map(|c| {
            let bits = match &c.sample_data {
                FlatSamples::F16(v) => v.iter().map(|x| u32::from(x.to_bits())).collect(),
                FlatSamples::F32(v) => v.iter().map(|x| x.to_bits()).collect(),
                FlatSamples::U32(v) => v.clone(),
            };
            (c.name.to_string(), bits)
        })
        .collect()
}
