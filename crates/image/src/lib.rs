//! Image files for passes, masks and plots: PNG and OpenEXR decoding into flat buffers (EXR:
//! one `f32` plane per channel; PNG: interleaved 8- or 16-bit samples), the one PNG encoder
//! and the one EXR encoder (ZIP deflated in parallel by libdeflate), all behind one error type, [`ImageError`], whose
//! [`kind`](ImageError::kind) is the class a user can act on.
//!
//! Every call into a codec runs under a panic guard: a panic becomes
//! [`ImageError::CodecPanic`] (class [`ImageErrorKind::Internal`]), never a claim about the file.

#![warn(missing_docs)]

mod error;
mod exr_bands;
mod exr_header;
mod exr_layers;
pub mod exr_read;
mod exr_write;
mod exr_zip;
mod guard;
mod memory;
pub mod png_read;
mod png_write;
mod window;

use std::io::Read as _;

pub use error::{Codec, ImageError, ImageErrorKind};
/// The `exr` crate's attribute and sample types that cross this crate's API.
pub use exr::meta::header::{
    ImageAttributes as ExrImageAttributes, LayerAttributes as ExrLayerAttributes,
};
pub use exr::prelude::FlatSamples;
pub use exr_header::{
    ExrChannelInfo, ExrColourTag, ExrHeaders, ExrPart, ExrSampleType, MAX_EXR_PARTS,
    read_exr_header_info, read_exr_headers, read_exr_text_attributes,
};
pub use exr_layers::{
    ChannelMatch, LayerChoiceError, RgbLayer, all_channel_names, choose_rgb_layer, find_channel,
    plane_group_layers, plane_layers, rgb_layers,
};
pub use exr_read::{
    ExactExr, ExactPart, check_exr_readable, read_exr_attributes, read_exr_channel_rows,
    read_exr_channel_rows_from, read_exr_channels, read_exr_exact, read_exr_exact_keeping,
};
pub use exr_write::{
    ClampedSample, ExrImageOut, ExrPartOut, ExrPlane, ExrStorage, ExrWriteOptions, ExrWriteReport,
    PlaneSamples, encode_exr_f32, write_exr_image, write_exr_planes,
};
pub use exr_zip::{DEFAULT_ZIP_LEVEL, zip_block_lines};
pub use memory::ReadMemory;
pub use png_read::{PngHeader, PngPixels, PngSamples, decode_png, read_png_header};
pub use png_write::{PngColor, PngCompression, PngEncodeOptions, PngSampleSlice, encode_png};
pub use window::{ImageWindows, PixelWindow, place_plane};

/// The largest image file read: a pass or a mask, PNG or EXR (its pixel count is limited
/// separately, from its header, before decoding).
pub const IMAGE_FILE: glassdb_io::InputLimit = glassdb_io::InputLimit::gib(8, "an image");

/// Default pixel limit: 2^27 (134 million pixels, e.g. 16384×8192).
pub const DEFAULT_MAX_PIXELS: u64 = 1 << 27;

/// The file formats this crate recognises by their first bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFileKind {
    /// PNG (its signature).
    Png,
    /// OpenEXR (its magic number).
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

/// What an image file's header says, read before any pixel is decoded
/// ([`read_image_header`]).
#[derive(Debug, Clone)]
pub enum ImageHeader {
    /// A PNG's header chunks.
    Png(PngHeader),
    /// An OpenEXR's headers.
    Exr(ExrHeaders),
}

/// Reads the header of a PNG (its chunks up to the pixel data; refused above `max_pixels`) or
/// an OpenEXR (its headers), detected from the magic number, reading `reader` only that far.
/// No pixel is decompressed: a file whose pixel data is corrupt or truncated is not noticed.
pub fn read_image_header<R: std::io::BufRead + std::io::Seek>(
    mut reader: R,
    max_pixels: u64,
) -> Result<ImageHeader, ImageError> {
    let start = reader.stream_position().map_err(ImageError::Read)?;
    let mut magic = Vec::with_capacity(8);
    (&mut reader)
        .take(8)
        .read_to_end(&mut magic)
        .map_err(ImageError::Read)?;
    reader
        .seek(std::io::SeekFrom::Start(start))
        .map_err(ImageError::Read)?;
    match sniff_image_kind(&magic) {
        Some(ImageFileKind::Png) => read_png_header(reader, max_pixels).map(ImageHeader::Png),
        Some(ImageFileKind::Exr) => read_exr_header_info(reader).map(ImageHeader::Exr),
        None => Err(ImageError::UnknownFormat { start: magic }),
    }
}

/// An image file opened by [`open_image`]: a PNG is decoded whole; an EXR has its headers read,
/// and its channels are decoded on request (only the part and channels a caller needs).
#[derive(Debug)]
pub enum ImageFile<'a> {
    /// A PNG, decoded whole.
    Png(PngPixels),
    /// An OpenEXR, its headers read and its channels decoded on request.
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

    /// The file's bytes.
    pub fn bytes(&self) -> &[u8] {
        self.bytes
    }

    /// The pixel limit its parts are decoded under.
    pub fn max_pixels(&self) -> u64 {
        self.max_pixels
    }

    /// Decodes channels `channels` of part `part`, one `f32` plane each (see
    /// [`read_exr_channels`]).
    pub fn read_channels(
        &self,
        part: usize,
        channels: &[usize],
    ) -> Result<(ExrPart, Vec<Vec<f32>>), ImageError> {
        let bytes = std::io::Cursor::new(self.bytes);
        read_exr_channel_rows_from(bytes, &self.parts, part, channels, self.max_pixels, None)
    }
}

/// Opens an OpenEXR held in memory: its headers are read, its channels decoded on request
/// (refusing parts of more than `max_pixels` pixels before allocating them).
pub fn open_exr(bytes: &[u8], max_pixels: u64) -> Result<ExrFile<'_>, ImageError> {
    Ok(ExrFile {
        bytes,
        parts: read_exr_headers(bytes)?,
        max_pixels,
    })
}

/// The one sniff-and-dispatch reader: detects PNG or OpenEXR from the bytes and opens it,
/// refusing images of more than `max_pixels` pixels before allocating their pixels.
pub fn open_image(bytes: &[u8], max_pixels: u64) -> Result<ImageFile<'_>, ImageError> {
    match sniff_image_kind(bytes) {
        Some(ImageFileKind::Png) => decode_png(bytes, max_pixels).map(ImageFile::Png),
        Some(ImageFileKind::Exr) => open_exr(bytes, max_pixels).map(ImageFile::Exr),
        None => Err(ImageError::UnknownFormat {
            start: bytes.iter().take(8).copied().collect(),
        }),
    }
}
