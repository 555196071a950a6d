//! Reading passes through glassdb-image's one reader (EXR into flat per-channel buffers,
//! PNG into samples): the header alone first ([`read_pass_header`], [`read_refl_header`]),
//! then the pixels of the RGB layer each pass names, as linear premultiplied planes
//! ([`read_pass`], [`read_pass_rows`]).

use std::fs::File;
use std::io::{BufReader, Seek, SeekFrom};
use std::path::Path;

use glassdb_image::{
    ExrColourTag, ExrPart, ExrSampleType, ImageError, ImageFile, ImageHeader, ImageWindows,
    LayerChoiceError, PngPixels, PngSamples, ReadMemory,
};

use crate::PassError;
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
    /// Read the pass as this weighted sum of its light-group layers instead of `layer`
    /// (`None`: one layer).
    pub light_mix: Option<LightMix>,
}

impl Default for PassReadOptions {
    fn default() -> Self {
        PassReadOptions {
            layer: None,
            transfer: InputTransfer::Srgb,
            max_pixels: glassdb_image::DEFAULT_MAX_PIXELS,
            light_mix: None,
        }
    }
}

/// A pass read as a weighted sum of its light-group layers, `Σ_g w_g · layer_g` per channel
/// (the relit swap, docs/compose.md "Relit swap"): every group's layer of one EXR part decoded
/// in one pass over the file, so that P parts cost one read, not P.
#[derive(Debug, Clone, Default)]
pub struct LightMix {
    /// Each light group (as [`crate::light_group_of_layer`] names it) and its R, G, B weights.
    pub weights: Vec<(String, [f32; 3])>,
}

impl PartialEq for LightMix {
    /// Equal weights bit for bit (so that options stay `Eq`).
    fn eq(&self, other: &Self) -> bool {
        self.weights.len() == other.weights.len()
            && self.weights.iter().zip(&other.weights).all(|(a, b)| {
                a.0 == b.0
                    && a.1
                        .iter()
                        .zip(&b.1)
                        .all(|(x, y)| x.to_bits() == y.to_bits())
            })
    }
}

impl Eq for LightMix {}

/// The layers of `mix`'s groups in an EXR with parts `parts`, in the mix's order: each group's
/// layer must exist and all must lie in one part (decoded together).
fn mix_layers(
    parts: &[ExrPart],
    mix: &LightMix,
    path: &Path,
) -> Result<Vec<glassdb_image::RgbLayer>, PassError> {
    let layers = glassdb_image::rgb_layers(parts);
    let mut out: Vec<glassdb_image::RgbLayer> = Vec::with_capacity(mix.weights.len());
    for (group, _) in &mix.weights {
        let layer = layers
            .iter()
            .find(|l| crate::light_group_of_layer(&l.name).is_some_and(|(g, _)| g == group))
            .ok_or_else(|| PassError::LayerNotFound {
                path: path.to_path_buf(),
                layer: format!("of light group {group}"),
                candidates: layers.iter().map(|l| l.label()).collect(),
            })?;
        if let Some(first) = out.first().filter(|f| f.part != layer.part) {
            return Err(PassError::LightMixParts {
                path: path.to_path_buf(),
                layers: vec![first.name.clone(), layer.name.clone()],
            });
        }
        out.push(layer.clone());
    }
    if out.is_empty() {
        return Err(PassError::LayerNotFound {
            path: path.to_path_buf(),
            layer: "of no light group (an empty mix)".into(),
            candidates: layers.iter().map(|l| l.label()).collect(),
        });
    }
    Ok(out)
}

/// The layer a pass is read from, and the channels decoded: `opts.layer`'s (R, G, B, then A),
/// or with a [`LightMix`] the first group's layer and every group's R, G, B.
pub(crate) fn read_layer(
    parts: &[ExrPart],
    opts: &PassReadOptions,
    path: &Path,
) -> Result<(glassdb_image::RgbLayer, Vec<usize>), PassError> {
    match &opts.light_mix {
        None => {
            let chosen = choose_layer(parts, opts.layer.as_deref(), path)?;
            let channels = layer_channels(&chosen);
            Ok((chosen, channels))
        }
        Some(mix) => {
            let layers = mix_layers(parts, mix, path)?;
            let channels = layers.iter().flat_map(|l| l.rgb).collect();
            let mut first = layers[0].clone();
            first.alpha = None;
            Ok((first, channels))
        }
    }
}

/// `Σ_g w_g · buffers[3g + c]` per channel `c`: the weighted sum of the groups' R, G, B planes
/// decoded in mix order.
fn mix_planes(mix: &LightMix, buffers: Vec<Vec<f32>>) -> [Vec<f32>; 3] {
    let mut planes = buffers.into_iter();
    let mut out: [Vec<f32>; 3] = Default::default();
    for (_, w) in &mix.weights {
        for (c, sum) in out.iter_mut().enumerate() {
            let plane = planes.next().unwrap_or_default();
            if sum.is_empty() {
                *sum = plane;
                sum.iter_mut().for_each(|v| *v *= w[c]);
            } else {
                sum.iter_mut().zip(&plane).for_each(|(s, v)| *s += w[c] * v);
            }
        }
    }
    out
}

/// What a pass was stored as (to pick output defaults, report, and write the output like it).
#[derive(Debug, Clone, PartialEq)]
pub enum PassSource {
    /// An EXR layer.
    Exr {
        /// The R channel's sample type (half, float, uint).
        sample_type: ExrSampleType,
        /// The part's compression.
        compression: exr::compression::Compression,
        /// The layer's name (`""` for bare R, G, B).
        layer: String,
        /// The part holding it, and the names of its R, G, B (and A) channels as stored.
        part: usize,
        /// The layer's channel names as stored: R, G, B, then A if any.
        channel_names: Vec<String>,
    },
    /// A PNG.
    Png {
        /// Its bits per sample.
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
    /// The pixels of its data window.
    pub image: LinearImage,
    /// Its data and display windows (a PNG: its size at the origin).
    pub windows: ImageWindows,
    /// What it was stored as.
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
    /// An EXR's parts (none for a PNG), shared with every other header of the same file.
    pub parts: std::sync::Arc<[ExrPart]>,
    /// Reading it: the file and the decoder's buffers while reading, the linear planes after.
    pub memory: ReadMemory,
}

/// The pane groups' reflection layers `plane<K>.group<G>` of an EXR file (issue 27), as (K, G,
/// layer name); empty for a PNG or a file without them.
pub fn plane_group_layers_of(
    path: &Path,
    max_pixels: u64,
) -> Result<Vec<(u32, u32, String)>, PassError> {
    let (_, header, _) = open_seekable(path, max_pixels)?;
    Ok(match header {
        ImageHeader::Exr(headers) => glassdb_image::plane_group_layers(&headers.parts),
        _ => Vec::new(),
    })
}

/// The plane layers of a reflection file holding several planes' passes (docs/compose.md,
/// "Several planes in one file"): the layer names `plane0`, `plane1`, … in plane order, from
/// the header alone; `None` for a PNG or an EXR without such layers. Planes must be numbered
/// from 0 without gaps.
pub fn plane_layers_of(path: &Path, max_pixels: u64) -> Result<Option<Vec<String>>, PassError> {
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
            return Err(PassError::PlaneLayers {
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
pub fn read_pass_header(path: &Path, opts: &PassReadOptions) -> Result<PassHeader, PassError> {
    pass_header(path, opts, false)
}

/// [`read_pass_header`] of a reflection pass, read as [`read_pass_rows`] reads it: an EXR's
/// memory counts its compressed blocks, not the whole file, and the planes of its whole data
/// window (the rows its plane needs are known only once the mask is decoded).
pub fn read_refl_header(path: &Path, opts: &PassReadOptions) -> Result<PassHeader, PassError> {
    pass_header(path, opts, true)
}

fn pass_header(
    path: &Path,
    opts: &PassReadOptions,
    seeking: bool,
) -> Result<PassHeader, PassError> {
    let (_, header, file_len) = open_seekable(path, opts.max_pixels)?;
    match header {
        ImageHeader::Png(_) if opts.light_mix.is_some() => Err(PassError::LightMixNotExr {
            path: path.to_path_buf(),
        }),
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
            let (chosen, channels) = read_layer(&parts, opts, path)?;
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
            let source = exr_source(info, chosen.clone(), &layer_channels(&chosen));
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
pub(crate) fn choose_layer(
    parts: &[ExrPart],
    wanted: Option<&str>,
    path: &Path,
) -> Result<glassdb_image::RgbLayer, PassError> {
    glassdb_image::choose_rgb_layer(parts, wanted).map_err(|e| {
        let path = path.to_path_buf();
        match e {
            LayerChoiceError::NoRgb { available } => PassError::NoRgb { path, available },
            LayerChoiceError::NotFound { wanted, layers } => PassError::LayerNotFound {
                path,
                layer: wanted,
                candidates: layers,
            },
            LayerChoiceError::Ambiguous { layers, .. } => PassError::AmbiguousLayer {
                path,
                candidates: layers,
            },
        }
    })
}

/// Reads a pass file (format from its bytes).
pub fn read_pass(path: &Path, opts: &PassReadOptions) -> Result<Pass, PassError> {
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
) -> Result<Pass, PassError> {
    let (file, header, len) = open_seekable(path, opts.max_pixels)?;
    let ImageHeader::Exr(headers) = header else {
        let bytes = glassdb_io::read_open_input(file, len, glassdb_image::IMAGE_FILE)
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
pub(crate) fn open_seekable(
    path: &Path,
    max_pixels: u64,
) -> Result<(BufReader<File>, ImageHeader, u64), PassError> {
    let (file, len) = glassdb_io::open_input(path, glassdb_image::IMAGE_FILE)
        .map_err(|cause| read_err(path, cause))?;
    let mut file = BufReader::with_capacity(1 << 16, file.into_inner());
    let header = glassdb_image::read_image_header(&mut file, max_pixels)
        .map_err(|source| decode_err(path, source))?;
    rewind(&mut file, path)?;
    Ok((file, header, len))
}

pub(crate) fn rewind(file: &mut BufReader<File>, path: &Path) -> Result<(), PassError> {
    file.seek(SeekFrom::Start(0))
        .map(drop)
        .map_err(|e| read_err(path, glassdb_io::InputError::from(e)))
}

pub(crate) fn read_err(path: &Path, cause: glassdb_io::InputError) -> PassError {
    PassError::Read {
        path: path.to_path_buf(),
        cause,
    }
}

/// The bytes of an input image, of at most [`glassdb_image::IMAGE_FILE`].
fn read_file(path: &Path) -> Result<Vec<u8>, PassError> {
    glassdb_io::read_input(path, glassdb_image::IMAGE_FILE).map_err(|cause| read_err(path, cause))
}

/// Reads a pass from bytes in memory; `path` names it in errors.
pub fn read_pass_bytes(
    bytes: &[u8],
    path: &Path,
    opts: &PassReadOptions,
) -> Result<Pass, PassError> {
    let decoded = glassdb_image::open_image(bytes, opts.max_pixels)
        .map_err(|source| decode_err(path, source))?;
    match decoded {
        ImageFile::Png(_) if opts.light_mix.is_some() => Err(PassError::LightMixNotExr {
            path: path.to_path_buf(),
        }),
        ImageFile::Png(png) => Ok(pass_from_png(png, opts.transfer)),
        ImageFile::Exr(exr) => read_exr_pass(exr.parts(), path, opts, |part, channels| {
            exr.read_channels(part, channels)
        }),
    }
}

pub(crate) fn decode_err(path: &Path, source: ImageError) -> PassError {
    PassError::Decode {
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
pub(crate) fn read_exr_pass(
    parts: &[ExrPart],
    path: &Path,
    opts: &PassReadOptions,
    decode: impl FnOnce(usize, &[usize]) -> Result<(ExrPart, Vec<Vec<f32>>), ImageError>,
) -> Result<Pass, PassError> {
    let (chosen, channels) = read_layer(parts, opts, path)?;
    let (info, mut buffers) =
        decode(chosen.part, &channels).map_err(|source| decode_err(path, source))?;
    if let Some(mix) = &opts.light_mix {
        buffers = mix_planes(mix, buffers).into();
    }
    let channels = layer_channels(&chosen);
    let alpha_plane = if chosen.alpha.is_some() {
        buffers.pop()
    } else {
        None
    };
    let b = buffers.pop().unwrap_or_default();
    let g = buffers.pop().unwrap_or_default();
    let r = buffers.pop().unwrap_or_default();
    let too_big = || PassError::TooLarge {
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
pub(crate) fn layer_channels(layer: &glassdb_image::RgbLayer) -> Vec<usize> {
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
pub(crate) fn channel_names(info: &ExrPart, channels: &[usize]) -> Vec<String> {
    channels
        .iter()
        .filter_map(|&c| info.channels.get(c).map(|c| c.name.clone()))
        .collect()
}
