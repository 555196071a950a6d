//! Fit time per table (91 angles, degree 2–10, both bases) and evaluation time per value.
//!
//!     cargo bench -p glassdb-fit --bench fit -- --warm-up-time 1 --measurement-time 3
//!
//! Numbers are recorded in docs/fit.md.

use std::hint::black_box;
use std::path::Path;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glassdb_fit::{Basis, FitOptions, Quantity, fit_curve, read_angle_table};

fn table() -> glassdb_fit::GlassAngleTable {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/angles/clear_6mm_fresnel.csv");
    read_angle_table(&path, false)
        .expect("bundled table")
        .remove(0)
}

fn bench_fit(c: &mut Criterion) {
    let t = table();
    let r = t.reflectance.expect("R column");
    let mut g = c.benchmark_group("fit_91_points");
    for basis in [Basis::Full, Basis::Paper] {
        for degree in [2u32, 4, 6, 8, 10] {
            let opts = FitOptions {
                degree: Some(degree),
                basis: Some(basis),
                ..FitOptions::new(Quantity::Reflectance)
            };
            g.bench_with_input(BenchmarkId::new(basis.name(), degree), &opts, |b, o| {
                b.iter(|| fit_curve(black_box(&r), black_box(o)).expect("fit"))
            });
        }
    }
    let auto = FitOptions::new(Quantity::Reflectance);
    g.bench_function("auto_degree_reflectance", |b| {
        b.iter(|| fit_curve(black_box(&r), &auto).expect("fit"))
    });
    g.finish();
}

fn bench_eval(c: &mut Criterion) {
    let t = table();
    let r = t.reflectance.expect("R column");
    let cos: Vec<f64> = (0..4096).map(|i| i as f64 / 4095.0).collect();
    let mut g = c.benchmark_group("eval_per_value");
    g.throughput(Throughput::Elements(cos.len() as u64));
    for degree in [2u32, 4, 6, 8, 10] {
        let fit = fit_curve(
            &r,
            &FitOptions {
                degree: Some(degree),
                basis: Some(Basis::Full),
                ..FitOptions::new(Quantity::Reflectance)
            },
        )
        .expect("fit");
        g.bench_with_input(BenchmarkId::new("full", degree), &fit, |b, f| {
            b.iter(|| {
                let mut acc = 0.0;
                for &x in black_box(&cos) {
                    acc += f.eval_cos(x);
                }
                acc
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_fit, bench_eval);
criterion_main!(benches);
