//! A 4K frame held in memory composited as the Python package's `glassdb.compose` does it,
//! from interleaved (H, W, 3) float passes and a packed (H, W, 3) 8-bit mask to an interleaved
//! composite: `planes_from_interleaved` for the transmission pass and three reflection passes,
//! `MaskImage::from_packed8`, `compose_in_memory` with the bundled registry, `interleave`.
//! python/bench/compose_4k.py times the same frame through Python (docs/performance.md).
//!
//! `cargo bench -p glassdb-compose --bench in_memory -- --warm-up-time 2 --measurement-time 10`

use criterion::{Criterion, criterion_group, criterion_main};
use glassdb_compose::colour::RegistryLuts;
use glassdb_compose::{
    ComposeSettings, MemoryFrame, MemoryLabels, compose_in_memory, interleave,
    planes_from_interleaved,
};
use glassdb_mask::MaskImage;

const W: usize = 3840;
const H: usize = 2160;

/// The packed mask of python/bench/compose_4k.py: planes 0–2 in vertical thirds, ids 1–3 in
/// stripes 1280 pixels wide on even rows (odd rows no glass), cos θ codes along x.
fn packed_mask() -> Vec<u8> {
    let mut m = vec![0u8; W * H * 3];
    for (i, px) in m.chunks_exact_mut(3).enumerate() {
        let (x, y) = (i % W, i / W);
        px[0] = (x * 3 / W) as u8;
        px[1] = if y % 2 == 0 { (x / 1280 + 1) as u8 } else { 0 };
        px[2] = (x * 255 / W) as u8;
    }
    m
}

/// An interleaved RGB pass: `base + (i mod 977)·1e-3 + 0.01·c` at pixel i, channel c.
fn pass(base: f32) -> Vec<f32> {
    (0..W * H * 3)
        .map(|s| base + ((s / 3) % 977) as f32 * 1e-3 + 0.01 * (s % 3) as f32)
        .collect()
}

fn bench(c: &mut Criterion) {
    let registry = glassdb_registry::default_registry().expect("the bundled registry");
    let luts = RegistryLuts::new(&registry);
    let trans = pass(0.1);
    let refl: Vec<Vec<f32>> = (0..3).map(|k| pass(0.05 * (k + 1) as f32)).collect();
    let mask = packed_mask();
    let settings = ComposeSettings::default();
    let labels = MemoryLabels {
        trans: "trans".into(),
        mask: "mask".into(),
    };
    c.bench_function("compose_in_memory 4K interleaved in and out", |b| {
        b.iter(|| {
            let (t, alpha) = planes_from_interleaved(&trans, 3);
            let frame = MemoryFrame {
                trans: t,
                refl: refl
                    .iter()
                    .map(|r| planes_from_interleaved(r, 3).0)
                    .collect(),
                mask: MaskImage::from_packed8(W as u32, H as u32, 3, &mask),
                space: None,
            };
            let out = compose_in_memory(frame, &settings, &luts, &labels).expect("composite");
            interleave(&out.rgb, alpha.as_deref())
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
