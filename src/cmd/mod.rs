//! One module per subcommand. Each exposes clap `Args` and `run(args) -> anyhow::Result<ExitCode>`.

pub mod compose;
pub mod fit;
pub mod hints;
pub mod plot;
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
