//! Arbitrary input never panics the readers, and evaluation always stays physical.

use std::path::Path;

use glassdb_fit::{Basis, CosPolynomial, FitSummary};
use glassdb_registry::{
    AngleCurve, GlassRecord, Registry, RegistryTable, Side, catalog::parse_catalog,
};
use glassdb_spectral::{IntegrationSettings, Method};
use proptest::prelude::*;

fn curve(coefficients: Vec<f64>) -> AngleCurve {
    AngleCurve {
        fit: FitSummary::exact(coefficients.len().saturating_sub(1) as u32),
        polynomial: CosPolynomial {
            basis: Basis::Full,
            powers: (0..coefficients.len() as u32).collect(),
            coefficients,
        },
        tolerance: 0.002,
    }
}

fn glass(r0: f64, t0: f64, cr: Vec<f64>, ct: Vec<f64>) -> GlassRecord {
    let (cr, ct) = (curve(cr), curve(ct));
    GlassRecord::with_shared_curves(
        1,
        "random",
        "uncoated",
        [[r0; 3], [t0; 3], [r0; 3]],
        [&cr, &ct, &cr],
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(4), ..ProptestConfig::default() })]

    #[test]
    fn registry_json_reader_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        let text = String::from_utf8_lossy(&bytes);
        let _ = Registry::from_json_str(&text, "fuzz.json");
        let _ = Registry::from_json_str(&format!("{{\"schema\": 1, \"glasses\": [{text}]}}"), "fuzz.json");
    }

    #[test]
    fn catalog_reader_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        let text = String::from_utf8_lossy(&bytes);
        let _ = parse_catalog(&text, Path::new("fuzz.toml"));
        let _ = parse_catalog(&format!("[[glass]]\nid = 1\nname = \"x\"\n{text}"), Path::new("fuzz.toml"));
    }

    #[test]
    fn eval_is_always_physical(
        r0 in 0.0f64..1.0,
        t0 in 0.0f64..1.0,
        cr in proptest::collection::vec(-50.0f64..50.0, 1..8),
        ct in proptest::collection::vec(-50.0f64..50.0, 1..8),
        cos in -0.5f64..1.5,
    ) {
        let g = glass(r0, t0, cr, ct);
        for side in [Side::Front, Side::Back] {
            let (r, t) = g.eval(side, cos);
            for c in 0..3 {
                prop_assert!((0.0..=1.0).contains(&r[c]));
                prop_assert!(t[c] >= 0.0 && r[c] + t[c] <= 1.0 + 1e-15);
            }
        }
        // Validation either accepts or gives an error; it never panics.
        let reg = Registry::single(RegistryTable {
            light: None,
            spectral: IntegrationSettings { method: Method::Luminous, extrapolate: false },
            glasses: vec![g],
        });
        let _ = reg.validate();
    }
}
