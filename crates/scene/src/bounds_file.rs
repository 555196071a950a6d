//! The plane-bounds sidecar of `glassdb mask --bounds` (schema in docs/scene.md, "Plane
//! bounds"): each plane's screen rectangle in one frame, so that a renderer renders that plane's
//! reflection pass over just that region (Blender's render border, an EXR data window).

use std::collections::BTreeMap;
use std::path::Path;

use glassdb_mask::{MaskImage, PlaneBounds};
use serde::{Deserialize, Serialize};

use crate::error::SceneError;

/// Value of [`PlaneBoundsFile::format`].
pub const PLANE_BOUNDS_FORMAT: &str = "glassdb-plane-bounds/1";

/// One frame's plane rectangles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneBoundsFile {
    /// [`PLANE_BOUNDS_FORMAT`].
    pub format: String,
    /// The animation frame, or `null` for a single mask.
    pub frame: Option<u32>,
    /// The mask the rectangles were measured on, as given on the command line.
    pub mask: String,
    /// The frame's size in pixels (the display window).
    pub width: u32,
    /// Mask height in pixels.
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
    /// the frame with y from the **bottom**, each edge half a pixel on so that Blender's
    /// float32 truncation `int(fraction · size)` gives exactly the data window
    /// (`glassdb_mask::PlaneBounds::blender_border`).
    pub blender_border: BlenderBorder,
    /// The rectangles of the plane's deeper pane groups (issue 27), group 1 and on: where
    /// each group's reflection pass is composited, the glass pixels of the plane whose glass
    /// is a unit with that group (docs/scene.md, "Units"). Absent without units.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<GroupBoundsEntry>,
}

/// One deeper pane group's rectangle on a plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupBoundsEntry {
    /// The pane group, 1 or more, in the order the camera's rays meet the groups (compose's
    /// `refl_<plane>_<group>`).
    pub group: usize,
    /// `[x_min, y_min, x_max, y_max]` as [`PlaneBoundsEntry::data_window`].
    pub data_window: [i32; 4],
    /// Glass pixels of the plane whose glass has this group.
    pub glass_pixels: u64,
    /// The same rectangle as Blender's render border.
    pub blender_border: BlenderBorder,
}

/// A render border as Blender stores it: fractions in [0, 1], y up.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlenderBorder {
    /// Left edge, fraction of the frame's width.
    pub min_x: f64,
    /// Right edge, fraction of the frame's width.
    pub max_x: f64,
    /// Bottom edge, fraction of the frame's height (y up).
    pub min_y: f64,
    /// Top edge, fraction of the frame's height (y up).
    pub max_y: f64,
}

impl BlenderBorder {
    /// `b`'s border in a `width × height` frame (`PlaneBounds::blender_border`).
    fn of(b: &PlaneBounds, width: u32, height: u32) -> BlenderBorder {
        let [min_x, max_x, min_y, max_y] = b.blender_border(width, height);
        BlenderBorder {
            min_x,
            max_x,
            min_y,
            max_y,
        }
    }
}

impl PlaneBoundsFile {
    /// The rectangles of `mask` (a whole frame at the origin, as `glassdb mask` writes it).
    pub fn from_mask(mask: &MaskImage, frame: Option<u32>, mask_name: &str) -> PlaneBoundsFile {
        let planes = mask
            .plane_bounds()
            .into_iter()
            .map(|(plane, b)| PlaneBoundsEntry {
                plane,
                data_window: [b.x_min, b.y_min, b.x_max, b.y_max],
                glass_pixels: b.glass_pixels,
                blender_border: BlenderBorder::of(&b, mask.width, mask.height),
                groups: Vec::new(),
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

    /// The file with each plane's deeper pane groups' rectangles (`MaskImage::group_bounds`,
    /// by `(plane, group)`).
    pub fn with_groups(mut self, groups: &BTreeMap<(u16, usize), PlaneBounds>) -> PlaneBoundsFile {
        for p in &mut self.planes {
            p.groups = groups
                .range((p.plane, 1)..=(p.plane, usize::MAX))
                .map(|(&(_, group), b)| GroupBoundsEntry {
                    group,
                    data_window: [b.x_min, b.y_min, b.x_max, b.y_max],
                    glass_pixels: b.glass_pixels,
                    blender_border: BlenderBorder::of(b, self.width, self.height),
                })
                .collect();
        }
        self
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
                "format {} is not {PLANE_BOUNDS_FORMAT:?}",
                glassdb_io::quoted(&file.format)
            )));
        }
        let windows = file.planes.iter().flat_map(|p| {
            std::iter::once((p.plane, None, p.data_window)).chain(
                p.groups
                    .iter()
                    .map(|g| (p.plane, Some(g.group), g.data_window)),
            )
        });
        for (plane, group, data_window) in windows {
            let [x0, y0, x1, y1] = data_window;
            if x0 < 0
                || y0 < 0
                || x1 < x0
                || y1 < y0
                || x1 as u32 >= file.width
                || y1 as u32 >= file.height
            {
                let group = group.map_or_else(String::new, |g| format!(", pane group {g}"));
                return Err(bad(format!(
                    "plane {plane}{group}: data_window {data_window:?} is not inside the {}x{} frame",
                    file.width, file.height
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

    /// Blender's edge rule: `int(fraction · size)`, the fraction stored and multiplied in
    /// float32.
    fn blender_edge(fraction: f64, size: u32) -> i64 {
        ((fraction as f32) * size as f32) as i64
    }

    #[test]
    fn the_blender_border_truncates_to_the_data_window_with_y_up() {
        // Exact edges can truncate short in float32: 13/22 gives 12.
        assert_eq!(blender_edge(13.0 / 22.0, 22), 12);
        // W×H frames; plane 3's glass fills a rectangle `[x_min, y_min, x_max, y_max]` (row 0
        // at the top) with such edges (13 of 22, 27 of 49, 7, 27 and 31 of 99), plane 0 is the
        // bottom left pixel.
        for (w, h, rect) in [
            (4u32, 2u32, [1, 1, 2, 1]),
            (22, 22, [1, 9, 12, 21]),
            (49, 22, [27, 0, 48, 8]),
            (99, 49, [7, 22, 30, 48]),
            (7, 5, [1, 1, 5, 3]),
        ] {
            let n = (w * h) as usize;
            let (mut id, mut plane) = (vec![0u16; n], vec![0u16; n]);
            for y in rect[1]..=rect[3] {
                for x in rect[0]..=rect[2] {
                    let i = (y * w as i32 + x) as usize;
                    (id[i], plane[i]) = (5, 3);
                }
            }
            id[((h - 1) * w) as usize] = 5;
            let mask = MaskImage {
                width: w,
                height: h,
                id,
                cos_theta: CosTheta::Normal,
                plane,
                coverage: None,
            };
            let f = PlaneBoundsFile::from_mask(&mask, Some(7), "m.exr");
            let pixels = ((rect[2] - rect[0] + 1) * (rect[3] - rect[1] + 1)) as u64;
            let bottom_left = [0, h as i32 - 1, 0, h as i32 - 1];
            let got: Vec<_> = f
                .planes
                .iter()
                .map(|p| (p.plane, p.data_window, p.glass_pixels))
                .collect();
            assert_eq!(got, [(0, bottom_left, 1), (3, rect, pixels)], "{w}x{h}");
            for p in &f.planes {
                let b = p.blender_border;
                let [x0, y0, x1, y1] = p.data_window.map(i64::from);
                let h = i64::from(h);
                // y up: the bottom edge is the rows below y_max.
                assert_eq!(
                    [
                        blender_edge(b.min_x, w),
                        blender_edge(b.max_x, w),
                        blender_edge(b.min_y, h as u32),
                        blender_edge(b.max_y, h as u32),
                    ],
                    [x0, x1 + 1, h - 1 - y1, h - y0],
                    "{w}x{h} plane {}",
                    p.plane
                );
                let fractions = [b.min_x, b.max_x, b.min_y, b.max_y];
                assert!(fractions.iter().all(|f| (0.0..=1.0).contains(f)));
            }
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("b.json");
            f.write(&path).unwrap();
            assert_eq!(PlaneBoundsFile::load(&path).unwrap(), f);
        }
    }
}
