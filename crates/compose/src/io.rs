//! Reading passes (through glassdb-image's one reader: EXR into flat per-channel buffers, PNG
//! into samples), choosing a pass's RGB layer, and writing the result through glassdb-image's
//! EXR and PNG encoders, atomically.

use std::fs::File;
use std::io::{BufReader, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use glassdb_image::{
    ExactExr, ExactPart, ExrColourTag, ExrImageAttributes, ExrImageOut, ExrLayerAttributes,
    ExrPart, ExrPartOut, ExrPlane, ExrSampleType, ExrStorage, ExrWriteOptions, ExrWriteReport,
    ImageError, ImageFile, ImageHeader, ImageWindows, LayerChoiceError, PlaneSamples, PngColor,
    PngCompression, PngEncodeOptions, PngPixels, PngSampleSlice, PngSamples, ReadMemory,
};

use exr::meta::attribute::{AttributeValue, Text};

use crate::ComposeError;
use crate::pixels::{EncodedImage, EncodedSamples, InputTransfer, LinearImage, PngBits};
use crate::view::ViewTransform;
use glassdb_colour::RgbSpace;

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

/// What a pass was stored as (to pick output defaults, report, and write the output like it).
#[derive(Debug, Clone, PartialEq)]
pub enum PassSource {
    Exr {
        sample_type: ExrSampleType,
        compression: exr::compression::Compression,
        /// The layer's name (`""` for bare R, G, B).
        layer: String,
        /// The part holding it, and the names of its R, G, B (and A) channels as stored.
        part: usize,
        channel_names: Vec<String>,
    },
    Png {
        bits: PngBits,
    },
}

impl PassSource {
    /// Whether the pass states its pixels' coordinates (an EXR; a PNG does not).
    pub fn has_coordinates(&self) -> bool {
        !matches!(self, PassSource::Png { .. })
    }
}

/// A decoded pass: linear, premultiplied RGB(A) over its data window.
#[derive(Debug, Clone)]
pub struct Pass {
    pub image: LinearImage,
    pub windows: ImageWindows,
    pub source: PassSource,
}

/// What a pass's header says, read and checked before any pixel is decoded
/// ([`read_pass_header`]).
#[derive(Debug, Clone)]
pub struct PassHeader {
    /// The pass's own windows (a PNG: its size at the origin).
    pub windows: ImageWindows,
    /// How it is stored (as [`Pass::source`] will say).
    pub source: PassSource,
    /// The colour attributes of the layer's part (none for a PNG).
    pub colour: ExrColourTag,
    /// An EXR's parts (none for a PNG).
    pub parts: std::sync::Arc<[ExrPart]>,
    /// Reading it: the file and the decoder's buffers while reading, the linear planes after.
    pub memory: ReadMemory,
}

/// The plane layers of a reflection file holding several planes' passes (docs/compose.md,
/// "Several planes in one file"): the layer names `plane0`, `plane1`, … in plane order, from
/// the header alone; `None` for a PNG or an EXR without such layers. Planes must be numbered
/// from 0 without gaps.
pub fn plane_layers_of(path: &Path, max_pixels: u64) -> Result<Option<Vec<String>>, ComposeError> {
    let (_, header, _) = open_seekable(path, max_pixels)?;
    let ImageHeader::Exr(headers) = header else {
        return Ok(None);
    };
    let planes = glassdb_image::plane_layers(&headers.parts);
    if planes.is_empty() {
        return Ok(None);
    }
    for (expected, (k, _)) in planes.iter().enumerate() {
        if *k as usize != expected {
            return Err(ComposeError::PlaneLayers {
                path: path.to_path_buf(),
                problem: if (*k as usize) < expected {
                    format!("two layers are plane {k}")
                } else {
                    format!(
                        "plane {expected} is missing (the layers go to plane {})",
                        planes.len() - 1
                    )
                },
                layers: planes.iter().map(|(_, n)| n.clone()).collect(),
            });
        }
    }
    Ok(Some(planes.into_iter().map(|(_, n)| n).collect()))
}

/// Reads a pass's header only (a PNG's chunks up to the pixel data, an EXR's headers; no pixel
/// is decompressed) and checks what [`read_pass`] would refuse from it: an unknown format, a
/// missing or ambiguous layer, too many pixels, deep data, subsampled channels.
pub fn read_pass_header(path: &Path, opts: &PassReadOptions) -> Result<PassHeader, ComposeError> {
    pass_header(path, opts, false)
}

/// [`read_pass_header`] of a reflection pass, read as [`read_pass_rows`] reads it: an EXR's
/// memory counts its compressed blocks, not the whole file, and the planes of its whole data
/// window (the rows its plane needs are known only once the mask is decoded).
pub fn read_refl_header(path: &Path, opts: &PassReadOptions) -> Result<PassHeader, ComposeError> {
    pass_header(path, opts, true)
}

fn pass_header(
    path: &Path,
    opts: &PassReadOptions,
    seeking: bool,
) -> Result<PassHeader, ComposeError> {
    let (_, header, file_len) = open_seekable(path, opts.max_pixels)?;
    match header {
        ImageHeader::Png(h) => {
            let planes = 3 + u64::from(h.channels == 2 || h.channels == 4);
            Ok(PassHeader {
                windows: ImageWindows::full_frame(h.width as usize, h.height as usize),
                source: PassSource::Png {
                    bits: if h.sixteen_bit {
                        PngBits::Sixteen
                    } else {
                        PngBits::Eight
                    },
                },
                colour: ExrColourTag::default(),
                parts: Default::default(),
                memory: ReadMemory::png(file_len, &h)
                    .keeping(h.pixel_count().saturating_mul(4 * planes)),
            })
        }
        ImageHeader::Exr(headers) => {
            let parts = headers.parts;
            let chosen = choose_layer(&parts, opts.layer.as_deref(), path)?;
            let channels = layer_channels(&chosen);
            let info = parts.get(chosen.part).ok_or_else(|| {
                decode_err(
                    path,
                    ImageError::Unsupported {
                        feature: format!("part {} (the file has {})", chosen.part, parts.len()),
                    },
                )
            })?;
            glassdb_image::check_exr_readable(info, &channels, opts.max_pixels)
                .map_err(|source| decode_err(path, source))?;
            let source = exr_source(info, chosen, &channels);
            Ok(PassHeader {
                windows: info.windows(),
                colour: info.colour.clone(),
                memory: if seeking {
                    ReadMemory::exr_planes_from_file(file_len, info.pixel_count(), channels.len())
                } else {
                    ReadMemory::exr_planes(file_len, info.pixel_count(), channels.len())
                },
                source,
                parts,
            })
        }
    }
}

/// The RGB layer `wanted` names (or the default one), as compose's errors.
fn choose_layer(
    parts: &[ExrPart],
    wanted: Option<&str>,
    path: &Path,
) -> Result<glassdb_image::RgbLayer, ComposeError> {
    glassdb_image::choose_rgb_layer(parts, wanted).map_err(|e| {
        let path = path.to_path_buf();
        match e {
            LayerChoiceError::NoRgb { available } => ComposeError::NoRgb { path, available },
            LayerChoiceError::NotFound { wanted, layers } => ComposeError::LayerNotFound {
                path,
                layer: wanted,
                candidates: layers,
            },
            LayerChoiceError::Ambiguous { layers, .. } => ComposeError::AmbiguousLayer {
                path,
                candidates: layers,
            },
        }
    })
}

/// Reads a pass file (format from its bytes).
pub fn read_pass(path: &Path, opts: &PassReadOptions) -> Result<Pass, ComposeError> {
    let bytes = read_file(path)?;
    read_pass_bytes(&bytes, path, opts)
}

/// [`read_pass`] of what rows `y_first..=y_last` (frame pixel coordinates) need: an EXR's
/// blocks holding them only (a reflection pass decodes the rows of its plane's glass); a PNG
/// whole.
pub fn read_pass_rows(
    path: &Path,
    opts: &PassReadOptions,
    rows: (i64, i64),
) -> Result<Pass, ComposeError> {
    let (file, header, len) = open_seekable(path, opts.max_pixels)?;
    let ImageHeader::Exr(headers) = header else {
        let bytes = glassdb_io::read_open_input(file, len, glassdb_io::limits::IMAGE)
            .map_err(|cause| read_err(path, cause))?;
        return read_pass_bytes(&bytes, path, opts);
    };
    read_exr_pass(&headers.parts, path, opts, |part, channels| {
        let max = opts.max_pixels;
        glassdb_image::read_exr_channel_rows_from(
            file,
            &headers.parts,
            part,
            channels,
            max,
            Some(rows),
        )
    })
}

/// An input image opened to be read by seeking (or for its header alone): the file, back at its
/// start, its header and its size (the size limit was checked from the metadata as opened).
fn open_seekable(
    path: &Path,
    max_pixels: u64,
) -> Result<(BufReader<File>, ImageHeader, u64), ComposeError> {
    let (file, len) = glassdb_io::open_input(path, glassdb_io::limits::IMAGE)
        .map_err(|cause| read_err(path, cause))?;
    let mut file = BufReader::with_capacity(1 << 16, file.into_inner());
    let header = glassdb_image::read_image_header(&mut file, max_pixels)
        .map_err(|source| decode_err(path, source))?;
    rewind(&mut file, path)?;
    Ok((file, header, len))
}

fn rewind(file: &mut BufReader<File>, path: &Path) -> Result<(), ComposeError> {
    file.seek(SeekFrom::Start(0))
        .map(drop)
        .map_err(|e| read_err(path, glassdb_io::InputError::from(e)))
}

fn read_err(path: &Path, cause: glassdb_io::InputError) -> ComposeError {
    ComposeError::Read {
        path: path.to_path_buf(),
        cause,
    }
}

/// The bytes of an input image, of at most [`glassdb_io::limits::IMAGE`].
pub fn read_file(path: &Path) -> Result<Vec<u8>, ComposeError> {
    glassdb_io::read_input(path, glassdb_io::limits::IMAGE).map_err(|cause| read_err(path, cause))
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
        ImageFile::Exr(exr) => read_exr_pass(exr.parts(), path, opts, |part, channels| {
            exr.read_channels(part, channels)
        }),
    }
}

fn decode_err(path: &Path, source: ImageError) -> ComposeError {
    ComposeError::Decode {
        path: path.to_path_buf(),
        source,
    }
}

/// A PNG pass: its samples mapped to linear light by `transfer`, and its straight alpha (PNG's
/// convention) premultiplied into the colour, as EXR passes store it.
fn pass_from_png(png: PngPixels, transfer: InputTransfer) -> Pass {
    let bits = match png.samples {
        PngSamples::U8(_) => PngBits::Eight,
        PngSamples::U16(_) => PngBits::Sixteen,
    };
    let windows = ImageWindows::full_frame(png.width as usize, png.height as usize);
    let encoded = EncodedImage {
        width: png.width,
        height: png.height,
        channels: png.channels,
        samples: match png.samples {
            PngSamples::U8(v) => EncodedSamples::U8(v),
            PngSamples::U16(v) => EncodedSamples::U16(v),
        },
    };
    let mut image = encoded.to_linear(transfer);
    image.premultiply();
    Pass {
        image,
        windows,
        source: PassSource::Png { bits },
    }
}

/// The pass in the RGB layer of an EXR with parts `parts`; `decode(part, channels)` decodes
/// the chosen channels (all rows, or those a plane needs).
fn read_exr_pass(
    parts: &[ExrPart],
    path: &Path,
    opts: &PassReadOptions,
    decode: impl FnOnce(usize, &[usize]) -> Result<(ExrPart, Vec<Vec<f32>>), ImageError>,
) -> Result<Pass, ComposeError> {
    let chosen = choose_layer(parts, opts.layer.as_deref(), path)?;
    let channels = layer_channels(&chosen);
    let (info, mut buffers) =
        decode(chosen.part, &channels).map_err(|source| decode_err(path, source))?;
    let alpha_plane = if chosen.alpha.is_some() {
        buffers.pop()
    } else {
        None
    };
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
        windows: info.windows(),
        source: exr_source(&info, chosen, &channels),
    })
}

/// The channels of `layer` a pass decodes: R, G, B, then A where the layer has one.
fn layer_channels(layer: &glassdb_image::RgbLayer) -> Vec<usize> {
    let mut channels = layer.rgb.to_vec();
    channels.extend(layer.alpha);
    channels
}

/// What an EXR pass decoded from `layer`'s `channels` of part `info` is.
fn exr_source(info: &ExrPart, layer: glassdb_image::RgbLayer, channels: &[usize]) -> PassSource {
    PassSource::Exr {
        sample_type: info
            .channels
            .get(layer.rgb[0])
            .map_or(ExrSampleType::Float, |c| c.sample_type),
        compression: info.compression,
        layer: layer.name,
        part: layer.part,
        channel_names: channel_names(info, channels),
    }
}

/// The names of `channels` (indices) of part `info`, as stored.
fn channel_names(info: &ExrPart, channels: &[usize]) -> Vec<String> {
    channels
        .iter()
        .filter_map(|&c| info.channels.get(c).map(|c| c.name.clone()))
        .collect()
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

/// The default output compression: ZIP (16-line blocks), compressed in parallel by libdeflate
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
    /// View transform of PNG output (`None`: [`ViewTransform::Standard`]). Given for an EXR
    /// output, which stays scene-linear, it is an error ([`ComposeError::ViewOnExr`]).
    pub view: Option<ViewTransform>,
    /// EXR output keeps the transmission file's other channels and parts (Z, AOVs, other
    /// views), unchanged.
    pub keep_channels: bool,
    /// EXR output writes the composite as this new layer (`NAME.R`, …) beside the original
    /// channels instead of replacing the transmission pass's RGB.
    pub output_layer: Option<String>,
    /// Attributes glassdb adds to EXR output (name, text): its version, the registry's hash.
    pub provenance: Vec<(String, String)>,
}

impl Default for OutputOptions {
    fn default() -> Self {
        OutputOptions {
            exr_data_type: None,
            exr_compression: None,
            exr_zip_level: None,
            png_bits: None,
            dither: true,
            view: None,
            keep_channels: true,
            output_layer: None,
            provenance: Vec::new(),
        }
    }
}

/// What of the transmission pass's file the output carries besides the composite.
#[derive(Debug, Clone)]
pub struct OutputFrame {
    /// The output's data and display windows: the transmission pass's.
    pub windows: ImageWindows,
    /// For an EXR transmission pass: its attributes, and its other channels when kept.
    pub exr: Option<ExrCarried>,
    /// The colour space to tag an EXR output with (`chromaticities`, and `colorInteropID` on
    /// the composite's part); `None` leaves the carried attributes as they are.
    pub tag_space: Option<RgbSpace>,
}

/// The parts of an EXR transmission file written into the output.
#[derive(Debug, Clone)]
pub enum ExrCarried {
    /// The file's shared attributes and the chosen part's own; no other channels. The
    /// composite keeps the layer's channel names (`names`: R, G, B, then A) when the file holds
    /// nothing else and channels are kept; `None`: bare `R`, `G`, `B`, `A`.
    Attributes {
        image: Box<ExrImageAttributes>,
        part: Box<ExrLayerAttributes>,
        names: Option<Vec<String>>,
    },
    /// Every part exactly as stored; the composite replaces (or goes beside) the chosen layer's
    /// channels `channel_names` (R, G, B, then A if any) of part `part`.
    Whole {
        file: ExactExr,
        part: usize,
        channel_names: Vec<String>,
    },
}

impl OutputFrame {
    /// A whole frame of `width × height` at the origin, with nothing carried over.
    pub fn whole(width: u32, height: u32) -> OutputFrame {
        OutputFrame {
            windows: ImageWindows::full_frame(width as usize, height as usize),
            exr: None,
            tag_space: None,
        }
    }

    /// The frame of a transmission pass read from `bytes` (the file `path`): attributes always,
    /// every part and channel when `keep_channels` and the file holds more than the layer or
    /// the composite goes `beside` the original layer.
    pub fn of_transmission(
        pass: &Pass,
        bytes: &[u8],
        path: &Path,
        (keep_channels, beside): (bool, bool),
        max_pixels: u64,
    ) -> Result<OutputFrame, ComposeError> {
        let PassSource::Exr {
            part,
            channel_names,
            ..
        } = &pass.source
        else {
            return Ok(OutputFrame {
                windows: pass.windows,
                exr: None,
                tag_space: None,
            });
        };
        let parts = glassdb_image::read_exr_headers(bytes).map_err(|s| decode_err(path, s))?;
        if !carries_whole_file(&parts, channel_names, (keep_channels, beside)) {
            return Self::with_attributes(pass, &parts, bytes, path, keep_channels);
        }
        let file = glassdb_image::read_exr_exact(bytes, max_pixels).map_err(|source| {
            ComposeError::KeepChannels {
                path: path.to_path_buf(),
                source,
            }
        })?;
        Ok(OutputFrame {
            windows: pass.windows,
            exr: Some(ExrCarried::Whole {
                file,
                part: *part,
                channel_names: channel_names.clone(),
            }),
            tag_space: None,
        })
    }

    /// The frame of an EXR transmission pass (`parts`, the file's headers) of which only the
    /// attributes are carried over, read from `header` (the file from its start: only its
    /// headers are read).
    fn with_attributes(
        pass: &Pass,
        parts: &[ExrPart],
        header: impl std::io::Read,
        path: &Path,
        keep_channels: bool,
    ) -> Result<OutputFrame, ComposeError> {
        let (part, channel_names) = match &pass.source {
            PassSource::Exr {
                part,
                channel_names,
                ..
            } => (*part, channel_names),
            PassSource::Png { .. } => {
                return Ok(OutputFrame {
                    windows: pass.windows,
                    exr: None,
                    tag_space: None,
                });
            }
        };
        let (image, part) =
            glassdb_image::read_exr_attributes(header, part).map_err(|s| decode_err(path, s))?;
        Ok(OutputFrame {
            windows: pass.windows,
            exr: Some(ExrCarried::Attributes {
                image: Box::new(image),
                part: Box::new(part),
                names: (keep_channels && only_the_layer(parts, channel_names))
                    .then(|| channel_names.clone()),
            }),
            tag_space: None,
        })
    }
}

/// Reads the transmission pass and what the output carries over from it, from one open file
/// (a file replaced meanwhile cannot mix two versions): an EXR whose other channels are not
/// carried is decoded by seeking (its blocks are read as they are decoded, never the whole
/// file at once), then its headers again for the attributes; otherwise the whole file is read.
pub fn read_transmission(
    path: &Path,
    opts: &PassReadOptions,
    keep: (bool, bool),
    max_pixels: u64,
) -> Result<(Pass, OutputFrame), ComposeError> {
    let (mut file, header, len) = open_seekable(path, opts.max_pixels)?;
    if let ImageHeader::Exr(headers) = &header {
        let chosen = choose_layer(&headers.parts, opts.layer.as_deref(), path)?;
        let names = headers
            .parts
            .get(chosen.part)
            .map_or_else(Vec::new, |p| channel_names(p, &layer_channels(&chosen)));
        if !carries_whole_file(&headers.parts, &names, keep) {
            let pass = read_exr_pass(&headers.parts, path, opts, |part, channels| {
                glassdb_image::read_exr_channel_rows_from(
                    &mut file,
                    &headers.parts,
                    part,
                    channels,
                    opts.max_pixels,
                    None,
                )
            })?;
            rewind(&mut file, path)?;
            let frame = OutputFrame::with_attributes(&pass, &headers.parts, file, path, keep.0)?;
            return Ok((pass, frame));
        }
    }
    let bytes = glassdb_io::read_open_input(file, len, glassdb_io::limits::IMAGE)
        .map_err(|cause| read_err(path, cause))?;
    let pass = read_pass_bytes(&bytes, path, opts)?;
    let frame = OutputFrame::of_transmission(&pass, &bytes, path, keep, max_pixels)?;
    Ok((pass, frame))
}

/// What was written.
#[derive(Debug, Clone, PartialEq)]
pub struct WrittenOutput {
    pub path: PathBuf,
    pub format: OutputFormat,
    /// e.g. "half, zip" or "8-bit, dithered".
    pub encoding: String,
    pub bytes: u64,
    /// Finite samples too large for half float, written as ±Inf (half output only).
    pub half_overflow: u64,
    /// Channels and parts carried over from the transmission file besides the composite.
    pub kept_channels: usize,
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
    let frame = OutputFrame::whole(image.width, image.height);
    write_output_in_frame(path, image, frame, source, opts)
}

/// [`write_output`] into `frame`: the transmission pass's windows, and for EXR output its
/// attributes and the channels carried over.
pub fn write_output_in_frame(
    path: &Path,
    mut image: LinearImage,
    frame: OutputFrame,
    source: &PassSource,
    opts: &OutputOptions,
) -> Result<WrittenOutput, ComposeError> {
    let format = output_format(path)?;
    check_view(path, opts)?;
    let mut half_overflow = 0;
    let mut kept_channels = 0;
    let (bytes_written, encoding) = match format {
        OutputFormat::Exr => {
            let data_type = output_data_type(source, opts);
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
            let out = exr_output(image, frame, opts);
            kept_channels = out.1;
            let options = ExrWriteOptions {
                storage: match data_type {
                    ExrDataType::Half => ExrStorage::Half,
                    ExrDataType::Float => ExrStorage::Float,
                },
                compression,
                zip_level,
            };
            let (n, report) = write_exr(path, out.0, options)?;
            half_overflow = report.half_overflow;
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
            let bits = output_png_bits(source, opts);
            image.unpremultiply();
            let view = opts.view.clone().unwrap_or_default();
            let encoded = image.to_encoded_view(bits, opts.dither, &view);
            let n = write_png(path, &encoded)?;
            let depth = match bits {
                PngBits::Eight => "8-bit",
                PngBits::Sixteen => "16-bit",
            };
            let mut desc = format!("{depth} {}", view.describe());
            if bits == PngBits::Eight && opts.dither {
                desc += ", ordered dither";
            }
            (n, desc)
        }
    };
    Ok(WrittenOutput {
        path: path.to_path_buf(),
        format,
        encoding,
        bytes: bytes_written,
        half_overflow,
        kept_channels,
    })
}

/// The EXR output's sample type: as asked, else the transmission pass's (half for 8-bit PNG
/// input, float for 16-bit).
pub fn output_data_type(source: &PassSource, opts: &OutputOptions) -> ExrDataType {
    opts.exr_data_type.unwrap_or(match source {
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
    })
}

/// The PNG output's bits per sample: as asked, else the transmission pass's (8 for EXR input).
pub fn output_png_bits(source: &PassSource, opts: &OutputOptions) -> PngBits {
    opts.png_bits.unwrap_or(match source {
        PassSource::Png { bits } => *bits,
        PassSource::Exr { .. } => PngBits::Eight,
    })
}

/// Whether the output carries every part and channel of the transmission file (`parts`, its
/// chosen layer's channels `channel_names`): when they are kept and the file holds more than
/// the layer, or the composite goes beside the original layer.
pub fn carries_whole_file(
    parts: &[ExrPart],
    channel_names: &[String],
    (keep_channels, beside): (bool, bool),
) -> bool {
    keep_channels && (beside || !only_the_layer(parts, channel_names))
}

/// Whether the file (`parts`) holds nothing but the chosen layer's channels `channel_names`.
fn only_the_layer(parts: &[ExrPart], channel_names: &[String]) -> bool {
    parts.len() == 1
        && parts
            .first()
            .is_some_and(|p| p.channels.len() == channel_names.len())
}

/// Refuses a view transform for an EXR output (scene-linear) before any work is done.
pub fn check_view(path: &Path, opts: &OutputOptions) -> Result<(), ComposeError> {
    if opts.view.is_some() && output_format(path)? == OutputFormat::Exr {
        return Err(ComposeError::ViewOnExr {
            path: path.to_path_buf(),
        });
    }
    Ok(())
}

/// The R, G, B (and A) planes of the composite, named `prefix` + channel.
fn composite_planes(image: LinearImage, names: &[String]) -> Vec<ExrPlane> {
    let LinearImage {
        rgb: [r, g, b],
        alpha,
        ..
    } = image;
    let mut planes: Vec<ExrPlane> = [r, g, b]
        .into_iter()
        .zip(names)
        .map(|(v, n)| ExrPlane::new(n, v))
        .collect();
    if let (Some(a), Some(name)) = (alpha, names.get(3)) {
        // Alpha is linear data: quantise it linearly in lossy compressions.
        planes.push(ExrPlane {
            linear: true,
            ..ExrPlane::new(name, a)
        });
    }
    planes
}

/// `R`, `G`, `B`, `A` under `layer` (`layer.R`, …), or bare.
fn layer_channel_names(layer: Option<&str>) -> Vec<String> {
    ["R", "G", "B", "A"]
        .iter()
        .map(|c| match layer {
            Some(l) => format!("{l}.{c}"),
            None => c.to_string(),
        })
        .collect()
}

/// The EXR file to write: the composite in the transmission pass's windows, with its file's
/// attributes, its other channels and parts when carried, and glassdb's provenance. Returns
/// the file and the number of channels carried over.
fn exr_output(
    image: LinearImage,
    frame: OutputFrame,
    opts: &OutputOptions,
) -> (ExrImageOut, usize) {
    let OutputFrame {
        windows,
        exr,
        tag_space,
    } = frame;
    let new_layer = opts.output_layer.as_deref();
    let (mut attributes, parts, kept) = match exr {
        None => (
            ExrImageAttributes::new(to_bounds(&windows.display)),
            vec![ExrPartOut {
                data_window: windows.data,
                attributes: ExrLayerAttributes::default(),
                planes: composite_planes(image, &layer_channel_names(new_layer)),
            }],
            0,
        ),
        Some(ExrCarried::Attributes {
            image: shared,
            part,
            names,
        }) => {
            let names = match (names, new_layer) {
                (Some(names), None) => names,
                _ => layer_channel_names(new_layer),
            };
            (
                *shared,
                vec![ExrPartOut {
                    data_window: windows.data,
                    attributes: *part,
                    planes: composite_planes(image, &names),
                }],
                0,
            )
        }
        Some(ExrCarried::Whole {
            file,
            part,
            channel_names,
        }) => {
            let (parts, kept) = carried_parts(image, file.parts, part, &channel_names, new_layer);
            (file.attributes, parts, kept)
        }
    };
    for (name, value) in &opts.provenance {
        if let (Some(name), Some(value)) = (exr_text(name), exr_text(value)) {
            attributes.other.insert(name, AttributeValue::Text(value));
        }
    }
    let mut parts = parts;
    if let Some(space) = tag_space {
        tag_colour(&mut attributes, &mut parts, space);
    }
    (
        ExrImageOut {
            display_window: windows.display,
            attributes,
            parts,
        },
        kept,
    )
}

/// Tags the output with `space`: `chromaticities` (shared by every part), and
/// `colorInteropID` on each part holding the composite's R, G, B (other parts, e.g. Blender's
/// `data` passes, keep theirs).
fn tag_colour(attributes: &mut ExrImageAttributes, parts: &mut [ExrPartOut], space: RgbSpace) {
    let c = space.chromaticities().map(|v| v as f32);
    attributes.chromaticities = Some(exr::meta::attribute::Chromaticities {
        red: exr::math::Vec2(c[0], c[1]),
        green: exr::math::Vec2(c[2], c[3]),
        blue: exr::math::Vec2(c[4], c[5]),
        white: exr::math::Vec2(c[6], c[7]),
    });
    let id = Text::from(space.interop_id());
    for part in parts {
        let holds_composite = part
            .planes
            .iter()
            .any(|p| matches!(p.samples, PlaneSamples::Converted(_)) && !p.linear);
        if holds_composite {
            part.attributes.other.insert(
                Text::from("colorInteropID"),
                AttributeValue::Text(id.clone()),
            );
        }
    }
}

/// Every part of the transmission file with the composite in part `part`: replacing the
/// layer's R, G, B (its alpha is the composite's alpha, unchanged), or as the new layer
/// `new_layer` (a new part of that name in a multi-part file).
fn carried_parts(
    image: LinearImage,
    parts: Vec<ExactPart>,
    part: usize,
    channel_names: &[String],
    new_layer: Option<&str>,
) -> (Vec<ExrPartOut>, usize) {
    let multi_part = parts.len() > 1;
    let mut kept = 0;
    let mut out: Vec<ExrPartOut> = Vec::with_capacity(parts.len() + 1);
    let mut composite = Some(image);
    for (k, p) in parts.into_iter().enumerate() {
        let mut planes: Vec<ExrPlane> = Vec::with_capacity(p.channels.len() + 4);
        let replacing = k == part && new_layer.is_none();
        for (name, samples) in p.channels {
            // The layer's R, G, B are replaced; its A is kept exactly (it is the output's).
            if replacing && channel_names.iter().take(3).any(|n| *n == name) {
                continue;
            }
            kept += 1;
            planes.push(ExrPlane {
                name,
                samples: PlaneSamples::Exact(samples),
                linear: false,
            });
        }
        if k == part
            && let Some(mut image) = composite.take()
        {
            let names = match new_layer {
                None => channel_names.to_vec(),
                Some(l) => layer_channel_names(Some(l)),
            };
            if new_layer.is_none() {
                image.alpha = None;
            }
            if multi_part && new_layer.is_some() {
                let mut attributes = p.attributes.clone();
                attributes.layer_name = new_layer.and_then(exr_text);
                out.push(ExrPartOut {
                    data_window: p.data_window,
                    attributes: p.attributes,
                    planes,
                });
                out.push(ExrPartOut {
                    data_window: p.data_window,
                    attributes,
                    planes: composite_planes(image, &names),
                });
                continue;
            }
            planes.extend(composite_planes(image, &names));
        }
        out.push(ExrPartOut {
            data_window: p.data_window,
            attributes: p.attributes,
            planes,
        });
    }
    (out, kept)
}

/// EXR text (Latin-1 bytes); `None` for text it cannot hold.
fn exr_text(s: &str) -> Option<Text> {
    Text::new_or_none(s)
}

/// Checks that `name` can be an EXR layer name (Latin-1, not empty, no dot at either end).
pub fn check_layer_name(name: &str) -> Result<(), ComposeError> {
    if exr_text(name).is_none() || name.is_empty() || name.starts_with('.') || name.ends_with('.') {
        return Err(ComposeError::BadLayerName {
            name: name.to_string(),
        });
    }
    Ok(())
}

fn to_bounds(w: &glassdb_image::PixelWindow) -> exr::meta::attribute::IntegerBounds {
    exr::meta::attribute::IntegerBounds::new(
        exr::math::Vec2(w.x, w.y),
        exr::math::Vec2(w.width, w.height),
    )
}

fn write_exr(
    path: &Path,
    image: ExrImageOut,
    options: ExrWriteOptions,
) -> Result<(u64, ExrWriteReport), ComposeError> {
    let mut size = 0u64;
    let mut report = ExrWriteReport::default();
    glassdb_io::write_atomic(path, |out| {
        let mut counting = CountingWriter {
            inner: out,
            pos: 0,
            len: 0,
        };
        report = glassdb_image::write_exr_image(&mut counting, image, options)
            .map_err(std::io::Error::other)?;
        size = counting.len;
        Ok(())
    })?;
    Ok((size, report))
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

impl<W: Seek> Seek for CountingWriter<W> {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
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
