//! The block decoding under glassdb-image's EXR reader: a part's blocks decompressed in
//! parallel (rayon, one task per band of rows) straight into the output buffers, each band's
//! rows checked to be fully covered, every sample type converted to `f32` or kept as stored.

use std::sync::Mutex;

use exr::block::UncompressedBlock;
use exr::block::chunk::Chunk;
use exr::meta::header::Header;
use exr::prelude::FlatSamples;
use rayon::prelude::*;

use crate::exr_header::{ExrPart, ExrSampleType};
use crate::exr_read::{guarded, incomplete};
use crate::guard::catch_codec_panic;
use crate::{Codec, ImageError};

/// The image size, its division into bands of `band_height` rows, and the bands decoded
/// (`first_band..end_band`).
pub(crate) struct BandLayout {
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) band_height: usize,
    pub(crate) first_band: usize,
    pub(crate) end_band: usize,
}

impl BandLayout {
    /// The first row decoded, from the data window's top.
    pub(crate) fn y_start(&self) -> usize {
        self.first_band * self.band_height
    }

    /// How many rows are decoded (whole bands, the last cut at the image's bottom).
    pub(crate) fn decoded_rows(&self) -> usize {
        (self.end_band * self.band_height)
            .min(self.height)
            .saturating_sub(self.y_start())
    }
}

/// How the decoded samples are kept: converted to `f32`, or in the channel's own type (half,
/// float, uint), exactly as stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Samples {
    /// Every channel as `f32` (`FlatSamples::F32`).
    AsF32,
    /// Each channel in its stored type.
    AsStored,
}

/// Decompresses the blocks `chunks` yields in parallel, each straight into the output buffers
/// of its band (one buffer per selected channel, of the type `samples` says), checking that
/// each band's rows are fully covered.
pub(crate) fn decode_bands(
    meta: &exr::meta::MetaData,
    header: &Header,
    info: &ExrPart,
    channels: &[usize],
    chunks: impl Iterator<Item = exr::error::Result<Chunk>> + Send,
    layout: &BandLayout,
    samples: Samples,
) -> Result<Vec<FlatSamples>, ImageError> {
    let BandLayout {
        width,
        height,
        band_height,
        first_band,
        end_band,
    } = *layout;
    // Which output buffer each channel of the part goes to.
    let mut target: Vec<Option<usize>> = vec![None; info.channels.len()];
    for (k, &c) in channels.iter().enumerate() {
        if let Some(t) = target.get_mut(c) {
            *t = Some(k);
        }
    }
    let sample_types: Vec<ExrSampleType> = info.channels.iter().map(|c| c.sample_type).collect();

    let len = width * layout.decoded_rows();
    let mut outputs: Vec<FlatSamples> = channels
        .iter()
        .map(|&c| {
            let stored = sample_types.get(c).copied().unwrap_or(ExrSampleType::Float);
            match (samples, stored) {
                (Samples::AsStored, ExrSampleType::Half) => {
                    FlatSamples::F16(vec![half::f16::ZERO; len])
                }
                (Samples::AsStored, ExrSampleType::Uint) => FlatSamples::U32(vec![0; len]),
                _ => FlatSamples::F32(vec![0.0; len]),
            }
        })
        .collect();
    let mut band_slices: Vec<BandTarget<'_>> = (first_band..end_band)
        .map(|_| BandTarget {
            slices: Vec::with_capacity(channels.len()),
            written: 0,
        })
        .collect();
    let rows = width * band_height;
    for buffer in outputs.iter_mut() {
        let bands: Box<dyn Iterator<Item = SliceMut<'_>>> = match buffer {
            FlatSamples::F16(b) => Box::new(b.chunks_mut(rows).map(SliceMut::F16)),
            FlatSamples::F32(b) => Box::new(b.chunks_mut(rows).map(SliceMut::F32)),
            FlatSamples::U32(b) => Box::new(b.chunks_mut(rows).map(SliceMut::U32)),
        };
        for (band, slice) in band_slices.iter_mut().zip(bands) {
            band.slices.push(slice);
        }
    }
    let bands: Vec<Mutex<BandTarget<'_>>> = band_slices.into_iter().map(Mutex::new).collect();

    guarded_chunks(chunks)
        .par_bridge()
        .try_for_each(|chunk| -> Result<(), ImageError> {
            let chunk = chunk?;
            let tile = guarded(|| header.get_block_data_indices(&chunk.compressed_block))?;
            let index = tile.tile_index.y().wrapping_sub(first_band);
            let band = bands.get(index).ok_or_else(|| {
                incomplete(format!(
                    "block row {} is outside the image",
                    tile.tile_index.y()
                ))
            })?;
            let block = guarded(|| UncompressedBlock::decompress_chunk(chunk, meta, false))?;
            let y0 = (first_band + index) * band_height;
            let rows = band_height.min(height - y0);
            let mut band = band
                .lock()
                .map_err(|_| incomplete("a band's decoder stopped".into()))?;
            let BandTarget { slices, written } = &mut *band;
            *written += catch_codec_panic(Codec::Exr, || {
                scatter_block(
                    &block,
                    header,
                    &target,
                    &sample_types,
                    slices,
                    y0,
                    rows,
                    width,
                )
            })??;
            Ok(())
        })?;
    for (index, band) in bands.into_iter().enumerate() {
        let written = band.into_inner().map(|b| b.written).unwrap_or_default();
        let y0 = (first_band + index) * band_height;
        let rows = band_height.min(height - y0);
        let expected = rows * width * channels.len();
        if written != expected {
            return Err(incomplete(format!(
                "rows {}..{}: {written} of {expected} samples present",
                y0,
                y0 + rows
            )));
        }
    }
    Ok(outputs)
}

/// One band's slice of every output buffer, and the samples written into them so far.
struct BandTarget<'a> {
    slices: Vec<SliceMut<'a>>,
    written: usize,
}

/// A band's part of one output buffer, of the buffer's sample type.
enum SliceMut<'a> {
    F16(&'a mut [half::f16]),
    F32(&'a mut [f32]),
    U32(&'a mut [u32]),
}

impl SliceMut<'_> {
    /// Its `start..start + n` samples, of the same type; `None` out of range.
    fn range(&mut self, start: usize, n: usize) -> Option<SliceMut<'_>> {
        let end = start.checked_add(n)?;
        Some(match self {
            SliceMut::F16(s) => SliceMut::F16(s.get_mut(start..end)?),
            SliceMut::F32(s) => SliceMut::F32(s.get_mut(start..end)?),
            SliceMut::U32(s) => SliceMut::U32(s.get_mut(start..end)?),
        })
    }
}

/// The blocks of a chunk reader, with a panic in the reader on a corrupt file turned into an
/// error; nothing more is read after an error.
fn guarded_chunks(
    mut chunks: impl Iterator<Item = exr::error::Result<Chunk>> + Send,
) -> impl Iterator<Item = Result<Chunk, ImageError>> + Send {
    let mut failed = false;
    std::iter::from_fn(move || {
        if failed {
            return None;
        }
        let next = match catch_codec_panic(Codec::Exr, || chunks.next()) {
            Ok(next) => next?.map_err(ImageError::ExrDecode),
            Err(panic) => Err(panic),
        };
        failed = next.is_err();
        Some(next)
    })
}

/// Copies the selected channels' lines of one decompressed block into the band's buffers;
/// returns the number of samples written.
#[allow(clippy::too_many_arguments)]
fn scatter_block(
    block: &UncompressedBlock,
    header: &Header,
    target: &[Option<usize>],
    sample_types: &[ExrSampleType],
    slices: &mut [SliceMut<'_>],
    y0: usize,
    rows: usize,
    width: usize,
) -> Result<usize, ImageError> {
    let mut written = 0;
    for line in block.lines(&header.channels) {
        let loc = line.location;
        let Some(&Some(k)) = target.get(loc.channel) else {
            continue;
        };
        let (x, y, n) = (loc.position.x(), loc.position.y(), loc.sample_count);
        if y < y0 || y >= y0 + rows || x + n > width {
            return Err(incomplete(format!(
                "a block line at ({x}, {y}) lies outside its block"
            )));
        }
        let start = (y - y0) * width + x;
        let dst = slices
            .get_mut(k)
            .and_then(|s| s.range(start, n))
            .ok_or_else(|| incomplete("block line out of range".into()))?;
        let ty = sample_types
            .get(loc.channel)
            .copied()
            .unwrap_or(ExrSampleType::Float);
        convert_samples(line.value, ty, dst)?;
        written += n;
    }
    Ok(written)
}

/// Native-endian sample bytes into `dst`: converted to `f32`, or copied into a buffer of their
/// own type.
fn convert_samples(bytes: &[u8], ty: ExrSampleType, dst: SliceMut<'_>) -> Result<(), ImageError> {
    let size = match ty {
        ExrSampleType::Half => 2,
        ExrSampleType::Float | ExrSampleType::Uint => 4,
    };
    let len = match &dst {
        SliceMut::F16(d) => d.len(),
        SliceMut::F32(d) => d.len(),
        SliceMut::U32(d) => d.len(),
    };
    if bytes.len() != len * size {
        return Err(incomplete("a block line has the wrong byte length".into()));
    }
    let four = |c: &[u8]| [c[0], c[1], c[2], c[3]];
    let two = |c: &[u8]| u16::from_ne_bytes([c[0], c[1]]);
    match (ty, dst) {
        (ExrSampleType::Float, SliceMut::F32(dst)) => {
            for (d, c) in dst.iter_mut().zip(bytes.chunks_exact(4)) {
                *d = f32::from_ne_bytes(four(c));
            }
        }
        (ExrSampleType::Uint, SliceMut::F32(dst)) => {
            for (d, c) in dst.iter_mut().zip(bytes.chunks_exact(4)) {
                *d = u32::from_ne_bytes(four(c)) as f32;
            }
        }
        (ExrSampleType::Uint, SliceMut::U32(dst)) => {
            for (d, c) in dst.iter_mut().zip(bytes.chunks_exact(4)) {
                *d = u32::from_ne_bytes(four(c));
            }
        }
        (ExrSampleType::Half, SliceMut::F32(dst)) => {
            for (d, c) in dst.iter_mut().zip(bytes.chunks_exact(2)) {
                *d = half::f16::from_bits(two(c)).to_f32();
            }
        }
        (ExrSampleType::Half, SliceMut::F16(dst)) => {
            for (d, c) in dst.iter_mut().zip(bytes.chunks_exact(2)) {
                *d = half::f16::from_bits(two(c));
            }
        }
        _ => return Err(incomplete("a channel's samples changed type".into())),
    }
    Ok(())
}
