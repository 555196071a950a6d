//! Writing masks (atomically, through `glassdb-io`).

use std::path::Path;

use glassdb_image::{ImageError, PngColor, PngCompression, PngEncodeOptions, PngSampleSlice};

use crate::{CosCode, CosTheta, MaskError, MaskImage};

/// The file formats a mask can be written in (see the crate docs and `docs/mask.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MaskFormat {
    /// 8-bit RGB PNG: R = plane (0–255), G = id (1–255), B = round(cos θ·255).
    Png8,
    /// 16-bit RGB PNG: R = plane, G = id (1–65535), B = round(cos θ·65535).
    Png16,
    /// OpenEXR, ZIP-compressed float channels `id`, `cos_theta`, and `plane` (when any pixel
    /// is on a plane other than 0) and `coverage` (when the mask has it).
    Exr,
    /// The paper's binary mask (section 5.1): 8-bit grey PNG, 255 = glass, 0 = not, grey =
    /// partial coverage. It holds one glass on one plane and no angle: `compose --glass ID`
    /// shows it at normal incidence.
    Binary,
}

impl MaskFormat {
    fn name(self) -> &'static str {
        match self {
            MaskFormat::Png8 => "8-bit PNG",
            MaskFormat::Png16 => "16-bit PNG",
            MaskFormat::Exr => "EXR",
            MaskFormat::Binary => "binary PNG",
        }
    }
}

/// Writes `mask` to `path` in `format`, atomically (a temporary file renamed into place).
/// cos θ is quantised to the format's precision (round to nearest); ids, planes or coverage
/// that the format cannot hold are an error naming the first pixel, never a silent loss.
pub fn write_mask(path: &Path, mask: &MaskImage, format: MaskFormat) -> Result<(), MaskError> {
    let bytes = write_mask_bytes(path, mask, format)?;
    glassdb_io::write_bytes_atomic(path, &bytes)?;
    Ok(())
}

/// Encodes `mask` in `format` into memory; `path` is only used in error messages.
pub fn write_mask_bytes(
    path: &Path,
    mask: &MaskImage,
    format: MaskFormat,
) -> Result<Vec<u8>, MaskError> {
    mask.check_consistent().map_err(MaskError::Inconsistent)?;
    let at = PixelErrors { path, mask, format };
    match format {
        MaskFormat::Png8 => packed_png(mask, CosCode::Bits8, &at),
        MaskFormat::Png16 => packed_png(mask, CosCode::Bits16, &at),
        MaskFormat::Binary => binary_png(mask, &at),
        MaskFormat::Exr => exr_channels(mask, path),
    }
}

/// Builds the "cannot be stored" errors of one mask write, naming the pixel.
struct PixelErrors<'a> {
    path: &'a Path,
    mask: &'a MaskImage,
    format: MaskFormat,
}

impl PixelErrors<'_> {
    fn whole(&self, detail: &str) -> MaskError {
        MaskError::NotRepresentable {
            path: self.path.to_path_buf(),
            format: self.format.name(),
            detail: detail.to_string(),
        }
    }

    fn at(&self, i: usize, detail: String) -> MaskError {
        let w = (self.mask.width as usize).max(1);
        self.whole(&format!("pixel (x {}, y {}): {detail}", i % w, i / w))
    }
}

/// The packed formats: R = plane, G = id, B = cos θ code of `code_width`'s precision.
fn packed_png(
    mask: &MaskImage,
    code_width: CosCode,
    at: &PixelErrors<'_>,
) -> Result<Vec<u8>, MaskError> {
    if mask.coverage.is_some() {
        return Err(
            at.whole("a PNG mask has no coverage channel; write EXR to keep antialiased edges")
        );
    }
    let limit = code_width.max_code();
    let mut samples: Vec<u16> = Vec::with_capacity(mask.pixel_count() * 3);
    for i in 0..mask.pixel_count() {
        let id = mask.id[i];
        let plane = mask.plane[i];
        if id > limit {
            return Err(at.at(i, format!("glass id {id} is above {limit}")));
        }
        if plane > limit {
            return Err(at.at(i, format!("plane {plane} is above {limit}")));
        }
        let code = match (&mask.cos_theta, code_width) {
            (CosTheta::Quantized8(c), CosCode::Bits8) => u16::from(c[i]),
            (CosTheta::Quantized8(c), _) => CosCode::Bits8.to_bits16(u16::from(c[i])),
            (CosTheta::Quantized16(c), CosCode::Bits16) => c[i],
            (CosTheta::Normal, _) => limit,
            _ => {
                let c = mask.cos_theta_at(i);
                if !c.is_finite() {
                    return Err(at.at(i, format!("cos θ {c} is not a number")));
                }
                code_width.encode(c)
            }
        };
        samples.extend_from_slice(&[plane, id, code]);
    }
    encode_png_rgb(
        at.path,
        mask.width,
        mask.height,
        &samples,
        code_width == CosCode::Bits16,
    )
}

/// The paper's binary form: one glass on one plane, coverage as grey, never black on glass.
fn binary_png(mask: &MaskImage, at: &PixelErrors<'_>) -> Result<Vec<u8>, MaskError> {
    let mut glass_id = None;
    let mut grey = Vec::with_capacity(mask.pixel_count());
    for i in 0..mask.pixel_count() {
        let id = mask.id[i];
        if id == 0 {
            grey.push(0u8);
            continue;
        }
        match glass_id {
            None => glass_id = Some(id),
            Some(first) if first != id => {
                return Err(at.at(
                    i,
                    format!(
                        "glass id {id} after id {first}: a binary mask shows one glass; \
                         write a packed PNG or EXR mask for several"
                    ),
                ));
            }
            Some(_) => {}
        }
        if mask.plane[i] != 0 {
            return Err(at.at(
                i,
                format!(
                    "plane {}: a binary mask has one plane; write a packed PNG or EXR mask",
                    mask.plane[i]
                ),
            ));
        }
        let c = mask.coverage.as_ref().map_or(1.0, |c| c[i]);
        if !c.is_finite() {
            return Err(at.at(i, format!("coverage {c} is not a number")));
        }
        // A glass pixel never turns black: black means "no glass" to the reader.
        grey.push(((c.clamp(0.0, 1.0) * 255.0).round() as u8).max(1));
    }
    encode_png_grey(at.path, mask.width, mask.height, &grey)
}

/// Float EXR channels `id`, `cos_theta`, `plane`, and `coverage` where the mask has it. The
/// plane channel is written even when every pixel is on plane 0: a frame that sees one plane
/// of several still says so, and compose refuses several reflection passes beside a mask that
/// does not say which plane each pixel is on.
fn exr_channels(mask: &MaskImage, path: &Path) -> Result<Vec<u8>, MaskError> {
    let n = mask.pixel_count();
    let id: Vec<f32> = mask.id.iter().map(|&v| f32::from(v)).collect();
    let cos: Vec<f32> = match &mask.cos_theta {
        CosTheta::Float(c) => c.clone(),
        _ => (0..n).map(|i| mask.cos_theta_at(i) as f32).collect(),
    };
    let plane: Vec<f32> = mask.plane.iter().map(|&p| f32::from(p)).collect();
    let mut channels = vec![("id", id), ("cos_theta", cos), ("plane", plane)];
    if let Some(c) = &mask.coverage {
        channels.push(("coverage", c.clone()));
    }
    glassdb_image::encode_exr_f32(mask.width as usize, mask.height as usize, channels)
        .map_err(|source| encode_err(path, source))
}

fn encode_err(path: &Path, source: ImageError) -> MaskError {
    MaskError::Encode {
        path: path.to_path_buf(),
        source,
    }
}

/// Masks are small and written once: balanced deflate, no colour chunk (the samples are codes,
/// not light).
const MASK_PNG: PngEncodeOptions = PngEncodeOptions {
    compression: PngCompression::Balanced,
    srgb_chunk: false,
};

/// Encodes interleaved RGB samples (each < 256 when `sixteen` is false) as a PNG.
fn encode_png_rgb(
    path: &Path,
    width: u32,
    height: u32,
    samples: &[u16],
    sixteen: bool,
) -> Result<Vec<u8>, MaskError> {
    let eight: Vec<u8>;
    let data = if sixteen {
        PngSampleSlice::U16(samples)
    } else {
        eight = samples.iter().map(|&s| s as u8).collect();
        PngSampleSlice::U8(&eight)
    };
    glassdb_image::encode_png(width, height, PngColor::Rgb, data, MASK_PNG)
        .map_err(|source| encode_err(path, source))
}

/// Encodes 8-bit grey samples as a PNG.
fn encode_png_grey(
    path: &Path,
    width: u32,
    height: u32,
    grey: &[u8],
) -> Result<Vec<u8>, MaskError> {
    glassdb_image::encode_png(
        width,
        height,
        PngColor::Grey,
        PngSampleSlice::U8(grey),
        MASK_PNG,
    )
    .map_err(|source| encode_err(path, source))
}
