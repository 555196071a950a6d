//! The one error type of glassdb-plot: each variant is a failure a user can act on.

use std::path::PathBuf;

/// Failures of plotting.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The output name has no extension we can write (`.png` or `.svg`).
    #[error("cannot tell the figure format of {path}: use a .png or .svg name")]
    UnknownFormat {
        /// The output.
        path: PathBuf,
    },
    /// The requested figure size is zero or too large to allocate.
    #[error("figure size {width}×{height} px is out of range (1…{max} px per side)")]
    BadSize {
        /// The width asked for.
        width: u32,
        /// The height asked for.
        height: u32,
        /// The largest side.
        max: u32,
    },
    /// The embedded font could not be loaded (a corrupt build).
    #[error("the embedded DejaVu Sans font could not be registered")]
    Font,
    /// The plotting library reported an error while drawing.
    #[error("drawing the figure failed: {0}")]
    Draw(String),
    /// The plotting library panicked (a bug in it, or input it cannot handle).
    #[error("the plotting library failed internally while drawing {what}")]
    DrawPanic {
        /// The figure.
        what: String,
    },
    /// Encoding the PNG failed.
    #[error("encoding the PNG failed")]
    Encode(#[source] glassdb_image::ImageError),
    /// An image file (a written figure) could not be decoded.
    #[error("cannot decode {path}")]
    Decode {
        /// The image.
        path: PathBuf,
        /// The decoder's error.
        #[source]
        source: glassdb_image::ImageError,
    },
    /// Writing the output failed (directory missing, permission, disk full).
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
    /// Reading an input file failed.
    #[error("cannot read {path}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why it could not be read.
        source: glassdb_io::InputError,
    },
    /// An input file parsed but does not hold what this plot needs.
    #[error("{path}: {message}")]
    Input {
        /// The file.
        path: PathBuf,
        /// What it lacks.
        message: String,
    },
    /// There is nothing to plot (e.g. a mask with no glass pixel, a file with no curve).
    #[error("nothing to plot: {0}")]
    Empty(String),
    /// A value that must be finite is not (NaN or infinite), named with where it came from.
    #[error("{what} is not finite ({value})")]
    NotFinite {
        /// Which value.
        what: String,
        /// The value.
        value: f64,
    },
    /// An error from the fit crate (angle tables, fit files, fitting).
    #[error(transparent)]
    Fit(#[from] glassdb_fit::FitError),
    /// An error from the spectral crate (reading spectra, integrating them).
    #[error(transparent)]
    Spectral(#[from] glassdb_spectral::SpectralError),
    /// An error from the registry crate.
    #[error(transparent)]
    Registry(#[from] glassdb_registry::RegistryError),
    /// An error from the mask crate.
    #[error(transparent)]
    Mask(#[from] glassdb_mask::MaskError),
}

/// Converts any displayable drawing error into [`PlotError::Draw`].
pub(crate) fn draw_err<E: std::fmt::Display>(e: E) -> PlotError {
    PlotError::Draw(e.to_string())
}

impl PlotError {
    /// The class of this error: a wrapped reader's or writer's own class; a panic of the
    /// drawing library is internal; a figure size over the limit is a limit; anything else is
    /// an input or an option to fix.
    pub fn kind(&self) -> glassdb_io::ErrorKind {
        use glassdb_io::ErrorKind;
        match self {
            PlotError::Fit(e) => e.kind(),
            PlotError::Spectral(e) => e.kind(),
            PlotError::Registry(e) => e.kind(),
            PlotError::Mask(e) => e.kind(),
            PlotError::Output(e) => e.kind(),
            PlotError::Read { source, .. } => source.kind(),
            PlotError::Encode(e) | PlotError::Decode { source: e, .. } => e.kind(),
            PlotError::DrawPanic { .. } | PlotError::Font | PlotError::Draw(_) => {
                ErrorKind::Internal
            }
            PlotError::BadSize { .. } => ErrorKind::Limits,
            _ => ErrorKind::Invalid,
        }
    }
}
