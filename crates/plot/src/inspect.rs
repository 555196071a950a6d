//! A summary of a written PNG (size, distinct colours, spread of lightness): what the tests and
//! `glassdb report` check to know a figure is really drawn, without comparing pixels exactly.

use std::path::Path;

use glassdb_image::PngSamples;

use crate::PlotError;

/// What a PNG holds, in numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct PngSummary {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Number of distinct RGB colours.
    pub distinct_colours: usize,
    /// Standard deviation of the Rec.709 luma over all pixels (0…255).
    pub luma_std: f64,
    /// Fraction of pixels that are not pure white.
    pub inked_fraction: f64,
}

/// Decodes the PNG at `path` (grey, RGB or RGBA; 16-bit samples as their high byte) and
/// summarises it.
pub fn summarize_png(path: &Path) -> Result<PngSummary, PlotError> {
    let bytes = glassdb_io::read_input(path, glassdb_image::IMAGE_FILE).map_err(|source| {
        PlotError::Read {
            path: path.into(),
            source,
        }
    })?;
    let png =
        glassdb_image::decode_png(&bytes, glassdb_image::DEFAULT_MAX_PIXELS).map_err(|source| {
            PlotError::Decode {
                path: path.into(),
                source,
            }
        })?;
    let channels = png.channels;
    // 16-bit samples keep their high byte, as 8-bit colours.
    let data: Vec<u8> = match png.samples {
        PngSamples::U8(v) => v,
        PngSamples::U16(v) => v.iter().map(|s| (s >> 8) as u8).collect(),
    };
    let mut colours = std::collections::HashSet::new();
    let (mut sum, mut sum2, mut inked, mut n) = (0.0, 0.0, 0usize, 0usize);
    for px in data.chunks_exact(channels) {
        let (r, g, b) = if channels >= 3 {
            (px[0], px[1], px[2])
        } else {
            (px[0], px[0], px[0])
        };
        colours.insert((r, g, b));
        let l = 0.2126 * r as f64 + 0.7152 * g as f64 + 0.0722 * b as f64;
        sum += l;
        sum2 += l * l;
        n += 1;
        if (r, g, b) != (255, 255, 255) {
            inked += 1;
        }
    }
    let nf = n.max(1) as f64;
    let mean = sum / nf;
    Ok(PngSummary {
        width: png.width,
        height: png.height,
        distinct_colours: colours.len(),
        luma_std: (sum2 / nf - mean * mean).max(0.0).sqrt(),
        inked_fraction: inked as f64 / nf,
    })
}
