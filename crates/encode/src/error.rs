//! The errors of writing an output, each naming the file or the option involved.

use std::path::PathBuf;

use glassdb_io::ErrorKind;

/// Why an output could not be written (or, checked before any work, would not be).
#[derive(Debug, thiserror::Error)]
pub enum EncodeError {
    /// An output name without a `.exr` or `.png` extension.
    #[error("cannot tell the output format of {path}: use a .exr or .png extension")]
    OutputExtension {
        /// The output.
        path: PathBuf,
    },
    /// An EXR compression name that is not one of OpenEXR's.
    #[error("unknown EXR compression {name:?} (choose one of: {})", known.join(", "))]
    UnknownCompression {
        /// The name given.
        name: String,
        /// The names known ([`crate::EXR_COMPRESSIONS`]).
        known: Vec<&'static str>,
    },
    /// A zip level given for a compression that is not zip or zips.
    #[error("a zip level applies to zip and zips output, not {compression}")]
    ZipLevelNotApplicable {
        /// The compression asked for.
        compression: &'static str,
    },
    /// A zip level outside zlib's 0–9.
    #[error("zip level {level} is out of range (0–9)")]
    ZipLevelOutOfRange {
        /// The level given.
        level: u32,
    },
    /// An output layer name EXR cannot hold.
    #[error("{name:?} cannot be an EXR layer name (Latin-1 text, not empty, no dot at either end)")]
    BadLayerName {
        /// The name given.
        name: String,
    },
    /// A display view asked of an EXR output, which stays scene-linear.
    #[error(
        "a view transform applies to PNG output only, but {path} is EXR, which stays scene-linear"
    )]
    ViewOnExr {
        /// The output.
        path: PathBuf,
    },
    /// The encoder failed.
    #[error("cannot encode {path}")]
    Encode {
        /// The output.
        path: PathBuf,
        /// The encoder's error.
        #[source]
        source: glassdb_image::ImageError,
    },
    /// Writing the file failed (atomic: the target is left as it was).
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
}

impl EncodeError {
    /// The class of this error: an option or name that cannot be written is invalid; the
    /// encoder's and the file system's failures keep their own class.
    pub fn kind(&self) -> ErrorKind {
        match self {
            EncodeError::Encode { source, .. } => source.kind(),
            EncodeError::Output(e) => e.kind(),
            EncodeError::OutputExtension { .. }
            | EncodeError::UnknownCompression { .. }
            | EncodeError::ZipLevelNotApplicable { .. }
            | EncodeError::ZipLevelOutOfRange { .. }
            | EncodeError::BadLayerName { .. }
            | EncodeError::ViewOnExr { .. } => ErrorKind::Invalid,
        }
    }
}
