//! OpenEXR ZIP / ZIPS output with a chosen deflate level, compressed by libdeflate.
//!
//! ZIP output is the compositor's largest single cost (docs/performance.md). The `exr` crate
//! compresses ZIP blocks with miniz_oxide at a fixed level 4; this module prepares each block
//! exactly as OpenEXR does (little-endian samples line by line and channel by channel, bytes
//! split into even and odd halves, then a byte-delta predictor, then zlib) and deflates it with
//! libdeflate at the level asked for, as OpenEXR ≥ 3.2 does (its default level is 4). Headers,
//! offset table and chunk layout stay `exr`'s own (`exr::block::write`), so the file is what
//! `exr` would write with a different deflate stream; any EXR reader decodes it.

use std::io::{Seek, Write};

use exr::block::chunk::{Chunk, CompressedBlock, CompressedScanLineBlock};
use exr::block::writer::ChunksWriter;
use exr::compression::Compression;
use exr::image::write::layers::WritableLayers;
use exr::meta::header::ImageAttributes;
use exr::prelude::{AnyChannels, FlatSamples, Layer, SmallVec};
use rayon::prelude::*;

/// OpenEXR's default zlib level for ZIP and ZIPS (`Imf::getDefaultZipCompressionLevel`).
pub const DEFAULT_ZIP_LEVEL: u32 = 4;

/// Lines per ZIP block, or `None` for a compression this module does not write.
pub fn zip_block_lines(compression: Compression) -> Option<usize> {
    match compression {
        Compression::ZIP16 => Some(16),
        Compression::ZIP1 => Some(1),
        _ => None,
    }
}

/// Writes scan-line layers (one part each) whose encoding is ZIP or ZIPS, deflating at
/// `level` (0–9). Blocks are compressed in parallel, a batch at a time, and written in order.
pub fn write_zip_layers<W: Write + Seek>(
    attributes: &ImageAttributes,
    layers: &[Layer<AnyChannels<FlatSamples>>],
    level: u32,
    out: W,
) -> exr::error::UnitResult {
    let mut headers: exr::meta::Headers = SmallVec::new();
    for layer in layers {
        if zip_block_lines(layer.encoding.compression).is_none() {
            return Err(exr::error::Error::NotSupported(
                "write_zip_layers needs ZIP or ZIPS compression".into(),
            ));
        }
        headers.extend(layer.infer_headers(attributes));
    }
    exr::block::write(out, headers, true, |_meta, writer| {
        for (layer_index, layer) in layers.iter().enumerate() {
            write_layer_blocks(layer_index, layer, level, writer)?;
        }
        Ok(())
    })
}

/// Compresses and writes the blocks of one layer.
fn write_layer_blocks(
    layer_index: usize,
    layer: &Layer<AnyChannels<FlatSamples>>,
    level: u32,
    writer: &mut impl ChunksWriter,
) -> exr::error::UnitResult {
    let lines_per_block = zip_block_lines(layer.encoding.compression).unwrap_or(16);
    let width = layer.size.width();
    let height = layer.size.height();
    let y_origin = layer.attributes.layer_position.y();
    let channels = &layer.channel_data.list;
    let blocks = height.div_ceil(lines_per_block);
    // A batch of blocks per round keeps both cores busy and the compressed bytes of only one
    // batch in memory.
    let batch = (rayon::current_num_threads() * 4).max(1);
    for first in (0..blocks).step_by(batch) {
        let last = (first + batch).min(blocks);
        let chunks: Vec<Chunk> = (first..last)
            .into_par_iter()
            .map(|block| {
                let y0 = block * lines_per_block;
                let y1 = (y0 + lines_per_block).min(height);
                let raw = block_bytes_le(channels, width, y0..y1);
                let packed = deflate_block(&raw, level)?;
                Ok(Chunk {
                    layer_index,
                    compressed_block: CompressedBlock::ScanLine(CompressedScanLineBlock {
                        y_coordinate: y_origin + y0 as i32,
                        // OpenEXR stores a block raw when deflate does not make it smaller.
                        compressed_pixels_le: if packed.len() < raw.len() {
                            packed
                        } else {
                            raw
                        },
                    }),
                })
            })
            .collect::<exr::error::Result<_>>()?;
        for (offset, chunk) in chunks.into_iter().enumerate() {
            writer.write_chunk(first + offset, chunk)?;
        }
    }
    Ok(())
}

/// The uncompressed bytes of lines `lines`: per line, per channel (sorted by name, as in the
/// header), the samples in little-endian order.
fn block_bytes_le(
    channels: &[exr::prelude::AnyChannel<FlatSamples>],
    width: usize,
    lines: std::ops::Range<usize>,
) -> Vec<u8> {
    let bytes_per_pixel: usize = channels
        .iter()
        .map(|c| match c.sample_data {
            FlatSamples::F16(_) => 2,
            FlatSamples::F32(_) | FlatSamples::U32(_) => 4,
        })
        .sum();
    let mut out = Vec::with_capacity(bytes_per_pixel * width * lines.len());
    for y in lines {
        let row = y * width..(y + 1) * width;
        for c in channels {
            match &c.sample_data {
                FlatSamples::F16(v) => {
                    for s in &v[row.clone()] {
                        out.extend_from_slice(&s.to_bits().to_le_bytes());
                    }
                }
                FlatSamples::F32(v) => {
                    for s in &v[row.clone()] {
                        out.extend_from_slice(&s.to_le_bytes());
                    }
                }
                FlatSamples::U32(v) => {
                    for s in &v[row.clone()] {
                        out.extend_from_slice(&s.to_le_bytes());
                    }
                }
            }
        }
    }
    out
}

/// OpenEXR's ZIP transform of one block: even bytes then odd bytes, a byte-delta predictor
/// (`d[i] = s[i] − s[i−1] + 128`), then a zlib stream at `level` (libdeflate).
fn deflate_block(raw: &[u8], level: u32) -> exr::error::Result<Vec<u8>> {
    let half = raw.len().div_ceil(2);
    let mut split = vec![0u8; raw.len()];
    let (evens, odds) = split.split_at_mut(half);
    for ((pair, e), o) in raw
        .chunks_exact(2)
        .zip(evens.iter_mut())
        .zip(odds.iter_mut())
    {
        *e = pair[0];
        *o = pair[1];
    }
    if raw.len() % 2 == 1 {
        evens[half - 1] = raw[raw.len() - 1];
    }
    let mut previous = split.first().copied().unwrap_or(0);
    for b in split.iter_mut().skip(1) {
        let current = *b;
        *b = current.wrapping_sub(previous).wrapping_add(128);
        previous = current;
    }
    COMPRESSOR.with(|cell| {
        let mut slot = cell.borrow_mut();
        let compressor = match slot.as_mut() {
            Some((l, c)) if *l == level => c,
            _ => {
                let lvl = libdeflater::CompressionLvl::new(level as i32).map_err(|_| {
                    exr::error::Error::NotSupported(format!("zip level {level}").into())
                })?;
                &mut slot.insert((level, libdeflater::Compressor::new(lvl))).1
            }
        };
        let mut out = vec![0u8; compressor.zlib_compress_bound(split.len())];
        let n = compressor
            .zlib_compress(&split, &mut out)
            .map_err(|e| exr::error::Error::Io(std::io::Error::other(e.to_string())))?;
        out.truncate(n);
        Ok(out)
    })
}

thread_local! {
    /// One libdeflate compressor per thread (with its level): it holds about 1 MB of tables,
    /// too much to allocate per block.
    static COMPRESSOR: std::cell::RefCell<Option<(u32, libdeflater::Compressor)>> =
        const { std::cell::RefCell::new(None) };
}

#[cfg(test)]
mod tests {
    use std::io::Cursor;

    use exr::prelude::{
        AnyChannel, Encoding, LayerAttributes, LineOrder, ReadChannels, ReadLayers, SmallVec,
        WritableImage, read,
    };
    use half::f16;

    use super::*;
    use exr::prelude::Image;

    /// Writes a single-layer scan-line image whose encoding is ZIP or ZIPS, deflating at `level`
    /// (0–9); see [`write_zip_layers`].
    pub fn write_zip_image<W: Write + Seek>(
        image: &Image<Layer<AnyChannels<FlatSamples>>>,
        level: u32,
        out: W,
    ) -> exr::error::UnitResult {
        write_zip_layers(
            &image.attributes,
            std::slice::from_ref(&image.layer_data),
            level,
            out,
        )
    }

    /// A deterministic mix of smooth and noisy samples (noise defeats deflate in places, so
    /// both the compressed and the stored-raw block paths run).
    fn samples(n: usize, seed: u32, noisy: bool) -> Vec<f32> {
        (0..n)
            .map(|i| {
                let h = (i as u32 ^ seed).wrapping_mul(0x9e37_79b9).rotate_left(13);
                let smooth = (i % 97) as f32 / 97.0;
                if noisy {
                    f32::from_bits(h & 0x3fff_ffff)
                } else {
                    smooth + (h >> 24) as f32 / 4096.0
                }
            })
            .collect()
    }

    fn image(
        w: usize,
        h: usize,
        half: bool,
        alpha: bool,
        compression: Compression,
        noisy: bool,
    ) -> Image<Layer<AnyChannels<FlatSamples>>> {
        let data = |seed| {
            let v = samples(w * h, seed, noisy);
            if half {
                FlatSamples::F16(v.into_iter().map(f16::from_f32).collect())
            } else {
                FlatSamples::F32(v)
            }
        };
        let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
        for (k, name) in ["R", "G", "B"].iter().enumerate() {
            list.push(AnyChannel::new(*name, data(k as u32 * 7919)));
        }
        if alpha {
            list.push(AnyChannel::new("A", data(31)));
        }
        let encoding = Encoding {
            compression,
            blocks: exr::prelude::Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        };
        Image::from_layer(Layer::new(
            (w, h),
            LayerAttributes::default(),
            encoding,
            AnyChannels::sort(list),
        ))
    }

    fn decode(bytes: Vec<u8>) -> Vec<(String, FlatSamples)> {
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_buffered(Cursor::new(bytes))
            .expect("an EXR reader decodes the file");
        image
            .layer_data
            .channel_data
            .list
            .into_iter()
            .map(|c| (c.name.to_string(), c.sample_data))
            .collect()
    }

    #[test]
    fn every_level_type_and_block_size_round_trips_bit_exactly() {
        // 37 × 21: a last ZIP block of 5 lines; noisy data exercises the stored-raw blocks.
        for compression in [Compression::ZIP16, Compression::ZIP1] {
            for (half, alpha, noisy) in [
                (true, false, false),
                (false, true, false),
                (true, true, true),
                (false, false, true),
            ] {
                let img = image(37, 21, half, alpha, compression, noisy);
                let expected: Vec<(String, FlatSamples)> = img
                    .layer_data
                    .channel_data
                    .list
                    .iter()
                    .map(|c| (c.name.to_string(), c.sample_data.clone()))
                    .collect();
                for level in [0, 1, 4, 9] {
                    let mut out = Cursor::new(Vec::new());
                    write_zip_image(&img, level, &mut out).unwrap();
                    let got = decode(out.into_inner());
                    assert_eq!(
                        got, expected,
                        "{compression:?}, half {half}, alpha {alpha}, noisy {noisy}, level {level}"
                    );
                }
                // Same pixels as the exr crate's own ZIP writer.
                let mut theirs = Cursor::new(Vec::new());
                img.write().to_buffered(&mut theirs).unwrap();
                assert_eq!(decode(theirs.into_inner()), expected);
            }
        }
    }

    #[test]
    fn higher_levels_are_not_larger_and_other_compressions_are_refused() {
        let img = image(64, 48, true, false, Compression::ZIP16, false);
        let size = |level| {
            let mut out = Cursor::new(Vec::new());
            write_zip_image(&img, level, &mut out).unwrap();
            out.into_inner().len()
        };
        let (stored, fast, default, best) = (size(0), size(1), size(4), size(9));
        assert!(
            stored > fast && fast >= default && default >= best,
            "{stored} {fast} {default} {best}"
        );
        let piz = image(8, 8, true, false, Compression::PIZ, false);
        let err = write_zip_image(&piz, 4, Cursor::new(Vec::new())).unwrap_err();
        assert!(err.to_string().contains("ZIP"), "{err}");
    }
}
