//! Delimited text: our CSV (`wavelength_nm,T,R,Rb`) and the exports of spectrophotometer
//! software and spreadsheets.
//!
//! - Title lines above the header (Agilent Cary writes the sample name there) are skipped: the
//!   header is the first line with a wavelength column.
//! - Headers with units: `"Wavelength (nm)"`, `Wavelength [µm]`, `λ/nm`, `nm`, `wavelength` (the
//!   unit then comes from the values, as for Optics files: nm when every wavelength is ≥ 100);
//!   `%T`, `T (%)`, `R [%]` mark a column in percent.
//! - Separators: `,`, `;` or tab, chosen by the header line. Decimal commas (`0,912`) are read
//!   wherever a field holds one comma and no point (European exports).
//! - Rows in strictly decreasing wavelength order (instruments scan from long to short
//!   wavelengths) are reversed; any other disorder stays an error.
//! - A blank line followed by a line that does not start with a number ends the table (the
//!   metadata block Cary writes after the data); a column with an empty header (a trailing
//!   separator) must be empty.

use crate::error::SpectralError;
use crate::read::{
    Collected, Place, ProductInfo, QUANTITY_NAMES, ReadOptions, SpectralData, SpectralFormat,
    decode_cp1252, microns_to_nm, parse_number,
};

/// How many lines (title lines, comments) the header may be preceded by.
const MAX_HEADER_LINE: usize = 50;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum WavelengthUnit {
    Nanometres,
    Microns,
    /// No unit in the header: nm when every wavelength is ≥ 100, else µm.
    FromValues,
}

/// What a header field names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Column {
    Wavelength(WavelengthUnit),
    /// T, Rf, Rb (index into [`QUANTITY_NAMES`]); `percent` when the header says so.
    Quantity {
        slot: usize,
        percent: bool,
    },
    /// An empty header (a trailing separator): its values must be empty too.
    Unnamed,
}

const NM: &[&str] = &["nm", "nanometer", "nanometers", "nanometre", "nanometres"];
const UM: &[&str] = &[
    "um",
    "µm",
    "μm",
    "micron",
    "microns",
    "micrometer",
    "micrometers",
    "micrometre",
    "micrometres",
];
const PERCENT: &[&str] = &["%", "percent", "pct"];
const FRACTION: &[&str] = &["fraction", "1", "-", "0-1"];

/// `("wavelength", Some("nm"))` from `wavelength (nm)`, `wavelength [nm]`, `wavelength/nm`,
/// `wavelength_nm`, `wavelength nm`; the name alone when it carries no unit.
fn split_unit(lower: &str) -> (&str, Option<&str>) {
    for (open, close) in [('(', ')'), ('[', ']')] {
        if let Some(inner) = lower.strip_suffix(close)
            && let Some(i) = inner.rfind(open)
        {
            return (inner[..i].trim(), Some(inner[i + open.len_utf8()..].trim()));
        }
    }
    if let Some((base, unit)) = lower.split_once('/') {
        return (base.trim(), Some(unit.trim()));
    }
    let is_unit = |u: &str| NM.contains(&u) || UM.contains(&u) || PERCENT.contains(&u);
    for sep in ['_', ' '] {
        if let Some((base, unit)) = lower.rsplit_once(sep)
            && is_unit(unit.trim())
            && !base.trim().is_empty()
        {
            return (base.trim(), Some(unit.trim()));
        }
    }
    (lower, None)
}

/// A header field taken apart: its name without unit or `%`, its unit, whether it says percent.
struct HeaderName<'a> {
    base: &'a str,
    unit: Option<&'a str>,
    percent: bool,
}

fn header_name(lower: &str) -> HeaderName<'_> {
    let (mut base, unit) = split_unit(lower);
    let mut percent = unit.is_some_and(|u| PERCENT.contains(&u));
    if let Some(b) = base.strip_prefix('%') {
        percent = true;
        base = b.trim();
    }
    if let Some(b) = base.strip_suffix('%') {
        percent = true;
        base = b.trim();
    }
    HeaderName {
        base,
        unit,
        percent,
    }
}

/// The unit a wavelength column's name implies (`Some(None)`: none, from the values), or `None`
/// when the name is not a wavelength column's.
fn wavelength_unit<'a>(h: &HeaderName<'a>) -> Option<Option<&'a str>> {
    match h.base {
        "nm" => Some(Some("nm")),
        "um" | "µm" | "μm" | "micron" | "microns" => Some(Some("um")),
        "wavelength" | "wavelengths" | "wave length" | "lambda" | "λ" | "wl" => Some(h.unit),
        _ => None,
    }
}

/// Classifies a header field; `Err` says why it is not a column we read.
fn classify(name: &str) -> Result<Column, String> {
    let lower = name.trim().to_lowercase();
    if lower.is_empty() {
        return Ok(Column::Unnamed);
    }
    let h = header_name(&lower);
    let (base, unit, percent) = (h.base, h.unit, h.percent);
    if let Some(unit) = wavelength_unit(&h) {
        if percent {
            return Err("a wavelength column cannot be in percent".to_owned());
        }
        return match unit {
            None => Ok(Column::Wavelength(WavelengthUnit::FromValues)),
            Some(u) if NM.contains(&u) => Ok(Column::Wavelength(WavelengthUnit::Nanometres)),
            Some(u) if UM.contains(&u) => Ok(Column::Wavelength(WavelengthUnit::Microns)),
            Some(u) => Err(format!(
                "unknown wavelength unit {} (expected nm or µm)",
                glassdb_io::backticked(u)
            )),
        };
    }
    let slot = match base {
        "t" | "transmittance" | "transmission" => 0,
        "r" | "rf" | "reflectance" | "reflection" => 1,
        "rb" => 2,
        "a" | "abs" | "absorbance" => {
            return Err(
                "absorbance is not read: export transmittance (T or %T) instead".to_owned(),
            );
        }
        _ => {
            return Err(format!(
                "unknown column {}: expected wavelength_nm or wavelength_um (or a wavelength header with its unit, e.g. `Wavelength (nm)`), then T, R (or Rf), Rb, each optionally in percent (`%T`, `T (%)`)",
                glassdb_io::backticked(name.trim())
            ));
        }
    };
    if let Some(u) = unit
        && !PERCENT.contains(&u)
        && !FRACTION.contains(&u)
    {
        return Err(format!(
            "unknown unit {} for {} (expected % or none)",
            glassdb_io::backticked(u),
            QUANTITY_NAMES[slot]
        ));
    }
    Ok(Column::Quantity { slot, percent })
}

/// The separator a line uses: tab, then `;`, else `,`.
fn delimiter_of(line: &str) -> u8 {
    if line.contains('\t') {
        b'\t'
    } else if line.contains(';') {
        b';'
    } else {
        b','
    }
}

/// The fields of one line (double quotes group and are removed), trimmed.
fn split_fields(line: &str, delimiter: u8) -> Vec<String> {
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    for c in line.chars() {
        match c {
            '"' => quoted = !quoted,
            c if !quoted && c as u32 == u32::from(delimiter) => {
                fields.push(field.trim().to_owned());
                field.clear();
            }
            c => field.push(c),
        }
    }
    fields.push(field.trim().to_owned());
    fields
}

/// `0,912` → `0.912`: a field with one comma and no point uses a decimal comma.
fn decimal_comma(text: &str) -> Option<String> {
    (text.matches(',').count() == 1 && !text.contains('.')).then(|| text.replace(',', "."))
}

/// A number in a CSV field, decimal comma allowed; errors as [`parse_number`] on the text as
/// written.
fn csv_number(text: &str, source: &str, place: Place, what: &str) -> Result<f64, SpectralError> {
    if let Some(v) =
        decimal_comma(text.trim()).and_then(|t| parse_number(&t, source, place, what).ok())
    {
        return Ok(v);
    }
    parse_number(text, source, place, what)
}

fn is_number(text: &str) -> bool {
    let t = text.trim();
    let t = decimal_comma(t).unwrap_or_else(|| t.to_owned());
    t.parse::<f64>().is_ok()
}

/// Neither blank nor a `#` comment.
fn has_content(line: &str) -> bool {
    let t = line.trim();
    !t.is_empty() && !t.starts_with('#')
}

/// Whether a line names a wavelength column (even one with a unit glassdb then refuses).
fn is_header(line: &str) -> bool {
    split_fields(line, delimiter_of(line))
        .iter()
        .any(|f| wavelength_unit(&header_name(&f.to_lowercase())).is_some())
}

fn starts_with_number(line: &str, delimiter: u8) -> bool {
    split_fields(line, delimiter)
        .first()
        .is_some_and(|f| is_number(f))
}

/// Where the table is: the header's line index, the separator, and the index of the first line
/// after the table (the footer, or the end).
struct Layout {
    header: usize,
    delimiter: u8,
    end: usize,
}

fn layout(lines: &[&str]) -> Layout {
    let first = lines.iter().position(|l| has_content(l)).unwrap_or(0);
    let mut header = first;
    for (i, line) in lines.iter().enumerate().skip(first).take(MAX_HEADER_LINE) {
        if !has_content(line) {
            continue;
        }
        if is_header(line) {
            header = i;
            break;
        }
        if starts_with_number(line, delimiter_of(line)) {
            // Data before any wavelength header: the first line is read as the header (and
            // its error names what is wrong with it).
            break;
        }
    }
    let delimiter = delimiter_of(lines.get(header).copied().unwrap_or(""));
    let mut end = lines.len();
    let mut i = header + 1;
    while i < lines.len() {
        if lines[i].trim().is_empty() {
            match lines[i + 1..].iter().position(|l| has_content(l)) {
                None => break,
                Some(j) if !starts_with_number(lines[i + 1 + j], delimiter) => {
                    end = i;
                    break;
                }
                Some(j) => i += 1 + j,
            }
        } else {
            i += 1;
        }
    }
    Layout {
        header,
        delimiter,
        end,
    }
}

pub(crate) fn read_csv(
    bytes: &[u8],
    source: &str,
    opts: &ReadOptions,
) -> Result<SpectralData, SpectralError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let text = decode_cp1252(bytes);
    let lines: Vec<&str> = text.split('\n').collect();
    let Layout {
        header,
        delimiter,
        end,
    } = layout(&lines);
    // Byte offsets of the table's first line and of the line after it.
    let offset_of = |index: usize| -> usize { lines[..index].iter().map(|l| l.len() + 1).sum() };
    let table = &text[offset_of(header).min(text.len())..offset_of(end).min(text.len())];
    let line_offset = header;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .delimiter(delimiter)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(table.as_bytes());
    let headers = reader
        .headers()
        .map_err(|e| csv_error(source, e, line_offset))?
        .clone();
    let columns = Columns::of(&headers, source, header + 1)?;
    let (raw_wl, mut collected) = columns.read_rows(&mut reader, source, line_offset)?;
    let microns = match columns.wavelength.1 {
        WavelengthUnit::Nanometres => false,
        WavelengthUnit::Microns => true,
        WavelengthUnit::FromValues => !raw_wl.iter().all(|&w| w >= 100.0),
    };
    collected.wavelength_nm = if microns {
        raw_wl.iter().map(|&w| microns_to_nm(w)).collect()
    } else {
        raw_wl
    };
    let percent = columns
        .quantities
        .map(|c| opts.percent || c.is_some_and(|(_, p)| p));
    collected.finish(
        percent,
        opts.percent,
        ProductInfo::empty(SpectralFormat::Csv),
    )
}

/// What the header says of each column: the wavelength column and its unit, each quantity's
/// column and whether it is in percent, and the columns without a name (which must stay
/// empty).
struct Columns {
    wavelength: (usize, WavelengthUnit),
    quantities: [Option<(usize, bool)>; 3],
    unnamed: Vec<usize>,
}

impl Columns {
    /// The columns of `headers` (on line `header_line` of `source`).
    fn of(
        headers: &csv::StringRecord,
        source: &str,
        header_line: usize,
    ) -> Result<Columns, SpectralError> {
        let mut wl_col: Option<(usize, WavelengthUnit)> = None;
        let mut q_cols: [Option<(usize, bool)>; 3] = [None, None, None];
        let mut unnamed: Vec<usize> = Vec::new();
        for (i, name) in headers.iter().enumerate() {
            let column = classify(name).map_err(|message| {
                SpectralError::parse(source, header_line, Some(i + 1), message)
            })?;
            match column {
                Column::Unnamed => unnamed.push(i),
                Column::Wavelength(unit) => {
                    if wl_col.is_some() {
                        return Err(SpectralError::parse(
                            source,
                            header_line,
                            Some(i + 1),
                            "more than one wavelength column (several samples side by side? glassdb reads one sample per file)",
                        ));
                    }
                    wl_col = Some((i, unit));
                }
                Column::Quantity { slot, percent } => {
                    if q_cols[slot].is_some() {
                        return Err(SpectralError::parse(
                            source,
                            header_line,
                            Some(i + 1),
                            format!(
                                "column `{}` repeats {} (R and Rf are the same quantity)",
                                name.trim(),
                                QUANTITY_NAMES[slot]
                            ),
                        ));
                    }
                    q_cols[slot] = Some((i, percent));
                }
            }
        }
        let Some(wavelength) = wl_col else {
            return Err(SpectralError::parse(
                source,
                header_line,
                None,
                "no wavelength_nm or wavelength_um column",
            ));
        };
        Ok(Columns {
            wavelength,
            quantities: q_cols,
            unnamed,
        })
    }

    /// Reads every row: the raw wavelengths (in the file's unit) and the quantities with the
    /// place of every value; a table from long to short wavelengths is reversed.
    fn read_rows<'s, R: std::io::Read>(
        &self,
        reader: &mut csv::Reader<R>,
        source: &'s str,
        line_offset: usize,
    ) -> Result<(Vec<f64>, Collected<'s>), SpectralError> {
        let wl_index = self.wavelength.0;
        let mut raw_wl: Vec<f64> = Vec::new();
        let mut collected = Collected {
            source,
            wavelength_nm: Vec::new(),
            wavelength_places: Vec::new(),
            quantities: self.quantities.map(|c| c.map(|_| (Vec::new(), Vec::new()))),
        };
        let mut record = csv::StringRecord::new();
        loop {
            match reader.read_record(&mut record) {
                Ok(false) => break,
                Ok(true) => {}
                Err(e) => return Err(csv_error(source, e, line_offset)),
            }
            let line = record.position().map_or(0, |p| p.line() as usize) + line_offset;
            let field = |i: usize| record.get(i).unwrap_or("");
            for &i in &self.unnamed {
                if !field(i).is_empty() {
                    return Err(SpectralError::parse(
                        source,
                        line,
                        Some(i + 1),
                        format!("column {} has values but no header", i + 1),
                    ));
                }
            }
            let place = Place {
                line,
                column: Some(wl_index + 1),
            };
            raw_wl.push(csv_number(field(wl_index), source, place, "wavelength")?);
            collected.wavelength_places.push(place);
            for (slot, col) in self.quantities.iter().enumerate() {
                let (Some((col, _)), Some((values, places))) =
                    (col, collected.quantities[slot].as_mut())
                else {
                    continue;
                };
                let place = Place {
                    line,
                    column: Some(col + 1),
                };
                values.push(csv_number(
                    field(*col),
                    source,
                    place,
                    QUANTITY_NAMES[slot],
                )?);
                places.push(place);
            }
        }
        // Instruments scan from long to short wavelengths: a strictly decreasing table is
        // reversed.
        if raw_wl.len() > 1 && raw_wl.windows(2).all(|w| w[1] < w[0]) {
            raw_wl.reverse();
            collected.wavelength_places.reverse();
            for (values, places) in collected.quantities.iter_mut().flatten() {
                values.reverse();
                places.reverse();
            }
        }
        Ok((raw_wl, collected))
    }
}

fn csv_error(source: &str, e: csv::Error, line_offset: usize) -> SpectralError {
    let line = e.position().map_or(0, |p| p.line() as usize) + line_offset;
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => SpectralError::parse(
            source,
            line,
            None,
            format!("{len} fields where the header has {expected_len}"),
        ),
        _ => SpectralError::Csv {
            source_name: source.to_owned(),
            line,
            source: e,
        },
    }
}

/// Whether `text` looks like delimited text with a wavelength header within its first lines
/// (for files whose extension says nothing).
pub(crate) fn looks_like_csv(text: &str) -> bool {
    text.lines()
        .filter(|l| has_content(l) && !l.contains('{'))
        .take(MAX_HEADER_LINE)
        .any(is_header)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_with_units_and_percent() {
        use Column::*;
        use WavelengthUnit::*;
        let cases: [(&str, Column); 16] = [
            ("wavelength_nm", Wavelength(Nanometres)),
            ("wavelength_um", Wavelength(Microns)),
            ("Wavelength_µm", Wavelength(Microns)),
            ("Wavelength (nm)", Wavelength(Nanometres)),
            ("Wavelength [µm]", Wavelength(Microns)),
            ("λ/nm", Wavelength(Nanometres)),
            ("nm", Wavelength(Nanometres)),
            ("Wavelength", Wavelength(FromValues)),
            ("wavelength nm", Wavelength(Nanometres)),
            (
                "T",
                Quantity {
                    slot: 0,
                    percent: false,
                },
            ),
            (
                "%T",
                Quantity {
                    slot: 0,
                    percent: true,
                },
            ),
            (
                "T (%)",
                Quantity {
                    slot: 0,
                    percent: true,
                },
            ),
            (
                "R [%]",
                Quantity {
                    slot: 1,
                    percent: true,
                },
            ),
            (
                "%R",
                Quantity {
                    slot: 1,
                    percent: true,
                },
            ),
            (
                "Rb",
                Quantity {
                    slot: 2,
                    percent: false,
                },
            ),
            ("", Unnamed),
        ];
        for (name, want) in cases {
            assert_eq!(classify(name), Ok(want), "{name}");
        }
        assert!(classify("Abs").unwrap_err().contains("absorbance"));
        assert!(classify("Wavelength (cm-1)").unwrap_err().contains("cm-1"));
        assert!(classify("T (mm)").unwrap_err().contains("unknown unit"));
        assert!(
            classify("Tr")
                .unwrap_err()
                .starts_with("unknown column `Tr`")
        );
    }

    #[test]
    fn layout_skips_title_lines_and_a_footer() {
        let text = "Sample1,,\nWavelength (nm),%T,\n800.0,89.5,\n\n790.0,89.4,\n\nCollection Time: 3/14/2019\nScan Rate: 600\n";
        let lines: Vec<&str> = text.split('\n').collect();
        let l = layout(&lines);
        assert_eq!((l.header, l.delimiter, l.end), (1, b',', 5));
        // No header at all: the first line is the header (its error says what is wrong).
        let lines = ["T,R", "0.5,0.1"];
        let l = layout(&lines);
        assert_eq!((l.header, l.end), (0, 2));
        assert_eq!(layout(&["a;b", "nm;%T"]).delimiter, b';');
        assert_eq!(layout(&["nm\t%T"]).delimiter, b'\t');
        // A header with a unit glassdb refuses is still the header (its error names the unit).
        assert_eq!(
            layout(&["Title", "Wavelength (cm-1),T", "4000,0.5"]).header,
            1
        );
    }

    #[test]
    fn fields_and_decimal_commas() {
        assert_eq!(
            split_fields("\"Wavelength (nm)\";\"%T\"", b';'),
            vec!["Wavelength (nm)", "%T"]
        );
        assert_eq!(decimal_comma("0,912").as_deref(), Some("0.912"));
        assert_eq!(decimal_comma("1,5E-03").as_deref(), Some("1.5E-03"));
        assert_eq!(decimal_comma("1.234,5"), None);
        assert!(is_number("2500,0") && !is_number("Collection Time: 3"));
    }
}
