//! OBJ scenes with the MTL their `mtllib` names: load, then find the glass planes. The input is
//! the OBJ, a NUL byte, then scene.mtl (seeds are made that way by scripts/fuzz.sh).
#![no_main]
use libfuzzer_sys::fuzz_target;

#[path = "files.rs"]
mod files;

fuzz_target!(|data: &[u8]| {
    let (obj_bytes, mtl_bytes) = match data.iter().position(|&b| b == 0) {
        Some(k) => (&data[..k], &data[k + 1..]),
        None => (data, &[][..]),
    };
    files::with_files(
        &[("scene.obj", obj_bytes), ("scene.mtl", mtl_bytes)],
        |dir| {
            if let Ok(scene) = glassdb_scene::load_obj(&dir.join("scene.obj")) {
                // Every material whose name starts with "G" is glass.
                let is_glass = |m: Option<usize>| {
                    m.and_then(|i| scene.materials.get(i))
                        .is_some_and(|name| name.starts_with('G'))
                };
                let tol = glassdb_scene::PlaneTolerance::default_for(&scene);
                let _ = glassdb_scene::detect_planes(&scene, is_glass, tol, "G*");
            }
        },
    );
});
