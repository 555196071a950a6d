//! Reading passes (through glassdb-image's one reader: EXR into flat per-channel buffers, PNG
//! into samples), choosing a pass's RGB layer, and writing the result through glassdb-image's
//! EXR and PNG encoders, atomically.

use std::path::{Path, PathBuf};

use glassdb_image::{
    ExrFile, ExrPart, ExrPlane, ExrSampleType, ExrStorage, ExrWriteOptions, ImageError, ImageFile,
    PngColor, PngCompression, PngEncodeOptions, PngPixels, PngSampleSlice, PngSamples,
};

use crate::ComposeError;
use crate::pixels::{EncodedImage, EncodedSamples, InputTransfer, LinearImage, PngBits};

/// How to read a pass.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PassReadOptions {
    /// EXR layer (channel-name prefix or part name), e.g. `ViewLayer.Combined`. `None`: the
    /// only RGB layer, or the bare `R`, `G`, `B`, or the one named `…Combined`.
    pub layer: Option<String>,
    /// How PNG samples map to linear light.
    pub transfer: InputTransfer,
    /// Pixel limit, checked from the header before allocating.
    pub max_pixels: u64,
}

impl Default for PassReadOptions {
    fn default() -> Self {
        PassReadOptions {
            layer: None,
            transfer: InputTransfer::Srgb,
            max_pixels: glassdb_image::DEFAULT_MAX_PIXELS,
        }
    }
}

/// What a pass was stored as (to pick output defaults and report).
#[derive(Debug, Clone, PartialEq)]
pub enum PassSource {
    Exr {
        sample_type: ExrSampleType,
        compression: exr::compression::Compression,
        layer: String,
    },
    Png {
        bits: PngBits,
    },
}

/// A decoded pass.
#[derive(Debug, Clone)]
pub struct Pass {
    pub image: LinearImage,
    pub source: PassSource,
}

/// Reads a pass file (format from its bytes).
pub fn read_pass(path: &Path, opts: &PassReadOptions) -> Result<Pass, ComposeError> {
    let bytes = std::fs::read(path).map_err(|cause| ComposeError::Read {
        path: path.to_path_buf(),
        cause,
    })?;
    read_pass_bytes(&bytes, path, opts)
}

/// Reads a pass from bytes in memory; `path` names it in errors.
pub fn read_pass_bytes(
    bytes: &[u8],
    path: &Path,
    opts: &PassReadOptions,
) -> Result<Pass, ComposeError> {
    let decoded = glassdb_image::open_image(bytes, opts.max_pixels)
        .map_err(|source| decode_err(path, source))?;
    match decoded {
        ImageFile::Png(png) => Ok(pass_from_png(png, opts.transfer)),
        ImageFile::Exr(exr) => {
            exr.require_full_frame()
                .map_err(|source| decode_err(path, source))?;
            read_exr_pass(&exr, path, opts)
        }
    }
}

fn decode_err(path: &Path, source: ImageError) -> ComposeError {
    ComposeError::Decode {
        path: path.to_path_buf(),
        source,
    }
}

/// A PNG pass: its samples mapped to linear light by `transfer`.
fn pass_from_png(png: PngPixels, transfer: InputTransfer) -> Pass {
    let bits = match png.samples {
        PngSamples::U8(_) => PngBits::Eight,
        PngSamples::U16(_) => PngBits::Sixteen,
    };
    let encoded = EncodedImage {
        width: png.width,
        height: png.height,
        channels: png.channels,
        samples: match png.samples {
            PngSamples::U8(v) => EncodedSamples::U8(v),
            PngSamples::U16(v) => EncodedSamples::U16(v),
        },
    };
    Pass {
        image: encoded.to_linear(transfer),
        source: PassSource::Png { bits },
    }
}

/// RGB layers of an EXR: prefix (`""` for bare `R`, `G`, `B`) → (part, [r, g, b], alpha).
fn rgb_layers(parts: &[ExrPart]) -> Vec<(String, usize, [usize; 3], Option<usize>)> {
    let mut out = Vec::new();
    for (p, part) in parts.iter().enumerate() {
        let names: Vec<String> = (0..part.channels.len())
            .filter_map(|i| part.qualified_name(i))
            .collect();
        for name in &names {
            let prefix = match name.strip_suffix('R') {
                Some(pre) if pre.is_empty() || pre.ends_with('.') => pre.trim_end_matches('.'),
                _ => continue,
            };
            let find = |c: &str| {
                let full = if prefix.is_empty() {
                    c.to_string()
                } else {
                    format!("{prefix}.{c}")
                };
                names.iter().position(|n| *n == full)
            };
            if let (Some(r), Some(g), Some(b)) = (find("R"), find("G"), find("B")) {
                out.push((prefix.to_string(), p, [r, g, b], find("A")));
            }
        }
    }
    out
}

fn read_exr_pass(
    exr: &ExrFile<'_>,
    path: &Path,
    opts: &PassReadOptions,
) -> Result<Pass, ComposeError> {
    let parts = exr.parts();
    let layers = rgb_layers(parts);
    let candidates: Vec<String> = layers
        .iter()
        .map(|l| {
            if l.0.is_empty() {
                "(R, G, B)".to_string()
            } else {
                l.0.clone()
            }
        })
        .collect();
    let chosen = match &opts.layer {
        Some(want) => {
            let want = want.trim_end_matches('.');
            layers
                .iter()
                .find(|l| l.0 == want)
                .ok_or_else(|| ComposeError::LayerNotFound {
                    path: path.to_path_buf(),
                    layer: want.to_string(),
                    candidates: candidates.clone(),
                })?
        }
        None => match layers.as_slice() {
            [] => {
                return Err(ComposeError::NoRgb {
                    path: path.to_path_buf(),
                    available: glassdb_image::all_channel_names(parts),
                });
            }
            [only] => only,
            many => {
                let combined: Vec<_> = many.iter().filter(|l| l.0.ends_with("Combined")).collect();
                match (many.iter().find(|l| l.0.is_empty()), combined.as_slice()) {
                    (Some(bare), _) => bare,
                    (None, [one]) => one,
                    _ => {
                        return Err(ComposeError::AmbiguousLayer {
                            path: path.to_path_buf(),
                            candidates,
                        });
                    }
                }
            }
        },
    };
    let (layer, part, rgb, alpha) = chosen.clone();
    let mut channels = rgb.to_vec();
    channels.extend(alpha);
    let (info, mut buffers) = exr
        .read_channels(part, &channels)
        .map_err(|source| decode_err(path, source))?;
    let sample_type = info
        .channels
        .get(rgb[0])
        .map_or(ExrSampleType::Float, |c| c.sample_type);
    let alpha_plane = if alpha.is_some() { buffers.pop() } else { None };
    let b = buffers.pop().unwrap_or_default();
    let g = buffers.pop().unwrap_or_default();
    let r = buffers.pop().unwrap_or_default();
    let too_big = || ComposeError::TooLarge {
        path: path.to_path_buf(),
    };
    Ok(Pass {
        image: LinearImage {
            width: u32::try_from(info.width).map_err(|_| too_big())?,
            height: u32::try_from(info.height).map_err(|_| too_big())?,
            rgb: [r, g, b],
            alpha: alpha_plane,
        },
        source: PassSource::Exr {
            sample_type,
            compression: info.compression,
            layer,
        },
    })
}

/// EXR sample type of the output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExrDataType {
    Half,
    Float,
}

/// EXR compressions the writer offers (names as in OpenEXR / oiiotool).
pub const EXR_COMPRESSIONS: &[(&str, exr::compression::Compression)] = &[
    ("none", exr::compression::Compression::Uncompressed),
    ("rle", exr::compression::Compression::RLE),
    ("zips", exr::compression::Compression::ZIP1),
    ("zip", exr::compression::Compression::ZIP16),
    ("piz", exr::compression::Compression::PIZ),
    ("pxr24", exr::compression::Compression::PXR24),
    ("b44", exr::compression::Compression::B44),
    ("b44a", exr::compression::Compression::B44A),
    ("dwaa", exr::compression::Compression::DWAA(None)),
    ("dwab", exr::compression::Compression::DWAB(None)),
];

/// Parses an EXR compression name (`none`, `rle`, `zips`, `zip`, `piz`, `pxr24`, `b44`, `b44a`,
/// `dwaa`, `dwab`).
pub fn parse_exr_compression(name: &str) -> Result<exr::compression::Compression, ComposeError> {
    EXR_COMPRESSIONS
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, c)| *c)
        .ok_or_else(|| ComposeError::UnknownCompression {
            name: name.to_string(),
            known: EXR_COMPRESSIONS.iter().map(|(n, _)| *n).collect(),
        })
}

/// The name of a compression in [`EXR_COMPRESSIONS`].
pub fn exr_compression_name(c: exr::compression::Compression) -> &'static str {
    EXR_COMPRESSIONS
        .iter()
        .find(|(_, k)| *k == c)
        .map_or("other", |(n, _)| n)
}

/// The default output compression: ZIP (16-line blocks), compressed in parallel by zlib-rs
/// (glassdb-image's `exr_zip`) and read by every EXR reader; docs/performance.md has the measured alternatives.
pub const DEFAULT_EXR_COMPRESSION: exr::compression::Compression =
    exr::compression::Compression::ZIP16;

/// Output file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    Exr,
    Png,
}

/// The output format from the extension (`.exr`, `.png`, any case).
pub fn output_format(path: &Path) -> Result<OutputFormat, ComposeError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("exr") => Ok(OutputFormat::Exr),
        Some("png") => Ok(OutputFormat::Png),
        _ => Err(ComposeError::OutputExtension {
            path: path.to_path_buf(),
        }),
    }
}

/// Output encoding settings; `None` fields take defaults from the transmission pass.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputOptions {
    pub exr_data_type: Option<ExrDataType>,
    pub exr_compression: Option<exr::compression::Compression>,
    /// zlib level (0–9) of ZIP/ZIPS output; `None`: OpenEXR's default, 4.
    pub exr_zip_level: Option<u32>,
    pub png_bits: Option<PngBits>,
    /// Ordered dither for 8-bit PNG output.
    pub dither: bool,
}

impl Default for OutputOptions {
    fn default() -> Self {
        OutputOptions {
            exr_data_type: None,
            exr_compression: None,
            exr_zip_level: None,
            png_bits: None,
            dither: true,
        }
    }
}

/// What was written.
#[derive(Debug, Clone, PartialEq)]
pub struct WrittenOutput {
    pub path: PathBuf,
    pub format: OutputFormat,
    /// e.g. "half, zip" or "8-bit, dithered".
    pub encoding: String,
    pub bytes: u64,
}

/// Writes `image` to `path` (format from the extension), atomically. `source` (the
/// transmission pass's storage) gives the defaults: its EXR sample type (half for 8-bit PNG
/// input, float for 16-bit), its PNG bit depth (8 for EXR input).
pub fn write_output(
    path: &Path,
    image: LinearImage,
    source: &PassSource,
    opts: &OutputOptions,
) -> Result<WrittenOutput, ComposeError> {
    let format = output_format(path)?;
    let (bytes_written, encoding) = match format {
        OutputFormat::Exr => {
            let data_type = opts.exr_data_type.unwrap_or(match source {
                PassSource::Exr {
                    sample_type: ExrSampleType::Half,
                    ..
                } => ExrDataType::Half,
                PassSource::Exr { .. } => ExrDataType::Float,
                PassSource::Png {
                    bits: PngBits::Eight,
                } => ExrDataType::Half,
                PassSource::Png {
                    bits: PngBits::Sixteen,
                } => ExrDataType::Float,
            });
            let compression = opts.exr_compression.unwrap_or(DEFAULT_EXR_COMPRESSION);
            let zip_level = match (
                glassdb_image::zip_block_lines(compression),
                opts.exr_zip_level,
            ) {
                (Some(_), level) => Some(level.unwrap_or(glassdb_image::DEFAULT_ZIP_LEVEL)),
                (None, None) => None,
                (None, Some(_)) => {
                    return Err(ComposeError::ZipLevelNotApplicable {
                        compression: exr_compression_name(compression),
                    });
                }
            };
            if let Some(level) = zip_level.filter(|&l| l > 9) {
                return Err(ComposeError::ZipLevelOutOfRange { level });
            }
            let n = write_exr(path, image, data_type, compression, zip_level)?;
            let ty = if data_type == ExrDataType::Half {
                "half"
            } else {
                "float"
            };
            let name = exr_compression_name(compression);
            let encoding = match zip_level {
                Some(level) => format!("{ty}, {name} level {level}"),
                None => format!("{ty}, {name}"),
            };
            (n, encoding)
        }
        OutputFormat::Png => {
            let bits = opts.png_bits.unwrap_or(match source {
                PassSource::Png { bits } => *bits,
                PassSource::Exr { .. } => PngBits::Eight,
            });
            let encoded = image.to_encoded(bits, opts.dither);
            let n = write_png(path, &encoded)?;
            let desc = match bits {
                PngBits::Eight if opts.dither => "8-bit sRGB, ordered dither",
                PngBits::Eight => "8-bit sRGB",
                PngBits::Sixteen => "16-bit sRGB",
            };
            (n, desc.to_string())
        }
    };
    Ok(WrittenOutput {
        path: path.to_path_buf(),
        format,
        encoding,
        bytes: bytes_written,
    })
}

fn write_exr(
    path: &Path,
    image: LinearImage,
    data_type: ExrDataType,
    compression: exr::compression::Compression,
    zip_level: Option<u32>,
) -> Result<u64, ComposeError> {
    let (w, h) = (image.width as usize, image.height as usize);
    let LinearImage {
        rgb: [r, g, b],
        alpha,
        ..
    } = image;
    let mut planes = vec![
        ExrPlane::new("R", r),
        ExrPlane::new("G", g),
        ExrPlane::new("B", b),
    ];
    if let Some(a) = alpha {
        // Alpha is linear data: quantise it linearly in lossy compressions.
        planes.push(ExrPlane {
            linear: true,
            ..ExrPlane::new("A", a)
        });
    }
    let options = ExrWriteOptions {
        storage: match data_type {
            ExrDataType::Half => ExrStorage::Half,
            ExrDataType::Float => ExrStorage::Float,
        },
        compression,
        zip_level,
    };
    let mut size = 0u64;
    glassdb_io::write_atomic(path, |out| {
        let mut counting = CountingWriter {
            inner: out,
            pos: 0,
            len: 0,
        };
        glassdb_image::write_exr_planes(&mut counting, w, h, planes, options)
            .map_err(std::io::Error::other)?;
        size = counting.len;
        Ok(())
    })?;
    Ok(size)
}

/// Tracks the file length through seeks (exr seeks back to fill its offset table).
struct CountingWriter<W> {
    inner: W,
    pos: u64,
    len: u64,
}

impl<W: std::io::Write> std::io::Write for CountingWriter<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.pos += n as u64;
        self.len = self.len.max(self.pos);
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

impl<W: std::io::Seek> std::io::Seek for CountingWriter<W> {
    fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
        self.pos = self.inner.seek(pos)?;
        Ok(self.pos)
    }
}

/// Composited output is large: fast deflate, and an `sRGB` chunk (the samples are sRGB-encoded).
const OUTPUT_PNG: PngEncodeOptions = PngEncodeOptions {
    compression: PngCompression::Fast,
    srgb_chunk: true,
};

fn write_png(path: &Path, image: &EncodedImage) -> Result<u64, ComposeError> {
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
        .map_err(|source| ComposeError::Encode {
            path: path.to_path_buf(),
            source,
        })?;
    glassdb_io::write_bytes_atomic(path, &bytes)?;
    Ok(bytes.len() as u64)
}
