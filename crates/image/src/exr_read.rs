//! OpenEXR decoding into flat per-channel `f32` buffers, built on the `exr` crate's block API:
//! only the chosen part (layer) is decompressed, blocks are decompressed in parallel (rayon,
//! one task per band of rows) and written straight into the output buffers, and a panic in the
//! decoder on a corrupt block becomes an `Internal` error. Used for masks and for passes.

use std::io::{Cursor, Read, Seek, SeekFrom};
use std::sync::Arc;

use exr::block::chunk::Chunk;
use exr::block::chunk::TileCoordinates;
use exr::math::Vec2;
use exr::meta::BlockDescription;
use exr::meta::header::{ImageAttributes, LayerAttributes};
use exr::prelude::{FlatSamples, ReadChannels, ReadLayers};

use crate::exr_bands::{BandLayout, Samples, decode_bands};
use crate::exr_header::{ExrPart, ParsedHeaders, parsed_headers, read_exr_headers};
use crate::guard::catch_codec_panic;
use crate::{Codec, ImageError, PixelWindow};

/// Runs an `exr` call that sees file bytes: a panic becomes `CodecPanic`, an error `ExrDecode`.
pub(crate) fn guarded<T>(decode: impl FnOnce() -> exr::error::Result<T>) -> Result<T, ImageError> {
    catch_codec_panic(Codec::Exr, decode)?.map_err(ImageError::ExrDecode)
}

pub(crate) fn incomplete(detail: String) -> ImageError {
    ImageError::Incomplete { detail }
}

fn unsupported(feature: String) -> ImageError {
    ImageError::Unsupported { feature }
}

/// Decodes channels `channels` (indices into the part's channel list) of part `part` into
/// one row-major `f32` buffer each (`width * height` samples; half and uint samples are
/// converted exactly). The size is checked against `max_pixels` before any allocation.
pub fn read_exr_channels(
    bytes: &[u8],
    part: usize,
    channels: &[usize],
    max_pixels: u64,
) -> Result<(ExrPart, Vec<Vec<f32>>), ImageError> {
    read_exr_channel_rows(bytes, part, channels, max_pixels, None)
}

/// [`read_exr_channels`] of only the rows `rows` of the data window (absolute pixel
/// coordinates, `y_first..=y_last`; `None`: every row): only the blocks holding them are
/// decompressed. The part returned describes what was decoded: its data window is the whole
/// blocks covering those rows (full width), so that it places the buffers in the frame. Rows
/// outside the data window are ignored; none inside decodes the first block.
pub fn read_exr_channel_rows(
    bytes: &[u8],
    part: usize,
    channels: &[usize],
    max_pixels: u64,
    rows: Option<(i64, i64)>,
) -> Result<(ExrPart, Vec<Vec<f32>>), ImageError> {
    let parts = read_exr_headers(bytes)?;
    read_exr_channel_rows_from(Cursor::new(bytes), &parts, part, channels, max_pixels, rows)
}

/// [`read_exr_channel_rows`] from a seekable reader (a file) whose headers the caller has read
/// (`parts`, from [`read_exr_header_info`](crate::read_exr_header_info) or [`read_exr_headers`]; the size limit is checked
/// on them before the offset tables are read): only the offset tables and the compressed
/// blocks holding the rows asked for are read, so a pass whose plane covers a third of the
/// frame costs a third of the file's reading, and its memory.
pub fn read_exr_channel_rows_from<R: Read + Seek + Send>(
    mut source: R,
    parts: &[ExrPart],
    part: usize,
    channels: &[usize],
    max_pixels: u64,
    rows: Option<(i64, i64)>,
) -> Result<(ExrPart, Vec<Vec<f32>>), ImageError> {
    let mut info = parts
        .get(part)
        .cloned()
        .ok_or_else(|| unsupported(format!("part {part} (the file has {})", parts.len())))?;
    check_exr_readable(&info, channels, max_pixels)?;
    let io_err = |e| ImageError::ExrDecode(exr::error::Error::Io(e));
    source.seek(SeekFrom::Start(0)).map_err(io_err)?;
    let parsed = parsed_headers(&mut source)?;
    let meta = &parsed.meta;
    let header = meta
        .headers
        .get(part)
        .ok_or_else(|| unsupported(format!("part {part}")))?
        .clone();
    let band_height = band_height(&header)?;
    let band_count = info.height.div_ceil(band_height);
    // The bands (block rows) holding the rows asked for, relative to the data window.
    let (first_band, end_band) = match rows {
        None => (0, band_count),
        Some((y_first, y_last)) => {
            let top = i64::from(info.data_window.y);
            let bottom = top + info.height as i64 - 1;
            if y_last < top || y_first > bottom || y_first > y_last {
                (0, 1)
            } else {
                let first = (y_first.max(top) - top) as usize;
                let last = (y_last.min(bottom) - top) as usize;
                (first / band_height, last / band_height + 1)
            }
        }
    };
    // Blocks are read one at a time, as decoders ask for them, so that only the blocks being
    // decoded are in memory, and reading overlaps decoding.
    let chunks = part_chunks(source, &parsed, part, first_band..end_band)?;
    let layout = BandLayout {
        width: info.width,
        height: info.height,
        band_height,
        first_band,
        end_band,
    };
    if (first_band, end_band) != (0, band_count) {
        let (y_start, decoded_rows) = (layout.y_start(), layout.decoded_rows());
        info.data_window.y += y_start as i32;
        info.data_window.height = decoded_rows;
        info.height = decoded_rows;
    }
    // A channel asked for twice is decoded once and copied; the buffers are otherwise moved
    // into the order asked for (R, G, B is the reverse of the file's B, G, R).
    let mut unique: Vec<usize> = channels.to_vec();
    unique.sort_unstable();
    unique.dedup();
    let mut decoded = decode_bands(
        meta,
        &header,
        &info,
        &unique,
        chunks,
        &layout,
        Samples::AsF32,
    )?
    .into_iter()
    .map(|samples| match samples {
        FlatSamples::F32(v) => Ok(v),
        _ => Err(incomplete("a channel was not decoded as f32".into())),
    })
    .collect::<Result<Vec<_>, _>>()?;
    let outputs = channels
        .iter()
        .enumerate()
        .map(|(j, c)| {
            let k = unique.binary_search(c).unwrap_or_default();
            let slot = decoded.get_mut(k);
            if channels[j + 1..].contains(c) {
                slot.map(|b| b.clone()).unwrap_or_default()
            } else {
                slot.map(std::mem::take).unwrap_or_default()
            }
        })
        .collect();
    Ok((info, outputs))
}

/// The rows of one band: a scan-line block's, or a tile's height.
fn band_height(header: &exr::meta::header::Header) -> Result<usize, ImageError> {
    let rows = match header.blocks {
        BlockDescription::ScanLines => header.compression.scan_lines_per_block(),
        BlockDescription::Tiles(t) => t.tile_size.height(),
    };
    if rows == 0 {
        return Err(unsupported("tile height 0".into()));
    }
    Ok(rows)
}

/// The blocks of part `part` whose band (block row, level 0) is in `bands`, read one at a time
/// as the decoders ask for them, from the file `source` whose headers are `parsed`: only that
/// part's offset table is read (where the headers' end is known), so reading one part of a
/// file of many costs that part, not the file's every table.
fn part_chunks<'r, R: Read + Seek + Send + 'r>(
    mut source: R,
    parsed: &Arc<ParsedHeaders>,
    part: usize,
    bands: std::ops::Range<usize>,
) -> Result<Box<dyn Iterator<Item = exr::error::Result<Chunk>> + Send + 'r>, ImageError> {
    let io_err = |e| ImageError::ExrDecode(exr::error::Error::Io(e));
    let headers = &parsed.meta.headers;
    let wanted = |tile: TileCoordinates| {
        tile.level_index == Vec2(0, 0) && bands.contains(&tile.tile_index.y())
    };
    if parsed.bytes.is_empty() {
        // Where the headers end is unknown: the `exr` crate reads every table.
        source.seek(SeekFrom::Start(0)).map_err(io_err)?;
        let reader = guarded(|| exr::block::read(source, false))?;
        let chunks = guarded(|| {
            reader.filter_chunks(false, |_, tile, block| block.layer == part && wanted(tile))
        })?;
        return Ok(Box::new(chunks));
    }
    let before: usize = headers.iter().take(part).map(|h| h.chunk_count).sum();
    let header = headers
        .get(part)
        .ok_or_else(|| unsupported(format!("part {part}")))?;
    let table_at = (parsed.bytes.len() as u64).saturating_add((before as u64).saturating_mul(8));
    source.seek(SeekFrom::Start(table_at)).map_err(io_err)?;
    let mut table = vec![0u8; header.chunk_count.saturating_mul(8)];
    source.read_exact(&mut table).map_err(io_err)?;
    let table: Vec<u64> = table
        .chunks_exact(8)
        .map(|b| u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]))
        .collect();
    let mut offsets = Vec::new();
    for (index, tile) in header.blocks_increasing_y_order().enumerate() {
        if wanted(tile.location) {
            let offset = table
                .get(index)
                .ok_or_else(|| incomplete(format!("part {part}'s offset table is short")))?;
            offsets.push(*offset);
        }
    }
    offsets.sort_unstable();
    let parsed = Arc::clone(parsed);
    Ok(Box::new(offsets.into_iter().map(move |offset| {
        source.seek(SeekFrom::Start(offset))?;
        Chunk::read(&mut source, &parsed.meta)
    })))
}

/// Refuses what [`read_exr_channels`] cannot decode, from the header alone: too many pixels,
/// no pixels, deep data, a missing or subsampled channel.
pub fn check_exr_readable(
    info: &ExrPart,
    channels: &[usize],
    max_pixels: u64,
) -> Result<(), ImageError> {
    let (width, height) = (info.width as u64, info.height as u64);
    let pixels = width.saturating_mul(height);
    if pixels > max_pixels {
        return Err(ImageError::TooLarge {
            width,
            height,
            max_pixels,
        });
    }
    if pixels == 0 {
        return Err(unsupported("an image without pixels".into()));
    }
    if info.deep {
        return Err(unsupported("deep EXR data".into()));
    }
    for &c in channels {
        let ch = info.channels.get(c).ok_or_else(|| {
            unsupported(format!(
                "channel {c} (the part has {})",
                info.channels.len()
            ))
        })?;
        if ch.sampling != (1, 1) {
            return Err(unsupported(format!(
                "subsampled channel {} ({}×{}); only full-resolution channels are read",
                ch.name, ch.sampling.0, ch.sampling.1
            )));
        }
    }
    Ok(())
}

/// The attributes of an EXR (`file` from its start; only its headers are read), as the `exr`
/// crate models them: those shared by every part (display window, chromaticities, pixel
/// aspect, custom ones) and part `part`'s own (name, view, renderer attributes). No pixel data
/// is touched.
pub fn read_exr_attributes(
    file: impl Read,
    part: usize,
) -> Result<(ImageAttributes, LayerAttributes), ImageError> {
    let meta = guarded(|| exr::meta::MetaData::read_from_buffered(file, false))?;
    let header = meta
        .headers
        .get(part)
        .ok_or_else(|| unsupported(format!("part {part} (the file has {})", meta.headers.len())))?;
    Ok((
        header.shared_attributes.clone(),
        header.own_attributes.clone(),
    ))
}

/// One part of an [`ExactExr`].
#[derive(Debug, Clone, PartialEq)]
pub struct ExactPart {
    /// The part's own attributes.
    pub attributes: LayerAttributes,
    /// The part's data window.
    pub data_window: PixelWindow,
    /// Channel names as stored, and their full-resolution samples as stored (half, float or
    /// uint), row-major over the data window.
    pub channels: Vec<(String, FlatSamples)>,
}

/// Every part of an EXR with its full-resolution samples exactly as stored, and the attributes:
/// what is copied, unchanged, into a file written from it.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactExr {
    /// The file's shared attributes.
    pub attributes: ImageAttributes,
    /// Every part, exactly as stored.
    pub parts: Vec<ExactPart>,
}

/// Reads every part of an EXR exactly (see [`ExactExr`]); parts over `max_pixels` in total,
/// deep parts and subsampled channels are refused from the headers, before any pixel is decoded.
pub fn read_exr_exact(bytes: &[u8], max_pixels: u64) -> Result<ExactExr, ImageError> {
    let parts = read_exr_headers(bytes)?;
    check_exact_readable(&parts, max_pixels)?;
    let image = guarded(|| {
        exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .from_buffered(Cursor::new(bytes))
    })?;
    Ok(ExactExr {
        attributes: image.attributes,
        parts: image
            .layer_data
            .into_iter()
            .map(|layer| ExactPart {
                data_window: PixelWindow {
                    x: layer.attributes.layer_position.x(),
                    y: layer.attributes.layer_position.y(),
                    width: layer.size.width(),
                    height: layer.size.height(),
                },
                attributes: layer.attributes,
                channels: layer
                    .channel_data
                    .list
                    .into_iter()
                    .map(|c| (c.name.to_string(), c.sample_data))
                    .collect(),
            })
            .collect(),
    })
}

/// [`read_exr_exact`] of only the channels `keep` accepts (by their full names), from a
/// seekable reader (a file) whose headers the caller has read (`parts`): each part's blocks are
/// read as they are decoded (in parallel, as [`read_exr_channel_rows_from`] reads a pass's),
/// never the whole file at once, and only the channels kept are held, in their stored types.
/// A part none of whose channels is kept is returned without channels. The same checks as
/// [`read_exr_exact`], from the headers.
pub fn read_exr_exact_keeping<R: Read + Seek + Send>(
    mut source: R,
    parts: &[ExrPart],
    max_pixels: u64,
    keep: &dyn Fn(&str) -> bool,
) -> Result<ExactExr, ImageError> {
    check_exact_readable(parts, max_pixels)?;
    let io_err = |e| ImageError::ExrDecode(exr::error::Error::Io(e));
    source.seek(SeekFrom::Start(0)).map_err(io_err)?;
    let parsed = parsed_headers(&mut source)?;
    let meta = &parsed.meta;
    let header_of = |p: usize| {
        meta.headers
            .get(p)
            .ok_or_else(|| unsupported(format!("part {p}")))
    };
    let attributes = header_of(0)?.shared_attributes.clone();
    let mut exact = Vec::with_capacity(parts.len());
    for (p, info) in parts.iter().enumerate() {
        let header = header_of(p)?;
        let kept: Vec<usize> = (0..info.channels.len())
            .filter(|&c| keep(&info.channels[c].name))
            .collect();
        let samples = if kept.is_empty() {
            Vec::new()
        } else {
            let band_height = band_height(header)?;
            let band_count = info.height.div_ceil(band_height);
            let chunks = part_chunks(&mut source, &parsed, p, 0..band_count)?;
            let layout = BandLayout {
                width: info.width,
                height: info.height,
                band_height,
                first_band: 0,
                end_band: band_count,
            };
            decode_bands(
                meta,
                header,
                info,
                &kept,
                chunks,
                &layout,
                Samples::AsStored,
            )?
        };
        exact.push(ExactPart {
            attributes: header.own_attributes.clone(),
            data_window: info.data_window,
            channels: kept
                .iter()
                .map(|&c| info.channels[c].name.clone())
                .zip(samples)
                .collect(),
        });
    }
    Ok(ExactExr {
        attributes,
        parts: exact,
    })
}

/// What [`read_exr_exact`] refuses from the headers: more than `max_pixels` in all parts, deep
/// data, subsampled channels.
fn check_exact_readable(parts: &[ExrPart], max_pixels: u64) -> Result<(), ImageError> {
    let total: u64 = parts
        .iter()
        .map(|p| p.data_window.pixel_count())
        .fold(0, u64::saturating_add);
    if total > max_pixels {
        let largest = parts
            .iter()
            .map(|p| p.data_window)
            .max_by_key(|w| w.pixel_count());
        return Err(ImageError::TooLarge {
            width: largest.map_or(0, |w| w.width as u64),
            height: largest.map_or(0, |w| w.height as u64),
            max_pixels,
        });
    }
    for part in parts {
        if part.deep {
            return Err(unsupported("deep EXR data".into()));
        }
        if let Some(c) = part.channels.iter().find(|c| c.sampling != (1, 1)) {
            return Err(unsupported(format!(
                "subsampled channel {} ({}×{})",
                c.name, c.sampling.0, c.sampling.1
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::cell::Cell;
    use std::io::Cursor;

    use exr::meta::header::{ImageAttributes, LayerAttributes};

    use crate::{
        ExrImageOut, ExrPartOut, ExrPlane, ExrStorage, ExrWriteOptions, ImageErrorKind,
        PixelWindow, read_exr_channel_rows_from, read_exr_header_info,
    };

    use crate::exr_header::PARSES;

    /// An EXR of `n` parts `plane0`, `plane1`, …, each 2×1 pixels with R, G, B = its index,
    /// on rows `k % 4` of a 2×4 frame.
    fn many_parts(n: usize) -> Vec<u8> {
        let frame = PixelWindow::at_origin(2, 4);
        let image = ExrImageOut {
            display_window: frame,
            attributes: ImageAttributes::new(exr::prelude::IntegerBounds::from_dimensions((2, 4))),
            parts: (0..n)
                .map(|k| ExrPartOut {
                    data_window: PixelWindow {
                        x: 0,
                        y: (k % 4) as i32,
                        width: 2,
                        height: 1,
                    },
                    attributes: LayerAttributes::named(format!("plane{k}").as_str()),
                    planes: ["R", "G", "B"]
                        .iter()
                        .map(|c| ExrPlane::new(c, vec![k as f32; 2]))
                        .collect(),
                })
                .collect(),
        };
        let mut out = Cursor::new(Vec::new());
        let options = ExrWriteOptions {
            storage: ExrStorage::Float,
            compression: exr::compression::Compression::Uncompressed,
            zip_level: None,
        };
        crate::write_exr_image(&mut out, image, options).unwrap();
        out.into_inner()
    }

    #[test]
    fn every_part_of_a_file_of_many_is_read_with_its_headers_parsed_once() {
        let bytes = many_parts(300);
        let before = PARSES.with(Cell::get);
        let headers = read_exr_header_info(Cursor::new(&bytes)).unwrap();
        assert_eq!(headers.parts.len(), 300);
        for k in [0, 1, 150, 299] {
            let (part, planes) = read_exr_channel_rows_from(
                Cursor::new(&bytes),
                &headers.parts,
                k,
                &[0, 2],
                100,
                None,
            )
            .unwrap();
            assert_eq!(part.data_window.y, (k % 4) as i32);
            assert_eq!(planes, vec![vec![k as f32; 2]; 2], "part {k}");
            // Again through the header reader, as each plane's pass does.
            assert_eq!(
                read_exr_header_info(Cursor::new(&bytes))
                    .unwrap()
                    .parts
                    .len(),
                300
            );
        }
        assert_eq!(PARSES.with(Cell::get) - before, 1);
    }

    #[test]
    fn a_file_of_too_many_parts_is_refused_before_its_headers_are_parsed() {
        let bytes = many_parts(crate::MAX_EXR_PARTS + 1);
        let before = PARSES.with(Cell::get);
        let e = read_exr_header_info(Cursor::new(&bytes)).unwrap_err();
        assert_eq!(e.kind(), ImageErrorKind::Limits, "{e}");
        assert!(e.to_string().contains("more than 1024 parts"), "{e}");
        assert_eq!(PARSES.with(Cell::get), before);
        // The limit itself is read.
        let bytes = many_parts(crate::MAX_EXR_PARTS);
        assert_eq!(
            read_exr_header_info(Cursor::new(&bytes))
                .unwrap()
                .parts
                .len(),
            crate::MAX_EXR_PARTS
        );
    }
}
