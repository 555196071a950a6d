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
    let mut refusals = screen(table);
    if !opts.force && !refusals.is_empty() {
        return Err(refusals.swap_remove(0));
    }
    let (r, t) = fit_curves(table, opts)?;
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
    refusals.extend(judge(table, opts, r.as_ref(), t.as_ref()));
    let forced = refuse_unless_forced(refusals, opts.force, table)?;

    let mut warnings = repeated_angle_warnings(table);
    warnings.extend(violations.iter().map(|v| format!("physical check: {v}")));
    warnings.extend(forced);
    Ok(GlassFit {
        name: table.name.clone(),
        reflectance: r,
        transmittance: t,
        warnings,
    })
}

/// Phase 1: the screen's findings as refusals.
fn screen(table: &GlassAngleTable) -> Vec<FitError> {
    let screening = table.screen();
    let mut refusals: Vec<FitError> = screening
        .reversed
        .iter()
        .map(|&quantity| FitError::ReversedCurve {
            path: table.path.clone(),
            glass: table.name.clone(),
            quantity,
        })
        .collect();
    if !screening.points.is_empty() {
        refusals.push(FitError::InconsistentPoints {
            path: table.path.clone(),
            glass: table.name.clone(),
            points: screening.points,
        });
    }
    refusals
}

/// Phase 2: the curves the table has, each with its options (quantity set); an error names the
/// file, the glass and the curve.
fn fit_curves(
    table: &GlassAngleTable,
    opts: &GlassFitOptions,
) -> Result<(Option<CurveFit>, Option<CurveFit>), FitError> {
    let fit = |samples: Option<&AngleSamples>, opts: &FitOptions, quantity: Quantity| {
        let opts = FitOptions {
            quantity,
            ..opts.clone()
        };
        samples
            .map(|s| fit_curve(s, &opts))
            .transpose()
            .map_err(|e| FitError::Curve {
                path: table.path.clone(),
                glass: table.name.clone(),
                quantity: quantity.name(),
                error: Box::new(e),
            })
    };
    Ok((
        fit(
            table.reflectance.as_ref(),
            &opts.reflectance,
            Quantity::Reflectance,
        )?,
        fit(
            table.transmittance.as_ref(),
            &opts.transmittance,
            Quantity::Transmittance,
        )?,
    ))
}

/// Phase 3: the fits far from their data ([`far_from_data`]) or failing [`refusing_checks`],
/// as refusals.
fn judge(
    table: &GlassAngleTable,
    opts: &GlassFitOptions,
    r: Option<&CurveFit>,
    t: Option<&CurveFit>,
) -> Vec<FitError> {
    let mut refusals: Vec<FitError> = [
        (
            r,
            &table.reflectance,
            &opts.reflectance,
            Quantity::Reflectance,
        ),
        (
            t,
            &table.transmittance,
            &opts.transmittance,
            Quantity::Transmittance,
        ),
    ]
    .into_iter()
    .filter_map(|(curve, samples, o, quantity)| {
        far_from_data(table, curve?, samples.as_ref()?, o.tol, quantity)
    })
    .collect();
    // whether an angle lies within the measured range of a curve
    let measured = |s: &Option<AngleSamples>, angle: f64| {
        s.as_ref().is_some_and(|s| {
            let lo = s.angle_deg.first().copied().unwrap_or(0.0);
            let hi = s.angle_deg.last().copied().unwrap_or(90.0);
            (lo..=hi).contains(&angle)
        })
    };
    for (violation, tolerance) in refusing_checks(r, t) {
        let (of_r, of_t) = violation.curves();
        let angle = violation.worst_angle_deg;
        let beyond_data = (of_r && !measured(&table.reflectance, angle))
            || (of_t && !measured(&table.transmittance, angle));
        refusals.push(FitError::UnphysicalFit {
            path: table.path.clone(),
            glass: table.name.clone(),
            violation,
            tolerance,
            beyond_data,
        });
    }
    refusals
}

/// Warnings for the angles given on several rows (averaged).
fn repeated_angle_warnings(table: &GlassAngleTable) -> Vec<String> {
    table
        .repeated_angles()
        .map(|rep| {
            let mut spreads = Vec::new();
            if let Some(s) = rep.reflectance_spread {
                spreads.push(format!("R spread {s:.5}"));
            }
            if let Some(s) = rep.transmittance_spread {
                spreads.push(format!("T spread {s:.5}"));
            }
            format!(
                "angle {}° given on {} rows: averaged ({})",
                rep.angle_deg,
                rep.lines.len(),
                spreads.join(", ")
            )
        })
        .collect()
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
/// [`REFUSE_TOLERANCE_FACTOR`] × `tol`.
fn far_from_data(
    table: &GlassAngleTable,
    curve: &CurveFit,
    samples: &AngleSamples,
    tol: f64,
    quantity: Quantity,
) -> Option<FitError> {
    let (angle_deg, error) = samples
        .angle_deg
        .iter()
        .zip(&samples.value)
        .map(|(&a, &v)| (a, (curve.eval_angle_deg(a) - v).abs()))
        .max_by(|x, y| x.1.total_cmp(&y.1))?;
    (error > REFUSE_TOLERANCE_FACTOR * tol).then(|| FitError::FarFromData {
        path: table.path.clone(),
        glass: table.name.clone(),
        quantity,
        angle_deg,
        lines: table.lines_of(angle_deg).to_vec(),
        error,
        tol,
    })
}
