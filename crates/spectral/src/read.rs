//! Readers for spectral glazing data: our CSV, LBNL Optics/IGDB text files and IGSDB JSON.
//!
//! Every reader returns wavelengths in nm, strictly increasing, and values as fractions in
//! `[0, 1]`; anything else is an error naming the source and line (and column for CSV and the
//! whitespace-separated Optics rows).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::SpectralError;

/// Which reader produced a [`SpectralData`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpectralFormat {
    /// `wavelength_nm` / `wavelength_um` plus `T`, `R` (= `Rf`), `Rb` columns.
    Csv,
    /// LBNL Optics5 / IGDB text (`.DAT`, `.LOF`, `.afg`, `.oag`, …).
    Optics,
    /// The JSON igsdb.lbl.gov returns for one product (both schema generations).
    IgsdbJson,
}

/// Product metadata found in the file (all optional: our CSV carries none).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProductInfo {
    pub name: Option<String>,
    pub manufacturer: Option<String>,
    /// Optics `{ Type: … }` or IGSDB `subtype` (falling back to `type` in the older schema), as written.
    pub product_type: Option<String>,
    /// `Front`, `Back`, `Neither`, `Both`, as written.
    pub coated_side: Option<String>,
    pub thickness_mm: Option<f64>,
    pub format: SpectralFormat,
}

impl ProductInfo {
    fn empty(format: SpectralFormat) -> Self {
        ProductInfo {
            name: None,
            manufacturer: None,
            product_type: None,
            coated_side: None,
            thickness_mm: None,
            format,
        }
    }
}

/// One glazing layer's normal-incidence spectra.
///
/// `wavelength_nm` is strictly increasing and finite; every present quantity has the same
/// length and holds fractions in `[0, 1]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpectralData {
    /// The file name (or the name given to [`read_spectral_bytes`]), for messages.
    pub source: String,
    pub wavelength_nm: Vec<f64>,
    /// Spectral transmittance τ(λ).
    pub transmittance: Option<Vec<f64>>,
    /// Spectral reflectance ρ(λ) of the front side (CSV `R` or `Rf`).
    pub reflectance_front: Option<Vec<f64>>,
    /// Spectral reflectance of the back side (CSV `Rb`).
    pub reflectance_back: Option<Vec<f64>>,
    pub product: ProductInfo,
}

/// Reader options.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// Values are in percent (0–100) rather than fractions. Applies to CSV only: Optics and
    /// IGSDB files are always fractions. Giving it for a file whose values never exceed 1 is an
    /// error (the file looks like fractions).
    pub percent: bool,
}

/// Reads a spectral file; the format comes from the extension, then from the content.
pub fn read_spectral_file(path: &Path, opts: &ReadOptions) -> Result<SpectralData, SpectralError> {
    let bytes = glassdb_io::read_input(path, glassdb_io::limits::SPECTRAL).map_err(|source| {
        SpectralError::Io {
            path: path.to_path_buf(),
            source,
        }
    })?;
    read_spectral_bytes(&bytes, &path.display().to_string(), opts)
}

/// Reads spectral data from memory. `source_name` is used for messages and, by its extension
/// (`.csv`, `.json`, anything else), to choose the format; when the extension says nothing
/// the content decides (`{"` starts JSON, a `wavelength_` header starts CSV, else Optics).
pub fn read_spectral_bytes(
    bytes: &[u8],
    source_name: &str,
    opts: &ReadOptions,
) -> Result<SpectralData, SpectralError> {
    match detect_format(bytes, source_name) {
        SpectralFormat::Csv => read_csv(bytes, source_name, opts),
        SpectralFormat::Optics => read_optics(bytes, source_name),
        SpectralFormat::IgsdbJson => read_igsdb_json(bytes, source_name),
    }
}

/// Chooses the reader: by extension, then by the first non-blank bytes.
pub fn detect_format(bytes: &[u8], source_name: &str) -> SpectralFormat {
    let ext = Path::new(source_name)
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("csv") => return SpectralFormat::Csv,
        Some("json") => return SpectralFormat::IgsdbJson,
        Some(
            "dat" | "lof" | "afg" | "oag" | "ipe" | "vta" | "gvb" | "hct" | "ppg" | "sgg" | "gdt",
        ) => {
            return SpectralFormat::Optics;
        }
        _ => {}
    }
    let text_start: Vec<u8> = bytes
        .iter()
        .copied()
        .skip_while(|b| b.is_ascii_whitespace() || *b == 0xEF || *b == 0xBB || *b == 0xBF)
        .take(4096)
        .collect();
    if text_start.first() == Some(&b'{') {
        let after = text_start[1..].iter().find(|b| !b.is_ascii_whitespace());
        if matches!(after, Some(b'"') | Some(b'}')) {
            return SpectralFormat::IgsdbJson;
        }
        return SpectralFormat::Optics;
    }
    let lower: Vec<u8> = text_start.iter().map(|b| b.to_ascii_lowercase()).collect();
    if lower.windows(11).any(|w| w == b"wavelength_") {
        return SpectralFormat::Csv;
    }
    SpectralFormat::Optics
}

/// Where a value came from, for messages.
#[derive(Debug, Clone, Copy)]
struct Place {
    line: usize,
    column: Option<usize>,
}

/// Rows collected by a reader before the common checks.
struct Collected<'a> {
    source: &'a str,
    wavelength_nm: Vec<f64>,
    wavelength_places: Vec<Place>,
    /// T, Rf, Rb; each with the place of every value.
    quantities: [Option<(Vec<f64>, Vec<Place>)>; 3],
}

const QUANTITY_NAMES: [&str; 3] = ["T", "Rf", "Rb"];

/// Converts µm to nm and snaps to 1e-6 nm, so that `0.305 µm` becomes exactly `305 nm` and
/// uniformly spaced files stay uniformly spaced (colour-science decides Sprague vs. spline by
/// exact equality of the steps). The Python oracle does the same (`np.round(um * 1000, 6)`).
pub fn microns_to_nm(um: f64) -> f64 {
    (um * 1000.0 * 1e6).round_ties_even() / 1e6
}

fn parse_number(text: &str, source: &str, place: Place, what: &str) -> Result<f64, SpectralError> {
    let t = text.trim();
    if t.is_empty() {
        return Err(SpectralError::parse(
            source,
            place.line,
            place.column,
            format!("empty {what}"),
        ));
    }
    let v: f64 = t.parse().map_err(|_| {
        SpectralError::parse(
            source,
            place.line,
            place.column,
            format!("{what} `{t}` is not a number"),
        )
    })?;
    if !v.is_finite() {
        return Err(SpectralError::parse(
            source,
            place.line,
            place.column,
            format!("{what} is {t}: not a finite number"),
        ));
    }
    Ok(v)
}

impl Collected<'_> {
    /// The checks every format shares: sorted unique positive wavelengths, values in range.
    fn finish(self, percent: bool, product: ProductInfo) -> Result<SpectralData, SpectralError> {
        let source = self.source;
        if self.wavelength_nm.is_empty() {
            return Err(SpectralError::format(source, "no data rows"));
        }
        if self.quantities.iter().all(Option::is_none) {
            return Err(SpectralError::format(source, "no T, R/Rf or Rb values"));
        }
        for (i, (&wl, place)) in self
            .wavelength_nm
            .iter()
            .zip(&self.wavelength_places)
            .enumerate()
        {
            if !wl.is_finite() {
                return Err(SpectralError::parse(
                    source,
                    place.line,
                    place.column,
                    "wavelength is out of range after conversion to nm",
                ));
            }
            if wl <= 0.0 {
                return Err(SpectralError::parse(
                    source,
                    place.line,
                    place.column,
                    format!("wavelength {wl} nm is not positive"),
                ));
            }
            if i > 0 {
                let prev = self.wavelength_nm[i - 1];
                let prev_line = self.wavelength_places[i - 1].line;
                if wl == prev {
                    return Err(SpectralError::parse(
                        source,
                        place.line,
                        place.column,
                        format!("duplicate wavelength {wl} nm (also on line {prev_line})"),
                    ));
                }
                if wl < prev {
                    return Err(SpectralError::parse(
                        source,
                        place.line,
                        place.column,
                        format!(
                            "wavelengths are not sorted: {wl} nm follows {prev} nm (line {prev_line}); sort the rows by wavelength"
                        ),
                    ));
                }
            }
        }
        let scale = if percent { 0.01 } else { 1.0 };
        let mut any_above_one = false;
        let mut out: [Option<Vec<f64>>; 3] = [None, None, None];
        for (k, q) in self.quantities.into_iter().enumerate() {
            let Some((values, places)) = q else { continue };
            let name = QUANTITY_NAMES[k];
            let mut scaled = Vec::with_capacity(values.len());
            for (&v, place) in values.iter().zip(&places) {
                if v < 0.0 {
                    return Err(SpectralError::parse(
                        source,
                        place.line,
                        place.column,
                        format!(
                            "{name} = {v} is negative; transmittance and reflectance lie in [0, 1]"
                        ),
                    ));
                }
                if v > 1.0 {
                    any_above_one = true;
                }
                let s = v * scale;
                if s > 1.0 {
                    if !percent {
                        return Err(SpectralError::AboveOneInFractions {
                            source_name: source.to_owned(),
                            line: place.line,
                            column: place.column,
                            name: name.to_string(),
                            value: v,
                        });
                    }
                    return Err(SpectralError::parse(
                        source,
                        place.line,
                        place.column,
                        format!("{name} = {v} is above 1 (above 100 %)"),
                    ));
                }
                scaled.push(s);
            }
            out[k] = Some(scaled);
        }
        if percent && !any_above_one {
            return Err(SpectralError::FractionsReadAsPercent {
                source_name: source.to_owned(),
            });
        }
        let [transmittance, reflectance_front, reflectance_back] = out;
        Ok(SpectralData {
            source: source.to_owned(),
            wavelength_nm: self.wavelength_nm,
            transmittance,
            reflectance_front,
            reflectance_back,
            product,
        })
    }
}

// ---------------------------------------------------------------------------------------------
// CSV
// ---------------------------------------------------------------------------------------------

fn read_csv(bytes: &[u8], source: &str, opts: &ReadOptions) -> Result<SpectralData, SpectralError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(bytes);
    let headers = reader
        .byte_headers()
        .map_err(|e| csv_error(source, e))?
        .clone();
    let header_line = 1usize;
    let mut wl_col: Option<(usize, f64)> = None; // (index, scale to nm)
    let mut q_cols: [Option<usize>; 3] = [None, None, None];
    for (i, raw) in headers.iter().enumerate() {
        let name = std::str::from_utf8(raw)
            .map_err(|_| {
                SpectralError::parse(source, header_line, Some(i + 1), "header is not UTF-8")
            })?
            .trim();
        let lower = name.to_ascii_lowercase();
        let slot = match lower.as_str() {
            "wavelength_nm" | "wavelength_um" | "wavelength_µm" => {
                if wl_col.is_some() {
                    return Err(SpectralError::parse(
                        source,
                        header_line,
                        Some(i + 1),
                        "more than one wavelength column",
                    ));
                }
                let scale = if lower == "wavelength_nm" {
                    1.0
                } else {
                    1000.0
                };
                wl_col = Some((i, scale));
                continue;
            }
            "t" => 0,
            "r" | "rf" => 1,
            "rb" => 2,
            _ => {
                return Err(SpectralError::parse(
                    source,
                    header_line,
                    Some(i + 1),
                    format!(
                        "unknown column `{name}`: expected wavelength_nm or wavelength_um, then T, R (or Rf), Rb"
                    ),
                ));
            }
        };
        if q_cols[slot].is_some() {
            return Err(SpectralError::parse(
                source,
                header_line,
                Some(i + 1),
                format!(
                    "column `{name}` repeats {} (R and Rf are the same quantity)",
                    QUANTITY_NAMES[slot]
                ),
            ));
        }
        q_cols[slot] = Some(i);
    }
    let Some((wl_index, wl_scale)) = wl_col else {
        return Err(SpectralError::parse(
            source,
            header_line,
            None,
            "no wavelength_nm or wavelength_um column",
        ));
    };
    let mut collected = Collected {
        source,
        wavelength_nm: Vec::new(),
        wavelength_places: Vec::new(),
        quantities: q_cols.map(|c| c.map(|_| (Vec::new(), Vec::new()))),
    };
    let mut record = csv::ByteRecord::new();
    loop {
        match reader.read_byte_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => return Err(csv_error(source, e)),
        }
        let line = record.position().map(|p| p.line() as usize).unwrap_or(0);
        let field = |i: usize| -> Result<&str, SpectralError> {
            let raw = record.get(i).unwrap_or(b"");
            std::str::from_utf8(raw)
                .map_err(|_| SpectralError::parse(source, line, Some(i + 1), "not UTF-8"))
        };
        let place = Place {
            line,
            column: Some(wl_index + 1),
        };
        let wl = parse_number(field(wl_index)?, source, place, "wavelength")?;
        let wl_nm = if wl_scale == 1.0 {
            wl
        } else {
            microns_to_nm(wl)
        };
        collected.wavelength_nm.push(wl_nm);
        collected.wavelength_places.push(place);
        for (slot, col) in q_cols.iter().enumerate() {
            let (Some(col), Some((values, places))) = (col, collected.quantities[slot].as_mut())
            else {
                continue;
            };
            let place = Place {
                line,
                column: Some(col + 1),
            };
            let v = parse_number(field(*col)?, source, place, QUANTITY_NAMES[slot])?;
            values.push(v);
            places.push(place);
        }
    }
    collected.finish(opts.percent, ProductInfo::empty(SpectralFormat::Csv))
}

fn csv_error(source: &str, e: csv::Error) -> SpectralError {
    let line = e.position().map(|p| p.line() as usize).unwrap_or(0);
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

// ---------------------------------------------------------------------------------------------
// LBNL Optics / IGDB text
// ---------------------------------------------------------------------------------------------

/// Decodes Windows-1252 (the Optics files' ™ is byte 0x99), which is a superset of ASCII.
fn decode_cp1252(bytes: &[u8]) -> String {
    const HIGH: [char; 32] = [
        '€', '\u{81}', '‚', 'ƒ', '„', '…', '†', '‡', 'ˆ', '‰', 'Š', '‹', 'Œ', '\u{8d}', 'Ž',
        '\u{8f}', '\u{90}', '‘', '’', '“', '”', '•', '–', '—', '˜', '™', 'š', '›', 'œ', '\u{9d}',
        'ž', 'Ÿ',
    ];
    if let Ok(s) = std::str::from_utf8(bytes) {
        return s.to_owned();
    }
    bytes
        .iter()
        .map(|&b| match b {
            0x80..=0x9F => HIGH[(b - 0x80) as usize],
            _ => b as char,
        })
        .collect()
}

#[derive(Clone, Copy, PartialEq)]
enum WavelengthUnit {
    Microns,
    Nanometers,
}

fn read_optics(bytes: &[u8], source: &str) -> Result<SpectralData, SpectralError> {
    let mut product = ProductInfo::empty(SpectralFormat::Optics);
    let mut unit: Option<WavelengthUnit> = None;
    let mut raw_wl: Vec<f64> = Vec::new();
    let mut places: Vec<Place> = Vec::new();
    let mut values: [Vec<f64>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    let mut value_places: [Vec<Place>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    for (index, raw_line) in bytes.split(|&b| b == b'\n').enumerate() {
        let line_no = index + 1;
        let raw_line = raw_line.strip_suffix(b"\r").unwrap_or(raw_line);
        let text = decode_cp1252(raw_line);
        let trimmed = text.trim().trim_start_matches('\u{feff}');
        if trimmed.is_empty() {
            continue;
        }
        if trimmed.contains('{') {
            parse_optics_header(trimmed, source, line_no, &mut product, &mut unit)?;
            continue;
        }
        let fields: Vec<&str> = trimmed.split_whitespace().collect();
        if fields.len() != 4 {
            return Err(SpectralError::parse(
                source,
                line_no,
                None,
                format!(
                    "expected 4 numbers `wavelength T Rf Rb`, found {} fields",
                    fields.len()
                ),
            ));
        }
        let wl = parse_number(
            fields[0],
            source,
            Place {
                line: line_no,
                column: Some(1),
            },
            "wavelength",
        )?;
        raw_wl.push(wl);
        places.push(Place {
            line: line_no,
            column: Some(1),
        });
        for k in 0..3 {
            let place = Place {
                line: line_no,
                column: Some(k + 2),
            };
            values[k].push(parse_number(
                fields[k + 1],
                source,
                place,
                QUANTITY_NAMES[k],
            )?);
            value_places[k].push(place);
        }
    }
    if raw_wl.is_empty() {
        return Err(SpectralError::format(
            source,
            "no data rows `wavelength T Rf Rb`",
        ));
    }
    // Without a `{ Units, Wavelength Units }` line, decide by magnitude: Optics files hold
    // 0.3–40 µm; anything with every wavelength ≥ 100 is in nm.
    let unit = unit.unwrap_or_else(|| {
        if raw_wl.iter().all(|&w| w >= 100.0) {
            WavelengthUnit::Nanometers
        } else {
            WavelengthUnit::Microns
        }
    });
    let wavelength_nm = match unit {
        WavelengthUnit::Microns => raw_wl.iter().map(|&w| microns_to_nm(w)).collect(),
        WavelengthUnit::Nanometers => raw_wl,
    };
    let [t, rf, rb] = values;
    let [tp, rfp, rbp] = value_places;
    Collected {
        source,
        wavelength_nm,
        wavelength_places: places,
        quantities: [Some((t, tp)), Some((rf, rfp)), Some((rb, rbp))],
    }
    .finish(false, product)
}

fn parse_optics_header(
    line: &str,
    source: &str,
    line_no: usize,
    product: &mut ProductInfo,
    unit: &mut Option<WavelengthUnit>,
) -> Result<(), SpectralError> {
    let Some(open) = line.find('{') else {
        return Ok(());
    };
    let Some(close_rel) = line[open..].find('}') else {
        return Err(SpectralError::parse(
            source,
            line_no,
            None,
            "header line has `{` but no `}`",
        ));
    };
    let inside = line[open + 1..open + close_rel].trim();
    let after = line[open + close_rel + 1..].trim();
    let (key, value) = match inside.split_once(':') {
        Some((k, v)) => (k.trim(), v.trim()),
        None => (inside, after),
    };
    let non_empty = |v: &str| (!v.is_empty()).then(|| v.to_owned());
    match key.to_ascii_lowercase().as_str() {
        "units, wavelength units" => {
            let lower = value.to_ascii_lowercase();
            *unit = if lower.contains("micron") {
                Some(WavelengthUnit::Microns)
            } else if lower.contains("nanometer") {
                Some(WavelengthUnit::Nanometers)
            } else {
                return Err(SpectralError::parse(
                    source,
                    line_no,
                    None,
                    format!(
                        "unknown wavelength units `{value}` (expected `SI Microns` or `SI Nanometers`)"
                    ),
                ));
            };
        }
        "thickness" if !value.is_empty() => {
            let place = Place {
                line: line_no,
                column: None,
            };
            product.thickness_mm = Some(parse_number(value, source, place, "thickness")?);
        }
        "product name" => product.name = non_empty(value),
        "manufacturer" => product.manufacturer = non_empty(value),
        "type" => product.product_type = non_empty(value),
        "coated side" => product.coated_side = non_empty(value),
        _ => {}
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// IGSDB JSON
// ---------------------------------------------------------------------------------------------

fn read_igsdb_json(bytes: &[u8], source: &str) -> Result<SpectralData, SpectralError> {
    let value: serde_json::Value =
        serde_json::from_slice(bytes).map_err(|e| SpectralError::Parse {
            source_name: source.to_owned(),
            line: e.line(),
            column: Some(e.column()),
            message: format!("invalid JSON: {e}"),
        })?;
    let rows = value
        .get("spectral_data")
        .and_then(|s| s.get("spectral_data").or(Some(s)))
        .and_then(|s| s.as_array())
        .ok_or_else(|| {
            SpectralError::format(
                source,
                "no `spectral_data.spectral_data` array: not an IGSDB product",
            )
        })?;
    let lines = json_element_lines(bytes);
    let place_of = |i: usize| Place {
        line: lines.get(i).copied().unwrap_or(0),
        column: None,
    };
    let text = |v: Option<&serde_json::Value>| -> Option<String> {
        v.and_then(|v| match v {
            serde_json::Value::String(s) if !s.trim().is_empty() => Some(s.trim().to_owned()),
            serde_json::Value::Object(o) => o
                .get("name")
                .and_then(|n| n.as_str())
                .map(|s| s.trim().to_owned()),
            _ => None,
        })
    };
    let product = ProductInfo {
        name: text(value.get("name")).or_else(|| text(value.get("product_name"))),
        manufacturer: text(value.get("manufacturer_name"))
            .or_else(|| text(value.get("manufacturer"))),
        product_type: text(value.get("subtype")).or_else(|| text(value.get("type"))),
        coated_side: text(value.get("coated_side")),
        thickness_mm: value
            .get("measured_data")
            .and_then(|m| m.get("thickness"))
            .and_then(|t| t.as_f64()),
        format: SpectralFormat::IgsdbJson,
    };
    let keys = ["T", "Rf", "Rb"];
    let present: Vec<bool> = keys
        .iter()
        .map(|k| rows.iter().any(|r| r.get(*k).is_some_and(|v| !v.is_null())))
        .collect();
    let mut collected = Collected {
        source,
        wavelength_nm: Vec::with_capacity(rows.len()),
        wavelength_places: Vec::with_capacity(rows.len()),
        quantities: [0, 1, 2].map(|k| present[k].then(|| (Vec::new(), Vec::new()))),
    };
    for (i, row) in rows.iter().enumerate() {
        let place = place_of(i);
        let number = |key: &str| -> Result<f64, SpectralError> {
            match row.get(key) {
                Some(serde_json::Value::Number(n)) => n.as_f64().ok_or_else(|| {
                    SpectralError::parse(
                        source,
                        place.line,
                        None,
                        format!("spectral_data[{i}].{key} is out of range"),
                    )
                }),
                Some(other) => Err(SpectralError::parse(
                    source,
                    place.line,
                    None,
                    format!("spectral_data[{i}].{key} is {other}, not a number"),
                )),
                None => Err(SpectralError::parse(
                    source,
                    place.line,
                    None,
                    format!("spectral_data[{i}] has no `{key}`"),
                )),
            }
        };
        let wl = number("wavelength")?;
        collected.wavelength_nm.push(microns_to_nm(wl));
        collected.wavelength_places.push(place);
        for (k, key) in keys.iter().enumerate() {
            if let Some((values, places)) = collected.quantities[k].as_mut() {
                values.push(number(key)?);
                places.push(place);
            }
        }
    }
    collected.finish(false, product)
}

/// 1-based line of each element of the `spectral_data` array of objects (best effort: used
/// only to point messages at the right place in an already valid JSON text).
fn json_element_lines(bytes: &[u8]) -> Vec<usize> {
    let key = b"\"spectral_data\"";
    let mut search_from = 0;
    while let Some(rel) = bytes
        .get(search_from..)
        .and_then(|b| b.windows(key.len()).position(|w| w == key))
    {
        let mut i = search_from + rel + key.len();
        search_from = i;
        while bytes.get(i).is_some_and(|b| b.is_ascii_whitespace()) {
            i += 1;
        }
        if bytes.get(i) != Some(&b':') {
            continue;
        }
        i += 1;
        while bytes.get(i).is_some_and(|b| b.is_ascii_whitespace()) {
            i += 1;
        }
        if bytes.get(i) != Some(&b'[') {
            continue;
        }
        let mut line = 1 + bytes[..i].iter().filter(|&&b| b == b'\n').count();
        let mut depth = 0usize;
        let mut in_string = false;
        let mut escaped = false;
        let mut out = Vec::new();
        for &b in &bytes[i..] {
            if b == b'\n' {
                line += 1;
            }
            if in_string {
                if escaped {
                    escaped = false;
                } else if b == b'\\' {
                    escaped = true;
                } else if b == b'"' {
                    in_string = false;
                }
                continue;
            }
            match b {
                b'"' => in_string = true,
                b'[' | b'{' => {
                    if depth == 1 && b == b'{' {
                        out.push(line);
                    }
                    depth += 1;
                }
                b']' | b'}' => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        return out;
                    }
                }
                _ => {}
            }
        }
        return out;
    }
    Vec::new()
}
