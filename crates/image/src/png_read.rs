//! PNG decoding into interleaved 8- or 16-bit samples with the `png` crate: the size is checked
//! from the header before the pixel buffer is allocated, palettes and low bit depths are
//! expanded, and a decoder panic becomes an `Internal` error. Used for masks, passes and plots.

use std::io::Cursor;

use crate::guard::catch_codec_panic;
use crate::{Codec, ImageError};

/// Decoded samples, interleaved, row-major, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub enum PngSamples {
    /// 8-bit samples.
    U8(Vec<u8>),
    /// 16-bit samples.
    U16(Vec<u16>),
}

/// A decoded PNG.
#[derive(Debug, Clone, PartialEq)]
pub struct PngPixels {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel after expansion: 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA.
    pub channels: usize,
    /// The samples, interleaved.
    pub samples: PngSamples,
}

impl PngPixels {
    /// Largest sample value: 255 or 65535.
    pub fn max_value(&self) -> u32 {
        match self.samples {
            PngSamples::U8(_) => 255,
            PngSamples::U16(_) => 65535,
        }
    }

    /// Sample `c` of pixel `i` (0 if out of range).
    pub fn sample(&self, i: usize, c: usize) -> u16 {
        let k = i * self.channels + c;
        match &self.samples {
            PngSamples::U8(v) => v.get(k).copied().map_or(0, u16::from),
            PngSamples::U16(v) => v.get(k).copied().unwrap_or(0),
        }
    }
}

/// What a PNG's chunks before its pixel data say, in the terms of [`decode_png`]'s output:
/// the size, and the samples per pixel and bits per sample after expansion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PngHeader {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel after expansion: 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA.
    pub channels: usize,
    /// 16-bit samples (else 8-bit, after expansion).
    pub sixteen_bit: bool,
}

impl PngHeader {
    /// Number of pixels.
    pub fn pixel_count(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }

    /// Bytes of the samples [`decode_png`] returns.
    pub fn sample_bytes(&self) -> u64 {
        let per_sample = if self.sixteen_bit { 2 } else { 1 };
        self.pixel_count()
            .saturating_mul(self.channels as u64 * per_sample)
    }

    /// Bytes [`decode_png`] holds at its peak: its decoding buffer, and for 16-bit samples the
    /// `u16` copy beside it.
    pub fn decode_bytes(&self) -> u64 {
        let copies = if self.sixteen_bit { 2 } else { 1 };
        self.sample_bytes().saturating_mul(copies)
    }
}

/// Refuses an image of more than `max_pixels` pixels.
fn check_pixel_limit(width: u32, height: u32, max_pixels: u64) -> Result<(), ImageError> {
    if u64::from(width) * u64::from(height) > max_pixels {
        return Err(ImageError::TooLarge {
            width: width.into(),
            height: height.into(),
            max_pixels,
        });
    }
    Ok(())
}

/// Reads a PNG's chunks up to its first pixel data (IDAT), without decompressing any pixel:
/// the size (refused above `max_pixels`), and the samples [`decode_png`] would return. A
/// corrupt or truncated image after the header is not noticed here.
pub fn read_png_header<R: std::io::BufRead + std::io::Seek>(
    reader: R,
    max_pixels: u64,
) -> Result<PngHeader, ImageError> {
    catch_codec_panic(Codec::Png, || {
        let mut decoder = png::Decoder::new(reader);
        decoder.set_transformations(png::Transformations::EXPAND);
        let header = decoder.read_header_info().map_err(ImageError::PngDecode)?;
        check_pixel_limit(header.width, header.height, max_pixels)?;
        let reader = decoder.read_info().map_err(ImageError::PngDecode)?;
        let (color, depth) = reader.output_color_type();
        let info = reader.info();
        Ok(PngHeader {
            width: info.width,
            height: info.height,
            channels: color.samples(),
            sixteen_bit: depth == png::BitDepth::Sixteen,
        })
    })?
}

/// Decodes a PNG held in memory. Palette images become RGB(A), grey images below 8 bits
/// become 8-bit grey, 16-bit samples are returned as `u16`.
pub fn decode_png(bytes: &[u8], max_pixels: u64) -> Result<PngPixels, ImageError> {
    catch_codec_panic(Codec::Png, || decode_png_inner(bytes, max_pixels))?
}

fn decode_png_inner(bytes: &[u8], max_pixels: u64) -> Result<PngPixels, ImageError> {
    let err = ImageError::PngDecode;
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND);
    let header = decoder.read_header_info().map_err(err)?;
    let (width, height) = (header.width, header.height);
    check_pixel_limit(width, height, max_pixels)?;
    let mut reader = decoder.read_info().map_err(err)?;
    let (color, depth) = reader.output_color_type();
    let channels = color.samples();
    let size = reader.output_buffer_size().ok_or(ImageError::TooLarge {
        width: width.into(),
        height: height.into(),
        max_pixels,
    })?;
    let mut buf = vec![0u8; size];
    let frame = reader.next_frame(&mut buf).map_err(err)?;
    buf.truncate(frame.buffer_size());
    let row_samples = width as usize * channels;
    let samples = match depth {
        png::BitDepth::Sixteen => {
            let row_bytes = frame.line_size;
            let mut out = Vec::with_capacity(row_samples * height as usize);
            for row in buf.chunks_exact(row_bytes).take(height as usize) {
                out.extend(
                    row.chunks_exact(2)
                        .take(row_samples)
                        .map(|b| u16::from_be_bytes([b[0], b[1]])),
                );
            }
            PngSamples::U16(out)
        }
        png::BitDepth::Eight => {
            if frame.line_size == row_samples {
                PngSamples::U8(buf)
            } else {
                let mut out = Vec::with_capacity(row_samples * height as usize);
                for row in buf.chunks_exact(frame.line_size).take(height as usize) {
                    out.extend_from_slice(row.get(..row_samples).unwrap_or(row));
                }
                PngSamples::U8(out)
            }
        }
        other => {
            return Err(ImageError::Unsupported {
                feature: format!("bit depth {other:?} after expansion"),
            });
        }
    };
    let expected = row_samples * height as usize;
    let got = match &samples {
        PngSamples::U8(v) => v.len(),
        PngSamples::U16(v) => v.len(),
    };
    if got != expected {
        return Err(ImageError::Incomplete {
            detail: format!("decoded {got} samples, expected {expected}"),
        });
    }
    Ok(PngPixels {
        width,
        height,
        channels,
        samples,
    })
}
