//! The pinhole camera of `glassdb mask` (conventions in docs/scene.md): right-handed world,
//! image x to the right, row 0 at the top, pixel (i, j) sampled by the ray through its centre
//! `(i + 0.5, j + 0.5)`, square pixels, `fov_x_deg` the full horizontal field of view.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::SceneError;
use crate::math::{self, Vec3};

/// Largest width or height accepted.
pub const MAX_SIDE: u32 = 32_768;
/// Largest pixel count accepted (the rasteriser keeps ~24 bytes per pixel and sample).
pub const MAX_PIXELS: u64 = 1 << 27;

/// The camera JSON as written by users.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    pub origin: [f64; 3],
    pub target: [f64; 3],
    pub up: [f64; 3],
    pub fov_x_deg: f64,
    pub width: u32,
    pub height: u32,
}

/// A validated camera with its orthonormal frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub origin: Vec3,
    /// Unit view direction (towards `target`).
    pub forward: Vec3,
    /// Unit image-right direction: `forward × up`, normalised.
    pub right: Vec3,
    /// Unit image-up direction: `right × forward`.
    pub up: Vec3,
    /// tan of half the horizontal / vertical field of view.
    pub tan_half_x: f64,
    pub tan_half_y: f64,
    pub width: u32,
    pub height: u32,
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

impl Camera {
    /// Validates a camera spec; `path` only names the source in errors.
    pub fn new(spec: &CameraSpec, path: &Path) -> Result<Camera, SceneError> {
        let bad = |message: String| SceneError::BadCamera {
            path: path.to_path_buf(),
            message,
        };
        for (name, v) in [
            ("origin", spec.origin),
            ("target", spec.target),
            ("up", spec.up),
        ] {
            if !math::is_finite(v) {
                return Err(bad(format!("{name} {v:?} is not finite")));
            }
        }
        check_image_size(spec.width, spec.height)?;
        if !(spec.fov_x_deg.is_finite() && spec.fov_x_deg > 0.0 && spec.fov_x_deg < 180.0) {
            return Err(bad(format!(
                "fov_x_deg {} must be strictly between 0 and 180",
                spec.fov_x_deg
            )));
        }
        let forward = math::normalize(math::sub(spec.target, spec.origin))
            .ok_or_else(|| bad("origin and target are the same point: no view direction".into()))?;
        let up_in = math::normalize(spec.up).ok_or_else(|| bad("up is the zero vector".into()))?;
        let side = math::cross(forward, up_in);
        if math::norm(side) < 1e-9 {
            return Err(bad(format!(
                "up {:?} is parallel to the view direction {forward:?}; the roll is undefined",
                spec.up
            )));
        }
        let right = math::normalize(side)
            .ok_or_else(|| bad("up is parallel to the view direction".into()))?;
        let up = math::cross(right, forward);
        let tan_half_x = (spec.fov_x_deg.to_radians() / 2.0).tan();
        let tan_half_y = tan_half_x * spec.height as f64 / spec.width as f64;
        Ok(Camera {
            origin: spec.origin,
            forward,
            right,
            up,
            tan_half_x,
            tan_half_y,
            width: spec.width,
            height: spec.height,
        })
    }

    /// Reads and validates a camera JSON file.
    pub fn load(path: &Path) -> Result<Camera, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let spec: CameraSpec = serde_json::from_str(&text).map_err(|e| SceneError::BadCamera {
            path: path.to_path_buf(),
            message: format!("line {}, column {}: {e}", e.line(), e.column()),
        })?;
        Camera::new(&spec, path)
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
        [
            (c[0] / (c[2] * self.tan_half_x) + 1.0) * 0.5 * w,
            (1.0 - c[1] / (c[2] * self.tan_half_y)) * 0.5 * h,
        ]
    }

    /// Unnormalised world direction of the ray through image position (x, y) in pixels.
    #[inline]
    pub fn ray_direction(&self, x: f64, y: f64) -> Vec3 {
        let sx = (x * 2.0 / self.width as f64 - 1.0) * self.tan_half_x;
        let sy = (1.0 - y * 2.0 / self.height as f64) * self.tan_half_y;
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

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> CameraSpec {
        CameraSpec {
            origin: [0.0, 0.0, 5.0],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_x_deg: 90.0,
            width: 4,
            height: 2,
        }
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

    #[test]
    fn bad_cameras_are_errors() {
        let mut s = spec();
        s.up = [0.0, 0.0, 2.0];
        let e = Camera::new(&s, Path::new("c.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("parallel"), "{e}");
        let mut s = spec();
        s.width = 0;
        assert!(matches!(
            Camera::new(&s, Path::new("c.json")),
            Err(SceneError::BadImageSize { .. })
        ));
        let mut s = spec();
        s.fov_x_deg = 180.0;
        assert!(Camera::new(&s, Path::new("c.json")).is_err());
        let mut s = spec();
        s.target = s.origin;
        assert!(Camera::new(&s, Path::new("c.json")).is_err());
    }
}
