//! What every reader of spectral glazing data shares (the data, its product information, the
//! values collected before the common checks), and the LBNL Optics/IGDB text reader; our CSV
//! and instrument exports are read by `read_csv`, IGSDB JSON of both schema generations by
//! `read_igsdb`, and `open` chooses among them.
//!
//! Every reader returns wavelengths in nm, strictly increasing, and values as fractions in
//! `[0, 1]`; anything else is an error naming the source and line (and column for CSV and the
//! whitespace-separated Optics rows). Data glassdb does not read (shading products, BSDF XML,
//! diffuse data, binary files) is refused by name ([`crate::UnsupportedKind`]).

use serde::{Deserialize, Serialize};

use crate::error::{SpectralError, UnsupportedKind};

/// Which reader produced a [`SpectralData`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpectralFormat {
    /// `wavelength_nm` / `wavelength_um` plus `T`, `R` (= `Rf`), `Rb` columns, and instrument
    /// exports (title lines, `Wavelength (nm)`, `%T`, `;` or tab separators, decimal commas).
    Csv,
    /// LBNL Optics5 / IGDB text (`.DAT`, `.LOF`, `.afg`, `.oag`, …).
    Optics,
    /// The JSON igsdb.lbl.gov returns for one product (schema v1 `spectral_data`, and v2
    /// `physical_properties.optical_properties.optical_data.angle_blocks`).
    IgsdbJson,
}

/// Product metadata found in the file (all optional: our CSV carries none).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProductInfo {
    /// The product's name.
    pub name: Option<String>,
    /// Its maker.
    pub manufacturer: Option<String>,
    /// Optics `{ Type: … }` or IGSDB `subtype` (falling back to `type` in the older schema), as written.
    pub product_type: Option<String>,
    /// `Front`, `Back`, `Neither`, `Both`, as written.
    pub coated_side: Option<String>,
    /// Its thickness.
    pub thickness_mm: Option<f64>,
    /// Incidence angles (degrees) other than 0° for which the file also holds spectra (IGSDB v2
    /// angle blocks), in file order. Only the 0° spectrum is read; empty for other formats.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub other_incidence_angles_deg: Vec<f64>,
    /// The parts an IGSDB product lists in its `composition` (a laminate's plies and
    /// interlayer), each as "name (subtype, thickness mm)"; empty for other formats.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub composition: Vec<String>,
    /// The reader that read it.
    pub format: SpectralFormat,
}

impl ProductInfo {
    pub(crate) fn empty(format: SpectralFormat) -> Self {
        ProductInfo {
            name: None,
            manufacturer: None,
            product_type: None,
            coated_side: None,
            thickness_mm: None,
            other_incidence_angles_deg: Vec::new(),
            composition: Vec::new(),
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
    /// The file name (or the name given to [`crate::read_spectral_bytes`]), for messages.
    pub source: String,
    /// Wavelengths, nm, strictly increasing.
    pub wavelength_nm: Vec<f64>,
    /// Spectral transmittance τ(λ).
    pub transmittance: Option<Vec<f64>>,
    /// Spectral reflectance ρ(λ) of the front side (CSV `R` or `Rf`).
    pub reflectance_front: Option<Vec<f64>>,
    /// Spectral reflectance of the back side (CSV `Rb`).
    pub reflectance_back: Option<Vec<f64>>,
    /// The product, as far as the file says.
    pub product: ProductInfo,
}

/// Reader options.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// Values are in percent (0–100) rather than fractions. Applies to CSV only: Optics and
    /// IGSDB files are always fractions. Giving it for a file whose values never exceed 1 is an
    /// error (the file looks like fractions). CSV columns whose header says percent (`%T`,
    /// `T (%)`) are percent without it.
    pub percent: bool,
}

/// Where a value came from, for messages.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Place {
    pub(crate) line: usize,
    pub(crate) column: Option<usize>,
}

/// Rows collected by a reader before the common checks.
pub(crate) struct Collected<'a> {
    pub(crate) source: &'a str,
    pub(crate) wavelength_nm: Vec<f64>,
    pub(crate) wavelength_places: Vec<Place>,
    /// T, Rf, Rb; each with the place of every value.
    pub(crate) quantities: [Option<(Vec<f64>, Vec<Place>)>; 3],
}

pub(crate) const QUANTITY_NAMES: [&str; 3] = ["T", "Rf", "Rb"];

/// Converts µm to nm and snaps to 1e-6 nm, so that `0.305 µm` becomes exactly `305 nm` and
/// uniformly spaced files stay uniformly spaced (colour-science decides Sprague vs. spline by
/// exact equality of the steps). The Python oracle does the same (`np.round(um * 1000, 6)`).
pub fn microns_to_nm(um: f64) -> f64 {
    (um * 1000.0 * 1e6).round_ties_even() / 1e6
}

pub(crate) fn parse_number(
    text: &str,
    source: &str,
    place: Place,
    what: &str,
) -> Result<f64, SpectralError> {
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
            format!("{what} {} is not a number", glassdb_io::backticked(t)),
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
    /// `percent[k]`: quantity k is in percent (scaled by 0.01); `check_fractions`: refuse a file
    /// none of whose values exceeds 1 (percent was asked for, but the file looks like fractions).
    pub(crate) fn finish(
        self,
        percent: [bool; 3],
        check_fractions: bool,
        product: ProductInfo,
    ) -> Result<SpectralData, SpectralError> {
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
        let mut any_above_one = false;
        let mut out: [Option<Vec<f64>>; 3] = [None, None, None];
        for (k, q) in self.quantities.into_iter().enumerate() {
            let Some((values, places)) = q else { continue };
            let name = QUANTITY_NAMES[k];
            let percent = percent[k];
            let scale = if percent { 0.01 } else { 1.0 };
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
        if check_fractions && !any_above_one {
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
// LBNL Optics / IGDB text
// ---------------------------------------------------------------------------------------------

/// Decodes Windows-1252 (the Optics files' ™ is byte 0x99), which is a superset of ASCII.
pub(crate) fn decode_cp1252(bytes: &[u8]) -> String {
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

pub(crate) fn read_optics(bytes: &[u8], source: &str) -> Result<SpectralData, SpectralError> {
    let mut product = ProductInfo::empty(SpectralFormat::Optics);
    let mut unit: Option<WavelengthUnit> = None;
    let mut raw_wl: Vec<f64> = Vec::new();
    let mut places: Vec<Place> = Vec::new();
    let mut values: [Vec<f64>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    let mut value_places: [Vec<Place>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    // Numbers per data row (4, or 9 with diffuse columns); every row has the same.
    let mut row_width: Option<usize> = None;
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
        // 9 numbers: λ, then direct and diffuse Tf, Tb, Rf, Rb (the Optics layout for scattering
        // layers). Read only when every diffuse value is 0, i.e. the data are specular.
        let columns: [usize; 3] = match fields.len() {
            4 => [1, 2, 3],
            9 => [1, 5, 7],
            n => {
                return Err(SpectralError::parse(
                    source,
                    line_no,
                    None,
                    format!("expected 4 numbers `wavelength T Rf Rb`, found {n} fields"),
                ));
            }
        };
        match row_width {
            Some(w) if w != fields.len() => {
                return Err(SpectralError::parse(
                    source,
                    line_no,
                    None,
                    format!("{} numbers where the rows above have {w}", fields.len()),
                ));
            }
            _ => row_width = Some(fields.len()),
        }
        let place = |column: usize| Place {
            line: line_no,
            column: Some(column + 1),
        };
        let wl = parse_number(fields[0], source, place(0), "wavelength")?;
        raw_wl.push(wl);
        places.push(place(0));
        for k in 0..3 {
            let c = columns[k];
            values[k].push(parse_number(
                fields[c],
                source,
                place(c),
                QUANTITY_NAMES[k],
            )?);
            value_places[k].push(place(c));
        }
        if fields.len() == 9 {
            for c in [2, 4, 6, 8] {
                if parse_number(fields[c], source, place(c), "diffuse value")? != 0.0 {
                    return Err(SpectralError::Unsupported {
                        source_name: source.to_owned(),
                        kind: UnsupportedKind::DiffuseOptics { line: line_no },
                    });
                }
            }
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
    .finish([false; 3], false, product)
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
                        "unknown wavelength units {} (expected `SI Microns` or `SI Nanometers`)",
                        glassdb_io::backticked(value)
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
