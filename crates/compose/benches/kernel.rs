//! The per-pixel composite against a plain copy of the same bytes, at 4K (3840×2160), float
//! RGB passes, 8-bit mask, on rayon's pool (2 threads on the reference machine).
//!
//! `cargo bench -p glassdb-compose --bench kernel -- --warm-up-time 1 --measurement-time 3`

use criterion::{Criterion, criterion_group, criterion_main};
use glassdb_compose::kernel::{KernelInput, compose_in_place};
use glassdb_compose::lut::GlassLut;
use glassdb_mask::{CosTheta, MaskImage};
use glassdb_side::Side;
use rayon::prelude::*;

const W: usize = 3840;
const H: usize = 2160;

fn mask() -> MaskImage {
    // Half the frame is glass (ids 1–3 in vertical stripes), cos θ varying along x.
    let n = W * H;
    let id = (0..n)
        .map(|i| {
            if (i / W).is_multiple_of(2) {
                ((i % W) / 1280 + 1) as u16
            } else {
                0
            }
        })
        .collect();
    let cos = (0..n).map(|i| ((i % W) * 255 / W) as u8).collect();
    MaskImage {
        width: W as u32,
        height: H as u32,
        id,
        cos_theta: CosTheta::Quantized8(cos),
        plane: vec![0; n],
        coverage: None,
    }
}

fn plane(seed: f32) -> Vec<f32> {
    (0..W * H).map(|i| seed + (i % 977) as f32 * 1e-3).collect()
}

fn bench(c: &mut Criterion) {
    let m = mask();
    let lut = GlassLut::from_fn(
        &[1, 2, 3],
        |id, _, cos| {
            (
                [0.04 + 0.02 * f64::from(id) * (1.0 - cos); 3],
                [0.8 * cos; 3],
            )
        },
        |_, _| ([0.06; 3], [0.8; 3]),
    );
    let refl = [plane(0.1), plane(0.2), plane(0.3)];
    let trans_src = [plane(0.4), plane(0.5), plane(0.6)];
    let mut trans = trans_src.clone();
    let refl_planes = [[refl[0].as_slice(), refl[1].as_slice(), refl[2].as_slice()]];
    let sides = [Side::Front];
    let mut g = c.benchmark_group("4K float RGB, 8-bit mask");
    g.sample_size(20);
    g.bench_function("composite (in place)", |b| {
        b.iter(|| {
            let [r, gg, bb] = &mut trans;
            let input = KernelInput::new([r, gg, bb], &refl_planes, &sides, &m, &lut).unwrap();
            compose_in_place(input)
        })
    });
    // The same bytes the composite reads (trans, refl, mask id + cos) copied to a destination.
    let mut dst_f: Vec<Vec<f32>> = (0..6).map(|_| vec![0f32; W * H]).collect();
    let mut dst_id = vec![0u16; W * H];
    let mut dst_cos = vec![0u8; W * H];
    let CosTheta::Quantized8(cos) = &m.cos_theta else {
        unreachable!()
    };
    g.bench_function("plain copy of the same bytes", |b| {
        b.iter(|| {
            let srcs = [
                &refl[0],
                &refl[1],
                &refl[2],
                &trans_src[0],
                &trans_src[1],
                &trans_src[2],
            ];
            dst_f
                .par_iter_mut()
                .zip(srcs.par_iter())
                .for_each(|(d, s)| {
                    d.par_chunks_mut(1 << 16)
                        .zip(s.par_chunks(1 << 16))
                        .for_each(|(d, s)| d.copy_from_slice(s))
                });
            dst_id
                .par_chunks_mut(1 << 16)
                .zip(m.id.par_chunks(1 << 16))
                .for_each(|(d, s)| d.copy_from_slice(s));
            dst_cos
                .par_chunks_mut(1 << 16)
                .zip(cos.par_chunks(1 << 16))
                .for_each(|(d, s)| d.copy_from_slice(s));
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
