//! End-to-end tests of the scene commands: `glassdb mirror` and `glassdb mask` on the room
//! fixture (fixtures/scene/README.md). Expected values are hand-computed from the fixture's
//! geometry (planes z = 0 and x = 2, eye (0.3, 1.2, 4)).

use std::path::{Path, PathBuf};

use glassdb_mask::{CosTheta, MaskReadOptions, read_mask};

use crate::util::{fails, fails_naming, glassdb, mask_from, ok, repo_path, write_file};

fn room() -> PathBuf {
    repo_path("fixtures/scene/room.obj")
}

fn camera() -> PathBuf {
    repo_path("fixtures/scene/camera.json")
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Vertex positions and `usemtl` names of an OBJ written by `mirror`.
fn obj_summary(path: &Path) -> (Vec<[f64; 3]>, Vec<String>, Vec<String>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut v = Vec::new();
    let mut mtls = Vec::new();
    let mut libs = Vec::new();
    for l in text.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        match w.first() {
            Some(&"v") => v.push([
                w[1].parse().unwrap(),
                w[2].parse().unwrap(),
                w[3].parse().unwrap(),
            ]),
            Some(&"usemtl") => mtls.push(w[1].to_string()),
            Some(&"mtllib") => libs.push(w[1].to_string()),
            _ => {}
        }
    }
    (v, mtls, libs)
}

fn has_point(v: &[[f64; 3]], p: [f64; 3]) -> bool {
    v.iter()
        .any(|q| (0..3).all(|k| (q[k] - p[k]).abs() < 1e-12))
}

#[test]
fn mirror_finds_both_planes_and_writes_clipped_virtual_scenes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("virtual");
    let glass_and_eye = [
        "--glass-material",
        "Clear*",
        "--glass-material",
        "Tinted*",
        "--eye",
        "0.3,1.2,4",
    ];
    let stdout = ok(&mut mirror(&room(), &glass_and_eye, &out));
    assert!(stdout.contains("2 glass planes"), "{stdout}");
    let planes = json(&out.join("planes.json"));
    let p = planes["planes"].as_array().unwrap();
    assert_eq!(p.len(), 2);
    // Plane 0: z = 0 facing +z, area 2×2; plane 1: x = 2 facing −x, i.e. −x + 2 = 0.
    let eq = |k: usize| -> Vec<f64> {
        p[k]["equation"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    assert_eq!(eq(0), vec![0.0, 0.0, 1.0, 0.0]);
    assert_eq!(eq(1), vec![-1.0, 0.0, 0.0, 2.0]);
    assert_eq!(p[0]["area"].as_f64().unwrap(), 4.0);
    assert_eq!(p[1]["area"].as_f64().unwrap(), 4.0);
    assert_eq!(p[0]["materials"], serde_json::json!(["Clear_6mm"]));
    assert_eq!(p[1]["materials"], serde_json::json!(["Tinted_Grey"]));
    assert_eq!(p[0]["eye_side"], "front");
    assert_eq!(p[1]["eye_side"], "front");
    // Reflection across z = 0 is diag(1, 1, −1, 1); across x = 2 it is x ↦ 4 − x.
    assert_eq!(
        p[0]["reflection_matrix"],
        serde_json::json!([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, -1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0]
        ])
    );
    assert_eq!(
        p[1]["reflection_matrix"][0],
        serde_json::json!([-1.0, 0.0, 0.0, 4.0])
    );

    let (v, mtls, libs) = obj_summary(&out.join(p[0]["file"].as_str().unwrap()));
    // No glass in the virtual scene; the other materials are kept.
    assert!(
        !mtls
            .iter()
            .any(|m| m.starts_with("Clear") || m.starts_with("Tinted")),
        "{mtls:?}"
    );
    assert!(mtls.contains(&"Wood".to_string()) && mtls.contains(&"Concrete".to_string()));
    // The MTL reference resolves from the output directory.
    assert!(out.join(&libs[0]).exists(), "{libs:?}");
    // Everything kept was at z ≥ 0 and is now at z ≤ 0.
    assert!(v.iter().all(|q| q[2] <= 0.0), "{v:?}");
    // Known points: a box corner (0.3, 0.6, 1.1) ↦ (0.3, 0.6, −1.1); the floor is clipped at
    // the plane (new corners (±3, 0, 0)) and its far half (z < 0) is gone.
    assert!(has_point(&v, [0.3, 0.6, -1.1]));
    assert!(has_point(&v, [3.0, 0.0, 0.0]) && has_point(&v, [-3.0, 0.0, 0.0]));
    assert!(has_point(&v, [-3.0, 0.0, -3.0]) && !has_point(&v, [-3.0, 0.0, 3.0]));

    // Plane 1 (x = 2): the floor keeps x ≤ 2, mirrored to x ≥ 2 (x ↦ 4 − x): (−3, 0, 3) ↦ (7, 0, 3).
    let (v1, _, _) = obj_summary(&out.join(p[1]["file"].as_str().unwrap()));
    assert!(v1.iter().all(|q| q[0] >= 2.0 - 1e-12), "{v1:?}");
    assert!(has_point(&v1, [7.0, 0.0, 3.0]) && has_point(&v1, [2.0, 0.0, 3.0]));
}

#[test]
fn mirror_with_an_explicit_plane_and_the_eye_behind_it() {
    let dir = tempfile::tempdir().unwrap();
    // The plane y = 1 (normal +y), eye below it: the kept half-space is y ≤ 1.
    let plane_and_eye = ["--plane", "0,2,0,-2", "--eye", "0,0.5,3"];
    ok(&mut mirror(&room(), &plane_and_eye, dir.path()));
    let planes = json(&dir.path().join("planes.json"));
    assert_eq!(
        planes["planes"][0]["equation"],
        serde_json::json!([0.0, 1.0, 0.0, -1.0])
    );
    assert_eq!(planes["planes"][0]["eye_side"], "back");
    let (v, mtls, _) = obj_summary(&dir.path().join("plane_0.obj"));
    // Without --glass-material nothing is dropped: the windows are mirrored too (y ↦ 2 − y).
    assert!(mtls.contains(&"Clear_6mm".to_string()));
    assert!(v.iter().all(|q| q[1] >= 1.0 - 1e-12), "{v:?}");
    assert!(has_point(&v, [-1.0, 2.0, 0.0]) && has_point(&v, [-1.0, 1.0, 0.0]));
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The fixture camera (fixtures/scene/camera.json): its origin and its forward, right and up
/// unit vectors.
fn camera_frame() -> ([f64; 3], [f64; 3], [f64; 3], [f64; 3]) {
    let o = [0.3, 1.2, 4.0];
    let t = [0.5, 0.8, 0.0];
    let f = unit(sub(t, o));
    let r = unit(cross(f, [0.0, 1.0, 0.0]));
    let u = cross(r, f);
    (o, f, r, u)
}

/// The ray from the fixture camera's origin towards world point `p` and the pixel it falls
/// in, by the conventions of docs/scene.md (computed here from the camera JSON).
fn pixel_of(p: [f64; 3]) -> (u32, u32, [f64; 3]) {
    let (o, f, r, u) = camera_frame();
    let d = sub(p, o);
    let (x, y, z) = (dot(d, r), dot(d, u), dot(d, f));
    let tx = 35f64.to_radians().tan();
    let ty = tx * 120.0 / 160.0;
    let px = (x / z / tx + 1.0) * 80.0;
    let py = (1.0 - y / z / ty) * 60.0;
    (px.floor() as u32, py.floor() as u32, unit(d))
}

/// The exact cos θ at the centre of pixel (i, j) on a plane with normal `n`.
fn cos_at_pixel(i: u32, j: u32, n: [f64; 3]) -> f64 {
    let (_, f, r, u) = camera_frame();
    let tx = 35f64.to_radians().tan();
    let sx = ((i as f64 + 0.5) / 80.0 - 1.0) * tx;
    let sy = (1.0 - (j as f64 + 0.5) / 60.0) * tx * 0.75;
    let d = unit([
        f[0] + sx * r[0] + sy * u[0],
        f[1] + sx * r[1] + sy * u[1],
        f[2] + sx * r[2] + sy * u[2],
    ]);
    dot(d, n).abs()
}

/// `glassdb mask` of the room from `camera` with `--glass` mappings `glass`, into `out`.
fn mask_cmd(camera: &Path, glass: &[&str], out: &Path) -> std::process::Command {
    let mut c = glassdb();
    c.arg("mask").arg(room()).arg("--camera").arg(camera);
    for g in glass {
        c.args(["--glass", g]);
    }
    c.arg("-o").arg(out);
    c
}

/// `glassdb mirror <obj> [args…] --out-dir <out_dir>`.
fn mirror(obj: &Path, args: &[&str], out_dir: &Path) -> std::process::Command {
    let mut c = glassdb();
    c.arg("mirror")
        .arg(obj)
        .args(args)
        .arg("--out-dir")
        .arg(out_dir);
    c
}

fn mask_args(out: &Path) -> std::process::Command {
    mask_cmd(&camera(), &["Clear*=1", "Tinted*=2"], out)
}

#[test]
fn mask_png_has_ids_planes_occlusion_and_exact_cos() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mask.png");
    let stdout = ok(&mut mask_args(&out));
    assert!(stdout.contains("160x120"), "{stdout}");
    let m = read_mask(&out, &MaskReadOptions::default()).unwrap();
    assert_eq!((m.width, m.height), (160, 120));
    let CosTheta::Quantized8(codes) = &m.cos_theta else {
        panic!("8-bit PNG gives 8-bit codes")
    };
    let at = |i: u32, j: u32| (j * 160 + i) as usize;

    // Main window, upper part (not behind the box): id 1, plane 0, cos code = round(cos·255).
    let (i, j, _) = pixel_of([0.5, 1.5, 0.0]);
    assert_eq!((m.id[at(i, j)], m.plane[at(i, j)]), (1, 0));
    let expect = (cos_at_pixel(i, j, [0.0, 0.0, 1.0]) * 255.0).round() as u8;
    assert_eq!(codes[at(i, j)], expect);
    // The box (in front of the window's lower middle) hides the glass: id 0.
    let (i, j, _) = pixel_of([0.0, 0.45, 1.1]);
    assert_eq!(m.id[at(i, j)], 0);
    // ...but the window beside the box is glass.
    let (i, j, _) = pixel_of([-0.8, 0.3, 0.0]);
    assert_eq!(m.id[at(i, j)], 1);
    // Side window: id 2 on plane 1, normal −x.
    let (i, j, _) = pixel_of([2.0, 1.0, 0.5]);
    assert_eq!((m.id[at(i, j)], m.plane[at(i, j)]), (2, 1));
    let expect = (cos_at_pixel(i, j, [-1.0, 0.0, 0.0]) * 255.0).round() as u8;
    assert_eq!(codes[at(i, j)], expect);
    // The floor is not glass.
    let (i, j, _) = pixel_of([0.5, 0.0, 2.0]);
    assert_eq!(m.id[at(i, j)], 0);
    // Every glass pixel's code is the exact cos of its centre ray on its plane.
    let mut checked = 0;
    for j in 0..120 {
        for i in 0..160 {
            let k = at(i, j);
            let n = match m.id[k] {
                0 => continue,
                1 => [0.0, 0.0, 1.0],
                _ => [-1.0, 0.0, 0.0],
            };
            assert_eq!(
                codes[k],
                (cos_at_pixel(i, j, n) * 255.0).round() as u8,
                "pixel ({i}, {j})"
            );
            checked += 1;
        }
    }
    assert!(checked > 1000, "{checked}");
}

#[test]
fn mask_16_bit_and_exr_with_coverage_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("mask16.png");
    ok(mask_args(&png).args(["--format", "png16"]));
    let m16 = read_mask(&png, &MaskReadOptions::default()).unwrap();
    let CosTheta::Quantized16(c16) = &m16.cos_theta else {
        panic!("16-bit codes expected")
    };
    let (i, j, _) = pixel_of([0.5, 1.5, 0.0]);
    let k = (j * 160 + i) as usize;
    assert_eq!(
        c16[k],
        (cos_at_pixel(i, j, [0.0, 0.0, 1.0]) * 65535.0).round() as u16
    );

    let exr = dir.path().join("mask.exr");
    ok(mask_args(&exr).args(["--samples", "3"]));
    let m = read_mask(&exr, &MaskReadOptions::default()).unwrap();
    let cov = m.coverage.as_ref().expect("coverage channel");
    // Where the centre ray sees glass, the ids agree whatever the format; a pixel whose centre
    // misses the glass takes the glass most of its sub-pixel rays see, with partial coverage.
    for (k, (&a, &b)) in m.id.iter().zip(&m16.id).enumerate() {
        assert!(b == 0 || a == b, "pixel {k}: {a} vs {b}");
        assert!(
            a == b || (cov[k] > 0.0 && cov[k] < 1.0),
            "pixel {k}: {a} vs {b}, coverage {}",
            cov[k]
        );
    }
    let CosTheta::Float(c) = &m.cos_theta else {
        panic!("float cos expected")
    };
    assert!((c[k] as f64 - cos_at_pixel(i, j, [0.0, 0.0, 1.0])).abs() < 1e-6);
    // Inside the pane: full coverage; coverage is in ninths; some pixels are partly covered.
    assert_eq!(cov[k], 1.0);
    assert!(
        cov.iter()
            .all(|&x| (x * 9.0 - (x * 9.0).round()).abs() < 1e-5)
    );
    assert!(cov.iter().any(|&x| x > 0.0 && x < 1.0));
}

#[test]
fn mask_binary_is_the_papers_white_on_black_for_one_glass() {
    let dir = tempfile::tempdir().unwrap();
    let clear_only = |out: &Path| mask_cmd(&camera(), &["Clear*=1"], out);
    let packed = dir.path().join("packed.png");
    ok(&mut clear_only(&packed));
    let binary = dir.path().join("binary.png");
    ok(clear_only(&binary).args(["--format", "binary"]));
    let want = read_mask(&packed, &MaskReadOptions::default()).unwrap();
    let as_glass = |id| MaskReadOptions {
        binary_glass_id: Some(id),
        ..MaskReadOptions::default()
    };
    let got = read_mask(&binary, &as_glass(1)).unwrap();
    assert_eq!(
        got.id, want.id,
        "white exactly where the packed mask has glass 1"
    );
    assert_eq!(got.cos_theta, CosTheta::Normal);
    assert!(
        got.coverage.is_none(),
        "one sample per pixel: pure black and white"
    );
    assert!(want.id.iter().filter(|&&i| i == 1).count() > 1000);

    // With sub-pixel samples the pane's edges are grey (coverage), the inside white.
    let soft = dir.path().join("soft.png");
    ok(clear_only(&soft).args(["--format", "binary", "--samples", "3"]));
    let got = read_mask(&soft, &as_glass(1)).unwrap();
    let cov = got.coverage.expect("grey edges");
    assert!(cov.iter().any(|&c| c > 0.0 && c < 1.0));
    let (i, j, _) = pixel_of([0.5, 1.5, 0.0]);
    assert_eq!(cov[(j * 160 + i) as usize], 1.0);

    // Two glasses, or one glass on two planes, do not fit a binary mask.
    let err = fails(mask_args(&dir.path().join("two.png")).args(["--format", "binary"]));
    assert!(err.contains("one glass"), "{err}");
    let planes = dir.path().join("planes.png");
    let err = fails(mask_cmd(&camera(), &["*_*=1"], &planes).args(["--format", "binary"]));
    assert!(err.contains("one plane"), "{err}");
}

#[test]
fn mask_gouraud_is_close_to_exact_and_uses_the_mirror_planes() {
    let dir = tempfile::tempdir().unwrap();
    // Plane indices from planes.json, with the planes listed in the opposite order of
    // detection: the mask must follow the file.
    let planes = serde_json::json!({
        "format": "glassdb-planes/1", "source": "room.obj", "eye": null,
        "tolerance": {"angle_deg": 0.1, "distance": 1e-6},
        "planes": [
            {"index": 0, "equation": [-1.0, 0.0, 0.0, 2.0], "area": 4.0, "materials": ["Tinted_Grey"], "triangles": 2,
             "eye_side": "front", "reflection_matrix": [[-1.0,0.0,0.0,4.0],[0.0,1.0,0.0,0.0],[0.0,0.0,1.0,0.0],[0.0,0.0,0.0,1.0]],
             "file": "plane_0.obj", "triangles_written": 0, "triangles_clipped": 0},
            {"index": 1, "equation": [0.0, 0.0, 1.0, 0.0], "area": 4.0, "materials": ["Clear_6mm"], "triangles": 2,
             "eye_side": "front", "reflection_matrix": [[1.0,0.0,0.0,0.0],[0.0,1.0,0.0,0.0],[0.0,0.0,-1.0,0.0],[0.0,0.0,0.0,1.0]],
             "file": "plane_1.obj", "triangles_written": 0, "triangles_clipped": 0}
        ]
    });
    let pj = write_file(dir.path(), "planes.json", planes.to_string().as_bytes());
    let exact = dir.path().join("exact.exr");
    let gouraud = dir.path().join("gouraud.exr");
    ok(mask_args(&exact).arg("--planes").arg(&pj));
    ok(mask_args(&gouraud)
        .arg("--planes")
        .arg(&pj)
        .args(["--cos", "gouraud", "--mesh", "16"]));
    let a = read_mask(&exact, &MaskReadOptions::default()).unwrap();
    let b = read_mask(&gouraud, &MaskReadOptions::default()).unwrap();
    let (i, j, _) = pixel_of([0.5, 1.5, 0.0]);
    assert_eq!(
        a.plane[(j * 160 + i) as usize],
        1,
        "the main window is plane 1 in this planes.json"
    );
    let (i, j, _) = pixel_of([2.0, 1.0, 0.5]);
    assert_eq!(a.plane[(j * 160 + i) as usize], 0);
    assert_eq!(a.id, b.id);
    let (CosTheta::Float(ca), CosTheta::Float(cb)) = (&a.cos_theta, &b.cos_theta) else {
        panic!()
    };
    let worst = ca
        .iter()
        .zip(cb)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0f32, f32::max);
    // A 16×16 mesh over a 2 m pane at ~4 m: linear interpolation error well under 1/255.
    assert!(worst > 0.0 && worst < 1.0 / 255.0, "{worst}");
}

#[test]
fn bad_input_gives_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bad = write_file(
        d,
        "bad.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl Glass\nf 1 2 oops\n",
    );
    // A syntax error names file and line; no glass faces matched lists the materials that exist;
    // a degenerate plane and an eye on a glass plane are named.
    let mirror_cases: [(&Path, &[&str], &[&str]); 4] = [
        (&bad, &["--glass-material", "Glass"], &["bad.obj:5:"]),
        (
            &room(),
            &["--glass-material", "Window*"],
            &["Clear_6mm", "Wood", "Window*"],
        ),
        (&room(), &["--plane", "0,0,0,1"], &["degenerate plane"]),
        (
            &room(),
            &["--glass-material", "Clear*", "--eye", "0,1,0"],
            &["lies on glass plane 0"],
        ),
    ];
    for (obj, args, parts) in mirror_cases {
        fails_naming(&mut mirror(obj, args, &d.join("o")), parts);
    }
    let no_such_material = &mut mask_cmd(&camera(), &["Nope=1"], &d.join("m.png"));
    fails_naming(no_such_material, &["Concrete"]);
    // Camera with up parallel to the view direction, zero size, a misspelt key.
    let cameras: [(&str, &[u8], &[&str]); 3] = [
        (
            "up.json",
            br#"{"origin":[0,5,0],"target":[0,0,0],"up":[0,1,0],"fov_x_deg":60,"width":8,"height":8}"#,
            &["parallel"],
        ),
        (
            "zero.json",
            br#"{"origin":[0,1,4],"target":[0,1,0],"up":[0,1,0],"fov_x_deg":60,"width":0,"height":8}"#,
            &["0x8"],
        ),
        (
            "typo.json",
            br#"{"origin":[0,1,4],"target":[0,1,0],"up":[0,1,0],"fov_deg":60,"width":8,"height":8}"#,
            &["typo.json", "fov_deg"],
        ),
    ];
    for (name, json, parts) in cameras {
        let cam = write_file(d, name, json);
        fails_naming(&mut mask_cmd(&cam, &["Clear*=1"], &d.join("m.png")), parts);
    }
    // A coverage channel cannot go into a PNG; a bad --glass mapping is named.
    let e = fails(mask_args(&d.join("m.png")).args(["--samples", "2"]));
    assert!(e.contains("EXR") || e.contains(".exr"), "{e}");
    let no_id = &mut mask_cmd(&camera(), &["Clear*"], &d.join("m.png"));
    fails_naming(no_id, &["PATTERN=ID"]);
    // Nothing was written by the failed runs.
    assert!(!d.join("m.png").exists() && !d.join("o").join("planes.json").exists());
}

/// A scene with one U-shaped glass pane in the plane z = 0 (3 wide, 2 high, a 1 × 1 notch from
/// the top middle, x ∈ [1, 2], y ∈ [1, 2]) behind an opaque floor strip, with its materials in
/// two MTL files named on one `mtllib` line and a third on another; and a camera 4 units in
/// front of the pane, looking at it straight on (64 × 64 pixels, 60° wide).
fn u_pane_scene(dir: &Path) -> (PathBuf, PathBuf) {
    write_file(dir, "glass.mtl", b"newmtl Glass_U\nKd 0.9 0.9 0.9\n");
    write_file(dir, "wood.mtl", b"newmtl Wood\nKd 0.5 0.3 0.1\n");
    write_file(dir, "my stone.mtl", b"newmtl Stone\nKd 0.5 0.5 0.5\n");
    let obj = write_file(
        dir,
        "u.obj",
        b"mtllib glass.mtl wood.mtl\nmtllib my stone.mtl\n\
          v 0 0 0\nv 3 0 0\nv 3 2 0\nv 2 2 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n\
          v -1 -0.5 1\nv 4 -0.5 1\nv 4 -0.5 -1\nv -1 -0.5 -1\n\
          g pane\nusemtl Glass_U\nf 1 2 3 4 5 6 7 8\n\
          g floor\nusemtl Wood\nf 9 10 11 12\nusemtl Stone\nf 9 11 10\n",
    );
    let camera = write_file(
        dir,
        "u_camera.json",
        br#"{"origin": [1.5, 1.0, 4.0], "target": [1.5, 1.0, 0.0], "up": [0, 1, 0], "fov_x_deg": 60, "width": 64, "height": 64}"#,
    );
    (obj, camera)
}

#[test]
fn mask_of_a_u_shaped_pane_leaves_its_notch_clear() {
    let dir = tempfile::tempdir().unwrap();
    let (obj, camera) = u_pane_scene(dir.path());
    let out = dir.path().join("u.png");
    let mut cmd = mask_from(&obj, &camera);
    cmd.args(["--glass", "Glass*=3", "-o"]).arg(&out);
    let (status, _, stderr) = crate::util::run(&mut cmd);
    assert!(status.status.success(), "{stderr}");
    assert!(!stderr.contains("warning"), "{stderr}");
    let m = read_mask(&out, &MaskReadOptions::default()).unwrap();
    assert_eq!((m.width, m.height), (64, 64));
    // Where each pixel's centre ray meets z = 0 (the camera looks down −z; x right, y up).
    let t = 30f64.to_radians().tan();
    let (mut in_notch, mut in_pane) = (0, 0);
    for j in 0..64u32 {
        for i in 0..64u32 {
            let x = 1.5 + 4.0 * ((i as f64 + 0.5) / 32.0 - 1.0) * t;
            let y = 1.0 + 4.0 * (1.0 - (j as f64 + 0.5) / 32.0) * t;
            let id = m.id[(j * 64 + i) as usize];
            let inside = |lo: f64, hi: f64, v: f64| v > lo + 0.03 && v < hi - 0.03;
            if inside(1.0, 2.0, x) && inside(1.0, 2.0, y) {
                assert_eq!(
                    id, 0,
                    "pixel ({i}, {j}) at ({x:.3}, {y:.3}) in the notch is glass"
                );
                in_notch += 1;
            } else if inside(0.0, 3.0, x)
                && inside(0.0, 2.0, y)
                && !(inside(0.97, 2.03, x) && y > 0.97)
            {
                assert_eq!(
                    id, 3,
                    "pixel ({i}, {j}) at ({x:.3}, {y:.3}) on the pane is not glass"
                );
                in_pane += 1;
            }
        }
    }
    assert!(in_notch > 30 && in_pane > 150, "{in_notch} {in_pane}");
}

#[test]
fn mirror_refers_to_every_material_library_of_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let (obj, _) = u_pane_scene(dir.path());
    let out = dir.path().join("virtual");
    ok(&mut mirror(&obj, &["--glass-material", "Glass*"], &out));
    let text = std::fs::read_to_string(out.join("plane_0.obj")).unwrap();
    let libs: Vec<&str> = text
        .lines()
        .filter_map(|l| l.strip_prefix("mtllib "))
        .collect();
    assert_eq!(libs, ["../glass.mtl", "../wood.mtl", "../my stone.mtl"]);
    for lib in libs {
        assert!(out.join(lib).exists(), "{lib}");
    }
    // The pane's area is the U's (3·2 − 1), not its bounding rectangle's.
    let planes = json(&out.join("planes.json"));
    let area = planes["planes"][0]["area"].as_f64().unwrap();
    assert!((area - 5.0).abs() < 1e-9, "{area}");
}

/// Each plane's rectangle of glass pixels in a packed PNG mask (R plane, G id), computed here
/// from the decoded samples: (plane, [x_min, y_min, x_max, y_max], glass pixels).
fn png_mask_rectangles(path: &Path) -> Vec<(u16, [i64; 4], u64)> {
    let img = crate::util::read_png_planes(path);
    let mut found: std::collections::BTreeMap<u16, ([i64; 4], u64)> = Default::default();
    for y in 0..img.height {
        for x in 0..img.width {
            let k = y * img.width + x;
            if img.channels[1][k] == 0.0 {
                continue;
            }
            let (x, y) = (x as i64, y as i64);
            let e = found
                .entry(img.channels[0][k] as u16)
                .or_insert(([x, y, x, y], 0));
            e.0 = [e.0[0].min(x), e.0[1].min(y), e.0[2].max(x), e.0[3].max(y)];
            e.1 += 1;
        }
    }
    found.into_iter().map(|(p, (r, n))| (p, r, n)).collect()
}

/// The rectangles of a bounds file, checking its frame, size and Blender border on the way.
fn bounds_rectangles(path: &Path, frame: Option<u32>) -> Vec<(u16, [i64; 4], u64)> {
    let b = json(path);
    assert_eq!(b["format"], "glassdb-plane-bounds/1");
    assert_eq!(b["frame"], serde_json::json!(frame));
    let (w, h) = (b["width"].as_i64().unwrap(), b["height"].as_i64().unwrap());
    // Blender's edge rule: `int(fraction · size)`, the fraction stored and multiplied in float32.
    let blender_edge = |fraction: &serde_json::Value, size: i64| -> i64 {
        ((fraction.as_f64().unwrap() as f32) * size as f32) as i64
    };
    b["planes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let r: Vec<i64> = p["data_window"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_i64().unwrap())
                .collect();
            let border = &p["blender_border"];
            // Blender's border is y-up, in fractions of the frame; truncated as Blender does,
            // it gives exactly the rectangle.
            let edges = [
                blender_edge(&border["min_x"], w),
                h - blender_edge(&border["max_y"], h),
                blender_edge(&border["max_x"], w) - 1,
                h - blender_edge(&border["min_y"], h) - 1,
            ];
            assert_eq!(edges.to_vec(), r, "{}", path.display());
            (
                p["plane"].as_u64().unwrap() as u16,
                [r[0], r[1], r[2], r[3]],
                p["glass_pixels"].as_u64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn mask_bounds_give_each_planes_glass_rectangle_per_frame() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mask.png");
    let bounds = dir.path().join("bounds.json");
    ok(mask_args(&out).arg("--bounds").arg(&bounds));
    let want = png_mask_rectangles(&out);
    assert_eq!(want.len(), 2, "both windows are in view");
    assert_eq!(bounds_rectangles(&bounds, None), want);

    // An animation: the camera steps right, so the rectangles move; one file per frame.
    let cam = json(&camera());
    let mut frames = serde_json::Map::new();
    for (frame, dx) in [(1, 0.0), (2, 0.4)] {
        let mut c = cam.clone();
        c["origin"][0] = serde_json::json!(c["origin"][0].as_f64().unwrap() + dx);
        frames.insert(frame.to_string(), c);
    }
    let anim = write_file(
        dir.path(),
        "anim.json",
        serde_json::json!({ "frames": frames })
            .to_string()
            .as_bytes(),
    );
    let masks = dir.path().join("m.####.png");
    ok(mask_cmd(&anim, &["Clear*=1", "Tinted*=2"], &masks)
        .arg("--bounds")
        .arg(dir.path().join("b.####.json")));
    let mut seen = Vec::new();
    for frame in [1, 2] {
        let m = dir.path().join(format!("m.{frame:04}.png"));
        let b = dir.path().join(format!("b.{frame:04}.json"));
        let rects = bounds_rectangles(&b, Some(frame));
        assert_eq!(rects, png_mask_rectangles(&m), "frame {frame}");
        seen.push(rects);
    }
    assert_ne!(seen[0], seen[1], "the camera moved");

    // A pattern on one side only would put every frame's bounds in one file.
    fails_naming(
        mask_cmd(&anim, &["Clear*=1"], &masks)
            .arg("--bounds")
            .arg(dir.path().join("b.json")),
        &["--bounds", "####"],
    );
}
