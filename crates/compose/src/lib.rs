//! The glazing compositor (method.md, "Composite", eqs. 8–10): reflection passes (one per glass
//! plane) and a transmission pass, combined through an id + cos θ mask with each glass's r and
//! t from the registry, in linear light.
//!
//! A frame goes through four phases, each in its own file, and a frame's settings enter each
//! file once per phase:
//!
//! 1. header (`plan.rs`): every input's header read and compared before any pixel is decoded,
//!    the passes' colour space and registry table chosen ([`colour`]), and the frame's memory
//!    estimated from them and held ([`memory`]);
//! 2. decode (`decode.rs`): the inputs decoded in parallel (glassdb-pass reads the passes,
//!    glassdb-mask the mask), placed in the transmission pass's frame and checked;
//! 3. composite (`composite.rs`): the per-pixel composite ([`kernel`]), in place, with the
//!    tables of [`lut`] in the passes' colour space;
//! 4. write (`write.rs`): glassdb-encode writes the composite as EXR or PNG, atomically.
//!
//! [`compose_frame`] runs them for one image, with per-stage timings for `--stats`;
//! [`compose_frame_with_progress`] also reports each stage to a `glassdb_io::Progress`. The
//! viewer runs the first two ([`decode_frame`]), with no output at all. A frame split into
//! light groups is [`compose_light_groups`]: the phases once per group, each with its light's
//! table (the groups after the first in row bands, into the sum), and the sum written
//! ([`light_groups`]). A frame split by the light's path is
//! [`compose_light_parts`]: each part scaled by what its aperture's glass passes, the parts
//! summed as each pass is read, composited once ([`relight`], the relit swap).
//! [`compose_in_memory`] composites a host
//! application's arrays with the same checks and kernel, without files.

#![warn(missing_docs)]

mod bands;
pub mod colour;
mod composite;
mod decode;
pub mod error;
mod in_memory;
pub mod kernel;
pub mod light_groups;
pub mod light_parts;
pub mod lut;
pub mod memory;
mod pane_groups;
mod place;
mod plan;
pub mod relight;
pub mod shares;
mod write;

use std::collections::BTreeMap;
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub use decode::{DecodedFrame, DecodedGroupPass};
pub use error::ComposeError;
use glassdb_encode::{OutputFormat, OutputOptions, WrittenOutput};
use glassdb_image::ImageWindows;
use glassdb_mask::MaskReadOptions;
use glassdb_pass::{Carry, PassReadOptions};
use glassdb_side::Side;
pub use in_memory::{
    MemoryComposite, MemoryFrame, MemoryGroup, MemoryLabels, compose_in_memory,
    compose_light_groups_in_memory, interleave, planes_from_interleaved,
};
pub use light_groups::{
    GroupPasses, LightGroup, compose_light_groups, compose_light_groups_within, group_passes,
};
use memory::{MemoryBudget, MemoryEstimate};
pub use plan::DecodeTarget;
pub use relight::{
    ApertureGlass, FactorKind, PartFactor, PartTables, RelitReport, compose_light_parts,
    part_factors, part_passes, read_light_parts,
};

use crate::colour::{ChosenTable, PassSpace, RegistryLuts};
use crate::composite::Composited;
use crate::kernel::KernelCounts;

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
    /// The transmission pass's layer.
    pub trans: Option<String>,
    /// Per reflection pass, in order; missing entries take `None`.
    pub refl: Vec<Option<String>>,
}

/// The input files of one frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameFiles {
    /// Reflection passes; the k-th belongs to plane k of the mask (the first pane group its
    /// rays meet).
    pub refl: Vec<PathBuf>,
    /// The reflection passes of units' deeper pane groups (issue 27), each on a plane of
    /// `refl`.
    pub groups: Vec<GroupPassFile>,
    /// The transmission pass: its image is the frame.
    pub trans: PathBuf,
    /// The id + cos θ mask.
    pub mask: PathBuf,
}

/// The reflection pass of a unit's pane group behind the first: the scene mirrored about the
/// group's mid-plane (docs/compose.md, "Units").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GroupPassFile {
    /// The plane (its own pass is `FrameFiles::refl[plane]`).
    pub plane: usize,
    /// The pane group, 1 or more, counted in the order the camera's rays meet the groups (from
    /// the front: the outer pane is 0; from the back: the inner pane is 0).
    pub group: usize,
    /// The file.
    pub path: PathBuf,
    /// Its EXR layer (`None`: the default choice).
    pub layer: Option<String>,
}

impl FrameFiles {
    /// The input files of one frame without pane-group passes.
    pub fn new(refl: Vec<PathBuf>, trans: PathBuf, mask: PathBuf) -> FrameFiles {
        FrameFiles {
            refl,
            groups: Vec::new(),
            trans,
            mask,
        }
    }

    /// Every input file.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.refl
            .iter()
            .map(PathBuf::as_path)
            .chain(self.groups.iter().map(|g| g.path.as_path()))
            .chain([self.trans.as_path(), self.mask.as_path()])
    }

    /// Every reflection pass with its plane: the planes' own, then the pane groups'.
    pub(crate) fn reflection_inputs(&self) -> Vec<(usize, &Path)> {
        self.refl
            .iter()
            .enumerate()
            .map(|(k, p)| (k, p.as_path()))
            .chain(self.groups.iter().map(|g| (g.plane, g.path.as_path())))
            .collect()
    }

    /// The files of frame `frame`: every path with a `#` run expanded (paths without one, such
    /// as a reflection pass reused for every frame, stay as they are).
    pub fn for_frame(&self, frame: u32) -> Result<FrameFiles, glassdb_io::FrameError> {
        Ok(FrameFiles {
            refl: self
                .refl
                .iter()
                .map(|p| frame_path(p, frame))
                .collect::<Result<_, _>>()?,
            groups: self
                .groups
                .iter()
                .map(|g| {
                    Ok(GroupPassFile {
                        path: frame_path(&g.path, frame)?,
                        ..g.clone()
                    })
                })
                .collect::<Result<_, _>>()?,
            trans: frame_path(&self.trans, frame)?,
            mask: frame_path(&self.mask, frame)?,
        })
    }
}

/// `path` with its `#` run replaced by `frame`, or as it is without one.
fn frame_path(path: &Path, frame: u32) -> Result<PathBuf, glassdb_io::FrameError> {
    if glassdb_io::is_frame_pattern(path) {
        glassdb_io::expand_frame_pattern(path, frame)
    } else {
        Ok(path.to_path_buf())
    }
}

/// The input and output files of one image.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ComposeJob {
    /// The passes and the mask.
    pub inputs: FrameFiles,
    /// The composite, `.exr` or `.png`.
    pub output: PathBuf,
}

impl ComposeJob {
    /// The job of frame `frame`: the inputs' and the output's `#` runs expanded.
    pub fn for_frame(&self, frame: u32) -> Result<ComposeJob, glassdb_io::FrameError> {
        Ok(ComposeJob {
            inputs: self.inputs.for_frame(frame)?,
            output: frame_path(&self.output, frame)?,
        })
    }
}

/// How a frame's inputs are read and checked: everything [`decode_frame`] needs, and nothing of
/// the output.
#[derive(Debug, Clone)]
pub struct DecodeSettings {
    /// How passes are read; its `layer` is the default for inputs without their own.
    pub pass: PassReadOptions,
    /// Layers chosen per input (over `pass.layer`).
    pub layers: InputLayers,
    /// How the mask is read.
    pub mask: MaskReadOptions,
    /// The passes' linear RGB space, over what their headers say (`--input-space`).
    pub input_space: Option<glassdb_colour::RgbSpace>,
    /// Mask ids the registry does not have.
    pub unknown: UnknownIds,
    /// Glass outside its plane's (cropped) reflection pass.
    pub outside: OutsidePolicy,
    /// How many of a unit's pane groups get a reflection pass of their own (`None`: all; the
    /// deeper groups' reflectance goes to the last one's pass, so `1` is one pass per plane).
    pub max_groups: Option<NonZeroUsize>,
    /// The registry's name for messages (its path, or "the bundled catalog").
    pub registry_label: String,
    /// Bytes a frame may hold (estimated from the headers, [`memory`]); the frames of a
    /// sequence in flight together share it.
    pub max_memory: u64,
}

impl Default for DecodeSettings {
    fn default() -> Self {
        DecodeSettings {
            pass: PassReadOptions::default(),
            layers: InputLayers::default(),
            mask: MaskReadOptions::default(),
            input_space: None,
            unknown: UnknownIds::Error,
            outside: OutsidePolicy::Error,
            max_groups: None,
            registry_label: "the registry".into(),
            max_memory: memory::DEFAULT_MAX_MEMORY,
        }
    }
}

/// Settings shared by every frame of a composite.
#[derive(Debug, Clone, Default)]
pub struct ComposeSettings {
    /// How the inputs are read and checked.
    pub decode: DecodeSettings,
    /// Side of each plane that faces the camera; planes not listed show the front.
    pub plane_sides: BTreeMap<usize, Side>,
    /// How the composite is written.
    pub output: OutputOptions,
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
    /// The three stages together.
    pub fn total(&self) -> Duration {
        self.decode + self.compose + self.encode
    }
}

/// What one image's composite did (for `--stats` and messages).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameReport {
    /// The file written.
    pub output: WrittenOutput,
    /// Width of the output's data window.
    pub width: u32,
    /// Height of the output's data window.
    pub height: u32,
    /// The output's data and display windows (the transmission pass's).
    pub windows: ImageWindows,
    /// Wall-clock time of each stage.
    pub timings: StageTimings,
    /// Glass pixels per id (id 0 not counted).
    pub id_counts: BTreeMap<u16, u64>,
    /// cos θ range over glass pixels.
    pub cos_range: Option<(f64, f64)>,
    /// What the kernel counted (non-finite samples, pixels passed through).
    pub counts: KernelCounts,
    /// Number of reflection passes (planes).
    pub planes: usize,
    /// Number of pane groups' reflection passes (beyond the planes' own).
    pub group_passes: usize,
    /// Glass pixels of units whose deeper pane groups were composited on a nearer group's pass
    /// ([`DecodeSettings::max_groups`]).
    pub folded_pixels: u64,
    /// Glass pixels outside their plane's reflection pass (composited as the chosen
    /// [`OutsidePolicy`] says).
    pub outside_pixels: u64,
    /// The passes' colour space and the registry table used.
    pub colour: FrameColour,
    /// The memory estimated from the headers (held within [`DecodeSettings::max_memory`]).
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

/// The stages [`compose_frame_with_progress`] reports, in order.
pub const FRAME_STAGES: [&str; 3] = ["decode", "composite", "encode"];

/// Composites one image end to end: read every input's header and check the frame from them
/// (sizes and windows, layers, channels, colour space, memory within
/// [`DecodeSettings::max_memory`]), decode (all inputs in parallel), place every input in the
/// transmission pass's frame by its pixel coordinates, check, composite in place, encode and
/// write atomically. The output may not be one of the inputs: they are declared as this
/// process's inputs (`glassdb_io::declare_inputs`), which the binaries protect.
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
    let budget = MemoryBudget::new(settings.decode.max_memory);
    compose_frame_within(job, settings, luts, &budget, progress)
}

/// [`compose_frame_with_progress`] holding its memory estimate from `budget` (shared by the
/// frames of a sequence) while it decodes, composites and encodes.
pub fn compose_frame_within(
    job: &ComposeJob,
    settings: &ComposeSettings,
    luts: &RegistryLuts,
    budget: &MemoryBudget,
    progress: &dyn glassdb_io::Progress,
) -> Result<FrameReport, ComposeError> {
    let target = check_job(job, settings)?;
    let read = SharedRead {
        carry: target.carry,
        mask: None,
    };
    let (composited, timings) =
        decode_and_composite(job, settings, &target, luts, budget, read, progress)?;
    write_composited(job, settings, composited, timings, progress)
}

/// How one of several composites of a frame (its light groups) reads what they share.
#[derive(Clone, Copy)]
struct SharedRead<'a> {
    /// What the transmission file carries over in this read: the target's, or nothing where
    /// the output's channels are read once the composites are summed.
    carry: Carry,
    /// The frame's mask, decoded once for all of them.
    mask: Option<&'a decode::MaskOnce>,
}

/// The header, decode and composite phases of a checked job, timed, telling `progress` as
/// each begins; `target` is what the frame's memory is estimated for, `read` what this
/// composite reads of what the frame's composites share.
fn decode_and_composite(
    job: &ComposeJob,
    settings: &ComposeSettings,
    target: &DecodeTarget,
    luts: &RegistryLuts,
    budget: &MemoryBudget,
    read: SharedRead<'_>,
    progress: &dyn glassdb_io::Progress,
) -> Result<(Composited, StageTimings), ComposeError> {
    let [decode_stage, composite_stage, _] = FRAME_STAGES;
    progress.stage(decode_stage);
    let t0 = Instant::now();
    let plan = plan::plan_frame(&job.inputs, &settings.decode, luts, budget, target)?;
    let frame = decode::decode_planned(&job.inputs, &settings.decode, plan, read.carry, read.mask)?;
    let decode = t0.elapsed();

    progress.stage(composite_stage);
    let t1 = Instant::now();
    let composited = composite::composite(frame, settings, read.mask)?;
    let compose = t1.elapsed();
    let timings = StageTimings {
        decode,
        compose,
        encode: Duration::ZERO,
    };
    Ok((composited, timings))
}

/// The write phase of a composited frame, and its report.
fn write_composited(
    job: &ComposeJob,
    settings: &ComposeSettings,
    composited: Composited,
    mut timings: StageTimings,
    progress: &dyn glassdb_io::Progress,
) -> Result<FrameReport, ComposeError> {
    progress.stage(FRAME_STAGES[2]);
    let t2 = Instant::now();
    let (output, colour) = write::write(job, composited.image, settings)?;
    timings.encode = t2.elapsed();

    let Composited { facts, .. } = composited;
    Ok(FrameReport {
        output,
        width: facts.width,
        height: facts.height,
        windows: facts.windows,
        timings,
        id_counts: facts.id_counts,
        cos_range: facts.cos_range,
        counts: facts.counts,
        planes: job.inputs.refl.len(),
        group_passes: job.inputs.groups.len(),
        folded_pixels: facts.folded_pixels,
        outside_pixels: facts.outside_pixels,
        colour,
        memory: facts.memory,
    })
}

/// Reads every input's header and checks the frame from them (memory within `budget`), decodes
/// the inputs, places them in the transmission pass's frame and checks ids, planes and glass
/// outside cropped passes (as `settings` says): the header and decode phases, with no output.
/// `target` says what the transmission file carries over and what the frame will be encoded
/// as ([`DecodeTarget::display`] for a frame that is only shown).
pub fn decode_frame<'a>(
    files: &FrameFiles,
    settings: &DecodeSettings,
    luts: &'a RegistryLuts,
    budget: &'a MemoryBudget,
    target: &DecodeTarget,
) -> Result<DecodedFrame<'a>, ComposeError> {
    let plan = plan::plan_frame(files, settings, luts, budget, target)?;
    decode::decode_planned(files, settings, plan, target.carry, None)
}

/// Refuses a job before any pixel is read: no reflection pass, an output that cannot be
/// written as asked, an output that is one of the inputs (declared here; the binaries protect
/// every file declared or read). Returns what the frame is decoded
/// for.
fn check_job(job: &ComposeJob, settings: &ComposeSettings) -> Result<DecodeTarget, ComposeError> {
    if job.inputs.refl.is_empty() {
        return Err(ComposeError::NoReflectionPass);
    }
    let opts = &settings.output;
    let format = glassdb_encode::check_output(&job.output, opts)?;
    glassdb_io::declare_inputs(job.inputs.paths());
    glassdb_io::refuse_input_as_output(&job.output)?;
    Ok(DecodeTarget {
        carry: Carry {
            keep_channels: opts.keep_channels && format == OutputFormat::Exr,
            beside: opts.output_layer.is_some(),
        },
        encoding: glassdb_encode::Encoding::of(&job.output, opts)?,
        name: memory::file_label(&job.output),
    })
}

#[cfg(test)]
mod pane_groups_tests;
#[cfg(test)]
mod tests;
