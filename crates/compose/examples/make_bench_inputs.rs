//! Benchmark inputs for `scripts/bench_compose_vs_oiiotool.sh`: a reflection and a
//! transmission pass (smooth gradients plus render-like noise, so that compression sees
//! realistic data) and an 8-bit packed mask (half the frame glass, ids 2 and 6 of the bundled
//! catalog, cos θ varying across the frame).
//!
//! `cargo run --release -p glassdb-compose --example make_bench_inputs -- OUT_DIR WIDTH HEIGHT half|float COMPRESSION`

use std::path::PathBuf;

use glassdb_compose::io::{
    ExrDataType, OutputOptions, PassSource, parse_exr_compression, write_output,
};
use glassdb_compose::pixels::{LinearImage, PngBits};
use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};

fn noise(i: u64) -> f32 {
    let mut x = i.wrapping_mul(0x9e37_79b9_7f4a_7c15);
    x ^= x >> 31;
    x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x ^= x >> 29;
    (x >> 40) as f32 / (1u64 << 24) as f32
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    if a.len() != 6 {
        return Err("usage: make_bench_inputs OUT_DIR WIDTH HEIGHT half|float COMPRESSION".into());
    }
    let out = PathBuf::from(&a[1]);
    let (w, h): (u32, u32) = (a[2].parse()?, a[3].parse()?);
    let ty = if a[4] == "half" {
        ExrDataType::Half
    } else {
        ExrDataType::Float
    };
    let compression = parse_exr_compression(&a[5])?;
    std::fs::create_dir_all(&out)?;
    let n = (w * h) as usize;
    let pass = |seed: u64, base: [f32; 3]| {
        let mut rgb = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
        for (c, plane) in rgb.iter_mut().enumerate() {
            for (i, v) in plane.iter_mut().enumerate() {
                let (x, y) = (
                    (i % w as usize) as f32 / w as f32,
                    (i / w as usize) as f32 / h as f32,
                );
                *v = base[c] * (0.3 + 0.7 * x * (1.0 - 0.5 * y))
                    + 0.05 * noise(seed + (i * 3 + c) as u64);
            }
        }
        LinearImage {
            width: w,
            height: h,
            rgb,
            alpha: None,
        }
    };
    let opts = OutputOptions {
        exr_data_type: Some(ty),
        exr_compression: Some(compression),
        ..OutputOptions::default()
    };
    let src = PassSource::Png {
        bits: PngBits::Eight,
    };
    write_output(
        &out.join("trans.exr"),
        pass(1, [0.6, 0.5, 0.4]),
        &src,
        &opts,
    )?;
    write_output(
        &out.join("refl.exr"),
        pass(1 << 40, [0.9, 1.0, 1.2]),
        &src,
        &opts,
    )?;
    let mut id = vec![0u16; n];
    let mut cos = vec![0u8; n];
    for i in 0..n {
        let (x, y) = (i % w as usize, i / w as usize);
        if (y * 4 / h as usize).is_multiple_of(2) {
            id[i] = if x < w as usize / 2 { 2 } else { 6 };
            cos[i] = (40 + x * 200 / w as usize) as u8;
        }
    }
    let mask = MaskImage {
        width: w,
        height: h,
        id,
        cos_theta: CosTheta::Quantized8(cos),
        plane: vec![0; n],
        coverage: None,
    };
    write_mask(&out.join("mask.png"), &mask, MaskFormat::Png8)?;
    println!(
        "wrote {}/{{trans.exr, refl.exr, mask.png}} ({w}×{h}, {}, {})",
        out.display(),
        a[4],
        a[5]
    );
    Ok(())
}
