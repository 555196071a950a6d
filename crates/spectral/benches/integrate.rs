//! Speed of per-spectrum integration on 1000 real-shaped spectra (the irregular 300–2500 nm
//! grid of `fixtures/glazing/CLEAR5.LOF`, 369 samples, with smoothly varied values). The same
//! spectra are built by `python_oracle/bench_spectral.py`, which runs this bench and times
//! colour-science side by side; numbers in docs/spectral.md.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use glassdb_spectral::{
    IntegrationSettings, Integrator, Method, ReadOptions, RgbCmf, luminous_iso9050,
    read_spectral_bytes,
};

const BASE: &[u8] = include_bytes!("../../../fixtures/glazing/CLEAR5.LOF");
const N_SPECTRA: usize = 1000;

/// Spectrum k: the base transmittance times a smooth factor in [0.2, 1] (formula shared with
/// bench_spectral.py).
fn spectra() -> (Vec<f64>, Vec<Vec<f64>>) {
    let Ok(d) = read_spectral_bytes(BASE, "CLEAR5.LOF", &ReadOptions::default()) else {
        return (Vec::new(), Vec::new());
    };
    let t = d.transmittance.unwrap_or_default();
    let all = (0..N_SPECTRA)
        .map(|k| {
            let kf = k as f64;
            d.wavelength_nm
                .iter()
                .zip(&t)
                .map(|(w, v)| v * (0.6 + 0.4 * (0.37 * kf + w / (150.0 + (k % 50) as f64)).sin()))
                .collect()
        })
        .collect();
    (d.wavelength_nm, all)
}

fn bench(c: &mut Criterion) {
    let (wl, all) = spectra();
    let mut group = c.benchmark_group("spectral_1000");
    let settings = [
        ("colorimetric", IntegrationSettings::default()),
        (
            "paper_wright_guild",
            IntegrationSettings {
                method: Method::Paper(RgbCmf::WrightGuild1931),
                extrapolate: false,
            },
        ),
    ];
    for (name, s) in settings {
        let Ok(it) = Integrator::new(&s) else {
            continue;
        };
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for v in &all {
                    if let Ok(rgb) = it.channels(black_box(&wl), black_box(v)) {
                        acc += rgb[0];
                    }
                }
                acc
            })
        });
    }
    // Every spectrum on its own wavelength array (shifted by k·1e-7 nm): no kernel reuse.
    let shifted: Vec<Vec<f64>> = (0..all.len())
        .map(|k| wl.iter().map(|w| w + k as f64 * 1e-7).collect())
        .collect();
    if let Ok(it) = Integrator::new(&IntegrationSettings::default()) {
        group.bench_function("colorimetric_distinct_grids", |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for (w, v) in shifted.iter().zip(&all) {
                    if let Ok(rgb) = it.channels(black_box(w), black_box(v)) {
                        acc += rgb[0];
                    }
                }
                acc
            })
        });
    }
    group.bench_function("luminous_iso9050", |b| {
        b.iter(|| {
            all.iter()
                .filter_map(|v| luminous_iso9050(black_box(&wl), black_box(v)).ok())
                .sum::<f64>()
        })
    });
    group.bench_function("integrator_new_colorimetric", |b| {
        b.iter(|| {
            Integrator::new(black_box(&IntegrationSettings::default())).map(|i| i.grid_nm().len())
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
