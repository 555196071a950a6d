//! glassdb-fit: angle dependence of glass reflectance and transmittance (`docs/method.md`,
//! "Angle dependence", eqs. 11–14): `r(θ) = r0·C_r(θ)`, `t(θ) = t0·C_t(θ)` with
//! `C(θ) = Σ_k c_k cos^{p_k} θ` and `C(0°) = 1`.
//!
//! - [`read_angle_table`]: the angle-table CSV (errors name file, line, column).
//! - [`fit_curve`]: one curve, constrained least squares by Householder QR on a Chebyshev
//!   basis, exported in the power basis; degree by tolerance with a leave-one-out guard.
//! - [`fit_glass`]: both curves of a glass plus the physical checks (0 ≤ r, t ≤ 1, r + t ≤ 1).
//! - [`FitFile`] / [`read_fit_file`]: the JSON that `glassdb fit --json` writes
//!   (`docs/fit-json.md`), validated on every read ([`FitFile::validate`]: physical ranges
//!   within [`MAX_CURVE_TOLERANCE`] at most, as the registry checks its curves), and
//!   [`CurveFit::eval_angle_deg`] / [`CosPolynomial::eval`] to use it.

#![warn(missing_docs)]

mod dd;
mod error;
mod glass;
mod model;
mod solve;
mod table;

pub use error::FitError;
pub use glass::{
    CHECK_SLACK, CHECK_STEP_DEG, FitFile, GlassFit, MAX_CURVE_TOLERANCE, OtherJson,
    PhysicalViolation, fit_glass, parse_fit_json, physical_checks, read_fit_file,
};
pub use model::{
    AngleSamples, Basis, CosPolynomial, CurveFit, DEFAULT_MAX_DEGREE, DEFAULT_TOL, FitDiagnostics,
    FitOptions, FitSummary, MAX_POWER, PolynomialShape, Quantity, SuspectPoint, cos_deg,
};
pub use solve::{
    EXTRAPOLATION_MARGIN_DEG, LOO_GUARD_FACTOR, MAX_DEGREE, SUSPECT_STUDENTIZED, fit_curve,
};
pub use table::{
    ANGLE_TABLE_FILE, GlassAngleTable, MAX_TABLE_BYTES, RepeatedAngle, parse_angle_table,
    read_angle_table,
};
