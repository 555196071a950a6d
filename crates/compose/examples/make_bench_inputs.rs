//! Benchmark inputs for `scripts/bench_compose_vs_oiiotool.sh`: a reflection and a
//! transmission pass (smooth gradients plus render-like noise, so that compression sees
//! realistic data) and an 8-bit packed mask (half the frame glass, ids 2 and 6 of the bundled
//! catalog, cos θ varying across the frame).
//!
//! `cargo run --release -p glassdb-compose --example make_bench_inputs -- OUT_DIR WIDTH HEIGHT half|float COMPRESSION`

use std::path::PathBuf;

mod bench_passes;

use glassdb_encode::{ExrDataType, parse_exr_compression};
use glassdb_mask::{MaskFormat, write_mask};

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
    bench_passes::write_passes(&out, w as usize, h as usize, ty, compression)?;
    let mask = bench_passes::half_glass_mask(w, h);
    write_mask(&out.join("mask.png"), &mask, MaskFormat::Png8)?;
    println!(
        "wrote {}/{{trans.exr, refl.exr, mask.png}} ({w}×{h}, {}, {})",
        out.display(),
        a[4],
        a[5]
    );
    Ok(())
}
