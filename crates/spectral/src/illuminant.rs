//! The light a glass is seen under: a bundled CIE illuminant ([`CieIlluminant`]: the D series,
//! A, E, FL1–FL12 and the CIE 15:2018 LED series, `data/illuminants/`) or a spectral power
//! distribution read from a CSV file ([`Spd`]), and the white a camera is balanced to
//! ([`WhiteBalance`]), where the chromatic adaptation to a space's white starts.
//!
//! Every light is interpolated **linearly** between its samples and held at its end values
//! outside them, as colour-science 0.4.7 does with its own illuminant datasets (its
//! `LinearInterpolator` and constant extrapolation).

use std::fmt;
use std::hash::{Hash, Hasher};
use std::path::Path;
use std::sync::Arc;

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sha2::{Digest, Sha256};

use crate::error::SpectralError;
use crate::integrate::Observer;
use crate::read::{Place, parse_number};
use crate::tables::{linear_at, tables};

/// A CIE illuminant bundled with glassdb (`data/illuminants/`, exported bit for bit from
/// colour-science 0.4.7's `SDS_ILLUMINANTS`; its white from `CCS_ILLUMINANTS`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CieIlluminant {
    /// CIE D50, daylight of about 5000 K (CIE 15:2004; CCTs here are from each white, Ohno 2013).
    D50,
    /// CIE D55, daylight of about 5500 K.
    D55,
    /// CIE D65, daylight of about 6500 K: the default.
    D65,
    /// CIE D75, daylight of about 7500 K.
    D75,
    /// CIE standard illuminant A: incandescent (tungsten) light, Planck's law at 2856 K.
    A,
    /// The equal-energy illuminant E.
    E,
    /// FL1, daylight fluorescent, 6430 K (CIE 15:2004's F1–F12, named FL1–FL12 since CIE
    /// 15:2018).
    Fl1,
    /// FL2, cool white fluorescent, 4220 K.
    Fl2,
    /// FL3, white fluorescent, 3450 K.
    Fl3,
    /// FL4, warm white fluorescent, 2940 K.
    Fl4,
    /// FL5, daylight fluorescent, 6340 K.
    Fl5,
    /// FL6, lite white fluorescent, 4150 K.
    Fl6,
    /// FL7, broadband fluorescent simulating D65, 6490 K.
    Fl7,
    /// FL8, broadband fluorescent simulating D50, 5000 K.
    Fl8,
    /// FL9, broadband cool white deluxe fluorescent, 4150 K.
    Fl9,
    /// FL10, three-band fluorescent, 5000 K.
    Fl10,
    /// FL11, three-band fluorescent, 4000 K.
    Fl11,
    /// FL12, three-band fluorescent, 3000 K.
    Fl12,
    /// LED-B1, phosphor-converted blue LED, 2730 K (the CIE 15:2018 LED series).
    LedB1,
    /// LED-B2, phosphor-converted blue LED, 3000 K.
    LedB2,
    /// LED-B3, phosphor-converted blue LED, 4100 K.
    LedB3,
    /// LED-B4, phosphor-converted blue LED, 5110 K.
    LedB4,
    /// LED-B5, phosphor-converted blue LED, 6600 K.
    LedB5,
    /// LED-BH1, hybrid of a phosphor-converted blue LED and a red LED, 2850 K.
    LedBh1,
    /// LED-RGB1, mixed red, green and blue LEDs, 2840 K.
    LedRgb1,
    /// LED-V1, phosphor-converted violet LED, 2720 K.
    LedV1,
    /// LED-V2, phosphor-converted violet LED, 4070 K.
    LedV2,
}

names!(CieIlluminant {
    D50 => "D50", D55 => "D55", D65 => "D65", D75 => "D75", A => "A", E => "E",
    Fl1 => "FL1" | "F1", Fl2 => "FL2" | "F2", Fl3 => "FL3" | "F3", Fl4 => "FL4" | "F4",
    Fl5 => "FL5" | "F5", Fl6 => "FL6" | "F6", Fl7 => "FL7" | "F7", Fl8 => "FL8" | "F8",
    Fl9 => "FL9" | "F9", Fl10 => "FL10" | "F10", Fl11 => "FL11" | "F11", Fl12 => "FL12" | "F12",
    LedB1 => "LED-B1", LedB2 => "LED-B2", LedB3 => "LED-B3", LedB4 => "LED-B4",
    LedB5 => "LED-B5", LedBh1 => "LED-BH1", LedRgb1 => "LED-RGB1", LedV1 => "LED-V1",
    LedV2 => "LED-V2",
});

impl CieIlluminant {
    /// Its position in [`CieIlluminant::ALL`] (the order of the bundled tables).
    pub(crate) fn index(self) -> usize {
        Self::ALL.iter().position(|&i| i == self).unwrap_or(0)
    }

    /// The illuminant's white as CIE xy for `observer`, as colour's `CCS_ILLUMINANTS` holds it
    /// (`data/illuminants/whites.csv`): the CIE's published values (four or five decimals) for
    /// the D series, A, E and FL, colour's 15-decimal computation for the LED series.
    pub fn white_xy(self, observer: Observer) -> Result<[f64; 2], SpectralError> {
        Ok(tables()?.whites[self.index()][observer as usize])
    }

    /// Its relative spectral power on `grid_nm` (linear between the 5 nm samples, end values
    /// held outside them).
    pub fn power_on(self, grid_nm: &[f64]) -> Result<Vec<f64>, SpectralError> {
        let table = &tables()?.illuminants[self.index()];
        let (x, y) = (&table.wavelength_nm, &table.columns[0]);
        Ok(grid_nm.iter().map(|&w| linear_at(x, y, w)).collect())
    }
}

serde_as_name!(CieIlluminant);

/// The wavelengths (nm) every light must overlap: those of the colorimetric method (the CIE
/// colour-matching functions as colour-science uses them, 360–780 nm).
pub const LIGHT_RANGE_NM: (f64, f64) = (360.0, 780.0);

/// The most samples an SPD may hold (a 1 nm table from 0 to 100 µm is far less).
pub const MAX_SPD_SAMPLES: usize = 100_000;

/// A light's spectral power distribution, from a file: `wavelength_nm,power` samples, strictly
/// increasing, finite and non-negative, overlapping 360–780 nm with some power there
/// ([`Spd::new`] checks it). The file's name and the SHA-256 of its bytes are kept, so that a
/// registry that records the SPD says where it came from and holds the samples themselves.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Spd {
    /// The file the samples were read from, as it was named (or any label of their source).
    pub file: String,
    /// The SHA-256 of the file's bytes (hex).
    pub sha256: String,
    /// The samples' wavelengths (nm), strictly increasing.
    wavelength_nm: Vec<f64>,
    /// The relative power at each wavelength (any unit: only ratios matter).
    power: Vec<f64>,
}

/// The JSON form of an [`Spd`], checked by [`Spd::new`] when read.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SpdJson {
    file: String,
    sha256: String,
    wavelength_nm: Vec<f64>,
    power: Vec<f64>,
}

impl<'de> Deserialize<'de> for Spd {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let j = SpdJson::deserialize(d)?;
        Spd::new(j.file, j.sha256, j.wavelength_nm, j.power).map_err(serde::de::Error::custom)
    }
}

/// Validated samples are finite, so equality is total.
impl Eq for Spd {}

impl Hash for Spd {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.file.hash(state);
        self.sha256.hash(state);
        for v in self.wavelength_nm.iter().chain(&self.power) {
            v.to_bits().hash(state);
        }
    }
}

impl Spd {
    /// Checks and keeps the samples of a light: at least 2 and at most [`MAX_SPD_SAMPLES`],
    /// as many powers as wavelengths, wavelengths finite and strictly increasing, powers finite
    /// and non-negative, the range overlapping [`LIGHT_RANGE_NM`] with some power inside it.
    /// Errors name `file` and the index of the first bad sample.
    pub fn new(
        file: String,
        sha256: String,
        wavelength_nm: Vec<f64>,
        power: Vec<f64>,
    ) -> Result<Spd, SpectralError> {
        let bad = |message: String| SpectralError::format(&file, message);
        if wavelength_nm.len() != power.len() {
            return Err(bad(format!(
                "{} wavelengths but {} powers",
                wavelength_nm.len(),
                power.len()
            )));
        }
        if wavelength_nm.len() < 2 || wavelength_nm.len() > MAX_SPD_SAMPLES {
            return Err(bad(format!(
                "{} samples: a light needs 2 to {MAX_SPD_SAMPLES}",
                wavelength_nm.len()
            )));
        }
        for (i, (&w, &p)) in wavelength_nm.iter().zip(&power).enumerate() {
            if !w.is_finite() || !p.is_finite() {
                return Err(bad(format!("sample {}: not a finite number", i + 1)));
            }
            if p < 0.0 {
                return Err(bad(format!(
                    "sample {} ({w} nm): power {p} is negative",
                    i + 1
                )));
            }
            if i > 0 && w <= wavelength_nm[i - 1] {
                return Err(bad(format!(
                    "sample {}: {w} nm follows {} nm: wavelengths must increase",
                    i + 1,
                    wavelength_nm[i - 1]
                )));
            }
        }
        let spd = Spd {
            file,
            sha256,
            wavelength_nm,
            power,
        };
        spd.check_range()?;
        Ok(spd)
    }

    /// The range overlaps [`LIGHT_RANGE_NM`], and some power falls inside it.
    fn check_range(&self) -> Result<(), SpectralError> {
        let (lo, hi) = LIGHT_RANGE_NM;
        let (first, last) = (
            self.wavelength_nm[0],
            self.wavelength_nm[self.power.len() - 1],
        );
        if !(first < hi && last > lo) {
            return Err(SpectralError::format(
                &self.file,
                format!(
                    "the light covers {first}–{last} nm, which does not overlap the colour-matching functions' {lo}–{hi} nm"
                ),
            ));
        }
        let grid: Vec<f64> = (360..=780).map(f64::from).collect();
        if self.power_on(&grid).iter().all(|&p| p == 0.0) {
            return Err(SpectralError::format(
                &self.file,
                format!("the light has no power in {lo}–{hi} nm"),
            ));
        }
        Ok(())
    }

    /// The samples' wavelengths (nm).
    pub fn wavelength_nm(&self) -> &[f64] {
        &self.wavelength_nm
    }

    /// The samples' relative powers.
    pub fn power(&self) -> &[f64] {
        &self.power
    }

    /// The power on `grid_nm`: linear between samples, end values held outside them.
    pub fn power_on(&self, grid_nm: &[f64]) -> Vec<f64> {
        grid_nm
            .iter()
            .map(|&w| linear_at(&self.wavelength_nm, &self.power, w))
            .collect()
    }
}

/// Reads a light's SPD from a CSV file: a header `wavelength_nm,power`, then one sample per
/// line (`#` starts a comment line; blank lines are skipped). Errors name the file and line.
pub fn read_spd_file(path: &Path) -> Result<Spd, SpectralError> {
    let bytes =
        glassdb_io::read_input(path, crate::SPECTRAL_FILE).map_err(|source| SpectralError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    read_spd_bytes(&bytes, &path.display().to_string())
}

/// Reads a light's SPD from CSV bytes ([`read_spd_file`]); `source_name` names it in errors
/// and in the [`Spd`].
pub fn read_spd_bytes(bytes: &[u8], source_name: &str) -> Result<Spd, SpectralError> {
    let sha256: String = Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(bytes);
    let csv_error = |e: csv::Error| SpectralError::Csv {
        source_name: source_name.to_owned(),
        line: e.position().map_or(1, |p| p.line() as usize),
        source: e,
    };
    let headers = reader.headers().map_err(csv_error)?.clone();
    let header_line = headers.position().map_or(1, |p| p.line() as usize);
    let names: Vec<String> = headers.iter().map(str::to_ascii_lowercase).collect();
    if names != ["wavelength_nm", "power"] {
        return Err(SpectralError::parse(
            source_name,
            header_line,
            None,
            format!(
                "the header is `{}`; a light's CSV has the header `wavelength_nm,power`",
                headers.iter().collect::<Vec<_>>().join(",")
            ),
        ));
    }
    let (mut wavelength_nm, mut power, mut lines) = (Vec::new(), Vec::new(), Vec::new());
    for record in reader.records() {
        let record = record.map_err(csv_error)?;
        let line = record.position().map_or(0, |p| p.line() as usize);
        if record.len() != 2 {
            return Err(SpectralError::parse(
                source_name,
                line,
                None,
                format!("{} fields; expected 2 (wavelength_nm,power)", record.len()),
            ));
        }
        if wavelength_nm.len() == MAX_SPD_SAMPLES {
            return Err(SpectralError::parse(
                source_name,
                line,
                None,
                format!("more than {MAX_SPD_SAMPLES} samples"),
            ));
        }
        let at = |column| Place {
            line,
            column: Some(column),
        };
        let w = parse_number(&record[0], source_name, at(1), "wavelength")?;
        let p = parse_number(&record[1], source_name, at(2), "power")?;
        if p < 0.0 {
            let message = format!("power {p} at {w} nm is negative");
            return Err(SpectralError::parse(source_name, line, Some(2), message));
        }
        if let Some(&previous) = wavelength_nm.last()
            && w <= previous
        {
            let message = format!(
                "{w} nm follows {previous} nm (line {}): wavelengths must increase",
                lines.last().copied().unwrap_or(0)
            );
            return Err(SpectralError::parse(source_name, line, Some(1), message));
        }
        wavelength_nm.push(w);
        power.push(p);
        lines.push(line);
    }
    Spd::new(source_name.to_owned(), sha256, wavelength_nm, power)
}

/// The light a glass is integrated under (method.md "Colour", eqs. 15–20): a bundled CIE
/// illuminant or an SPD from a file. JSON: a CIE illuminant is its name (`"D65"`), an SPD the
/// object `{"file", "sha256", "wavelength_nm", "power"}`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Illuminant {
    /// A bundled CIE illuminant.
    Cie(CieIlluminant),
    /// An SPD read from a file.
    Spd(Arc<Spd>),
}

impl Default for Illuminant {
    /// CIE D65.
    fn default() -> Self {
        Illuminant::Cie(CieIlluminant::D65)
    }
}

impl From<CieIlluminant> for Illuminant {
    fn from(c: CieIlluminant) -> Self {
        Illuminant::Cie(c)
    }
}

impl Illuminant {
    /// A CIE illuminant's name (any case; `F2` for `FL2`), else the path of an SPD CSV file,
    /// read now. An argument that is neither is an error that lists the names.
    pub fn from_name_or_file(text: &str) -> Result<Illuminant, SpectralError> {
        if let Ok(cie) = text.trim().parse::<CieIlluminant>() {
            return Ok(Illuminant::Cie(cie));
        }
        let path = Path::new(text);
        if !path.exists() {
            let names: Vec<&str> = CieIlluminant::ALL.iter().map(|i| i.name()).collect();
            return Err(SpectralError::format(
                text,
                format!(
                    "neither a bundled illuminant ({}) nor an SPD file (wavelength_nm,power CSV)",
                    names.join(", ")
                ),
            ));
        }
        Ok(Illuminant::Spd(Arc::new(read_spd_file(path)?)))
    }

    /// The CIE illuminant's name, or the SPD's file.
    pub fn name(&self) -> &str {
        match self {
            Illuminant::Cie(c) => c.name(),
            Illuminant::Spd(s) => &s.file,
        }
    }

    /// The light's white in CIE xy for `observer`: a CIE illuminant's tabulated white
    /// ([`CieIlluminant::white_xy`]); an SPD's computed one, `x = X/(X+Y+Z)`, `y = Y/(X+Y+Z)`
    /// of `XYZ = Σ S(λ)·(x̄, ȳ, z̄)(λ)` over 360–780 nm at 1 nm (colour-science's
    /// `XYZ_to_xy(sd_to_XYZ(…))` of a perfect reflector under the light).
    pub fn white_xy(&self, observer: Observer) -> Result<[f64; 2], SpectralError> {
        match self {
            Illuminant::Cie(c) => c.white_xy(observer),
            Illuminant::Spd(_) => {
                let grid: Vec<f64> = (360..=780).map(f64::from).collect();
                let xyz = crate::integrate::xyz_weights_of(observer, self, &grid)?
                    .iter()
                    .fold([0.0; 3], |a, w| [a[0] + w[0], a[1] + w[1], a[2] + w[2]]);
                Ok(xy_of(xyz))
            }
        }
    }

    /// The light's relative power on `grid_nm` (linear between its samples, end values held).
    pub fn power_on(&self, grid_nm: &[f64]) -> Result<Vec<f64>, SpectralError> {
        match self {
            Illuminant::Cie(c) => c.power_on(grid_nm),
            Illuminant::Spd(s) => Ok(s.power_on(grid_nm)),
        }
    }
}

/// CIE xy of an XYZ triple.
pub(crate) fn xy_of(xyz: [f64; 3]) -> [f64; 2] {
    let sum = xyz[0] + xyz[1] + xyz[2];
    [xyz[0] / sum, xyz[1] / sum]
}

impl fmt::Display for Illuminant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for Illuminant {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Illuminant::Cie(c) => c.serialize(s),
            Illuminant::Spd(spd) => spd.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Illuminant {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        // A name or an SPD object, decided by the JSON type (so that each form's own error
        // reaches the user).
        let value = serde_json::Value::deserialize(d)?;
        match value {
            serde_json::Value::String(name) => name
                .parse::<CieIlluminant>()
                .map(Illuminant::Cie)
                .map_err(serde::de::Error::custom),
            other => Spd::deserialize(other)
                .map(|spd| Illuminant::Spd(Arc::new(spd)))
                .map_err(serde::de::Error::custom),
        }
    }
}

/// The white a camera (a renderer) is balanced to: the chromatic adaptation (CAT02) to the
/// colour space's white starts from it. JSON and command line: `light` or a CIE illuminant's
/// name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum WhiteBalance {
    /// Balanced to the light itself, which renders white: CAT02 from the light's white to the
    /// space's, as colour-science's `XYZ_to_RGB(…, illuminant=<the light's white>)` does.
    #[default]
    Light,
    /// Balanced to a fixed CIE illuminant's white (a renderer's camera balanced to D65, where
    /// a tungsten lamp renders orange): CAT02 from that white to the space's.
    Fixed(CieIlluminant),
}

impl WhiteBalance {
    /// `light`, or the illuminant's name.
    pub fn name(self) -> &'static str {
        match self {
            WhiteBalance::Light => "light",
            WhiteBalance::Fixed(c) => c.name(),
        }
    }

    /// The white the adaptation starts from, for a light `illuminant` seen by `observer`.
    pub fn white_xy(
        self,
        illuminant: &Illuminant,
        observer: Observer,
    ) -> Result<[f64; 2], SpectralError> {
        match self {
            WhiteBalance::Light => illuminant.white_xy(observer),
            WhiteBalance::Fixed(c) => c.white_xy(observer),
        }
    }
}

impl fmt::Display for WhiteBalance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for WhiteBalance {
    type Err = String;
    /// `light`, or a CIE illuminant's name (any case).
    fn from_str(s: &str) -> Result<Self, String> {
        if s.trim().eq_ignore_ascii_case("light") {
            return Ok(WhiteBalance::Light);
        }
        s.trim()
            .parse::<CieIlluminant>()
            .map(WhiteBalance::Fixed)
            .map_err(|e| format!("{e}, or light"))
    }
}

serde_as_name!(WhiteBalance);

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Spd, SpectralError> {
        read_spd_bytes(text.as_bytes(), "lamp.csv")
    }

    fn message(text: &str) -> String {
        read(text).unwrap_err().to_string()
    }

    #[test]
    fn an_spd_csv_reads_with_comments_and_is_linear_between_samples() {
        let spd = read("# a lamp\nwavelength_nm,power\n350,0\n\n400,2\n# middle\n700,4\n800,0\n")
            .unwrap();
        assert_eq!(spd.wavelength_nm(), [350.0, 400.0, 700.0, 800.0]);
        assert_eq!(
            spd.power_on(&[300.0, 375.0, 550.0, 850.0]),
            [0.0, 1.0, 3.0, 0.0]
        );
        assert_eq!(spd.file, "lamp.csv");
        assert_eq!(spd.sha256.len(), 64);
        // Header case and spaces do not matter.
        assert!(read(" Wavelength_nm , POWER \n400,1\n700,1\n").is_ok());
    }

    #[test]
    fn bad_spd_files_name_the_file_and_line() {
        let cases = [
            (
                "wavelength_nm,T\n400,1\n",
                "lamp.csv:1: the header is `wavelength_nm,T`",
            ),
            (
                "wavelength_nm,power\n400,1\n390,1\n",
                "lamp.csv:3:1: 390 nm follows 400 nm (line 2)",
            ),
            (
                "wavelength_nm,power\n400,1\n400,1\n",
                "lamp.csv:3:1: 400 nm follows 400 nm",
            ),
            (
                "wavelength_nm,power\n400,1\n500,NaN\n",
                "lamp.csv:3:2: power is NaN: not a finite",
            ),
            (
                "wavelength_nm,power\n400,1\n500,-0.5\n",
                "lamp.csv:3:2: power -0.5 at 500 nm is negative",
            ),
            (
                "wavelength_nm,power\n400,1\n500,x\n",
                "lamp.csv:3:2: power `x` is not a number",
            ),
            (
                "wavelength_nm,power\n400,1,2\n500,1\n",
                "lamp.csv:2: 3 fields; expected 2",
            ),
            (
                "wavelength_nm,power\n400,1\n",
                "lamp.csv: 1 samples: a light needs 2",
            ),
            (
                "wavelength_nm,power\n800,1\n900,1\n",
                "does not overlap the colour-matching functions' 360–780 nm",
            ),
            (
                "wavelength_nm,power\n400,0\n700,0\n",
                "lamp.csv: the light has no power in 360–780 nm",
            ),
        ];
        for (text, want) in cases {
            let got = message(text);
            assert!(got.contains(want), "{text:?}: {got}");
        }
    }

    #[test]
    fn illuminants_by_name_or_file_and_their_json() {
        assert_eq!(
            Illuminant::from_name_or_file("led-b3").unwrap(),
            Illuminant::Cie(CieIlluminant::LedB3)
        );
        let e = Illuminant::from_name_or_file("no-such-lamp.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("no-such-lamp.csv: neither") && e.contains("LED-B3"),
            "{e}"
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("lamp.csv");
        std::fs::write(&path, "wavelength_nm,power\n380,1\n780,2\n").unwrap();
        let lamp = Illuminant::from_name_or_file(path.to_str().unwrap()).unwrap();
        assert_eq!(lamp.name(), path.to_str().unwrap());
        // JSON: a name, or the samples with their file and hash; both read back.
        let name = serde_json::to_string(&Illuminant::Cie(CieIlluminant::Fl11)).unwrap();
        assert_eq!(name, "\"FL11\"");
        let text = serde_json::to_string(&lamp).unwrap();
        assert!(text.contains("\"wavelength_nm\":[380.0,780.0]"), "{text}");
        assert_eq!(serde_json::from_str::<Illuminant>(&text).unwrap(), lamp);
        // A tampered SPD in JSON is refused with the reason.
        let bad = text.replace("[1.0,2.0]", "[1.0,-2.0]");
        let e = serde_json::from_str::<Illuminant>(&bad)
            .unwrap_err()
            .to_string();
        assert!(e.contains("negative"), "{e}");
        assert!(serde_json::from_str::<Illuminant>("\"F99\"").is_err());
    }

    #[test]
    fn an_spd_white_is_its_integrated_chromaticity() {
        // An SPD equal to the bundled A table has A's white to the tabulated 4-5 decimals.
        let t = tables().unwrap();
        let a = &t.illuminants[CieIlluminant::A.index()];
        let spd = Spd::new(
            "a.csv".into(),
            String::new(),
            a.wavelength_nm.clone(),
            a.columns[0].clone(),
        )
        .unwrap();
        for &observer in Observer::ALL {
            let ours = Illuminant::Spd(Arc::new(spd.clone()))
                .white_xy(observer)
                .unwrap();
            let table = CieIlluminant::A.white_xy(observer).unwrap();
            assert!((ours[0] - table[0]).abs() < 1e-4 && (ours[1] - table[1]).abs() < 1e-4);
        }
        assert_eq!(
            "light".parse::<WhiteBalance>().unwrap(),
            WhiteBalance::Light
        );
        assert_eq!(
            "d65".parse::<WhiteBalance>().unwrap(),
            WhiteBalance::Fixed(CieIlluminant::D65)
        );
        assert!("sunset".parse::<WhiteBalance>().is_err());
    }
}
