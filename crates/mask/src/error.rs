//! The one error type of glassdb-mask: every variant names the file.

use std::path::PathBuf;

use glassdb_image::{ImageError, ImageErrorKind};

/// Everything that can go wrong reading or writing a mask.
#[derive(Debug, thiserror::Error)]
pub enum MaskError {
    /// The file could not be read.
    #[error("cannot read mask {path}")]
    Read {
        /// The mask.
        path: PathBuf,
        /// Why it could not be read.
        #[source]
        source: glassdb_io::InputError,
    },
    /// The file is not a PNG or EXR this reader can decode (its class says whether it is
    /// corrupt, unsupported or too large).
    #[error("mask {path}")]
    Decode {
        /// The mask.
        path: PathBuf,
        /// The decoder's error.
        #[source]
        source: ImageError,
    },
    /// The file decodes but is not laid out as any mask format (e.g. grey PNG without a glass id).
    #[error("mask {path}: {detail}")]
    Layout {
        /// The mask.
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },
    /// A Cryptomatte manifest entry used as glass whose hash is not the MurmurHash3_32 of its
    /// name (the specification's rule): a corrupt manifest would relabel other objects.
    #[error(
        "mask {path}: Cryptomatte {layer}: the manifest gives {} the hash {manifest:08x}, but the MurmurHash3_32 of that name is {expected:08x} (the manifest is corrupt; its ids cannot be trusted)",
        glassdb_io::quoted(name)
    )]
    ManifestHash {
        /// The mask.
        path: PathBuf,
        /// The Cryptomatte layer.
        layer: String,
        /// The object's name in the manifest.
        name: String,
        /// The hash the manifest gives it.
        manifest: u32,
        /// The MurmurHash3_32 of the name.
        expected: u32,
    },
    /// A binary (white-on-black) mask given as an EXR.
    #[error("mask {path}: a binary mask must be a PNG; an EXR mask carries its ids in a channel")]
    BinaryMaskNotPng {
        /// The mask.
        path: PathBuf,
    },
    /// A grey PNG read as a packed mask, with no glass id given for the binary form.
    #[error(
        "mask {path}: a grey PNG is not a packed id + cos θ mask (it needs RGB: R = plane, G = id, B = cos θ); for the paper's binary white/black mask give the glass id"
    )]
    GreyPngWithoutGlassId {
        /// The mask.
        path: PathBuf,
    },
    /// A channel the mask needs is missing.
    #[error("mask {path} has no channel {channel:?} (it has: {})", available.join(", "))]
    MissingChannel {
        /// The mask.
        path: PathBuf,
        /// The channel.
        channel: String,
        /// The channels it has.
        available: Vec<String>,
    },
    /// A pixel value that the format does not allow.
    #[error(
        "mask {path}: the channel name {channel:?} fits several channels ({}); give the full name",
        candidates.join(", ")
    )]
    AmbiguousChannel {
        /// The mask.
        path: PathBuf,
        /// The name given.
        channel: String,
        /// The channels it fits.
        candidates: Vec<String>,
    },
    /// Glass patterns that name nothing in a Cryptomatte manifest.
    #[error(
        "mask {path}: no name in the Cryptomatte layer {layer} matches {} (its names: {})",
        patterns.join(", "),
        names.join(", ")
    )]
    UnmatchedGlassNames {
        /// The mask.
        path: PathBuf,
        /// The Cryptomatte layer.
        layer: String,
        /// The patterns that match nothing.
        patterns: Vec<String>,
        /// The names the layer has.
        names: Vec<String>,
    },
    /// A `PATTERN=ID` glass mapping is malformed or its id is out of range.
    #[error("invalid glass mapping {spec:?}: {message}")]
    BadGlassMapping {
        /// The mapping as given.
        spec: String,
        /// What is wrong.
        message: String,
    },
    /// A pixel value the format does not allow.
    #[error("mask {path}, pixel (x {x}, y {y}): {detail}")]
    BadPixel {
        /// The mask.
        path: PathBuf,
        /// The pixel's column.
        x: u32,
        /// The pixel's row.
        y: u32,
        /// What is wrong.
        detail: String,
    },
    /// A mask that cannot be stored in the requested format without loss.
    #[error("cannot write mask {path} as {format}: {detail}")]
    NotRepresentable {
        /// The mask.
        path: PathBuf,
        /// The format asked for.
        format: &'static str,
        /// What it cannot hold.
        detail: String,
    },
    /// A mask image whose planes do not match its size (a bug of its maker).
    #[error("mask image is inconsistent: {0}")]
    Inconsistent(String),
    /// The encoder failed.
    #[error("cannot encode mask {path}")]
    Encode {
        /// The mask.
        path: PathBuf,
        /// The encoder's error.
        #[source]
        source: ImageError,
    },
    /// The mask file could not be written.
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
