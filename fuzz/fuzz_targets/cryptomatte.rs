//! Masks from a render's Cryptomatte (manifest in the header, ranked id/coverage pairs, AOVs).
#![no_main]
use glassdb_mask::{
    AovWeighting, CosSource, CryptomatteOptions, GlassMapping, GlassNames, MaskReadOptions,
    PlaneSource, read_placed_mask_bytes,
};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(glass) = GlassMapping::parse("Glass*=1").and_then(|m| GlassNames::new(&[m])) else {
        return;
    };
    for weighting in [AovWeighting::GlassOnly, AovWeighting::EveryMaterial] {
        let opts = MaskReadOptions {
            max_pixels: 1 << 20,
            cryptomatte: Some(CryptomatteOptions {
                layer: None,
                glass: glass.clone(),
                cos: CosSource::Aov {
                    channel: "facing".into(),
                },
                planes: PlaneSource::Aov("plane".into()),
                weighting,
            }),
            ..MaskReadOptions::default()
        };
        let _ = read_placed_mask_bytes(data, std::path::Path::new("fuzz.exr"), &opts);
    }
});
