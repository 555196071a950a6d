//! Encoding flat planes as a scan-line OpenEXR file: composited passes (half or float, any
//! compression, ZIP at a chosen level; with the transmission pass's windows, attributes and
//! other channels, in one part or several) and EXR masks alike.

use std::io::{Cursor, Seek, Write};

use exr::compression::Compression;
use exr::math::Vec2;
use exr::meta::attribute::IntegerBounds;
use exr::meta::header::{ImageAttributes, LayerAttributes};
use exr::prelude::{
    AnyChannel, AnyChannels, Blocks, Encoding, FlatSamples, Image, Layer, LineOrder, SmallVec,
    WritableImage,
};
use half::slice::HalfFloatSliceExt;
use rayon::prelude::*;

use crate::{ImageError, PixelWindow};

/// How samples are stored in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExrStorage {
    /// 16-bit float (converted from `f32`, round to nearest).
    Half,
    /// 32-bit float.
    Float,
}

/// The samples of one plane: linear `f32` values to store as the options' [`ExrStorage`], or
/// samples kept exactly as another file stored them (half, float or uint).
#[derive(Debug, Clone, PartialEq)]
pub enum PlaneSamples {
    /// Linear samples, written in the output's storage (half or float).
    Converted(Vec<f32>),
    /// Samples copied exactly, in their own type (carried channels).
    Exact(FlatSamples),
}

impl PlaneSamples {
    fn len(&self) -> usize {
        match self {
            PlaneSamples::Converted(v) => v.len(),
            PlaneSamples::Exact(FlatSamples::F16(v)) => v.len(),
            PlaneSamples::Exact(FlatSamples::F32(v)) => v.len(),
            PlaneSamples::Exact(FlatSamples::U32(v)) => v.len(),
        }
    }
}

/// One channel to write: its name and one sample per pixel of its part's data window,
/// row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct ExrPlane {
    /// The channel's full name (`layer.R`).
    pub name: String,
    /// Its samples, one per pixel of the part's data window.
    pub samples: PlaneSamples,
    /// Quantise linearly in lossy compressions (alpha and other data); `false` leaves it to
    /// the `exr` crate's guess from the channel name.
    pub linear: bool,
}

impl ExrPlane {
    /// A plane of `f32` samples whose quantisation is guessed from its name.
    pub fn new(name: &str, samples: Vec<f32>) -> Self {
        ExrPlane {
            name: name.to_string(),
            samples: PlaneSamples::Converted(samples),
            linear: false,
        }
    }
}

/// One part of the file to write.
#[derive(Debug, Clone, PartialEq)]
pub struct ExrPartOut {
    /// The pixels the part stores, in the file's coordinates.
    pub data_window: PixelWindow,
    /// The part's own attributes (its name, view, renderer attributes); the data window is
    /// set from `data_window`.
    pub attributes: LayerAttributes,
    /// Its channels (any order: written sorted by name).
    pub planes: Vec<ExrPlane>,
}

/// A whole file to write: the display window and attributes shared by every part, and the
/// parts (several make a multi-part file, each of which needs a name).
#[derive(Debug, Clone, PartialEq)]
pub struct ExrImageOut {
    /// The file's display window.
    pub display_window: PixelWindow,
    /// Attributes shared by the parts (chromaticities, pixel aspect, time code, custom ones);
    /// the display window is set from `display_window`.
    pub attributes: ImageAttributes,
    /// Its parts, in order.
    pub parts: Vec<ExrPartOut>,
}

/// Encoding settings of [`write_exr_image`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExrWriteOptions {
    /// How converted samples are stored.
    pub storage: ExrStorage,
    /// The compression of every part.
    pub compression: Compression,
    /// zlib level (0–9) for ZIP/ZIPS, deflated in parallel by libdeflate (`exr_zip`); `None`
    /// leaves ZIP to the `exr` crate's own encoder (level 4).
    pub zip_level: Option<u32>,
}

/// What [`write_exr_image`] did beyond writing the samples.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExrWriteReport {
    /// Finite `f32` samples too large for half float, stored as ±65504, the largest finite half
    /// (half storage only): an infinity would misstate a finite value and turn every later
    /// filter, and glassdb's own next composite, into Inf or NaN.
    pub half_overflow: u64,
    /// The first of them (in part, channel and scan-line order), with its value.
    pub first_half_overflow: Option<ClampedSample>,
}

/// A sample clamped to the half-float range, where it lies and what it was.
#[derive(Debug, Clone, PartialEq)]
pub struct ClampedSample {
    /// The channel's full name.
    pub channel: String,
    /// The pixel's column, in the image's pixel coordinates (the data window's origin added).
    pub x: i64,
    /// The pixel's row, likewise.
    pub y: i64,
    /// The value before it was clamped.
    pub value: f32,
}

/// The largest finite half-float value.
const HALF_MAX: f32 = 65504.0;

/// Writes `planes` as one scan-line part covering `width × height` at the origin (channels
/// sorted by name, as EXR requires).
pub fn write_exr_planes<W: Write + Seek + Send>(
    out: W,
    width: usize,
    height: usize,
    planes: Vec<ExrPlane>,
    options: ExrWriteOptions,
) -> Result<ExrWriteReport, ImageError> {
    let frame = PixelWindow::at_origin(width, height);
    let image = ExrImageOut {
        display_window: frame,
        attributes: ImageAttributes::new(to_bounds(&frame)),
        parts: vec![ExrPartOut {
            data_window: frame,
            attributes: LayerAttributes::default(),
            planes,
        }],
    };
    write_exr_image(out, image, options)
}

/// Writes a whole file: every part as scan lines with the options' compression.
pub fn write_exr_image<W: Write + Seek + Send>(
    out: W,
    image: ExrImageOut,
    options: ExrWriteOptions,
) -> Result<ExrWriteReport, ImageError> {
    if let Some(level) = options.zip_level.filter(|&l| l > 9) {
        return Err(ImageError::Unsupported {
            feature: format!("zlib level {level} (levels are 0–9)"),
        });
    }
    if image.parts.is_empty() {
        return Err(ImageError::Unsupported {
            feature: "a file without parts".into(),
        });
    }
    let mut report = ExrWriteReport::default();
    let mut attributes = image.attributes;
    attributes.display_window = to_bounds(&image.display_window);
    let multi_part = image.parts.len() > 1;
    let mut layers: Vec<Layer<AnyChannels<FlatSamples>>> = Vec::with_capacity(image.parts.len());
    for part in image.parts {
        let (w, h) = (part.data_window.width, part.data_window.height);
        if let Some(bad) = part.planes.iter().find(|p| p.samples.len() != w * h) {
            return Err(ImageError::SampleCount {
                samples: bad.samples.len(),
                width: u32::try_from(w).unwrap_or(u32::MAX),
                height: u32::try_from(h).unwrap_or(u32::MAX),
                channels: 1,
            });
        }
        if multi_part && part.attributes.layer_name.is_none() {
            return Err(ImageError::Unsupported {
                feature: "a part without a name in a multi-part file".into(),
            });
        }
        let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
        for plane in part.planes {
            let samples = match plane.samples {
                PlaneSamples::Converted(mut v) => match options.storage {
                    ExrStorage::Float => FlatSamples::F32(v),
                    ExrStorage::Half => {
                        let (count, first) = clamp_half_overflow(&mut v);
                        report.half_overflow += count;
                        if report.first_half_overflow.is_none()
                            && let Some((i, value)) = first
                        {
                            report.first_half_overflow = Some(ClampedSample {
                                channel: plane.name.clone(),
                                x: i64::from(part.data_window.x) + (i % w.max(1)) as i64,
                                y: i64::from(part.data_window.y) + (i / w.max(1)) as i64,
                                value,
                            });
                        }
                        FlatSamples::F16(to_half(&v))
                    }
                },
                PlaneSamples::Exact(s) => s,
            };
            let mut channel = AnyChannel::new(plane.name.as_str(), samples);
            if plane.linear {
                channel.quantize_linearly = true;
            }
            list.push(channel);
        }
        let encoding = Encoding {
            compression: options.compression,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        };
        let mut layer_attributes = part.attributes;
        layer_attributes.layer_position = Vec2(part.data_window.x, part.data_window.y);
        layers.push(Layer::new(
            (w, h),
            layer_attributes,
            encoding,
            AnyChannels::sort(list),
        ));
    }
    match options.zip_level {
        Some(level) => crate::exr_zip::write_zip_layers(&attributes, &layers, level, out),
        None => {
            let layers: SmallVec<[Layer<AnyChannels<FlatSamples>>; 2]> = layers.into();
            Image::from_layers(attributes, layers)
                .write()
                .to_buffered(out)
        }
    }
    .map_err(ImageError::ExrEncode)?;
    Ok(report)
}

fn to_bounds(w: &PixelWindow) -> IntegerBounds {
    IntegerBounds::new(Vec2(w.x, w.y), Vec2(w.width, w.height))
}

/// Clamps the finite samples beyond the half-float range to ±[`HALF_MAX`] (NaN and ±Inf are
/// left as they are); returns how many there were and the index and value of the first.
fn clamp_half_overflow(v: &mut [f32]) -> (u64, Option<(usize, f32)>) {
    const CHUNK: usize = 1 << 16;
    v.par_chunks_mut(CHUNK)
        .enumerate()
        .map(|(k, c)| {
            let mut count = 0u64;
            let mut first = None;
            for (i, s) in c.iter_mut().enumerate() {
                if s.is_finite() && s.abs() > HALF_MAX {
                    count += 1;
                    first = first.or(Some((k * CHUNK + i, *s)));
                    *s = s.clamp(-HALF_MAX, HALF_MAX);
                }
            }
            (count, first)
        })
        .reduce(
            || (0, None),
            |(n, a), (m, b)| (n + m, if a.is_some() { a } else { b }),
        )
}

/// `f32` to half in parallel chunks.
fn to_half(v: &[f32]) -> Vec<half::f16> {
    let mut out = vec![half::f16::ZERO; v.len()];
    out.par_chunks_mut(1 << 16)
        .zip(v.par_chunks(1 << 16))
        .for_each(|(d, s)| d.convert_from_f32_slice(s));
    out
}

/// Encodes float planes (name, samples) as a ZIP-compressed EXR in memory: the EXR mask format.
pub fn encode_exr_f32(
    width: usize,
    height: usize,
    channels: Vec<(&str, Vec<f32>)>,
) -> Result<Vec<u8>, ImageError> {
    let planes = channels
        .into_iter()
        .map(|(name, samples)| ExrPlane::new(name, samples))
        .collect();
    let mut out = Cursor::new(Vec::new());
    let options = ExrWriteOptions {
        storage: ExrStorage::Float,
        compression: Compression::ZIP16,
        zip_level: None,
    };
    write_exr_planes(&mut out, width, height, planes, options)?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_overflow_clamps_only_finite_samples_beyond_the_range() {
        let mut v = vec![1.0, 65504.0, f32::INFINITY, f32::NAN];
        v.extend(std::iter::repeat_n(0.5, 1 << 17));
        v.extend([65520.0, -1e6]);
        let (count, first) = clamp_half_overflow(&mut v);
        assert_eq!(count, 2);
        assert_eq!(first, Some(((1 << 17) + 4, 65520.0)));
        let n = v.len();
        assert_eq!(v[n - 2..], [HALF_MAX, -HALF_MAX]);
        assert!(v[2] == f32::INFINITY && v[3].is_nan() && v[1] == 65504.0);
    }
}
