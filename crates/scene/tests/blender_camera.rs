//! glassdb's camera against Blender's own projection (Blender 3.4.1, the numbers in
//! fixtures/blender/cameras_b34.json, made by scripts/blender/camera_oracle.py): the view plane
//! Blender renders with (`Object.calc_matrix_camera`) and the image position of world points
//! (`bpy_extras.object_utils.world_to_camera_view`), for cameras with object scale, every
//! sensor fit, lens shift and pixel aspects ≠ 1. Blender computes in single precision, so the
//! tolerances are float32's.

use std::path::{Path, PathBuf};

use glassdb_scene::{Camera, CameraSpec};
use serde::Deserialize;

#[derive(Deserialize)]
struct Oracle {
    blender: String,
    cases: Vec<Case>,
}

#[derive(Deserialize)]
struct Case {
    camera: CameraSpec,
    view_plane: [f64; 4],
    points: Vec<Point>,
}

#[derive(Deserialize)]
struct Point {
    world: [f64; 3],
    depth: f64,
    pixel: [f64; 2],
}

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/blender/cameras_b34.json")
}

#[test]
fn cameras_project_as_blender_does() {
    let path = fixture();
    let oracle: Oracle = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert_eq!(oracle.blender, "3.4.1");
    assert!(oracle.cases.len() >= 12);
    let (mut worst_view, mut worst_px, mut points) = (0f64, 0f64, 0);
    for (k, case) in oracle.cases.iter().enumerate() {
        let cam = Camera::new(&case.camera, &path).unwrap_or_else(|e| panic!("case {k}: {e}"));
        let v = cam.view;
        let got = [v.x_min, v.x_max, v.y_min, v.y_max];
        for a in 0..4 {
            let want = case.view_plane[a];
            let err = (got[a] - want).abs() / want.abs().max(1.0);
            worst_view = worst_view.max(err);
            assert!(
                err < 1e-6,
                "case {k}: view plane {got:?}, Blender {:?}",
                case.view_plane
            );
        }
        for p in &case.points {
            let c = cam.to_camera(p.world);
            assert!(
                (c[2] - p.depth).abs() < 1e-5 * p.depth.abs().max(1.0),
                "case {k}: depth"
            );
            if c[2] <= 0.0 {
                continue;
            }
            let px = cam.project(c);
            let scale = (cam.width.max(cam.height)) as f64;
            for a in 0..2 {
                let err = (px[a] - p.pixel[a]).abs();
                worst_px = worst_px.max(err / scale);
                assert!(
                    err < 2e-6 * scale,
                    "case {k}, point {:?}: glassdb {px:?}, Blender {:?}",
                    p.world,
                    p.pixel
                );
            }
            points += 1;
        }
    }
    assert!(points >= 40, "{points} points in front of the cameras");
    eprintln!(
        "worst view-plane error {worst_view:e}, worst pixel error {worst_px:e} of the image size"
    );
}
