//! Reader robustness: arbitrary bytes never panic; mutated real files give errors or data that
//! satisfy the documented invariants; format detection; integration input checks.

use glassdb_spectral::{
    IntegrationSettings, Integrator, ReadOptions, SpectralData, SpectralError, SpectralFormat,
    detect_format, luminous_iso9050, read_spectral_bytes,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

const CLEAR3: &[u8] = include_bytes!("../../../fixtures/glazing/CLEAR_3.DAT");
const JSON913: &[u8] = include_bytes!("../../../fixtures/glazing/913.json");

fn runner(cases: u32) -> TestRunner {
    TestRunner::new_with_rng(
        Config {
            cases,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::from_seed(RngAlgorithm::ChaCha, &[7; 32]),
    )
}

/// The invariants every successful read promises.
fn check_invariants(d: &SpectralData) {
    assert!(!d.wavelength_nm.is_empty());
    assert!(d.wavelength_nm.windows(2).all(|p| p[1] > p[0]));
    assert!(d.wavelength_nm.iter().all(|w| w.is_finite() && *w > 0.0));
    for q in [&d.transmittance, &d.reflectance_front, &d.reflectance_back]
        .into_iter()
        .flatten()
    {
        assert_eq!(q.len(), d.wavelength_nm.len());
        assert!(q.iter().all(|v| (0.0..=1.0).contains(v)));
    }
}

fn read_all_ways(bytes: &[u8]) {
    for name in ["x.csv", "x.json", "x.DAT", "x", "x.txt"] {
        for percent in [false, true] {
            if let Ok(d) = read_spectral_bytes(bytes, name, &ReadOptions { percent }) {
                check_invariants(&d);
                // Integration of whatever was read must not panic either.
                if let Some(t) = &d.transmittance {
                    let it = Integrator::new(&IntegrationSettings {
                        extrapolate: true,
                        ..Default::default()
                    })
                    .unwrap();
                    let _ = it.channels(&d.wavelength_nm, t);
                    let _ = luminous_iso9050(&d.wavelength_nm, t);
                }
            }
        }
    }
}

#[test]
fn arbitrary_bytes_never_panic() {
    runner(256)
        .run(&proptest::collection::vec(any::<u8>(), 0..512), |bytes| {
            read_all_ways(&bytes);
            Ok(())
        })
        .unwrap();
}

#[test]
fn mutated_real_files_never_panic() {
    for base in [CLEAR3, JSON913] {
        let strategy = proptest::collection::vec((0..base.len(), any::<u8>()), 1..8);
        runner(96)
            .run(&strategy, |edits| {
                let mut bytes = base.to_vec();
                for (i, b) in edits {
                    bytes[i] = b;
                }
                read_all_ways(&bytes);
                Ok(())
            })
            .unwrap();
    }
}

#[test]
fn csv_like_text_never_panics() {
    let line = "[0-9.eE+-]{0,8}(,[0-9.eE+naNinf-]{0,8}){0,3}";
    let strategy = proptest::collection::vec(proptest::string::string_regex(line).unwrap(), 0..40);
    runner(128)
        .run(&strategy, |lines| {
            let text = format!("wavelength_nm,T,R,Rb\n{}", lines.join("\n"));
            read_all_ways(text.as_bytes());
            Ok(())
        })
        .unwrap();
}

#[test]
fn format_detection_by_extension_then_content() {
    assert_eq!(detect_format(b"", "a.CSV"), SpectralFormat::Csv);
    assert_eq!(detect_format(b"", "a.json"), SpectralFormat::IgsdbJson);
    assert_eq!(detect_format(b"", "a.lof"), SpectralFormat::Optics);
    assert_eq!(detect_format(CLEAR3, "noext"), SpectralFormat::Optics);
    assert_eq!(detect_format(JSON913, "noext"), SpectralFormat::IgsdbJson);
    assert_eq!(
        detect_format(b"# c\nwavelength_um,T\n0.3,0.1\n", "noext"),
        SpectralFormat::Csv
    );
}

/// Reads `bytes` named `name` with the default options.
fn read_default(bytes: &[u8], name: &str) -> Result<SpectralData, SpectralError> {
    read_spectral_bytes(bytes, name, &ReadOptions::default())
}

#[test]
fn csv_in_microns_and_optics_in_nanometres_become_nm() {
    let d = read_default(
        b"wavelength_um,T,Rb\n0.305,0.5,0.1\n0.310,0.6,0.2\n",
        "a.csv",
    )
    .unwrap();
    assert_eq!(d.wavelength_nm, vec![305.0, 310.0]);
    assert!(d.reflectance_front.is_none());
    assert_eq!(d.reflectance_back, Some(vec![0.1, 0.2]));
    let optics_nm: &[u8] = b"{ Units, Wavelength Units } SI Nanometers\r\n{ Thickness } 4\r\n300\t0.1\t0.2\t0.3\r\n305 0.1 0.2 0.3\r\n";
    let d = read_default(optics_nm, "n.txt").unwrap();
    assert_eq!(d.wavelength_nm, vec![300.0, 305.0]);
    assert_eq!(d.product.thickness_mm, Some(4.0));
}

#[test]
fn errors_name_source_line_and_column() {
    // (bytes, file name, the whole message)
    let exact: [(&[u8], &str, &str); 2] = [
        (
            b"wavelength_nm,T\n380,0.5\n390,x\n",
            "g.csv",
            "g.csv:3:2: T `x` is not a number",
        ),
        (
            b"0.3 0.1 0.2\n",
            "g.DAT",
            "g.DAT:1: expected 4 numbers `wavelength T Rf Rb`, found 3 fields",
        ),
    ];
    for (bytes, name, message) in exact {
        assert_eq!(read_default(bytes, name).unwrap_err().to_string(), message);
    }
    // (bytes, file name, how the message starts)
    let starts: [(&[u8], &str, &str); 2] = [
        (
            b"{ Units, Wavelength Units } SI Furlongs\n",
            "g.DAT",
            "g.DAT:1: unknown wavelength units",
        ),
        (
            b"wavelength_um,T\n1e300,0.5\n",
            "h.csv",
            "h.csv:2:1: wavelength is out of range",
        ),
    ];
    for (bytes, name, start) in starts {
        let e = read_default(bytes, name).unwrap_err();
        assert!(e.to_string().starts_with(start), "{e}");
    }
    let e = read_default(b"{\"name\": 1}", "g.json").unwrap_err();
    assert!(matches!(e, SpectralError::Format { .. }), "{e}");
}

#[test]
fn integrator_rejects_bad_arrays_without_panicking() {
    let it = Integrator::new(&IntegrationSettings::default()).unwrap();
    assert!(matches!(
        it.channels(&[1.0, 2.0], &[1.0]),
        Err(SpectralError::LengthMismatch { .. })
    ));
    assert!(matches!(
        it.channels(&[], &[]),
        Err(SpectralError::TooFewPoints { .. })
    ));
    let wl: Vec<f64> = (0..60).map(|i| 300.0 + 10.0 * f64::from(i)).collect();
    let mut v = vec![0.5; 60];
    v[10] = f64::INFINITY;
    assert!(matches!(
        it.channels(&wl, &v),
        Err(SpectralError::NonFinite {
            what: "value",
            index: 10
        })
    ));
}
