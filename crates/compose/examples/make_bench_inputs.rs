//! Benchmark inputs for `scripts/bench_compose_vs_oiiotool.sh`: a reflection and a
//! transmission pass (smooth gradients plus render-like noise, so that compression sees
//! realistic data) and an 8-bit packed mask (half the frame glass, ids 2 and 6 of the bundled
//! catalog, cos θ varying across the frame).
//!
//! `cargo run --release -p glassdb-compose --example make_bench_inputs -- OUT_DIR WIDTH HEIGHT half|float COMPRESSION`

mod bench_passes;

use bench_passes::FrameArgs;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    if a.len() != 6 {
        return Err("usage: make_bench_inputs OUT_DIR WIDTH HEIGHT half|float COMPRESSION".into());
    }
    let frame = FrameArgs::parse(&a)?;
    let (out, w, h) = (&frame.out, frame.width, frame.height);
    std::fs::create_dir_all(out)?;
    bench_passes::write_passes(&frame)?;
    bench_passes::write_half_glass_mask(out, w as u32, h as u32)?;
    println!(
        "wrote {}/{{trans.exr, refl.exr, mask.png}} ({w}×{h}, {}, {})",
        out.display(),
        a[4],
        a[5]
    );
    Ok(())
}
