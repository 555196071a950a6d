//! Reading masks: the header first (glassdb-image reads a PNG's chunks up to its pixel data,
//! an EXR's headers), from which the format's layout is checked and the channels to decode are
//! chosen ([`MaskPlan`]); then the one image reader of glassdb-image decodes only those, and
//! each mask format's layout (packed PNG, binary PNG, EXR channels, Cryptomatte) becomes a
//! [`MaskImage`].

use std::io::{BufReader, Cursor};
use std::path::Path;

use glassdb_image::{
    ExrFile, ExrPart, ImageHeader, ImageWindows, PngHeader, PngPixels, PngSamples, ReadMemory,
};

use crate::channels::{
    MaskHeader, PixelError, decode_channels, decode_err, locate_channel, plan_channels,
};
use crate::cryptomatte::{CryptomattePlan, decode_cryptomatte, plan_cryptomatte};
use crate::{CosTheta, ExrMaskChannels, MaskError, MaskImage, MaskReadOptions, PlacedMask};

/// Reads a mask file's header only (a PNG's chunks up to its pixel data, an EXR's headers; no
/// pixel is decompressed) and checks the layout `opts` asks for: a packed PNG is RGB, a binary
/// mask is a PNG, the EXR channels (or the Cryptomatte layer, its manifest and the cos θ and
/// plane channels) are present, the parts read are within the pixel limit. A file whose pixel
/// data is corrupt passes; [`read_placed_mask`] finds that.
pub fn read_mask_header(path: &Path, opts: &MaskReadOptions) -> Result<MaskHeader, MaskError> {
    let read_err = |source| MaskError::Read {
        path: path.to_path_buf(),
        source,
    };
    let (file, file_len) =
        glassdb_io::open_input(path, glassdb_image::IMAGE_FILE).map_err(read_err)?;
    let header = glassdb_image::read_image_header(BufReader::new(file), opts.max_pixels)
        .map_err(|source| decode_err(path, source))?;
    Ok(MaskPlan::new(&header, path, opts)?.header(file_len))
}

/// Reads a mask file (PNG or EXR, detected from its bytes); see the crate docs for the formats.
/// The pixels are those the file stores (an EXR's data window); [`read_placed_mask`] also says
/// where they lie.
pub fn read_mask(path: &Path, opts: &MaskReadOptions) -> Result<MaskImage, MaskError> {
    read_placed_mask(path, opts).map(|m| m.image)
}

/// Reads a mask file with its windows and whether it stores planes.
pub fn read_placed_mask(path: &Path, opts: &MaskReadOptions) -> Result<PlacedMask, MaskError> {
    let bytes = glassdb_io::read_input(path, glassdb_image::IMAGE_FILE).map_err(|source| {
        MaskError::Read {
            path: path.to_path_buf(),
            source,
        }
    })?;
    read_placed_mask_bytes(&bytes, path, opts)
}

/// Reads a mask from bytes in memory; `path` is only used in error messages.
pub fn read_mask_bytes(
    bytes: &[u8],
    path: &Path,
    opts: &MaskReadOptions,
) -> Result<MaskImage, MaskError> {
    read_placed_mask_bytes(bytes, path, opts).map(|m| m.image)
}

/// Reads a mask from bytes in memory with its windows; `path` is only used in error messages.
/// The header is read and checked first ([`read_mask_header`]'s checks), then only what the
/// layout needs is decoded.
pub fn read_placed_mask_bytes(
    bytes: &[u8],
    path: &Path,
    opts: &MaskReadOptions,
) -> Result<PlacedMask, MaskError> {
    let header = glassdb_image::read_image_header(Cursor::new(bytes), opts.max_pixels)
        .map_err(|source| decode_err(path, source))?;
    let plan = MaskPlan::new(&header, path, opts)?;
    let png = || glassdb_image::decode_png(bytes, opts.max_pixels).map_err(|s| decode_err(path, s));
    let exr = || glassdb_image::open_exr(bytes, opts.max_pixels).map_err(|s| decode_err(path, s));
    let placed = match plan {
        MaskPlan::Packed(h) => PlacedMask {
            image: packed_from_png(&png()?, path)?,
            windows: ImageWindows::full_frame(h.width as usize, h.height as usize),
            stores_planes: true,
            has_coordinates: false,
        },
        MaskPlan::Binary(h, id) => PlacedMask {
            image: binary_from_png(&png()?, id),
            windows: ImageWindows::full_frame(h.width as usize, h.height as usize),
            stores_planes: false,
            has_coordinates: false,
        },
        MaskPlan::Exr(p) => mask_from_exr(&exr()?, path, opts, &p)?,
        MaskPlan::Cryptomatte(p) => {
            let crypto = opts.cryptomatte.as_ref().ok_or_else(|| MaskError::Layout {
                path: path.to_path_buf(),
                detail: "no Cryptomatte options".into(),
            })?;
            decode_cryptomatte(&exr()?, path, crypto, p)?
        }
    };
    placed
        .image
        .check_consistent()
        .map_err(MaskError::Inconsistent)?;
    Ok(placed)
}

/// What the header decided: the layout and, for an EXR, the channels to decode.
pub(crate) enum MaskPlan {
    /// The packed RGB formats (8- or 16-bit).
    Packed(PngHeader),
    /// The paper's binary mask, every glass pixel getting the id.
    Binary(PngHeader, u16),
    Exr(ExrChannelsPlan),
    Cryptomatte(CryptomattePlan),
}

/// The (part, channel) of the id, cos θ, plane and coverage channels of an EXR mask (the last
/// two optional), and where they lie.
pub(crate) struct ExrChannelsPlan {
    wanted: [Option<(usize, usize)>; 4],
    windows: ImageWindows,
}

impl MaskPlan {
    /// Checks the layout `opts` asks for against the header.
    pub(crate) fn new(
        header: &ImageHeader,
        path: &Path,
        opts: &MaskReadOptions,
    ) -> Result<MaskPlan, MaskError> {
        match header {
            ImageHeader::Png(h) => match opts.binary_glass_id {
                Some(0) => Err(MaskError::Layout {
                    path: path.to_path_buf(),
                    detail: "glass id 0 means \"no glass\"; a binary mask needs an id from 1"
                        .into(),
                }),
                Some(id) => Ok(MaskPlan::Binary(*h, id)),
                None if h.channels < 3 => Err(MaskError::GreyPngWithoutGlassId {
                    path: path.to_path_buf(),
                }),
                None => Ok(MaskPlan::Packed(*h)),
            },
            ImageHeader::Exr(exr) => {
                if opts.binary_glass_id.is_some() {
                    return Err(MaskError::BinaryMaskNotPng {
                        path: path.to_path_buf(),
                    });
                }
                match &opts.cryptomatte {
                    Some(crypto) => plan_cryptomatte(exr, path, crypto, opts.max_pixels)
                        .map(MaskPlan::Cryptomatte),
                    None => plan_exr_channels(&exr.parts, path, opts).map(MaskPlan::Exr),
                }
            }
        }
    }

    /// The header's facts and the memory reading costs, for a file of `file_len` bytes.
    pub(crate) fn header(&self, file_len: u64) -> MaskHeader {
        let png = |h: &PngHeader, per_pixel: u64| MaskHeader {
            windows: ImageWindows::full_frame(h.width as usize, h.height as usize),
            stores_planes: false,
            has_coordinates: false,
            bytes_per_pixel: per_pixel,
            memory: ReadMemory::png(file_len, h).keeping(h.pixel_count().saturating_mul(per_pixel)),
        };
        match self {
            // id and plane u16, cos θ a code of the PNG's depth.
            MaskPlan::Packed(h) => MaskHeader {
                stores_planes: true,
                ..png(h, 4 + if h.sixteen_bit { 2 } else { 1 })
            },
            // id and plane u16, coverage f32.
            MaskPlan::Binary(h, _) => png(h, 8),
            MaskPlan::Exr(p) => {
                let pixels = p.windows.data.pixel_count();
                let [_, _, plane, coverage] = p.wanted;
                // id, plane u16; cos θ f32 (the decoded plane); coverage f32 (likewise).
                let per_pixel = 8 + if coverage.is_some() { 4 } else { 0 };
                let channels = p.wanted.iter().flatten().count();
                // The id and plane channels are decoded as f32 and converted.
                let decoded_id_plane = 4 * (1 + u64::from(plane.is_some()));
                MaskHeader {
                    windows: p.windows,
                    stores_planes: plane.is_some(),
                    has_coordinates: true,
                    bytes_per_pixel: per_pixel,
                    memory: ReadMemory {
                        transient: ReadMemory::exr_planes(file_len, pixels, channels).transient,
                        kept: 0,
                    }
                    .with_transient(pixels.saturating_mul(decoded_id_plane))
                    .keeping(pixels.saturating_mul(per_pixel)),
                }
            }
            MaskPlan::Cryptomatte(p) => p.header(file_len),
        }
    }
}

/// Locates the EXR mask's channels (id and cos θ required) and checks that their parts can be
/// read and share one data window.
fn plan_exr_channels(
    parts: &[ExrPart],
    path: &Path,
    opts: &MaskReadOptions,
) -> Result<ExrChannelsPlan, MaskError> {
    let names = &opts.exr_channels;
    let layer = opts.layer.as_deref();
    let wanted = [
        locate_channel(parts, &names.id, layer, true, path)?,
        locate_channel(parts, &names.cos_theta, layer, true, path)?,
        locate_channel(parts, &names.plane, layer, false, path)?,
        locate_channel(parts, &names.coverage, layer, false, path)?,
    ];
    let present: Vec<(usize, usize)> = wanted.iter().flatten().copied().collect();
    let windows = plan_channels(parts, &present, path, opts.max_pixels)?;
    Ok(ExrChannelsPlan { wanted, windows })
}

/// The packed formats: R = plane, G = id, B = cos θ code (8- or 16-bit). Alpha is ignored.
fn packed_from_png(png: &PngPixels, path: &Path) -> Result<MaskImage, MaskError> {
    if png.channels < 3 {
        return Err(MaskError::GreyPngWithoutGlassId {
            path: path.to_path_buf(),
        });
    }
    let n = png.width as usize * png.height as usize;
    let ch = png.channels;
    let (id, plane, cos_theta) = match &png.samples {
        PngSamples::U8(s) => return Ok(MaskImage::from_packed8(png.width, png.height, ch, s)),
        PngSamples::U16(s) => {
            let mut id = Vec::with_capacity(n);
            let mut plane = Vec::with_capacity(n);
            let mut cos = Vec::with_capacity(n);
            for px in s.chunks_exact(ch) {
                plane.push(px[0]);
                id.push(px[1]);
                cos.push(px[2]);
            }
            (id, plane, CosTheta::Quantized16(cos))
        }
    };
    Ok(MaskImage {
        width: png.width,
        height: png.height,
        id,
        cos_theta,
        plane,
        coverage: None,
    })
}

/// The paper's binary mask: black = no glass; any other value = glass `glass_id`, with coverage
/// = the largest colour sample / maximum (1 for white). Alpha is ignored.
/// The glass id is checked (not 0) by [`MaskPlan::new`].
fn binary_from_png(png: &PngPixels, glass_id: u16) -> MaskImage {
    let n = png.width as usize * png.height as usize;
    let colour_channels = if png.channels >= 3 { 3 } else { 1 };
    let max = png.max_value();
    let mut id = Vec::with_capacity(n);
    let mut coverage = Vec::with_capacity(n);
    let mut partial = false;
    for i in 0..n {
        let v = (0..colour_channels)
            .map(|c| u32::from(png.sample(i, c)))
            .max()
            .unwrap_or(0);
        id.push(if v == 0 { 0 } else { glass_id });
        partial |= v != 0 && v != max;
        coverage.push(v as f32 / max as f32);
    }
    MaskImage {
        width: png.width,
        height: png.height,
        id,
        cos_theta: CosTheta::Normal,
        plane: vec![0; n],
        coverage: partial.then_some(coverage),
    }
}

/// EXR masks: float (or uint) channels for id, cos θ and optionally plane and coverage, as
/// planned from the header.
fn mask_from_exr(
    exr: &ExrFile<'_>,
    path: &Path,
    opts: &MaskReadOptions,
    plan: &ExrChannelsPlan,
) -> Result<PlacedMask, MaskError> {
    let names = &opts.exr_channels;
    let wanted = plan.wanted;
    let stores_planes = wanted[2].is_some();
    let present: Vec<(usize, usize)> = wanted.iter().flatten().copied().collect();
    let (windows, mut decoded) = decode_channels(exr, &present, path)?;
    // Back to the four slots, in order: id, cos θ, plane, coverage (the absent ones None).
    decoded.reverse();
    let [id_f, cos_f, plane_f, cov_f] = wanted.map(|w| w.and_then(|_| decoded.pop()));
    let channels = FloatMaskChannels {
        id: &id_f.unwrap_or_default(),
        cos_theta: cos_f.unwrap_or_default(),
        plane: plane_f.as_deref(),
        coverage: cov_f,
    };
    let (w, h) = (windows.data.width, windows.data.height);
    Ok(PlacedMask {
        image: mask_from_floats(path, names, (w, h), channels)?,
        windows,
        stores_planes,
        has_coordinates: true,
    })
}

/// A mask's channels as float samples, one per pixel, row-major: what an EXR mask stores, or
/// what a host application (Python, a compositor plug-in) holds as arrays.
pub struct FloatMaskChannels<'a> {
    /// Glass id per pixel: integers 0–65535 (0: no glass).
    pub id: &'a [f32],
    /// cos θ per pixel, in [0, 1] on glass (rounding up to 1e-3 outside is clamped).
    pub cos_theta: Vec<f32>,
    /// Plane per pixel (integers 0–65535); `None`: every pixel on plane 0.
    pub plane: Option<&'a [f32]>,
    /// Coverage per pixel in [0, 1]; `None`: whole pixels.
    pub coverage: Option<Vec<f32>>,
}

/// The mask of `channels` over `size` (width, height) pixels, checked as an EXR mask's
/// channels are (ids and planes integers, cos θ and coverage in [0, 1]); errors name `path`
/// (the file, or the host's label for its arrays), the channel (`names`) and the pixel.
pub fn mask_from_floats(
    path: &Path,
    names: &ExrMaskChannels,
    size: (usize, usize),
    channels: FloatMaskChannels<'_>,
) -> Result<MaskImage, MaskError> {
    let (w, h) = size;
    let layout_err = |detail: &str| MaskError::Layout {
        path: path.to_path_buf(),
        detail: detail.into(),
    };
    let width = u32::try_from(w).map_err(|_| layout_err("too wide"))?;
    let height = u32::try_from(h).map_err(|_| layout_err("too tall"))?;
    let n = w * h;
    let lengths = [
        Some(channels.id.len()),
        Some(channels.cos_theta.len()),
        channels.plane.map(<[f32]>::len),
        channels.coverage.as_ref().map(Vec::len),
    ];
    if let Some(len) = lengths.into_iter().flatten().find(|&l| l != n) {
        return Err(layout_err(&format!(
            "a channel holds {len} samples for {w}×{h} pixels"
        )));
    }
    let pixel_err = PixelError { path, width: w };
    let id = indices_from_floats(channels.id, "glass id", &names.id, &pixel_err)?;
    let mut cos_f = channels.cos_theta;
    clamp_cos_theta(&mut cos_f, &id, &names.cos_theta, &pixel_err)?;
    let plane = match channels.plane {
        Some(p) => indices_from_floats(p, "plane", &names.plane, &pixel_err)?,
        None => vec![0; n],
    };
    let coverage = match channels.coverage {
        Some(mut c) => {
            clamp_coverage(&mut c, &names.coverage, &pixel_err)?;
            Some(c)
        }
        None => None,
    };
    Ok(MaskImage {
        width,
        height,
        id,
        cos_theta: CosTheta::Float(cos_f),
        plane,
        coverage,
    })
}

/// Float samples that must be integers in 0–65535 (ids, planes).
fn indices_from_floats(
    values: &[f32],
    what: &str,
    channel: &str,
    bad: &PixelError<'_>,
) -> Result<Vec<u16>, MaskError> {
    values
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            if (0.0..=65535.0).contains(&v) && v.fract() == 0.0 {
                Ok(v as u16)
            } else {
                Err(bad.at(
                    i,
                    format!("{what} {v} in channel {channel:?} is not an integer in 0–65535"),
                ))
            }
        })
        .collect()
}

/// How far outside [0, 1] a cos θ or coverage sample may stray (rounding) before it is an error.
const UNIT_TOLERANCE: f32 = 1e-3;

/// cos θ: checked on glass pixels; tiny excursions from rounding are clamped. Off glass any
/// value is clamped (NaN becomes 0).
fn clamp_cos_theta(
    cos: &mut [f32],
    id: &[u16],
    channel: &str,
    bad: &PixelError<'_>,
) -> Result<(), MaskError> {
    for (i, c) in cos.iter_mut().enumerate() {
        if id.get(i).copied().unwrap_or(0) == 0 {
            *c = c.clamp(0.0, 1.0);
            if c.is_nan() {
                *c = 0.0;
            }
            continue;
        }
        if !(c.is_finite() && *c >= -UNIT_TOLERANCE && *c <= 1.0 + UNIT_TOLERANCE) {
            return Err(bad.at(
                i,
                format!("cos θ {c} in channel {channel:?} is not in [0, 1]"),
            ));
        }
        *c = c.clamp(0.0, 1.0);
    }
    Ok(())
}

/// Coverage: every pixel in [0, 1] up to rounding, then clamped.
fn clamp_coverage(
    coverage: &mut [f32],
    channel: &str,
    bad: &PixelError<'_>,
) -> Result<(), MaskError> {
    for (i, v) in coverage.iter_mut().enumerate() {
        if !(v.is_finite() && *v >= -UNIT_TOLERANCE && *v <= 1.0 + UNIT_TOLERANCE) {
            return Err(bad.at(
                i,
                format!("coverage {v} in channel {channel:?} is not in [0, 1]"),
            ));
        }
        *v = v.clamp(0.0, 1.0);
    }
    Ok(())
}
