//! Errors as Python exceptions: the class of the error's `glassdb_io::ErrorKind` (defined in
//! python/glassdb/_errors.py, so that `IoError` is also an `OSError` and `InvalidInput` a
//! `ValueError`), with the message `glassdb` prints after `error: ` and its hints.

use glassdb_io::ErrorKind;
use pyo3::prelude::*;

/// The Python class name of each kind (python/glassdb/_errors.py).
fn class_name(kind: Option<ErrorKind>) -> &'static str {
    match kind {
        // No library made it: an argument the front-end refused, as the binary does.
        None | Some(ErrorKind::Invalid) => "InvalidInput",
        Some(ErrorKind::Unsupported) => "Unsupported",
        Some(ErrorKind::Limits) => "LimitExceeded",
        Some(ErrorKind::Io) => "IoError",
        Some(ErrorKind::Internal) => "InternalError",
    }
}

/// `err` as the exception the Python package raises: its class from the error's kind (that
/// of the first glassdb error in its cause chain, as the binaries decide their exit code), its
/// message the whole chain as `glassdb` prints it, and `hints` the lines it prints after.
pub(crate) fn to_py(py: Python<'_>, err: anyhow::Error) -> PyErr {
    let kind = glassdb::cmd::hints::kind(&err);
    let message = format!("{err:#}");
    let hints = glassdb::cmd::hints::hints(&err);
    let made = py
        .import("glassdb._errors")
        .and_then(|m| m.getattr(class_name(kind)))
        .and_then(|class| class.call1((message.clone(), hints)));
    match made {
        Ok(exception) => PyErr::from_value(exception),
        // The package's own module is missing (the extension imported alone).
        Err(e) => e,
    }
}

/// A front-end's refusal of an argument (an `InvalidInput`), worded as `what`.
pub(crate) fn invalid(py: Python<'_>, what: String) -> PyErr {
    to_py(py, anyhow::Error::msg(what))
}

/// The value of `choices` named `given` for the argument `argument`; an `InvalidInput` naming
/// the choices otherwise (`aovs: "x"; expected "glass-only" or "every-material"`).
pub(crate) fn choose<T: Copy>(
    py: Python<'_>,
    argument: &str,
    given: &str,
    choices: &[(&str, T)],
) -> PyResult<T> {
    match choices.iter().find(|(name, _)| *name == given) {
        Some(&(_, value)) => Ok(value),
        None => {
            let names: Vec<String> = choices
                .iter()
                .map(|(name, _)| format!("{name:?}"))
                .collect();
            Err(invalid(
                py,
                format!("{argument}: {given:?}; expected {}", names.join(" or ")),
            ))
        }
    }
}

/// `Result<T, E>` into a `PyResult<T>` through [`to_py`].
pub(crate) trait OrRaise<T> {
    /// The value, or the error raised as its class.
    fn or_raise(self, py: Python<'_>) -> PyResult<T>;
}

impl<T, E: Into<anyhow::Error>> OrRaise<T> for Result<T, E> {
    fn or_raise(self, py: Python<'_>) -> PyResult<T> {
        self.map_err(|e| to_py(py, e.into()))
    }
}
