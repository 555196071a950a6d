//! Masks (packed 8/16-bit PNG, EXR id/cos_theta channels, binary PNG).
#![no_main]
use glassdb_mask::{MaskReadOptions, read_placed_mask_bytes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::path::Path::new("fuzz.mask");
    let small = MaskReadOptions {
        max_pixels: 1 << 20,
        ..MaskReadOptions::default()
    };
    let _ = read_placed_mask_bytes(data, path, &small);
    let binary = MaskReadOptions {
        binary_glass_id: Some(3),
        ..small
    };
    let _ = read_placed_mask_bytes(data, path, &binary);
});
