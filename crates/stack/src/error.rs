//! The one error type of the stack engine. Errors about one element of a build-up carry its
//! 1-based position among the elements (layers and gaps, outside first) and its label, so that
//! a catalog can name its line and a command line its argument.

/// Everything that can go wrong assembling or evaluating a stack.
#[derive(Debug, thiserror::Error)]
pub enum StackError {
    /// The build-up has no glass layer (nothing, or only gaps).
    #[error("the build-up has no glass layer: a unit needs at least one")]
    NoGlass,

    /// A gap is the first or the last element: a gap lies between two layers.
    #[error(
        "element {position} is a gap at the {end} end of the build-up: a gap lies between two layers"
    )]
    GapAtEnd {
        /// 1-based position of the gap.
        position: usize,
        /// `outer` or `inner`.
        end: &'static str,
    },

    /// Two gaps follow each other with no layer between them.
    #[error("elements {} and {position} are two gaps in a row: put a layer between them (or make them one gap)", position - 1)]
    TwoGapsInARow {
        /// 1-based position of the second gap.
        position: usize,
    },

    /// An opaque layer (zero transmittance) has layers behind it that no light reaches.
    #[error(
        "layer {position} ({label}) is opaque but layer {next} lies behind it: no light reaches it (an opaque layer can only be the last)"
    )]
    OpaqueBeforeAnother {
        /// 1-based position of the opaque layer.
        position: usize,
        /// The layer's label.
        label: String,
        /// 1-based position of the next layer.
        next: usize,
    },

    /// A layer's spectrum does not overlap the wavelengths of the layers before it.
    #[error(
        "layer {position} ({label}, {start_nm}–{end_nm} nm) does not overlap the wavelengths of the layers before it ({common_start_nm}–{common_end_nm} nm)"
    )]
    NoOverlap {
        /// 1-based position of the layer.
        position: usize,
        /// The layer's label.
        label: String,
        /// Its wavelength range.
        start_nm: f64,
        /// End of its range.
        end_nm: f64,
        /// The range the layers before it share.
        common_start_nm: f64,
        /// End of that range.
        common_end_nm: f64,
    },

    /// A thickness (of a layer or a gap) is negative, zero or not a number.
    #[error(
        "element {position} ({what}): thickness {value} mm is not a positive number of millimetres"
    )]
    Thickness {
        /// 1-based position of the element.
        position: usize,
        /// `gap` or the layer's label.
        what: String,
        /// The value given.
        value: f64,
    },

    /// A unit of several panes needs every layer's thickness to place its panes, and this
    /// layer's file states none.
    #[error(
        "layer {position} ({label}) has no thickness: its file states none, so give `thickness_mm` (the depth of every pane of a unit is recorded)"
    )]
    MissingThickness {
        /// 1-based position of the layer.
        position: usize,
        /// The layer's label.
        label: String,
    },

    /// A layer's data cannot describe a layer (missing column, wrong lengths, T + R > 1, …).
    #[error("layer {label}: {message}")]
    Layer {
        /// The layer's label.
        label: String,
        /// What is wrong.
        message: String,
    },

    /// A layer's spectra failed a spectral check (T + R ≤ 1 per wavelength).
    #[error("layer {label}")]
    LayerSpectrum {
        /// The layer's label.
        label: String,
        /// The check that failed.
        #[source]
        source: Box<glassdb_spectral::SpectralError>,
    },

    /// Integrating a spectrum of the stack failed (e.g. the common wavelengths do not cover
    /// the method's range).
    #[error("integrating the {what}")]
    Integration {
        /// Which spectrum, at which angle.
        what: String,
        /// The integration error.
        #[source]
        source: Box<glassdb_spectral::SpectralError>,
    },

    /// A measured angle table of a layer could not be fitted.
    #[error("layer {label}: fitting its measured {curve} angle curve")]
    Fit {
        /// The layer's label.
        label: String,
        /// `R` or `T`.
        curve: &'static str,
        /// The fit's error.
        #[source]
        source: Box<glassdb_fit::FitError>,
    },

    /// An angle of incidence outside 0–90° or not a number.
    #[error("angle {0}° is outside 0–90°")]
    Angle(f64),
}

impl StackError {
    /// The 1-based position of the element the error is about, when it is about one.
    pub fn position(&self) -> Option<usize> {
        match self {
            StackError::GapAtEnd { position, .. }
            | StackError::TwoGapsInARow { position }
            | StackError::OpaqueBeforeAnother { position, .. }
            | StackError::NoOverlap { position, .. }
            | StackError::Thickness { position, .. }
            | StackError::MissingThickness { position, .. } => Some(*position),
            _ => None,
        }
    }
}

impl StackError {
    /// The class of this error: a spectrum that cannot be integrated or checked, or a table
    /// that cannot be fitted, keeps its own class; anything else is a build-up to fix.
    pub fn kind(&self) -> glassdb_io::ErrorKind {
        match self {
            StackError::LayerSpectrum { source, .. } | StackError::Integration { source, .. } => {
                source.kind()
            }
            StackError::Fit { source, .. } => source.kind(),
            _ => glassdb_io::ErrorKind::Invalid,
        }
    }
}
