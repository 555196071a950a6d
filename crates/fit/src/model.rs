//! The fitted model of `docs/method.md` eqs. 11–14 and its JSON form (`docs/fit-json.md`):
//! `r(θ) = r0·C_r(θ)`, `t(θ) = t0·C_t(θ)`, `C(θ) = Σ_k c_k·cos^{p_k} θ`.

use serde::{Deserialize, Serialize};

/// Which powers of cos θ a curve uses.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Basis {
    /// Powers 1…n, no constant term: the paper's eqs. 12–13 (and EnergyPlus's form). Forces
    /// C(90°) = 0, right for transmittance, wrong for reflectance (which rises to 1 at grazing).
    Paper,
    /// Powers 0…n: a constant term lets C_r reach 1/r0 at grazing incidence.
    Full,
}

impl Basis {
    /// The lowercase name used in JSON and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Basis::Paper => "paper",
            Basis::Full => "full",
        }
    }

    /// The powers of cos θ of this basis at `degree` (paper: 1..=degree, full: 0..=degree).
    pub fn powers(self, degree: u32) -> Vec<u32> {
        match self {
            Basis::Paper => (1..=degree).collect(),
            Basis::Full => (0..=degree).collect(),
        }
    }

    /// The smallest meaningful degree (paper: 1, full: 0).
    pub fn min_degree(self) -> u32 {
        match self {
            Basis::Paper => 1,
            Basis::Full => 0,
        }
    }
}

impl std::fmt::Display for Basis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Basis {
    type Err = String;

    fn from_str(s: &str) -> Result<Basis, String> {
        [Basis::Paper, Basis::Full]
            .into_iter()
            .find(|b| s.eq_ignore_ascii_case(b.name()))
            .ok_or_else(|| format!("unknown basis `{s}`; expected paper or full"))
    }
}

/// `C(θ) = Σ_k coefficients[k] · cos(θ)^powers[k]` (method eqs. 12–13): the ratio of a
/// quantity at incidence angle θ to its normal-incidence value. `powers` ascend strictly.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct CosPolynomial {
    /// Which powers the curve may use (paper: 1…n, full: 0…n).
    pub basis: Basis,
    /// The powers p_k of cos θ, strictly ascending.
    pub powers: Vec<u32>,
    /// The coefficients c_k, one per power.
    pub coefficients: Vec<f64>,
}

impl CosPolynomial {
    /// C at `cos_theta` by Horner's rule over the (strictly ascending) powers: one multiply-add
    /// per coefficient, times `cos^gap` where consecutive powers skip (never, for the fits this
    /// crate writes), times `cos^powers[0]` at the end.
    #[inline]
    pub fn eval(&self, cos_theta: f64) -> f64 {
        let n = self.coefficients.len().min(self.powers.len());
        let Some(last) = n.checked_sub(1) else {
            return 0.0;
        };
        let x = cos_theta;
        let mut acc = self.coefficients[last];
        for k in (0..last).rev() {
            let gap = self.powers[k + 1].saturating_sub(self.powers[k]);
            acc = acc * pow_small(x, gap) + self.coefficients[k];
        }
        acc * pow_small(x, self.powers[0])
    }

    /// C at an incidence angle in degrees (cos 90° is taken as exactly 0).
    pub fn eval_angle_deg(&self, angle_deg: f64) -> f64 {
        self.eval(cos_deg(angle_deg))
    }

    /// The highest power (the degree n of eqs. 12–13).
    pub fn degree(&self) -> u32 {
        self.powers.last().copied().unwrap_or(0)
    }
}

/// The highest power of cos θ a curve may have (the power basis is hopeless far below it).
pub const MAX_POWER: u32 = 64;

/// Why a [`CosPolynomial`] as written (in a fit file or a registry) cannot be evaluated.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PolynomialShape {
    /// Neither powers nor coefficients.
    #[error("no terms")]
    NoTerms,
    /// Not one coefficient per power.
    #[error("{powers} powers but {coefficients} coefficients")]
    LengthMismatch {
        /// How many powers the curve lists.
        powers: usize,
        /// How many coefficients it lists.
        coefficients: usize,
    },
    /// A power above [`MAX_POWER`].
    #[error("power {0} is beyond the supported {MAX_POWER}")]
    PowerTooHigh(u32),
    /// Two consecutive powers that do not ascend.
    #[error("powers must ascend strictly, but {0} is followed by {1}")]
    NotAscending(u32, u32),
    /// Power 0 in the paper basis.
    #[error("the paper basis has no constant term (power 0)")]
    ConstantInPaperBasis,
}

impl CosPolynomial {
    /// Checks what [`CosPolynomial::eval`] relies on: at least one term, one coefficient per
    /// power, powers ≤ [`MAX_POWER`] and strictly ascending, no power 0 in the paper basis.
    /// (Finiteness of the coefficients is the caller's check, to name the coefficient.)
    pub fn check_shape(&self) -> Result<(), PolynomialShape> {
        if self.powers.is_empty() && self.coefficients.is_empty() {
            return Err(PolynomialShape::NoTerms);
        }
        if self.powers.len() != self.coefficients.len() {
            return Err(PolynomialShape::LengthMismatch {
                powers: self.powers.len(),
                coefficients: self.coefficients.len(),
            });
        }
        if let Some(&p) = self.powers.iter().find(|&&p| p > MAX_POWER) {
            return Err(PolynomialShape::PowerTooHigh(p));
        }
        if let Some(w) = self.powers.windows(2).find(|w| w[1] <= w[0]) {
            return Err(PolynomialShape::NotAscending(w[0], w[1]));
        }
        if self.basis == Basis::Paper && self.powers[0] == 0 {
            return Err(PolynomialShape::ConstantInPaperBasis);
        }
        Ok(())
    }
}

/// `x^p` with the common small powers 0 and 1 exact and free.
#[inline]
fn pow_small(x: f64, p: u32) -> f64 {
    match p {
        0 => 1.0,
        1 => x,
        p => x.powi(p.min(i32::MAX as u32) as i32),
    }
}

/// cos of an angle in degrees, exact at 0° and 90° (so the paper basis gives exactly 0 at 90°).
pub fn cos_deg(angle_deg: f64) -> f64 {
    if angle_deg == 90.0 {
        0.0
    } else if angle_deg == 0.0 {
        1.0
    } else {
        angle_deg.to_radians().cos()
    }
}

/// A data point whose residual stands out from the noise of the rest (externally studentized
/// residual above 4, and above the tolerance): a probable outlier or typo in the table.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct SuspectPoint {
    /// The point's angle of incidence (degrees).
    pub angle_deg: f64,
    /// fitted − measured, in the quantity's units (fraction).
    pub residual: f64,
    /// The residual in units of the noise estimated without this point.
    pub studentized: f64,
}

/// How well a curve fits its data: the five numbers every consumer of a fit keeps (the fit
/// JSON and the registry store them beside the polynomial, under these keys).
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct FitSummary {
    /// Highest power of cos θ.
    pub degree: u32,
    /// RMS of fitted − measured over the data (fraction, absolute: r(θ), not C(θ)).
    pub rms_error: f64,
    /// Largest |fitted − measured| over the data.
    pub max_abs_error: f64,
    /// The angle of that largest residual.
    pub max_error_angle_deg: f64,
    /// 2-norm condition number of the least-squares matrix actually solved (orthogonal
    /// Chebyshev basis on the data's cos θ range, restricted to the constraint's null space).
    pub condition_number: f64,
}

impl FitSummary {
    /// The summary of an exact curve that was not fitted (no residual, condition number 1).
    pub fn exact(degree: u32) -> FitSummary {
        FitSummary {
            degree,
            rms_error: 0.0,
            max_abs_error: 0.0,
            max_error_angle_deg: 0.0,
            condition_number: 1.0,
        }
    }
}

/// How well a curve fits its data, and what was solved: the [`FitSummary`] keys (the issue's
/// JSON keys) and extra keys (all optional when reading).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct FitDiagnostics {
    /// The five numbers every consumer keeps.
    #[serde(flatten)]
    pub summary: FitSummary,
    /// Condition number of the same fit written in the power basis (cos^p θ columns): what a
    /// naive solver would face; the normal equations square it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub power_basis_condition_number: Option<f64>,
    /// Distinct angles fitted (repeated angles averaged first).
    #[serde(default)]
    pub points: usize,
    /// The smallest measured angle; evaluating below it is extrapolation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_min_deg: Option<f64>,
    /// The largest measured angle; evaluating above it is extrapolation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_max_deg: Option<f64>,
    /// True when `normal` is the table's 0° value; false when the table had no 0° row and
    /// `normal` is the fitted absolute curve's value at cos θ = 1.
    #[serde(default = "default_true")]
    pub normal_measured: bool,
    /// Leave-one-out RMS prediction error (each point predicted by the fit without it);
    /// absent when a point determines a coefficient by itself (as many coefficients as points).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loo_rms_error: Option<f64>,
    /// How the degree was chosen: `fixed` (--degree), `tolerance` (smallest degree meeting
    /// --tol), `leave-one-out` (tolerance unmet or overfitting: best leave-one-out error).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub degree_selection: String,
    /// Points whose residual stands out from the rest (probable outliers), worst first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub suspect_points: Vec<SuspectPoint>,
    /// Warnings about this curve (tolerance not met, extrapolated normal value, …).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

fn default_true() -> bool {
    true
}

/// One fitted curve: `value(θ) = normal · C(θ)`. Serialises to the flat JSON object of
/// `docs/fit-json.md` (`normal`, `basis`, `powers`, `coefficients`, `degree`, …).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct CurveFit {
    /// The normal-incidence value r0 or t0 (fraction).
    pub normal: f64,
    /// The ratio C(θ) to the normal value.
    #[serde(flatten)]
    pub polynomial: CosPolynomial,
    /// How well it fits its data, and what was solved.
    #[serde(flatten)]
    pub diagnostics: FitDiagnostics,
}

impl CurveFit {
    /// The fitted absolute value (fraction) at an incidence angle in degrees: normal · C(θ).
    pub fn eval_angle_deg(&self, angle_deg: f64) -> f64 {
        self.normal * self.polynomial.eval_angle_deg(angle_deg)
    }

    /// The fitted absolute value at a given cos θ (what the compositor's mask stores).
    #[inline]
    pub fn eval_cos(&self, cos_theta: f64) -> f64 {
        self.normal * self.polynomial.eval(cos_theta)
    }

    /// True when `angle_deg` lies outside the measured range by more than `margin_deg`
    /// (unknown range: false).
    pub fn is_extrapolated(&self, angle_deg: f64, margin_deg: f64) -> bool {
        let (lo, hi) = self.data_range();
        angle_deg < lo - margin_deg || angle_deg > hi + margin_deg
    }
}

/// One measured curve: angles of incidence (degrees, 0–90) and the value at each (fraction).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct AngleSamples {
    /// Angles of incidence (degrees).
    pub angle_deg: Vec<f64>,
    /// The value at each angle (fraction).
    pub value: Vec<f64>,
}

/// Which quantity a curve is: it decides the default basis.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Quantity {
    /// r(θ): the full basis by default.
    Reflectance,
    /// t(θ): the better of the paper and full bases by default.
    Transmittance,
}

impl Quantity {
    /// The lowercase name used in JSON and messages.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Reflectance => "reflectance",
            Quantity::Transmittance => "transmittance",
        }
    }
}

/// Default `--tol`: largest acceptable |fitted − measured| over the data (fraction).
pub const DEFAULT_TOL: f64 = 0.002;
/// Default `--max-degree` for automatic degree selection.
pub const DEFAULT_MAX_DEGREE: u32 = 8;

/// How to fit one curve.
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// Fixed degree; `None` selects it (smallest meeting `tol`, guarded by leave-one-out error).
    pub degree: Option<u32>,
    /// Tolerance on max |fitted − measured| over the data, in absolute value (fraction).
    pub tol: f64,
    /// Highest degree tried by automatic selection.
    pub max_degree: u32,
    /// `None`: full for reflectance; for transmittance the more accurate of paper and full on
    /// the data, preferring one whose t(θ) stays within 0–1 over 0–90°.
    pub basis: Option<Basis>,
    /// Which curve this is (decides the default basis).
    pub quantity: Quantity,
}

impl FitOptions {
    /// The defaults: automatic degree, tol 0.002, max degree 8, default basis.
    pub fn new(quantity: Quantity) -> Self {
        FitOptions {
            degree: None,
            tol: DEFAULT_TOL,
            max_degree: DEFAULT_MAX_DEGREE,
            basis: None,
            quantity,
        }
    }
}
