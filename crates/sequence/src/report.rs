//! `compose --report frames.json`: what became of every frame of a sequence, for a render
//! farm's scripts (schema in docs/farm.md). Written atomically once every frame has finished,
//! failed frames included, or when a signal stops the run ([`SequenceProgress`]): then it
//! says which frames were finished, which the stop interrupted and which never started.

use std::path::Path;

use serde::Serialize;

use std::collections::BTreeMap;
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::Instant;

use glassdb_compose::ComposeJob;

use crate::{FrameDone, FrameOutcome, SequenceError};

/// Value of [`FramesReport::format`].
pub const FRAMES_REPORT_FORMAT: &str = "glassdb-frames-report/1";

/// The whole report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FramesReport {
    /// [`FRAMES_REPORT_FORMAT`].
    pub format: String,
    /// The signal that stopped the run (`"SIGTERM"`), `None` when every frame was done.
    pub stopped_by: Option<String>,
    /// Frames composited, skipped and failed (their numbers), for a quick look.
    pub composed: usize,
    /// Frames whose complete output was kept.
    pub skipped: usize,
    /// The numbers of the frames that failed.
    pub failed: Vec<u32>,
    /// The numbers of the frames the stop interrupted (empty unless stopped).
    pub interrupted: Vec<u32>,
    /// One entry per requested frame, by frame number.
    pub frames: Vec<FrameEntry>,
}

/// One frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameEntry {
    /// The frame number.
    pub frame: u32,
    /// `"composed"`, `"skipped"` (complete output kept) or `"failed"`; in a stopped run also
    /// `"interrupted"` (in flight when the signal came: no output written) and `"not-started"`.
    pub status: &'static str,
    /// The frame's files, patterns expanded (`null` when a pattern could not be expanded).
    pub inputs: Option<FrameInputs>,
    /// The frame's output (`null` when its pattern could not be expanded).
    pub output: Option<String>,
    /// Wall-clock seconds of the frame (until the stop for an interrupted one, 0 for one not
    /// started), and of its stages when composited.
    pub seconds: FrameSeconds,
    /// Why an existing output was replaced (it was incomplete), when it was.
    pub replaced: Option<String>,
    /// The error and its causes, for a failed frame.
    pub error: Option<String>,
    /// The error's class, for a failed frame: `invalid` and `unsupported` inputs fail again
    /// until they are fixed, `limits` may pass on a larger machine or with a higher limit,
    /// `io` may pass on a retry, `internal` is a bug of glassdb's.
    pub error_kind: Option<&'static str>,
}

/// The input files of a frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameInputs {
    /// The reflection passes.
    pub refl: Vec<String>,
    /// The transmission pass.
    pub trans: String,
    /// The mask.
    pub mask: String,
}

/// Seconds per stage; the stages are `null` unless the frame was composited.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FrameSeconds {
    /// The frame's whole time (with the completeness check).
    pub wall: f64,
    /// Decoding every input.
    pub decode: Option<f64>,
    /// The checks and the composite.
    pub compose: Option<f64>,
    /// Encoding and writing the output.
    pub encode: Option<f64>,
}

fn text(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

impl FramesReport {
    /// The report of a finished sequence (outcomes in any order; listed by frame).
    pub fn from_outcomes(outcomes: &[FrameOutcome]) -> FramesReport {
        let frames = outcomes.iter().map(FrameEntry::from_outcome).collect();
        FramesReport::from_entries(frames, None)
    }

    /// The report of `frames` (in any order; listed by frame), stopped by `stopped_by` if any.
    fn from_entries(mut frames: Vec<FrameEntry>, stopped_by: Option<String>) -> FramesReport {
        frames.sort_by_key(|f| f.frame);
        let numbers = |status: &str| -> Vec<u32> {
            frames
                .iter()
                .filter(|f| f.status == status)
                .map(|f| f.frame)
                .collect()
        };
        FramesReport {
            format: FRAMES_REPORT_FORMAT.to_string(),
            stopped_by,
            composed: numbers("composed").len(),
            skipped: numbers("skipped").len(),
            failed: numbers("failed"),
            interrupted: numbers("interrupted"),
            frames,
        }
    }

    /// Writes the report atomically (pretty JSON).
    pub fn write(&self, path: &Path) -> Result<(), SequenceError> {
        let text =
            serde_json::to_string_pretty(self).map_err(|source| SequenceError::EncodeReport {
                path: path.to_path_buf(),
                source,
            })?;
        glassdb_io::create_output_dirs(path)?;
        glassdb_io::write_bytes_atomic(path, format!("{text}\n").as_bytes())?;
        Ok(())
    }
}

impl FrameEntry {
    /// A frame that has no outcome: `status` `interrupted` (after `wall` seconds) or
    /// `not-started`.
    fn unfinished(frame: u32, job: Option<&ComposeJob>, status: &'static str, wall: f64) -> Self {
        FrameEntry {
            frame,
            status,
            inputs: job.map(FrameInputs::of),
            output: job.map(|j| text(&j.output)),
            seconds: FrameSeconds {
                wall,
                decode: None,
                compose: None,
                encode: None,
            },
            replaced: None,
            error: None,
            error_kind: None,
        }
    }

    fn from_outcome(o: &FrameOutcome) -> FrameEntry {
        let mut seconds = FrameSeconds {
            wall: o.wall.as_secs_f64(),
            decode: None,
            compose: None,
            encode: None,
        };
        let (status, replaced, error) = match &o.result {
            Ok(FrameDone::Composed { report, replaced }) => {
                let t = &report.timings;
                seconds.decode = Some(t.decode.as_secs_f64());
                seconds.compose = Some(t.compose.as_secs_f64());
                seconds.encode = Some(t.encode.as_secs_f64());
                ("composed", replaced.clone(), None)
            }
            Ok(FrameDone::Skipped) => ("skipped", None, None),
            Err(e) => ("failed", None, Some(e)),
        };
        FrameEntry {
            frame: o.frame,
            status,
            inputs: o.job.as_ref().map(FrameInputs::of),
            output: o.job.as_ref().map(|j| text(&j.output)),
            seconds,
            replaced,
            error: error.map(|e| glassdb_io::ErrorChain(e).to_string()),
            error_kind: error.map(|e| e.kind().name()),
        }
    }
}

impl FrameInputs {
    fn of(job: &ComposeJob) -> FrameInputs {
        FrameInputs {
            refl: job.inputs.refl.iter().map(|p| text(p)).collect(),
            trans: text(&job.inputs.trans),
            mask: text(&job.inputs.mask),
        }
    }
}

/// A sequence as far as it has got, shared with a stop handler: the entries of the frames
/// finished, the frames in flight and since when. [`crate::compose_sequence`] keeps it up to
/// date; [`SequenceProgress::stopped_report`] is the report of a run stopped by a signal.
#[derive(Debug)]
pub struct SequenceProgress {
    state: Mutex<ProgressState>,
}

#[derive(Debug)]
struct ProgressState {
    /// The output and inputs pattern and the frames asked for.
    pattern: ComposeJob,
    frames: Vec<u32>,
    finished: Vec<FrameEntry>,
    in_flight: BTreeMap<u32, (Option<ComposeJob>, Instant)>,
    /// The report was taken: outcomes that come after it (frames failing because the process
    /// is being stopped) are not the sequence's.
    stopped: bool,
}

impl SequenceProgress {
    /// The progress of `frames` of `pattern`, none started.
    pub fn new(pattern: &ComposeJob, frames: &[u32]) -> SequenceProgress {
        SequenceProgress {
            state: Mutex::new(ProgressState {
                pattern: pattern.clone(),
                frames: frames.to_vec(),
                finished: Vec::with_capacity(frames.len()),
                in_flight: BTreeMap::new(),
                stopped: false,
            }),
        }
    }

    fn lock(&self) -> MutexGuard<'_, ProgressState> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Frame `frame` (its files `job`) starts now.
    pub(crate) fn start(&self, frame: u32, job: Option<&ComposeJob>) {
        self.lock()
            .in_flight
            .insert(frame, (job.cloned(), Instant::now()));
    }

    /// A frame is done.
    pub(crate) fn finish(&self, outcome: &FrameOutcome) {
        let mut s = self.lock();
        if !s.stopped {
            s.in_flight.remove(&outcome.frame);
            s.finished.push(FrameEntry::from_outcome(outcome));
        }
    }

    /// The report of the run stopped now by `signal` (its name): the frames finished as they
    /// ended, those in flight `interrupted`, the others `not-started`. Later outcomes are
    /// ignored.
    pub fn stopped_report(&self, signal: &str) -> FramesReport {
        let mut s = self.lock();
        s.stopped = true;
        let mut entries = s.finished.clone();
        for (&frame, (job, since)) in &s.in_flight {
            let wall = since.elapsed().as_secs_f64();
            entries.push(FrameEntry::unfinished(
                frame,
                job.as_ref(),
                "interrupted",
                wall,
            ));
        }
        let done: std::collections::BTreeSet<u32> = entries.iter().map(|e| e.frame).collect();
        for &frame in s.frames.iter().filter(|f| !done.contains(f)) {
            let job = s.pattern.for_frame(frame).ok();
            entries.push(FrameEntry::unfinished(
                frame,
                job.as_ref(),
                "not-started",
                0.0,
            ));
        }
        FramesReport::from_entries(entries, Some(signal.to_string()))
    }
}
