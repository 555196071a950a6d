//! The one error type of glassdb-image. Each variant belongs to one [`ImageErrorKind`], the
//! class a user can act on; the decoder's or encoder's own error is kept as the `source`.

/// What a user can do about an [`ImageError`]: the class every glassdb error shares
/// ([`glassdb_io::ErrorKind`]), under the name this crate has always given it.
pub use glassdb_io::ErrorKind as ImageErrorKind;

/// The codec a [`ImageError::CodecPanic`] came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Codec {
    /// PNG (the `png` crate).
    Png,
    /// OpenEXR (the `exr` crate).
    Exr,
}

impl std::fmt::Display for Codec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Codec::Png => "PNG",
            Codec::Exr => "OpenEXR",
        })
    }
}

/// Why an image could not be decoded or encoded. The caller adds the file name.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The bytes start with neither the PNG nor the OpenEXR magic number.
    #[error("neither PNG nor OpenEXR (it starts with bytes {start:02x?})")]
    UnknownFormat {
        /// The file's first bytes.
        start: Vec<u8>,
    },
    /// The `exr` crate rejected the bytes; its error tells whether they are invalid,
    /// unsupported or unreadable.
    #[error("the OpenEXR data cannot be decoded")]
    ExrDecode(#[source] exr::error::Error),
    /// The `png` crate rejected the bytes.
    #[error("the PNG data cannot be decoded")]
    PngDecode(#[source] png::DecodingError),
    /// The file's blocks are missing, overlapping or of the wrong size: truncated or corrupt.
    #[error("pixel data incomplete: {detail}")]
    Incomplete {
        /// What is missing or wrong.
        detail: String,
    },
    /// A feature this crate does not handle (deep data, subsampled channels, an empty image).
    #[error("unsupported: {feature}")]
    Unsupported {
        /// The feature.
        feature: String,
    },
    /// Larger than the allowed number of pixels (checked from the header, before allocating).
    #[error("{width}×{height} pixels exceeds the limit of {max_pixels} pixels")]
    TooLarge {
        /// The image's width.
        width: u64,
        /// The image's height.
        height: u64,
        /// The pixel limit.
        max_pixels: u64,
    },
    /// An EXR of more parts than [`crate::MAX_EXR_PARTS`] (counted from its headers, before
    /// they are parsed).
    #[error("the OpenEXR file has more than {max} parts")]
    TooManyParts {
        /// The most parts allowed.
        max: usize,
    },
    /// A codec panicked (a bug in it, reached by these bytes); the panic is caught, not renamed.
    #[error("the {codec} codec failed internally (it panicked: {message})")]
    CodecPanic {
        /// The codec that panicked.
        codec: Codec,
        /// The panic's message.
        message: String,
    },
    /// Reading the file's header from its stream failed.
    #[error("cannot read the image header")]
    Read(#[source] std::io::Error),
    /// The sample buffer handed to an encoder does not match the image size.
    #[error("{samples} samples given for a {width}×{height} image of {channels} channel(s)")]
    SampleCount {
        /// Samples given.
        samples: usize,
        /// The image's width.
        width: u32,
        /// The image's height.
        height: u32,
        /// Channels per pixel.
        channels: usize,
    },
    /// The `png` crate could not encode the image.
    #[error("the PNG encoder failed")]
    PngEncode(#[source] png::EncodingError),
    /// The `exr` crate could not encode the image.
    #[error("the OpenEXR encoder failed")]
    ExrEncode(#[source] exr::error::Error),
}

impl ImageError {
    /// The class of this error (what a user can act on).
    pub fn kind(&self) -> ImageErrorKind {
        match self {
            ImageError::UnknownFormat { .. } | ImageError::Unsupported { .. } => {
                ImageErrorKind::Unsupported
            }
            ImageError::ExrDecode(e) | ImageError::ExrEncode(e) => exr_kind(e),
            ImageError::PngDecode(e) => match e {
                png::DecodingError::IoError(io) => io_kind(io),
                png::DecodingError::Format(_) => ImageErrorKind::Invalid,
                png::DecodingError::LimitsExceeded => ImageErrorKind::Limits,
                png::DecodingError::Parameter(_) => ImageErrorKind::Internal,
            },
            ImageError::PngEncode(e) => match e {
                png::EncodingError::IoError(io) => io_kind(io),
                png::EncodingError::Format(_) | png::EncodingError::Parameter(_) => {
                    ImageErrorKind::Invalid
                }
                png::EncodingError::LimitsExceeded => ImageErrorKind::Limits,
            },
            ImageError::Incomplete { .. } | ImageError::SampleCount { .. } => {
                ImageErrorKind::Invalid
            }
            ImageError::TooLarge { .. } | ImageError::TooManyParts { .. } => ImageErrorKind::Limits,
            ImageError::Read(io) => io_kind(io),
            ImageError::CodecPanic { .. } => ImageErrorKind::Internal,
        }
    }
}

fn exr_kind(e: &exr::error::Error) -> ImageErrorKind {
    match e {
        exr::error::Error::Invalid(_) => ImageErrorKind::Invalid,
        exr::error::Error::NotSupported(_) => ImageErrorKind::Unsupported,
        exr::error::Error::Io(io) => io_kind(io),
        exr::error::Error::Aborted => ImageErrorKind::Internal,
    }
}

/// Decoders read from memory here, so running out of bytes means a truncated file, not a
/// failing device.
fn io_kind(e: &std::io::Error) -> ImageErrorKind {
    if e.kind() == std::io::ErrorKind::UnexpectedEof {
        ImageErrorKind::Invalid
    } else {
        ImageErrorKind::Io
    }
}
