//! OpenEXR decoding into flat per-channel `f32` buffers, built on the `exr` crate's block API:
//! only the chosen part (layer) is decompressed, blocks are decompressed in parallel (rayon,
//! one task per band of rows) and written straight into the output buffers, and a panic in the
//! decoder on a corrupt block becomes an `Internal` error. Used for masks and for passes.

use std::io::{Cursor, Read, Seek, SeekFrom};
use std::sync::{Arc, Mutex};

use exr::block::chunk::Chunk;
use exr::block::chunk::TileCoordinates;
use exr::math::Vec2;
use exr::meta::BlockDescription;
use exr::meta::attribute::{SampleType, Text};
use exr::meta::header::{Header, ImageAttributes, LayerAttributes};
use exr::prelude::{FlatSamples, ReadChannels, ReadLayers};

use crate::exr_bands::{BandLayout, decode_bands};
use crate::guard::catch_codec_panic;
use crate::{Codec, ImageError, ImageWindows, PixelWindow};

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
    /// Its sample type.
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
    /// Height of the data window.
    pub height: usize,
    /// The data window: the pixels the part stores, in the file's pixel coordinates.
    pub data_window: PixelWindow,
    /// The display window: the frame the image is meant to fill (shared by all parts).
    pub display_window: PixelWindow,
    /// Its channels, in the file's (alphabetical) order.
    pub channels: Vec<ExrChannelInfo>,
    /// Its compression.
    pub compression: exr::compression::Compression,
    /// Whether it holds deep data (not read here).
    pub deep: bool,
    /// The part's `view` attribute (multi-part stereo files: `left`, `right`).
    pub view: Option<String>,
    /// The `multiView` attribute of a single-part multi-view file: the view names, the first
    /// (the "hero" view) stored in the bare channels, the others as `view.channel`.
    pub multi_view: Vec<String>,
    /// Mip-map or rip-map levels beyond the full resolution (only level 0 is read).
    pub multi_resolution: bool,
    /// Whether the file has several parts: only then does a part's name qualify its channel
    /// names (a single-part file's channel names are complete, even when it has a `name`).
    pub multi_part: bool,
    /// What the header says of the colour of the part's RGB.
    pub colour: ExrColourTag,
}

/// The colour attributes of an EXR part, as stored (interpreted by the compositor).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ExrColourTag {
    /// OpenEXR's `chromaticities`: red, green, blue and white CIE xy (absent: OpenEXR's
    /// default, Rec.709 primaries and D65).
    pub chromaticities: Option<[f32; 8]>,
    /// The Color Interop Forum id of the part's colour space (`colorInteropID`, written per
    /// part by Blender 5: `lin_rec709_scene`, `lin_ap1_scene`, `data`, …).
    pub interop_id: Option<String>,
}

/// The part's colour attributes: `chromaticities` (shared or the part's own) and a text
/// `colorInteropID` (the part's own, else shared).
fn colour_tag(h: &Header) -> ExrColourTag {
    let text = |name: &str| {
        [&h.own_attributes.other, &h.shared_attributes.other]
            .into_iter()
            .find_map(|map| match map.get(&Text::from(name)) {
                Some(exr::meta::attribute::AttributeValue::Text(t)) => Some(t.to_string()),
                _ => None,
            })
    };
    let chromaticities = h.shared_attributes.chromaticities.or_else(|| {
        match h.own_attributes.other.get(&Text::from("chromaticities")) {
            Some(exr::meta::attribute::AttributeValue::Chromaticities(c)) => Some(*c),
            _ => None,
        }
    });
    ExrColourTag {
        chromaticities: chromaticities.map(|c| {
            [
                c.red.x(),
                c.red.y(),
                c.green.x(),
                c.green.y(),
                c.blue.x(),
                c.blue.y(),
                c.white.x(),
                c.white.y(),
            ]
        }),
        interop_id: text("colorInteropID"),
    }
}

impl ExrPart {
    /// Where the part's pixels lie: its data window inside the display window.
    pub fn windows(&self) -> ImageWindows {
        ImageWindows {
            data: self.data_window,
            display: self.display_window,
        }
    }
}

fn part_from_header(h: &Header) -> ExrPart {
    ExrPart {
        layer_name: h.own_attributes.layer_name.as_ref().map(|t| t.to_string()),
        width: h.layer_size.width(),
        height: h.layer_size.height(),
        data_window: PixelWindow {
            x: h.own_attributes.layer_position.x(),
            y: h.own_attributes.layer_position.y(),
            width: h.layer_size.width(),
            height: h.layer_size.height(),
        },
        display_window: PixelWindow {
            x: h.shared_attributes.display_window.position.x(),
            y: h.shared_attributes.display_window.position.y(),
            width: h.shared_attributes.display_window.size.width(),
            height: h.shared_attributes.display_window.size.height(),
        },
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
        view: h.own_attributes.view_name.as_ref().map(|t| t.to_string()),
        multi_view: h
            .own_attributes
            .multi_view_names
            .iter()
            .flatten()
            .map(|t| t.to_string())
            .collect(),
        multi_part: false,
        multi_resolution: match h.blocks {
            BlockDescription::Tiles(t) => t.level_mode != exr::meta::attribute::LevelMode::Singular,
            BlockDescription::ScanLines => false,
        },
        colour: colour_tag(h),
    }
}

impl ExrPart {
    /// Number of pixels of the data window.
    pub fn pixel_count(&self) -> u64 {
        self.data_window.pixel_count()
    }

    /// Bytes of every channel's samples as stored (half 2, float and uint 4 per sample): what
    /// [`read_exr_exact`] holds of this part.
    pub fn stored_bytes(&self) -> u64 {
        let per_pixel: u64 = self
            .channels
            .iter()
            .map(|c| match c.sample_type {
                ExrSampleType::Half => 2,
                ExrSampleType::Float | ExrSampleType::Uint => 4,
            })
            .sum();
        self.pixel_count().saturating_mul(per_pixel)
    }
}

/// Reads only the headers of an EXR held in memory (no pixel data is touched or allocated).
pub fn read_exr_headers(bytes: &[u8]) -> Result<Vec<ExrPart>, ImageError> {
    read_exr_header_info(Cursor::new(bytes)).map(|h| h.parts.to_vec())
}

/// What an EXR's headers say: its parts, and every text attribute as (part, name, value).
/// Shared, not copied: the passes of the planes of one multi-part file hold one list.
#[derive(Debug, Clone)]
pub struct ExrHeaders {
    /// Every part's header, in file order.
    pub parts: Arc<[ExrPart]>,
    /// Every text attribute, from the attributes shared by the parts and each part's own, as
    /// (part, name, value), sorted, without repeats (see [`read_exr_text_attributes`]).
    pub text_attributes: Arc<[(usize, String, String)]>,
}

/// The most parts an EXR may have. Counted from the headers before any is parsed, so a file of
/// thousands of tiny parts is refused in the time it takes to read its headers' bytes.
pub const MAX_EXR_PARTS: usize = 1024;

/// Reads the headers of an EXR from `reader`, which is read only as far as the headers go (and
/// a buffer beyond): no offset table or pixel data is parsed (a file need not be loaded to be
/// checked). More than [`MAX_EXR_PARTS`] parts is refused. Headers read before (the planes of
/// one multi-part file, read pass by pass) are recognised by their bytes and not parsed again.
pub fn read_exr_header_info(reader: impl Read) -> Result<ExrHeaders, ImageError> {
    parsed_headers(reader).map(|h| h.info.clone())
}

/// An EXR's headers parsed, with their bytes (the file's start up to the first offset table).
#[derive(Debug)]
struct ParsedHeaders {
    bytes: Vec<u8>,
    meta: exr::meta::MetaData,
    info: ExrHeaders,
}

/// The headers parsed most recently, newest first (a few: one multi-part file's passes are
/// read one after the other, beside the frame's other files).
static PARSED: Mutex<Vec<Arc<ParsedHeaders>>> = Mutex::new(Vec::new());
/// How many [`PARSED`] keeps.
const PARSED_KEPT: usize = 4;
/// Headers of more bytes than this are parsed every time rather than kept.
const PARSED_MAX_BYTES: usize = 16 << 20;

/// The headers of the EXR `reader` starts with, from [`PARSED`] when their bytes were seen
/// before, else scanned (counting the parts), parsed and kept.
fn parsed_headers(mut reader: impl Read) -> Result<Arc<ParsedHeaders>, ImageError> {
    let kept: Vec<Arc<ParsedHeaders>> = PARSED
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .clone();
    let longest = kept.iter().map(|k| k.bytes.len()).max().unwrap_or(0);
    let mut start = Vec::new();
    (&mut reader)
        .take(longest as u64)
        .read_to_end(&mut start)
        .map_err(ImageError::Read)?;
    // Headers are self-delimiting: bytes equal to a kept header's are that header.
    if let Some(hit) = kept.iter().find(|k| start.starts_with(&k.bytes)) {
        return Ok(Arc::clone(hit));
    }
    let mut scan = HeaderScan {
        bytes: start,
        at: 0,
        reader,
    };
    let end = scan.header_end()?;
    let bytes = match end {
        Some(end) => scan.bytes[..end].to_vec(),
        None => Vec::new(),
    };
    #[cfg(test)]
    tests::PARSES.with(|n| n.set(n.get() + 1));
    let meta = guarded(|| {
        exr::meta::MetaData::read_from_buffered(Cursor::new(&scan.bytes).chain(scan.reader), false)
    })?;
    let multi_part = meta.headers.len() > 1;
    let info = ExrHeaders {
        parts: meta
            .headers
            .iter()
            .map(|h| ExrPart {
                multi_part,
                ..part_from_header(h)
            })
            .collect(),
        text_attributes: text_attributes(&meta).into(),
    };
    let parsed = Arc::new(ParsedHeaders { bytes, meta, info });
    if end.is_some() && parsed.bytes.len() <= PARSED_MAX_BYTES {
        let mut kept = PARSED
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        kept.insert(0, Arc::clone(&parsed));
        kept.truncate(PARSED_KEPT);
    }
    Ok(parsed)
}

/// Walks the header bytes of an EXR (magic number, version, each header's attributes as
/// name, type, size and value, up to the end of the headers) without interpreting them, to
/// find where they end and count the parts. `bytes` holds what was read so far.
struct HeaderScan<R> {
    bytes: Vec<u8>,
    at: usize,
    reader: R,
}

impl<R: Read> HeaderScan<R> {
    /// The next `n` bytes (read as needed); `None` at the end of the file.
    fn take(&mut self, n: usize) -> Result<Option<&[u8]>, ImageError> {
        let want = self.at + n;
        if self.bytes.len() < want {
            let missing = (want - self.bytes.len()).max(64 * 1024);
            (&mut self.reader)
                .take(missing as u64)
                .read_to_end(&mut self.bytes)
                .map_err(ImageError::Read)?;
        }
        if self.bytes.len() < want {
            return Ok(None);
        }
        self.at = want;
        Ok(Some(&self.bytes[want - n..want]))
    }

    /// A null-terminated name of at most 255 bytes; `None` when there is none.
    fn name(&mut self) -> Result<Option<usize>, ImageError> {
        for len in 0..=255 {
            match self.take(1)? {
                Some([0]) => return Ok(Some(len)),
                Some(_) => {}
                None => return Ok(None),
            }
        }
        Ok(None)
    }

    /// Where the headers end (the offset tables begin); `None` when the bytes are not headers
    /// as the scan expects (the parser then says what is wrong). Refuses more than
    /// [`MAX_EXR_PARTS`] parts.
    fn header_end(&mut self) -> Result<Option<usize>, ImageError> {
        let Some(start) = self.take(8)? else {
            return Ok(None);
        };
        let multi_part = start[5] & 0x10 != 0;
        let mut parts = 0usize;
        loop {
            // One header: attributes until an empty name.
            loop {
                match self.name()? {
                    None => return Ok(None),
                    Some(0) => break,
                    Some(_) => {}
                }
                if !matches!(self.name()?, Some(1..)) {
                    return Ok(None);
                }
                let Some(size) = self.take(4)? else {
                    return Ok(None);
                };
                let size = i32::from_le_bytes([size[0], size[1], size[2], size[3]]);
                let Ok(size) = usize::try_from(size) else {
                    return Ok(None);
                };
                if self.take(size)?.is_none() {
                    return Ok(None);
                }
            }
            parts += 1;
            if parts > MAX_EXR_PARTS {
                return Err(ImageError::TooManyParts { max: MAX_EXR_PARTS });
            }
            if !multi_part {
                return Ok(Some(self.at));
            }
            // A multi-part file's headers end with an empty header.
            match self.take(1)? {
                Some([0]) => return Ok(Some(self.at)),
                Some(_) => self.at -= 1,
                None => return Ok(None),
            }
        }
    }
}

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
/// (`parts`, from [`read_exr_header_info`] or [`read_exr_headers`]; the size limit is checked
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
    let band_height = match header.blocks {
        BlockDescription::ScanLines => header.compression.scan_lines_per_block(),
        BlockDescription::Tiles(t) => t.tile_size.height(),
    };
    if band_height == 0 {
        return Err(unsupported("tile height 0".into()));
    }
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
    let mut decoded = decode_bands(meta, &header, &info, &unique, chunks, &layout)?;
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
    for part in &parts {
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

/// Every text attribute of an EXR held in memory, from the attributes shared by its parts and
/// each part's own, as (part, name, value); no pixel data is touched. Renderers keep metadata
/// here (Cryptomatte's `cryptomatte/<key>/manifest`, Blender's `colorInteropID`).
pub fn read_exr_text_attributes(bytes: &[u8]) -> Result<Vec<(usize, String, String)>, ImageError> {
    read_exr_header_info(Cursor::new(bytes)).map(|h| h.text_attributes.to_vec())
}

fn text_attributes(meta: &exr::meta::MetaData) -> Vec<(usize, String, String)> {
    let mut out = Vec::new();
    for (k, header) in meta.headers.iter().enumerate() {
        for map in [
            &header.shared_attributes.other,
            &header.own_attributes.other,
        ] {
            for (name, value) in map {
                if let exr::meta::attribute::AttributeValue::Text(text) = value {
                    out.push((k, name.to_string(), text.to_string()));
                }
            }
        }
    }
    out.sort();
    out.dedup();
    out
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

    thread_local! {
        /// Headers parsed by the `exr` crate on this thread (the others are recognised).
        pub(super) static PARSES: Cell<usize> = const { Cell::new(0) };
    }

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
