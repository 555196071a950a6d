//! `.cube` view LUTs (Resolve and Adobe/Iridas dialects), then applying one to a few values.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = glassdb_colour::CubeLut::parse(text, std::path::Path::new("fuzz.cube"));
    }
});
