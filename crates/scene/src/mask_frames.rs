//! The mask pipeline every front-end calls (`glassdb mask`, `glassdb blender render`, the
//! Python package): the scene's glass labelled once ([`label_scene`]), then for each frame
//! ([`mask_frame`], [`mask_frames`]) its camera read, the scene rasterised, the mask written
//! and, when asked, each plane's screen rectangle beside it. Plain typed inputs ([`MaskJob`]);
//! no printing: progress goes to a `glassdb_io::Progress`, results to the caller.

use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use glassdb_io::Progress;
use glassdb_mask::{GlassMapping, MaskFormat, PlaneBounds};

use crate::bounds_file::PlaneBoundsFile;
use crate::camera::CameraSource;
use crate::error::SceneError;
use crate::mask::{CosEncoding, MaskScene, PlaneSource, build_mask_scene, to_mask_image};
use crate::obj::Scene;
use crate::planes::PlaneTolerance;
use crate::planes_file::PlanesFile;
use crate::raster::{RasterOptions, rasterize};

/// Where the glass planes of a mask come from.
#[derive(Debug, Clone)]
pub enum MaskPlanes {
    /// The planes of a `planes.json` written by `glassdb mirror`, so that plane indices match
    /// its virtual scenes: its tolerance, the angle raised to at least `angle_deg`, the
    /// distance replaced when given.
    File {
        /// The planes file.
        path: PathBuf,
        /// The least angle tolerance, degrees.
        angle_deg: f64,
        /// The distance tolerance, scene units (`None`: the file's).
        distance: Option<f64>,
    },
    /// Detected as `glassdb mirror` detects them, with the scene's default tolerance but
    /// these.
    Detect {
        /// The angle tolerance, degrees.
        angle_deg: f64,
        /// The distance tolerance, scene units (`None`: 1e-4 of the scene's diagonal).
        distance: Option<f64>,
    },
    /// These planes (a pipeline that found them itself).
    Given(PlaneSource),
}

impl MaskPlanes {
    /// The planes of `scene` this choice names (a planes file is read).
    pub fn source(&self, scene: &Scene) -> Result<PlaneSource, SceneError> {
        Ok(match self {
            MaskPlanes::File {
                path,
                angle_deg,
                distance,
            } => {
                let file = PlanesFile::load(path)?;
                let mut tolerance = file.tolerance();
                tolerance.angle_deg = angle_deg.max(tolerance.angle_deg);
                if let Some(d) = distance {
                    tolerance.distance = *d;
                }
                PlaneSource::Given {
                    planes: file.planes(),
                    tolerance,
                }
            }
            MaskPlanes::Detect {
                angle_deg,
                distance,
            } => {
                let mut tolerance = PlaneTolerance::default_for(scene);
                tolerance.angle_deg = *angle_deg;
                if let Some(d) = distance {
                    tolerance.distance = *d;
                }
                PlaneSource::Detect(tolerance)
            }
            MaskPlanes::Given(source) => source.clone(),
        })
    }
}

/// Labels `scene`'s triangles for masks: glass by `glass` (first match wins) with its id and
/// plane (from `planes`), and its pane when the mask's cos θ is interpolated per pane
/// (`panes`, the Gouraud mode). Done once for every frame.
pub fn label_scene(
    scene: &Scene,
    glass: &[GlassMapping],
    planes: &MaskPlanes,
    panes: bool,
) -> Result<MaskScene, SceneError> {
    build_mask_scene(scene, glass, &planes.source(scene)?, panes)
}

/// The masks of a labelled scene, frame after frame.
#[derive(Debug)]
pub struct MaskJob<'a> {
    /// The labelled scene ([`label_scene`]).
    pub labelled: &'a MaskScene,
    /// The camera of each frame.
    pub cameras: &'a CameraSource,
    /// How cos θ and coverage are computed.
    pub options: RasterOptions,
    /// The masks' file format.
    pub format: MaskFormat,
    /// The mask of each frame: `####` is replaced by the frame number.
    pub output: PathBuf,
    /// Each frame's plane rectangles, `####` replaced as in `output`.
    pub bounds: Option<PathBuf>,
    /// Pane groups of each glass id that is a unit of two or more (issue 27); an id not
    /// listed has one. Gives each deeper group's rectangle ([`FrameMask::group_bounds`]).
    pub pane_groups: BTreeMap<u16, usize>,
}

/// What one written mask holds.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameMask {
    /// The mask file.
    pub output: PathBuf,
    /// Its width in pixels.
    pub width: u32,
    /// Its height in pixels.
    pub height: u32,
    /// Triangles drawn (in view).
    pub drawn: usize,
    /// Glass pixels per id.
    pub id_pixels: BTreeMap<u16, u64>,
    /// Each plane's glass rectangle in the frame.
    pub plane_bounds: BTreeMap<u16, PlaneBounds>,
    /// Each deeper pane group's rectangle by `(plane, group)`, groups 1 and on
    /// (`MaskImage::group_bounds` with [`MaskJob::pane_groups`]).
    pub group_bounds: BTreeMap<(u16, usize), PlaneBounds>,
    /// Where the frame's camera is (which side of each plane it sees).
    pub camera_origin: [f64; 3],
}

/// The stages [`mask_frame`] reports, in order.
pub const MASK_STAGES: [&str; 2] = ["rasterise", "write"];

/// The mask of `frame` (`None`: the camera file's one camera): the camera read, the scene
/// rasterised, the mask (and its plane rectangles) written. Neither output may replace a file
/// this process has read or declared as an input (`glassdb_io`), the frame's camera included.
pub fn mask_frame(
    job: &MaskJob<'_>,
    frame: Option<u32>,
    progress: &dyn Progress,
) -> Result<FrameMask, SceneError> {
    let camera_path = job.cameras.path(frame);
    glassdb_io::declare_inputs([camera_path.as_path()]);
    let output = frame_path(&job.output, frame)?;
    glassdb_io::refuse_input_as_output(&output)?;
    let bounds = match &job.bounds {
        Some(b) => Some(frame_path(b, frame)?),
        None => None,
    };
    if let Some(b) = &bounds {
        glassdb_io::refuse_input_as_output(b)?;
    }
    let camera = job.cameras.camera(frame)?;
    let [rasterise_stage, write_stage] = MASK_STAGES;
    progress.stage(rasterise_stage);
    let raster = rasterize(&job.labelled.raster, &camera, &job.options)?;
    let drawn = raster.triangles_drawn;
    let encoding = match job.format {
        MaskFormat::Png8 | MaskFormat::Binary => CosEncoding::Quantized8,
        MaskFormat::Png16 => CosEncoding::Quantized16,
        MaskFormat::Exr => CosEncoding::Float,
    };
    progress.stage(write_stage);
    let mask = to_mask_image(raster, encoding);
    glassdb_mask::write_mask(&output, &mask, job.format)?;
    let group_bounds = mask.group_bounds(|id| job.pane_groups.get(&id).copied().unwrap_or(1));
    if let Some(bounds) = &bounds {
        PlaneBoundsFile::from_mask(&mask, frame, &output.to_string_lossy())
            .with_groups(&group_bounds)
            .write(bounds)?;
    }
    Ok(FrameMask {
        width: mask.width,
        height: mask.height,
        drawn,
        id_pixels: mask.id_pixel_counts(),
        plane_bounds: mask.plane_bounds(),
        group_bounds,
        camera_origin: camera.origin,
        output,
    })
}

/// The masks of `frames`, in order, each handed to `on_frame` as it is done (a frame that fails
/// is handed its error, and the others go on unless `on_frame` breaks). `progress` hears each
/// frame's stages and, before each, the count of frames done.
pub fn mask_frames(
    job: &MaskJob<'_>,
    frames: &[u32],
    progress: &dyn Progress,
    on_frame: &mut dyn FnMut(u32, Result<FrameMask, SceneError>) -> ControlFlow<()>,
) {
    let total = frames.len() as u64;
    for (k, &frame) in frames.iter().enumerate() {
        progress.step(k as u64, total);
        if on_frame(frame, mask_frame(job, Some(frame), progress)).is_break() {
            return;
        }
    }
}

/// `pattern` with its `#` run replaced by `frame`, or as it is (a single frame, or a pattern
/// without one).
fn frame_path(pattern: &Path, frame: Option<u32>) -> Result<PathBuf, SceneError> {
    match frame {
        Some(f) if glassdb_io::is_frame_pattern(pattern) => {
            Ok(glassdb_io::expand_frame_pattern(pattern, f)?)
        }
        _ => Ok(pattern.to_path_buf()),
    }
}
