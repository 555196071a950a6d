//! The one PNG encoder of the workspace (masks, composited output, figures): 8- or 16-bit grey,
//! RGB or RGBA, with the deflate effort each caller picks.

use crate::ImageError;

/// Colour layout of the samples handed to [`encode_png`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PngColor {
    /// One grey channel.
    Grey,
    /// Red, green, blue.
    Rgb,
    /// Red, green, blue, alpha.
    Rgba,
}

impl PngColor {
    /// Samples per pixel.
    pub fn channels(self) -> usize {
        match self {
            PngColor::Grey => 1,
            PngColor::Rgb => 3,
            PngColor::Rgba => 4,
        }
    }

    fn png_type(self) -> png::ColorType {
        match self {
            PngColor::Grey => png::ColorType::Grayscale,
            PngColor::Rgb => png::ColorType::Rgb,
            PngColor::Rgba => png::ColorType::Rgba,
        }
    }
}

/// Interleaved samples, row-major, row 0 at the top; the variant sets the bit depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PngSampleSlice<'a> {
    /// 8-bit samples.
    U8(&'a [u8]),
    /// 16-bit samples.
    U16(&'a [u16]),
}

impl PngSampleSlice<'_> {
    fn len(&self) -> usize {
        match self {
            PngSampleSlice::U8(s) => s.len(),
            PngSampleSlice::U16(s) => s.len(),
        }
    }
}

/// How hard deflate works: large output (renders) wants speed, small flat-colour figures want
/// size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PngCompression {
    /// The fastest deflate (large frames).
    Fast,
    /// The `png` crate's default.
    Balanced,
    /// The smallest files (figures).
    High,
}

/// Encoder settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PngEncodeOptions {
    /// How hard the deflate works.
    pub compression: PngCompression,
    /// Write an `sRGB` chunk (perceptual intent): the samples are sRGB-encoded light.
    pub srgb_chunk: bool,
}

/// Encodes interleaved samples as a PNG file in memory (16-bit samples are stored big-endian,
/// as PNG requires).
pub fn encode_png(
    width: u32,
    height: u32,
    color: PngColor,
    samples: PngSampleSlice<'_>,
    options: PngEncodeOptions,
) -> Result<Vec<u8>, ImageError> {
    let expected = width as usize * height as usize * color.channels();
    if samples.len() != expected {
        return Err(ImageError::SampleCount {
            samples: samples.len(),
            width,
            height,
            channels: color.channels(),
        });
    }
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(color.png_type());
    encoder.set_compression(match options.compression {
        PngCompression::Fast => png::Compression::Fast,
        PngCompression::Balanced => png::Compression::Balanced,
        PngCompression::High => png::Compression::High,
    });
    if options.srgb_chunk {
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    let big_endian: Vec<u8>;
    let data: &[u8] = match samples {
        PngSampleSlice::U8(s) => {
            encoder.set_depth(png::BitDepth::Eight);
            s
        }
        PngSampleSlice::U16(s) => {
            encoder.set_depth(png::BitDepth::Sixteen);
            big_endian = s.iter().flat_map(|v| v.to_be_bytes()).collect();
            &big_endian
        }
    };
    let mut writer = encoder.write_header().map_err(ImageError::PngEncode)?;
    writer
        .write_image_data(data)
        .map_err(ImageError::PngEncode)?;
    writer.finish().map_err(ImageError::PngEncode)?;
    Ok(out)
}
