//! The glazing compositor (method.md, "Composite", eqs. 8–10): reflection passes (one per glass
//! plane) and a transmission pass, combined through an id + cos θ mask with each glass's r and
//! t from the registry, in linear light.
//!
//! - [`io`]: passes in (EXR, any compression `exr` reads, layer by name; PNG 8/16-bit, sRGB
//!   decoded), results out (EXR half/float with a chosen compression; PNG 8/16-bit sRGB).
//! - [`pixels`]: linear and encoded pixels as different types.
//! - [`lut`]: the per-id lookup tables built once from the registry.
//! - [`colour`]: the passes' colour space and the registry table in it.
//! - [`kernel`]: the per-pixel composite, in place, rayon over rows.
//! - [`sequence`]: frame patterns (`r.####.exr`) and frames in parallel.
//! - [`memory`]: the frame's memory, estimated from the headers, and its limit.
//! - [`compose_frame`]: one image end to end — every input's header read and compared first
//!   (`plan`), then decoded — with per-stage timings for `--stats`.
//!   [`compose_frame_with_progress`] also reports each stage to a `glassdb_io::Progress`.

pub mod colour;
pub mod error;
pub mod frames_report;
pub mod io;
pub mod kernel;
pub mod lut;
pub mod memory;
pub mod pixels;
mod plan;
pub mod sequence;
pub mod view;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub use error::ComposeError;
use glassdb_image::{ImageWindows, PixelWindow};
use glassdb_mask::{MaskImage, MaskReadOptions, PlacedMask};
pub use glassdb_registry::Side;
use memory::{MemoryBudget, MemoryEstimate};
use rayon::prelude::*;

use crate::colour::{ChosenTable, PassSpace, RegistryLuts, SpaceSource};
use crate::io::{OutputFrame, OutputOptions, Pass, PassReadOptions, WrittenOutput};
use crate::kernel::{KernelCounts, KernelInput, OutsidePass, PlacedRefl};
use crate::lut::GlassLut;

/// What to do with mask ids the registry does not have.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UnknownIds {
    /// Refuse, listing the ids and their pixel counts.
    #[default]
    Error,
    /// Leave those pixels as the transmission pass.
    Passthrough,
}

/// What to do with glass pixels of a plane that its reflection pass does not cover (a pass
/// cropped to less than its pane).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OutsidePolicy {
    /// Refuse, naming the plane, the pixel count and their bounding box.
    #[default]
    Error,
    /// Composite them with no reflection (`out = trans·t`).
    NoReflection,
    /// Leave them as the transmission pass.
    Transmission,
}

/// The EXR layer each input is read from (`None`: the default choice, see
/// [`glassdb_image::choose_rgb_layer`]).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct InputLayers {
    pub trans: Option<String>,
    /// Per reflection pass, in order; missing entries take `None`.
    pub refl: Vec<Option<String>>,
}

/// The input and output files of one image.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ComposeJob {
    /// Reflection passes; the k-th belongs to plane k of the mask.
    pub refl: Vec<PathBuf>,
    pub trans: PathBuf,
    pub mask: PathBuf,
    pub output: PathBuf,
}

impl ComposeJob {
    /// Every input file.
    pub fn inputs(&self) -> impl Iterator<Item = &Path> {
        self.refl
            .iter()
            .map(PathBuf::as_path)
            .chain([self.trans.as_path(), self.mask.as_path()])
    }
}

/// Settings shared by every frame.
#[derive(Debug, Clone)]
pub struct ComposeSettings {
    /// How passes are read; its `layer` is the default for inputs without their own.
    pub pass: PassReadOptions,
    /// Layers chosen per input (over `pass.layer`).
    pub layers: InputLayers,
    pub mask: MaskReadOptions,
    /// Glass outside its plane's (cropped) reflection pass.
    pub outside: OutsidePolicy,
    /// Side of each plane that faces the camera; planes not listed show the front.
    pub plane_sides: BTreeMap<usize, Side>,
    pub unknown: UnknownIds,
    pub output: OutputOptions,
    /// The registry's name for messages (its path, or "the bundled catalog").
    pub registry_label: String,
    /// Files that must never be overwritten (e.g. the registry JSON).
    pub protected: Vec<PathBuf>,
    /// The passes' linear RGB space, over what their headers say (`--input-space`).
    pub input_space: Option<glassdb_colour::RgbSpace>,
    /// Bytes a frame may hold (estimated from the headers, [`memory`]); the frames of a
    /// sequence in flight together share it.
    pub max_memory: u64,
}

impl Default for ComposeSettings {
    fn default() -> Self {
        ComposeSettings {
            pass: PassReadOptions::default(),
            layers: InputLayers::default(),
            mask: MaskReadOptions::default(),
            outside: OutsidePolicy::Error,
            plane_sides: BTreeMap::new(),
            unknown: UnknownIds::Error,
            output: OutputOptions::default(),
            registry_label: "the registry".into(),
            protected: Vec::new(),
            input_space: None,
            max_memory: memory::DEFAULT_MAX_MEMORY,
        }
    }
}

/// Wall-clock time of each stage.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StageTimings {
    /// Reading and decoding every input (in parallel).
    pub decode: Duration,
    /// Checks and the per-pixel composite.
    pub compose: Duration,
    /// Encoding and writing the output.
    pub encode: Duration,
}

impl StageTimings {
    pub fn total(&self) -> Duration {
        self.decode + self.compose + self.encode
    }
}

/// What one image's composite did (for `--stats` and messages).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameReport {
    pub output: WrittenOutput,
    /// Size of the output's data window.
    pub width: u32,
    pub height: u32,
    /// The output's data and display windows (the transmission pass's).
    pub windows: ImageWindows,
    pub timings: StageTimings,
    /// Glass pixels per id (id 0 not counted).
    pub id_counts: BTreeMap<u16, u64>,
    /// cos θ range over glass pixels.
    pub cos_range: Option<(f64, f64)>,
    pub counts: KernelCounts,
    /// Number of reflection passes (planes).
    pub planes: usize,
    /// Glass pixels outside their plane's reflection pass (composited as the chosen
    /// [`OutsidePolicy`] says).
    pub outside_pixels: u64,
    /// The passes' colour space and the registry table used.
    pub colour: FrameColour,
    /// The memory estimated from the headers (held within [`ComposeSettings::max_memory`]).
    pub memory: MemoryEstimate,
}

/// The colour facts of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameColour {
    /// The passes' space and how it was known (the transmission pass's; the others agree).
    pub space: PassSpace,
    /// The registry table composited with.
    pub table: ChosenTable,
    /// Whether a PNG output was converted from the passes' space to linear Rec.709 before the
    /// `standard` view's sRGB transfer.
    pub converted_for_display: bool,
}

impl FrameReport {
    /// Megapixels per second over the whole run.
    pub fn megapixels_per_second(&self) -> f64 {
        let s = self.timings.total().as_secs_f64();
        if s > 0.0 {
            f64::from(self.width) * f64::from(self.height) / 1e6 / s
        } else {
            0.0
        }
    }
}

/// Plane sides from a `planes.json` written by `glassdb mirror` (`planes[k].eye_side`), read
/// by the scene crate's own reader (format and plane order checked).
pub fn sides_from_planes_json(
    path: &Path,
    passes: usize,
) -> Result<BTreeMap<usize, Side>, ComposeError> {
    let file = glassdb_scene::PlanesFile::load(path)?;
    if file.planes.len() != passes {
        return Err(ComposeError::PlaneCountMismatch {
            planes_file: path.to_path_buf(),
            planes: file.planes.len(),
            passes,
        });
    }
    Ok(file.planes.iter().map(|p| (p.index, p.eye_side)).collect())
}

/// The decoded inputs of one image.
struct DecodedInputs {
    trans: Pass,
    frame: OutputFrame,
    refl: Vec<Pass>,
    mask: PlacedMask,
}

impl ComposeSettings {
    /// Read options for a pass whose own layer is `layer` (else the default).
    fn pass_options(&self, layer: Option<&Option<String>>) -> PassReadOptions {
        let mut opts = self.pass.clone();
        if let Some(Some(l)) = layer {
            opts.layer = Some(l.clone());
        }
        opts
    }
}

/// Reads the inputs of one image in parallel; the transmission file's attributes (and other
/// channels, when kept) come with it.
fn decode_inputs(
    job: &ComposeJob,
    settings: &ComposeSettings,
    display: &PixelWindow,
    (keep, beside): (bool, bool),
) -> Result<DecodedInputs, ComposeError> {
    let read_trans = || -> Result<(Pass, OutputFrame), ComposeError> {
        let opts = settings.pass_options(Some(&settings.layers.trans));
        io::read_transmission(&job.trans, &opts, (keep, beside), settings.pass.max_pixels)
    };
    // The reflection passes a few at a time (as many as there are threads): each holds its
    // compressed blocks (read from its file by seeking) only while it is decoded, so that many
    // planes do not hold every file at once (`memory` counts it so). Of each, only the rows of
    // its plane's glass in the mask are decoded (`rows`, frame coordinates; a plane without
    // glass decodes one block).
    let read_refl = |rows: &BTreeMap<u16, (i64, i64)>| -> Result<Vec<Pass>, ComposeError> {
        let at_once = memory::decoding_at_once();
        let mut passes = Vec::with_capacity(job.refl.len());
        for (c, chunk) in job.refl.chunks(at_once).enumerate() {
            let decoded = chunk
                .par_iter()
                .enumerate()
                .map(|(i, p)| {
                    let k = c * at_once + i;
                    let rows = u16::try_from(k)
                        .ok()
                        .and_then(|plane| rows.get(&plane))
                        .copied()
                        .unwrap_or((i64::MIN, i64::MIN));
                    io::read_pass_rows(p, &settings.pass_options(settings.layers.refl.get(k)), rows)
                })
                .collect::<Result<Vec<_>, _>>()?;
            passes.extend(decoded);
        }
        Ok(passes)
    };
    let mask_then_refl = || -> Result<(PlacedMask, Vec<Pass>), ComposeError> {
        let mask = glassdb_mask::read_placed_mask(&job.mask, &settings.mask)?;
        let at = in_frame(mask.windows, !mask.has_coordinates, display).data;
        let rows = mask
            .image
            .plane_bounds()
            .into_iter()
            .map(|(plane, b)| {
                let y = i64::from(at.y);
                (plane, (y + i64::from(b.y_min), y + i64::from(b.y_max)))
            })
            .collect();
        let refl = read_refl(&rows)?;
        Ok((mask, refl))
    };
    let (trans, mask_refl) = rayon::join(read_trans, mask_then_refl);
    let (trans, frame) = trans?;
    let (mask, refl) = mask_refl?;
    Ok(DecodedInputs {
        trans,
        frame,
        refl,
        mask,
    })
}

/// Every input must frame the same display window; sizes are named when both are whole frames
/// at the origin (PNGs, full renders).
fn check_frames(
    job: &ComposeJob,
    trans: &ImageWindows,
    others: &[(&Path, ImageWindows)],
) -> Result<(), ComposeError> {
    for (path, w) in others {
        if w.display == trans.display {
            continue;
        }
        let whole = |w: &ImageWindows| w.data == w.display && w.display.x == 0 && w.display.y == 0;
        let size = |w: &PixelWindow| (w.width as u32, w.height as u32);
        return Err(if whole(trans) && whole(w) {
            ComposeError::SizeMismatch {
                a: job.trans.clone(),
                a_size: size(&trans.display),
                b: path.to_path_buf(),
                b_size: size(&w.display),
            }
        } else {
            ComposeError::DisplayWindowMismatch {
                a: job.trans.clone(),
                a_window: trans.display,
                b: path.to_path_buf(),
                b_window: w.display,
            }
        });
    }
    Ok(())
}

/// Checks ids and planes of the mask (placed in the frame) before compositing (that a mask
/// without planes is not given several passes is checked from its header, `plan`).
fn check_inputs(
    job: &ComposeJob,
    settings: &ComposeSettings,
    lut: &GlassLut,
    refl_count: usize,
    mask: &MaskImage,
    id_counts: &BTreeMap<u16, u64>,
) -> Result<(), ComposeError> {
    let unknown: Vec<(u16, u64)> = id_counts
        .iter()
        .filter(|(id, _)| !lut.contains(**id))
        .map(|(a, b)| (*a, *b))
        .collect();
    if !unknown.is_empty() && settings.unknown == UnknownIds::Error {
        return Err(ComposeError::UnknownIds {
            mask: job.mask.clone(),
            registry: settings.registry_label.clone(),
            none_known: unknown.len() == id_counts.len(),
            ids: unknown,
        });
    }
    if mask.max_plane() as usize >= refl_count {
        let mut per_plane: BTreeMap<u16, u64> = BTreeMap::new();
        for (&id, &p) in mask.id.iter().zip(&mask.plane) {
            if id != 0 && p as usize >= refl_count {
                *per_plane.entry(p).or_default() += 1;
            }
        }
        if let Some((&plane, &pixels)) = per_plane.iter().next() {
            return Err(ComposeError::PlaneWithoutPass {
                mask: job.mask.clone(),
                plane,
                pixels,
                passes: refl_count,
            });
        }
    }
    Ok(())
}

/// Glass pixels (with a table) outside their plane's reflection pass: per plane, the count and
/// bounding box in frame-relative coordinates. `windows[k]` is pass k's window relative to the
/// frame.
fn glass_outside_passes(
    mask: &MaskImage,
    lut: &GlassLut,
    windows: &[PixelWindow],
) -> BTreeMap<usize, (u64, PixelWindow)> {
    let frame = PixelWindow::at_origin(mask.width as usize, mask.height as usize);
    if windows.iter().all(|w| w.contains_window(&frame)) {
        return BTreeMap::new();
    }
    mask.plane_bounds_of(|x, y, id, plane| {
        lut.contains(id)
            && windows
                .get(usize::from(plane))
                .is_some_and(|w| !w.contains(i64::from(x), i64::from(y)))
    })
    .into_iter()
    .map(|(plane, b)| (usize::from(plane), (b.glass_pixels, b.window())))
    .collect()
}

/// The windows of an input in the frame `display`: an image without coordinates (a PNG) of the
/// frame's size is that frame, wherever it lies; anything else keeps its own windows.
fn in_frame(
    windows: ImageWindows,
    without_coordinates: bool,
    display: &PixelWindow,
) -> ImageWindows {
    let same_size =
        windows.display.width == display.width && windows.display.height == display.height;
    if without_coordinates && same_size {
        ImageWindows {
            data: *display,
            display: *display,
        }
    } else {
        windows
    }
}

/// `w` in coordinates relative to `origin`'s top-left pixel.
fn relative_to(w: &PixelWindow, origin: &PixelWindow) -> PixelWindow {
    PixelWindow {
        x: w.x - origin.x,
        y: w.y - origin.y,
        ..*w
    }
}

/// `w` (relative to `origin`'s top-left pixel) in absolute coordinates.
fn absolute_from(w: &PixelWindow, origin: &PixelWindow) -> PixelWindow {
    PixelWindow {
        x: w.x + origin.x,
        y: w.y + origin.y,
        ..*w
    }
}

/// One frame's inputs decoded, placed in the transmission pass's frame and checked, ready for
/// the kernel (compose) or for the viewer's GPU textures.
pub struct DecodedFrame<'a> {
    /// The transmission pass: its image is the frame (its data window).
    pub trans: Pass,
    /// What an output would carry from the transmission pass's file.
    pub frame: OutputFrame,
    /// The reflection passes, plane k at k.
    pub refl: Vec<Pass>,
    /// Each reflection pass's data window relative to the frame's top-left pixel.
    pub refl_windows: Vec<PixelWindow>,
    /// The mask, moved into the frame's data window.
    pub mask: MaskImage,
    /// The passes' colour space.
    pub space: PassSpace,
    /// The registry table chosen for that space, and its lookup table.
    pub table: ChosenTable,
    pub lut: &'a GlassLut,
    /// Glass pixels per id.
    pub id_counts: BTreeMap<u16, u64>,
    /// Per plane: glass pixels outside its reflection pass and their bounding box (frame-relative).
    pub outside: BTreeMap<usize, (u64, PixelWindow)>,
    /// The frame's memory estimate.
    pub memory: MemoryEstimate,
    /// The estimate held from the budget until this is dropped.
    pub reservation: memory::Reservation<'a>,
}

/// Reads every input's header and checks the frame from them (memory within `budget`), decodes
/// the inputs, places them in the transmission pass's frame and checks ids, planes and glass
/// outside cropped passes (as `settings` says). `keep` is (carry the transmission file's other
/// channels, the composite goes beside them), as the output will need.
pub fn decode_frame<'a>(
    job: &ComposeJob,
    settings: &ComposeSettings,
    luts: &'a RegistryLuts,
    budget: &'a MemoryBudget,
    keep: (bool, bool),
) -> Result<DecodedFrame<'a>, ComposeError> {
    if job.refl.is_empty() {
        return Err(ComposeError::NoReflectionPass);
    }
    let plan::FramePlan {
        space,
        display,
        refl_windows: stored_refl_windows,
        memory,
    } = plan::plan_frame(job, settings)?;
    let (table, lut) = luts.for_space(&space, &job.trans, &settings.registry_label)?;
    if memory.total > budget.limit() {
        return Err(ComposeError::MemoryLimit {
            trans: job.trans.clone(),
            estimate: memory.total,
            limit: budget.limit(),
            items: memory.items,
            carried: memory.carried,
        });
    }
    let reservation = budget.reserve(memory.total);
    let DecodedInputs {
        trans,
        frame,
        refl,
        mask,
    } = decode_inputs(job, settings, &display, keep)?;
    let data = trans.windows.data;
    let display = trans.windows.display;
    let mask_windows = in_frame(mask.windows, !mask.has_coordinates, &display);
    let refl_windows: Vec<ImageWindows> = refl
        .iter()
        .map(|p| in_frame(p.windows, !p.source.has_coordinates(), &display))
        .collect();
    // Checked again on what was decoded: `plan_frame` checked the headers, and a file
    // replaced between the two reads (a pass re-rendered while a farm composites) must not
    // give a silently misplaced image.
    let mut others: Vec<(&Path, ImageWindows)> = vec![(job.mask.as_path(), mask_windows)];
    others.extend(
        job.refl
            .iter()
            .map(PathBuf::as_path)
            .zip(refl_windows.iter().copied()),
    );
    check_frames(job, &trans.windows, &others)?;
    let PlacedMask { image: mask, .. } = mask;
    let mask = if mask_windows.data == data {
        mask
    } else {
        let placed = mask.placed(&mask_windows.data, &data);
        drop(mask);
        placed
    };
    let id_counts = mask.id_pixel_counts();
    check_inputs(job, settings, lut, refl.len(), &mask, &id_counts)?;
    let windows: Vec<PixelWindow> = refl_windows
        .iter()
        .map(|w| relative_to(&w.data, &data))
        .collect();
    let outside = glass_outside_passes(&mask, lut, &windows);
    if let (OutsidePolicy::Error, Some((&plane, &(pixels, bounds)))) =
        (settings.outside, outside.iter().next())
    {
        return Err(ComposeError::GlassOutsidePass {
            plane,
            pass: job.refl[plane].clone(),
            pixels,
            pass_window: stored_refl_windows
                .get(plane)
                .map_or(refl_windows[plane].data, |w| w.data),
            bounds: absolute_from(&bounds, &data),
        });
    }
    Ok(DecodedFrame {
        trans,
        frame,
        refl,
        refl_windows: windows,
        mask,
        space,
        table,
        lut,
        id_counts,
        outside,
        memory,
        reservation,
    })
}

/// The stages [`compose_frame_with_progress`] reports, in order.
pub const FRAME_STAGES: [&str; 3] = ["decode", "composite", "encode"];

/// Composites one image end to end: read every input's header and check the frame from them
/// (sizes and windows, layers, channels, colour space, memory within
/// [`ComposeSettings::max_memory`]), decode (all inputs in parallel), place every input in the
/// transmission pass's frame by its pixel coordinates, check, composite in place, encode and
/// write atomically. The output may not be one of the inputs.
pub fn compose_frame(
    job: &ComposeJob,
    settings: &ComposeSettings,
    luts: &RegistryLuts,
) -> Result<FrameReport, ComposeError> {
    compose_frame_with_progress(job, settings, luts, &glassdb_io::NoProgress)
}

/// [`compose_frame`], telling `progress` as each of the [`FRAME_STAGES`] begins.
pub fn compose_frame_with_progress(
    job: &ComposeJob,
    settings: &ComposeSettings,
    luts: &RegistryLuts,
    progress: &dyn glassdb_io::Progress,
) -> Result<FrameReport, ComposeError> {
    let budget = MemoryBudget::new(settings.max_memory);
    compose_frame_within(job, settings, luts, &budget, progress)
}

/// [`compose_frame_with_progress`] holding its memory estimate from `budget` (shared by the
/// frames of a sequence) while it decodes, composites and encodes.
pub(crate) fn compose_frame_within(
    job: &ComposeJob,
    settings: &ComposeSettings,
    luts: &RegistryLuts,
    budget: &MemoryBudget,
    progress: &dyn glassdb_io::Progress,
) -> Result<FrameReport, ComposeError> {
    let [decode_stage, composite_stage, encode_stage] = FRAME_STAGES;
    if job.refl.is_empty() {
        return Err(ComposeError::NoReflectionPass);
    }
    let format = io::output_format(&job.output)?;
    io::check_view(&job.output, &settings.output)?;
    if let Some(name) = &settings.output.output_layer {
        io::check_layer_name(name)?;
    }
    glassdb_io::refuse_input_as_output(
        &job.output,
        job.inputs()
            .chain(settings.protected.iter().map(PathBuf::as_path)),
    )?;

    progress.stage(decode_stage);
    let t0 = Instant::now();
    let keep = (
        settings.output.keep_channels && format == io::OutputFormat::Exr,
        settings.output.output_layer.is_some(),
    );
    let DecodedFrame {
        mut trans,
        mut frame,
        refl,
        refl_windows: windows,
        mask,
        space,
        table,
        lut,
        id_counts,
        outside,
        memory,
        reservation: _reserved,
    } = decode_frame(job, settings, luts, budget, keep)?;
    let decode = t0.elapsed();

    progress.stage(composite_stage);
    let t1 = Instant::now();
    let placed: Vec<PlacedRefl<'_>> = refl
        .iter()
        .zip(&windows)
        .enumerate()
        .map(|(k, (p, &window))| {
            let [r, g, b] = &p.image.rgb;
            PlacedRefl {
                rgb: [r.as_slice(), g.as_slice(), b.as_slice()],
                window,
                side: settings.plane_sides.get(&k).copied().unwrap_or(Side::Front),
            }
        })
        .collect();
    let outside_mode = match settings.outside {
        OutsidePolicy::Transmission => OutsidePass::Transmission,
        OutsidePolicy::Error | OutsidePolicy::NoReflection => OutsidePass::NoReflection,
    };
    let [r, g, b] = &mut trans.image.rgb;
    let input = KernelInput::placed([r, g, b], &placed, &mask, lut, outside_mode)?;
    let counts = kernel::compose_in_place(input);
    let cos_range = mask.cos_theta_range();
    let (width, height) = (trans.image.width, trans.image.height);
    drop(placed);
    // Returning a frame's decoded passes to the system takes tens of milliseconds on one core;
    // another thread does it while the encoder keeps both cores busy.
    // Where no thread can be started, the closure, and so the passes, are dropped here.
    let _ = std::thread::Builder::new()
        .name("glassdb-free".into())
        .spawn(move || drop((refl, mask)));
    let compose = t1.elapsed();

    progress.stage(encode_stage);
    let t2 = Instant::now();
    if space.source != SpaceSource::Untagged {
        frame.tag_space = Some(space.space);
    }
    let converted_for_display = format == io::OutputFormat::Png
        && matches!(
            settings.output.view,
            None | Some(view::ViewTransform::Standard)
        )
        && space.space != glassdb_colour::RgbSpace::Srgb;
    if converted_for_display {
        trans.image.convert_rgb(glassdb_colour::rgb_to_rgb(
            space.space,
            glassdb_colour::RgbSpace::Srgb,
        ));
    }
    let output = io::write_output_in_frame(
        &job.output,
        trans.image,
        frame,
        &trans.source,
        &settings.output,
    )?;
    let encode = t2.elapsed();

    Ok(FrameReport {
        output,
        width,
        height,
        windows: trans.windows,
        timings: StageTimings {
            decode,
            compose,
            encode,
        },
        id_counts,
        cos_range,
        counts,
        planes: job.refl.len(),
        outside_pixels: outside.values().map(|(n, _)| n).sum(),
        colour: FrameColour {
            space,
            table,
            converted_for_display,
        },
        memory,
    })
}

#[cfg(test)]
mod tests;
