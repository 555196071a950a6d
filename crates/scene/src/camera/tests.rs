//! The camera against hand-computed Blender view planes (docs/scene.md; the formula of
//! `BKE_camera_params_compute_viewplane`, camera.cc), the old symmetric pinhole bit for bit,
//! `matrix_world` poses, and the errors of bad or contradicting fields.

use std::path::Path;

use super::*;

fn spec() -> CameraSpec {
    CameraSpec::look_at(
        [0.0, 0.0, 5.0],
        [0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        90.0,
        4,
        2,
    )
}

/// A camera at the origin looking down −z with Blender's lens settings: `focal` mm, sensor
/// fit AUTO, no shift, square pixels.
fn blender(size: (u32, u32), focal: f64) -> CameraSpec {
    CameraSpec {
        matrix_world: Some(IDENTITY),
        focal_length_mm: Some(focal),
        shift_x: Some(0.0),
        shift_y: Some(0.0),
        width: size.0,
        height: size.1,
        ..CameraSpec::default()
    }
}

/// [`blender`] with an explicit sensor fit.
fn fitted(size: (u32, u32), focal: f64, fit: SensorFit) -> CameraSpec {
    CameraSpec {
        sensor_fit: Some(fit),
        ..blender(size, focal)
    }
}

/// `spec` with Blender's Shift X and Y.
fn shifted(spec: CameraSpec, (x, y): (f64, f64)) -> CameraSpec {
    CameraSpec {
        shift_x: Some(x),
        shift_y: Some(y),
        ..spec
    }
}

/// `spec` with a pixel aspect (width over height).
fn aspect(spec: CameraSpec, pixel_aspect: f64) -> CameraSpec {
    CameraSpec {
        pixel_aspect: Some(pixel_aspect),
        ..spec
    }
}

const IDENTITY: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

fn view(s: &CameraSpec) -> [f64; 4] {
    let v = Camera::new(s, Path::new("c.json")).unwrap().view;
    [v.x_min, v.x_max, v.y_min, v.y_max]
}

/// The view plane of `spec` is `want` (to 1e-15 relative).
#[track_caller]
fn assert_view(spec: &CameraSpec, want: [f64; 4]) {
    let got = view(spec);
    for k in 0..4 {
        assert!(
            (got[k] - want[k]).abs() <= 1e-15 * want[k].abs().max(1.0),
            "view plane {got:?}, want {want:?}"
        );
    }
}

fn err(s: &CameraSpec) -> String {
    Camera::new(s, Path::new("c.json")).unwrap_err().to_string()
}

#[test]
fn frame_is_right_handed_and_projection_inverts_the_ray() {
    let c = Camera::new(&spec(), Path::new("c.json")).unwrap();
    assert_eq!(c.forward, [0.0, 0.0, -1.0]);
    assert_eq!(c.right, [1.0, 0.0, 0.0]);
    assert_eq!(c.up, [0.0, 1.0, 0.0]);
    // fov 90°: the point (5, 0, 0) lies at the right image edge x = width.
    let p = c.project(c.to_camera([5.0, 0.0, 0.0]));
    assert!(
        (p[0] - 4.0).abs() < 1e-12 && (p[1] - 1.0).abs() < 1e-12,
        "{p:?}"
    );
    // A point above the axis is in the upper half (smaller y, row 0 at the top).
    assert!(c.project(c.to_camera([0.0, 1.0, 0.0]))[1] < 1.0);
    let d = c.ray_direction(3.5, 0.5);
    let q = c.project(c.to_camera(math::add(c.origin, math::scale(d, 7.0))));
    assert!((q[0] - 3.5).abs() < 1e-12 && (q[1] - 0.5).abs() < 1e-12);
}

/// The pinhole before lens shift, verbatim: masks of existing camera files must not change.
struct OldPinhole {
    tan_half_x: f64,
    tan_half_y: f64,
    width: u32,
    height: u32,
}

impl OldPinhole {
    fn project(&self, c: Vec3) -> [f64; 2] {
        let w = self.width as f64;
        let h = self.height as f64;
        [
            (c[0] / (c[2] * self.tan_half_x) + 1.0) * 0.5 * w,
            (1.0 - c[1] / (c[2] * self.tan_half_y)) * 0.5 * h,
        ]
    }
    fn ray(&self, cam: &Camera, x: f64, y: f64) -> Vec3 {
        let sx = (x * 2.0 / self.width as f64 - 1.0) * self.tan_half_x;
        let sy = (1.0 - y * 2.0 / self.height as f64) * self.tan_half_y;
        math::add(
            cam.forward,
            math::add(math::scale(cam.right, sx), math::scale(cam.up, sy)),
        )
    }
}

#[test]
fn fov_cameras_project_bit_for_bit_as_the_symmetric_pinhole() {
    let s = CameraSpec::look_at(
        [-0.5, 1.6, 7.5],
        [-1.5, 2.1, -5.0],
        [0.0, 1.0, 0.0],
        80.0,
        320,
        240,
    );
    let cam = Camera::new(&s, Path::new("c.json")).unwrap();
    let t = (80f64.to_radians() / 2.0).tan();
    let old = OldPinhole {
        tan_half_x: t,
        tan_half_y: t * 240.0 / 320.0,
        width: 320,
        height: 240,
    };
    assert_eq!(
        [
            cam.view.x_min,
            cam.view.x_max,
            cam.view.y_min,
            cam.view.y_max
        ],
        [-t, t, -old.tan_half_y, old.tan_half_y]
    );
    for k in 0..500 {
        let a = k as f64 * 0.731;
        let c = [
            a.sin() * 3.0,
            (a * 1.7).cos() * 2.0,
            0.1 + (a * 0.3).sin().abs() * 9.0,
        ];
        assert_eq!(
            cam.project(c).map(f64::to_bits),
            old.project(c).map(f64::to_bits)
        );
        let (x, y) = ((a * 37.0) % 320.0, (a * 53.0) % 240.0);
        assert_eq!(
            cam.ray_direction(x, y).map(f64::to_bits),
            old.ray(&cam, x, y).map(f64::to_bits),
            "({x}, {y})"
        );
    }
}

#[test]
fn horizontal_fit_is_blenders_view_plane() {
    // 320×240, 50 mm on 36 mm: s = 36/(50·320); x ±160·s = ±0.36, y ±120·s = ±0.27.
    assert_view(
        &fitted((320, 240), 50.0, SensorFit::Horizontal),
        [-0.36, 0.36, -0.27, 0.27],
    );
    // Auto resolves to horizontal for a landscape frame: the same.
    assert_view(&blender((320, 240), 50.0), [-0.36, 0.36, -0.27, 0.27]);
}

#[test]
fn vertical_fit_uses_the_sensor_height() {
    // Vertical: sensor 24 mm over the 240 rows: s = 24/(50·240) = 0.002.
    assert_view(
        &fitted((320, 240), 50.0, SensorFit::Vertical),
        [-0.32, 0.32, -0.24, 0.24],
    );
    // A custom sensor height counts only for the vertical fit.
    let mut s = fitted((320, 240), 50.0, SensorFit::Vertical);
    s.sensor_height_mm = Some(12.0);
    assert_view(&s, [-0.16, 0.16, -0.12, 0.12]);
    s.sensor_fit = Some(SensorFit::Horizontal);
    assert_view(&s, [-0.36, 0.36, -0.27, 0.27]);
}

#[test]
fn auto_fit_of_a_portrait_frame_spans_the_sensor_width_vertically() {
    // 240×320: aspx·W < aspy·H, so vertical, but AUTO keeps sensor_x = 36 mm:
    // viewfac = 320, s = 36/(50·320) = 0.00225; x ±120·s, y ±160·s.
    assert_view(&blender((240, 320), 50.0), [-0.27, 0.27, -0.36, 0.36]);
    // An explicit vertical fit uses the 24 mm height instead.
    assert_view(
        &fitted((240, 320), 50.0, SensorFit::Vertical),
        [-0.18, 0.18, -0.24, 0.24],
    );
    // A square frame is horizontal under AUTO (aspx·W ≥ aspy·H).
    assert_view(&blender((100, 100), 36.0), [-0.5, 0.5, -0.5, 0.5]);
}

#[test]
fn shift_moves_the_view_plane_in_units_of_the_fitted_side() {
    // 320×240, 35 mm, horizontal: s = 36/(35·320) = 9/2800, viewfac = 320;
    // shift_x 0.25 → +80 px, shift_y −0.1 → −32 px:
    // x ∈ [(−160 + 80)·s, (160 + 80)·s] = [−9/35, 27/35],
    // y ∈ [(−120 − 32)·s, (120 − 32)·s] = [−171/350, 99/350].
    assert_view(
        &shifted(blender((320, 240), 35.0), (0.25, -0.1)),
        [-9.0 / 35.0, 27.0 / 35.0, -171.0 / 350.0, 99.0 / 350.0],
    );
    // Vertical fit: the shift is in units of the height (viewfac = 240, s = 0.002):
    // shift_x 0.5 → +120 px: x ∈ [−40·s, 280·s].
    assert_view(
        &shifted(fitted((320, 240), 50.0, SensorFit::Vertical), (0.5, 0.0)),
        [-0.08, 0.56, -0.24, 0.24],
    );
    // fov_x_deg shifts the same way, viewfac = W: centre 2·shift·tan(fov/2).
    let mut s = CameraSpec::look_at([0.0; 3], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0], 90.0, 200, 100);
    s.shift_x = Some(0.25);
    s.shift_y = Some(0.5);
    assert_view(&s, [-0.5, 1.5, 0.5, 1.5]);
}

#[test]
fn pixel_aspect_scales_the_image_height() {
    // 200×100 with pixels twice as wide as high (aspx 2, aspy 1): ycor = 0.5, horizontal;
    // s = 36/(50·200) = 0.0036: x ±100·s = ±0.36, y ±0.5·50·s = ±0.09.
    assert_view(
        &aspect(blender((200, 100), 50.0), 2.0),
        [-0.36, 0.36, -0.09, 0.09],
    );
    // 100×150, aspx 1, aspy 2: ycor = 2, aspx·W = 100 < aspy·H = 300: vertical with the
    // sensor width (AUTO); viewfac = 300, s = 36/(50·300) = 0.0024: x ±0.12, y ±150·s = ±0.36.
    assert_view(
        &aspect(blender((100, 150), 50.0), 0.5),
        [-0.12, 0.12, -0.36, 0.36],
    );
    // 100×100, aspy 2, shift (0.1, 0.2): vertical, viewfac = 200, s = 0.0036;
    // x ∈ [(−50 + 20)·s, (50 + 20)·s], y ∈ [(−100 + 40)·s, (100 + 40)·s].
    assert_view(
        &aspect(shifted(blender((100, 100), 50.0), (0.1, 0.2)), 0.5),
        [-0.108, 0.252, -0.216, 0.504],
    );
    // With fov_x_deg: x keeps tan(fov/2), y is ycor·H/W of it.
    let mut s = CameraSpec::look_at([0.0; 3], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0], 90.0, 200, 100);
    s.pixel_aspect = Some(2.0);
    assert_view(&s, [-1.0, 1.0, -0.25, 0.25]);
}

#[test]
fn fov_x_deg_is_the_horizontal_fit_of_the_same_lens() {
    // 50 mm on a 36 mm sensor: fov = 2·atan(18/50).
    let fov = 2.0 * (18.0f64 / 50.0).atan().to_degrees();
    for (size, shift) in [((320, 240), (0.0, 0.0)), ((240, 320), (0.3, -0.2))] {
        let mut a = shifted(fitted(size, 50.0, SensorFit::Horizontal), shift);
        let mut b = a.clone();
        b.focal_length_mm = None;
        b.sensor_fit = None;
        b.fov_x_deg = Some(fov);
        a.pixel_aspect = Some(1.0);
        let (va, vb) = (view(&a), view(&b));
        for k in 0..4 {
            assert!((va[k] - vb[k]).abs() < 1e-14, "{va:?} {vb:?}");
        }
    }
}

#[test]
fn pixels_sample_their_centres_on_the_shifted_view_plane() {
    let s = aspect(shifted(blender((320, 240), 35.0), (0.25, -0.1)), 1.5);
    let cam = Camera::new(&s, Path::new("c.json")).unwrap();
    let v = cam.view;
    for (i, j) in [(0, 0), (319, 239), (17, 200), (160, 120)] {
        // Identity pose: the ray at unit depth is (X, Y, −1).
        let d = cam.ray_direction(i as f64 + 0.5, j as f64 + 0.5);
        let want_x = v.x_min + (i as f64 + 0.5) / 320.0 * (v.x_max - v.x_min);
        let want_y = v.y_max - (j as f64 + 0.5) / 240.0 * (v.y_max - v.y_min);
        assert!((d[0] - want_x).abs() < 1e-15 && (d[1] - want_y).abs() < 1e-15);
        assert_eq!(d[2], -1.0);
        // And the projection returns the pixel centre.
        let p = cam.project(cam.to_camera(math::scale(d, 3.0)));
        assert!((p[0] - i as f64 - 0.5).abs() < 1e-10 && (p[1] - j as f64 - 0.5).abs() < 1e-10);
        let u = cam.pixel_ray(i, j);
        assert!((math::norm(u) - 1.0).abs() < 1e-15);
    }
    // The corners of the view plane are the image corners.
    let p = cam.project([v.x_min * 2.0, v.y_max * 2.0, 2.0]);
    assert!(p[0].abs() < 1e-12 && p[1].abs() < 1e-12, "{p:?}");
    let p = cam.project([v.x_max, v.y_min, 1.0]);
    assert!(
        (p[0] - 320.0).abs() < 1e-12 && (p[1] - 240.0).abs() < 1e-12,
        "{p:?}"
    );
}

/// Blender 3.4's default camera, `[list(r) for r in bpy.data.objects["Camera"].matrix_world]`.
const DEFAULT_CAMERA: [[f64; 4]; 4] = [
    [
        0.6859206557273865,
        -0.32401347160339355,
        0.6515582203865051,
        7.358891487121582,
    ],
    [
        0.7276763319969177,
        0.305420845746994,
        -0.6141703724861145,
        -6.925790786743164,
    ],
    [
        0.0,
        0.8953956365585327,
        0.44527140259742737,
        4.958309173583984,
    ],
    [0.0, 0.0, 0.0, 1.0],
];

fn with_matrix(m: [[f64; 4]; 4]) -> CameraSpec {
    CameraSpec {
        matrix_world: Some(m),
        fov_x_deg: Some(60.0),
        width: 64,
        height: 48,
        ..CameraSpec::default()
    }
}

#[test]
fn matrix_world_gives_blenders_axes_and_scale_is_normalised() {
    let c = Camera::new(&with_matrix(IDENTITY), Path::new("c.json")).unwrap();
    assert_eq!(
        (c.origin, c.forward, c.right, c.up),
        ([0.0; 3], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    );
    let plain = Camera::new(&with_matrix(DEFAULT_CAMERA), Path::new("c.json")).unwrap();
    assert_eq!(
        plain.origin,
        [7.358891487121582, -6.925790786743164, 4.958309173583984]
    );
    let col = |k: usize| {
        [
            DEFAULT_CAMERA[0][k],
            DEFAULT_CAMERA[1][k],
            DEFAULT_CAMERA[2][k],
        ]
    };
    for (got, want) in [
        (plain.right, col(0)),
        (plain.up, col(1)),
        (plain.forward, math::scale(col(2), -1.0)),
    ] {
        for k in 0..3 {
            assert!((got[k] - want[k]).abs() < 1e-6, "{got:?} {want:?}");
        }
    }
    // The frame is orthonormal and right-handed to rounding.
    assert!(math::dot(plain.right, plain.up).abs() < 1e-15);
    assert!(math::dot(plain.right, plain.forward).abs() < 1e-15);
    assert!((math::dot(math::cross(plain.forward, plain.up), plain.right) - 1.0).abs() < 1e-15);
    // Scale per axis (an object scaled 2, 3, 0.5) changes nothing.
    let mut scaled = DEFAULT_CAMERA;
    for row in scaled.iter_mut().take(3) {
        for (k, s) in [2.0, 3.0, 0.5].into_iter().enumerate() {
            row[k] *= s;
        }
    }
    let c = Camera::new(&with_matrix(scaled), Path::new("c.json")).unwrap();
    for (a, b) in [
        (c.right, plain.right),
        (c.up, plain.up),
        (c.forward, plain.forward),
    ] {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < 1e-15, "{a:?} {b:?}");
        }
    }
    // A point straight ahead lands in the image centre.
    let ahead = math::add(plain.origin, math::scale(plain.forward, 4.0));
    let p = c.project(c.to_camera(ahead));
    assert!(
        (p[0] - 32.0).abs() < 1e-9 && (p[1] - 24.0).abs() < 1e-9,
        "{p:?}"
    );
}

#[test]
fn bad_matrices_are_errors_naming_matrix_world() {
    let mut skewed = IDENTITY;
    skewed[0][1] = 0.1; // local Y leans towards X
    let mut mirrored = IDENTITY;
    mirrored[0][0] = -1.0;
    let mut flat = IDENTITY;
    flat[2][2] = 0.0;
    let mut projective = IDENTITY;
    projective[3][2] = 0.5;
    let mut nan = IDENTITY;
    nan[1][3] = f64::NAN;
    for (m, part) in [
        (skewed, "skewed"),
        (mirrored, "determinant"),
        (flat, "zero length"),
        (projective, "last row"),
        (nan, "non-finite"),
    ] {
        let e = err(&with_matrix(m));
        assert!(e.contains("matrix_world") && e.contains(part), "{e}");
        assert!(e.starts_with("camera c.json: "), "{e}");
    }
}

#[test]
fn bad_cameras_are_errors() {
    let mut s = spec();
    s.up = Some([0.0, 0.0, 2.0]);
    assert!(err(&s).contains("parallel"));
    let mut s = spec();
    s.width = 0;
    assert!(matches!(
        Camera::new(&s, Path::new("c.json")),
        Err(SceneError::BadImageSize { .. })
    ));
    let mut s = spec();
    s.fov_x_deg = Some(180.0);
    assert!(err(&s).contains("fov_x_deg"));
    let mut s = spec();
    s.target = s.origin;
    assert!(err(&s).contains("same point"));
    // Far apart: the distance overflows; said so, not "the same point".
    let mut s = spec();
    s.origin = Some([1e308, 0.0, 0.0]);
    let e = err(&s);
    assert!(
        e.contains("too far apart") && !e.contains("same point"),
        "{e}"
    );
    let mut s = spec();
    s.origin = Some([-1e308, 0.0, 0.0]);
    s.target = Some([1e308, 0.0, 0.0]);
    assert!(err(&s).contains("too far apart"));
}

#[test]
fn contradicting_or_missing_fields_are_errors_naming_the_field() {
    let cases: Vec<(CameraSpec, &[&str])> = vec![
        (
            CameraSpec {
                matrix_world: Some(IDENTITY),
                ..spec()
            },
            &["matrix_world", "origin", "target", "up"],
        ),
        (
            CameraSpec {
                focal_length_mm: Some(50.0),
                ..spec()
            },
            &["fov_x_deg", "focal_length_mm"],
        ),
        (
            CameraSpec {
                sensor_fit: Some(SensorFit::Vertical),
                ..spec()
            },
            &["sensor_fit", "fov_x_deg"],
        ),
        (
            CameraSpec {
                sensor_width_mm: Some(35.0),
                ..spec()
            },
            &["sensor_width_mm"],
        ),
        (
            CameraSpec {
                fov_x_deg: None,
                ..spec()
            },
            &["fov_x_deg", "focal_length_mm", "missing"],
        ),
        (
            CameraSpec {
                target: None,
                ..spec()
            },
            &["target is missing", "matrix_world"],
        ),
        (
            CameraSpec {
                pixel_aspect: Some(0.0),
                ..spec()
            },
            &["pixel_aspect"],
        ),
        (
            CameraSpec {
                shift_y: Some(f64::INFINITY),
                ..spec()
            },
            &["shift_y"],
        ),
        (blender((64, 48), -35.0), &["focal_length_mm"]),
        (
            CameraSpec {
                sensor_height_mm: Some(0.0),
                ..blender((64, 48), 35.0)
            },
            &["sensor_height_mm"],
        ),
        (blender((64, 48), 1e-320), &["view plane"]),
    ];
    for (s, parts) in cases {
        let e = err(&s);
        for p in parts {
            assert!(e.contains(p), "{e:?} lacks {p:?}");
        }
    }
}

#[test]
fn old_camera_json_reads_as_before_and_new_fields_parse() {
    let old = r#"{"origin": [0.3, 1.2, 4.0], "target": [0.5, 0.8, 0.0], "up": [0, 1, 0],
                  "fov_x_deg": 70, "width": 160, "height": 120}"#;
    let s: CameraSpec = serde_json::from_str(old).unwrap();
    assert_eq!(
        s,
        CameraSpec::look_at(
            [0.3, 1.2, 4.0],
            [0.5, 0.8, 0.0],
            [0.0, 1.0, 0.0],
            70.0,
            160,
            120
        )
    );
    // Written back, it is the same six keys.
    let v = serde_json::to_value(&s).unwrap();
    assert_eq!(v.as_object().unwrap().len(), 6);
    let new = r#"{"matrix_world": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]],
                  "focal_length_mm": 35, "sensor_width_mm": 36, "sensor_height_mm": 24,
                  "sensor_fit": "vertical", "shift_x": 0.1, "shift_y": -0.05,
                  "pixel_aspect": 1.0, "width": 1920, "height": 1080}"#;
    let s: CameraSpec = serde_json::from_str(new).unwrap();
    assert_eq!(s.sensor_fit, Some(SensorFit::Vertical));
    assert!(Camera::new(&s, Path::new("c.json")).is_ok());
    for bad in [
        r#"{"sensor_fit": "diagonal", "width": 1, "height": 1}"#,
        r#"{"fov_deg": 60, "width": 1, "height": 1}"#,
    ] {
        assert!(serde_json::from_str::<CameraSpec>(bad).is_err(), "{bad}");
    }
}

#[test]
fn animation_files_give_each_frame_its_camera_and_name_missing_or_bad_frames() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("anim.json");
    std::fs::write(
        &path,
        r#"{"frames": {
            "1": {"origin": [0,0,5], "target": [0,0,0], "up": [0,1,0], "fov_x_deg": 60, "width": 8, "height": 6},
            "2": {"origin": [1,0,5], "target": [0,0,0], "up": [0,1,0], "fov_x_deg": 60, "width": 8, "height": 6},
            "10": {"origin": [1,0,5], "target": [0,0,0], "up": [0,1,0], "fov": 60, "width": 8, "height": 6}
        }}"#,
    )
    .unwrap();
    let src = CameraSource::open(&path).unwrap();
    assert!(src.is_animated());
    assert_eq!(src.frames(), Some(vec![1, 2, 10]));
    assert_eq!(src.camera(Some(1)).unwrap().origin, [0.0, 0.0, 5.0]);
    assert_eq!(src.camera(Some(2)).unwrap().origin, [1.0, 0.0, 5.0]);
    let e = src.camera(Some(3)).unwrap_err().to_string();
    assert!(
        e.contains("frame 3") && e.contains("anim.json") && e.contains("1-2, 10"),
        "{e}"
    );
    let e = src.camera(Some(10)).unwrap_err().to_string();
    assert!(e.contains("frame 10") && e.contains("fov"), "{e}");
    assert!(matches!(
        src.camera(None),
        Err(SceneError::CameraNeedsFrame { .. })
    ));
    assert!(matches!(
        Camera::load(&path),
        Err(SceneError::CameraNeedsFrame { .. })
    ));
    // Keys that are not frame numbers, a frame given twice, and extra keys are refused.
    for (text, part) in [
        (r#"{"frames": {"one": {}}}"#, "\"one\""),
        (r#"{"frames": {"1": {}, "01": {}}}"#, "twice"),
        (r#"{"frames": {}}"#, "empty"),
        (r#"{"frames": {"1": {}}, "width": 3}"#, "width"),
        (r#"{"frames": [1, 2]}"#, "frame number"),
    ] {
        std::fs::write(&path, text).unwrap();
        let e = CameraSource::open(&path).unwrap_err().to_string();
        assert!(e.contains("anim.json") && e.contains(part), "{e}");
    }
}

#[test]
fn per_frame_files_name_the_frame_and_file() {
    let dir = tempfile::tempdir().unwrap();
    let one = r#"{"origin": [0,0,5], "target": [0,0,0], "up": [0,1,0], "fov_x_deg": 60, "width": 8, "height": 6}"#;
    std::fs::write(dir.path().join("cam.0001.json"), one).unwrap();
    std::fs::write(dir.path().join("cam.0002.json"), "{\"width\": 8}").unwrap();
    let src = CameraSource::open(&dir.path().join("cam.####.json")).unwrap();
    assert!(src.is_animated() && src.frames().is_none());
    assert!(src.camera(Some(1)).is_ok());
    let e = src.camera(Some(2)).unwrap_err().to_string();
    assert!(e.contains("cam.0002.json, frame 2"), "{e}");
    let e = src.camera(Some(3)).unwrap_err();
    assert!(
        matches!(e, SceneError::MissingCameraFrame { frame: 3, .. }),
        "{e:?}"
    );
    let e = e.to_string();
    assert!(e.contains("frame 3") && e.contains("cam.0003.json"), "{e}");
    // A single camera file is the same camera for every frame.
    let single = dir.path().join("cam.0001.json");
    let src = CameraSource::open(&single).unwrap();
    assert!(!src.is_animated());
    assert_eq!(src.camera(Some(7)).unwrap(), src.camera(None).unwrap());
}

#[test]
fn oversized_camera_files_are_refused_before_parsing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.json");
    let f = std::fs::File::create(&path).unwrap();
    f.set_len(MAX_CAMERA_FILE_BYTES + 10).unwrap();
    let e = CameraSource::open(&path).unwrap_err();
    let e = glassdb_io::ErrorChain(&e).to_string();
    assert!(e.contains("big.json") && e.contains("16 MiB"), "{e}");
}

#[test]
fn the_worked_example_of_docs_scene_md() {
    // 1920×1080, 35 mm on 36×24, auto, shift_y 0.1: horizontal, s = 36/(35·1920).
    let s = shifted(blender((1920, 1080), 35.0), (0.0, 0.1));
    let px = 36.0 / (35.0 * 1920.0);
    assert_view(&s, [-960.0 * px, 960.0 * px, -348.0 * px, 732.0 * px]);
    let [x_min, x_max, y_min, y_max] = view(&s);
    assert!((x_max - 0.514286).abs() < 5e-7 && (y_min + 0.186429).abs() < 5e-7);
    assert!((y_max - 0.392143).abs() < 5e-7);
    assert!((2.0 * x_max.atan().to_degrees() - 54.43).abs() < 5e-3);
    // Pixel (0, 0) (identity pose: d = (X, Y, −1)).
    let cam = Camera::new(&s, Path::new("c.json")).unwrap();
    let d = cam.ray_direction(0.5, 0.5);
    assert!(
        (d[0] + 0.514018).abs() < 5e-7 && (d[1] - 0.391875).abs() < 5e-7,
        "{d:?}"
    );
    assert!((x_min + 0.5 * px - d[0]).abs() < 1e-15);
}
