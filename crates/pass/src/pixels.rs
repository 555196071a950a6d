//! Pixel containers. Linear-light pixels ([`LinearImage`], planar `f32`) are the only ones the
//! compositor's arithmetic accepts; sRGB-encoded samples as a PNG stores them
//! ([`EncodedImage`]) are a different type that must be converted explicitly
//! ([`EncodedImage::to_linear`], [`LinearImage::to_encoded`]), so encoded values cannot reach
//! the arithmetic by mistake.
//!
//! Error bounds of the conversions:
//! - decode (8- and 16-bit): a table of every code computed in `f64` from the IEC 61966-2-1
//!   formula and rounded once to `f32`: within 0.5 ulp of the exact value.
//! - encode: the same formula in `f32` (`powf`), then round to nearest code (16-bit) or ordered
//!   dither (8-bit); the `f32` formula is within 2e-7 of the exact encoded value, far below
//!   half a 16-bit code (7.6e-6), so without dither every exactly decoded code encodes back to
//!   itself.

use rayon::prelude::*;

use glassdb_colour::DisplayView;

/// Linear-light RGB(A), planar, row-major, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// R, G, B planes, `width * height` samples each.
    pub rgb: [Vec<f32>; 3],
    /// Alpha plane (straight, not an sRGB quantity), when the source has one.
    pub alpha: Option<Vec<f32>>,
}

impl LinearImage {
    /// Applies a 3×3 matrix (row-major, as nalgebra indexes it) to every pixel's RGB: a change
    /// of linear RGB space. Alpha is unchanged (a linear map commutes with premultiplication).
    pub fn convert_rgb(&mut self, m: glassdb_colour::Matrix3<f64>) {
        let m: [[f32; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)] as f32));
        let [r, g, b] = &mut self.rgb;
        for ((r, g), b) in r.iter_mut().zip(g.iter_mut()).zip(b.iter_mut()) {
            let v = [*r, *g, *b];
            let row = |k: usize| m[k][0] * v[0] + m[k][1] * v[1] + m[k][2] * v[2];
            (*r, *g, *b) = (row(0), row(1), row(2));
        }
    }

    /// Number of pixels.
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Straight alpha (PNG's convention) to premultiplied (EXR's and the compositor's):
    /// colour × alpha. Without alpha nothing changes.
    pub fn premultiply(&mut self) {
        self.with_alpha(|c, a| *c *= a);
    }

    /// Premultiplied to straight alpha, for PNG output: colour ÷ alpha where alpha > 0;
    /// where alpha is 0 (or not a number) the colour is left as it is, as oiiotool's
    /// `--unpremult` does (light with no coverage, e.g. a reflection on a transparent
    /// background, cannot be stored straight).
    pub fn unpremultiply(&mut self) {
        self.with_alpha(|c, a| {
            if a > 0.0 {
                *c /= a;
            }
        });
    }

    /// `f(colour, alpha)` on every colour sample with its pixel's alpha, in parallel; nothing
    /// without alpha.
    fn with_alpha(&mut self, f: impl Fn(&mut f32, f32) + Sync + Send) {
        if let Some(alpha) = &self.alpha {
            for plane in &mut self.rgb {
                plane
                    .par_iter_mut()
                    .zip(alpha.par_iter())
                    .for_each(|(c, &a)| f(c, a));
            }
        }
    }

    /// An image of one colour.
    pub fn filled(width: u32, height: u32, rgb: [f32; 3], alpha: Option<f32>) -> LinearImage {
        let n = width as usize * height as usize;
        LinearImage {
            width,
            height,
            rgb: [vec![rgb[0]; n], vec![rgb[1]; n], vec![rgb[2]; n]],
            alpha: alpha.map(|a| vec![a; n]),
        }
    }

    /// sRGB-encodes into PNG samples of `bits` (8 or 16) per sample. 8-bit output is dithered
    /// with an 8×8 ordered (Bayer) pattern when `dither` is set. Values outside [0, 1] are
    /// clamped, NaN becomes 0.
    pub fn to_encoded(&self, bits: PngBits, dither: bool) -> EncodedImage {
        self.to_encoded_view(bits, dither, &DisplayView::Standard)
    }

    /// Encodes into PNG samples through `view`: [`DisplayView::Standard`] is the sRGB
    /// transfer of [`LinearImage::to_encoded`]; a LUT's output is taken as display-encoded and
    /// only clamped to [0, 1] (NaN → 0) before the same quantisation (and dither).
    pub fn to_encoded_view(&self, bits: PngBits, dither: bool, view: &DisplayView) -> EncodedImage {
        let w = self.width as usize;
        let channels = if self.alpha.is_some() { 4 } else { 3 };
        let n = self.pixel_count();
        let linear = |i: usize, c: usize| self.rgb[c].get(i).copied().unwrap_or(0.0);
        let encode_pixel = |y: usize, x: usize| -> [f32; 4] {
            let i = y * w + x;
            let rgb = [linear(i, 0), linear(i, 1), linear(i, 2)];
            let [r, g, b] = match view {
                DisplayView::Standard => rgb.map(linear_to_srgb),
                DisplayView::Lut(lut) => lut.apply(rgb).map(sanitize),
            };
            let a = self
                .alpha
                .as_ref()
                .map_or(1.0, |a| sanitize(a.get(i).copied().unwrap_or(1.0)));
            [r, g, b, a]
        };
        let samples = match bits {
            PngBits::Eight => {
                EncodedSamples::U8(quantise_rows(w, n, channels, encode_pixel, |y, x, c, v| {
                    // Alpha is never dithered.
                    let t = if dither && c != 3 {
                        BAYER8[y % 8][x % 8]
                    } else {
                        0.5
                    };
                    (v * 255.0 + t).floor().clamp(0.0, 255.0) as u8
                }))
            }
            PngBits::Sixteen => {
                EncodedSamples::U16(quantise_rows(w, n, channels, encode_pixel, |_, _, _, v| {
                    (v * 65535.0 + 0.5).floor().clamp(0.0, 65535.0) as u16
                }))
            }
        };
        EncodedImage {
            width: self.width,
            height: self.height,
            channels,
            samples,
        }
    }
}

/// The samples of `n` pixels, `width` a row and `channels` a pixel, filled row by row in
/// parallel: `quantise(y, x, c, v)` is the sample of channel `c` of pixel (`x`, `y`), whose
/// encoded value `v` is channel `c` of `encode_pixel(y, x)`.
fn quantise_rows<S: Copy + Default + Send>(
    width: usize,
    n: usize,
    channels: usize,
    encode_pixel: impl Fn(usize, usize) -> [f32; 4] + Sync,
    quantise: impl Fn(usize, usize, usize, f32) -> S + Sync,
) -> Vec<S> {
    let mut out = vec![S::default(); n * channels];
    out.par_chunks_mut(width.max(1) * channels)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, px) in row.chunks_exact_mut(channels).enumerate() {
                let v = encode_pixel(y, x);
                for (c, s) in px.iter_mut().enumerate() {
                    *s = quantise(y, x, c, v[c]);
                }
            }
        });
    out
}

/// Bit depth of PNG samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PngBits {
    /// 8 bits per sample.
    Eight,
    /// 16 bits per sample.
    Sixteen,
}

/// How PNG samples map to linear light.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InputTransfer {
    /// sRGB-encoded (IEC 61966-2-1), the PNG default.
    #[default]
    Srgb,
    /// Already linear: value = code / max.
    Linear,
}

/// Samples as stored in a PNG: sRGB-encoded colour (alpha linear), interleaved. Not linear
/// light: convert with [`EncodedImage::to_linear`] before any arithmetic.
#[derive(Debug, Clone, PartialEq)]
pub struct EncodedImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA.
    pub channels: usize,
    /// The samples, `width × height × channels` of them.
    pub samples: EncodedSamples,
}

/// Interleaved encoded samples.
#[derive(Debug, Clone, PartialEq)]
pub enum EncodedSamples {
    /// 8-bit samples.
    U8(Vec<u8>),
    /// 16-bit samples.
    U16(Vec<u16>),
}

impl EncodedImage {
    /// Decodes to linear light through an exact table (see the module docs). Grey becomes
    /// R = G = B.
    pub fn to_linear(&self, transfer: InputTransfer) -> LinearImage {
        let n = self.width as usize * self.height as usize;
        let ch = self.channels.max(1);
        let colour = if ch >= 3 { 3 } else { 1 };
        let has_alpha = ch == 2 || ch == 4;
        let (table, max): (Vec<f32>, f32) = match self.samples {
            EncodedSamples::U8(_) => (decode_table(256, transfer), 255.0),
            EncodedSamples::U16(_) => (decode_table(65536, transfer), 65535.0),
        };
        let sample = |i: usize| -> u16 {
            match &self.samples {
                EncodedSamples::U8(v) => v.get(i).copied().map_or(0, u16::from),
                EncodedSamples::U16(v) => v.get(i).copied().unwrap_or(0),
            }
        };
        let mut rgb: [Vec<f32>; 3] = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        for (c, plane) in rgb.iter_mut().enumerate() {
            let src_c = if colour == 3 { c } else { 0 };
            plane
                .par_chunks_mut(4096)
                .enumerate()
                .for_each(|(k, chunk)| {
                    for (j, d) in chunk.iter_mut().enumerate() {
                        let i = k * 4096 + j;
                        *d = table
                            .get(sample(i * ch + src_c) as usize)
                            .copied()
                            .unwrap_or(0.0);
                    }
                });
        }
        let alpha = has_alpha.then(|| {
            (0..n)
                .map(|i| f32::from(sample(i * ch + ch - 1)) / max)
                .collect()
        });
        LinearImage {
            width: self.width,
            height: self.height,
            rgb,
            alpha,
        }
    }
}

/// Linear value of every code of a `len`-code depth, computed in f64 and rounded once.
fn decode_table(len: usize, transfer: InputTransfer) -> Vec<f32> {
    let max = (len - 1) as f64;
    (0..len)
        .map(|c| {
            let v = c as f64 / max;
            match transfer {
                InputTransfer::Srgb => srgb_to_linear_f64(v) as f32,
                InputTransfer::Linear => v as f32,
            }
        })
        .collect()
}

/// The sRGB decoding function (IEC 61966-2-1) on [0, 1].
pub fn srgb_to_linear_f64(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB encoding function on linear light, clamped to [0, 1] (NaN → 0).
#[inline]
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = sanitize(x);
    if x <= 0.003_130_8 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

#[inline]
fn sanitize(x: f32) -> f32 {
    if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) }
}

/// 8×8 Bayer thresholds in (0, 1): (rank + 0.5) / 64.
const BAYER8: [[f32; 8]; 8] = {
    const RANK: [[u8; 8]; 8] = [
        [0, 32, 8, 40, 2, 34, 10, 42],
        [48, 16, 56, 24, 50, 18, 58, 26],
        [12, 44, 4, 36, 14, 46, 6, 38],
        [60, 28, 52, 20, 62, 30, 54, 22],
        [3, 35, 11, 43, 1, 33, 9, 41],
        [51, 19, 59, 27, 49, 17, 57, 25],
        [15, 47, 7, 39, 13, 45, 5, 37],
        [63, 31, 55, 23, 61, 29, 53, 21],
    ];
    let mut t = [[0.0f32; 8]; 8];
    let mut y = 0;
    while y < 8 {
        let mut x = 0;
        while x < 8 {
            t[y][x] = (RANK[y][x] as f32 + 0.5) / 64.0;
            x += 1;
        }
        y += 1;
    }
    t
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_reference_points() {
        // IEC 61966-2-1: code 0.5 → 0.214041; the linear segment below 0.04045.
        assert!((srgb_to_linear_f64(0.5) - 0.214_041_140_482_232_5).abs() < 1e-12);
        assert!((srgb_to_linear_f64(0.04) - 0.04 / 12.92).abs() < 1e-15);
        assert_eq!(srgb_to_linear_f64(1.0), 1.0);
        assert!((linear_to_srgb(0.214_041_14) - 0.5).abs() < 2e-7);
    }

    #[test]
    fn every_8_and_16_bit_code_round_trips() {
        let n8 = 256u32;
        let img = EncodedImage {
            width: n8,
            height: 1,
            channels: 1,
            samples: EncodedSamples::U8((0..=255).collect()),
        };
        let lin = img.to_linear(InputTransfer::Srgb);
        for dither in [false, true] {
            let back = lin.to_encoded(PngBits::Eight, dither);
            let EncodedSamples::U8(s) = back.samples else {
                panic!()
            };
            let reds: Vec<u8> = s.chunks(3).map(|p| p[0]).collect();
            assert_eq!(reds, (0..=255).collect::<Vec<u8>>());
        }
        let img16 = EncodedImage {
            width: 65536,
            height: 1,
            channels: 1,
            samples: EncodedSamples::U16((0..=65535).collect()),
        };
        let back = img16
            .to_linear(InputTransfer::Srgb)
            .to_encoded(PngBits::Sixteen, false);
        let EncodedSamples::U16(s) = back.samples else {
            panic!()
        };
        let mismatches = s
            .chunks(3)
            .enumerate()
            .filter(|(i, p)| p[0] as usize != *i)
            .count();
        assert_eq!(mismatches, 0);
    }

    #[test]
    fn ordered_dither_preserves_the_mean() {
        // Linear value whose encoded value is 100.25 codes: dithered 8×8 block averages 100.25.
        let target = 100.25 / 255.0;
        let lin = srgb_to_linear_f64(target) as f32;
        let img = LinearImage::filled(8, 8, [lin; 3], None);
        let EncodedSamples::U8(s) = img.to_encoded(PngBits::Eight, true).samples else {
            panic!()
        };
        let mean: f64 = s.chunks(3).map(|p| f64::from(p[0])).sum::<f64>() / 64.0;
        assert!((mean - 100.25).abs() < 1.0 / 64.0 + 1e-9, "{mean}");
        let EncodedSamples::U8(s) = img.to_encoded(PngBits::Eight, false).samples else {
            panic!()
        };
        assert!(s.chunks(3).all(|p| p[0] == 100));
    }

    #[test]
    fn linear_transfer_is_code_over_max_and_alpha_is_linear() {
        let img = EncodedImage {
            width: 1,
            height: 1,
            channels: 4,
            samples: EncodedSamples::U8(vec![51, 0, 255, 102]),
        };
        let lin = img.to_linear(InputTransfer::Linear);
        assert_eq!(lin.rgb[0][0], 0.2);
        assert_eq!(lin.alpha.as_ref().unwrap()[0], 0.4);
        let srgb = img.to_linear(InputTransfer::Srgb);
        assert_eq!(srgb.alpha.unwrap()[0], 0.4);
        assert_eq!(srgb.rgb[2][0], 1.0);
    }
}
