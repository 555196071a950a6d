//! Fit files (`glassdb fit -o`), then evaluating every curve they hold.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = glassdb_fit::parse_fit_json(data, std::path::Path::new("fuzz.json"));
});
