//! Registry JSON (schema 2 and 3): parse and validate.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = glassdb_registry::Registry::from_json_str(text, "fuzz.json");
    }
});
