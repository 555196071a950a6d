//! The pinhole camera of `glassdb mask` (conventions in docs/scene.md, "Camera JSON and
//! conventions"): right-handed world, image x to the right, row 0 at the top, pixel (i, j)
//! sampled by the ray through its centre `(i + 0.5, j + 0.5)`.
//!
//! A camera is a pose (origin and an orthonormal right / up / forward frame) and Blender's
//! *view plane*: the rectangle the image covers at unit depth in camera space, which may be
//! off-centre (lens shift) and whose pixels may be non-square (pixel aspect). One step per file:
//! `spec` (the JSON and its validation: pose, lens, Blender's view plane), `file` (camera files
//! and animations: one file per frame or a `frames` object).

mod file;
mod spec;
#[cfg(test)]
mod tests;

use std::path::Path;

pub use file::{CAMERA_FILE, CameraSource, MAX_CAMERA_FILE_BYTES};
pub use spec::{CameraSpec, SensorFit};

use crate::error::SceneError;
use crate::math::{self, Vec3};

/// Largest width or height accepted.
pub const MAX_SIDE: u32 = 32_768;
/// Largest pixel count accepted (the rasteriser keeps ~24 bytes per pixel and sample).
pub const MAX_PIXELS: u64 = 1 << 27;

/// The image rectangle at unit depth in camera space (x to the right, y up): the image spans
/// `x_min ≤ X/Z ≤ x_max` and `y_min ≤ Y/Z ≤ y_max`, with `(x_min, y_max)` the top-left corner
/// of pixel (0, 0). Symmetric about 0 without lens shift.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewPlane {
    /// Left edge of the view plane at distance 1.
    pub x_min: f64,
    /// Right edge.
    pub x_max: f64,
    /// Bottom edge.
    pub y_min: f64,
    /// Top edge.
    pub y_max: f64,
}

/// A validated camera: its orthonormal frame and its view plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Where the camera is.
    pub origin: Vec3,
    /// Unit view direction (towards `target`; Blender's local −Z).
    pub forward: Vec3,
    /// Unit image-right direction: `forward × up`, normalised (Blender's local +X).
    pub right: Vec3,
    /// Unit image-up direction: `right × forward` (Blender's local +Y).
    pub up: Vec3,
    /// The image rectangle at unit depth.
    pub view: ViewPlane,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The view plane as centre and half-extent per axis, as computed from the lens (the
    /// projection uses these, so that an unshifted camera projects exactly as the symmetric
    /// pinhole did: centre 0, half-extent tan of the half field of view).
    centre: [f64; 2],
    half: [f64; 2],
}

/// Checks a requested image size against zero and the caps, before anything is allocated.
pub fn check_image_size(width: u32, height: u32) -> Result<(), SceneError> {
    let bad = |message: &str| SceneError::BadImageSize {
        width: width as u64,
        height: height as u64,
        message: message.into(),
    };
    if width == 0 || height == 0 {
        return Err(bad("width and height must be at least 1"));
    }
    if width > MAX_SIDE || height > MAX_SIDE {
        return Err(bad(&format!("each side must be at most {MAX_SIDE}")));
    }
    if width as u64 * height as u64 > MAX_PIXELS {
        return Err(bad(&format!("at most {MAX_PIXELS} pixels")));
    }
    Ok(())
}

/// The error of the camera file `path` (at animation frame `frame`) that says `message`.
pub(crate) fn bad_camera(
    path: &Path,
    frame: Option<u32>,
) -> impl Fn(String) -> SceneError + Copy + '_ {
    move |message| SceneError::BadCamera {
        path: path.to_path_buf(),
        frame,
        message,
    }
}

impl Camera {
    /// Validates a camera spec; `path` only names the source in errors.
    pub fn new(spec: &CameraSpec, path: &Path) -> Result<Camera, SceneError> {
        Camera::from_spec(spec, path, None)
    }

    /// Validates a camera spec of animation frame `frame` (named in errors with `path`).
    pub fn from_spec(
        spec: &CameraSpec,
        path: &Path,
        frame: Option<u32>,
    ) -> Result<Camera, SceneError> {
        let bad = bad_camera(path, frame);
        check_image_size(spec.width, spec.height)?;
        let pose = spec.pose().map_err(bad)?;
        let (centre, half) = spec.window().map_err(bad)?;
        Ok(Camera {
            origin: pose.origin,
            forward: pose.forward,
            right: pose.right,
            up: pose.up,
            view: ViewPlane {
                x_min: centre[0] - half[0],
                x_max: centre[0] + half[0],
                y_min: centre[1] - half[1],
                y_max: centre[1] + half[1],
            },
            width: spec.width,
            height: spec.height,
            centre,
            half,
        })
    }

    /// Reads and validates a camera JSON file holding one camera (an animation file is an
    /// error here: see [`CameraSource`]).
    pub fn load(path: &Path) -> Result<Camera, SceneError> {
        CameraSource::open(path)?.camera(None)
    }

    /// Camera-space coordinates (right, up, forward depth) of a world point.
    #[inline]
    pub fn to_camera(&self, p: Vec3) -> Vec3 {
        let v = math::sub(p, self.origin);
        [
            math::dot(v, self.right),
            math::dot(v, self.up),
            math::dot(v, self.forward),
        ]
    }

    /// Image position (x to the right, y down, in pixels; pixel centres at +0.5) of a
    /// camera-space point with positive depth.
    #[inline]
    pub fn project(&self, c: Vec3) -> [f64; 2] {
        let w = self.width as f64;
        let h = self.height as f64;
        // (X/Z − centre) / half in [−1, 1]; written so that centre 0 costs no rounding.
        [
            ((c[0] - self.centre[0] * c[2]) / (c[2] * self.half[0]) + 1.0) * 0.5 * w,
            (1.0 - (c[1] - self.centre[1] * c[2]) / (c[2] * self.half[1])) * 0.5 * h,
        ]
    }

    /// Unnormalised world direction of the ray through image position (x, y) in pixels.
    #[inline]
    pub fn ray_direction(&self, x: f64, y: f64) -> Vec3 {
        let sx = self.centre[0] + (x * 2.0 / self.width as f64 - 1.0) * self.half[0];
        let sy = self.centre[1] + (1.0 - y * 2.0 / self.height as f64) * self.half[1];
        math::add(
            self.forward,
            math::add(math::scale(self.right, sx), math::scale(self.up, sy)),
        )
    }

    /// Unit direction of the ray through the centre of pixel (i, j) (column i, row j from the top).
    #[inline]
    pub fn pixel_ray(&self, i: u32, j: u32) -> Vec3 {
        let d = self.ray_direction(i as f64 + 0.5, j as f64 + 0.5);
        math::scale(d, 1.0 / math::norm(d))
    }
}
