//! Camera JSON (one camera or a `frames` object), every frame it names.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(dir) = tempfile::tempdir() else { return };
    let path = dir.path().join("camera.json");
    if std::fs::write(&path, data).is_err() {
        return;
    }
    if let Ok(source) = glassdb_scene::CameraSource::open(&path) {
        let _ = source.camera(None);
        for frame in source.frames().unwrap_or_default().into_iter().take(8) {
            let _ = source.camera(Some(frame));
        }
    }
});
