//! The fit file (`{"glasses": [...]}`, `docs/fit-json.md`) that `glassdb fit -o` writes and
//! `glassdb eval`, `glassdb plot` and the registry builder read, validated on every read as
//! every reader of fit files must (`docs/fit-json.md`, "Rules for readers").

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::FitError;
use crate::glass::GlassFit;
use crate::model::CurveFit;
use crate::physical::{Slack, violations};
use crate::sniff::{ExpectedFile, FileContent};

/// The whole output of `glassdb fit --json` / `-o`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct FitFile {
    /// The fitted glasses, in the table's order.
    pub glasses: Vec<GlassFit>,
}

impl FitFile {
    /// Pretty JSON, newline-terminated.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self)
            .unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"));
        s.push('\n');
        s
    }

    /// The glass with this name (first match).
    pub fn glass(&self, name: &str) -> Option<&GlassFit> {
        self.glasses.iter().find(|g| g.name == name)
    }
}

/// Reads and validates a fit file (see [`parse_fit_json`]).
pub fn read_fit_file(path: &Path) -> Result<FitFile, FitError> {
    let text =
        glassdb_io::read_input(path, glassdb_io::limits::JSON).map_err(|source| FitError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    parse_fit_json(&text, path)
}

/// Parses a fit file and validates it ([`FitFile::validate`]). Another kind of file (binary
/// data, an angle table, a registry, a planes file) is named as such ([`FitError::OtherFile`]).
/// `path` is used in messages only.
pub fn parse_fit_json(bytes: &[u8], path: &Path) -> Result<FitFile, FitError> {
    if let Some(kind) = FileContent::not_a_fit_file(bytes) {
        return Err(FitError::OtherFile {
            path: path.to_path_buf(),
            kind,
            expected: ExpectedFile::FitFile,
        });
    }
    let file: FitFile = serde_json::from_slice(bytes).map_err(|e| FitError::FitFile {
        path: path.to_path_buf(),
        message: format!(
            "not a glassdb fit file (line {}, column {}): {e}",
            e.line(),
            e.column()
        ),
    })?;
    file.validate(path)?;
    Ok(file)
}

impl FitFile {
    /// Checks every glass, as the registry checks its curves (`docs/fit-json.md`, "Rules for
    /// readers"): at least one curve per glass; each curve well formed
    /// ([`crate::CosPolynomial::check_shape`]) with finite numbers; its normal value in [0, 1];
    /// and on the dense grid ([`crate::CHECK_STEP_DEG`]) over each curve's [`CurveFit::data_range`],
    /// 0 ≤ r, t ≤ 1 and r + t ≤ 1, each within the curves'
    /// [`CurveFit::validation_tolerance`]. `path` names the file in messages.
    pub fn validate(&self, path: &Path) -> Result<(), FitError> {
        for g in &self.glasses {
            if g.reflectance.is_none() && g.transmittance.is_none() {
                return Err(FitError::FitFile {
                    path: path.to_path_buf(),
                    message: format!(
                        "glass `{}` has neither a reflectance nor a transmittance curve",
                        g.name
                    ),
                });
            }
            for (q, c) in [
                ("reflectance", &g.reflectance),
                ("transmittance", &g.transmittance),
            ] {
                let Some(c) = c else { continue };
                validate_curve(c, path, &g.name, q)?;
            }
            let tol = |c: &Option<CurveFit>| c.as_ref().map_or(0.0, CurveFit::validation_tolerance);
            let (tol_r, tol_t) = (tol(&g.reflectance), tol(&g.transmittance));
            let range = |c: &Option<CurveFit>| c.as_ref().map_or((0.0, 90.0), CurveFit::data_range);
            let violations = violations(
                g.reflectance.as_ref(),
                g.transmittance.as_ref(),
                Slack {
                    r: tol_r,
                    t: tol_t,
                    sum: tol_r + tol_t,
                    range_r: range(&g.reflectance),
                    range_t: range(&g.transmittance),
                },
            );
            if let Some((v, tolerance)) = violations.into_iter().next() {
                return Err(FitError::Unphysical {
                    path: path.to_path_buf(),
                    glass: g.name.clone(),
                    violation: v,
                    tolerance,
                });
            }
        }
        Ok(())
    }
}

/// One curve of a fit file: shape, finite numbers, normal value in [0, 1] (within its
/// tolerance).
fn validate_curve(
    c: &CurveFit,
    path: &Path,
    glass: &str,
    quantity: &'static str,
) -> Result<(), FitError> {
    let p = &c.polynomial;
    p.check_shape().map_err(|source| FitError::CurveShape {
        path: path.to_path_buf(),
        glass: glass.to_string(),
        quantity,
        source,
    })?;
    let s = &c.diagnostics.summary;
    let numbers = [s.rms_error, s.max_abs_error, s.max_error_angle_deg];
    if !c.normal.is_finite()
        || p.coefficients.iter().any(|v| !v.is_finite())
        || numbers.iter().any(|v| !v.is_finite())
    {
        return Err(FitError::FitFile {
            path: path.to_path_buf(),
            message: format!(
                "glass `{glass}`, {quantity}: non-finite normal value, coefficient or error"
            ),
        });
    }
    let tolerance = c.validation_tolerance();
    if !(-tolerance..=1.0 + tolerance).contains(&c.normal) {
        return Err(FitError::NormalOutOfRange {
            path: path.to_path_buf(),
            glass: glass.to_string(),
            quantity,
            normal: c.normal,
            tolerance,
        });
    }
    Ok(())
}
