//! The one error type of the fit crate: one variant per failure a user can act on.

use std::path::PathBuf;

/// Everything that can go wrong reading an angle table, fitting a curve or reading a fit file.
/// Table errors name the file, and the line and column where the problem is.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// The file could not be read: missing, not a regular file, or larger than any angle
    /// table or fit file can reasonably be ([`crate::MAX_TABLE_BYTES`],
    /// [`glassdb_io::limits::JSON`]).
    #[error("cannot read {path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why it could not be read.
        source: glassdb_io::InputError,
    },
    /// The file has no header line (or nothing at all).
    #[error("{path}: the file is empty (expected a header line such as `angle_deg,R,T`)")]
    EmptyFile {
        /// The file.
        path: PathBuf,
    },
    /// The file has a header but no data rows.
    #[error("{path}: no data rows after the header")]
    NoRows {
        /// The file.
        path: PathBuf,
    },
    /// A row with a different number of fields than the header.
    #[error("{path}, line {line}: row has {fields} field(s) but the header has {header_fields}")]
    RaggedRow {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// Fields in the row.
        fields: u64,
        /// Fields in the header.
        header_fields: u64,
    },
    /// The CSV reader failed otherwise (text not UTF-8, an I/O error); the reader's error is
    /// the source.
    #[error("{path}, line {line}: not readable as CSV")]
    Csv {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The CSV reader's error.
        source: csv::Error,
    },
    /// A required column is missing from the header.
    #[error("{path}, line {line}: missing column {wanted} (header has: {found})")]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The column wanted.
        wanted: String,
        /// The header's columns.
        found: String,
    },
    /// The header has a column the reader does not know.
    #[error(
        "{path}, line {line}, column {column}: unknown column `{name}` (accepted: angle_deg/theta_deg, R/reflectance, T/transmittance, glass)"
    )]
    UnknownColumn {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The 1-based column.
        column: usize,
        /// The column's name.
        name: String,
    },
    /// Two header cells name the same quantity (e.g. `R` and `reflectance`).
    #[error(
        "{path}, line {line}, column {column}: column `{name}` repeats a quantity already given in column {first}"
    )]
    DuplicateColumn {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The 1-based column.
        column: usize,
        /// The column it repeats.
        first: usize,
        /// The column's name.
        name: String,
    },
    /// A cell is not a number.
    #[error("{path}, line {line}, column {column} ({header}): `{value}` is not a number")]
    NotANumber {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The 1-based column.
        column: usize,
        /// The column's header.
        header: String,
        /// The cell.
        value: String,
    },
    /// A cell is NaN or infinite.
    #[error("{path}, line {line}, column {column} ({header}): `{value}` is not a finite number")]
    NotFinite {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The 1-based column.
        column: usize,
        /// The column's header.
        header: String,
        /// The cell.
        value: String,
    },
    /// A required cell (the angle) is empty.
    #[error("{path}, line {line}, column {column} ({header}): empty cell")]
    EmptyCell {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The 1-based column.
        column: usize,
        /// The column's header.
        header: String,
    },
    /// An angle outside 0–90°.
    #[error("{path}, line {line}, column {column} ({header}): angle {value}° is outside 0–90°")]
    AngleOutOfRange {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The 1-based column.
        column: usize,
        /// The column's header.
        header: String,
        /// The angle.
        value: f64,
    },
    /// A value above 1 in a table read as fractions.
    #[error(
        "{path}, line {line}, column {column} ({header}): {value} is above 1; values are fractions 0–1 (the table may be in percent)"
    )]
    AboveOneInFractions {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The 1-based column.
        column: usize,
        /// The column's header.
        header: String,
        /// The value.
        value: f64,
    },
    /// A value outside 0–1 (or 0–100 when read as percent).
    #[error("{path}, line {line}, column {column} ({header}): {value} is outside {range}")]
    ValueOutOfRange {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The 1-based column.
        column: usize,
        /// The column's header.
        header: String,
        /// The value.
        value: f64,
        /// The allowed range.
        range: &'static str,
    },
    /// A glass name cell is empty in a file with a `glass` column.
    #[error("{path}, line {line}, column {column} (glass): empty glass name")]
    EmptyGlassName {
        /// The file.
        path: PathBuf,
        /// The 1-based line.
        line: u64,
        /// The 1-based column.
        column: usize,
    },
    /// The table has neither an R nor a T column, or a glass has no value in either.
    #[error("{path}: glass `{glass}` has no R or T values")]
    NoValues {
        /// The file.
        path: PathBuf,
        /// The glass.
        glass: String,
    },
    /// Samples handed to the fitter are inconsistent (different lengths, NaN, angle outside 0–90°).
    #[error("invalid samples: {0}")]
    InvalidSamples(String),
    /// Fewer distinct angles than the coefficients the requested fit needs.
    #[error(
        "{points} distinct angle(s) but the {basis} basis at degree {degree} has {coefficients} coefficients: need at least as many points as coefficients"
    )]
    TooFewPoints {
        /// Distinct angles given.
        points: usize,
        /// Coefficients to determine.
        coefficients: usize,
        /// The degree asked for.
        degree: u32,
        /// The basis.
        basis: &'static str,
    },
    /// The fit options are inconsistent (degree 0 with the paper basis, tol not positive, …).
    #[error("invalid fit options: {0}")]
    InvalidOptions(String),
    /// The value at normal incidence is zero or negative, so the ratio C(θ) is undefined.
    #[error(
        "the normal-incidence value is {normal}, {detail}: C(θ) = value(θ)/value(0°) is undefined"
    )]
    BadNormal {
        /// The normal-incidence value.
        normal: f64,
        /// Why it cannot be used.
        detail: &'static str,
    },
    /// The least-squares system is singular (should not happen with distinct angles).
    #[error("the least-squares system is singular (degree {degree}, {points} points)")]
    Singular {
        /// The degree.
        degree: u32,
        /// Distinct angles.
        points: usize,
    },
    /// A fit file (JSON) is malformed or inconsistent.
    #[error("{path}: {message}")]
    FitFile {
        /// The fit file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The file is another glassdb JSON file (a registry, a planes file), not a fit file.
    #[error("{path} is {kind}, not a fit file")]
    OtherFile {
        /// The file.
        path: PathBuf,
        /// What it is.
        kind: crate::OtherJson,
    },
    /// A curve's normal value r0 or t0 lies outside [0, 1] (beyond the curve's tolerance).
    #[error(
        "{path}: glass `{glass}`, {quantity}: the normal value {normal:?} is outside [0, 1] (allowed tolerance {tolerance:.2e})"
    )]
    NormalOutOfRange {
        /// The fit file.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// `reflectance` or `transmittance`.
        quantity: &'static str,
        /// Its normal value.
        normal: f64,
        /// The allowed tolerance.
        tolerance: f64,
    },
    /// A glass's curves leave the physical range (0 ≤ r, t ≤ 1, r + t ≤ 1) by more than their
    /// tolerance ([`crate::CurveFit::validation_tolerance`]).
    #[error("{path}: glass `{glass}`: {violation} (allowed tolerance {tolerance:.2e})")]
    Unphysical {
        /// The fit file.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// The check that failed, and where.
        violation: crate::PhysicalViolation,
        /// The curves' validation tolerance.
        tolerance: f64,
    },
    /// A curve of a fit file cannot be evaluated as written.
    #[error("{path}: glass `{glass}`, {quantity}")]
    CurveShape {
        /// The fit file.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// `reflectance` or `transmittance`.
        quantity: &'static str,
        /// What is wrong with its polynomial.
        source: crate::PolynomialShape,
    },
    /// A fit of one curve of one glass failed (the inner error says why).
    #[error("glass `{glass}`, {quantity}: {error}")]
    Curve {
        /// The glass.
        glass: String,
        /// `reflectance` or `transmittance`.
        quantity: &'static str,
        /// The fit's error.
        error: Box<FitError>,
    },
    /// A physical check failed and strict mode turns it into an error.
    #[error("glass `{glass}`: {message}")]
    Physical {
        /// The glass.
        glass: String,
        /// The check that failed.
        message: String,
    },
    /// The fitter failed internally (a caught panic): a bug, not a property of the table.
    #[error("{what} failed internally (it panicked: {message}); this is a bug of glassdb's")]
    Internal {
        /// What failed.
        what: &'static str,
        /// The panic's message.
        message: String,
    },
}

impl FitError {
    /// The class of this error: a file that cannot be read is the reader's class, a caught
    /// panic is internal, anything else is a table, a fit file or an option to fix.
    pub fn kind(&self) -> glassdb_io::ErrorKind {
        match self {
            FitError::Io { source, .. } => source.kind(),
            FitError::Internal { .. } => glassdb_io::ErrorKind::Internal,
            FitError::Curve { error, .. } => error.kind(),
            _ => glassdb_io::ErrorKind::Invalid,
        }
    }
}

/// The text of a caught panic's payload (a `&str` or `String` message; else a placeholder).
pub(crate) fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "no message".to_string())
}
