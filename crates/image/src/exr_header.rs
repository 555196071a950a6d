//! OpenEXR headers: what a file holds (its parts, their channels, windows, colour tags and
//! text attributes), parsed once per file and kept for the pixel reads that follow.

use std::io::{Cursor, Read};
use std::sync::{Arc, Mutex};

use exr::meta::BlockDescription;
use exr::meta::attribute::{SampleType, Text};
use exr::meta::header::Header;

use crate::exr_read::guarded;
use crate::{ImageError, ImageWindows, PixelWindow};

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
    /// [`read_exr_exact`](crate::read_exr_exact) holds of this part.
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
pub(crate) struct ParsedHeaders {
    pub(crate) bytes: Vec<u8>,
    pub(crate) meta: exr::meta::MetaData,
    pub(crate) info: ExrHeaders,
}

#[cfg(test)]
thread_local! {
    /// Headers parsed by the `exr` crate on this thread (the others are recognised).
    pub(crate) static PARSES: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
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
pub(crate) fn parsed_headers(mut reader: impl Read) -> Result<Arc<ParsedHeaders>, ImageError> {
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
    PARSES.with(|n| n.set(n.get() + 1));
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
