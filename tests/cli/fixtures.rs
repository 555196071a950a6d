//! The committed fixtures that glassdb itself makes are regenerated from their sources and
//! compared: the atrium's virtual scenes and `planes.json` (`glassdb mirror`), and its masks
//! (`glassdb mask`, from `atrium.obj` and `camera.json`), exactly as `fixtures/atrium/README.md`
//! states. `GLASSDB_MAKE_REF=1` writes them anew instead (then `git diff` shows what changed).

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::util::{
    assert_images_match, glassdb, make_ref, names, ok, read_exr_planes, read_png_planes, repo_path,
    repo_root,
};

const ATRIUM: &str = "fixtures/atrium";

/// `glassdb` run from the repository root, so that the paths recorded in outputs
/// (`planes.json`'s `source`) are the repository-relative ones the README gives.
fn glassdb_at_root() -> Command {
    let mut c = glassdb();
    c.current_dir(repo_root());
    c
}

/// `glassdb mirror` as the atrium README states it, into `out_dir`.
fn mirror_atrium(out_dir: &Path) {
    ok(glassdb_at_root()
        .arg("mirror")
        .arg(format!("{ATRIUM}/atrium.obj"))
        .args(["--glass-material", "Glass*", "--eye", "-0.5,1.6,7.5"])
        .arg("--out-dir")
        .arg(out_dir));
}

/// `glassdb mask` as the atrium README states it, into `out` (format by extension); the EXR
/// mask carries coverage from 4×4 sub-pixel rays.
fn mask_atrium(out: &Path) {
    let mut c = glassdb_at_root();
    c.arg("mask")
        .arg(format!("{ATRIUM}/atrium.obj"))
        .arg("--camera")
        .arg(format!("{ATRIUM}/camera.json"))
        .arg("--planes")
        .arg(format!("{ATRIUM}/virtual/planes.json"))
        .args(["--glass", "GlassClear=1", "--glass", "GlassTinted=5"])
        .arg("-o")
        .arg(out);
    if out.extension().is_some_and(|e| e == "exr") {
        c.args(["--samples", "4"]);
    }
    ok(&mut c);
}

/// The lines of a virtual-scene OBJ, with its `mtllib` resolved against the file's folder (the
/// relative path differs with where the file is written; the library it names must not).
fn obj_lines(path: &Path) -> Vec<String> {
    let text =
        std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let dir = path.parent().unwrap();
    text.lines()
        .map(|line| match line.strip_prefix("mtllib ") {
            Some(lib) => {
                let resolved: PathBuf = dir.join(lib.trim());
                let canonical = resolved
                    .canonicalize()
                    .unwrap_or_else(|e| panic!("{}: mtllib {lib}: {e}", path.display()));
                format!("mtllib {}", canonical.display())
            }
            None => line.to_string(),
        })
        .collect()
}

#[test]
fn atrium_virtual_scenes_regenerate_from_the_scene() {
    let committed = repo_path(ATRIUM).join("virtual");
    if make_ref() {
        mirror_atrium(&committed);
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let fresh = dir.path().join("virtual");
    mirror_atrium(&fresh);
    let fresh_names = names(&fresh);
    let names = names(&committed);
    assert_eq!(
        fresh_names, names,
        "mirror writes other files than are committed"
    );
    for name in &names {
        let (want, got) = (committed.join(name), fresh.join(name));
        if name.ends_with(".obj") {
            let (w, g) = (obj_lines(&want), obj_lines(&got));
            assert_eq!(g.len(), w.len(), "{name}: line count");
            for (k, (gl, wl)) in g.iter().zip(&w).enumerate() {
                assert_eq!(gl, wl, "{name}, line {}", k + 1);
            }
        } else {
            let read = |p: &Path| -> serde_json::Value {
                serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
            };
            assert_eq!(
                read(&got),
                read(&want),
                "{name} differs from the committed one"
            );
        }
    }
}

#[test]
fn atrium_masks_regenerate_from_the_scene_and_camera() {
    for name in ["mask.png", "mask.exr"] {
        let committed = repo_path(ATRIUM).join(name);
        if make_ref() {
            mask_atrium(&committed);
            continue;
        }
        let dir = tempfile::tempdir().unwrap();
        let fresh = dir.path().join(name);
        mask_atrium(&fresh);
        let (got, want) = if name.ends_with(".png") {
            (read_png_planes(&fresh), read_png_planes(&committed))
        } else {
            (read_exr_planes(&fresh), read_exr_planes(&committed))
        };
        // The mask is exact: ids, planes and cos θ codes must agree to the bit.
        assert_images_match(&format!("atrium_{name}"), &got, &want, 0.0);
    }
}
