//! Glass masks: which pixels show glass, which glass (registration id), at what cos θ, on which
//! plane. Read by `glassdb registry build --mask` and by the compositor; written by
//! `glassdb mask`. The on-disk formats are documented in `docs/mask.md`:
//!
//! | format | id | cos θ | plane | coverage |
//! |---|---|---|---|---|
//! | 8-bit RGB PNG (the paper's packed mask, method.md "Mask") | G, 1–255 | B / 255 | R | – |
//! | 16-bit RGB PNG | G, 1–65535 | B / 65535 | R | – |
//! | EXR, float channels (names selectable) | `id` | `cos_theta` | `plane` (optional) | `coverage` (optional) |
//! | binary PNG (method.md, binary form), with [`MaskReadOptions::binary_glass_id`] | the given id where not black | 1 (normal incidence) | 0 | grey level |
//!
//! Id 0 means "no glass" everywhere.

mod cos_code;
pub mod exr_flat;
pub mod guard;
pub mod png_flat;
mod write;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub use cos_code::CosCode;
pub use write::{MaskFormat, write_mask, write_mask_bytes};

/// A decoded mask, row-major, row 0 at the top. All per-pixel vectors have `width * height`
/// entries.
#[derive(Debug, Clone, PartialEq)]
pub struct MaskImage {
    pub width: u32,
    pub height: u32,
    /// Glass registration id per pixel; 0 means "no glass".
    pub id: Vec<u16>,
    /// cos θ per pixel (angle of incidence of the view ray on the glass), as stored.
    pub cos_theta: CosTheta,
    /// Glass plane index per pixel (selects the reflection pass); all 0 with one plane.
    pub plane: Vec<u16>,
    /// Fraction of the pixel covered by glass, when the mask carries it (antialiased edges).
    pub coverage: Option<Vec<f32>>,
}

/// cos θ as the mask stores it: quantised codes ([`CosCode`]) are kept as codes so that
/// lookups into 256-entry tables stay exact.
#[derive(Debug, Clone, PartialEq)]
pub enum CosTheta {
    /// 8-bit: cos θ = code / 255 (the paper's packed mask).
    Quantized8(Vec<u8>),
    /// 16-bit: cos θ = code / 65535.
    Quantized16(Vec<u16>),
    /// Float: cos θ as given (EXR masks).
    Float(Vec<f32>),
    /// A binary mask carries no angle: every glass pixel is seen at normal incidence.
    Normal,
}

impl MaskImage {
    /// Number of pixels (`width * height`).
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Glass pixels per id (id 0, "no glass", is not counted). Used to list unknown ids with
    /// their pixel counts and by `glassdb registry build --mask`.
    pub fn id_pixel_counts(&self) -> BTreeMap<u16, u64> {
        let mut counts = vec![0u64; 65536];
        for &id in &self.id {
            counts[id as usize] += 1;
        }
        counts
            .iter()
            .enumerate()
            .skip(1)
            .filter(|(_, n)| **n > 0)
            .map(|(id, n)| (id as u16, *n))
            .collect()
    }

    /// cos θ of pixel `index` as a number in [0, 1]: code/255, code/65535, the float value,
    /// or 1 for a binary mask. Returns NaN for an index outside the image.
    pub fn cos_theta_at(&self, index: usize) -> f64 {
        let v = match &self.cos_theta {
            CosTheta::Quantized8(c) => c.get(index).map(|&c| CosCode::decode8(c)),
            CosTheta::Quantized16(c) => c.get(index).map(|&c| CosCode::Bits16.decode(c)),
            CosTheta::Float(c) => c.get(index).map(|&c| f64::from(c)),
            CosTheta::Normal => (index < self.pixel_count()).then_some(1.0),
        };
        v.unwrap_or(f64::NAN)
    }

    /// Smallest and largest cos θ over glass pixels (id ≠ 0); `None` without glass.
    pub fn cos_theta_range(&self) -> Option<(f64, f64)> {
        let mut range: Option<(f64, f64)> = None;
        for (i, &id) in self.id.iter().enumerate() {
            if id != 0 {
                let c = self.cos_theta_at(i);
                range = Some(match range {
                    None => (c, c),
                    Some((lo, hi)) => (lo.min(c), hi.max(c)),
                });
            }
        }
        range
    }

    /// Largest plane index over glass pixels (0 without glass).
    pub fn max_plane(&self) -> u16 {
        self.id
            .iter()
            .zip(&self.plane)
            .filter(|(id, _)| **id != 0)
            .map(|(_, p)| *p)
            .max()
            .unwrap_or(0)
    }

    /// Checks that every per-pixel vector has `width * height` entries.
    pub fn check_consistent(&self) -> Result<(), String> {
        let n = self.pixel_count();
        let len_cos = match &self.cos_theta {
            CosTheta::Quantized8(c) => Some(c.len()),
            CosTheta::Quantized16(c) => Some(c.len()),
            CosTheta::Float(c) => Some(c.len()),
            CosTheta::Normal => None,
        };
        let bad = |what: &str, len: usize| format!("{what} has {len} entries for {n} pixels");
        if self.id.len() != n {
            return Err(bad("id", self.id.len()));
        }
        if self.plane.len() != n {
            return Err(bad("plane", self.plane.len()));
        }
        if let Some(l) = len_cos.filter(|&l| l != n) {
            return Err(bad("cos_theta", l));
        }
        if let Some(c) = self.coverage.as_ref().filter(|c| c.len() != n) {
            return Err(bad("coverage", c.len()));
        }
        Ok(())
    }
}

/// Names of the EXR channels a mask is read from. Full channel names as stored in the file
/// (`ViewLayer.IndexMA`), or `layer.channel` for a named part of a multi-part file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExrMaskChannels {
    /// Glass id (float or uint, integral values 0–65535). Default `id`.
    pub id: String,
    /// cos θ in [0, 1]. Default `cos_theta`.
    pub cos_theta: String,
    /// Plane index (optional in the file; all 0 when absent). Default `plane`.
    pub plane: String,
    /// Pixel coverage in [0, 1] (optional in the file). Default `coverage`.
    pub coverage: String,
}

impl Default for ExrMaskChannels {
    fn default() -> Self {
        ExrMaskChannels {
            id: "id".into(),
            cos_theta: "cos_theta".into(),
            plane: "plane".into(),
            coverage: "coverage".into(),
        }
    }
}

/// How to read a mask file. The format (PNG or EXR) is detected from the file's bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MaskReadOptions {
    /// EXR channel names.
    pub exr_channels: ExrMaskChannels,
    /// Read a PNG as the paper's binary mask (section 5.1: white = glass, black = not), every
    /// glass pixel getting this id at normal incidence. `None`: the packed RGB formats.
    pub binary_glass_id: Option<u16>,
    /// Refuse images with more pixels than this (checked from the header before allocating).
    pub max_pixels: u64,
}

/// Default pixel limit: 2^27 (134 million pixels, e.g. 16384×8192).
pub const DEFAULT_MAX_PIXELS: u64 = 1 << 27;

impl Default for MaskReadOptions {
    fn default() -> Self {
        MaskReadOptions {
            exr_channels: ExrMaskChannels::default(),
            binary_glass_id: None,
            max_pixels: DEFAULT_MAX_PIXELS,
        }
    }
}

/// Everything that can go wrong reading or writing a mask; every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum MaskError {
    #[error("cannot read mask {path}: {cause}")]
    Read {
        path: PathBuf,
        cause: std::io::Error,
    },
    #[error("mask {path} is neither PNG nor OpenEXR (it starts with bytes {start:02x?})")]
    UnknownFormat { path: PathBuf, start: Vec<u8> },
    #[error("mask {path}: {cause}")]
    Png {
        path: PathBuf,
        cause: png_flat::PngFlatError,
    },
    #[error("mask {path}: {cause}")]
    Exr {
        path: PathBuf,
        cause: exr_flat::ExrFlatError,
    },
    /// The file decodes but is not laid out as any mask format (e.g. grey PNG without a glass id).
    #[error("mask {path}: {detail}")]
    Layout { path: PathBuf, detail: String },
    #[error("mask {path} has no channel {channel:?} (it has: {})", available.join(", "))]
    MissingChannel {
        path: PathBuf,
        channel: String,
        available: Vec<String>,
    },
    /// A pixel value that the format does not allow.
    #[error("mask {path}, pixel (x {x}, y {y}): {detail}")]
    BadPixel {
        path: PathBuf,
        x: u32,
        y: u32,
        detail: String,
    },
    /// A mask that cannot be stored in the requested format without loss.
    #[error("cannot write mask {path} as {format}: {detail}")]
    NotRepresentable {
        path: PathBuf,
        format: &'static str,
        detail: String,
    },
    #[error("mask image is inconsistent: {0}")]
    Inconsistent(String),
    #[error("cannot encode mask {path}: {detail}")]
    Encode { path: PathBuf, detail: String },
    #[error(transparent)]
    Write(#[from] glassdb_io::OutputError),
}

/// The file formats this crate recognises by their first bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFileKind {
    Png,
    Exr,
}

/// Detects PNG or OpenEXR from the magic number.
pub fn sniff_image_kind(bytes: &[u8]) -> Option<ImageFileKind> {
    if bytes.starts_with(&[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]) {
        Some(ImageFileKind::Png)
    } else if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        Some(ImageFileKind::Exr)
    } else {
        None
    }
}

/// Reads a mask file (PNG or EXR, detected from its bytes); see the crate docs for the formats.
pub fn read_mask(path: &Path, opts: &MaskReadOptions) -> Result<MaskImage, MaskError> {
    let bytes = std::fs::read(path).map_err(|cause| MaskError::Read {
        path: path.to_path_buf(),
        cause,
    })?;
    read_mask_bytes(&bytes, path, opts)
}

/// Reads a mask from bytes in memory; `path` is only used in error messages.
pub fn read_mask_bytes(
    bytes: &[u8],
    path: &Path,
    opts: &MaskReadOptions,
) -> Result<MaskImage, MaskError> {
    let mask = match sniff_image_kind(bytes) {
        Some(ImageFileKind::Png) => {
            let png =
                png_flat::decode_png(bytes, opts.max_pixels).map_err(|cause| MaskError::Png {
                    path: path.to_path_buf(),
                    cause,
                })?;
            match opts.binary_glass_id {
                Some(id) => binary_from_png(&png, id, path)?,
                None => packed_from_png(&png, path)?,
            }
        }
        Some(ImageFileKind::Exr) => {
            if opts.binary_glass_id.is_some() {
                return Err(MaskError::Layout {
                    path: path.to_path_buf(),
                    detail: "a binary mask (--glass) must be a PNG; an EXR mask carries its ids in a channel".into(),
                });
            }
            mask_from_exr(bytes, path, opts)?
        }
        None => {
            return Err(MaskError::UnknownFormat {
                path: path.to_path_buf(),
                start: bytes.iter().take(8).copied().collect(),
            });
        }
    };
    mask.check_consistent().map_err(MaskError::Inconsistent)?;
    Ok(mask)
}

/// The packed formats: R = plane, G = id, B = cos θ code (8- or 16-bit). Alpha is ignored.
fn packed_from_png(png: &png_flat::PngPixels, path: &Path) -> Result<MaskImage, MaskError> {
    if png.channels < 3 {
        return Err(MaskError::Layout {
            path: path.to_path_buf(),
            detail: "a grey PNG is not a packed id + cos θ mask (it needs RGB: R = plane, G = id, B = cos θ); \
                     for the paper's binary white/black mask give the glass id (--glass ID)"
                .into(),
        });
    }
    let n = png.width as usize * png.height as usize;
    let ch = png.channels;
    let (id, plane, cos_theta) = match &png.samples {
        png_flat::PngSamples::U8(s) => {
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
        png_flat::PngSamples::U16(s) => {
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
fn binary_from_png(
    png: &png_flat::PngPixels,
    glass_id: u16,
    path: &Path,
) -> Result<MaskImage, MaskError> {
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
    bytes: &[u8],
    path: &Path,
    opts: &MaskReadOptions,
) -> Result<MaskImage, MaskError> {
    let exr_err = |cause| MaskError::Exr {
        path: path.to_path_buf(),
        cause,
    };
    let parts = exr_flat::read_exr_headers(bytes).map_err(exr_err)?;
    let names = &opts.exr_channels;
    let locate = |name: &str, required: bool| -> Result<Option<(usize, usize)>, MaskError> {
        match exr_flat::find_channel(&parts, name) {
            Some(found) => Ok(Some(found)),
            None if required => Err(MaskError::MissingChannel {
                path: path.to_path_buf(),
                channel: name.to_string(),
                available: exr_flat::all_channel_names(&parts),
            }),
            None => Ok(None),
        }
    };
    let wanted = [
        locate(&names.id, true)?,
        locate(&names.cos_theta, true)?,
        locate(&names.plane, false)?,
        locate(&names.coverage, false)?,
    ];
    // Decode each part once, with all its wanted channels.
    let mut decoded: [Option<Vec<f32>>; 4] = [None, None, None, None];
    let mut size: Option<(usize, usize)> = None;
    let mut part_indices: Vec<usize> = wanted.iter().flatten().map(|(p, _)| *p).collect();
    part_indices.sort_unstable();
    part_indices.dedup();
    for p in part_indices {
        let slots: Vec<usize> = (0..4)
            .filter(|&k| matches!(wanted[k], Some((q, _)) if q == p))
            .collect();
        let channels: Vec<usize> = slots
            .iter()
            .filter_map(|&k| wanted[k].map(|(_, c)| c))
            .collect();
        let (info, buffers) =
            exr_flat::read_exr_channels(bytes, p, &channels, opts.max_pixels).map_err(exr_err)?;
        match size {
            None => size = Some((info.width, info.height)),
            Some(s) if s != (info.width, info.height) => {
                return Err(MaskError::Layout {
                    path: path.to_path_buf(),
                    detail: format!(
                        "the mask channels lie in parts of different sizes ({}×{} and {}×{})",
                        s.0, s.1, info.width, info.height
                    ),
                });
            }
            Some(_) => {}
        }
        for (k, buf) in slots.into_iter().zip(buffers) {
            decoded[k] = Some(buf);
        }
    }
    let (w, h) = size.ok_or_else(|| MaskError::Layout {
        path: path.to_path_buf(),
        detail: "no mask channels".into(),
    })?;
    let (width, height) = (
        u32::try_from(w).map_err(|_| MaskError::Layout {
            path: path.to_path_buf(),
            detail: "too wide".into(),
        })?,
        u32::try_from(h).map_err(|_| MaskError::Layout {
            path: path.to_path_buf(),
            detail: "too tall".into(),
        })?,
    );
    let [id_f, cos_f, plane_f, cov_f] = decoded;
    let id_f = id_f.unwrap_or_default();
    let mut cos_f = cos_f.unwrap_or_default();
    let bad = |i: usize, detail: String| MaskError::BadPixel {
        path: path.to_path_buf(),
        x: (i % w) as u32,
        y: (i / w) as u32,
        detail,
    };
    let as_index = |v: f32, what: &str, channel: &str, i: usize| -> Result<u16, MaskError> {
        if (0.0..=65535.0).contains(&v) && v.fract() == 0.0 {
            Ok(v as u16)
        } else {
            Err(bad(
                i,
                format!("{what} {v} in channel {channel:?} is not an integer in 0–65535"),
            ))
        }
    };
    let mut id = Vec::with_capacity(w * h);
    for (i, &v) in id_f.iter().enumerate() {
        id.push(as_index(v, "glass id", &names.id, i)?);
    }
    // cos θ: checked on glass pixels; tiny excursions from rounding are clamped.
    const COS_TOLERANCE: f32 = 1e-3;
    for (i, c) in cos_f.iter_mut().enumerate() {
        if id.get(i).copied().unwrap_or(0) == 0 {
            *c = c.clamp(0.0, 1.0);
            if c.is_nan() {
                *c = 0.0;
            }
            continue;
        }
        if !(c.is_finite() && *c >= -COS_TOLERANCE && *c <= 1.0 + COS_TOLERANCE) {
            return Err(bad(
                i,
                format!(
                    "cos θ {c} in channel {:?} is not in [0, 1]",
                    names.cos_theta
                ),
            ));
        }
        *c = c.clamp(0.0, 1.0);
    }
    let plane = match plane_f {
        Some(p) => {
            let mut plane = Vec::with_capacity(w * h);
            for (i, &v) in p.iter().enumerate() {
                plane.push(as_index(v, "plane", &names.plane, i)?);
            }
            plane
        }
        None => vec![0; w * h],
    };
    let coverage = match cov_f {
        Some(mut c) => {
            for (i, v) in c.iter_mut().enumerate() {
                if !(v.is_finite() && *v >= -COS_TOLERANCE && *v <= 1.0 + COS_TOLERANCE) {
                    return Err(bad(
                        i,
                        format!(
                            "coverage {v} in channel {:?} is not in [0, 1]",
                            names.coverage
                        ),
                    ));
                }
                *v = v.clamp(0.0, 1.0);
            }
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

#[cfg(test)]
mod tests;
