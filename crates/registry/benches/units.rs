//! Speed of units in the registry (issue 26, docs/performance.md "Units"):
//!
//! - `registry_50_units_3_spaces`: `build_registry` on a catalog of 50 units (doubles and
//!   triples of the bundled glazing files, some flipped, with gaps), three colorimetric tables
//!   (linear Rec.709, ACEScg, Rec.2020; CIE 1931, D65, integrated at 1 nm), every unit
//!   combined per wavelength at 0–90° in 1° steps and fitted: the goal is well under 1 s.
//! - `viewer_unit_4_spaces`: what the viewer runs when a designer builds a unit on the page:
//!   [`UnitBuilder::build`] of a double unit from the bundled catalog's glasses, in the bundled
//!   registry's four tables, stack and fit included: the goal is under 100 ms.
//!
//! Run: `cargo bench -p glassdb-registry --bench units`. Before criterion's timings it prints
//! the wall and CPU time of five 50-unit builds (CPU from `/proc/self/stat`, both threads of
//! the build together): on a machine shared with other work the CPU time is what the build
//! itself costs.

use std::fmt::Write as _;
use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{Criterion, criterion_group, criterion_main};
use glassdb_registry::{BuildOptions, ChosenElement, UnitBuilder, UnitChoice, build_registry};
use glassdb_spectral::RgbSpace;
use glassdb_stack::Gas;

fn glazing() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/glazing")
}

/// A catalog of 50 units: every ordered pair of outer and inner panes from the bundled files
/// (doubles), then triples, until 50.
fn catalog_of_50_units(dir: &Path) -> PathBuf {
    let g = glazing().display().to_string();
    let outer = [
        ("igsdb_product_10693.json", false),
        ("LOW-E_5.LOF", true),
        ("CSR42_3.afg", false),
        ("nfrc_20748.oag", false),
        ("nfrc_9962.json", false),
        ("CLEAR_6.DAT", false),
        ("igsdb_product_11148.json", false),
    ];
    let inner = [
        "CLEAR_6.DAT",
        "CLEAR_3.DAT",
        "CLEAR5.LOF",
        "LOW-E_5.LOF",
        "913.json",
    ];
    let mut text = String::new();
    let mut id = 1;
    'outer: for triple in [false, true] {
        for (o, flip) in outer {
            for i in inner {
                if id > 50 {
                    break 'outer;
                }
                let _ = write!(
                    text,
                    "[[glass]]\nid = {id}\nname = \"unit {id}\"\nlayers = [\n  {{ spectral = \"{g}/{o}\", flip = {flip} }},\n  {{ gap_mm = 12.7, gas = \"argon\" }},\n"
                );
                if triple {
                    let _ = write!(
                        text,
                        "  {{ spectral = \"{g}/CLEAR5.LOF\" }},\n  {{ gap_mm = 12.7 }},\n"
                    );
                }
                let model = if i == "913.json" {
                    ", model = \"uncoated\""
                } else {
                    ""
                };
                let _ = write!(text, "  {{ spectral = \"{g}/{i}\"{model} }},\n]\n\n");
                id += 1;
            }
        }
    }
    let path = dir.join("units.toml");
    std::fs::write(&path, text).expect("write the catalog");
    path
}

/// This process's user + system CPU time (s), from `/proc/self/stat` (clock ticks of 1/100 s);
/// 0 where it cannot be read.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // fields after the parenthesised command name: state is field 3, utime 14, stime 15
    let Some(rest) = stat.rsplit_once(')').map(|(_, r)| r) else {
        return 0.0;
    };
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|f| f.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

fn bench(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("glassdb-bench-units-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let catalog = catalog_of_50_units(&dir);
    let opts =
        BuildOptions::colorimetric_in(&[RgbSpace::Srgb, RgbSpace::AcesCg, RgbSpace::Rec2020]);
    let reg = build_registry(&catalog, &opts).expect("the 50 units build");
    assert_eq!(reg.default_table().glasses.len(), 50);
    for _ in 0..5 {
        let (wall, cpu) = (std::time::Instant::now(), cpu_seconds());
        black_box(build_registry(&catalog, &opts).expect("build"));
        println!(
            "registry of 50 units × 3 spaces: {:.3} s wall, {:.2} s CPU ({} threads)",
            wall.elapsed().as_secs_f64(),
            cpu_seconds() - cpu,
            std::thread::available_parallelism().map_or(1, |n| n.get())
        );
    }
    let mut group = c.benchmark_group("units");
    group.sample_size(10);
    group.bench_function("registry_50_units_3_spaces", |b| {
        b.iter(|| black_box(build_registry(&catalog, &opts).expect("build")))
    });
    let bundled = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/catalog.toml");
    let viewer_opts = BuildOptions::colorimetric_in(&[
        RgbSpace::Srgb,
        RgbSpace::AcesCg,
        RgbSpace::Rec2020,
        RgbSpace::Aces2065_1,
    ]);
    let builder = UnitBuilder::new(&bundled, viewer_opts).expect("the bundled catalog");
    let choice = UnitChoice {
        id: 100,
        name: "R67 #2 | 12.7 argon | clear 6".into(),
        elements: vec![
            ChosenElement::Glass { id: 6, flip: false },
            ChosenElement::Gap {
                thickness_mm: 12.7,
                gas: Gas::Argon,
            },
            ChosenElement::Glass { id: 2, flip: false },
        ],
    };
    builder.build(&choice).expect("the viewer's unit builds");
    group.bench_function("viewer_unit_4_spaces", |b| {
        b.iter(|| black_box(builder.build(&choice).expect("build")))
    });
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench);
criterion_main!(benches);
