//! The passes both benchmark generators write (`make_bench_inputs`, `make_plane_bench_inputs`):
//! a transmission and a reflection pass of smooth gradients plus render-like noise, so that
//! compression sees realistic data.

use std::path::{Path, PathBuf};

use glassdb_encode::{ExrDataType, OutputOptions, parse_exr_compression, write_output};
use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};
use glassdb_pass::{CarriedFrame, LinearImage, PassSource, PngBits};

/// The arguments `make_bench_inputs` and `make_plane_bench_inputs` start with:
/// `OUT_DIR WIDTH HEIGHT half|float COMPRESSION`.
#[allow(dead_code)] // not every generator takes these arguments
pub struct FrameArgs {
    /// The folder the inputs are written to.
    pub out: PathBuf,
    /// The frame's width in pixels.
    pub width: usize,
    /// The frame's height in pixels.
    pub height: usize,
    /// The passes' sample type (`half`, else float).
    pub data_type: ExrDataType,
    /// The passes' EXR compression.
    pub compression: exr::compression::Compression,
}

#[allow(dead_code)] // not every generator takes these arguments
impl FrameArgs {
    /// Reads them from `a[1..=5]` (`a[0]` is the program).
    pub fn parse(a: &[String]) -> Result<FrameArgs, Box<dyn std::error::Error>> {
        Ok(FrameArgs {
            out: PathBuf::from(&a[1]),
            width: a[2].parse()?,
            height: a[3].parse()?,
            data_type: if a[4] == "half" {
                ExrDataType::Half
            } else {
                ExrDataType::Float
            },
            compression: parse_exr_compression(&a[5])?,
        })
    }
}

/// A deterministic hash of `i` in [0, 1).
fn noise(i: u64) -> f32 {
    let mut x = i.wrapping_mul(0x9e37_79b9_7f4a_7c15);
    x ^= x >> 31;
    x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x ^= x >> 29;
    (x >> 40) as f32 / (1u64 << 24) as f32
}

/// R, G, B planes of `w × h`: a gradient of `base` plus noise seeded by `seed`.
#[allow(dead_code)] // not every generator writes these passes
pub fn gradient_planes(w: usize, h: usize, seed: u64, base: [f32; 3]) -> [Vec<f32>; 3] {
    let n = w * h;
    let mut rgb = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
    for (c, plane) in rgb.iter_mut().enumerate() {
        for (i, v) in plane.iter_mut().enumerate() {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            *v = base[c] * (0.3 + 0.7 * x * (1.0 - 0.5 * y))
                + 0.05 * noise(seed + (i * 3 + c) as u64);
        }
    }
    rgb
}

/// A `w × h` pass: a gradient of `base` plus render-like noise from `seed`.
#[allow(dead_code)] // not every generator writes these passes
pub fn pass_image(w: usize, h: usize, seed: u64, base: [f32; 3]) -> LinearImage {
    LinearImage {
        width: w as u32,
        height: h as u32,
        rgb: gradient_planes(w, h, seed, base),
        alpha: None,
    }
}

/// The seed and base colour of the reflection pass.
#[allow(dead_code)] // not every generator writes these passes
pub const REFL: (u64, [f32; 3]) = (1 << 40, [0.9, 1.0, 1.2]);

/// Writes `frame.out/trans.exr` and `frame.out/refl.exr`, `frame.width × frame.height`, in
/// `frame.data_type` with `frame.compression`.
#[allow(dead_code)] // not every generator writes these passes
pub fn write_passes(frame: &FrameArgs) -> Result<(), Box<dyn std::error::Error>> {
    let (out, w, h) = (&frame.out, frame.width, frame.height);
    let opts = OutputOptions {
        exr_data_type: Some(frame.data_type),
        exr_compression: Some(frame.compression),
        ..OutputOptions::default()
    };
    let src = PassSource::Png {
        bits: PngBits::Eight,
    };
    let whole = || CarriedFrame::whole(w as u32, h as u32);
    let trans = pass_image(w, h, 1, [0.6, 0.5, 0.4]);
    write_output(&out.join("trans.exr"), trans, whole(), &src, &opts)?;
    let refl = pass_image(w, h, REFL.0, REFL.1);
    write_output(&out.join("refl.exr"), refl, whole(), &src, &opts)?;
    Ok(())
}

/// The benchmarks' mask, `w × h`: every other quarter of the rows glass (ids 2 and 6 of the
/// bundled catalog, left and right halves), cos θ varying across the frame, 8-bit.
#[allow(dead_code)] // not every generator writes this mask
fn half_glass_mask(w: u32, h: u32) -> MaskImage {
    let n = (w * h) as usize;
    let mut id = vec![0u16; n];
    let mut cos = vec![0u8; n];
    for i in 0..n {
        let (x, y) = (i % w as usize, i / w as usize);
        if (y * 4 / h as usize).is_multiple_of(2) {
            id[i] = if x < w as usize / 2 { 2 } else { 6 };
            cos[i] = (40 + x * 200 / w as usize) as u8;
        }
    }
    MaskImage {
        width: w,
        height: h,
        id,
        cos_theta: CosTheta::Quantized8(cos),
        plane: vec![0; n],
        coverage: None,
    }
}

/// Writes the benchmarks' mask ([`half_glass_mask`]), `w × h`, as `out/mask.png`.
#[allow(dead_code)] // not every generator writes this mask
pub fn write_half_glass_mask(out: &Path, w: u32, h: u32) -> Result<(), Box<dyn std::error::Error>> {
    write_mask(
        &out.join("mask.png"),
        &half_glass_mask(w, h),
        MaskFormat::Png8,
    )?;
    Ok(())
}
