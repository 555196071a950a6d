//! The plane-bounds sidecar of `glassdb mask --bounds` (schema in docs/scene.md, "Plane
//! bounds"): each plane's screen rectangle in one frame, so that a renderer renders that plane's
//! reflection pass over just that region (Blender's render border, an EXR data window).

use std::path::Path;

use glassdb_mask::MaskImage;
use serde::{Deserialize, Serialize};

use crate::error::SceneError;

/// Value of [`PlaneBoundsFile::format`].
pub const PLANE_BOUNDS_FORMAT: &str = "glassdb-plane-bounds/1";

/// One frame's plane rectangles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneBoundsFile {
    pub format: String,
    /// The animation frame, or `null` for a single mask.
    pub frame: Option<u32>,
    /// The mask the rectangles were measured on, as given on the command line.
    pub mask: String,
    /// The frame's size in pixels (the display window).
    pub width: u32,
    pub height: u32,
    /// Planes with glass in view, by increasing index; a plane not listed needs no reflection
    /// pass in this frame.
    pub planes: Vec<PlaneBoundsEntry>,
}

/// One plane's rectangle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneBoundsEntry {
    /// The plane index of the mask and planes.json.
    pub plane: u16,
    /// `[x_min, y_min, x_max, y_max]`, inclusive pixel bounds with row 0 at the top: the
    /// OpenEXR `dataWindow` a cropped reflection pass of this plane must cover.
    pub data_window: [i32; 4],
    /// Glass pixels of the plane inside the rectangle.
    pub glass_pixels: u64,
    /// The same rectangle as Blender's render border (`render.border_min_x` …): fractions of
    /// the frame with y from the **bottom**, on exact pixel edges (`x_min / width`,
    /// `(x_max + 1) / width`, `(height − 1 − y_max) / height`, `(height − y_min) / height`).
    pub blender_border: BlenderBorder,
}

/// A render border as Blender stores it: fractions in [0, 1], y up.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlenderBorder {
    pub min_x: f64,
    pub max_x: f64,
    pub min_y: f64,
    pub max_y: f64,
}

impl PlaneBoundsFile {
    /// The rectangles of `mask` (a whole frame at the origin, as `glassdb mask` writes it).
    pub fn from_mask(mask: &MaskImage, frame: Option<u32>, mask_name: &str) -> PlaneBoundsFile {
        let (w, h) = (f64::from(mask.width), f64::from(mask.height));
        let planes = mask
            .plane_bounds()
            .into_iter()
            .map(|(plane, b)| PlaneBoundsEntry {
                plane,
                data_window: [b.x_min, b.y_min, b.x_max, b.y_max],
                glass_pixels: b.glass_pixels,
                blender_border: BlenderBorder {
                    min_x: f64::from(b.x_min) / w,
                    max_x: f64::from(b.x_max + 1) / w,
                    min_y: (h - 1.0 - f64::from(b.y_max)) / h,
                    max_y: (h - f64::from(b.y_min)) / h,
                },
            })
            .collect();
        PlaneBoundsFile {
            format: PLANE_BOUNDS_FORMAT.to_string(),
            frame,
            mask: mask_name.to_string(),
            width: mask.width,
            height: mask.height,
            planes,
        }
    }

    /// Writes the file atomically (pretty JSON).
    pub fn write(&self, path: &Path) -> Result<(), SceneError> {
        let text = serde_json::to_string_pretty(self).map_err(|source| SceneError::EncodeJson {
            path: path.to_path_buf(),
            source,
        })?;
        glassdb_io::write_bytes_atomic(path, format!("{text}\n").as_bytes())?;
        Ok(())
    }

    /// Reads a bounds file, checking its format and that every rectangle lies in the frame.
    pub fn load(path: &Path) -> Result<PlaneBoundsFile, SceneError> {
        let file: PlaneBoundsFile = crate::planes_file::read_json_file(path, |path, source| {
            SceneError::BoundsJson { path, source }
        })?;
        let bad = |message: String| SceneError::BadBounds {
            path: path.to_path_buf(),
            message,
        };
        if file.format != PLANE_BOUNDS_FORMAT {
            return Err(bad(format!(
                "format {:?} is not {PLANE_BOUNDS_FORMAT:?}",
                file.format
            )));
        }
        for p in &file.planes {
            let [x0, y0, x1, y1] = p.data_window;
            if x0 < 0
                || y0 < 0
                || x1 < x0
                || y1 < y0
                || x1 as u32 >= file.width
                || y1 as u32 >= file.height
            {
                return Err(bad(format!(
                    "plane {}: data_window {:?} is not inside the {}x{} frame",
                    p.plane, p.data_window, file.width, file.height
                )));
            }
        }
        Ok(file)
    }
}

#[cfg(test)]
mod tests {
    use glassdb_mask::CosTheta;

    use super::*;

    #[test]
    fn the_blender_border_is_the_data_window_on_pixel_edges_with_y_up() {
        // 4×2 frame; plane 3 glass at column 1..=2 of the bottom row.
        let mask = MaskImage {
            width: 4,
            height: 2,
            id: vec![0, 0, 0, 0, 0, 5, 5, 0],
            cos_theta: CosTheta::Normal,
            plane: vec![0, 0, 0, 0, 0, 3, 3, 0],
            coverage: None,
        };
        let f = PlaneBoundsFile::from_mask(&mask, Some(7), "m.exr");
        assert_eq!(f.planes.len(), 1);
        let p = &f.planes[0];
        assert_eq!(
            (p.plane, p.data_window, p.glass_pixels),
            (3, [1, 1, 2, 1], 2)
        );
        assert_eq!(
            p.blender_border,
            BlenderBorder {
                min_x: 0.25,
                max_x: 0.75,
                min_y: 0.0,
                max_y: 0.5
            }
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.json");
        f.write(&path).unwrap();
        assert_eq!(PlaneBoundsFile::load(&path).unwrap(), f);
    }
}
