//! The camera JSON as written by users (docs/scene.md, "Camera JSON and conventions") and its
//! validation: the pose (look-at or Blender's `matrix_world`) and the view plane (a horizontal
//! field of view, or Blender's focal length, sensor and sensor fit; lens shift; pixel aspect).
//!
//! The view plane follows Blender's `BKE_camera_params_compute_viewplane`
//! (source/blender/blenkernel/intern/camera.cc; read at blender/blender 019b78cc, lines 312–333
//! for `BKE_camera_sensor_size` / `BKE_camera_sensor_fit` and 457–517 for the viewplane) for a
//! perspective camera, divided by the clip start (so at unit depth), without the viewport's zoom
//! and offset; checked numerically against Blender 3.4.1 in tests/blender_camera.rs:
//!
//! ```text
//! ycor        = aspy / aspx                       (1 / pixel_aspect)
//! sensor_size = sensor_fit == VERTICAL ? sensor_y : sensor_x      (AUTO uses sensor_x)
//! fit         = AUTO ? (aspx·W ≥ aspy·H ? HORIZONTAL : VERTICAL) : sensor_fit
//! viewfac     = fit == HORIZONTAL ? W : ycor·H
//! s           = sensor_size / (lens · viewfac)    (pixsize at unit depth)
//! x ∈ [(−W/2 + shift_x·viewfac)·s, (W/2 + shift_x·viewfac)·s]
//! y ∈ [(−ycor·H/2 + shift_y·viewfac)·s, (ycor·H/2 + shift_y·viewfac)·s]
//! ```

use serde::{Deserialize, Serialize};

use crate::math::{self, Vec3};

/// Blender's Sensor Fit (`Camera.sensor_fit`): which image side the sensor size spans.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SensorFit {
    /// The larger side of the image (in pixel-aspect-corrected units) spans the sensor
    /// *width*, whichever side that is.
    #[default]
    Auto,
    /// The image width spans the sensor width.
    Horizontal,
    /// The image height spans the sensor height.
    Vertical,
}

/// The camera JSON as written by users. Pose: `origin` + `target` + `up`, or `matrix_world`.
/// Lens: `fov_x_deg`, or `focal_length_mm` with the optional sensor fields. The remaining fields
/// are optional (defaults as in Blender). `None` means absent from the JSON.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// The eye, world units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin: Option<Vec3>,
    /// A point the camera looks at.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<Vec3>,
    /// Fixes the roll: the image's up is `up` made perpendicular to the view direction.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Vec3>,
    /// Blender's `camera.matrix_world`: 4×4 camera-to-world, row-major (`[list(r) for r in
    /// m]`); the camera looks down its local −Z with local +Y up. Scale is allowed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix_world: Option<[[f64; 4]; 4]>,
    /// Full horizontal field of view, degrees (0 < fov < 180).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fov_x_deg: Option<f64>,
    /// Blender's Focal Length (`Camera.lens`), millimetres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focal_length_mm: Option<f64>,
    /// Blender's sensor Width (`Camera.sensor_width`), millimetres; default 36.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor_width_mm: Option<f64>,
    /// Blender's sensor Height (`Camera.sensor_height`), millimetres; default 24.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor_height_mm: Option<f64>,
    /// Blender's Sensor Fit; default `auto`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor_fit: Option<SensorFit>,
    /// Blender's Shift X (`Camera.shift_x`), in units of the fitted image side; default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shift_x: Option<f64>,
    /// Blender's Shift Y (`Camera.shift_y`), in units of the fitted image side; default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shift_y: Option<f64>,
    /// Blender's pixel Aspect X / Aspect Y (`RenderSettings.pixel_aspect_x / pixel_aspect_y`):
    /// a pixel's width over its height; default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pixel_aspect: Option<f64>,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
}

/// The validated lens.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Lens {
    /// Full horizontal field of view in degrees (Blender's horizontal fit with
    /// `sensor/lens = 2·tan(fov/2)`).
    FovX { fov_x_deg: f64 },
    /// Blender's perspective lens.
    Blender {
        focal_length_mm: f64,
        sensor_width_mm: f64,
        sensor_height_mm: f64,
        sensor_fit: SensorFit,
    },
}

/// Blender's default sensor width and height, millimetres (`DEFAULT_SENSOR_WIDTH`/`_HEIGHT`).
pub const DEFAULT_SENSOR_WIDTH_MM: f64 = 36.0;
pub const DEFAULT_SENSOR_HEIGHT_MM: f64 = 24.0;

/// Off-perpendicularity of `matrix_world`'s axes accepted (cosine of the angle between two
/// normalised axes): float32 matrices printed by Blender are orthogonal to ~1e-7.
pub const MATRIX_SKEW_TOLERANCE: f64 = 1e-5;

/// The camera's position and orthonormal frame.
pub(super) struct Pose {
    pub(super) origin: Vec3,
    pub(super) forward: Vec3,
    pub(super) right: Vec3,
    pub(super) up: Vec3,
}

/// `Ok` when `v` is finite and strictly positive.
fn positive(name: &str, v: f64) -> Result<f64, String> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("{name} {v} must be a finite number above 0"))
    }
}

impl CameraSpec {
    /// A look-at camera with a horizontal field of view and no other option: the JSON of
    /// `{"origin", "target", "up", "fov_x_deg", "width", "height"}`.
    pub fn look_at(
        origin: Vec3,
        target: Vec3,
        up: Vec3,
        fov_x_deg: f64,
        width: u32,
        height: u32,
    ) -> CameraSpec {
        CameraSpec {
            origin: Some(origin),
            target: Some(target),
            up: Some(up),
            fov_x_deg: Some(fov_x_deg),
            width,
            height,
            ..CameraSpec::default()
        }
    }

    /// The pose from exactly one of the two forms; errors name the field.
    pub(super) fn pose(&self) -> Result<Pose, String> {
        let look_at = [
            ("origin", self.origin),
            ("target", self.target),
            ("up", self.up),
        ];
        match self.matrix_world {
            Some(m) => {
                let given: Vec<&str> = look_at
                    .iter()
                    .filter(|(_, v)| v.is_some())
                    .map(|(n, _)| *n)
                    .collect();
                if !given.is_empty() {
                    return Err(format!(
                        "matrix_world and {} both give the pose: give either matrix_world or \
                         origin, target and up",
                        given.join(", ")
                    ));
                }
                pose_from_matrix(&m)
            }
            None => {
                let mut v = [[0.0; 3]; 3];
                for (k, (name, value)) in look_at.iter().enumerate() {
                    v[k] = value.ok_or_else(|| {
                        format!(
                            "{name} is missing: the pose is origin, target and up, or matrix_world"
                        )
                    })?;
                    if !math::is_finite(v[k]) {
                        return Err(format!("{name} {:?} is not finite", v[k]));
                    }
                }
                pose_look_at(v[0], v[1], v[2])
            }
        }
    }

    /// The lens from exactly one of the two forms; errors name the field.
    pub(super) fn lens(&self) -> Result<Lens, String> {
        match (self.fov_x_deg, self.focal_length_mm) {
            (Some(_), Some(_)) => Err(
                "fov_x_deg and focal_length_mm both give the lens: give one of them".to_string(),
            ),
            (None, None) => Err(
                "the lens is missing: give fov_x_deg, or focal_length_mm (with sensor_width_mm, \
                 sensor_height_mm, sensor_fit if not Blender's defaults)"
                    .to_string(),
            ),
            (Some(fov), None) => {
                let sensor_fields = [
                    ("sensor_width_mm", self.sensor_width_mm.is_some()),
                    ("sensor_height_mm", self.sensor_height_mm.is_some()),
                    ("sensor_fit", self.sensor_fit.is_some()),
                ];
                if let Some((name, _)) = sensor_fields.iter().find(|(_, given)| *given) {
                    return Err(format!(
                        "{name} applies to focal_length_mm, but fov_x_deg is given (the \
                         horizontal field of view already fixes the lens): give focal_length_mm \
                         instead, or drop {name}"
                    ));
                }
                if !(fov.is_finite() && fov > 0.0 && fov < 180.0) {
                    return Err(format!(
                        "fov_x_deg {fov} must be strictly between 0 and 180"
                    ));
                }
                Ok(Lens::FovX { fov_x_deg: fov })
            }
            (None, Some(focal)) => Ok(Lens::Blender {
                focal_length_mm: positive("focal_length_mm", focal)?,
                sensor_width_mm: positive(
                    "sensor_width_mm",
                    self.sensor_width_mm.unwrap_or(DEFAULT_SENSOR_WIDTH_MM),
                )?,
                sensor_height_mm: positive(
                    "sensor_height_mm",
                    self.sensor_height_mm.unwrap_or(DEFAULT_SENSOR_HEIGHT_MM),
                )?,
                sensor_fit: self.sensor_fit.unwrap_or_default(),
            }),
        }
    }

    /// The view plane at unit depth as (centre, half-extent) per axis; errors name the field.
    pub(super) fn window(&self) -> Result<([f64; 2], [f64; 2]), String> {
        let lens = self.lens()?;
        let mut shift = [0.0; 2];
        for (k, (name, v)) in [("shift_x", self.shift_x), ("shift_y", self.shift_y)]
            .into_iter()
            .enumerate()
        {
            shift[k] = v.unwrap_or(0.0);
            if !shift[k].is_finite() {
                return Err(format!("{name} {} is not finite", shift[k]));
            }
        }
        let aspect = positive("pixel_aspect", self.pixel_aspect.unwrap_or(1.0))?;
        let (centre, half) = view_window(&lens, shift, aspect, self.width, self.height);
        let ok =
            centre.iter().all(|c| c.is_finite()) && half.iter().all(|h| h.is_finite() && *h > 0.0);
        if !ok {
            return Err(format!(
                "the lens gives no usable view plane (centre {centre:?}, half-extent {half:?} at \
                 unit depth): check focal_length_mm, the sensor size, shift_x, shift_y and \
                 pixel_aspect"
            ));
        }
        Ok((centre, half))
    }
}

/// Blender's view plane at unit depth (module docs) as (centre, half-extent) per axis, for a
/// `width`×`height` image whose pixels are `pixel_aspect` (aspx/aspy) wide per unit of height.
/// For [`Lens::FovX`] this is the horizontal fit with `s·W/2 = tan(fov/2)`; the half-extents are
/// computed exactly as the symmetric pinhole always did (`tan`, `tan·H/W`).
pub(super) fn view_window(
    lens: &Lens,
    shift: [f64; 2],
    pixel_aspect: f64,
    width: u32,
    height: u32,
) -> ([f64; 2], [f64; 2]) {
    let (w, h) = (width as f64, height as f64);
    let ycor = 1.0 / pixel_aspect;
    match *lens {
        Lens::FovX { fov_x_deg } => {
            let t = (fov_x_deg.to_radians() / 2.0).tan();
            // viewfac = W and s = 2t/W: shift·viewfac·s = 2·shift·t.
            (
                [2.0 * shift[0] * t, 2.0 * shift[1] * t],
                [t, t * ycor * h / w],
            )
        }
        Lens::Blender {
            focal_length_mm,
            sensor_width_mm,
            sensor_height_mm,
            sensor_fit,
        } => {
            // BKE_camera_sensor_size: AUTO uses the width, even where it resolves to vertical.
            let sensor_size = match sensor_fit {
                SensorFit::Vertical => sensor_height_mm,
                SensorFit::Auto | SensorFit::Horizontal => sensor_width_mm,
            };
            // BKE_camera_sensor_fit(AUTO, aspx·W, aspy·H): horizontal when aspx·W ≥ aspy·H,
            // i.e. W ≥ ycor·H (at equality both fits give the same viewfac).
            let horizontal = match sensor_fit {
                SensorFit::Auto => w >= ycor * h,
                SensorFit::Horizontal => true,
                SensorFit::Vertical => false,
            };
            let viewfac = if horizontal { w } else { ycor * h };
            let s = sensor_size / (focal_length_mm * viewfac);
            (
                [shift[0] * viewfac * s, shift[1] * viewfac * s],
                [0.5 * w * s, 0.5 * ycor * h * s],
            )
        }
    }
}

/// The look-at frame: forward towards the target, right = forward × up, up = right × forward.
fn pose_look_at(origin: Vec3, target: Vec3, up: Vec3) -> Result<Pose, String> {
    let towards = math::sub(target, origin);
    let forward = math::normalize(towards).ok_or_else(|| {
        if towards == [0.0; 3] {
            "origin and target are the same point: no view direction".to_string()
        } else if !math::is_finite(towards) || !math::norm(towards).is_finite() {
            format!(
                "origin {origin:?} and target {target:?} are too far apart: their distance \
                 overflows double precision (give coordinates below about 1e150)"
            )
        } else {
            format!(
                "origin {origin:?} and target {target:?} are too close: their distance \
                 underflows double precision"
            )
        }
    })?;
    let up_in = math::normalize(up).ok_or_else(|| "up is the zero vector".to_string())?;
    let side = math::cross(forward, up_in);
    if math::norm(side) < 1e-9 {
        return Err(format!(
            "up {up:?} is parallel to the view direction {forward:?}; the roll is undefined"
        ));
    }
    let right =
        math::normalize(side).ok_or_else(|| "up is parallel to the view direction".to_string())?;
    Ok(Pose {
        origin,
        forward,
        right,
        up: math::cross(right, forward),
    })
}

/// The frame of a camera-to-world matrix: columns 0, 1, 2 are the local X (right), Y (up) and
/// Z (backwards) axes, column 3 the origin. Scale is normalised away; anything that is not a
/// rotation times a positive scale per axis is an error.
fn pose_from_matrix(m: &[[f64; 4]; 4]) -> Result<Pose, String> {
    if !m.iter().flatten().all(|v| v.is_finite()) {
        return Err("matrix_world has a non-finite entry".to_string());
    }
    if m[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(format!(
            "matrix_world's last row is {:?}, not [0, 0, 0, 1]: a camera-to-world matrix is a \
             rotation, a scale and a translation",
            m[3]
        ));
    }
    let column = |k: usize| [m[0][k], m[1][k], m[2][k]];
    let names = ["X", "Y", "Z"];
    let mut axes = [[0.0; 3]; 3];
    for (k, axis) in axes.iter_mut().enumerate() {
        *axis = math::normalize(column(k)).ok_or_else(|| {
            format!(
                "matrix_world's local {} axis (column {k}) has zero length: the matrix is \
                 singular",
                names[k]
            )
        })?;
    }
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let c = math::dot(axes[a], axes[b]);
        if c.abs() > MATRIX_SKEW_TOLERANCE {
            return Err(format!(
                "matrix_world is skewed: its local {} and {} axes are {:.6}° apart, not 90° (a \
                 camera matrix is a rotation times a scale)",
                names[a],
                names[b],
                c.clamp(-1.0, 1.0).acos().to_degrees()
            ));
        }
    }
    let det = math::dot(math::cross(axes[0], axes[1]), axes[2]);
    if det <= 0.0 {
        return Err(format!(
            "matrix_world's rotation part has determinant {det:.6} ≤ 0: it mirrors the camera \
             (a camera matrix is a rotation times a positive scale)"
        ));
    }
    // Gram–Schmidt from the view axis, so that the frame is orthonormal to rounding.
    let forward = math::scale(axes[2], -1.0);
    let x = axes[0];
    let right = math::normalize(math::sub(x, math::scale(forward, math::dot(x, forward))))
        .ok_or_else(|| "matrix_world's local X axis is parallel to its Z axis".to_string())?;
    Ok(Pose {
        origin: [m[0][3], m[1][3], m[2][3]],
        forward,
        right,
        up: math::cross(right, forward),
    })
}
