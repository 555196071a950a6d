//! An animation whose camera sees only some of the scene's glass planes in some frames: the
//! tiny scene (two panes, plane 0 the clear one, plane 1 the bronze one) with its camera moved
//! so that frame 2 sees only plane 0 and frame 3 only plane 1. Once frame 2's mask was written
//! without its plane channel (every glass pixel on plane 0), and `glassdb blender render`,
//! `glassdb blender compose DIR`, `compose --frames` and `glassdb view DIR` all refused it: "mask
//! … stores no plane per pixel, but 2 reflection passes were given".

use std::path::Path;

use super::{
    assert_within_noise, background_blender, channel, copy_dir, json, make_glassdb_scene,
    render_test_glasses,
};
use crate::util::{glassdb, ok, read_exr_planes};

/// Moves the camera of the tiny scene `blend` (saved in place): frame 2 close in front of the
/// clear pane (y = 1) looking along +y, frame 3 looking along +x at the bronze pane (x = 1.5)
/// from where the clear pane lies outside the view (24 mm lens: 37° either side).
fn see_one_pane_per_frame(blend: &Path) {
    let script = "\
import bpy
from mathutils import Vector
scene = bpy.context.scene
cam = scene.camera
for frame, eye, target in ((2, (-0.5, -1.0, 1.0), (-0.5, 1.0, 1.0)),
                           (3, (-0.5, -0.5, 1.0), (1.5, -0.5, 1.0))):
    cam.location = eye
    cam.rotation_euler = (Vector(target) - Vector(eye)).to_track_quat('-Z', 'Y').to_euler()
    cam.keyframe_insert('location', frame=frame)
    cam.keyframe_insert('rotation_euler', frame=frame)
scene.frame_end = 3
bpy.ops.wm.save_mainfile()
";
    ok(background_blender(&[
        "--factory-startup".as_ref(),
        "-noaudio".as_ref(),
        blend.as_os_str(),
    ])
    .args(["--python-expr", script]));
}

/// `glassdb blender render` of `blend` into `out` with the tiny scene's glasses, seed `seed`,
/// the Cycles reference too, on one thread.
fn render(blend: &Path, out: &Path, seed: u32) -> String {
    ok(render_test_glasses(blend, out).args([
        "--threads",
        "1",
        "--reference",
        "--seed",
        &seed.to_string(),
    ]))
}

#[test]
fn frames_that_see_one_of_two_planes_composite_and_recomposite() {
    let dir = tempfile::tempdir().unwrap();
    let blend = dir.path().join("partial.blend");
    make_glassdb_scene("tiny", &blend, &[]);
    see_one_pane_per_frame(&blend);
    let runs = [dir.path().join("run0"), dir.path().join("run1")];
    for (seed, run) in runs.iter().enumerate() {
        let said = render(&blend, run, seed as u32);
        assert!(said.contains("3 frame(s), 2 glass plane(s)"), "{said}");
    }
    let run = &runs[0];

    // The frames see what the camera was moved to see: the record has no rectangle for the
    // plane a frame does not see, and each mask says which plane its glass is on.
    let record = json(&run.join("glassdb-blender.json"));
    for (frame, seen) in [(2usize, 0usize), (3, 1)] {
        let f = &record["frames"][frame - 1];
        let bounds = f["bounds"].as_array().unwrap();
        assert!(
            bounds[seen].is_object() && bounds[1 - seen].is_null(),
            "frame {frame}: {f}"
        );
        let mask = read_exr_planes(&run.join(format!("mask.{frame:04}.exr")));
        let (id, plane) = (channel(&mask, "id"), channel(&mask, "plane"));
        let on: Vec<f64> = (0..id.len())
            .filter(|&i| id[i] > 0.0)
            .map(|i| plane[i])
            .collect();
        assert!(on.len() > 200, "frame {frame}: {} glass pixels", on.len());
        assert!(
            on.iter().all(|&p| p == seen as f64),
            "frame {frame}: glass pixels off plane {seen}"
        );
    }
    // The composite agrees with Cycles on the frames that see one plane.
    let psnr = assert_within_noise(&runs, &[2, 3]);
    eprintln!("one plane of two in view, PSNR in glass per frame (dB): {psnr:.2?}");

    // Recomposited by `glassdb blender compose DIR` and by `compose --frames`: the same pixels.
    let again = dir.path().join("again");
    copy_dir(run, &again);
    let said = ok(glassdb().args(["blender", "compose"]).arg(&again));
    assert!(said.contains("composited 3 frame(s)"), "{said}");
    let pattern = |stem: &str| run.join(format!("{stem}.####.exr"));
    ok(glassdb()
        .args(["compose", "--frames", "1-3", "--refl"])
        .arg(pattern("refl_0"))
        .arg("--refl")
        .arg(pattern("refl_1"))
        .arg("--trans")
        .arg(pattern("trans"))
        .arg("--mask")
        .arg(pattern("mask"))
        .arg("--planes")
        .arg(run.join("planes.json"))
        .arg("--light-parts")
        .arg(run.join("light_parts.####.json"))
        .arg("-o")
        .arg(dir.path().join("frames.####.exr")));
    for frame in 1..=3 {
        let name = format!("composite.{frame:04}.exr");
        let want = read_exr_planes(&run.join(&name));
        for got in [
            read_exr_planes(&again.join(&name)),
            read_exr_planes(&dir.path().join(format!("frames.{frame:04}.exr"))),
        ] {
            assert_eq!(got.names, want.names, "frame {frame}");
            assert_eq!(got.channels, want.channels, "frame {frame}");
        }
    }

    // The viewer opens the run folder (its export decodes and composites every frame).
    let export = dir.path().join("export");
    let said = ok(glassdb().arg("view").arg(run).arg("--export").arg(&export));
    assert!(said.contains("wrote"), "{said}");
    for k in 0..3 {
        assert!(
            export.join(format!("frame-{k:04}.js")).is_file(),
            "frame {k}"
        );
    }
}
