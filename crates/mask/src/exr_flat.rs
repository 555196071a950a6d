//! OpenEXR decoding into flat per-channel `f32` buffers, built on the `exr` crate's block API:
//! only the chosen part (layer) is decompressed, blocks are decompressed in parallel (rayon,
//! one task per band of rows) and written straight into the output buffers, and a panic in the
//! decoder on a corrupt block becomes an error. Used for masks here and for passes by
//! `glassdb-compose`.

use std::io::Cursor;

use exr::block::UncompressedBlock;
use exr::block::chunk::Chunk;
use exr::math::Vec2;
use exr::meta::BlockDescription;
use exr::meta::attribute::SampleType;
use exr::meta::header::Header;
use rayon::prelude::*;

use crate::guard::catch_decoder_panic;

/// Why an EXR could not be decoded (the caller adds the file name).
#[derive(Debug, thiserror::Error)]
pub enum ExrFlatError {
    /// The `exr` crate rejected the file (corrupt, truncated or unsupported).
    #[error("{0}")]
    Decode(String),
    /// The decoder panicked on this file's bytes (a corrupt file reaching a bug in `exr`).
    #[error("the EXR decoder crashed on this file ({0}); the file is probably corrupt")]
    DecoderPanic(String),
    /// The image is larger than the allowed number of pixels (checked from the header before
    /// anything is allocated).
    #[error("{width}×{height} pixels exceeds the limit of {max_pixels} pixels")]
    TooLarge {
        width: usize,
        height: usize,
        max_pixels: u64,
    },
    /// A feature this reader does not handle (deep data, subsampled channels, empty image).
    #[error("{0}")]
    Unsupported(String),
    /// Blocks are missing or overlap: the file is truncated or corrupt.
    #[error("pixel data incomplete: {0}")]
    Incomplete(String),
}

/// The sample type of one EXR channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExrSampleType {
    /// 16-bit float.
    Half,
    /// 32-bit float.
    Float,
    /// 32-bit unsigned integer.
    Uint,
}

impl From<SampleType> for ExrSampleType {
    fn from(t: SampleType) -> Self {
        match t {
            SampleType::F16 => ExrSampleType::Half,
            SampleType::F32 => ExrSampleType::Float,
            SampleType::U32 => ExrSampleType::Uint,
        }
    }
}

/// One channel as the header describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct ExrChannelInfo {
    /// The channel name as stored (Blender stores `ViewLayer.Combined.R` in single-part files).
    pub name: String,
    pub sample_type: ExrSampleType,
    /// Subsampling factors (x, y); this reader needs (1, 1).
    pub sampling: (usize, usize),
}

/// One part ("layer" in the `exr` crate) of an EXR file, from its header.
#[derive(Debug, Clone)]
pub struct ExrPart {
    /// The part's `name` attribute (required in multi-part files).
    pub layer_name: Option<String>,
    /// Data window size in pixels.
    pub width: usize,
    pub height: usize,
    pub channels: Vec<ExrChannelInfo>,
    pub compression: exr::compression::Compression,
    pub deep: bool,
}

impl ExrPart {
    /// The name a user gives to select channel `index`: `layer.channel` for a named part,
    /// the bare channel name otherwise.
    pub fn qualified_name(&self, index: usize) -> Option<String> {
        let c = self.channels.get(index)?;
        Some(match &self.layer_name {
            Some(layer) if !layer.is_empty() => format!("{layer}.{}", c.name),
            _ => c.name.clone(),
        })
    }

    /// Index of the channel that `name` selects: an exact channel name, or `layer.channel`.
    pub fn find_channel(&self, name: &str) -> Option<usize> {
        self.channels
            .iter()
            .position(|c| c.name == name)
            .or_else(|| {
                (0..self.channels.len()).find(|&i| self.qualified_name(i).as_deref() == Some(name))
            })
    }
}

/// Finds the (part, channel) that `name` selects in a file's parts.
pub fn find_channel(parts: &[ExrPart], name: &str) -> Option<(usize, usize)> {
    parts
        .iter()
        .enumerate()
        .find_map(|(p, part)| part.find_channel(name).map(|c| (p, c)))
}

/// Every selectable channel name in the file (for error messages).
pub fn all_channel_names(parts: &[ExrPart]) -> Vec<String> {
    parts
        .iter()
        .flat_map(|p| (0..p.channels.len()).filter_map(|i| p.qualified_name(i)))
        .collect()
}

fn part_from_header(h: &Header) -> ExrPart {
    ExrPart {
        layer_name: h.own_attributes.layer_name.as_ref().map(|t| t.to_string()),
        width: h.layer_size.width(),
        height: h.layer_size.height(),
        channels: h
            .channels
            .list
            .iter()
            .map(|c| ExrChannelInfo {
                name: c.name.to_string(),
                sample_type: c.sample_type.into(),
                sampling: (c.sampling.x(), c.sampling.y()),
            })
            .collect(),
        compression: h.compression,
        deep: h.deep,
    }
}

/// Reads only the headers of an EXR held in memory (no pixel data is touched or allocated).
pub fn read_exr_headers(bytes: &[u8]) -> Result<Vec<ExrPart>, ExrFlatError> {
    let meta =
        catch_decoder_panic(|| exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false))
            .map_err(ExrFlatError::DecoderPanic)?
            .map_err(|e| ExrFlatError::Decode(e.to_string()))?;
    Ok(meta.headers.iter().map(part_from_header).collect())
}

/// Decodes channels `channels` (indices into the part's channel list) of part `part` into
/// one row-major `f32` buffer each (`width * height` samples; half and uint samples are
/// converted exactly). The size is checked against `max_pixels` before any allocation.
pub fn read_exr_channels(
    bytes: &[u8],
    part: usize,
    channels: &[usize],
    max_pixels: u64,
) -> Result<(ExrPart, Vec<Vec<f32>>), ExrFlatError> {
    let decode_err = |e: exr::error::Error| ExrFlatError::Decode(e.to_string());
    // Headers first, so that the size limit is enforced before the offset tables are read.
    let parts = read_exr_headers(bytes)?;
    let info = parts
        .get(part)
        .cloned()
        .ok_or_else(|| ExrFlatError::Unsupported(format!("the file has no part {part}")))?;
    let (width, height) = (info.width, info.height);
    let pixels = (width as u64).saturating_mul(height as u64);
    if pixels > max_pixels {
        return Err(ExrFlatError::TooLarge {
            width,
            height,
            max_pixels,
        });
    }
    if pixels == 0 {
        return Err(ExrFlatError::Unsupported("the image has no pixels".into()));
    }
    if info.deep {
        return Err(ExrFlatError::Unsupported(
            "deep EXR data is not supported".into(),
        ));
    }
    for &c in channels {
        let ch = info
            .channels
            .get(c)
            .ok_or_else(|| ExrFlatError::Unsupported(format!("the part has no channel {c}")))?;
        if ch.sampling != (1, 1) {
            return Err(ExrFlatError::Unsupported(format!(
                "channel {} is subsampled ({}×{}); only full-resolution channels are supported",
                ch.name, ch.sampling.0, ch.sampling.1
            )));
        }
    }

    let reader = catch_decoder_panic(|| exr::block::read(Cursor::new(bytes), false))
        .map_err(ExrFlatError::DecoderPanic)?
        .map_err(decode_err)?;
    let meta = reader.meta_data().clone();
    let header = meta
        .headers
        .get(part)
        .ok_or_else(|| ExrFlatError::Unsupported(format!("the file has no part {part}")))?
        .clone();
    let band_height = match header.blocks {
        BlockDescription::ScanLines => header.compression.scan_lines_per_block(),
        BlockDescription::Tiles(t) => t.tile_size.height(),
    };
    if band_height == 0 {
        return Err(ExrFlatError::Unsupported("tile height 0".into()));
    }
    let band_count = height.div_ceil(band_height);

    let all_chunks: Vec<Chunk> = catch_decoder_panic(|| {
        reader
            .filter_chunks(false, |_, tile, block| {
                block.layer == part && tile.level_index == Vec2(0, 0)
            })?
            .collect::<exr::error::Result<Vec<Chunk>>>()
    })
    .map_err(ExrFlatError::DecoderPanic)?
    .map_err(decode_err)?;

    let mut band_chunks: Vec<Vec<Chunk>> = (0..band_count).map(|_| Vec::new()).collect();
    for chunk in all_chunks {
        let tile = catch_decoder_panic(|| header.get_block_data_indices(&chunk.compressed_block))
            .map_err(ExrFlatError::DecoderPanic)?
            .map_err(decode_err)?;
        if tile.level_index != Vec2(0, 0) {
            continue;
        }
        let band = band_chunks.get_mut(tile.tile_index.y()).ok_or_else(|| {
            ExrFlatError::Incomplete(format!(
                "block row {} is outside the image",
                tile.tile_index.y()
            ))
        })?;
        band.push(chunk);
    }

    // Which output buffer each channel of the part goes to.
    let mut target: Vec<Option<usize>> = vec![None; info.channels.len()];
    for (k, &c) in channels.iter().enumerate() {
        if let Some(t) = target.get_mut(c) {
            *t = Some(k);
        }
    }
    let sample_types: Vec<ExrSampleType> = info.channels.iter().map(|c| c.sample_type).collect();

    let mut outputs: Vec<Vec<f32>> = channels
        .iter()
        .map(|_| vec![0f32; width * height])
        .collect();
    let mut band_slices: Vec<Vec<&mut [f32]>> = (0..band_count)
        .map(|_| Vec::with_capacity(channels.len()))
        .collect();
    for buffer in outputs.iter_mut() {
        for (band, slice) in band_slices
            .iter_mut()
            .zip(buffer.chunks_mut(width * band_height))
        {
            band.push(slice);
        }
    }

    band_slices
        .into_par_iter()
        .zip(band_chunks.into_par_iter())
        .enumerate()
        .try_for_each(|(band, (mut slices, chunks))| -> Result<(), ExrFlatError> {
            let y0 = band * band_height;
            let rows = band_height.min(height - y0);
            let mut written = 0usize;
            for chunk in chunks {
                let block = catch_decoder_panic(|| {
                    UncompressedBlock::decompress_chunk(chunk, &meta, false)
                })
                .map_err(ExrFlatError::DecoderPanic)?
                .map_err(decode_err)?;
                let scattered = catch_decoder_panic(|| {
                    scatter_block(
                        &block,
                        &header,
                        &target,
                        &sample_types,
                        &mut slices,
                        y0,
                        rows,
                        width,
                    )
                })
                .map_err(ExrFlatError::DecoderPanic)??;
                written += scattered;
            }
            let expected = rows * width * channels.len();
            if written != expected {
                return Err(ExrFlatError::Incomplete(format!(
                    "rows {}..{}: {written} of {expected} samples present",
                    y0,
                    y0 + rows
                )));
            }
            Ok(())
        })?;
    Ok((info, outputs))
}

/// Copies the selected channels' lines of one decompressed block into the band's buffers;
/// returns the number of samples written.
#[allow(clippy::too_many_arguments)]
fn scatter_block(
    block: &UncompressedBlock,
    header: &Header,
    target: &[Option<usize>],
    sample_types: &[ExrSampleType],
    slices: &mut [&mut [f32]],
    y0: usize,
    rows: usize,
    width: usize,
) -> Result<usize, ExrFlatError> {
    let mut written = 0;
    for line in block.lines(&header.channels) {
        let loc = line.location;
        let Some(&Some(k)) = target.get(loc.channel) else {
            continue;
        };
        let (x, y, n) = (loc.position.x(), loc.position.y(), loc.sample_count);
        if y < y0 || y >= y0 + rows || x + n > width {
            return Err(ExrFlatError::Incomplete(format!(
                "a block line at ({x}, {y}) lies outside its block"
            )));
        }
        let start = (y - y0) * width + x;
        let dst = slices
            .get_mut(k)
            .and_then(|s| s.get_mut(start..start + n))
            .ok_or_else(|| ExrFlatError::Incomplete("block line out of range".into()))?;
        let ty = sample_types
            .get(loc.channel)
            .copied()
            .unwrap_or(ExrSampleType::Float);
        convert_samples(line.value, ty, dst)?;
        written += n;
    }
    Ok(written)
}

/// Native-endian sample bytes to `f32`.
fn convert_samples(bytes: &[u8], ty: ExrSampleType, dst: &mut [f32]) -> Result<(), ExrFlatError> {
    let size = match ty {
        ExrSampleType::Half => 2,
        ExrSampleType::Float | ExrSampleType::Uint => 4,
    };
    if bytes.len() != dst.len() * size {
        return Err(ExrFlatError::Incomplete(
            "a block line has the wrong byte length".into(),
        ));
    }
    match ty {
        ExrSampleType::Float => {
            for (d, c) in dst.iter_mut().zip(bytes.chunks_exact(4)) {
                *d = f32::from_ne_bytes([c[0], c[1], c[2], c[3]]);
            }
        }
        ExrSampleType::Uint => {
            for (d, c) in dst.iter_mut().zip(bytes.chunks_exact(4)) {
                *d = u32::from_ne_bytes([c[0], c[1], c[2], c[3]]) as f32;
            }
        }
        ExrSampleType::Half => {
            for (d, c) in dst.iter_mut().zip(bytes.chunks_exact(2)) {
                *d = half::f16::from_bits(u16::from_ne_bytes([c[0], c[1]])).to_f32();
            }
        }
    }
    Ok(())
}
