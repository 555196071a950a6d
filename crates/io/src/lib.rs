//! File input and output shared by every glassdb tool.
//!
//! - [`output`]: atomic output (a temporary file beside the target, renamed over it when
//!   complete), [`StagedOutput`] for several files that land together, and the refusal of an
//!   output that is one of the run's inputs or not a regular file.
//! - [`input`]: [`read_input`], the one bounded reader of every input file, with the limit of
//!   each kind of file in [`limits`].
//! - [`protect_inputs`] and [`exit_removing_temporaries`]: the process-wide records that keep
//!   every file read safe from the outputs and let a signal handler remove the unfinished
//!   temporary files (docs/reliability.md); [`on_stop`]: what a stop still writes.
//! - [`ChildGroup`]: a program started in a process group of its own, stopped with everything
//!   it started on a timeout or when the process is stopped.
//! - [`frames`]: frame patterns and frame lists of animations.
//! - [`progress`]: the observer through which libraries report the progress of long work.
//! - [`quoted`]: a value from an input quoted in a message, cut to a bounded length.
//! - [`sniff`]: binary data handed to a text reader, named from its signature.
//! - [`enum_names!`]: the names of a small enum (`name()`, `Display`, `from_name`), from one
//!   table.
//! - [`ErrorKind`]: the class of every glassdb error (invalid, unsupported, limits, I/O,
//!   internal), which each library's error type reports through its `kind()`.

#![warn(missing_docs)]

mod children;
mod error_kind;
pub mod frames;
pub mod input;
mod kind;
mod names;
pub mod output;
mod registry;
pub mod sniff;

pub use children::ChildGroup;
pub use error_kind::ErrorKind;
pub use frames::{FrameError, expand_frame_pattern, is_frame_pattern, parse_frame_list};
pub use input::{
    InputError, InputLimit, limits, open_input, read_input, read_input_string, read_open_input,
    read_previous_output,
};
pub use kind::{FileKind, lowercase_extension};
pub use output::{
    OutputError, StagedOutput, SyncingFile, create_output_dirs, create_output_folder,
    refuse_input_as_output, write_atomic, write_bytes_atomic,
};
pub use registry::{
    OnStop, TEMP_PREFIX, declare_inputs, exit_removing_temporaries, on_stop, protect_inputs,
};
pub mod progress;
mod quote;
pub use progress::{NoProgress, Progress, StageLog};
pub use quote::{BoundedError, MAX_QUOTED_CHARS, Quoted, backticked, bounded_message, quoted};

/// Displays an error with its causes as `outer: cause: root`, as `anyhow`'s `{:#}` does, for
/// messages that are printed or written without going through `anyhow`.
pub struct ErrorChain<'a>(pub &'a (dyn std::error::Error + 'static));

impl std::fmt::Display for ErrorChain<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)?;
        let mut cause = self.0.source();
        while let Some(c) = cause {
            write!(f, ": {c}")?;
            cause = c.source();
        }
        Ok(())
    }
}
