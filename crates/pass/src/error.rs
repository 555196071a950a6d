//! The errors of reading a pass, each naming the file.

use std::path::PathBuf;

use glassdb_io::ErrorKind;

/// Why a pass (or the transmission pass's other channels) could not be read.
#[derive(Debug, thiserror::Error)]
pub enum PassError {
    /// The file could not be read (missing, not a regular file, over the size limit).
    #[error("cannot read {path}")]
    Read {
        /// The pass.
        path: PathBuf,
        /// Why.
        #[source]
        cause: glassdb_io::InputError,
    },
    /// A pass that is not a PNG or EXR this reader can decode (the source's class says whether
    /// it is corrupt, unsupported or too large).
    #[error("{path}")]
    Decode {
        /// The pass.
        path: PathBuf,
        /// The decoder's error.
        #[source]
        source: glassdb_image::ImageError,
    },
    /// No R, G, B channel triple in an EXR pass.
    #[error(
        "{path} has no R, G, B channels (it has: {}){}",
        available.join(", "),
        if available.iter().any(|c| c == "Y" || c.ends_with(".Y")) {
            ": luminance (Y) and luminance/chroma (Y, RY, BY) images are not composited; convert it to RGB"
        } else {
            ""
        }
    )]
    NoRgb {
        /// The pass.
        path: PathBuf,
        /// The channels it has.
        available: Vec<String>,
    },
    /// Several RGB layers and none chosen.
    #[error("{path} has several RGB layers ({}); choose one", candidates.join(", "))]
    AmbiguousLayer {
        /// The pass.
        path: PathBuf,
        /// Its RGB layers.
        candidates: Vec<String>,
    },
    /// Two layers of a pass are the same light group's (`ViewLayer.Combined_sun` and
    /// `LightSelect_sun`).
    #[error("{path} has two layers for light group {group:?}: {}", layers.join(", "))]
    TwoGroupLayers {
        /// The pass.
        path: PathBuf,
        /// The group.
        group: String,
        /// Its layers.
        layers: Vec<String>,
    },
    /// The layer asked for is not in the file.
    #[error("{path} has no RGB layer {layer:?} (it has: {})", candidates.join(", "))]
    LayerNotFound {
        /// The pass.
        path: PathBuf,
        /// The layer asked for.
        layer: String,
        /// Its RGB layers.
        candidates: Vec<String>,
    },
    /// An image whose width or height does not fit the pixel buffers.
    #[error("{path}: image too large")]
    TooLarge {
        /// The pass.
        path: PathBuf,
    },
    /// A reflection file with plane layers (`plane0`, `plane1`, …) that are not numbered 0…N−1.
    #[error("{path}: {problem}; its plane layers: {}", layers.join(", "))]
    PlaneLayers {
        /// The reflection file.
        path: PathBuf,
        /// What is wrong with the numbering.
        problem: String,
        /// Its plane layers.
        layers: Vec<String>,
    },
    /// A pass read as a sum of light-group layers ([`crate::read::LightMix`]) whose groups lie in
    /// different parts of the file.
    #[error("{path}: the light-group layers {} are in different parts; a light mix reads one part", layers.join(" and "))]
    LightMixParts {
        /// The pass.
        path: PathBuf,
        /// Two layers in different parts.
        layers: Vec<String>,
    },
    /// A pass read as a sum of light-group layers that is not an EXR (a PNG has no layers).
    #[error("{path} is not an EXR: light-group layers are read from multilayer EXR passes only")]
    LightMixNotExr {
        /// The pass.
        path: PathBuf,
    },
    /// The transmission file's other channels could not be read to be carried over.
    #[error("cannot carry over the other channels of {path}")]
    KeepChannels {
        /// The transmission pass.
        path: PathBuf,
        /// The decoder's error.
        #[source]
        source: glassdb_image::ImageError,
    },
}

impl PassError {
    /// The class of this error: a decoding failure's own class (corrupt, unsupported, too
    /// large, internal), a read failure's, or invalid input (a missing or ambiguous layer).
    pub fn kind(&self) -> ErrorKind {
        match self {
            PassError::Read { cause, .. } => cause.kind(),
            PassError::Decode { source, .. } | PassError::KeepChannels { source, .. } => {
                source.kind()
            }
            PassError::TooLarge { .. } => ErrorKind::Limits,
            PassError::NoRgb { .. } => ErrorKind::Unsupported,
            PassError::AmbiguousLayer { .. }
            | PassError::LayerNotFound { .. }
            | PassError::TwoGroupLayers { .. }
            | PassError::LightMixParts { .. }
            | PassError::LightMixNotExr { .. }
            | PassError::PlaneLayers { .. } => ErrorKind::Invalid,
        }
    }

    /// The image-level class of a decoding failure (`None` for the other errors).
    pub fn image_error_kind(&self) -> Option<glassdb_image::ImageErrorKind> {
        match self {
            PassError::Decode { source, .. } | PassError::KeepChannels { source, .. } => {
                Some(source.kind())
            }
            _ => None,
        }
    }
}
