//! Helpers shared by the CLI's test binaries.

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
