//! The one error type of the crate: one variant per failure a user can act on.

use std::fmt;
use std::path::PathBuf;

/// Everything that can go wrong reading or integrating spectral data.
///
/// Reader errors name the source (file name) and the 1-based line (and, for CSV, the 1-based
/// column); integration errors describe the spectrum and say what would make it acceptable.
#[derive(Debug, thiserror::Error)]
pub enum SpectralError {
    /// The file could not be read: missing, not a regular file, or over
    /// [`crate::SPECTRAL_FILE`].
    #[error("{path}: cannot read")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why it could not be read.
        #[source]
        source: glassdb_io::InputError,
    },

    /// A syntax or content error at a known place in the file.
    #[error("{source_name}:{line}{}: {message}", column.map(|c| format!(":{c}")).unwrap_or_default())]
    Parse {
        /// The file or source.
        source_name: String,
        /// 1-based line number.
        line: usize,
        /// 1-based column (CSV field index) when known.
        column: Option<usize>,
        /// What is wrong.
        message: String,
    },

    /// The CSV reader failed (an I/O error, broken quoting); its error is the source.
    #[error("{source_name}:{line}: not readable as CSV")]
    Csv {
        /// The file or source.
        source_name: String,
        /// The 1-based line.
        line: usize,
        /// The CSV reader's error.
        source: csv::Error,
    },

    /// A value above 1 in a file read as fractions: the file is probably in percent
    /// ([`crate::ReadOptions::percent`]).
    #[error(
        "{source_name}:{line}{}: {name} = {value} is above 1; the file may be in percent", column.map(|c| format!(":{c}")).unwrap_or_default()
    )]
    AboveOneInFractions {
        /// The file or source.
        source_name: String,
        /// The 1-based line.
        line: usize,
        /// The 1-based column, where known.
        column: Option<usize>,
        /// The quantity.
        name: String,
        /// The value.
        value: f64,
    },

    /// Read as percent, but no value exceeds 1: the file looks like fractions.
    #[error(
        "{source_name}: read as percent, but no value exceeds 1: the file looks like fractions"
    )]
    FractionsReadAsPercent {
        /// The file or source.
        source_name: String,
    },

    /// The file is a kind of optical data glassdb does not read (a shading product, a BSDF, diffuse
    /// data, a binary file); [`UnsupportedKind`] names it.
    #[error("{source_name}: {kind}")]
    Unsupported {
        /// The file or source.
        source_name: String,
        /// What it is.
        kind: UnsupportedKind,
    },

    /// The file as a whole is unusable (no data rows, unknown format, no quantity columns).
    #[error("{source_name}: {message}")]
    Format {
        /// The file or source.
        source_name: String,
        /// What is wrong.
        message: String,
    },

    /// Wavelength and value arrays passed to an integrator differ in length.
    #[error("{wavelengths} wavelengths but {values} values")]
    LengthMismatch {
        /// Wavelengths given.
        wavelengths: usize,
        /// Values given.
        values: usize,
    },

    /// A wavelength or value handed to an integrator is NaN or infinite.
    #[error("non-finite {what} at index {index}")]
    NonFinite {
        /// Which array.
        what: &'static str,
        /// The position of the value.
        index: usize,
    },

    /// Wavelengths handed to an integrator are not strictly increasing.
    #[error(
        "wavelengths must be strictly increasing: {previous_nm} nm is followed by {next_nm} nm at index {index}"
    )]
    NotIncreasing {
        /// The position where they stop increasing.
        index: usize,
        /// The wavelength before it, nm.
        previous_nm: f64,
        /// The wavelength at it, nm.
        next_nm: f64,
    },

    /// Too few samples for the interpolator colour-science would use on this spacing.
    #[error(
        "{points} samples: {interpolator} interpolation needs at least {needed} (uniformly spaced data use Sprague, which needs 6; irregular spacing uses a cubic spline, which needs 4)"
    )]
    TooFewPoints {
        /// Points given.
        points: usize,
        /// Points needed.
        needed: usize,
        /// The interpolation that needs them.
        interpolator: &'static str,
    },

    /// The spectrum does not cover the wavelength range the chosen method integrates over.
    #[error(
        "the spectrum covers {have_start_nm}–{have_end_nm} nm but {method} integrates over {need_start_nm}–{need_end_nm} nm (IntegrationSettings::extrapolate holds the end values constant outside the data)"
    )]
    PartialCoverage {
        /// The method.
        method: String,
        /// The data's first wavelength, nm.
        have_start_nm: f64,
        /// The data's last wavelength, nm.
        have_end_nm: f64,
        /// The first wavelength the method needs, nm.
        need_start_nm: f64,
        /// The last wavelength the method needs, nm.
        need_end_nm: f64,
    },

    /// The spectrum does not cover the range a WINDOW average needs (WINDOW refuses such a
    /// layer too).
    #[error(
        "the spectrum covers {have_start_nm}–{have_end_nm} nm but WINDOW's {method} average needs {need_start_nm}–{need_end_nm} nm"
    )]
    WindowCoverage {
        /// The WINDOW average asked for (solar, visible, …).
        method: &'static str,
        /// The first wavelength the spectrum has, nm.
        have_start_nm: f64,
        /// The last wavelength the spectrum has, nm.
        have_end_nm: f64,
        /// The first wavelength the average needs, nm.
        need_start_nm: f64,
        /// The last wavelength the average needs, nm.
        need_end_nm: f64,
    },

    /// The spectrum does not overlap the integration range at all.
    #[error(
        "the spectrum ({have_start_nm}–{have_end_nm} nm) does not overlap {need_start_nm}–{need_end_nm} nm at all"
    )]
    NoOverlap {
        /// The data's first wavelength, nm.
        have_start_nm: f64,
        /// The data's last wavelength, nm.
        have_end_nm: f64,
        /// The first wavelength the method needs, nm.
        need_start_nm: f64,
        /// The last wavelength the method needs, nm.
        need_end_nm: f64,
    },

    /// More light leaves the glass than falls on it at one wavelength of the data.
    #[error("at {wavelength_nm} nm, T + R = {sum:.4} > 1: more light out than in")]
    SpectrumEnergy {
        /// The wavelength.
        wavelength_nm: f64,
        /// T + R there.
        sum: f64,
    },

    /// The integrated values of one channel transmit and reflect more than the light that
    /// falls on the glass (usually interpolation overshooting across sparse samples).
    #[error(
        "channel {channel}: integrated transmittance + {side} reflectance = {transmittance:.6} + {reflectance:.6} = {:.6} > 1 (energy is not conserved{})",
        transmittance + reflectance,
        largest_gap_nm.map(|(a, b)| format!("; largest gap between samples in 380–780 nm: {} nm, {a}–{b} nm", b - a)).unwrap_or_default()
    )]
    ChannelEnergy {
        /// `front` or `back`.
        side: &'static str,
        /// The channel.
        channel: &'static str,
        /// Its integrated transmittance.
        transmittance: f64,
        /// Its integrated reflectance.
        reflectance: f64,
        /// The data's largest gap between wavelengths, nm.
        largest_gap_nm: Option<(f64, f64)>,
    },

    /// The reference white of a method has a zero (or negative) channel, so no ratio exists.
    #[error(
        "illuminant {illuminant}: its {channel} channel in this colour space is {value}: no per-channel ratio exists (a light needs power in every channel)"
    )]
    DegenerateWhite {
        /// The light (its illuminant's name or SPD file).
        illuminant: String,
        /// The channel.
        channel: &'static str,
        /// Its white.
        value: f64,
    },

    /// An embedded reference table failed to parse (a build defect, reported rather than panicking).
    #[error("embedded table {table} is corrupt: {message}")]
    EmbeddedTable {
        /// The table.
        table: &'static str,
        /// What is wrong.
        message: String,
    },

    /// Reference data built once per process (tables, luminous weights) failed to build; the
    /// first failure, shared by every later call, is the source (a build defect).
    #[error("embedded {what} could not be built")]
    EmbeddedData {
        /// What failed to build.
        what: &'static str,
        /// The first failure.
        source: std::sync::Arc<SpectralError>,
    },
}

impl SpectralError {
    /// Shorthand for a [`SpectralError::Parse`] error.
    pub(crate) fn parse(
        source_name: &str,
        line: usize,
        column: Option<usize>,
        message: impl Into<String>,
    ) -> Self {
        SpectralError::Parse {
            source_name: source_name.to_owned(),
            line,
            column,
            message: message.into(),
        }
    }

    /// Shorthand for a [`SpectralError::Format`] error.
    pub(crate) fn format(source_name: &str, message: impl Into<String>) -> Self {
        SpectralError::Format {
            source_name: source_name.to_owned(),
            message: message.into(),
        }
    }
}

/// What an unsupported file is, as far as its content tells: [`SpectralError::Unsupported`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum UnsupportedKind {
    /// An IGSDB shading layer (venetian blind, woven shade, perforated screen, …). `subtype` and
    /// `name` as written in the file.
    ShadingProduct {
        /// The IGSDB subtype, as written.
        subtype: Option<String>,
        /// The product's name.
        name: Option<String>,
    },
    /// An IGSDB shade material (`"type": "material"`): the slat paint or fabric of a shading
    /// layer, not a glazing.
    ShadeMaterial {
        /// The material's name.
        name: Option<String>,
    },
    /// An IGSDB product whose optical data are not (only) specular: `is_specular` is false or
    /// its wavelength data carry non-zero `diffuse` values.
    DiffuseIgsdb {
        /// The product's name.
        name: Option<String>,
    },
    /// An LBNL Optics file whose rows hold 9 numbers (λ, then direct and diffuse Tf, Tb, Rf, Rb)
    /// with non-zero diffuse values; `line` is the first such row.
    DiffuseOptics {
        /// The first row with diffuse values.
        line: usize,
    },
    /// A BSDF XML file (WINDOW's `WindowElement`, angle-resolved scattering matrices).
    BsdfXml,
    /// Other markup (XML or HTML, e.g. a THERM `.thmx` or a saved web page); `root` is its first
    /// element's name.
    Markup {
        /// The first element's name.
        root: String,
    },
    /// Binary data; `what` names the container when its signature is known.
    Binary {
        /// The container, when its signature is known.
        what: Option<&'static str>,
    },
}

/// An IGSDB subtype as words: `VENETIAN_BLIND` / `venetian` → "venetian blind".
fn subtype_words(subtype: &str) -> String {
    let words = subtype.trim().replace(['_', '-'], " ").to_lowercase();
    match words.as_str() {
        "venetian" => "venetian blind".to_owned(),
        "woven" => "woven shade".to_owned(),
        "vertical" | "louver" | "vertical louvre" => "vertical louver".to_owned(),
        _ => words,
    }
}

/// `(a, "b")` from the present parts, or "" when none is.
fn parenthesised(parts: &[Option<String>]) -> String {
    let parts: Vec<&str> = parts.iter().flatten().map(String::as_str).collect();
    if parts.is_empty() {
        String::new()
    } else {
        format!(" ({})", parts.join(", "))
    }
}

impl fmt::Display for UnsupportedKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const GLAZING_ONLY: &str = "glassdb reads glazing (specular) products only";
        let quoted = |n: &Option<String>| n.as_ref().map(|n| format!("\"{n}\""));
        match self {
            UnsupportedKind::ShadingProduct { subtype, name } => write!(
                f,
                "is an IGSDB shading product{}; {GLAZING_ONLY}",
                parenthesised(&[subtype.as_deref().map(subtype_words), quoted(name)])
            ),
            UnsupportedKind::ShadeMaterial { name } => write!(
                f,
                "is an IGSDB shade material{}, the slat or fabric material of a shading layer; {GLAZING_ONLY}",
                parenthesised(&[quoted(name)])
            ),
            UnsupportedKind::DiffuseIgsdb { name } => write!(
                f,
                "is an IGSDB product{} with diffuse (scattering) optical data; glassdb reads specular spectral data only",
                parenthesised(&[quoted(name)])
            ),
            UnsupportedKind::DiffuseOptics { line } => write!(
                f,
                "is an Optics file with diffuse columns (9 numbers per row: λ, then direct and diffuse Tf, Tb, Rf, Rb; line {line} has non-zero diffuse values); glassdb reads specular data (λ T Rf Rb)"
            ),
            UnsupportedKind::BsdfXml => write!(
                f,
                "is a BSDF XML file (WINDOW's WindowElement: angle-resolved scattering matrices, not a spectrum); glassdb reads specular spectral data"
            ),
            UnsupportedKind::Markup { root } => write!(
                f,
                "is markup (XML or HTML, first element <{root}>), not spectral data"
            ),
            UnsupportedKind::Binary { what } => match what {
                Some(what) => write!(f, "is binary data ({what}), not a text spectral file"),
                None => write!(f, "is binary data, not a text spectral file"),
            },
        }
    }
}

impl SpectralError {
    /// The class of this error: a file that cannot be read is the reader's class; a kind of
    /// data glassdb does not read is unsupported; a corrupt embedded table is glassdb's bug;
    /// anything else is data (or an option) to fix.
    pub fn kind(&self) -> glassdb_io::ErrorKind {
        use glassdb_io::ErrorKind;
        match self {
            SpectralError::Io { source, .. } => source.kind(),
            SpectralError::Unsupported { .. } => ErrorKind::Unsupported,
            SpectralError::EmbeddedTable { .. } | SpectralError::EmbeddedData { .. } => {
                ErrorKind::Internal
            }
            _ => ErrorKind::Invalid,
        }
    }
}
