//! Animations through the compositor (docs/farm.md): every frame of a pattern job
//! (`r.####.exr` → `r.0007.exr`, frame lists such as `1-240`, both from `glassdb_io::frames`)
//! composed with two frames in flight at a time (so one frame's decoding overlaps another's
//! encoding) as long as their memory estimates fit the limit together; a frame with missing or
//! bad inputs is reported and the others go on. With [`SequenceOptions::skip_existing`] a
//! frame whose output is complete is left alone, so that a farm's retry only composites what
//! is missing; [`report`] writes what became of every frame.

#![warn(missing_docs)]

pub mod report;

use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use glassdb_compose::colour::RegistryLuts;
use glassdb_compose::memory::MemoryBudget;
use glassdb_compose::{
    ComposeError, ComposeJob, ComposeSettings, FrameReport, LightGroup, compose_frame_within,
    compose_light_groups_within,
};
use glassdb_io::ErrorKind;

pub use report::{FramesReport, SequenceProgress};

/// Why a frame of a sequence, or the sequence itself, failed.
#[derive(Debug, thiserror::Error)]
pub enum SequenceError {
    /// The frame could not be composited.
    #[error(transparent)]
    Compose(#[from] ComposeError),
    /// A path's frame pattern could not be expanded.
    #[error(transparent)]
    Frame(#[from] glassdb_io::FrameError),
    /// Several frames into one output file.
    #[error(
        "the output {path} has no #### for the frame number, so every frame would overwrite it"
    )]
    OutputWithoutFramePattern {
        /// The output pattern.
        path: std::path::PathBuf,
    },
    /// An existing output could not be read to see whether it is complete.
    #[error("cannot read {path}")]
    ReadOutput {
        /// The output.
        path: std::path::PathBuf,
        /// Why.
        #[source]
        cause: glassdb_io::InputError,
    },
    /// An existing output is not a complete image.
    #[error("{path}")]
    IncompleteOutput {
        /// The output.
        path: std::path::PathBuf,
        /// What the decoder found.
        #[source]
        source: glassdb_image::ImageError,
    },
    /// The frames report could not be encoded as JSON.
    #[error("cannot encode the frames report {path}")]
    EncodeReport {
        /// The report.
        path: std::path::PathBuf,
        /// serde's error.
        #[source]
        source: serde_json::Error,
    },
    /// The frames report could not be written.
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
}

impl SequenceError {
    /// The class of this error: the wrapped error's, invalid for an output pattern that would
    /// put every frame into one file.
    pub fn kind(&self) -> ErrorKind {
        match self {
            SequenceError::Compose(e) => e.kind(),
            SequenceError::Frame(e) => e.kind(),
            SequenceError::ReadOutput { cause, .. } => cause.kind(),
            SequenceError::IncompleteOutput { source, .. } => source.kind(),
            SequenceError::Output(e) => e.kind(),
            SequenceError::OutputWithoutFramePattern { .. } => ErrorKind::Invalid,
            SequenceError::EncodeReport { .. } => ErrorKind::Internal,
        }
    }
}

/// The result of one frame.
#[derive(Debug)]
pub struct FrameOutcome {
    /// The frame number.
    pub frame: u32,
    /// The frame's files (`None` when a pattern could not be expanded).
    pub job: Option<ComposeJob>,
    /// What became of it.
    pub result: Result<FrameDone, SequenceError>,
    /// Wall-clock time of the frame, including the check of an existing output.
    pub wall: Duration,
}

/// What became of a frame that did not fail.
#[derive(Debug)]
pub enum FrameDone {
    /// Composited and written; `replaced` says why an existing output was not kept (with
    /// [`SequenceOptions::skip_existing`]: it was incomplete).
    Composed {
        /// What the composite did.
        report: Box<FrameReport>,
        /// Why an existing output was replaced, when one was.
        replaced: Option<String>,
    },
    /// Left alone: its output exists and is complete ([`output_is_complete`]).
    Skipped,
}

impl FrameOutcome {
    /// The frame's report when it was composited.
    pub fn report(&self) -> Option<&FrameReport> {
        match &self.result {
            Ok(FrameDone::Composed { report, .. }) => Some(report),
            _ => None,
        }
    }
}

/// How a sequence treats outputs that already exist.
#[derive(Debug, Clone, Copy, Default)]
pub struct SequenceOptions {
    /// Skip a frame whose output exists and is complete, so that a rerun (a farm retrying a
    /// chunk) only composites the frames still missing.
    pub skip_existing: bool,
}

/// Checks that `path` is a complete image: a regular file that glassdb-image decodes whole
/// (every pixel of a PNG; every part, channel and chunk of an EXR), within `max_pixels` per
/// part. The error says what is wrong (missing, truncated, corrupt). It does not compare the
/// file with the frame's inputs: after changing an input, rerun without skipping.
pub fn output_is_complete(path: &Path, max_pixels: u64) -> Result<(), SequenceError> {
    let bytes =
        glassdb_io::read_previous_output(path, glassdb_image::IMAGE_FILE).map_err(|cause| {
            SequenceError::ReadOutput {
                path: path.to_path_buf(),
                cause,
            }
        })?;
    let decode = |source| SequenceError::IncompleteOutput {
        path: path.to_path_buf(),
        source,
    };
    match glassdb_image::sniff_image_kind(&bytes) {
        Some(glassdb_image::ImageFileKind::Exr) => {
            glassdb_image::read_exr_exact(&bytes, max_pixels).map_err(decode)?;
        }
        _ => {
            glassdb_image::open_image(&bytes, max_pixels).map_err(decode)?;
        }
    }
    Ok(())
}

/// What each frame of a sequence composites.
#[derive(Debug, Clone, Copy)]
pub enum FrameTables<'a> {
    /// The frame's beauty, with one set of tables.
    One(&'a RegistryLuts),
    /// The frame split into light groups, each with its light's tables, as
    /// [`glassdb_compose::compose_light_groups`] composites one frame (`compose --light-groups`).
    LightGroups {
        /// The groups, in the order summed.
        groups: &'a [LightGroup],
        /// Also write each group's composite as a layer.
        keep_groups: bool,
    },
}

impl FrameTables<'_> {
    /// The tables a frame's report is of: the one set, or the first group's (whose report a
    /// light-group frame returns).
    pub fn report_luts(&self) -> Option<&RegistryLuts> {
        match self {
            FrameTables::One(luts) => Some(luts),
            FrameTables::LightGroups { groups, .. } => groups.first().map(|g| &g.luts),
        }
    }
}

/// Frames composed at once.
pub const FRAMES_IN_FLIGHT: usize = 2;

/// Composes every frame; `on_done` is called as each finishes (from worker threads, in
/// completion order). Returns the outcomes in frame order. The frames in flight share
/// `settings.max_memory`: a frame whose estimate does not fit beside the other's waits for it
/// (so two large frames run one after the other), and a frame over the whole limit fails.
/// `progress` (made for `pattern` and `frames`) follows the frames as they start and end;
/// `tables` says what each frame composites (its beauty, or its light groups).
pub fn compose_sequence(
    pattern: &ComposeJob,
    frames: &[u32],
    settings: &ComposeSettings,
    tables: FrameTables<'_>,
    options: SequenceOptions,
    progress: &SequenceProgress,
    on_done: &(dyn Fn(&FrameOutcome) + Sync),
) -> Result<Vec<FrameOutcome>, SequenceError> {
    if !glassdb_io::is_frame_pattern(&pattern.output) && frames.len() > 1 {
        return Err(SequenceError::OutputWithoutFramePattern {
            path: pattern.output.clone(),
        });
    }
    let next = AtomicUsize::new(0);
    let budget = MemoryBudget::new(settings.decode.max_memory);
    let results: Mutex<Vec<FrameOutcome>> = Mutex::new(Vec::with_capacity(frames.len()));
    std::thread::scope(|scope| {
        for _ in 0..FRAMES_IN_FLIGHT.min(frames.len()) {
            scope.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&frame) = frames.get(k) else { break };
                    let start = Instant::now();
                    let job = pattern.for_frame(frame);
                    progress.start(frame, job.as_ref().ok());
                    let (job, result) = match job {
                        Ok(job) => {
                            let result = compose_or_skip(&job, settings, tables, &budget, options);
                            (Some(job), result)
                        }
                        Err(e) => (None, Err(e.into())),
                    };
                    let outcome = FrameOutcome {
                        frame,
                        job,
                        result,
                        wall: start.elapsed(),
                    };
                    progress.finish(&outcome);
                    on_done(&outcome);
                    if let Ok(mut r) = results.lock() {
                        r.push(outcome);
                    }
                }
            });
        }
    });
    let mut out = results.into_inner().unwrap_or_else(|e| e.into_inner());
    out.sort_by_key(|o| o.frame);
    Ok(out)
}

/// One frame: skipped when asked and its output is complete, else composited.
fn compose_or_skip(
    job: &ComposeJob,
    settings: &ComposeSettings,
    tables: FrameTables<'_>,
    budget: &MemoryBudget,
    options: SequenceOptions,
) -> Result<FrameDone, SequenceError> {
    let mut replaced = None;
    if options.skip_existing && job.output.exists() {
        match output_is_complete(&job.output, settings.decode.pass.max_pixels) {
            Ok(()) => return Ok(FrameDone::Skipped),
            Err(e) => {
                replaced = Some(format!(
                    "the existing output was incomplete: {}",
                    glassdb_io::ErrorChain(&e)
                ))
            }
        }
    }
    let none = &glassdb_io::NoProgress;
    let report = match tables {
        FrameTables::One(luts) => compose_frame_within(job, settings, luts, budget, none)?,
        FrameTables::LightGroups {
            groups,
            keep_groups,
        } => compose_light_groups_within(job, settings, groups, keep_groups, budget, none)?,
    };
    Ok(FrameDone::Composed {
        report: Box::new(report),
        replaced,
    })
}
