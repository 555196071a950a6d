//! The one error type of glassdb-mask: every variant names the file.

use std::path::PathBuf;

use glassdb_image::{ImageError, ImageErrorKind};

/// Everything that can go wrong reading or writing a mask.
#[derive(Debug, thiserror::Error)]
pub enum MaskError {
    #[error("cannot read mask {path}")]
    Read {
        path: PathBuf,
        #[source]
        source: glassdb_io::InputError,
    },
    /// The file is not a PNG or EXR this reader can decode (its class says whether it is
    /// corrupt, unsupported or too large).
    #[error("mask {path}")]
    Decode {
        path: PathBuf,
        #[source]
        source: ImageError,
    },
    /// The file decodes but is not laid out as any mask format (e.g. grey PNG without a glass id).
    #[error("mask {path}: {detail}")]
    Layout { path: PathBuf, detail: String },
    /// A binary (white-on-black) mask given as an EXR.
    #[error("mask {path}: a binary mask must be a PNG; an EXR mask carries its ids in a channel")]
    BinaryMaskNotPng { path: PathBuf },
    /// A grey PNG read as a packed mask, with no glass id given for the binary form.
    #[error(
        "mask {path}: a grey PNG is not a packed id + cos θ mask (it needs RGB: R = plane, G = id, B = cos θ); for the paper's binary white/black mask give the glass id"
    )]
    GreyPngWithoutGlassId { path: PathBuf },
    #[error("mask {path} has no channel {channel:?} (it has: {})", available.join(", "))]
    MissingChannel {
        path: PathBuf,
        channel: String,
        available: Vec<String>,
    },
    /// A pixel value that the format does not allow.
    #[error(
        "mask {path}: the channel name {channel:?} fits several channels ({}); give the full name",
        candidates.join(", ")
    )]
    AmbiguousChannel {
        path: PathBuf,
        channel: String,
        candidates: Vec<String>,
    },
    /// Glass patterns that name nothing in a Cryptomatte manifest.
    #[error(
        "mask {path}: no name in the Cryptomatte layer {layer} matches {} (its names: {})",
        patterns.join(", "),
        names.join(", ")
    )]
    UnmatchedGlassNames {
        path: PathBuf,
        layer: String,
        patterns: Vec<String>,
        names: Vec<String>,
    },
    /// A `PATTERN=ID` glass mapping is malformed or its id is out of range.
    #[error("invalid glass mapping {spec:?}: {message}")]
    BadGlassMapping { spec: String, message: String },
    #[error("mask {path}, pixel (x {x}, y {y}): {detail}")]
    BadPixel {
        path: PathBuf,
        x: u32,
        y: u32,
        detail: String,
    },
    /// A mask that cannot be stored in the requested format without loss.
    #[error("cannot write mask {path} as {format}: {detail}")]
    NotRepresentable {
        path: PathBuf,
        format: &'static str,
        detail: String,
    },
    #[error("mask image is inconsistent: {0}")]
    Inconsistent(String),
    #[error("cannot encode mask {path}")]
    Encode {
        path: PathBuf,
        #[source]
        source: ImageError,
    },
    #[error(transparent)]
    Write(#[from] glassdb_io::OutputError),
}

impl MaskError {
    /// The class of this error: a read's, decoder's or writer's own class; a mask image that
    /// does not hold together is glassdb's bug; anything else is a mask (or a glass mapping)
    /// to fix.
    pub fn kind(&self) -> glassdb_io::ErrorKind {
        use glassdb_io::ErrorKind;
        match self {
            MaskError::Read { source, .. } => source.kind(),
            MaskError::Decode { source, .. } | MaskError::Encode { source, .. } => source.kind(),
            MaskError::Write(e) => e.kind(),
            MaskError::Inconsistent(_) => ErrorKind::Internal,
            _ => ErrorKind::Invalid,
        }
    }

    /// The image-level class of a decoding or encoding failure (`None` for mask-level errors).
    pub fn image_error_kind(&self) -> Option<ImageErrorKind> {
        match self {
            MaskError::Decode { source, .. } | MaskError::Encode { source, .. } => {
                Some(source.kind())
            }
            _ => None,
        }
    }
}
