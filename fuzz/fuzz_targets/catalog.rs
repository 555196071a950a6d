//! Catalog TOML (`[[glass]]` tables).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = glassdb_registry::catalog::parse_catalog(text, std::path::Path::new("fuzz.toml"));
    }
});
