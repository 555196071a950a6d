//! The PNG output: the composite through a display view, 8 or 16 bits, through
//! glassdb-image's one PNG encoder.

use std::path::Path;

use glassdb_image::{PngColor, PngCompression, PngEncodeOptions, PngSampleSlice};
use glassdb_pass::{EncodedImage, EncodedSamples};

use glassdb_pass::{LinearImage, PngBits};

use crate::{EncodeError, OutputOptions, Written};

/// Composited output is large: fast deflate, and an `sRGB` chunk (the samples are sRGB-encoded).
const OUTPUT_PNG: PngEncodeOptions = PngEncodeOptions {
    compression: PngCompression::Fast,
    srgb_chunk: true,
};

fn write_png(path: &Path, image: &EncodedImage) -> Result<u64, EncodeError> {
    let color = if image.channels == 4 {
        PngColor::Rgba
    } else {
        PngColor::Rgb
    };
    let samples = match &image.samples {
        EncodedSamples::U8(v) => PngSampleSlice::U8(v),
        EncodedSamples::U16(v) => PngSampleSlice::U16(v),
    };
    let bytes = glassdb_image::encode_png(image.width, image.height, color, samples, OUTPUT_PNG)
        .map_err(|source| EncodeError::Encode {
            path: path.to_path_buf(),
            source,
        })?;
    glassdb_io::write_bytes_atomic(path, &bytes)?;
    Ok(bytes.len() as u64)
}

/// Writes the PNG output: `image` un-premultiplied, through the options' display view, at
/// `bits` per sample (8-bit with the ordered dither when asked).
pub(crate) fn write_png_output(
    path: &Path,
    mut image: LinearImage,
    bits: PngBits,
    opts: &OutputOptions,
) -> Result<Written, EncodeError> {
    image.unpremultiply();
    let view = opts.view.clone().unwrap_or_default();
    let encoded = image.to_encoded_view(bits, opts.dither, &view);
    let bytes = write_png(path, &encoded)?;
    let depth = match bits {
        PngBits::Eight => "8-bit",
        PngBits::Sixteen => "16-bit",
    };
    let mut encoding = format!("{depth} {}", view.describe());
    if bits == PngBits::Eight && opts.dither {
        encoding += ", ordered dither";
    }
    Ok(Written {
        bytes,
        encoding,
        half_overflow: 0,
        first_half_overflow: None,
        kept_channels: 0,
    })
}
