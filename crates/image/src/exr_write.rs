//! Encoding flat `f32` planes as a single-part scan-line OpenEXR file: composited passes
//! (half or float, any compression, ZIP at a chosen level) and EXR masks alike.

use std::io::{Cursor, Seek, Write};

use exr::compression::Compression;
use exr::prelude::{
    AnyChannel, AnyChannels, Blocks, Encoding, FlatSamples, Image, Layer, LayerAttributes,
    LineOrder, SmallVec, WritableImage,
};
use half::slice::HalfFloatSliceExt;
use rayon::prelude::*;

use crate::ImageError;

/// How samples are stored in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExrStorage {
    /// 16-bit float (converted from `f32`, round to nearest).
    Half,
    /// 32-bit float.
    Float,
}

/// One channel to write: its name and `width * height` row-major samples.
#[derive(Debug, Clone, PartialEq)]
pub struct ExrPlane {
    pub name: String,
    pub samples: Vec<f32>,
    /// Quantise linearly in lossy compressions (alpha and other data); `false` leaves it to
    /// the `exr` crate's guess from the channel name.
    pub linear: bool,
}

impl ExrPlane {
    /// A plane whose quantisation is guessed from its name.
    pub fn new(name: &str, samples: Vec<f32>) -> Self {
        ExrPlane {
            name: name.to_string(),
            samples,
            linear: false,
        }
    }
}

/// Encoding settings of [`write_exr_planes`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExrWriteOptions {
    pub storage: ExrStorage,
    pub compression: Compression,
    /// zlib level (0–9) for ZIP/ZIPS, deflated in parallel by zlib-rs (`exr_zip`); `None`
    /// leaves ZIP to the `exr` crate's own encoder (level 4).
    pub zip_level: Option<u32>,
}

/// Writes `planes` as one scan-line layer to `out` (channels are sorted by name, as EXR
/// requires).
pub fn write_exr_planes<W: Write + Seek>(
    out: W,
    width: usize,
    height: usize,
    planes: Vec<ExrPlane>,
    options: ExrWriteOptions,
) -> Result<(), ImageError> {
    if let Some(bad) = planes.iter().find(|p| p.samples.len() != width * height) {
        return Err(ImageError::SampleCount {
            samples: bad.samples.len(),
            width: u32::try_from(width).unwrap_or(u32::MAX),
            height: u32::try_from(height).unwrap_or(u32::MAX),
            channels: 1,
        });
    }
    if let Some(level) = options.zip_level.filter(|&l| l > 9) {
        return Err(ImageError::Unsupported {
            feature: format!("zlib level {level} (levels are 0–9)"),
        });
    }
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for plane in planes {
        let samples = match options.storage {
            ExrStorage::Float => FlatSamples::F32(plane.samples),
            ExrStorage::Half => FlatSamples::F16(to_half(&plane.samples)),
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
    let layer = Layer::new(
        (width, height),
        LayerAttributes::default(),
        encoding,
        AnyChannels::sort(list),
    );
    let image = Image::from_layer(layer);
    match options.zip_level {
        Some(level) => crate::exr_zip::write_zip_image(&image, level, out),
        None => image.write().to_buffered(out),
    }
    .map_err(ImageError::ExrEncode)
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
