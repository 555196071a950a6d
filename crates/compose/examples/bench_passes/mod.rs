//! The passes both benchmark generators write (`make_bench_inputs`, `make_plane_bench_inputs`):
//! a transmission and a reflection pass of smooth gradients plus render-like noise, so that
//! compression sees realistic data.

use std::path::Path;

use glassdb_encode::{ExrDataType, OutputOptions, write_output};
use glassdb_pass::{CarriedFrame, LinearImage, PassSource, PngBits};

/// A deterministic hash of `i` in [0, 1).
fn noise(i: u64) -> f32 {
    let mut x = i.wrapping_mul(0x9e37_79b9_7f4a_7c15);
    x ^= x >> 31;
    x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x ^= x >> 29;
    (x >> 40) as f32 / (1u64 << 24) as f32
}

/// A `w × h` pass: a gradient of `base` plus render-like noise from `seed`.
pub fn pass_image(w: usize, h: usize, seed: u64, base: [f32; 3]) -> LinearImage {
    let n = w * h;
    let mut rgb = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
    for (c, plane) in rgb.iter_mut().enumerate() {
        for (i, v) in plane.iter_mut().enumerate() {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            *v = base[c] * (0.3 + 0.7 * x * (1.0 - 0.5 * y))
                + 0.05 * noise(seed + (i * 3 + c) as u64);
        }
    }
    LinearImage {
        width: w as u32,
        height: h as u32,
        rgb,
        alpha: None,
    }
}

/// The seed and base colour of the reflection pass.
pub const REFL: (u64, [f32; 3]) = (1 << 40, [0.9, 1.0, 1.2]);

/// Writes `out/trans.exr` and `out/refl.exr`, `w × h`, in `ty` with `compression`.
pub fn write_passes(
    out: &Path,
    w: usize,
    h: usize,
    ty: ExrDataType,
    compression: exr::compression::Compression,
) -> Result<(), Box<dyn std::error::Error>> {
    let opts = OutputOptions {
        exr_data_type: Some(ty),
        exr_compression: Some(compression),
        ..OutputOptions::default()
    };
    let src = PassSource::Png {
        bits: PngBits::Eight,
    };
    let frame = || CarriedFrame::whole(w as u32, h as u32);
    let trans = pass_image(w, h, 1, [0.6, 0.5, 0.4]);
    write_output(&out.join("trans.exr"), trans, frame(), &src, &opts)?;
    let refl = pass_image(w, h, REFL.0, REFL.1);
    write_output(&out.join("refl.exr"), refl, frame(), &src, &opts)?;
    Ok(())
}
