//! Reading masks: the one image reader of glassdb-image decodes the file, and each mask
//! format's layout (packed PNG, binary PNG, EXR channels) becomes a [`MaskImage`].

use std::path::Path;

use glassdb_image::{
    ChannelMatch, ExrFile, ExrPart, ImageFile, ImageWindows, PngPixels, PngSamples,
};

use crate::{CosTheta, MaskError, MaskImage, MaskReadOptions, PlacedMask};

/// Reads a mask file (PNG or EXR, detected from its bytes); see the crate docs for the formats.
/// The pixels are those the file stores (an EXR's data window); [`read_placed_mask`] also says
/// where they lie.
pub fn read_mask(path: &Path, opts: &MaskReadOptions) -> Result<MaskImage, MaskError> {
    read_placed_mask(path, opts).map(|m| m.image)
}

/// Reads a mask file with its windows and whether it stores planes.
pub fn read_placed_mask(path: &Path, opts: &MaskReadOptions) -> Result<PlacedMask, MaskError> {
    let bytes = glassdb_io::read_input(path, glassdb_io::limits::IMAGE).map_err(|source| {
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
pub fn read_placed_mask_bytes(
    bytes: &[u8],
    path: &Path,
    opts: &MaskReadOptions,
) -> Result<PlacedMask, MaskError> {
    let decode_err = |source| MaskError::Decode {
        path: path.to_path_buf(),
        source,
    };
    let placed = match glassdb_image::open_image(bytes, opts.max_pixels).map_err(decode_err)? {
        ImageFile::Png(png) => {
            let windows = ImageWindows::full_frame(png.width as usize, png.height as usize);
            match opts.binary_glass_id {
                Some(id) => PlacedMask {
                    image: binary_from_png(&png, id, path)?,
                    windows,
                    stores_planes: false,
                    has_coordinates: false,
                },
                None => PlacedMask {
                    image: packed_from_png(&png, path)?,
                    windows,
                    stores_planes: true,
                    has_coordinates: false,
                },
            }
        }
        ImageFile::Exr(exr) => {
            if opts.binary_glass_id.is_some() {
                return Err(MaskError::BinaryMaskNotPng {
                    path: path.to_path_buf(),
                });
            }
            match &opts.cryptomatte {
                Some(crypto) => crate::mask_from_cryptomatte(&exr, path, crypto)?,
                None => mask_from_exr(&exr, path, opts)?,
            }
        }
    };
    placed
        .image
        .check_consistent()
        .map_err(MaskError::Inconsistent)?;
    Ok(placed)
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
        PngSamples::U8(s) => {
            let mut id = Vec::with_capacity(n);
            let mut plane = Vec::with_capacity(n);
            let mut cos = Vec::with_capacity(n);
            for px in s.chunks_exact(ch) {
                plane.push(u16::from(px[0]));
                id.push(u16::from(px[1]));
                cos.push(px[2]);
            }
            (id, plane, CosTheta::Quantized8(cos))
        }
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
fn binary_from_png(png: &PngPixels, glass_id: u16, path: &Path) -> Result<MaskImage, MaskError> {
    if glass_id == 0 {
        return Err(MaskError::Layout {
            path: path.to_path_buf(),
            detail: "glass id 0 means \"no glass\"; a binary mask needs an id from 1".into(),
        });
    }
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
    Ok(MaskImage {
        width: png.width,
        height: png.height,
        id,
        cos_theta: CosTheta::Normal,
        plane: vec![0; n],
        coverage: partial.then_some(coverage),
    })
}

/// EXR masks: float (or uint) channels for id, cos θ and optionally plane and coverage.
fn mask_from_exr(
    exr: &ExrFile<'_>,
    path: &Path,
    opts: &MaskReadOptions,
) -> Result<PlacedMask, MaskError> {
    let names = &opts.exr_channels;
    let layer = opts.layer.as_deref();
    let wanted = [
        locate_channel(exr.parts(), &names.id, layer, true, path)?,
        locate_channel(exr.parts(), &names.cos_theta, layer, true, path)?,
        locate_channel(exr.parts(), &names.plane, layer, false, path)?,
        locate_channel(exr.parts(), &names.coverage, layer, false, path)?,
    ];
    let stores_planes = wanted[2].is_some();
    let present: Vec<(usize, usize)> = wanted.iter().flatten().copied().collect();
    let (windows, mut decoded) = decode_channels(exr, &present, path)?;
    // Back to the four slots, in order: id, cos θ, plane, coverage (the absent ones None).
    decoded.reverse();
    let [id_f, cos_f, plane_f, cov_f] = wanted.map(|w| w.and_then(|_| decoded.pop()));
    let (w, h) = (windows.data.width, windows.data.height);
    let layout_err = |detail: &str| MaskError::Layout {
        path: path.to_path_buf(),
        detail: detail.into(),
    };
    let width = u32::try_from(w).map_err(|_| layout_err("too wide"))?;
    let height = u32::try_from(h).map_err(|_| layout_err("too tall"))?;
    let pixel_err = PixelError { path, width: w };
    let id = indices_from_floats(&id_f.unwrap_or_default(), "glass id", &names.id, &pixel_err)?;
    let mut cos_f = cos_f.unwrap_or_default();
    clamp_cos_theta(&mut cos_f, &id, &names.cos_theta, &pixel_err)?;
    let plane = match plane_f {
        Some(p) => indices_from_floats(&p, "plane", &names.plane, &pixel_err)?,
        None => vec![0; w * h],
    };
    let coverage = match cov_f {
        Some(mut c) => {
            clamp_coverage(&mut c, &names.coverage, &pixel_err)?;
            Some(c)
        }
        None => None,
    };
    Ok(PlacedMask {
        image: MaskImage {
            width,
            height,
            id,
            cos_theta: CosTheta::Float(cos_f),
            plane,
            coverage,
        },
        windows,
        stores_planes,
        has_coordinates: true,
    })
}

/// Finds the (part, channel) named `name` (in `layer`, when given); a required channel that is
/// missing is an error listing the channels the file has.
pub(crate) fn locate_channel(
    parts: &[ExrPart],
    name: &str,
    layer: Option<&str>,
    required: bool,
    path: &Path,
) -> Result<Option<(usize, usize)>, MaskError> {
    match glassdb_image::find_channel(parts, name, layer) {
        ChannelMatch::Found(p, c) => Ok(Some((p, c))),
        ChannelMatch::Ambiguous(candidates) => Err(MaskError::AmbiguousChannel {
            path: path.to_path_buf(),
            channel: name.to_string(),
            candidates,
        }),
        ChannelMatch::Missing if required => Err(MaskError::MissingChannel {
            path: path.to_path_buf(),
            channel: match layer {
                Some(l) => format!("{l}.{name}"),
                None => name.to_string(),
            },
            available: glassdb_image::all_channel_names(parts),
        }),
        ChannelMatch::Missing => Ok(None),
    }
}

/// Decodes channels `wanted` (part, channel) of the file, each part once with all its wanted
/// channels, in the order asked; every part must have the same data window.
pub(crate) fn decode_channels(
    exr: &ExrFile<'_>,
    wanted: &[(usize, usize)],
    path: &Path,
) -> Result<(ImageWindows, Vec<Vec<f32>>), MaskError> {
    let mut out: Vec<Vec<f32>> = vec![Vec::new(); wanted.len()];
    let mut windows: Option<ImageWindows> = None;
    let mut parts: Vec<usize> = wanted.iter().map(|w| w.0).collect();
    parts.sort_unstable();
    parts.dedup();
    for p in parts {
        let slots: Vec<usize> = (0..wanted.len()).filter(|&k| wanted[k].0 == p).collect();
        let channels: Vec<usize> = slots.iter().map(|&k| wanted[k].1).collect();
        let (info, buffers) =
            exr.read_channels(p, &channels)
                .map_err(|source| MaskError::Decode {
                    path: path.to_path_buf(),
                    source,
                })?;
        match windows {
            None => windows = Some(info.windows()),
            Some(w) if w.data != info.data_window => {
                return Err(MaskError::Layout {
                    path: path.to_path_buf(),
                    detail: format!(
                        "the mask channels lie in parts with different data windows ({} and {})",
                        w.data, info.data_window
                    ),
                });
            }
            Some(_) => {}
        }
        for (k, b) in slots.into_iter().zip(buffers) {
            out[k] = b;
        }
    }
    let windows = windows.ok_or_else(|| MaskError::Layout {
        path: path.to_path_buf(),
        detail: "no mask channels".into(),
    })?;
    Ok((windows, out))
}

/// Builds [`MaskError::BadPixel`] for a pixel index of a mask file.
pub(crate) struct PixelError<'a> {
    pub(crate) path: &'a Path,
    pub(crate) width: usize,
}

impl PixelError<'_> {
    pub(crate) fn at(&self, i: usize, detail: String) -> MaskError {
        MaskError::BadPixel {
            path: self.path.to_path_buf(),
            x: (i % self.width) as u32,
            y: (i / self.width) as u32,
            detail,
        }
    }
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
