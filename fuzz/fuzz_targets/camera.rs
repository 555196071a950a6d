//! Camera JSON (one camera or a `frames` object), every frame it names.
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "files.rs"]
mod files;

fuzz_target!(|data: &[u8]| {
    files::with_files(&[("camera.json", data)], |dir| {
        if let Ok(source) = glassdb_scene::CameraSource::open(&dir.join("camera.json")) {
            let _ = source.camera(None);
            for frame in source.frames().unwrap_or_default().into_iter().take(8) {
                let _ = source.camera(Some(frame));
            }
        }
    });
});
