//! planes.json (`glassdb mirror`'s plane list).
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "files.rs"]
mod files;

fuzz_target!(|data: &[u8]| {
    files::with_files(&[("planes.json", data)], |dir| {
        if let Ok(planes) = glassdb_scene::PlanesFile::load(&dir.join("planes.json")) {
            let _ = planes.planes();
        }
    });
});
