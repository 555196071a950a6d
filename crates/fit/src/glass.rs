//! Glass-level fitting: both curves of one glass from its angle table, the screen for
//! inconsistent readings before the fit, and the checks after it that refuse a fit far from
//! its data or unphysical (`docs/fit.md`, "Refused fits").

use serde::{Deserialize, Serialize};

use crate::error::FitError;
use crate::model::{AngleSamples, CurveFit, FitOptions, Quantity};
use crate::physical::{REFUSE_TOLERANCE_FACTOR, physical_checks, refusing_checks};
use crate::solve::fit_curve;
use crate::table::GlassAngleTable;

/// The fitted curves of one glass. A glass measured for only one of R/T has only that key.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct GlassFit {
    /// The glass's name (the table's `glass` column, or the file's stem).
    pub name: String,
    /// r(θ), when the table has R values.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reflectance: Option<CurveFit>,
    /// t(θ), when the table has T values.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmittance: Option<CurveFit>,
    /// Glass-level warnings: failed physical checks, repeated angles averaged, and what
    /// `force` let through.
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

/// How to fit the two curves of a glass, and what to refuse.
#[derive(Clone, Debug, PartialEq)]
pub struct GlassFitOptions {
    /// The options of the reflectance curve (its `quantity` is set to reflectance).
    pub reflectance: FitOptions,
    /// The options of the transmittance curve (its `quantity` is set to transmittance).
    pub transmittance: FitOptions,
    /// Every failed physical check, however small (beyond [`crate::CHECK_SLACK`]), is an
    /// error ([`FitError::Physical`]).
    pub strict: bool,
    /// Fit and return what would be refused (inconsistent readings, a fit far from its data
    /// or unphysical), with each refusal as a warning instead.
    pub force: bool,
}

impl Default for GlassFitOptions {
    /// The defaults of [`FitOptions::new`] for both curves, not strict, not forced.
    fn default() -> Self {
        GlassFitOptions {
            reflectance: FitOptions::new(Quantity::Reflectance),
            transmittance: FitOptions::new(Quantity::Transmittance),
            strict: false,
            force: false,
        }
    }
}

/// Fits both curves of a glass, in three phases:
///
/// 1. the screen ([`GlassAngleTable::screen`]): readings their neighbours contradict
///    ([`FitError::InconsistentPoints`], [`FitError::ReversedCurve`]);
/// 2. the fits ([`fit_curve`]);
/// 3. the judgement: a curve that misses a reading by more than
///    [`REFUSE_TOLERANCE_FACTOR`] × its tolerance ([`FitError::FarFromData`]), or fails
///    [`refusing_checks`] over 0–90° ([`FitError::UnphysicalFit`]); with `strict`, any failed
///    [`physical_checks`] ([`FitError::Physical`]).
///
/// Phases 1 and 3 refuse unless `force`, which turns their findings into warnings (strict
/// checks stay errors). Smaller physical violations are warnings.
pub fn fit_glass(table: &GlassAngleTable, opts: &GlassFitOptions) -> Result<GlassFit, FitError> {
    let mut refusals: Vec<FitError> = Vec::new();
    let screening = table.screen();
    for &quantity in &screening.reversed {
        refusals.push(FitError::ReversedCurve {
            path: table.path.clone(),
            glass: table.name.clone(),
            quantity,
        });
    }
    if !screening.points.is_empty() {
        refusals.push(FitError::InconsistentPoints {
            path: table.path.clone(),
            glass: table.name.clone(),
            points: screening.points,
        });
    }
    if !opts.force && !refusals.is_empty() {
        return Err(refusals.remove(0));
    }

    let r_opts = FitOptions {
        quantity: Quantity::Reflectance,
        ..opts.reflectance.clone()
    };
    let t_opts = FitOptions {
        quantity: Quantity::Transmittance,
        ..opts.transmittance.clone()
    };
    // Fits one curve of the table when it has one; an error names the glass and the quantity.
    let fit = |samples: Option<&AngleSamples>, opts: &FitOptions| {
        samples
            .map(|s| fit_curve(s, opts))
            .transpose()
            .map_err(|e| FitError::Curve {
                path: table.path.clone(),
                glass: table.name.clone(),
                quantity: opts.quantity.name(),
                error: Box::new(e),
            })
    };
    let r = fit(table.reflectance.as_ref(), &r_opts)?;
    let t = fit(table.transmittance.as_ref(), &t_opts)?;

    let violations = physical_checks(r.as_ref(), t.as_ref());
    if opts.strict
        && let Some(v) = violations.first()
    {
        return Err(FitError::Physical {
            path: table.path.clone(),
            glass: table.name.clone(),
            violation: v.clone(),
        });
    }
    for (curve, samples, o) in [
        (&r, &table.reflectance, &r_opts),
        (&t, &table.transmittance, &t_opts),
    ] {
        if let (Some(c), Some(s)) = (curve, samples)
            && let Some(far) = far_from_data(table, c, s, o)
        {
            refusals.push(far);
        }
    }
    for (violation, tolerance) in refusing_checks(r.as_ref(), t.as_ref()) {
        let measured = |s: &Option<AngleSamples>| {
            s.as_ref().is_some_and(|s| {
                let lo = s.angle_deg.first().copied().unwrap_or(0.0);
                let hi = s.angle_deg.last().copied().unwrap_or(90.0);
                (lo..=hi).contains(&violation.worst_angle_deg)
            })
        };
        let beyond_data = match violation.check.chars().next() {
            Some('r') if violation.check.starts_with("r + t") => {
                !(measured(&table.reflectance) && measured(&table.transmittance))
            }
            Some('r') => !measured(&table.reflectance),
            _ => !measured(&table.transmittance),
        };
        refusals.push(FitError::UnphysicalFit {
            path: table.path.clone(),
            glass: table.name.clone(),
            violation,
            tolerance,
            beyond_data,
        });
    }
    let forced = refuse_unless_forced(refusals, opts.force, table)?;

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
    warnings.extend(violations.iter().map(|v| format!("physical check: {v}")));
    warnings.extend(forced);
    Ok(GlassFit {
        name: table.name.clone(),
        reflectance: r,
        transmittance: t,
        warnings,
    })
}

/// The first of `refusals` as the error, or with `force` all of them as warnings (without
/// the file and glass the warning's glass already names).
fn refuse_unless_forced(
    mut refusals: Vec<FitError>,
    force: bool,
    table: &GlassAngleTable,
) -> Result<Vec<String>, FitError> {
    if !force && !refusals.is_empty() {
        return Err(refusals.swap_remove(0));
    }
    let prefix = format!("{}: glass `{}`", table.path.display(), table.name);
    Ok(refusals
        .iter()
        .map(|e| {
            let text = e.to_string();
            let finding = text.strip_prefix(&prefix).map_or(text.as_str(), |rest| {
                rest.trim_start_matches([':', ',', ' '])
            });
            format!("written with --force: {finding}")
        })
        .collect())
}

/// The reading a curve misses by most, as [`FitError::FarFromData`] when that is more than
/// [`REFUSE_TOLERANCE_FACTOR`] × the tolerance.
fn far_from_data(
    table: &GlassAngleTable,
    curve: &CurveFit,
    samples: &AngleSamples,
    opts: &FitOptions,
) -> Option<FitError> {
    let (angle_deg, error) = samples
        .angle_deg
        .iter()
        .zip(&samples.value)
        .map(|(&a, &v)| (a, (curve.eval_angle_deg(a) - v).abs()))
        .max_by(|x, y| x.1.total_cmp(&y.1))?;
    (error > REFUSE_TOLERANCE_FACTOR * opts.tol).then(|| FitError::FarFromData {
        path: table.path.clone(),
        glass: table.name.clone(),
        quantity: opts.quantity,
        angle_deg,
        lines: table.lines_of(angle_deg).to_vec(),
        error,
        tol: opts.tol,
    })
}
