//! The formats glazing data come in today (fixtures/glazing/README.md): IGSDB v2 JSON, Optics
//! files with (all-zero) diffuse columns and instrument CSV exports read to the same numbers as
//! the plain files of the same product; shading products, BSDF XML, diffuse data and binary files
//! are refused by name.

use glassdb_spectral::{
    ReadOptions, SpectralData, SpectralError, SpectralFormat, UnsupportedKind, detect_format,
    read_spectral_bytes,
};

fn fixture(name: &str) -> Vec<u8> {
    let path = format!(
        "{}/../../fixtures/glazing/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn read_as(bytes: &[u8], name: &str, percent: bool) -> Result<SpectralData, SpectralError> {
    read_spectral_bytes(bytes, name, &ReadOptions { percent })
}

fn read(name: &str) -> SpectralData {
    read_as(&fixture(name), name, false).unwrap_or_else(|e| panic!("{e}"))
}

fn unsupported(bytes: &[u8], name: &str) -> (UnsupportedKind, String) {
    match read_as(bytes, name, false) {
        Err(e @ SpectralError::Unsupported { .. }) => {
            let message = e.to_string();
            let SpectralError::Unsupported { kind, .. } = e else {
                unreachable!()
            };
            (kind, message)
        }
        other => panic!("{name}: {other:?}"),
    }
}

fn quantities(d: &SpectralData) -> [&Option<Vec<f64>>; 3] {
    [&d.transmittance, &d.reflectance_front, &d.reflectance_back]
}

/// The fixture `name`, read, after checking it holds exactly the numbers of the plain Optics
/// file of the same product (`CLEAR_3.DAT`).
#[track_caller]
fn read_as_clear_3(name: &str) -> SpectralData {
    let optics = read("CLEAR_3.DAT");
    let d = read(name);
    assert_eq!(d.wavelength_nm, optics.wavelength_nm, "{name}");
    assert_eq!(quantities(&d), quantities(&optics), "{name}");
    d
}

#[test]
fn igsdb_v2_reads_to_exactly_the_optics_files_numbers() {
    let v2 = read_as_clear_3("igsdb_v2_clear_3.json");
    let p = &v2.product;
    assert_eq!(p.format, SpectralFormat::IgsdbJson);
    assert_eq!(p.name.as_deref(), Some("Generic Clear Glass"));
    assert_eq!(p.manufacturer.as_deref(), Some("Generic"));
    assert_eq!(p.product_type.as_deref(), Some("MONOLITHIC"));
    assert_eq!(p.coated_side.as_deref(), Some("NA"));
    assert_eq!(p.thickness_mm, Some(3.048));
    assert!(p.other_incidence_angles_deg.is_empty());
    // Without the extension the content says JSON.
    let bytes = fixture("igsdb_v2_clear_3.json");
    assert_eq!(detect_format(&bytes, "x"), SpectralFormat::IgsdbJson);
    assert_eq!(
        read_as(&bytes, "x", false).unwrap().wavelength_nm,
        v2.wavelength_nm
    );
}

#[test]
fn optics_with_all_zero_diffuse_columns_reads_its_direct_columns() {
    let dir_dif = read_as_clear_3("CLEAR_3_dir_dif.DAT");
    assert_eq!(dir_dif.product.name.as_deref(), Some("Generic Clear Glass"));
}

#[test]
fn instrument_csv_exports_read_to_the_plain_csvs_numbers() {
    let plain = read_as_clear_3("CLEAR_3.csv");
    // (file, has Rb): Cary's layout carries T and R only.
    for (name, has_rb) in [
        ("CLEAR_3_cary.csv", false),
        ("CLEAR_3_semicolon.csv", true),
        ("CLEAR_3_tab.txt", true),
    ] {
        let d = read(name);
        assert_eq!(d.product.format, SpectralFormat::Csv, "{name}");
        assert_eq!(d.wavelength_nm, plain.wavelength_nm, "{name}");
        let want = quantities(&plain);
        for (k, got) in quantities(&d).into_iter().enumerate() {
            if k == 2 && !has_rb {
                assert!(got.is_none(), "{name}");
                continue;
            }
            let (got, want) = (got.as_ref().unwrap(), want[k].as_ref().unwrap());
            for (g, w) in got.iter().zip(want) {
                // Percent values are scaled by 0.01: equal to the last bit or two.
                assert!((g - w).abs() <= 1e-15, "{name} quantity {k}: {g} vs {w}");
            }
        }
    }
    let tab = fixture("CLEAR_3_tab.txt");
    assert_eq!(detect_format(&tab, "CLEAR_3_tab.txt"), SpectralFormat::Csv);
    // A header in percent needs no flag; the flag agrees with it.
    let cary = fixture("CLEAR_3_cary.csv");
    let flagged = read_as(&cary, "c.csv", true).unwrap();
    assert_eq!(
        flagged.transmittance,
        read("CLEAR_3_cary.csv").transmittance
    );
}

#[test]
fn csv_dialects_one_row_at_a_time() {
    let want = |d: &SpectralData| (d.wavelength_nm.clone(), d.transmittance.clone());
    let base = read_as(b"wavelength_nm,T\n380,0.5\n390,0.25\n", "a.csv", false).unwrap();
    let cases: [&[u8]; 9] = [
        b"Sample 1\n\"Wavelength (nm)\",\"T\"\n380,0.5\n390,0.25\n",
        b"nm,%T\n390,25\n380,50\n",
        b"Wavelength (nm);T (%)\r\n380,0;50,0\r\n390,0;25,0\r\n",
        b"wavelength\tT\n380\t0.5\n390\t0.25\n",
        b"Wavelength [um],T\n0.38,0.5\n0.39,0.25\n",
        b"wavelength,T\n0.38,0.5\n0.39,0.25\n",
        b"Wavelength (nm),%T,\n390.0,25.0,\n380.0,50.0,\n\nCollection Time: today\n",
        b"# comment\n\nTitle\n\xB5m;T\n0,38;0,5\n0,39;0,25\n",
        b"\xEF\xBB\xBFnm\tT\n380\t0.5\n\n390\t0.25\n",
    ];
    for (i, bytes) in cases.iter().enumerate() {
        let d = read_as(bytes, &format!("case{i}.csv"), false)
            .unwrap_or_else(|e| panic!("case {i}: {e}"));
        assert_eq!(want(&d), want(&base), "case {i}");
    }
    let mut utf16 = vec![0xFF, 0xFE];
    for u in "Wavelength (nm)\t%T\r\n380\t50\r\n390\t25\r\n".encode_utf16() {
        utf16.extend(u.to_le_bytes());
    }
    let d = read_as(&utf16, "unicode.txt", false).unwrap();
    assert_eq!(want(&d), want(&base));
}

#[test]
fn csv_errors_still_name_the_line_and_column() {
    // (bytes, the whole message): lines count the title lines above the header.
    let cases: [(&[u8], &str); 5] = [
        (
            b"Title\nnm;%T\n380;50\n390;x\n",
            "e.csv:4:2: T `x` is not a number",
        ),
        (
            b"Title\nnm,%T,\n380,50,\n390,25,7\n",
            "e.csv:4:3: column 3 has values but no header",
        ),
        (
            b"nm,Abs\n380,0.1\n",
            "e.csv:1:2: absorbance is not read: export transmittance (T or %T) instead",
        ),
        (
            b"nm,T,Wavelength (nm),T\n380,0.5,380,0.5\n",
            "e.csv:1:3: more than one wavelength column (several samples side by side? glassdb reads one sample per file)",
        ),
        (
            b"nm,T\n380,0.5\n390,0.5\n385,0.5\n",
            "e.csv:4:1: wavelengths are not sorted: 385 nm follows 390 nm (line 3); sort the rows by wavelength",
        ),
    ];
    for (bytes, message) in cases {
        assert_eq!(
            read_as(bytes, "e.csv", false).unwrap_err().to_string(),
            message
        );
    }
    // A header in percent with values above 100.
    let e = read_as(b"nm,%T\n380,101\n", "e.csv", false).unwrap_err();
    assert_eq!(e.to_string(), "e.csv:2:2: T = 101 is above 1 (above 100 %)");
}

#[test]
fn shading_products_are_named() {
    let (kind, message) = unsupported(&fixture("igsdb_v1_venetian.json"), "igsdb_v1_venetian.json");
    assert_eq!(
        kind,
        UnsupportedKind::ShadingProduct {
            subtype: Some("venetian".into()),
            name: Some("Slim White Open".into())
        }
    );
    assert_eq!(
        message,
        "igsdb_v1_venetian.json: is an IGSDB shading product (venetian blind, \"Slim White Open\"); glassdb reads glazing (specular) products only"
    );
    let v2 = br#"{"type": "SHADING", "subtype": "ROLLER_SHADE", "name": "Screen 5%",
        "physical_properties": {"is_specular": false, "optical_properties": {"optical_data": null}}}"#;
    let (_, message) = unsupported(v2, "roller.json");
    assert!(
        message.contains("shading product (roller shade, \"Screen 5%\")"),
        "{message}"
    );
}

#[test]
fn diffuse_data_are_named() {
    let (kind, message) = unsupported(&fixture("diffuse_optics_file_2.txt"), "frit.txt");
    // The first data row (line 16) already has diffuse transmittance 0.001.
    assert_eq!(kind, UnsupportedKind::DiffuseOptics { line: 16 });
    assert!(
        message.starts_with("frit.txt: is an Optics file with diffuse columns"),
        "{message}"
    );
    // Rows of 4 and 9 numbers do not mix.
    let mixed = b"0.30 0.1 0.1 0.1\n0.31 0.1 0 0.1 0 0.1 0 0.1 0\n";
    let e = read_as(mixed, "m.DAT", false).unwrap_err().to_string();
    assert_eq!(e, "m.DAT:2: 9 numbers where the rows above have 4");
}

#[test]
fn bsdf_xml_markup_and_binary_files_are_named() {
    for name in [
        "2011-SA1_trimmed.XML",
        "renamed.DAT",
        "renamed.csv",
        "renamed.json",
    ] {
        let (kind, message) = unsupported(&fixture("2011-SA1_trimmed.XML"), name);
        assert_eq!(kind, UnsupportedKind::BsdfXml, "{name}");
        assert!(message.contains("is a BSDF XML file"), "{message}");
    }
    let html = b"<!DOCTYPE html>\n<html><body>Not found</body></html>\n";
    let (kind, _) = unsupported(html, "product.json");
    assert_eq!(
        kind,
        UnsupportedKind::Markup {
            root: "html".into()
        }
    );
    let png = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00";
    let (_, message) = unsupported(png, "glass.csv");
    assert_eq!(
        message,
        "glass.csv: is binary data (a PNG image), not a text spectral file"
    );
    let (kind, message) = unsupported(b"\x01\x02\x03\x00\x00spectra", "glass.DAT");
    assert_eq!(kind, UnsupportedKind::Binary { what: None });
    assert_eq!(
        message,
        "glass.DAT: is binary data, not a text spectral file"
    );
}
