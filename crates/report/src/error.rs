//! The one error type of glassdb-report: a section that cannot be computed names what failed.

use std::path::PathBuf;

/// Failures of generating the report.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// An input file (the catalog) could not be read.
    #[error("cannot read {path}")]
    Read {
        /// The catalog.
        path: PathBuf,
        /// Why it could not be read.
        source: glassdb_io::InputError,
    },
    /// Writing the page or a figure failed (nothing was written).
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
    /// Drawing or saving a figure failed.
    #[error(transparent)]
    Plot(#[from] glassdb_plot::PlotError),
    /// An error from the spectral crate (reading spectra, integrating them).
    #[error(transparent)]
    Spectral(#[from] glassdb_spectral::SpectralError),
    /// An error from the registry crate (catalog parsing, building a registry).
    #[error(transparent)]
    Registry(#[from] glassdb_registry::RegistryError),
    /// An error from the scene crate (OBJ loading, rasterising a mask).
    #[error(transparent)]
    Scene(#[from] glassdb_scene::SceneError),
    /// An error from the mask crate (a glass mapping).
    #[error(transparent)]
    Mask(#[from] glassdb_mask::MaskError),
}

impl ReportError {
    /// The class of this error: a wrapped error's own class; a folder that cannot be made is
    /// I/O.
    pub fn kind(&self) -> glassdb_io::ErrorKind {
        match self {
            ReportError::Read { source, .. } => source.kind(),
            ReportError::Output(e) => e.kind(),
            ReportError::Plot(e) => e.kind(),
            ReportError::Spectral(e) => e.kind(),
            ReportError::Registry(e) => e.kind(),
            ReportError::Scene(e) => e.kind(),
            ReportError::Mask(e) => e.kind(),
        }
    }
}
