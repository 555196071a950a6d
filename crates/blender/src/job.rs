//! The files between glassdb and Blender: the render job the Blender-side script reads, what
//! its export writes, and the run record `glassdb blender compose` reads back.

use std::path::{Path, PathBuf};

use glassdb_image::PixelWindow;
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
    /// Cycles' seed.
    pub seed: u32,
    /// Render threads, or Blender's choice.
    pub threads: Option<u32>,
    /// Camera rays see the glass too (the Cycles reference render), instead of through it.
    pub reference: bool,
    /// Lamps on the camera's side of a plane are visible to the camera rays of its reflection
    /// pass, those on the far side hidden ([`crate::RenderRequest::lamps_in_reflections`]).
    pub lamps_in_reflections: bool,
    /// The glass as thin panes.
    pub glass: Vec<ThinPane>,
    /// The frames to render.
    pub frames: Vec<ScriptFrame>,
    /// Render every pass once per light-split state, with light groups by source
    /// ([`crate::light_split`]).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub light_split: bool,
    /// Render with light groups by source, without the split (the reference of a split run:
    /// its layers `ViewLayer.Combined_<group>` say each source's light).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub light_groups: bool,
    /// The scene's own light groups (issue 29, [`crate::scene_lights`]): with the split, each
    /// source is split by them too; without it, every pass gets a `Combined_<group>` layer
    /// per group. Empty: the scene is one light.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub scene_groups: Vec<String>,
}

/// One frame of a [`ScriptJob`].
#[derive(Debug, Clone, Serialize)]
pub struct ScriptFrame {
    /// The frame number.
    pub frame: u32,
    /// The transmission pass (or the reference) to write.
    pub trans: PathBuf,
    /// The reflection passes to render, one per plane with glass.
    pub planes: Vec<ScriptPlane>,
    /// The frame's apertures, opened one at a time by a light-split render.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub apertures: Vec<crate::light_split::ScriptAperture>,
    /// Where a light-split render writes the frame's light sources.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lights: Option<PathBuf>,
}

/// One reflection pass of a [`ScriptFrame`].
#[derive(Debug, Clone, Serialize)]
pub struct ScriptPlane {
    /// The plane's index.
    pub index: usize,
    /// `[a, b, c, d]` of a·x + b·y + c·z + d = 0 in Blender's world, with the camera on the
    /// positive side.
    pub equation: [f64; 4],
    /// Distance within which glass counts as on the plane (planes.json's tolerance).
    pub tolerance: f64,
    /// Blender's render border `[min_x, max_x, min_y, max_y]`, fractions of the frame with y
    /// up, chosen so that Blender's truncation gives exactly the plane's pixel rectangle
    /// (`glassdb_mask::PlaneBounds::blender_border`).
    pub border: [f64; 4],
    /// The pass to write.
    pub output: PathBuf,
}

/// What the script's `export` mode says besides the scene and cameras (`export.json`; its
/// other fields, such as the Blender version, are not read).
#[derive(Debug, Clone, Deserialize)]
pub struct ExportInfo {
    /// The frames exported.
    pub frames: Vec<u32>,
    /// The scene's materials.
    pub materials: Vec<String>,
    /// The frames whose geometry differs from the first frame's (by frame number): each has
    /// its own OBJ (`scene.NNNN.obj`), planes (`planes.NNNN/`) and mask.
    #[serde(default)]
    pub moving: std::collections::BTreeMap<u32, MovingFrame>,
    /// The scene denoises (Cycles' denoiser on), which the passes turn off.
    #[serde(default)]
    pub denoising: bool,
    /// The scene has motion blur on, which the passes turn off.
    #[serde(default)]
    pub motion_blur: bool,
    /// The scene's own light groups, their emitters and `glassdb_light` properties.
    #[serde(default)]
    pub light_groups: crate::scene_lights::SceneLightGroups,
}

/// A frame whose objects are not where they are in the first frame.
#[derive(Debug, Clone, Deserialize)]
pub struct MovingFrame {
    /// The objects whose geometry differs from the first frame's.
    pub objects: Vec<String>,
}

impl ExportInfo {
    /// The scene's render settings that the passes do not take, said as the run record and
    /// the command say them.
    pub fn overrides(&self) -> Vec<String> {
        let mut said = Vec::new();
        if self.denoising {
            said.push(
                "denoising off (the scene denoises; the passes keep Cycles' own noise, and \
                 Blender builds without OpenImageDenoise could not render them)"
                    .to_string(),
            );
        }
        if self.motion_blur {
            said.push(
                "motion blur off (the scene blurs motion; the masks are of each frame's instant)"
                    .to_string(),
            );
        }
        said
    }
}

/// A plane's pixels in one frame: columns `x..x+width`, rows `y..y+height` (row 0 at the top).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PixelBounds {
    /// First column.
    pub x: u32,
    /// First row.
    pub y: u32,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

impl PixelBounds {
    /// The rectangle as a window in the frame.
    pub fn window(&self) -> PixelWindow {
        PixelWindow {
            x: self.x as i32,
            y: self.y as i32,
            width: self.width as usize,
            height: self.height as usize,
        }
    }
}

impl From<PixelWindow> for PixelBounds {
    /// A window inside a frame (coordinates not negative, as a mask's plane rectangles are).
    fn from(w: PixelWindow) -> PixelBounds {
        PixelBounds {
            x: w.x.max(0) as u32,
            y: w.y.max(0) as u32,
            width: w.width as u32,
            height: w.height as u32,
        }
    }
}

/// One frame of a run: its files (relative to the output directory), each plane's side and
/// pixels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameRecord {
    /// The frame number.
    pub frame: u32,
    /// The transmission pass, relative to the output folder.
    pub trans: String,
    /// The mask, relative to the output folder.
    pub mask: String,
    /// The reflection passes, plane k at k.
    pub refl: Vec<String>,
    /// Which face of each plane the camera sees.
    pub sides: Vec<Side>,
    /// Each plane's glass pixels (`None`: none in this frame; its pass is one black pixel).
    pub bounds: Vec<Option<PixelBounds>>,
    /// The composite, relative to the output folder.
    pub composite: String,
    /// The frame's light parts (`light_parts.####.json`, [`glassdb_compose::light_parts`]),
    /// when the passes keep the light's path apart.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub light_parts: Option<String>,
    /// The reflection passes of units' deeper pane groups (issue 27): the scene mirrored about
    /// each group's mid-plane, cropped to the glass of that group. Absent without units.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<GroupPassRecord>,
}

impl FrameRecord {
    /// The frame's pane-group passes as compose takes them, in the run folder `dir`.
    pub fn group_pass_files(&self, dir: &Path) -> Vec<glassdb_compose::GroupPassFile> {
        self.groups
            .iter()
            .map(|g| glassdb_compose::GroupPassFile {
                plane: g.plane,
                group: g.group,
                path: dir.join(&g.file),
                layer: None,
            })
            .collect()
    }
}

/// The reflection pass of pane group `group` (1 or more) of plane `plane` in one frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupPassRecord {
    /// The plane (its group 0 pass is `FrameRecord::refl[plane]`).
    pub plane: usize,
    /// The pane group, counted in the order the camera's rays meet the groups.
    pub group: usize,
    /// The pass, relative to the output folder (`refl_<plane>_<group>.####.exr`).
    pub file: String,
    /// Its mirror plane's depth behind the glass face (metres along −normal).
    pub depth_m: f64,
    /// The glass pixels it covers (`glassdb mask --bounds`' group rectangle).
    pub bounds: PixelBounds,
}

/// `glassdb-blender.json`: what `glassdb blender render` made, for re-compositing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunRecord {
    /// [`RECORD_FORMAT`].
    pub format: String,
    /// The scene rendered.
    pub blend: String,
    /// The Blender version that rendered it.
    pub blender: String,
    /// The `--glass PATTERN=ID` mappings.
    pub glass: Vec<String>,
    /// Cycles samples per pixel, or the scene's.
    pub samples: Option<u32>,
    /// The frames' width in pixels.
    pub width: u32,
    /// The frames' height in pixels.
    pub height: u32,
    /// The scene's render settings the passes overrode (denoising, motion blur), in words;
    /// Cycles never denoises the passes.
    #[serde(default)]
    pub overrides: Vec<String>,
    /// Every frame rendered.
    pub frames: Vec<FrameRecord>,
    /// The glasses whose thin-pane shader lit the passes (absent in runs before they were
    /// recorded): what a swap to other glasses cannot change ([`crate::swap`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lit_by: Vec<crate::swap::PassGlass>,
    /// How many of a unit's pane groups got a reflection pass (`--surfaces N`; absent: all):
    /// the deeper groups' reflectance is composited on the last one's pass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surfaces: Option<std::num::NonZeroUsize>,
    /// The scene's light groups and each one's spectrum (issue 29); absent: the scene is one
    /// light, composited with the registry's default tables.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lights: Vec<crate::scene_lights::SceneLight>,
    /// Every pass holds a `ViewLayer.Combined_<group>` layer per light group of
    /// [`RunRecord::lights`] (the render without the light split); with the split the groups
    /// are in each frame's light parts instead.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub group_layers: bool,
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
            if let Some(g) = f
                .groups
                .iter()
                .find(|g| g.plane >= f.refl.len() || g.group == 0)
            {
                return Err(bad(format!(
                    "frame {}: pane group {} of plane {} is not a deeper group of one of its {} planes",
                    f.frame,
                    g.group,
                    g.plane,
                    f.refl.len()
                )));
            }
            let files = [&f.trans, &f.mask, &f.composite]
                .into_iter()
                .chain(&f.refl)
                .chain(f.groups.iter().map(|g| &g.file))
                .chain(&f.light_parts);
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

    #[test]
    fn export_info_reads_the_scripts_fields_and_ignores_the_others() {
        let info: ExportInfo = serde_json::from_str(
            r#"{"blender": "3.4.1", "frames": [1, 2], "materials": ["Glass"], "new": 1}"#,
        )
        .unwrap();
        assert_eq!(
            (info.frames, info.materials),
            (vec![1, 2], vec!["Glass".into()])
        );
    }

    #[test]
    fn pixel_bounds_of_a_window() {
        let w = PixelWindow {
            x: 3,
            y: 4,
            width: 5,
            height: 6,
        };
        assert_eq!(
            PixelBounds::from(w),
            PixelBounds {
                x: 3,
                y: 4,
                width: 5,
                height: 6
            }
        );
    }
}
