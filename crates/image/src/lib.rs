//! Image files for passes, masks and plots: PNG and OpenEXR decoding into flat buffers (EXR:
//! one `f32` plane per channel; PNG: interleaved 8- or 16-bit samples), the one PNG encoder
//! and the one EXR encoder (ZIP deflated in parallel by zlib-rs), all behind one error type, [`ImageError`], whose
//! [`kind`](ImageError::kind) is the class a user can act on.
//!
//! Every call into a codec runs under a panic guard: a panic becomes
//! [`ImageError::CodecPanic`] (class [`ImageErrorKind::Internal`]), never a claim about the file.

mod error;
pub mod exr_read;
mod exr_write;
mod exr_zip;
mod guard;
pub mod png_read;
mod png_write;

pub use error::{Codec, ImageError, ImageErrorKind};
pub use exr_read::{
    ExrChannelInfo, ExrPart, ExrSampleType, PixelWindow, all_channel_names, find_channel,
    read_exr_channels, read_exr_headers,
};
pub use exr_write::{ExrPlane, ExrStorage, ExrWriteOptions, encode_exr_f32, write_exr_planes};
pub use exr_zip::{DEFAULT_ZIP_LEVEL, zip_block_lines};
pub use png_read::{PngPixels, PngSamples, decode_png};
pub use png_write::{PngColor, PngCompression, PngEncodeOptions, PngSampleSlice, encode_png};

/// Default pixel limit: 2^27 (134 million pixels, e.g. 16384×8192).
pub const DEFAULT_MAX_PIXELS: u64 = 1 << 27;

/// The file formats this crate recognises by their first bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFileKind {
    Png,
    Exr,
}

/// Detects PNG or OpenEXR from the magic number.
pub fn sniff_image_kind(bytes: &[u8]) -> Option<ImageFileKind> {
    if bytes.starts_with(&[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]) {
        Some(ImageFileKind::Png)
    } else if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        Some(ImageFileKind::Exr)
    } else {
        None
    }
}

/// An image file opened by [`open_image`]: a PNG is decoded whole; an EXR has its headers read,
/// and its channels are decoded on request (only the part and channels a caller needs).
#[derive(Debug)]
pub enum ImageFile<'a> {
    Png(PngPixels),
    Exr(ExrFile<'a>),
}

/// An OpenEXR file whose headers have been read.
#[derive(Debug, Clone)]
pub struct ExrFile<'a> {
    bytes: &'a [u8],
    parts: Vec<ExrPart>,
    max_pixels: u64,
}

impl ExrFile<'_> {
    /// The file's parts, from their headers.
    pub fn parts(&self) -> &[ExrPart] {
        &self.parts
    }

    /// Decodes channels `channels` of part `part`, one `f32` plane each (see
    /// [`read_exr_channels`]).
    pub fn read_channels(
        &self,
        part: usize,
        channels: &[usize],
    ) -> Result<(ExrPart, Vec<Vec<f32>>), ImageError> {
        read_exr_channels(self.bytes, part, channels, self.max_pixels)
    }

    /// Refuses a file whose data window is not its display window (a cropped render, a render
    /// border, overscan): its pixels cannot yet be placed in the frame by their coordinates,
    /// and reading them index by index would shift them.
    pub fn require_full_frame(&self) -> Result<(), ImageError> {
        match self
            .parts
            .iter()
            .find(|p| p.data_window != p.display_window)
        {
            Some(p) => Err(ImageError::WindowNotFrame {
                part: p.layer_name.clone(),
                data: p.data_window,
                display: p.display_window,
            }),
            None => Ok(()),
        }
    }
}

/// The one sniff-and-dispatch reader: detects PNG or OpenEXR from the bytes and opens it,
/// refusing images of more than `max_pixels` pixels before allocating their pixels.
pub fn open_image(bytes: &[u8], max_pixels: u64) -> Result<ImageFile<'_>, ImageError> {
    match sniff_image_kind(bytes) {
        Some(ImageFileKind::Png) => decode_png(bytes, max_pixels).map(ImageFile::Png),
        Some(ImageFileKind::Exr) => Ok(ImageFile::Exr(ExrFile {
            bytes,
            parts: read_exr_headers(bytes)?,
            max_pixels,
        })),
        None => Err(ImageError::UnknownFormat {
            start: bytes.iter().take(8).copied().collect(),
        }),
    }
}
