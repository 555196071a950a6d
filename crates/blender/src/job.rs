//! The files between glassdb and Blender: the render job the Blender-side script reads, what
//! its export writes, and the run record `glassdb blender compose` reads back.

use std::path::{Path, PathBuf};

use glassdb_registry::Side;
use serde::{Deserialize, Serialize};

use crate::BlenderError;
use crate::thin_pane::ThinPane;

/// Name of the run record in the output directory.
pub const RECORD_NAME: &str = "glassdb-blender.json";
/// Its `format`.
pub const RECORD_FORMAT: &str = "glassdb-blender/1";

/// What the script's `render` mode renders.
#[derive(Debug, Clone, Serialize)]
pub struct ScriptJob {
    /// `WxH`, or the scene's resolution.
    pub resolution: Option<String>,
    /// Cycles samples per pixel, or the scene's.
    pub samples: Option<u32>,
    pub seed: u32,
    /// Render threads, or Blender's choice.
    pub threads: Option<u32>,
    /// Camera rays see the glass too (the Cycles reference render), instead of through it.
    pub reference: bool,
    pub glass: Vec<ThinPane>,
    pub frames: Vec<ScriptFrame>,
}

/// One frame of a [`ScriptJob`].
#[derive(Debug, Clone, Serialize)]
pub struct ScriptFrame {
    pub frame: u32,
    /// The transmission pass (or the reference) to write.
    pub trans: PathBuf,
    pub planes: Vec<ScriptPlane>,
}

/// One reflection pass of a [`ScriptFrame`].
#[derive(Debug, Clone, Serialize)]
pub struct ScriptPlane {
    pub index: usize,
    /// `[a, b, c, d]` of a·x + b·y + c·z + d = 0 in Blender's world, with the camera on the
    /// positive side.
    pub equation: [f64; 4],
    /// Distance within which glass counts as on the plane (planes.json's tolerance).
    pub tolerance: f64,
    /// Blender's render border `[min_x, max_x, min_y, max_y]`, fractions of the frame with y
    /// up, chosen so that Blender's truncation gives exactly the plane's pixel rectangle.
    pub border: [f64; 4],
    pub output: PathBuf,
}

/// What the script's `export` mode says besides the scene and cameras (`export.json`).
#[derive(Debug, Clone, Deserialize)]
pub struct ExportInfo {
    pub blender: String,
    pub frames: Vec<u32>,
    pub materials: Vec<String>,
}

/// A plane's pixels in one frame: columns `x..x+width`, rows `y..y+height` (row 0 at the top).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PixelBounds {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl PixelBounds {
    /// Blender's render border for these pixels of a `width × height` frame. Blender takes
    /// `int(fraction · size)` for each edge (render_init_from_main), so each edge is given
    /// half a pixel inside, which truncates to the pixel edge whatever the float rounding.
    pub fn blender_border(&self, width: u32, height: u32) -> [f64; 4] {
        let (w, h) = (f64::from(width), f64::from(height));
        let frac = |edge: u32, size: f64| ((f64::from(edge) + 0.5) / size).min(1.0);
        let y_min = height - (self.y + self.height);
        let y_max = height - self.y;
        [
            frac(self.x, w),
            frac(self.x + self.width, w),
            frac(y_min, h),
            frac(y_max, h),
        ]
    }
}

/// One frame of a run: its files (relative to the output directory), each plane's side and
/// pixels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameRecord {
    pub frame: u32,
    pub trans: String,
    pub mask: String,
    pub refl: Vec<String>,
    /// Which face of each plane the camera sees.
    pub sides: Vec<Side>,
    /// Each plane's glass pixels (`None`: none in this frame; its pass is one black pixel).
    pub bounds: Vec<Option<PixelBounds>>,
    pub composite: String,
}

/// `glassdb-blender.json`: what `glassdb blender render` made, for re-compositing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunRecord {
    pub format: String,
    pub blend: String,
    pub blender: String,
    /// The `--glass PATTERN=ID` mappings.
    pub glass: Vec<String>,
    pub samples: Option<u32>,
    pub width: u32,
    pub height: u32,
    pub frames: Vec<FrameRecord>,
}

impl RunRecord {
    /// Reads `dir/glassdb-blender.json` (bounded, validated).
    pub fn load(dir: &Path) -> Result<RunRecord, BlenderError> {
        let path = dir.join(RECORD_NAME);
        let text = glassdb_io::read_input_string(&path, glassdb_io::limits::JSON)?;
        let bad = |message: String| BlenderError::BadRecord {
            path: path.clone(),
            message,
        };
        let record: RunRecord = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
        if record.format != RECORD_FORMAT {
            return Err(bad(format!(
                "format {:?}, not {RECORD_FORMAT:?}",
                record.format
            )));
        }
        for f in &record.frames {
            if f.refl.len() != f.sides.len() || f.refl.len() != f.bounds.len() {
                return Err(bad(format!(
                    "frame {}: planes, sides and bounds differ in number",
                    f.frame
                )));
            }
            let files = [&f.trans, &f.mask, &f.composite].into_iter().chain(&f.refl);
            if let Some(p) = files.into_iter().find(|p| !is_plain_name(p)) {
                return Err(bad(format!(
                    "frame {}: {p:?} is not a file name in the directory",
                    f.frame
                )));
            }
        }
        Ok(record)
    }
}

/// A file name without directories (the record names files beside it only).
fn is_plain_name(name: &str) -> bool {
    !name.is_empty() && !name.contains(['/', '\\']) && name != "." && name != ".."
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Blender's own edge rule (`int(fraction · size)`, in float32 as it stores the border)
    /// gives back the bounds.
    #[test]
    fn borders_truncate_to_the_bounds() {
        for (w, h) in [(64u32, 48u32), (320, 240), (1920, 1080), (7, 5)] {
            for (x, y, bw, bh) in [
                (0, 0, w, h),
                (1, 2, 3, 1),
                (w - 1, h - 1, 1, 1),
                (0, h / 2, w / 2, h / 2),
            ] {
                let b = PixelBounds {
                    x,
                    y,
                    width: bw,
                    height: bh,
                };
                let [x0, x1, y0, y1] = b.blender_border(w, h);
                let px = |f: f64, size: u32| ((f as f32) * size as f32) as u32;
                assert_eq!((px(x0, w), px(x1, w)), (x, x + bw));
                assert_eq!((px(y0, h), px(y1, h)), (h - y - bh, h - y));
            }
        }
    }
}
