//! One module per subcommand. Each exposes clap `Args` and `run(args) -> anyhow::Result<ExitCode>`.
//! Command output goes through `outln!` / `out!` ([`out`]: a closed pipe ends the process
//! quietly instead of panicking).

/// `println!` for command output, through [`out::write`].
macro_rules! outln {
    () => {
        $crate::cmd::out::write(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::cmd::out::write(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` for command output, through [`out::write`].
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cmd::out::write(format_args!($($arg)*))
    };
}

pub mod compose;
pub mod fit;
pub mod hints;
pub mod out;
pub mod plot;
pub mod progress;
pub mod registry;
pub mod report;
pub mod scene;
pub mod spectral;

use std::process::ExitCode;

/// Exit code for a run that failed on its input or output (clap uses 2 for usage errors).
pub const EXIT_FAILURE: u8 = 1;

/// Turns a subcommand's result into the process exit code, printing the whole error chain and
/// the hints that say which flag or command fixes it.
pub fn finish(result: anyhow::Result<ExitCode>) -> ExitCode {
    match result {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {err:#}");
            for hint in hints::hints(&err) {
                eprintln!("hint: {hint}");
            }
            ExitCode::from(EXIT_FAILURE)
        }
    }
}

/// The exit of a command over frames: success, or the failed frames listed and exit code 1.
pub(crate) fn frames_exit(failed: &[u32], total: usize) -> ExitCode {
    if failed.is_empty() {
        return ExitCode::SUCCESS;
    }
    let list: Vec<String> = failed.iter().map(u32::to_string).collect();
    eprintln!(
        "error: {} of {total} frame(s) failed: {}",
        failed.len(),
        list.join(", ")
    );
    ExitCode::from(EXIT_FAILURE)
}
