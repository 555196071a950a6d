//! Angle tables (CSV), as fractions and as percent.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for percent in [false, true] {
        let _ =
            glassdb_fit::parse_angle_table(data, std::path::Path::new("fuzz.csv"), "fuzz", percent);
    }
});
