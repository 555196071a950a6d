//! The angle-table CSV reader (format: `docs/fit.md`, "Input").
//!
//! Columns (header names case-insensitive, surrounding blanks ignored): `angle_deg` (or
//! `theta_deg`), `R` (or `reflectance`) and/or `T` (or `transmittance`), optional `glass`.
//! Lines starting with `#` are comments. Rows may come in any order; repeated angles of one
//! glass are averaged and reported. An empty R or T cell means "not measured at this angle".

use std::path::{Path, PathBuf};

use crate::error::{CellRef, FitError};
use crate::model::AngleSamples;
use crate::screen::{Screening, screen_curves};
use crate::sniff::{ExpectedFile, FileContent};

/// The largest angle table read (CSV): far above any real table, small enough to never exhaust
/// memory.
pub const ANGLE_TABLE_FILE: glassdb_io::InputLimit =
    glassdb_io::InputLimit::mib(64, "an angle table");

/// Largest angle table read (bytes).
pub const MAX_TABLE_BYTES: u64 = ANGLE_TABLE_FILE.bytes;

/// One distinct angle of a glass as read: the file's line numbers of its rows (1-based) and,
/// when the angle is repeated (its values averaged), how far those rows disagree.
#[derive(Clone, Debug, PartialEq)]
pub struct AngleRows {
    /// The angle of incidence (degrees).
    pub angle_deg: f64,
    /// The lines of the rows that give this angle, ascending (several when it is repeated).
    pub lines: Vec<u64>,
    /// Largest minus smallest R among those rows (None: R not measured there).
    pub reflectance_spread: Option<f64>,
    /// Largest minus smallest T among those rows (None: T not measured there).
    pub transmittance_spread: Option<f64>,
}

impl AngleRows {
    /// Whether the angle was given on more than one row (its values were averaged).
    pub fn is_repeated(&self) -> bool {
        self.lines.len() > 1
    }
}

/// The measured curves of one glass, sorted by angle, repeated angles averaged.
#[derive(Clone, Debug, PartialEq)]
pub struct GlassAngleTable {
    /// The `glass` column's value, or the file stem when there is no `glass` column.
    pub name: String,
    /// The file the table was read from (for messages).
    pub path: PathBuf,
    /// The reflectance curve, if the table has R values for this glass.
    pub reflectance: Option<AngleSamples>,
    /// The transmittance curve, if the table has T values for this glass.
    pub transmittance: Option<AngleSamples>,
    /// The rows of each distinct angle, ascending by angle.
    pub rows: Vec<AngleRows>,
}

impl GlassAngleTable {
    /// The readings of this table that their neighbours contradict ([`screen_curves`]), each
    /// with its file lines.
    pub fn screen(&self) -> Screening {
        let mut screening = screen_curves(self.reflectance.as_ref(), self.transmittance.as_ref());
        for p in &mut screening.points {
            p.lines = self.lines_of(p.angle_deg).to_vec();
        }
        screening
    }

    /// The angles given on several rows (averaged), ascending.
    pub fn repeated_angles(&self) -> impl Iterator<Item = &AngleRows> {
        self.rows.iter().filter(|r| r.is_repeated())
    }

    /// The file lines that give `angle_deg` (empty when the table has no such angle).
    pub fn lines_of(&self, angle_deg: f64) -> &[u64] {
        self.rows
            .iter()
            .find(|r| r.angle_deg == angle_deg)
            .map_or(&[], |r| r.lines.as_slice())
    }
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Field {
    Angle,
    R,
    T,
    Glass,
}

fn classify(header: &str) -> Option<Field> {
    match header.trim().to_ascii_lowercase().as_str() {
        "angle_deg" | "theta_deg" => Some(Field::Angle),
        "r" | "reflectance" => Some(Field::R),
        "t" | "transmittance" => Some(Field::T),
        "glass" => Some(Field::Glass),
        _ => None,
    }
}

/// One data row as read: the cells already numbers, not yet checked against the unit.
struct Row {
    glass: String,
    angle_deg: f64,
    line: u64,
    r: Option<Cell>,
    t: Option<Cell>,
}

/// An R or T cell: its value as written and where it stands.
#[derive(Clone, Copy)]
struct Cell {
    value: f64,
    line: u64,
    /// 0-based column index.
    column: usize,
}

/// Reads an angle table. With `percent`, R and T are in percent (0–100) and converted to
/// fractions; without it a table whose values are mostly above 1 is an error that suggests
/// `--percent`, and a few values above 1 among fractions are named as typos.
/// Every error names the file, and the line and column of the offending cell.
pub fn read_angle_table(path: &Path, percent: bool) -> Result<Vec<GlassAngleTable>, FitError> {
    let io_err = |source| FitError::Io {
        path: path.to_path_buf(),
        source,
    };
    let bytes = glassdb_io::read_input(path, ANGLE_TABLE_FILE).map_err(io_err)?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "glass".to_string());
    parse_angle_table(&bytes, path, &stem, percent)
}

/// Parses angle-table bytes (see [`read_angle_table`]); `path` is used in messages only and
/// `default_name` names the glass when there is no `glass` column. Binary data and JSON (a fit
/// file, a registry) are named as what they are ([`FitError::OtherFile`]).
pub fn parse_angle_table(
    bytes: &[u8],
    path: &Path,
    default_name: &str,
    percent: bool,
) -> Result<Vec<GlassAngleTable>, FitError> {
    if let Some(kind) = FileContent::not_an_angle_table(bytes) {
        return Err(FitError::OtherFile {
            path: path.to_path_buf(),
            kind,
            expected: ExpectedFile::AngleTable,
        });
    }
    let (names, rows) = read_rows(bytes, path, default_name, percent)?;
    check_units(&rows, &names, path, percent)?;
    let divisor = if percent { 100.0 } else { 1.0 };
    group(rows, path, divisor)
}

/// The header's names and the data rows, every cell a finite number, every angle within 0–90°,
/// no value negative (or above 100 with `percent`).
fn read_rows(
    bytes: &[u8],
    path: &Path,
    default_name: &str,
    percent: bool,
) -> Result<(Vec<String>, Vec<Row>), FitError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .flexible(false)
        .from_reader(bytes);
    let headers = rdr
        .byte_headers()
        .map_err(|e| csv_error(path.to_path_buf(), e))?
        .clone();
    let (names, columns) = read_header(&headers, path)?;
    let reader = RowReader {
        path,
        names: &names,
        columns,
        default_name,
        percent,
    };
    let mut rows = Vec::new();
    let mut record = csv::ByteRecord::new();
    while rdr
        .read_byte_record(&mut record)
        .map_err(|e| csv_error(path.to_path_buf(), e))?
    {
        rows.push(reader.row(&record)?);
    }
    if rows.is_empty() {
        return Err(FitError::NoRows {
            path: path.to_path_buf(),
        });
    }
    Ok((names, rows))
}

/// Where the table's columns stand (0-based).
#[derive(Clone, Copy)]
struct Columns {
    angle: usize,
    r: Option<usize>,
    t: Option<usize>,
    glass: Option<usize>,
}

/// The header's names and where the columns stand: every name known and given once, an angle
/// column and an R and/or a T column.
fn read_header(headers: &csv::ByteRecord, path: &Path) -> Result<(Vec<String>, Columns), FitError> {
    let p = || path.to_path_buf();
    if headers.is_empty() || (headers.len() == 1 && headers[0].iter().all(u8::is_ascii_whitespace))
    {
        return Err(FitError::EmptyFile { path: p() });
    }
    let header_line = headers.position().map(|pos| pos.line()).unwrap_or(1);
    let mut names = Vec::with_capacity(headers.len());
    let mut cols: [Option<usize>; 4] = [None; 4];
    for (i, raw) in headers.iter().enumerate() {
        let name = String::from_utf8_lossy(raw).trim().to_string();
        let Some(field) = classify(&name) else {
            return Err(FitError::UnknownColumn {
                path: p(),
                line: header_line,
                column: i + 1,
                name,
            });
        };
        let slot = &mut cols[field as usize];
        if let Some(first) = *slot {
            return Err(FitError::DuplicateColumn {
                path: p(),
                line: header_line,
                column: i + 1,
                first: first + 1,
                name,
            });
        }
        *slot = Some(i);
        names.push(name);
    }
    let found = names.join(", ");
    let Some(angle) = cols[Field::Angle as usize] else {
        return Err(FitError::MissingColumn {
            path: p(),
            line: header_line,
            wanted: "angle_deg (or theta_deg)".into(),
            found,
        });
    };
    let columns = Columns {
        angle,
        r: cols[Field::R as usize],
        t: cols[Field::T as usize],
        glass: cols[Field::Glass as usize],
    };
    if columns.r.is_none() && columns.t.is_none() {
        return Err(FitError::MissingColumn {
            path: p(),
            line: header_line,
            wanted: "R (or reflectance) and/or T (or transmittance)".into(),
            found,
        });
    }
    Ok((names, columns))
}

/// Reads the data rows of one table: what an error names (file, header names) and how the
/// cells are read.
struct RowReader<'a> {
    path: &'a Path,
    names: &'a [String],
    columns: Columns,
    default_name: &'a str,
    percent: bool,
}

impl RowReader<'_> {
    /// One data row: the angle within 0–90°, R and T (when given) not negative (nor above 100
    /// with `percent`), the glass named.
    fn row(&self, record: &csv::ByteRecord) -> Result<Row, FitError> {
        let line = record.position().map(|pos| pos.line()).unwrap_or(0);
        let col = self.columns.angle;
        let angle_text = self.cell(record, line, col)?;
        if angle_text.is_empty() {
            return Err(FitError::EmptyCell {
                path: self.path.to_path_buf(),
                line,
                column: col + 1,
                header: self.names[col].clone(),
            });
        }
        let angle_deg = self.number(line, col, angle_text)?;
        if !(0.0..=90.0).contains(&angle_deg) {
            return Err(FitError::AngleOutOfRange {
                path: self.path.to_path_buf(),
                cell: CellRef {
                    line,
                    column: col + 1,
                    header: self.names[col].clone(),
                    value: angle_deg,
                },
            });
        }
        let r = self.value(record, line, self.columns.r)?;
        let t = self.value(record, line, self.columns.t)?;
        let glass = match self.columns.glass {
            Some(col) => {
                let name = self.cell(record, line, col)?;
                if name.is_empty() {
                    return Err(FitError::EmptyGlassName {
                        path: self.path.to_path_buf(),
                        line,
                        column: col + 1,
                    });
                }
                name.to_string()
            }
            None => self.default_name.to_string(),
        };
        Ok(Row {
            glass,
            angle_deg,
            line,
            r,
            t,
        })
    }

    /// The text of a cell, trimmed; not UTF-8 is not a number.
    fn cell<'r>(
        &self,
        record: &'r csv::ByteRecord,
        line: u64,
        col: usize,
    ) -> Result<&'r str, FitError> {
        let raw = record.get(col).unwrap_or(b"");
        std::str::from_utf8(raw)
            .map(str::trim)
            .map_err(|_| FitError::NotANumber {
                path: self.path.to_path_buf(),
                line,
                column: col + 1,
                header: self.names.get(col).cloned().unwrap_or_default(),
                value: String::from_utf8_lossy(raw).into_owned(),
            })
    }

    /// A cell's text as a finite number.
    fn number(&self, line: u64, col: usize, text: &str) -> Result<f64, FitError> {
        let header = self.names.get(col).cloned().unwrap_or_default();
        let v: f64 = text.parse().map_err(|_| FitError::NotANumber {
            path: self.path.to_path_buf(),
            line,
            column: col + 1,
            header: header.clone(),
            value: text.to_string(),
        })?;
        if !v.is_finite() {
            return Err(FitError::NotFinite {
                path: self.path.to_path_buf(),
                line,
                column: col + 1,
                header,
                value: text.to_string(),
            });
        }
        Ok(v)
    }

    /// An R or T cell of column `col` (none when the column or the cell is empty), within its
    /// range.
    fn value(
        &self,
        record: &csv::ByteRecord,
        line: u64,
        col: Option<usize>,
    ) -> Result<Option<Cell>, FitError> {
        let Some(col) = col else { return Ok(None) };
        let text = self.cell(record, line, col)?;
        if text.is_empty() {
            return Ok(None);
        }
        let v = self.number(line, col, text)?;
        let (top, range) = if self.percent {
            (100.0, "0–100 (percent)")
        } else {
            (f64::INFINITY, "0–1")
        };
        if v < 0.0 || v > top {
            return Err(FitError::ValueOutOfRange {
                path: self.path.to_path_buf(),
                line,
                column: col + 1,
                header: self.names[col].clone(),
                value: v,
                range,
            });
        }
        Ok(Some(Cell {
            value: v,
            line,
            column: col,
        }))
    }
}

/// The unit of the R and T cells, judged on the whole table: without `percent`, a table whose
/// values are mostly above 1 is in percent ([`FitError::AboveOneInFractions`]), a column that
/// is while another is not mixes units ([`FitError::MixedUnits`]), and a few values above 1
/// among fractions are typos ([`FitError::ValuesAboveOne`]: a percent value or a shifted
/// decimal point). With `percent`, a table whose non-zero values are mostly at most 1 is in
/// fractions ([`FitError::FractionsReadAsPercent`]).
fn check_units(rows: &[Row], names: &[String], path: &Path, percent: bool) -> Result<(), FitError> {
    let cells = || rows.iter().flat_map(|r| [r.r, r.t]).flatten();
    let above: Vec<Cell> = cells().filter(|c| c.value > 1.0).collect();
    let total = cells().count();
    let header = |c: &Cell| names.get(c.column).cloned().unwrap_or_default();
    if percent {
        // zeros (t at 90°, an opaque pane) say nothing about the unit
        let nonzero = cells().filter(|c| c.value != 0.0).count();
        let at_most_one = nonzero - above.len();
        if 2 * at_most_one > nonzero {
            return Err(FitError::FractionsReadAsPercent {
                path: path.to_path_buf(),
                at_most_one,
                nonzero,
            });
        }
        return Ok(());
    }
    let Some(first) = above.first() else {
        return Ok(());
    };
    if 2 * above.len() > total {
        return Err(FitError::AboveOneInFractions {
            path: path.to_path_buf(),
            line: first.line,
            column: first.column + 1,
            header: header(first),
            value: first.value,
        });
    }
    // per column: is it mostly above 1 (in percent) while another column is not?
    let mut columns: Vec<usize> = cells().map(|c| c.column).collect();
    columns.sort_unstable();
    columns.dedup();
    let mostly_above = |col: usize| {
        let n = cells().filter(|c| c.column == col).count();
        2 * above.iter().filter(|c| c.column == col).count() > n
    };
    if let (Some(&pc), Some(&fc)) = (
        columns.iter().find(|&&c| mostly_above(c)),
        columns.iter().find(|&&c| !mostly_above(c)),
    ) {
        return Err(FitError::MixedUnits {
            path: path.to_path_buf(),
            percent_column: names.get(pc).cloned().unwrap_or_default(),
            fraction_column: names.get(fc).cloned().unwrap_or_default(),
        });
    }
    Err(FitError::ValuesAboveOne {
        path: path.to_path_buf(),
        cells: above
            .iter()
            .map(|c| CellRef {
                line: c.line,
                column: c.column + 1,
                header: header(c),
                value: c.value,
            })
            .collect(),
    })
}

fn csv_error(path: PathBuf, e: csv::Error) -> FitError {
    let line = e.position().map(|pos| pos.line()).unwrap_or(0);
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => FitError::RaggedRow {
            path,
            line,
            fields: *len,
            header_fields: *expected_len,
        },
        _ => FitError::Csv {
            path,
            line,
            source: e,
        },
    }
}

/// Groups rows by glass (first-appearance order), sorts by angle, averages repeated angles;
/// R and T values are divided by `divisor` (100 for percent).
fn group(rows: Vec<Row>, path: &Path, divisor: f64) -> Result<Vec<GlassAngleTable>, FitError> {
    let mut order: Vec<String> = Vec::new();
    let mut by_glass: std::collections::HashMap<String, Vec<Row>> =
        std::collections::HashMap::new();
    for row in rows {
        if !by_glass.contains_key(&row.glass) {
            order.push(row.glass.clone());
        }
        by_glass.entry(row.glass.clone()).or_default().push(row);
    }
    let mut out = Vec::with_capacity(order.len());
    for name in order {
        let mut rows = by_glass.remove(&name).unwrap_or_default();
        rows.sort_by(|a, b| {
            a.angle_deg
                .total_cmp(&b.angle_deg)
                .then(a.line.cmp(&b.line))
        });
        let mut r = AngleSamples::default();
        let mut t = AngleSamples::default();
        let mut angle_rows = Vec::new();
        let mut i = 0;
        while i < rows.len() {
            let mut j = i + 1;
            while j < rows.len() && rows[j].angle_deg == rows[i].angle_deg {
                j += 1;
            }
            let group = &rows[i..j];
            let angle = rows[i].angle_deg;
            let rs: Vec<f64> = group
                .iter()
                .filter_map(|row| row.r)
                .map(|c| c.value / divisor)
                .collect();
            let ts: Vec<f64> = group
                .iter()
                .filter_map(|row| row.t)
                .map(|c| c.value / divisor)
                .collect();
            if !rs.is_empty() {
                r.angle_deg.push(angle);
                r.value.push(mean(&rs));
            }
            if !ts.is_empty() {
                t.angle_deg.push(angle);
                t.value.push(mean(&ts));
            }
            angle_rows.push(AngleRows {
                angle_deg: angle,
                lines: group.iter().map(|row| row.line).collect(),
                reflectance_spread: spread(&rs),
                transmittance_spread: spread(&ts),
            });
            i = j;
        }
        if r.angle_deg.is_empty() && t.angle_deg.is_empty() {
            return Err(FitError::NoValues {
                path: path.to_path_buf(),
                glass: name,
            });
        }
        out.push(GlassAngleTable {
            name,
            path: path.to_path_buf(),
            reflectance: (!r.angle_deg.is_empty()).then_some(r),
            transmittance: (!t.angle_deg.is_empty()).then_some(t),
            rows: angle_rows,
        });
    }
    Ok(out)
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn spread(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Some(hi - lo)
}
