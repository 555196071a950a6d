//! Speed of the stack engine alone (no fit): a triple unit (Solarban R67 | clear 6 | Stopray,
//! 441 common wavelengths) evaluated at 0–90° in 1° steps, combined per wavelength and
//! integrated in three colour spaces and to WINDOW's photopic and solar values.
//! Run: `cargo bench -p glassdb-stack --bench stack` (docs/performance.md, "Units").

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use glassdb_spectral::{
    IntegrationSettings, Integrator, ReadOptions, RgbSpace, read_spectral_file,
};
use glassdb_stack::{Element, Gap, Gas, Layer, LayerOptions, Stack};

fn layer(file: &str) -> Element {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/glazing")
        .join(file);
    let data = read_spectral_file(&path, &ReadOptions::default()).expect("glazing file");
    let layer = Layer::from_spectral_data(data, &LayerOptions::default(), file).expect("layer");
    Element::Layer(Box::new(layer))
}

fn gap() -> Element {
    Element::Gap(Gap {
        thickness_mm: 12.7,
        gas: Gas::Argon,
    })
}

fn bench(c: &mut Criterion) {
    let stack = Stack::new(vec![
        layer("igsdb_product_10693.json"),
        gap(),
        layer("CLEAR_6.DAT"),
        gap(),
        layer("nfrc_20748.oag"),
    ])
    .expect("the triple");
    let integrators: Vec<Integrator> = [RgbSpace::Srgb, RgbSpace::AcesCg, RgbSpace::Rec2020]
        .into_iter()
        .map(|space| {
            Integrator::new(&IntegrationSettings::colorimetric(
                space,
                Default::default(),
            ))
            .expect("integrator")
        })
        .collect();
    let angles: Vec<f64> = (0..=90).map(f64::from).collect();
    let mut group = c.benchmark_group("stack");
    group.bench_function("triple_91_angles_3_spaces_and_window", |b| {
        b.iter(|| {
            black_box(
                stack
                    .evaluate(&angles, &integrators, true, Default::default())
                    .expect("evaluate"),
            )
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
