//! End-to-end tests of the camera JSON of `glassdb mask` (docs/scene.md, "Camera JSON and
//! conventions"): lens shift as a crop of a wider frame, animations (one camera file per frame,
//! or one file with a `frames` object), and errors that name the file, frame and field.
//!
//! The crop identity. With a horizontal sensor fit the view plane at unit depth spans
//! `x ∈ [(−W/2 + shift_x·W)·s, (W/2 + shift_x·W)·s]` and `y ∈ [(−H/2 + shift_y·W)·s,
//! (H/2 + shift_y·W)·s]` with `s = sensor_width / (focal·W)`, the size of one pixel at unit
//! depth. A second camera with the same pose and pixel size `s` but `W + 2k` columns and
//! `H + 2m` rows (sensor width `s·focal·(W + 2k)`, no shift) spans `[−(W/2 + k)·s, (W/2 + k)·s]`
//! × `[−(H/2 + m)·s, (H/2 + m)·s]`; its column c starts at `−(W/2 + k)·s + c·s` and its row r
//! at `(H/2 + m)·s − r·s` from the top. So the unshifted W × H image is its columns `k … k + W`,
//! rows `m … m + H`, and `shift_x = k/W`, `shift_y = m/W` (k pixels right, m pixels up) gives
//! columns `2k … 2k + W`, rows `0 … H`: a shift of k pixels moves the image by exactly k pixels.
//! Every pixel of the shifted camera samples the same ray as its pixel in the wider frame, so
//! the masks agree sample for sample.

use std::path::{Path, PathBuf};

use crate::util::{
    Planes, assert_images_match, fails, fails_naming, mask_from, ok, read_exr_planes,
    read_png_planes, repo_path, run, write_file,
};

fn room() -> PathBuf {
    repo_path("fixtures/scene/room.obj")
}

/// `glassdb mask` of the room (both glasses) from `camera` into `out`.
fn mask(camera: &Path, out: &Path) -> std::process::Command {
    let mut c = mask_from(room(), camera);
    c.args(["--glass", "Clear*=1", "--glass", "Tinted*=2"])
        .arg("-o")
        .arg(out);
    c
}

/// The room's camera (fixtures/scene/camera.json's pose) with a 32 mm lens, horizontal fit.
fn lens_camera(sensor_width: f64, size: (u32, u32), shift: (f64, f64)) -> String {
    format!(
        r#"{{"origin": [0.3, 1.2, 4.0], "target": [0.5, 0.8, 0.0], "up": [0, 1, 0],
            "focal_length_mm": 32, "sensor_width_mm": {sensor_width}, "sensor_fit": "horizontal",
            "shift_x": {}, "shift_y": {}, "width": {}, "height": {}}}"#,
        shift.0, shift.1, size.0, size.1
    )
}

/// Columns `x0 … x0 + w`, rows `y0 … y0 + h` of every channel.
fn crop(p: &Planes, x0: usize, y0: usize, w: usize, h: usize) -> Planes {
    let channels = p
        .channels
        .iter()
        .map(|c| {
            (y0..y0 + h)
                .flat_map(|y| c[y * p.width + x0..y * p.width + x0 + w].iter().copied())
                .collect()
        })
        .collect();
    Planes {
        width: w,
        height: h,
        names: p.names.clone(),
        channels,
    }
}

/// Glass pixels (G, the id, non-zero) of a packed PNG mask.
fn glass_pixels(p: &Planes) -> usize {
    p.channels[1].iter().filter(|&&g| g != 0.0).count()
}

#[test]
fn a_shifted_camera_is_a_crop_of_a_wider_frame() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // W × H = 128 × 96, pixel size s = 32 mm / (32 mm · 128) at unit depth; k = 32, m = 16.
    let (w, h, k, m) = (128usize, 96usize, 32usize, 16usize);
    let cameras = [
        ("plain", lens_camera(32.0, (128, 96), (0.0, 0.0))),
        // shift_x = k/W = 0.25, shift_y = m/W = 0.125.
        ("shifted", lens_camera(32.0, (128, 96), (0.25, 0.125))),
        // W + 2k = 192 columns, H + 2m = 128 rows, sensor 32·192/128 = 48 mm: the same s.
        ("wide", lens_camera(48.0, (192, 128), (0.0, 0.0))),
    ];
    for (ext, read) in [
        ("png", read_png_planes as fn(&Path) -> Planes),
        ("exr", read_exr_planes as fn(&Path) -> Planes),
    ] {
        let mut masks = Vec::new();
        for (name, json) in &cameras {
            let cam = write_file(d, &format!("{name}.json"), json.as_bytes());
            let out = d.join(format!("{name}.{ext}"));
            let mut cmd = mask(&cam, &out);
            if ext == "exr" {
                cmd.args(["--samples", "3"]); // coverage from 3×3 sub-pixel rays as well
            }
            ok(&mut cmd);
            masks.push(read(&out));
        }
        let (plain, shifted, wide) = (&masks[0], &masks[1], &masks[2]);
        assert_eq!((wide.width, wide.height), (w + 2 * k, h + 2 * m));
        // ids, planes and cos θ codes (PNG) to the bit; float cos θ (EXR) to float rounding,
        // ids, planes and coverage exactly.
        let tolerance = if ext == "png" { 0.0 } else { 1e-6 };
        assert_images_match(
            &format!("shift_plain_{ext}"),
            plain,
            &crop(wide, k, m, w, h),
            tolerance,
        );
        assert_images_match(
            &format!("shift_shifted_{ext}"),
            shifted,
            &crop(wide, 2 * k, 0, w, h),
            tolerance,
        );
        if ext == "png" {
            // The shift shows glass the plain frame does not: the comparison is not vacuous.
            assert!(glass_pixels(shifted) > 1000 && glass_pixels(plain) > 1000);
            assert_ne!(glass_pixels(shifted), glass_pixels(plain));
        }
    }
}

/// Three cameras along a dolly, in the three JSON forms: look-at with a horizontal field of
/// view, look-at with a Blender lens and shift, and Blender's `matrix_world`.
fn dolly(frame: u32) -> String {
    let x = 0.1 * frame as f64;
    match frame {
        1 => format!(
            r#"{{"origin": [{x}, 1.2, 4.0], "target": [0.5, 0.8, 0.0], "up": [0, 1, 0],
                "fov_x_deg": 70, "width": 96, "height": 72}}"#
        ),
        2 => format!(
            r#"{{"origin": [{x}, 1.2, 4.0], "target": [0.5, 0.8, 0.0], "up": [0, 1, 0],
                "focal_length_mm": 24, "shift_y": 0.05, "width": 96, "height": 72}}"#
        ),
        // Looking down −z from (x, 1.2, 4), scaled ×2 (Blender normalises the axes).
        _ => format!(
            r#"{{"matrix_world": [[2, 0, 0, {x}], [0, 2, 0, 1.2], [0, 0, 2, 4.0], [0, 0, 0, 1]],
                "focal_length_mm": 20, "sensor_fit": "vertical", "pixel_aspect": 1.25,
                "width": 96, "height": 72}}"#
        ),
    }
}

#[test]
fn mask_frames_from_one_camera_file_per_frame_or_one_animation_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut singles = Vec::new();
    let mut animation = serde_json::Map::new();
    for f in 1..=3 {
        let json = dolly(f);
        write_file(d, &format!("cam.{f:04}.json"), json.as_bytes());
        let alone = write_file(d, &format!("alone{f}.json"), json.as_bytes());
        let out = d.join(format!("alone{f}.png"));
        ok(&mut mask(&alone, &out));
        singles.push(read_png_planes(&out));
        animation.insert(f.to_string(), serde_json::from_str(&json).unwrap());
    }
    // The three frames differ.
    assert_ne!(singles[0].channels, singles[1].channels);
    assert_ne!(singles[1].channels, singles[2].channels);

    let stdout =
        ok(mask(&d.join("cam.####.json"), &d.join("seq.####.png")).args(["--frames", "1-3"]));
    assert!(stdout.contains("frame 3:"), "{stdout}");
    let anim = write_file(
        d,
        "anim.json",
        serde_json::json!({ "frames": animation })
            .to_string()
            .as_bytes(),
    );
    // Every frame of an animation file when no --frames is given.
    ok(&mut mask(&anim, &d.join("anim.##.png")));
    for f in 1..=3usize {
        let want = &singles[f - 1];
        let seq = read_png_planes(&d.join(format!("seq.{f:04}.png")));
        assert_images_match(&format!("frames_seq_{f}"), &seq, want, 0.0);
        let from_anim = read_png_planes(&d.join(format!("anim.{f:02}.png")));
        assert_images_match(&format!("frames_anim_{f}"), &from_anim, want, 0.0);
    }
}

#[test]
fn missing_or_bad_frames_are_reported_and_the_others_go_on() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_file(d, "cam.0001.json", dolly(1).as_bytes());
    // Frame 2 contradicts itself: two lenses.
    let bad = dolly(2).replace(
        "\"focal_length_mm\"",
        "\"fov_x_deg\": 60, \"focal_length_mm\"",
    );
    write_file(d, "cam.0002.json", bad.as_bytes());
    write_file(d, "cam.0003.json", dolly(3).as_bytes());
    let (out, stdout, stderr) =
        run(mask(&d.join("cam.####.json"), &d.join("m.####.png")).args(["--frames", "1-4"]));
    assert_eq!(out.status.code(), Some(1), "{stdout}\n{stderr}");
    for part in [
        "frame 2: error: camera",
        "cam.0002.json, frame 2",
        "fov_x_deg and focal_length_mm",
        "frame 4",
        "cam.0004.json does not exist",
        "2 of 4 frame(s) failed: 2, 4",
    ] {
        assert!(stderr.contains(part), "{part:?} not in:\n{stderr}");
    }
    assert!(d.join("m.0001.png").exists() && d.join("m.0003.png").exists());
    assert!(!d.join("m.0002.png").exists() && !d.join("m.0004.png").exists());

    // An animation file without the frame asked for names the frame, the file and what it has.
    let anim = write_file(
        d,
        "anim.json",
        format!(r#"{{"frames": {{"1": {}, "2": {}}}}}"#, dolly(1), dolly(3)).as_bytes(),
    );
    fails_naming(
        mask(&anim, &d.join("a.####.png")).args(["--frames", "2-3"]),
        &[
            "frame 3",
            "anim.json",
            "its frames: 1-2",
            "1 of 2 frame(s) failed: 3",
        ],
    );
    assert!(d.join("a.0002.png").exists());
}

#[test]
fn camera_errors_name_the_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: [(&str, &str, &[&str]); 5] = [
        (
            "skew.json",
            r#"{"matrix_world": [[1, 0.3, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
                "fov_x_deg": 60, "width": 8, "height": 8}"#,
            &["skew.json", "matrix_world", "skewed"],
        ),
        (
            "mirror.json",
            r#"{"matrix_world": [[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
                "fov_x_deg": 60, "width": 8, "height": 8}"#,
            &["mirror.json", "matrix_world", "determinant"],
        ),
        (
            "both.json",
            r#"{"matrix_world": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
                "origin": [0, 0, 0], "fov_x_deg": 60, "width": 8, "height": 8}"#,
            &["both.json", "matrix_world", "origin"],
        ),
        (
            "sensor.json",
            r#"{"origin": [0, 1, 4], "target": [0, 1, 0], "up": [0, 1, 0], "fov_x_deg": 60,
                "sensor_fit": "vertical", "width": 8, "height": 8}"#,
            &["sensor.json", "sensor_fit", "fov_x_deg"],
        ),
        (
            "fit.json",
            r#"{"origin": [0, 1, 4], "target": [0, 1, 0], "up": [0, 1, 0],
                "focal_length_mm": 50, "sensor_fit": "diagonal", "width": 8, "height": 8}"#,
            &["fit.json", "diagonal"],
        ),
    ];
    for (name, json, parts) in cases {
        let cam = write_file(d, name, json.as_bytes());
        fails_naming(&mut mask(&cam, &d.join("m.png")), parts);
    }
    // Per-frame camera files need a frame list; several frames need a #### in the output.
    let cam = write_file(d, "c.0001.json", dolly(1).as_bytes());
    fails_naming(
        &mut mask(&d.join("c.####.json"), &d.join("m.png")),
        &["c.####.json", "--frames"],
    );
    fails_naming(
        mask(&cam, &d.join("m.png")).args(["--frames", "1-2"]),
        &["m.png", "####"],
    );
    let e = fails(mask(&cam, &d.join("m.png")).args(["--frames", "2-1"]));
    assert!(e.contains("hint: check --frames"), "{e}");
    assert!(!d.join("m.png").exists());
}

#[test]
fn masks_match_blenders_material_index_render() {
    // fixtures/blender/camera_render: a pane and a box, a camera keyframed over two frames with
    // object scale, Sensor Fit Vertical, Shift X/Y and Aspect X 1.2, exported by
    // scripts/blender/export_camera.py; Cycles' Material Index pass (Glass = 1) with one sample
    // at each pixel centre. Every pixel's glass must agree.
    let fixture = repo_path("fixtures/blender/camera_render");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mask.####.png");
    let mut c = mask_from(fixture.join("scene.obj"), fixture.join("camera.json"));
    c.args(["--glass", "Glass=1"]).arg("-o").arg(&out);
    ok(&mut c);
    let index: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixture.join("index_ma.json")).unwrap())
            .unwrap();
    assert_eq!(index["blender"], "3.4.1");
    for frame in 1..=2 {
        let rows = index["frames"][frame.to_string()].as_array().unwrap();
        let mask = read_png_planes(&dir.path().join(format!("mask.{frame:04}.png")));
        assert_eq!((mask.width, mask.height), (96, 64));
        let (mut glass, mut differ) = (0, Vec::new());
        for (y, row) in rows.iter().enumerate() {
            for (x, digit) in row.as_str().unwrap().bytes().enumerate() {
                let blender_glass = digit == b'1';
                let ours = mask.channels[1][y * mask.width + x] == 1.0;
                glass += usize::from(blender_glass);
                if blender_glass != ours {
                    differ.push((x, y));
                }
            }
        }
        assert!(glass > 1000, "frame {frame}: {glass} glass pixels");
        assert!(
            differ.is_empty(),
            "frame {frame}: pixels differ from Blender: {differ:?}"
        );
    }
}
