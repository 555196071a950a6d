//! Animations: file patterns with a `#` run for the frame number (`r.####.exr` → `r.0007.exr`),
//! frame lists (`1-240`, `1,5,10-20`) (both from `glassdb_io::frames`), and every frame composed with two frames in flight at
//! a time (so one frame's decoding overlaps another's encoding) as long as their memory
//! estimates fit the limit together; a frame with missing or bad inputs is reported and the
//! others go on.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use crate::colour::RegistryLuts;
use crate::memory::MemoryBudget;
use crate::{ComposeError, ComposeJob, ComposeSettings, FrameReport, compose_frame_within};

/// Whether `pattern` contains a `#` run (`glassdb_io::frames`, shared with `glassdb mask`).
pub fn is_pattern(pattern: &Path) -> bool {
    glassdb_io::is_frame_pattern(pattern)
}

/// Replaces the last run of `#` in `pattern` by `frame`, zero-padded to the run's length.
pub fn expand(pattern: &Path, frame: u32) -> Result<PathBuf, ComposeError> {
    glassdb_io::expand_frame_pattern(pattern, frame).map_err(ComposeError::from)
}

/// Parses a frame list: `N`, `A-B`, comma-separated, e.g. `1-240` or `1,5,10-20`.
pub fn parse_frames(spec: &str) -> Result<Vec<u32>, ComposeError> {
    glassdb_io::parse_frame_list(spec).map_err(ComposeError::from)
}

/// The job of frame `frame`: every path with a `#` run expanded (paths without one, such as a
/// reflection pass reused for every frame, stay as they are).
pub fn frame_job(pattern: &ComposeJob, frame: u32) -> Result<ComposeJob, ComposeError> {
    let ex = |p: &Path| {
        if is_pattern(p) {
            expand(p, frame)
        } else {
            Ok(p.to_path_buf())
        }
    };
    Ok(ComposeJob {
        refl: pattern
            .refl
            .iter()
            .map(|p| ex(p))
            .collect::<Result<_, _>>()?,
        trans: ex(&pattern.trans)?,
        mask: ex(&pattern.mask)?,
        output: ex(&pattern.output)?,
    })
}

/// The result of one frame.
#[derive(Debug)]
pub struct FrameOutcome {
    pub frame: u32,
    /// The frame's files (`None` when a pattern could not be expanded).
    pub job: Option<ComposeJob>,
    pub result: Result<FrameDone, ComposeError>,
    /// Wall-clock time of the frame, including the check of an existing output.
    pub wall: Duration,
}

/// What became of a frame that did not fail.
#[derive(Debug)]
pub enum FrameDone {
    /// Composited and written; `replaced` says why an existing output was not kept (with
    /// [`SequenceOptions::skip_existing`]: it was incomplete).
    Composed {
        report: Box<FrameReport>,
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
pub fn output_is_complete(path: &Path, max_pixels: u64) -> Result<(), ComposeError> {
    let bytes =
        glassdb_io::read_previous_output(path, glassdb_io::limits::IMAGE).map_err(|cause| {
            ComposeError::Read {
                path: path.to_path_buf(),
                cause,
            }
        })?;
    let decode = |source| ComposeError::Decode {
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

/// Frames composed at once.
pub const FRAMES_IN_FLIGHT: usize = 2;

/// Composes every frame; `on_done` is called as each finishes (from worker threads, in
/// completion order). Returns the outcomes in frame order. The frames in flight share
/// `settings.max_memory`: a frame whose estimate does not fit beside the other's waits for it
/// (so two large frames run one after the other), and a frame over the whole limit fails.
pub fn compose_sequence(
    pattern: &ComposeJob,
    frames: &[u32],
    settings: &ComposeSettings,
    luts: &RegistryLuts,
    options: SequenceOptions,
    on_done: &(dyn Fn(&FrameOutcome) + Sync),
) -> Result<Vec<FrameOutcome>, ComposeError> {
    if !is_pattern(&pattern.output) && frames.len() > 1 {
        return Err(ComposeError::OutputWithoutFramePattern {
            path: pattern.output.clone(),
        });
    }
    let next = AtomicUsize::new(0);
    let budget = MemoryBudget::new(settings.max_memory);
    let results: Mutex<Vec<FrameOutcome>> = Mutex::new(Vec::with_capacity(frames.len()));
    std::thread::scope(|scope| {
        for _ in 0..FRAMES_IN_FLIGHT.min(frames.len()) {
            scope.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&frame) = frames.get(k) else { break };
                    let start = Instant::now();
                    let (job, result) = match frame_job(pattern, frame) {
                        Ok(job) => {
                            let result = compose_or_skip(&job, settings, luts, &budget, options);
                            (Some(job), result)
                        }
                        Err(e) => (None, Err(e)),
                    };
                    let outcome = FrameOutcome {
                        frame,
                        job,
                        result,
                        wall: start.elapsed(),
                    };
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
    luts: &RegistryLuts,
    budget: &MemoryBudget,
    options: SequenceOptions,
) -> Result<FrameDone, ComposeError> {
    let mut replaced = None;
    if options.skip_existing && job.output.exists() {
        match output_is_complete(&job.output, settings.pass.max_pixels) {
            Ok(()) => return Ok(FrameDone::Skipped),
            Err(e) => {
                replaced = Some(format!(
                    "the existing output was incomplete: {}",
                    glassdb_io::ErrorChain(&e)
                ))
            }
        }
    }
    let report = compose_frame_within(job, settings, luts, budget, &glassdb_io::NoProgress)?;
    Ok(FrameDone::Composed {
        report: Box::new(report),
        replaced,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_expand_with_padding() {
        assert_eq!(
            expand(Path::new("r.####.exr"), 7).unwrap(),
            PathBuf::from("r.0007.exr")
        );
        assert_eq!(
            expand(Path::new("d#/t.##.png"), 123).unwrap(),
            PathBuf::from("d#/t.123.png")
        );
        assert!(expand(Path::new("r.exr"), 1).is_err());
    }

    #[test]
    fn frame_lists() {
        assert_eq!(parse_frames("1-3").unwrap(), vec![1, 2, 3]);
        assert_eq!(parse_frames("5, 1-2,2").unwrap(), vec![1, 2, 5]);
        assert!(parse_frames("3-1").is_err());
        assert!(parse_frames("a").is_err());
        assert!(parse_frames("0-4000000").is_err());
    }
}
