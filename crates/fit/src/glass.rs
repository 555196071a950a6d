//! Glass-level fitting (both curves of one glass), the physical checks, and the fit file
//! (`{"glasses": [...]}`, `docs/fit-json.md`) that `glassdb eval` and later tools read.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::FitError;
use crate::model::{AngleSamples, CurveFit, FitOptions, Quantity};
use crate::solve::fit_curve;
use crate::table::GlassAngleTable;

pub use crate::model::{CHECK_SLACK, CHECK_STEP_DEG};

/// The largest slack (absolute, on r or t) that validation ever allows a curve beyond the
/// physical range 0 ≤ r, t ≤ 1, r + t ≤ 1: 0.01, one percentage point of reflectance or
/// transmittance. Five times the default fit tolerance ([`crate::DEFAULT_TOL`]) and about the
/// absolute uncertainty of a spectrophotometer's regular R and T, so a curve that misses the
/// physical range by more is wrong, not noisy. A file never sets its own slack beyond this: fit
/// files and registries record a tolerance per curve, and validation takes it only up to this
/// cap (the registry refuses a larger recorded one; the registry builder refuses a larger fit
/// tolerance).
pub const MAX_CURVE_TOLERANCE: f64 = 0.01;

/// The fitted curves of one glass. A glass measured for only one of R/T has only that key.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct GlassFit {
    /// The glass's name, as in the table.
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    /// The fitted reflectance curve.
    pub reflectance: Option<CurveFit>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    /// The fitted transmittance curve.
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
    /// Every glass fitted, in the table's order.
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

/// Parses a fit file and validates it ([`FitFile::validate`]). Another glassdb JSON file (a
/// registry, a planes file) is named as such ([`FitError::OtherFile`]). `path` is used in
/// messages only.
pub fn parse_fit_json(bytes: &[u8], path: &Path) -> Result<FitFile, FitError> {
    if let Some(kind) = OtherJson::identify(bytes) {
        return Err(FitError::OtherFile {
            path: path.to_path_buf(),
            kind,
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

/// Another glassdb JSON file handed to the fit file reader.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OtherJson {
    /// A glass registry (`{"schema": …, "tables" or "glasses": …}`).
    Registry,
    /// A planes file (`{"format": "glassdb-planes/…"}`).
    Planes,
}

impl OtherJson {
    /// The kind of glassdb JSON file `bytes` hold when it is not a fit file, from the top-level
    /// keys only (none for anything else, including text that is not JSON).
    pub fn identify(bytes: &[u8]) -> Option<OtherJson> {
        #[derive(Deserialize)]
        struct TopLevel {
            #[serde(default)]
            schema: Option<serde::de::IgnoredAny>,
            #[serde(default)]
            format: Option<String>,
        }
        let top: TopLevel = serde_json::from_slice(bytes).ok()?;
        if top.schema.is_some() {
            Some(OtherJson::Registry)
        } else if top.format.is_some_and(|f| f.starts_with("glassdb-planes")) {
            Some(OtherJson::Planes)
        } else {
            None
        }
    }
}

impl std::fmt::Display for OtherJson {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            OtherJson::Registry => "a glassdb glass registry",
            OtherJson::Planes => "a glassdb planes file",
        })
    }
}

impl CurveFit {
    /// The slack validation allows this curve beyond the physical range: its largest residual
    /// on the data, at least [`crate::DEFAULT_TOL`] (the curve between and beyond the data
    /// points) and at most [`MAX_CURVE_TOLERANCE`] (what the file records cannot widen it).
    pub fn validation_tolerance(&self) -> f64 {
        let residual = self.diagnostics.summary.max_abs_error;
        let residual = if residual.is_finite() { residual } else { 0.0 };
        residual.clamp(crate::DEFAULT_TOL, MAX_CURVE_TOLERANCE)
    }

    /// The angles (degrees) the curve was fitted over, where validation holds it to the
    /// physical range: the measured range when the file records it, else 0–90°; a recorded
    /// range reaching outside 0–90° or inverted counts as 0–90°, so that an edited file cannot
    /// escape validation. Beyond it the curve is an extrapolation, which `glassdb eval`
    /// warns about.
    pub fn data_range(&self) -> (f64, f64) {
        let d = &self.diagnostics;
        let lo = d.angle_min_deg.filter(|a| a.is_finite()).unwrap_or(0.0);
        let hi = d.angle_max_deg.filter(|a| a.is_finite()).unwrap_or(90.0);
        if 0.0 <= lo && lo <= hi && hi <= 90.0 {
            (lo, hi)
        } else {
            (0.0, 90.0)
        }
    }
}

impl FitFile {
    /// Checks every glass, as the registry checks its curves (`docs/fit-json.md`, "Rules for
    /// readers"): at least one curve per glass; each curve well formed
    /// ([`crate::CosPolynomial::check_shape`]) with finite numbers; its normal value in [0, 1];
    /// and on the dense grid ([`CHECK_STEP_DEG`]) over each curve's [`CurveFit::data_range`],
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

/// One failed physical check, with the worst angle on the dense grid.
#[derive(Clone, Debug, PartialEq)]
pub struct PhysicalViolation {
    /// What failed, e.g. `r < 0`, `t > 1`, `r + t > 1`.
    pub check: &'static str,
    /// The angle (degrees) where it fails most.
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
/// ([`CHECK_STEP_DEG`]), each with the slack [`CHECK_SLACK`]. C_t(θ) > 1 near normal incidence
/// is not a violation (coated glass).
pub fn physical_checks(r: Option<&CurveFit>, t: Option<&CurveFit>) -> Vec<PhysicalViolation> {
    let slack = Slack {
        r: CHECK_SLACK,
        t: CHECK_SLACK,
        sum: CHECK_SLACK,
        range_r: (0.0, 90.0),
        range_t: (0.0, 90.0),
    };
    violations(r, t, slack)
        .into_iter()
        .map(|(v, _)| v)
        .collect()
}

/// How far each check may exceed the physical range before it is a violation, and the angles
/// (degrees, inclusive) each curve is checked over (r + t where both ranges hold).
#[derive(Clone, Copy)]
struct Slack {
    r: f64,
    t: f64,
    sum: f64,
    range_r: (f64, f64),
    range_t: (f64, f64),
}

/// The failed checks (see [`physical_checks`]) with the slack each exceeded, in the order
/// first met on the grid. A value that is not finite is a violation whatever the slack.
fn violations(
    r: Option<&CurveFit>,
    t: Option<&CurveFit>,
    slack: Slack,
) -> Vec<(PhysicalViolation, f64)> {
    let steps = (90.0 / CHECK_STEP_DEG).round() as usize;
    // (check, worst angle, worst value, amount, slack)
    let mut worst: Vec<(&'static str, f64, f64, f64, f64)> = Vec::new();
    let mut note = |check: &'static str, angle: f64, value: f64, amount: f64, slack: f64| {
        let amount = if value.is_finite() {
            amount
        } else {
            f64::INFINITY
        };
        if amount <= slack {
            return;
        }
        match worst.iter_mut().find(|w| w.0 == check) {
            Some(w) if amount > w.3 => *w = (check, angle, value, amount, slack),
            Some(_) => {}
            None => worst.push((check, angle, value, amount, slack)),
        }
    };
    let within = |(lo, hi): (f64, f64), angle: f64| (lo..=hi).contains(&angle);
    for i in 0..=steps {
        let angle = i as f64 * CHECK_STEP_DEG;
        let rv = r
            .filter(|_| within(slack.range_r, angle))
            .map(|c| c.eval_angle_deg(angle));
        let tv = t
            .filter(|_| within(slack.range_t, angle))
            .map(|c| c.eval_angle_deg(angle));
        if let Some(v) = rv {
            note("r < 0", angle, v, -v, slack.r);
            note("r > 1", angle, v, v - 1.0, slack.r);
        }
        if let Some(v) = tv {
            note("t < 0", angle, v, -v, slack.t);
            note("t > 1", angle, v, v - 1.0, slack.t);
        }
        if let (Some(a), Some(b)) = (rv, tv) {
            note("r + t > 1", angle, a + b, a + b - 1.0, slack.sum);
        }
    }
    worst
        .into_iter()
        .map(|(check, worst_angle_deg, worst_value, _, slack)| {
            let v = PhysicalViolation {
                check,
                worst_angle_deg,
                worst_value,
            };
            (v, slack)
        })
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
