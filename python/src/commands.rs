//! `stack` and `spectral`: the commands' own arguments and reports (`glassdb stack --json`,
//! `glassdb spectral --json`), returned as Python objects.

use std::ffi::OsString;
use std::path::PathBuf;

use clap::Parser;
use pyo3::prelude::*;

use crate::errors::{OrRaise, invalid};

/// `glassdb stack`'s arguments.
#[derive(Parser)]
#[command(name = "glassdb stack")]
struct StackCommand {
    #[command(flatten)]
    args: glassdb::cmd::stack::Args,
}

/// `glassdb spectral`'s arguments.
#[derive(Parser)]
#[command(name = "glassdb spectral")]
struct SpectralCommand {
    #[command(flatten)]
    args: glassdb::cmd::spectral::Args,
}

/// A clap error as one message without clap's `error: ` and usage lines.
pub(crate) fn clap_message(e: &clap::Error) -> String {
    let text = e.to_string();
    let first = text.lines().next().unwrap_or_default();
    first.strip_prefix("error: ").unwrap_or(first).to_string()
}

/// Python's `json.loads` of a JSON value.
fn to_python<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(v).or_raise(py)?;
    py.import("json")?.call_method1("loads", (text,))
}

/// The optics of an insulated unit as `glassdb stack --json` prints them (a dict: per angle the
/// photopic, solar and RGB T, Rf, Rb, absorptances and pane-group shares; the layers, gaps and
/// pane groups). `layers`: outside first, each a glazing file with `:flip`, `:model=M`,
/// `:thickness=MM` options as on the command line; `gaps`: `"MM[:GAS]"`, one for every gap or
/// one per gap (default 12.7 mm air); `angles`: degrees, a list or `"START:END:STEP"`;
/// `space`: the RGB space of the colours; `spectra`: also T, Rf, Rb per wavelength.
#[pyfunction]
#[pyo3(signature = (layers, gaps=None, angles=None, space="srgb", spectra=false,
    per_channel=false, combine="per-wavelength"))]
#[allow(clippy::too_many_arguments)]
pub fn stack<'py>(
    py: Python<'py>,
    layers: Vec<PathBuf>,
    gaps: Option<Vec<String>>,
    angles: Option<&Bound<'py, PyAny>>,
    space: &str,
    spectra: bool,
    per_channel: bool,
    combine: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let mut argv: Vec<OsString> = vec!["stack".into()];
    argv.extend(layers.into_iter().map(OsString::from));
    for g in gaps.unwrap_or_default() {
        argv.push(format!("--gap={g}").into());
    }
    if let Some(angles) = angles {
        let spec = match angles.extract::<String>() {
            Ok(s) => s,
            Err(_) => {
                let list: Vec<f64> = angles.extract().map_err(|_| {
                    invalid(py, "angles: a list of degrees or \"START:END:STEP\"".into())
                })?;
                list.iter()
                    .map(f64::to_string)
                    .collect::<Vec<_>>()
                    .join(",")
            }
        };
        argv.push(format!("--angles={spec}").into());
    }
    argv.push(format!("--space={space}").into());
    argv.push(format!("--combine={combine}").into());
    argv.push("--json".into());
    if spectra {
        argv.push("--spectra".into());
    }
    if per_channel {
        argv.push("--per-channel".into());
    }
    let parsed = StackCommand::try_parse_from(argv).map_err(|e| invalid(py, clap_message(&e)))?;
    let report = py.detach(|| glassdb::cmd::stack::report_json(&parsed.args));
    to_python(py, &report.or_raise(py)?)
}

/// A spectral file's per-channel and luminous values as `glassdb spectral --json` prints them
/// (a dict: the method and its settings, the file and product, and per quantity present —
/// `transmittance`, `reflectance`, `reflectance_back` — its `rgb`, `luminous` (ISO 9050) and
/// `luminous_1nm`). `method`: colorimetric (with `observer`, `illuminant`, `space`), paper
/// (with `cmf`) or luminous; `percent`: CSV values in percent; `extrapolate`: hold end values.
#[pyfunction]
#[pyo3(signature = (path, space=None, illuminant=None, observer=None, method="colorimetric",
    cmf=None, percent=false, extrapolate=false))]
#[allow(clippy::too_many_arguments)]
pub fn spectral<'py>(
    py: Python<'py>,
    path: PathBuf,
    space: Option<&str>,
    illuminant: Option<&str>,
    observer: Option<&str>,
    method: &str,
    cmf: Option<&str>,
    percent: bool,
    extrapolate: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let mut argv: Vec<OsString> = vec!["spectral".into(), path.into()];
    argv.push(format!("--method={method}").into());
    for (flag, value) in [
        ("space", space),
        ("illuminant", illuminant),
        ("observer", observer),
        ("cmf", cmf),
    ] {
        if let Some(v) = value {
            argv.push(format!("--{flag}={v}").into());
        }
    }
    if percent {
        argv.push("--percent".into());
    }
    if extrapolate {
        argv.push("--extrapolate".into());
    }
    argv.push("--json".into());
    let parsed =
        SpectralCommand::try_parse_from(argv).map_err(|e| invalid(py, clap_message(&e)))?;
    let report = py.detach(|| glassdb::cmd::spectral::report_json(&parsed.args));
    to_python(py, &report.or_raise(py)?)
}
