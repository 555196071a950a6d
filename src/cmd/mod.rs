//! One module per subcommand. Each exposes clap `Args` and `run(args) -> anyhow::Result<ExitCode>`.

pub mod compose;
pub mod fit;
pub mod plot;
pub mod registry;
pub mod report;
pub mod scene;
pub mod spectral;

use std::fmt;
use std::process::ExitCode;

use glassdb_fit::FitError;
use glassdb_registry::RegistryError;
use glassdb_spectral::SpectralError;

/// Exit code for a run that failed on its input or output (clap uses 2 for usage errors).
pub const EXIT_FAILURE: u8 = 1;

/// Turns a subcommand's result into the process exit code, printing the whole error chain.
pub fn finish(result: anyhow::Result<ExitCode>) -> ExitCode {
    match result {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(EXIT_FAILURE)
        }
    }
}

/// A library error followed by the command-line hint that fixes it: libraries say what is
/// wrong, only the binary knows its flags. The error's own causes stay its sources.
#[derive(Debug)]
pub struct WithHint<E> {
    pub error: E,
    pub hint: String,
}

impl<E: fmt::Display> fmt::Display for WithHint<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", self.error, self.hint)
    }
}

impl<E: std::error::Error> std::error::Error for WithHint<E> {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.error.source()
    }
}

fn hinted<E>(error: E, hint: Option<String>) -> anyhow::Error
where
    E: std::error::Error + Send + Sync + 'static,
{
    match hint {
        Some(hint) => anyhow::Error::new(WithHint { error, hint }),
        None => anyhow::Error::new(error),
    }
}

/// An angle-table or fit error with the flag that fixes it, if one does.
pub fn fit_error(error: FitError) -> anyhow::Error {
    let hint = match &error {
        FitError::AboveOneInFractions { .. } => {
            Some("if the table is in percent, pass --percent".to_string())
        }
        _ => None,
    };
    hinted(error, hint)
}

/// A spectral read or integration error with the flag that fixes it, if one does.
pub fn spectral_error(error: SpectralError) -> anyhow::Error {
    let hint = match &error {
        SpectralError::AboveOneInFractions { .. } => {
            Some("if the file is in percent, pass --percent".to_string())
        }
        SpectralError::FractionsReadAsPercent { .. } => Some("drop --percent".to_string()),
        SpectralError::PartialCoverage { .. } => {
            Some("pass --extrapolate to hold the end values constant outside the data".to_string())
        }
        _ => None,
    };
    hinted(error, hint)
}

/// A registry error with the command that fixes it, if one does (an old schema: rebuild).
pub fn registry_error(error: RegistryError) -> anyhow::Error {
    let hint = match &error {
        RegistryError::SchemaVersion { source_name, .. } => Some(format!(
            "rebuild it: glassdb registry build CATALOG.toml -o {source_name}"
        )),
        RegistryError::Integration { source, .. }
            if matches!(**source, SpectralError::PartialCoverage { .. }) =>
        {
            Some("pass --extrapolate to hold the end values constant outside the data".to_string())
        }
        _ => None,
    };
    hinted(error, hint)
}
