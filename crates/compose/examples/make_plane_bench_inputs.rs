//! Benchmark inputs for `scripts/bench_planes.sh`: the frame of `make_bench_inputs` (gradient
//! plus noise passes) with PLANES glass windows on a 6-column grid, one plane each, and the same
//! glass on a single plane. Writes OUT_DIR/{trans.exr, refl.exr, mask_planes.png, mask_one.png}
//! and prints each window as `K X Y WIDTH HEIGHT` (pixels, row 0 at the top), for cropping the
//! reflection pass to each plane's glass. The windows alternate between two glass ids, 2 and 6
//! (monolithic) unless IDS gives others (`11,12`: the bundled double units, for
//! `scripts/bench_ghosts.sh`); with IDS it also writes each window's reflection pass cropped to
//! it, `crop_K.exr`, and a second one, `group_K.exr` (pane group 1's pass), their data windows
//! at the window in the frame.
//!
//! `cargo run --release -p glassdb-compose --example make_plane_bench_inputs -- OUT_DIR WIDTH HEIGHT half|float COMPRESSION PLANES [IDS]`

mod bench_passes;

use bench_passes::FrameArgs;
use glassdb_encode::ExrDataType;
use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    if !(7..=8).contains(&a.len()) {
        return Err(
            "usage: make_plane_bench_inputs OUT_DIR WIDTH HEIGHT half|float COMPRESSION PLANES [IDS]"
                .into(),
        );
    }
    let ids: Vec<u16> = match a.get(7) {
        Some(list) => list.split(',').map(str::parse).collect::<Result<_, _>>()?,
        None => vec![2, 6],
    };
    if ids.is_empty() || ids.contains(&0) {
        return Err("IDS: glass ids 1 or more, separated by commas".into());
    }
    let frame = FrameArgs::parse(&a)?;
    let (out, w, h, ty) = (&frame.out, frame.width, frame.height, frame.data_type);
    let planes: usize = a[6].parse()?;
    std::fs::create_dir_all(out)?;
    let n = w * h;
    bench_passes::write_passes(&frame)?;

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
        if a.len() == 8 {
            for (name, seed) in [("crop", bench_passes::REFL.0), ("group", 7 << 40)] {
                let path = out.join(format!("{name}_{k}.exr"));
                write_crop(&path, (w, h), (x0, y0, x1 - x0, y1 - y0), seed, ty)?;
            }
        }
        for y in y0..y1 {
            for x in x0..x1 {
                let i = y * w + x;
                id[i] = ids[k % ids.len()];
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

/// A reflection pass of the `frame` cropped to `(x, y, width, height)`: its data window there.
fn write_crop(
    path: &std::path::Path,
    frame: (usize, usize),
    (x, y, cw, ch): (usize, usize, usize, usize),
    seed: u64,
    ty: ExrDataType,
) -> Result<(), Box<dyn std::error::Error>> {
    use exr::prelude::*;
    let image = bench_passes::pass_image(cw, ch, seed, bench_passes::REFL.1);
    let samples = |v: &[f32]| match ty {
        ExrDataType::Half => FlatSamples::F16(v.iter().map(|&s| f16::from_f32(s)).collect()),
        _ => FlatSamples::F32(v.to_vec()),
    };
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = ["R", "G", "B"]
        .iter()
        .zip(&image.rgb)
        .map(|(name, v)| AnyChannel::new(*name, samples(v)))
        .collect();
    let layer = Layer::new(
        (cw, ch),
        LayerAttributes {
            layer_position: Vec2(x as i32, y as i32),
            ..LayerAttributes::default()
        },
        Encoding {
            compression: Compression::ZIP16,
            ..Encoding::default()
        },
        AnyChannels::sort(list),
    );
    Image::new(
        ImageAttributes::new(IntegerBounds::from_dimensions(frame)),
        layer,
    )
    .write()
    .to_file(path)?;
    Ok(())
}
