//! PNG decoding into interleaved 8- or 16-bit samples with the `png` crate: the size is checked
//! from the header before the pixel buffer is allocated, palettes and low bit depths are
//! expanded, and a decoder panic becomes an error. Used for masks here and for passes by
//! `glassdb-compose`.

use std::io::Cursor;

use crate::guard::catch_decoder_panic;

/// Why a PNG could not be decoded (the caller adds the file name).
#[derive(Debug, thiserror::Error)]
pub enum PngFlatError {
    /// The `png` crate rejected the file (corrupt, truncated or unsupported).
    #[error("{0}")]
    Decode(String),
    /// The decoder panicked on this file's bytes.
    #[error("the PNG decoder crashed on this file ({0}); the file is probably corrupt")]
    DecoderPanic(String),
    /// Larger than the allowed number of pixels (checked from the header).
    #[error("{width}×{height} pixels exceeds the limit of {max_pixels} pixels")]
    TooLarge {
        width: u32,
        height: u32,
        max_pixels: u64,
    },
}

/// Decoded samples, interleaved, row-major, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub enum PngSamples {
    U8(Vec<u8>),
    U16(Vec<u16>),
}

/// A decoded PNG.
#[derive(Debug, Clone, PartialEq)]
pub struct PngPixels {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel after expansion: 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA.
    pub channels: usize,
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

/// Decodes a PNG held in memory. Palette images become RGB(A), grey images below 8 bits
/// become 8-bit grey, 16-bit samples are returned as `u16`.
pub fn decode_png(bytes: &[u8], max_pixels: u64) -> Result<PngPixels, PngFlatError> {
    catch_decoder_panic(|| decode_png_inner(bytes, max_pixels))
        .map_err(PngFlatError::DecoderPanic)?
}

fn decode_png_inner(bytes: &[u8], max_pixels: u64) -> Result<PngPixels, PngFlatError> {
    let err = |e: png::DecodingError| PngFlatError::Decode(e.to_string());
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND);
    let header = decoder.read_header_info().map_err(err)?;
    let (width, height) = (header.width, header.height);
    if u64::from(width) * u64::from(height) > max_pixels {
        return Err(PngFlatError::TooLarge {
            width,
            height,
            max_pixels,
        });
    }
    let mut reader = decoder.read_info().map_err(err)?;
    let (color, depth) = reader.output_color_type();
    let channels = color.samples();
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| PngFlatError::Decode("image too large for this machine".into()))?;
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
            return Err(PngFlatError::Decode(format!(
                "unexpected bit depth {other:?} after expansion"
            )));
        }
    };
    let expected = row_samples * height as usize;
    let got = match &samples {
        PngSamples::U8(v) => v.len(),
        PngSamples::U16(v) => v.len(),
    };
    if got != expected {
        return Err(PngFlatError::Decode(format!(
            "decoded {got} samples, expected {expected}"
        )));
    }
    Ok(PngPixels {
        width,
        height,
        channels,
        samples,
    })
}
