//! Benchmark inputs for `scripts/bench_planes.sh`: the frame of `make_bench_inputs` (gradient
//! plus noise passes) with PLANES glass windows on a 6-column grid, one plane each, and the same
//! glass on a single plane. Writes OUT_DIR/{trans.exr, refl.exr, mask_planes.png, mask_one.png}
//! and prints each window as `K X Y WIDTH HEIGHT` (pixels, row 0 at the top), for cropping the
//! reflection pass to each plane's glass.
//!
//! `cargo run --release -p glassdb-compose --example make_plane_bench_inputs -- OUT_DIR WIDTH HEIGHT half|float COMPRESSION PLANES`

use std::path::PathBuf;

mod bench_passes;

use glassdb_encode::{ExrDataType, parse_exr_compression};
use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    if a.len() != 7 {
        return Err(
            "usage: make_plane_bench_inputs OUT_DIR WIDTH HEIGHT half|float COMPRESSION PLANES"
                .into(),
        );
    }
    let out = PathBuf::from(&a[1]);
    let (w, h): (usize, usize) = (a[2].parse()?, a[3].parse()?);
    let ty = if a[4] == "half" {
        ExrDataType::Half
    } else {
        ExrDataType::Float
    };
    let compression = parse_exr_compression(&a[5])?;
    let planes: usize = a[6].parse()?;
    std::fs::create_dir_all(&out)?;
    let n = w * h;
    bench_passes::write_passes(&out, w, h, ty, compression)?;

    // Windows on a grid of 6 columns, each inset by a tenth of its cell on every side.
    let cols = 6;
    let rows = planes.div_ceil(cols);
    let mut id = vec![0u16; n];
    let mut cos = vec![0u8; n];
    let mut plane = vec![0u16; n];
    for k in 0..planes {
        let (cx, cy) = (k % cols, k / cols);
        let (x0, x1) = (
            (cx * 10 + 1) * w / (cols * 10),
            (cx * 10 + 9) * w / (cols * 10),
        );
        let (y0, y1) = (
            (cy * 10 + 1) * h / (rows * 10),
            (cy * 10 + 9) * h / (rows * 10),
        );
        println!("{k} {x0} {y0} {} {}", x1 - x0, y1 - y0);
        for y in y0..y1 {
            for x in x0..x1 {
                let i = y * w + x;
                id[i] = if k % 2 == 0 { 2 } else { 6 };
                cos[i] = (40 + x * 200 / w) as u8;
                plane[i] = k as u16;
            }
        }
    }
    let mask = |plane: Vec<u16>| MaskImage {
        width: w as u32,
        height: h as u32,
        id: id.clone(),
        cos_theta: CosTheta::Quantized8(cos.clone()),
        plane,
        coverage: None,
    };
    write_mask(&out.join("mask_planes.png"), &mask(plane), MaskFormat::Png8)?;
    write_mask(
        &out.join("mask_one.png"),
        &mask(vec![0; n]),
        MaskFormat::Png8,
    )?;
    Ok(())
}
