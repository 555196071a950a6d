//! Makes `fixtures/example/`: a small synthetic glazed view (256×192) for the README's main
//! job, `compose --refl refl.exr --trans trans.exr --mask mask.png`.
//!
//! - `trans.exr` (half, linear): an interior seen through a façade (floor, back wall, two boxes).
//! - `refl.exr` (half, linear): what the façade plane mirrors (sky, a bright building, ground).
//! - `mask.png` (the paper's packed 8-bit mask): two panes between mullions, the left one glass
//!   id 2 (clear float 6 mm), the right one id 6 (a reflective coated glass) of the bundled
//!   catalog, cos θ from a camera that looks at the façade 50° off its normal.
//!
//! `cargo run -p glassdb-compose --example make_example [OUT_DIR]` (default fixtures/example).

use std::path::PathBuf;

use glassdb_encode::{ExrDataType, OutputOptions, write_output};
use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};
use glassdb_pass::{CarriedFrame, LinearImage, PassSource, PngBits};

const W: u32 = 256;
const H: u32 = 192;

fn image(f: impl Fn(f32, f32) -> [f32; 3]) -> LinearImage {
    let n = (W * H) as usize;
    let mut rgb = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
    for y in 0..H {
        for x in 0..W {
            let (u, v) = ((x as f32 + 0.5) / W as f32, (y as f32 + 0.5) / H as f32);
            let c = f(u, v);
            let i = (y * W + x) as usize;
            for k in 0..3 {
                rgb[k][i] = c[k];
            }
        }
    }
    LinearImage {
        width: W,
        height: H,
        rgb,
        alpha: None,
    }
}

fn inside(u: f32, v: f32, rect: [f32; 4]) -> bool {
    u >= rect[0] && u < rect[2] && v >= rect[1] && v < rect[3]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("fixtures/example"));
    std::fs::create_dir_all(&out)?;

    // Transmission: back wall, floor below v = 0.62, a red and a blue box.
    let trans = image(|u, v| {
        if inside(u, v, [0.18, 0.45, 0.36, 0.75]) {
            [0.55, 0.08, 0.05]
        } else if inside(u, v, [0.62, 0.5, 0.85, 0.8]) {
            [0.05, 0.12, 0.45]
        } else if v > 0.62 {
            let d = 0.25 + 0.35 * (v - 0.62) / 0.38;
            [0.45 * d, 0.32 * d, 0.2 * d]
        } else {
            [0.3 - 0.1 * v, 0.3 - 0.1 * v, 0.28 - 0.1 * v]
        }
    });
    // Reflection: sky (bright at the horizon v = 0.55), a bright building, dark ground.
    let refl = image(|u, v| {
        if inside(u, v, [0.55, 0.2, 0.75, 0.55]) {
            [1.6, 1.5, 1.3]
        } else if v < 0.55 {
            let s = v / 0.55;
            [0.35 + 0.9 * s, 0.55 + 0.8 * s, 1.1 + 0.4 * s]
        } else {
            [0.08, 0.1, 0.06]
        }
    });
    // Mask: two panes, x 0.06–0.48 and 0.52–0.94, y 0.08–0.92 (mullions between).
    let n = (W * H) as usize;
    let mut id = vec![0u16; n];
    let mut cos = vec![0u8; n];
    let yaw = 50f32.to_radians();
    let focal = 1.2f32; // in units of the image width
    for y in 0..H {
        for x in 0..W {
            let (u, v) = ((x as f32 + 0.5) / W as f32, (y as f32 + 0.5) / H as f32);
            let i = (y * W + x) as usize;
            let glass = if inside(u, v, [0.06, 0.08, 0.48, 0.92]) {
                2
            } else if inside(u, v, [0.52, 0.08, 0.94, 0.92]) {
                6
            } else {
                0
            };
            id[i] = glass;
            if glass != 0 {
                // View ray (image-plane offsets) against the façade normal, rotated by the yaw.
                let (dx, dy) = ((u - 0.5) / focal, (v - 0.5) * (H as f32 / W as f32) / focal);
                let ray = [dx, dy, 1.0];
                let len = (ray[0] * ray[0] + ray[1] * ray[1] + 1.0).sqrt();
                let normal = [-yaw.sin(), 0.0, yaw.cos()];
                let c = (ray[0] * normal[0] + ray[2] * normal[2]) / len;
                cos[i] = (c.clamp(0.0, 1.0) * 255.0).round() as u8;
            }
        }
    }
    let mask = MaskImage {
        width: W,
        height: H,
        id,
        cos_theta: CosTheta::Quantized8(cos),
        plane: vec![0; n],
        coverage: None,
    };

    let half = OutputOptions {
        exr_data_type: Some(ExrDataType::Half),
        ..OutputOptions::default()
    };
    let src = PassSource::Png {
        bits: PngBits::Eight,
    };
    let frame = || CarriedFrame::whole(W, H);
    write_output(&out.join("trans.exr"), trans, frame(), &src, &half)?;
    write_output(&out.join("refl.exr"), refl, frame(), &src, &half)?;
    write_mask(&out.join("mask.png"), &mask, MaskFormat::Png8)?;
    println!("wrote {}/{{trans.exr, refl.exr, mask.png}}", out.display());
    Ok(())
}
