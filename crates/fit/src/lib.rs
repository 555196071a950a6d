//! glassdb-fit: angle dependence of glass reflectance and transmittance (`docs/method.md`,
//! "Angle dependence", eqs. 11–14): `r(θ) = r0·C_r(θ)`, `t(θ) = t0·C_t(θ)` with
//! `C(θ) = Σ_k c_k cos^{p_k} θ` and `C(0°) = 1`.
//!
//! - [`read_angle_table`]: the angle-table CSV (errors name file, line, column; binary data
//!   and other glassdb files named as what they are).
//! - [`GlassAngleTable::screen`] ([`screen_curves`]): readings their neighbours contradict
//!   (the typos of a hand-written table), with their lines.
//! - [`fit_curve`]: one curve, constrained least squares by Householder QR on a Chebyshev
//!   basis, exported in the power basis; degree by tolerance with a leave-one-out guard.
//! - [`fit_glass`]: both curves of a glass: the screen, the fits, then the checks that refuse
//!   a fit far from its data or unphysical ([`refusing_checks`]) unless forced.
//! - [`FitFile`] / [`read_fit_file`]: the JSON that `glassdb fit --json` writes
//!   (`docs/fit-json.md`), validated on every read ([`FitFile::validate`]: physical ranges
//!   within [`MAX_CURVE_TOLERANCE`] at most, as the registry checks its curves), and
//!   [`CurveFit::eval_angle_deg`] / [`CosPolynomial::eval`] to use it.
//!
//! Modules, each importing only those listed before it: `dd`, `model`, `physical`, `sniff`,
//! `screen`, `error`, `prepared`, `chebyshev`, `table`, `solve`, `glass`, `file`.

#![warn(missing_docs)]

mod chebyshev;
mod dd;
mod error;
mod file;
mod glass;
mod model;
mod physical;
mod prepared;
mod screen;
mod sniff;
mod solve;
mod table;

pub use error::{CellRef, FitError};
pub use file::{FitFile, parse_fit_json, read_fit_file};
pub use glass::{GlassFit, GlassFitOptions, fit_glass};
pub use model::{
    AngleSamples, Basis, CosPolynomial, CurveFit, DEFAULT_MAX_DEGREE, DEFAULT_TOL, FitDiagnostics,
    FitOptions, FitSummary, MAX_POWER, PolynomialShape, Quantity, SuspectPoint, cos_deg,
};
pub use physical::{
    CHECK_SLACK, CHECK_STEP_DEG, MAX_CURVE_TOLERANCE, MONOTONIC_SLACK, PhysicalViolation,
    REFUSE_TOLERANCE_FACTOR, physical_checks, refusing_checks,
};
pub use screen::{InconsistentPoint, LikelyTypo, NEAR_NORMAL_DEG, Screening, screen_curves};
pub use sniff::{ExpectedFile, FileContent};
pub use solve::{
    EXTRAPOLATION_MARGIN_DEG, LOO_GUARD_FACTOR, MAX_DEGREE, SUSPECT_STUDENTIZED, fit_curve,
};
pub use table::{
    ANGLE_TABLE_FILE, AngleRows, GlassAngleTable, MAX_TABLE_BYTES, parse_angle_table,
    read_angle_table,
};
