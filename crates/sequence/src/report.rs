//! `compose --report frames.json`: what became of every frame of a sequence, for a render
//! farm's scripts (schema in docs/farm.md). Written atomically once every frame has finished,
//! failed frames included.

use std::path::Path;

use serde::Serialize;

use crate::{FrameDone, FrameOutcome, SequenceError};

/// Value of [`FramesReport::format`].
pub const FRAMES_REPORT_FORMAT: &str = "glassdb-frames-report/1";

/// The whole report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FramesReport {
    /// [`FRAMES_REPORT_FORMAT`].
    pub format: String,
    /// Frames composited, skipped and failed (their numbers), for a quick look.
    pub composed: usize,
    /// Frames whose complete output was kept.
    pub skipped: usize,
    /// The numbers of the frames that failed.
    pub failed: Vec<u32>,
    /// One entry per requested frame, by frame number.
    pub frames: Vec<FrameEntry>,
}

/// One frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameEntry {
    /// The frame number.
    pub frame: u32,
    /// `"composed"`, `"skipped"` (complete output kept) or `"failed"`.
    pub status: &'static str,
    /// The frame's files, patterns expanded (`null` when a pattern could not be expanded).
    pub inputs: Option<FrameInputs>,
    /// The frame's output (`null` when its pattern could not be expanded).
    pub output: Option<String>,
    /// Wall-clock seconds of the frame, and of its stages when composited.
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
        let mut frames: Vec<FrameEntry> = outcomes.iter().map(FrameEntry::from_outcome).collect();
        frames.sort_by_key(|f| f.frame);
        FramesReport {
            format: FRAMES_REPORT_FORMAT.to_string(),
            composed: frames.iter().filter(|f| f.status == "composed").count(),
            skipped: frames.iter().filter(|f| f.status == "skipped").count(),
            failed: frames
                .iter()
                .filter(|f| f.status == "failed")
                .map(|f| f.frame)
                .collect(),
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
            inputs: o.job.as_ref().map(|j| FrameInputs {
                refl: j.inputs.refl.iter().map(|p| text(p)).collect(),
                trans: text(&j.inputs.trans),
                mask: text(&j.inputs.mask),
            }),
            output: o.job.as_ref().map(|j| text(&j.output)),
            seconds,
            replaced,
            error: error.map(|e| glassdb_io::ErrorChain(e).to_string()),
            error_kind: error.map(|e| e.kind().name()),
        }
    }
}
