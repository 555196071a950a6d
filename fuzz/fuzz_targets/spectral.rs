//! Spectral files (Optics, IGSDB JSON, CSV) from bytes, as fractions and as percent, under each
//! name extension that selects a format.
#![no_main]
use glassdb_spectral::{ReadOptions, read_spectral_bytes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for name in ["fuzz.dat", "fuzz.json", "fuzz.csv", "fuzz"] {
        for percent in [false, true] {
            let _ = read_spectral_bytes(data, name, &ReadOptions { percent });
        }
    }
});
