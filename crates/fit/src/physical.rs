//! The physical checks of fitted curves (`docs/fit.md`, "Physical checks"): 0 ≤ r, t ≤ 1 and
//! r + t ≤ 1 on a dense grid, each within a slack; t that does not rise and r that does not
//! fall with the angle of incidence beyond [`MONOTONIC_SLACK`]; and the slack that validation
//! allows each curve ([`CurveFit::validation_tolerance`]).

use crate::model::CurveFit;

/// Step of the dense grid the physical checks run on (degrees, 0–90 inclusive).
pub const CHECK_STEP_DEG: f64 = 0.25;
/// Slack for the physical checks (absolute): a millionth, far below any measurement precision,
/// so only real violations are reported.
pub const CHECK_SLACK: f64 = 1e-6;

/// The largest slack (absolute, on r or t) that validation ever allows a curve beyond the
/// physical range 0 ≤ r, t ≤ 1, r + t ≤ 1: 0.01, one percentage point of reflectance or
/// transmittance. Five times the default fit tolerance ([`crate::DEFAULT_TOL`]) and about the
/// absolute uncertainty of a spectrophotometer's regular R and T, so a curve that misses the
/// physical range by more is wrong, not noisy. A file never sets its own slack beyond this: fit
/// files and registries record a tolerance per curve, and validation takes it only up to this
/// cap (the registry refuses a larger recorded one; the registry builder refuses a larger fit
/// tolerance).
pub const MAX_CURVE_TOLERANCE: f64 = 0.01;

/// A fit whose error exceeds its tolerance by more than this factor is refused (unless
/// forced): an order of magnitude beyond what the fit was asked for is a wrong table or a
/// wrong model, not noise.
pub const REFUSE_TOLERANCE_FACTOR: f64 = 10.0;

/// How far (absolute) transmittance may rise, or reflectance fall, as the angle of incidence
/// grows, before the table or the fitted curve is inconsistent with a glazing: 0.02. Fresnel
/// reflection at every interface grows with the angle towards 1 at grazing incidence, so t
/// falls and r rises; only thin-film interference and measurement noise turn them back a
/// little (the WINDOW-4 bronze regression: r dips 0.006 between 0° and 20°, C_t rises 0.66 %).
/// Ten times the default tolerance ([`crate::DEFAULT_TOL`]): 3× the largest reversal in the
/// bundled tables and 7σ of the difference of two readings with σ = 0.002 noise, while a
/// dropped digit (0.80 → 0.08), a shifted decimal point or swapped R and T reverses the curve
/// by far more (docs/fit.md, "Inconsistent points").
pub const MONOTONIC_SLACK: f64 = 0.02;

/// One failed physical check, with the worst angle on the dense grid.
#[derive(Clone, Debug, PartialEq)]
pub struct PhysicalViolation {
    /// What failed: `r < 0`, `r > 1`, `t < 0`, `t > 1`, `r + t > 1`, `t rises with angle` or
    /// `r falls with angle`.
    pub check: &'static str,
    /// The angle (degrees) where the check fails worst; for the monotonic checks, where the
    /// worst rise or fall ends.
    pub worst_angle_deg: f64,
    /// The offending value at that angle (r, t or r + t); for the monotonic checks, the size
    /// of the rise or fall.
    pub worst_value: f64,
    /// For the monotonic checks, where the worst rise or fall starts.
    pub from_angle_deg: Option<f64>,
}

impl PhysicalViolation {
    /// Which curves the failed check is about: (r, t).
    pub fn curves(&self) -> (bool, bool) {
        if self.check.starts_with("r + t") {
            (true, true)
        } else {
            (self.check.starts_with('r'), self.check.starts_with('t'))
        }
    }
}

impl std::fmt::Display for PhysicalViolation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.from_angle_deg {
            Some(from) => write!(
                f,
                "{} by {:.4} between {}° and {}° on the fitted curve",
                self.check, self.worst_value, from, self.worst_angle_deg
            ),
            None => write!(
                f,
                "{} on the fitted curve, worst at {}° ({:.6})",
                self.check, self.worst_angle_deg, self.worst_value
            ),
        }
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

/// The checks a fit must pass to be written without `--force` (`docs/fit.md`, "Refused
/// fits"): over the whole 0–90° (every angle a mask can hold, measured or not), 0 ≤ r, t ≤ 1
/// and r + t ≤ 1 within the curves' [`CurveFit::validation_tolerance`], and t not rising, r
/// not falling with the angle by more than [`MONOTONIC_SLACK`]. Each failure comes with the
/// slack it exceeded.
pub fn refusing_checks(
    r: Option<&CurveFit>,
    t: Option<&CurveFit>,
) -> Vec<(PhysicalViolation, f64)> {
    let tol = |c: Option<&CurveFit>| c.map_or(0.0, CurveFit::validation_tolerance);
    let (tol_r, tol_t) = (tol(r), tol(t));
    let mut out = violations(
        r,
        t,
        Slack {
            r: tol_r,
            t: tol_t,
            sum: tol_r + tol_t,
            range_r: (0.0, 90.0),
            range_t: (0.0, 90.0),
        },
    );
    for (check, curve, sign) in [
        ("r falls with angle", r, -1.0),
        ("t rises with angle", t, 1.0),
    ] {
        if let Some(v) = curve.and_then(|c| monotonic_violation(c, check, sign)) {
            out.push((v, MONOTONIC_SLACK));
        }
    }
    out
}

/// The largest rise (`sign` = 1) or fall (`sign` = −1) of a curve with the angle on the
/// dense grid, if it exceeds [`MONOTONIC_SLACK`].
fn monotonic_violation(c: &CurveFit, check: &'static str, sign: f64) -> Option<PhysicalViolation> {
    let steps = (90.0 / CHECK_STEP_DEG).round() as usize;
    // the extreme (lowest for a rise, highest for a fall) value so far, and where
    let (mut extreme, mut extreme_at) = (f64::INFINITY, 0.0);
    let mut worst: Option<PhysicalViolation> = None;
    for i in 0..=steps {
        let angle = i as f64 * CHECK_STEP_DEG;
        let v = sign * c.eval_angle_deg(angle);
        if !v.is_finite() {
            continue;
        }
        let change = v - extreme;
        if change > MONOTONIC_SLACK && worst.as_ref().is_none_or(|w| change > w.worst_value) {
            worst = Some(PhysicalViolation {
                check,
                worst_angle_deg: angle,
                worst_value: change,
                from_angle_deg: Some(extreme_at),
            });
        }
        if v < extreme {
            (extreme, extreme_at) = (v, angle);
        }
    }
    worst
}

/// How far each check may exceed the physical range before it is a violation, and the angles
/// (degrees, inclusive) each curve is checked over (r + t where both ranges hold).
#[derive(Clone, Copy)]
pub(crate) struct Slack {
    pub r: f64,
    pub t: f64,
    pub sum: f64,
    pub range_r: (f64, f64),
    pub range_t: (f64, f64),
}

/// The failed checks (see [`physical_checks`]) with the slack each exceeded, in the order
/// first met on the grid. A value that is not finite is a violation whatever the slack.
pub(crate) fn violations(
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
                from_angle_deg: None,
            };
            (v, slack)
        })
        .collect()
}
