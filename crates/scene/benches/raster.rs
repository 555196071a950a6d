//! Mask rasteriser throughput: triangles and pixels per second at 1920×1080.
//! Goal (issue 7): a 1M-triangle scene at 1920×1080 in under 2 s on 2 cores.
//! Run: `cargo bench -p glassdb-scene --bench raster -- --warm-up-time 1 --measurement-time 3`.

use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glassdb_scene::raster::{GlassLabel, RasterScene};
use glassdb_scene::{Camera, CameraSpec, CosMode, RasterOptions, rasterize};

/// Deterministic pseudo-random numbers in [0, 1) (64-bit LCG, top bits).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn glass() -> Vec<GlassLabel> {
    vec![GlassLabel {
        id: 1,
        plane: 0,
        normal: [0.0, 0.0, 1.0],
        d: 0.0,
        pane: 0,
    }]
}

/// A wavy terrain of `n`×`n` cells (2n² triangles) filling the view; every 7th cell is glass.
fn terrain(n: usize) -> RasterScene {
    let mut s = RasterScene {
        glass: glass(),
        ..Default::default()
    };
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (
                i as f64 / n as f64 * 20.0 - 10.0,
                -(j as f64) / n as f64 * 20.0,
            );
            s.positions
                .push([x, -1.0 + 0.3 * (x * 1.3).sin() * (z * 0.7).cos(), z]);
        }
    }
    for j in 0..n {
        for i in 0..n {
            let v = |a: usize, b: usize| ((j + b) * (n + 1) + i + a) as u32;
            let label = u32::from((i + j) % 7 == 0);
            s.triangles.push([v(0, 0), v(1, 0), v(1, 1)]);
            s.triangles.push([v(0, 0), v(1, 1), v(0, 1)]);
            s.labels.extend([label, label]);
        }
    }
    s
}

/// `n` random small triangles in a box in front of the camera (heavy overdraw).
fn soup(n: usize) -> RasterScene {
    let mut rng = Lcg(42);
    let mut s = RasterScene {
        glass: glass(),
        ..Default::default()
    };
    for k in 0..n {
        let c = [
            rng.next() * 8.0 - 4.0,
            rng.next() * 4.5 - 2.25,
            -2.0 - rng.next() * 10.0,
        ];
        for _ in 0..3 {
            s.positions.push([
                c[0] + rng.next() * 0.06,
                c[1] + rng.next() * 0.06,
                c[2] + rng.next() * 0.06,
            ]);
        }
        let b = (3 * k) as u32;
        s.triangles.push([b, b + 1, b + 2]);
        s.labels.push(u32::from(k % 5 == 0));
    }
    s
}

fn camera() -> Camera {
    let spec = CameraSpec::look_at(
        [0.0, 0.0, 1.0],
        [0.0, -0.3, -5.0],
        [0.0, 1.0, 0.0],
        70.0,
        1920,
        1080,
    );
    Camera::new(&spec, Path::new("bench")).expect("bench camera")
}

fn bench(c: &mut Criterion) {
    let cam = camera();
    let exact = RasterOptions {
        cos: CosMode::Exact,
        samples: 1,
    };
    let mut g = c.benchmark_group("mask_1920x1080");
    g.sample_size(10);
    for (name, scene) in [
        ("terrain_1M_triangles", terrain(708)),
        ("soup_1M_triangles", soup(1_000_000)),
    ] {
        g.throughput(Throughput::Elements(scene.triangles.len() as u64));
        g.bench_function(format!("{name}/triangles"), |b| {
            b.iter(|| rasterize(&scene, &cam, &exact).expect("rasterise"))
        });
    }
    // Pixels per second: a light scene, so the per-pixel resolve dominates.
    let light = terrain(20);
    g.throughput(Throughput::Elements(1920 * 1080));
    g.bench_function("terrain_800_triangles/pixels", |b| {
        b.iter(|| rasterize(&light, &cam, &exact).expect("rasterise"))
    });
    let aa = RasterOptions {
        cos: CosMode::Exact,
        samples: 4,
    };
    g.bench_function("terrain_800_triangles_4x4_samples/pixels", |b| {
        b.iter(|| rasterize(&light, &cam, &aa).expect("rasterise"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
