//! Glass-level fitting (both curves of one glass), the physical checks, and the fit file
//! (`{"glasses": [...]}`, `docs/fit-json.md`) that `glassdb eval` and later tools read.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::FitError;
use crate::model::{AngleSamples, CurveFit, FitOptions, Quantity};
use crate::solve::fit_curve;
use crate::table::GlassAngleTable;

/// Step of the dense grid the physical checks run on (degrees, 0–90 inclusive).
pub const CHECK_STEP_DEG: f64 = 0.25;
/// Slack for the physical checks (absolute): a millionth, far below any measurement precision,
/// so only real violations are reported.
pub const CHECK_SLACK: f64 = 1e-6;

/// The fitted curves of one glass. A glass measured for only one of R/T has only that key.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct GlassFit {
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reflectance: Option<CurveFit>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmittance: Option<CurveFit>,
    /// Glass-level warnings: failed physical checks, repeated angles averaged.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

impl GlassFit {
    /// r(θ) at an angle in degrees, if the glass has a reflectance curve.
    pub fn reflectance_at(&self, angle_deg: f64) -> Option<f64> {
        self.reflectance
            .as_ref()
            .map(|c| c.eval_angle_deg(angle_deg))
    }
    /// t(θ) at an angle in degrees, if the glass has a transmittance curve.
    pub fn transmittance_at(&self, angle_deg: f64) -> Option<f64> {
        self.transmittance
            .as_ref()
            .map(|c| c.eval_angle_deg(angle_deg))
    }
}

/// The whole output of `glassdb fit --json` / `-o`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct FitFile {
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

/// Parses a fit file and checks each curve: as many powers as coefficients (at least one),
/// powers strictly ascending, every number finite. `path` is used in messages only.
pub fn parse_fit_json(bytes: &[u8], path: &Path) -> Result<FitFile, FitError> {
    let err = |message: String| FitError::FitFile {
        path: path.to_path_buf(),
        message,
    };
    let file: FitFile = serde_json::from_slice(bytes).map_err(|e| {
        err(format!(
            "not a glassdb fit file (line {}, column {}): {e}",
            e.line(),
            e.column()
        ))
    })?;
    for g in &file.glasses {
        for (q, c) in [
            ("reflectance", &g.reflectance),
            ("transmittance", &g.transmittance),
        ] {
            let Some(c) = c else { continue };
            let where_ = format!("glass `{}`, {q}", g.name);
            let p = &c.polynomial;
            p.check_shape().map_err(|source| FitError::CurveShape {
                path: path.to_path_buf(),
                glass: g.name.clone(),
                quantity: q,
                source,
            })?;
            if !c.normal.is_finite() || p.coefficients.iter().any(|v| !v.is_finite()) {
                return Err(err(format!(
                    "{where_}: non-finite normal value or coefficient"
                )));
            }
        }
    }
    Ok(file)
}

/// One failed physical check, with the worst angle on the dense grid.
#[derive(Clone, Debug, PartialEq)]
pub struct PhysicalViolation {
    /// What failed, e.g. `r < 0`, `t > 1`, `r + t > 1`.
    pub check: &'static str,
    pub worst_angle_deg: f64,
    /// The offending value at that angle (r, t or r + t).
    pub worst_value: f64,
}

impl std::fmt::Display for PhysicalViolation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} on the fitted curve, worst at {}° ({:.6})",
            self.check, self.worst_angle_deg, self.worst_value
        )
    }
}

/// Checks 0 ≤ r ≤ 1, 0 ≤ t ≤ 1 and r + t ≤ 1 (when both exist) on a dense 0–90° grid
/// ([`CHECK_STEP_DEG`]). C_t(θ) > 1 near normal incidence is not a violation (coated glass).
pub fn physical_checks(r: Option<&CurveFit>, t: Option<&CurveFit>) -> Vec<PhysicalViolation> {
    let steps = (90.0 / CHECK_STEP_DEG).round() as usize;
    // (check, worst angle, worst value, amount)
    let mut worst: Vec<(&'static str, f64, f64, f64)> = Vec::new();
    let mut note = |check: &'static str, angle: f64, value: f64, amount: f64| {
        if amount <= CHECK_SLACK {
            return;
        }
        match worst.iter_mut().find(|w| w.0 == check) {
            Some(w) if amount > w.3 => *w = (check, angle, value, amount),
            Some(_) => {}
            None => worst.push((check, angle, value, amount)),
        }
    };
    for i in 0..=steps {
        let angle = i as f64 * CHECK_STEP_DEG;
        let rv = r.map(|c| c.eval_angle_deg(angle));
        let tv = t.map(|c| c.eval_angle_deg(angle));
        if let Some(v) = rv {
            note("r < 0", angle, v, -v);
            note("r > 1", angle, v, v - 1.0);
        }
        if let Some(v) = tv {
            note("t < 0", angle, v, -v);
            note("t > 1", angle, v, v - 1.0);
        }
        if let (Some(a), Some(b)) = (rv, tv) {
            note("r + t > 1", angle, a + b, a + b - 1.0);
        }
    }
    worst
        .into_iter()
        .map(
            |(check, worst_angle_deg, worst_value, _)| PhysicalViolation {
                check,
                worst_angle_deg,
                worst_value,
            },
        )
        .collect()
}

/// Fits both curves of a glass and runs the physical checks. With `strict`, a failed check is
/// an error ([`FitError::Physical`]); otherwise it becomes a warning in the result.
pub fn fit_glass(
    table: &GlassAngleTable,
    reflectance: &FitOptions,
    transmittance: &FitOptions,
    strict: bool,
) -> Result<GlassFit, FitError> {
    let r_opts = FitOptions {
        quantity: Quantity::Reflectance,
        ..reflectance.clone()
    };
    let t_opts = FitOptions {
        quantity: Quantity::Transmittance,
        ..transmittance.clone()
    };
    // Fits one curve of the table when it has one; an error names the glass and the quantity.
    let fit = |samples: Option<&AngleSamples>, opts: &FitOptions, quantity: &'static str| {
        samples
            .map(|s| fit_curve(s, opts))
            .transpose()
            .map_err(|e| FitError::Curve {
                glass: table.name.clone(),
                quantity,
                error: Box::new(e),
            })
    };
    let r = fit(table.reflectance.as_ref(), &r_opts, "reflectance")?;
    let t = fit(table.transmittance.as_ref(), &t_opts, "transmittance")?;
    let mut warnings = Vec::new();
    for rep in &table.repeated_angles {
        let mut spreads = Vec::new();
        if let Some(s) = rep.reflectance_spread {
            spreads.push(format!("R spread {s:.5}"));
        }
        if let Some(s) = rep.transmittance_spread {
            spreads.push(format!("T spread {s:.5}"));
        }
        warnings.push(format!(
            "angle {}° given on {} rows: averaged ({})",
            rep.angle_deg,
            rep.rows,
            spreads.join(", ")
        ));
    }
    let violations = physical_checks(r.as_ref(), t.as_ref());
    if strict && let Some(v) = violations.first() {
        return Err(FitError::Physical {
            glass: table.name.clone(),
            message: format!("physical check failed: {v}"),
        });
    }
    warnings.extend(violations.iter().map(|v| format!("physical check: {v}")));
    Ok(GlassFit {
        name: table.name.clone(),
        reflectance: r,
        transmittance: t,
        warnings,
    })
}
