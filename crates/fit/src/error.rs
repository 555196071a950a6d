//! The one error type of the fit crate: one variant per failure a user can act on.

use std::path::PathBuf;

use crate::model::{PolynomialShape, Quantity};
use crate::physical::PhysicalViolation;
use crate::screen::InconsistentPoint;
use crate::sniff::{ExpectedFile, FileContent};

/// A cell of an angle table, for messages that name several.
#[derive(Clone, Debug, PartialEq)]
pub struct CellRef {
    /// Its line in the file (1-based).
    pub line: u64,
    /// Its column (1-based).
    pub column: usize,
    /// The column's header.
    pub header: String,
    /// The value as written.
    pub value: f64,
}

impl std::fmt::Display for CellRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "line {}, column {} ({}): {}",
            self.line, self.column, self.header, self.value
        )
    }
}

/// At most `max` items joined by `; `, then how many more.
fn list<T: std::fmt::Display>(items: &[T], max: usize) -> String {
    let mut text: Vec<String> = items.iter().take(max).map(T::to_string).collect();
    if items.len() > max {
        text.push(format!("and {} more", items.len() - max));
    }
    text.join("; ")
}

/// Lines as `line 7` or `lines 7, 9`.
fn line_list(lines: &[u64]) -> String {
    let text: Vec<String> = lines.iter().map(u64::to_string).collect();
    match lines.len() {
        0 => "no line".into(),
        1 => format!("line {}", text[0]),
        _ => format!("lines {}", text.join(", ")),
    }
}

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
    /// The file is another kind of file than the reader reads: binary data (an image, an
    /// archive), a fit file given as an angle table, an angle table given as a fit file, a
    /// registry or a planes file.
    #[error("{path} is {kind}, not {expected}")]
    OtherFile {
        /// The file.
        path: PathBuf,
        /// What the file is.
        kind: FileContent,
        /// What the reader reads.
        expected: ExpectedFile,
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
        /// The line (1-based).
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
        /// The line (1-based).
        line: u64,
        /// The CSV reader's error.
        source: csv::Error,
    },
    /// A required column is missing from the header.
    #[error("{path}, line {line}: missing column {wanted} (header has: {found})")]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: u64,
        /// The column(s) the table needs.
        wanted: String,
        /// The header's columns.
        found: String,
    },
    /// The header has a column the reader does not know.
    #[error(
        "{path}, line {line}, column {column}: unknown column {} (accepted: angle_deg/theta_deg, R/reflectance, T/transmittance, glass)",
        glassdb_io::backticked(name)
    )]
    UnknownColumn {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: u64,
        /// The column (1-based).
        column: usize,
        /// The header cell.
        name: String,
    },
    /// Two header cells name the same quantity (e.g. `R` and `reflectance`).
    #[error(
        "{path}, line {line}, column {column}: column {} repeats a quantity already given in column {first}",
        glassdb_io::backticked(name)
    )]
    DuplicateColumn {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: u64,
        /// The column (1-based).
        column: usize,
        /// The column that gave the quantity first.
        first: usize,
        /// The header cell.
        name: String,
    },
    /// A cell is not a number.
    #[error(
        "{path}, line {line}, column {column} ({header}): {} is not a number",
        glassdb_io::backticked(value)
    )]
    NotANumber {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: u64,
        /// The column (1-based).
        column: usize,
        /// The column's header.
        header: String,
        /// The cell as written.
        value: String,
    },
    /// A cell is NaN or infinite.
    #[error(
        "{path}, line {line}, column {column} ({header}): {} is not a finite number",
        glassdb_io::backticked(value)
    )]
    NotFinite {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: u64,
        /// The column (1-based).
        column: usize,
        /// The column's header.
        header: String,
        /// The cell as written.
        value: String,
    },
    /// A required cell (the angle) is empty.
    #[error("{path}, line {line}, column {column} ({header}): empty cell")]
    EmptyCell {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: u64,
        /// The column (1-based).
        column: usize,
        /// The column's header.
        header: String,
    },
    /// An angle outside 0–90°.
    #[error(
        "{path}, line {}, column {} ({}): angle {}° is outside 0–90°",
        cell.line, cell.column, cell.header, cell.value
    )]
    AngleOutOfRange {
        /// The file.
        path: PathBuf,
        /// The angle's cell.
        cell: CellRef,
    },
    /// Most R and T values are above 1 in a table read as fractions: it is in percent.
    #[error(
        "{path}, line {line}, column {column} ({header}): {value} is above 1; values are fractions 0–1 (the table may be in percent)"
    )]
    AboveOneInFractions {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: u64,
        /// The column (1-based).
        column: usize,
        /// The column's header.
        header: String,
        /// The value as written.
        value: f64,
    },
    /// A few values above 1 among fractions: typos (a percent value, a shifted decimal point).
    #[error(
        "{path}: {} above 1 where the other values are fractions 0–1 (a percent value or a shifted decimal point?): {}",
        if cells.len() == 1 { "a value" } else { "values" },
        list(cells, 5)
    )]
    ValuesAboveOne {
        /// The file.
        path: PathBuf,
        /// The cells above 1.
        cells: Vec<CellRef>,
    },
    /// One column is mostly above 1 (percent) while another is not (fractions).
    #[error(
        "{path}: column {percent_column} is in percent but column {fraction_column} is in fractions (0–1)"
    )]
    MixedUnits {
        /// The file.
        path: PathBuf,
        /// The column whose values are mostly above 1.
        percent_column: String,
        /// The column whose values are mostly at most 1.
        fraction_column: String,
    },
    /// Read as percent, but most non-zero values are at most 1: the table is in fractions.
    #[error(
        "{path}: read as percent, but {at_most_one} of the {nonzero} non-zero R and T values are at most 1: the table looks like fractions"
    )]
    FractionsReadAsPercent {
        /// The file.
        path: PathBuf,
        /// How many non-zero values are at most 1.
        at_most_one: usize,
        /// How many values are not zero.
        nonzero: usize,
    },
    /// A value outside 0–1 (or 0–100 when read as percent).
    #[error("{path}, line {line}, column {column} ({header}): {value} is outside {range}")]
    ValueOutOfRange {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: u64,
        /// The column (1-based).
        column: usize,
        /// The column's header.
        header: String,
        /// The value as written.
        value: f64,
        /// The range allowed: `0–1` or `0–100 (percent)`.
        range: &'static str,
    },
    /// A glass name cell is empty in a file with a `glass` column.
    #[error("{path}, line {line}, column {column} (glass): empty glass name")]
    EmptyGlassName {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: u64,
        /// The column (1-based).
        column: usize,
    },
    /// The table has neither an R nor a T column, or a glass has no value in either.
    #[error("{path}: glass {} has no R or T values", glassdb_io::backticked(glass))]
    NoValues {
        /// The file.
        path: PathBuf,
        /// The glass.
        glass: String,
    },
    /// Readings their neighbours contradict (`docs/fit.md`, "Inconsistent points"): T rising
    /// or R falling with the angle, or either changing near normal incidence, by more than
    /// [`crate::MONOTONIC_SLACK`]. The fit is not written (unless forced).
    #[error(
        "{path}: glass {glass_q}: {} inconsistent with {} neighbours: {}",
        if points.len() == 1 { "a reading is" } else { "readings are" },
        if points.len() == 1 { "its" } else { "their" },
        list(points, 8), glass_q = glassdb_io::backticked(glass))]
    InconsistentPoints {
        /// The file.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// The readings, by curve and angle.
        points: Vec<InconsistentPoint>,
    },
    /// A whole curve runs the wrong way: T rising or R falling with the angle at more than a
    /// third of its readings.
    #[error(
        "{path}: glass {glass_q}: {} {} with the angle at most readings (the R and T columns swapped?)",
        match quantity { Quantity::Reflectance => "R", Quantity::Transmittance => "T" },
        match quantity { Quantity::Reflectance => "falls", Quantity::Transmittance => "rises" }, glass_q = glassdb_io::backticked(glass))]
    ReversedCurve {
        /// The file.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// The curve.
        quantity: Quantity,
    },
    /// A fitted curve misses a reading by more than [`crate::REFUSE_TOLERANCE_FACTOR`] times
    /// the tolerance. The fit is not written (unless forced).
    #[error(
        "{path}: glass {glass_q}, {}: the fit misses the reading at {angle_deg}° ({}) by {error:.4}, more than {} × the tolerance {tol}",
        quantity.name(),
        line_list(lines),
        crate::physical::REFUSE_TOLERANCE_FACTOR, glass_q = glassdb_io::backticked(glass))]
    FarFromData {
        /// The file.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// The curve.
        quantity: Quantity,
        /// The reading's angle (degrees).
        angle_deg: f64,
        /// The reading's lines in the file.
        lines: Vec<u64>,
        /// |fitted − measured| there.
        error: f64,
        /// The fit's tolerance.
        tol: f64,
    },
    /// A fitted curve fails a check of [`crate::refusing_checks`] over 0–90°: outside
    /// 0 ≤ r, t ≤ 1, r + t ≤ 1 beyond its tolerance, or running the wrong way with the angle.
    /// The fit is not written (unless forced).
    #[error(
        "{path}: glass {glass_q}: {violation}{} (allowed tolerance {tolerance:.2e})",
        if *beyond_data { ", beyond the measured angles" } else { "" }, glass_q = glassdb_io::backticked(glass))]
    UnphysicalFit {
        /// The table.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// The failed check.
        violation: PhysicalViolation,
        /// The slack it exceeded.
        tolerance: f64,
        /// The worst angle lies outside the angles the curve was measured at (extrapolated).
        beyond_data: bool,
    },
    /// Samples handed to the fitter are inconsistent (different lengths, NaN, angle outside 0–90°).
    #[error("invalid samples: {0}")]
    InvalidSamples(String),
    /// Fewer distinct angles than the coefficients the requested fit needs.
    #[error(
        "{points} distinct angle(s) but the {basis} basis at degree {degree} has {coefficients} coefficients: need at least as many points as coefficients"
    )]
    TooFewPoints {
        /// Distinct angles in the data.
        points: usize,
        /// Coefficients of the fit asked for.
        coefficients: usize,
        /// The degree.
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
        /// The normal value (measured or extrapolated).
        normal: f64,
        /// Why it is unusable.
        detail: &'static str,
    },
    /// The least-squares system is singular (should not happen with distinct angles).
    #[error("the least-squares system is singular (degree {degree}, {points} points)")]
    Singular {
        /// The degree.
        degree: u32,
        /// Distinct angles of the curve.
        points: usize,
    },
    /// The fitter panicked: a bug in glassdb (or a library it uses), not a problem of the
    /// data; the panic's message is kept.
    #[error("internal error in the fitter ({points} points): {message}")]
    Internal {
        /// The points of the curve being fitted.
        points: usize,
        /// The panic's message.
        message: String,
    },
    /// A fit file (JSON) is malformed or inconsistent.
    #[error("{path}: {message}")]
    FitFile {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A curve's normal value r0 or t0 lies outside [0, 1] (beyond the curve's tolerance).
    #[error(
        "{path}: glass {glass_q}, {quantity}: the normal value {normal:?} is outside [0, 1] (allowed tolerance {tolerance:.2e})", glass_q = glassdb_io::backticked(glass))]
    NormalOutOfRange {
        /// The file.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// The curve: `reflectance` or `transmittance`.
        quantity: &'static str,
        /// The normal value.
        normal: f64,
        /// The slack it exceeded.
        tolerance: f64,
    },
    /// A fit file's curves leave the physical range (0 ≤ r, t ≤ 1, r + t ≤ 1) by more than
    /// their tolerance ([`crate::CurveFit::validation_tolerance`]) within their measured range:
    /// every reader refuses the file.
    #[error("{path}: glass {glass_q}: {violation} (allowed tolerance {tolerance:.2e})", glass_q = glassdb_io::backticked(glass))]
    Unphysical {
        /// The file.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// The failed check.
        violation: PhysicalViolation,
        /// The slack it exceeded.
        tolerance: f64,
    },
    /// A curve of a fit file cannot be evaluated as written.
    #[error("{path}: glass {glass_q}, {quantity}", glass_q = glassdb_io::backticked(glass))]
    CurveShape {
        /// The file.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// The curve: `reflectance` or `transmittance`.
        quantity: &'static str,
        /// What is wrong with its shape.
        source: PolynomialShape,
    },
    /// A fit of one curve of one glass failed (the inner error says why).
    #[error("{path}: glass {glass_q}, {quantity}: {error}", glass_q = glassdb_io::backticked(glass))]
    Curve {
        /// The table.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// The curve: `reflectance` or `transmittance`.
        quantity: &'static str,
        /// Why the fit failed.
        error: Box<FitError>,
    },
    /// A physical check failed and strict mode turns it into an error.
    #[error("{path}: glass {glass_q}: physical check failed: {violation}", glass_q = glassdb_io::backticked(glass))]
    Physical {
        /// The table.
        path: PathBuf,
        /// The glass.
        glass: String,
        /// The failed check.
        violation: PhysicalViolation,
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
