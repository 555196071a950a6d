//! planes.json (`glassdb mirror`'s plane list).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(dir) = tempfile::tempdir() else { return };
    let path = dir.path().join("planes.json");
    if std::fs::write(&path, data).is_err() {
        return;
    }
    if let Ok(planes) = glassdb_scene::PlanesFile::load(&path) {
        let _ = planes.planes();
    }
});
