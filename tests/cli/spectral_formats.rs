//! Glazing data as it is served today (issue 15), end to end: IGSDB v2 JSON and instrument CSV
//! exports give the numbers of the plain files of the same product through `glassdb spectral`
//! and `glassdb registry build`; shading products, BSDF XML, diffuse data and binary files fail
//! with messages that name what they are. Fixtures: fixtures/glazing/README.md.

use std::path::Path;

use serde_json::Value;

use crate::util::{
    fails_naming, glassdb, glazing_fixture, ok, registry_build, repo_path, write_file,
};

const QUANTITIES: [&str; 3] = ["transmittance", "reflectance", "reflectance_back"];

/// `glassdb spectral --json [args…] <file>`, parsed.
fn spectral_json(args: &[&str], file: &Path) -> Value {
    let out = ok(glassdb().args(["spectral", "--json"]).args(args).arg(file));
    serde_json::from_str(&out).unwrap()
}

/// The numbers of every method's output for `file`: per quantity, rgb then both luminous values.
fn numbers(args: &[&str], file: &Path) -> Vec<Option<Vec<f64>>> {
    let v = spectral_json(args, file);
    QUANTITIES
        .iter()
        .map(|q| {
            let r = &v[*q];
            r.is_object().then(|| {
                let mut n: Vec<f64> = r["rgb"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap())
                    .collect();
                n.push(r["luminous"].as_f64().unwrap());
                n.push(r["luminous_1nm"].as_f64().unwrap());
                n
            })
        })
        .collect()
}

const METHODS: [&[&str]; 3] = [
    &[],
    &["--method", "paper"],
    &[
        "--observer",
        "cie1964",
        "--illuminant",
        "A",
        "--space",
        "acescg",
    ],
];

#[test]
fn igsdb_v2_json_gives_exactly_the_optics_files_numbers() {
    let optics = glazing_fixture("CLEAR_3.DAT");
    for other in ["igsdb_v2_clear_3.json", "CLEAR_3_dir_dif.DAT"] {
        for args in METHODS {
            assert_eq!(
                numbers(args, &glazing_fixture(other)),
                numbers(args, &optics),
                "{other} {args:?}"
            );
        }
    }
    let v = spectral_json(&[], &glazing_fixture("igsdb_v2_clear_3.json"));
    let p = &v["product"];
    assert_eq!(
        (
            p["name"].as_str(),
            p["product_type"].as_str(),
            p["format"].as_str()
        ),
        (
            Some("Generic Clear Glass"),
            Some("MONOLITHIC"),
            Some("igsdb-json")
        )
    );
    assert_eq!(p["thickness_mm"].as_f64(), Some(3.048));
    // Only files with other angle blocks list them.
    assert!(p.get("other_incidence_angles_deg").is_none(), "{p}");
    let text = ok(glassdb()
        .arg("spectral")
        .arg(glazing_fixture("igsdb_v2_clear_3.json")));
    assert!(
        text.contains("Generic Clear Glass, Generic, MONOLITHIC, coated side NA, 3.048 mm"),
        "{text}"
    );
}

/// The glass a one-glass catalog of `file` builds to.
fn registry_glass(dir: &Path, file: &str) -> Value {
    let catalog = format!(
        "[[glass]]\nid = 1\nname = \"glass\"\nspectral = \"{}\"\n",
        glazing_fixture(file).display()
    );
    let catalog = write_file(dir, &format!("{file}.toml"), catalog.as_bytes());
    let out = dir.join(format!("{file}.registry.json"));
    ok(&mut registry_build(&catalog, &out, &[]));
    let reg: Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    reg["tables"][0]["glasses"][0].clone()
}

#[test]
fn registry_r0_t0_from_igsdb_v2_json_equal_the_optics_files() {
    // One catalog per file: within one catalog, the second glass of two identical spectra can
    // differ from the first in the last bit of r0 (a registry property, not a reader one).
    let dir = tempfile::tempdir().unwrap();
    let optics = registry_glass(dir.path(), "CLEAR_3.DAT");
    let v2 = registry_glass(dir.path(), "igsdb_v2_clear_3.json");
    for key in ["r0", "t0", "r0_back", "c_r", "c_t", "c_r_back"] {
        assert!(!optics[key].is_null(), "{key}");
        assert_eq!(optics[key], v2[key], "{key}");
    }
    // MONOLITHIC chooses the uncoated (Fresnel) model, as Monolithic does in the Optics file.
    assert_eq!(v2["angle_model"]["kind"], "uncoated");
    assert_eq!(optics["angle_model"]["kind"], "uncoated");
    assert_eq!(
        v2["angle_model"]["chosen_by"],
        "product type \"MONOLITHIC\""
    );
}

#[test]
fn instrument_csv_exports_give_the_plain_csvs_numbers() {
    let plain = glazing_fixture("CLEAR_3.csv");
    for args in METHODS {
        assert_eq!(
            numbers(args, &plain),
            numbers(args, &glazing_fixture("CLEAR_3.DAT")),
            "{args:?}"
        );
        for name in [
            "CLEAR_3_cary.csv",
            "CLEAR_3_semicolon.csv",
            "CLEAR_3_tab.txt",
        ] {
            let got = numbers(args, &glazing_fixture(name));
            let want = numbers(args, &plain);
            for (k, (g, w)) in got.iter().zip(&want).enumerate() {
                // The Cary layout holds T and R, not Rb.
                let (Some(g), Some(w)) = (g, w) else {
                    assert!(name.contains("cary") && k == 2, "{name} {}", QUANTITIES[k]);
                    continue;
                };
                for (a, b) in g.iter().zip(w) {
                    assert!(
                        (a - b).abs() <= 1e-12 * b.abs().max(1e-3),
                        "{name} {args:?} {}: {a} vs {b}",
                        QUANTITIES[k]
                    );
                }
            }
        }
    }
}

#[test]
fn unsupported_kinds_get_messages_that_name_them() {
    let named = |file: &Path, parts: &[&str]| {
        fails_naming(glassdb().arg("spectral").arg(file), parts);
    };
    named(
        &glazing_fixture("igsdb_v1_venetian.json"),
        &[
            "igsdb_v1_venetian.json",
            "is an IGSDB shading product (venetian blind, \"Slim White Open\")",
            "glassdb reads glazing (specular) products only",
        ],
    );
    named(
        &glazing_fixture("diffuse_optics_file_2.txt"),
        &[
            "diffuse_optics_file_2.txt",
            "is an Optics file with diffuse columns",
            "line 16 has non-zero diffuse values",
        ],
    );
    named(
        &glazing_fixture("2011-SA1_trimmed.XML"),
        &[
            "2011-SA1_trimmed.XML",
            "is a BSDF XML file",
            "glassdb reads specular spectral data",
        ],
    );
    named(
        &repo_path("fixtures/example/mask.png"),
        &[
            "mask.png",
            "is binary data (a PNG image), not a text spectral file",
        ],
    );
    let dir = tempfile::tempdir().unwrap();
    let v2_shade = br#"{"type": "SHADING", "subtype": "VENETIAN_BLIND",
        "product_description": {"name": "Slat 25 mm"}, "physical_properties": {}}"#;
    named(
        &write_file(dir.path(), "blind.json", v2_shade),
        &[
            "blind.json",
            "shading product (venetian blind, \"Slat 25 mm\")",
        ],
    );
    named(
        &write_file(dir.path(), "book.csv", b"PK\x03\x04\x14\x00\x06\x00"),
        &["book.csv", "a ZIP archive, e.g. an .xlsx workbook"],
    );
    named(
        &write_file(dir.path(), "page.json", b"<!DOCTYPE html>\n<html></html>"),
        &["page.json", "is markup (XML or HTML, first element <html>)"],
    );
    // The registry passes the reader's message on.
    let catalog = format!(
        "[[glass]]\nid = 1\nname = \"blind\"\nspectral = \"{}\"\n",
        glazing_fixture("igsdb_v1_venetian.json").display()
    );
    let catalog = write_file(dir.path(), "catalog.toml", catalog.as_bytes());
    let out = dir.path().join("reg.json");
    fails_naming(
        &mut registry_build(&catalog, &out, &[]),
        &["blind", "is an IGSDB shading product (venetian blind"],
    );
}

#[test]
fn igsdb_v2_other_incidence_angles_are_named_not_read() {
    // The real v2 file with its 0° block copied as a 30° block: the numbers stay the 0° ones,
    // and both outputs say which angles the file has beside it.
    let dir = tempfile::tempdir().unwrap();
    let mut v: Value =
        serde_json::from_slice(&std::fs::read(glazing_fixture("igsdb_v2_clear_3.json")).unwrap())
            .unwrap();
    let blocks = v["physical_properties"]["optical_properties"]["optical_data"]["angle_blocks"]
        .as_array_mut()
        .unwrap();
    let mut oblique = blocks[0].clone();
    oblique["incidence_angle"] = serde_json::json!(30);
    blocks.push(oblique);
    let file = write_file(dir.path(), "two_angles.json", v.to_string().as_bytes());
    let text = ok(glassdb().arg("spectral").arg(&file));
    assert!(
        text.contains("normal incidence read; the file also has 30° (not read)"),
        "{text}"
    );
    let json = spectral_json(&[], &file);
    assert_eq!(
        json["product"]["other_incidence_angles_deg"][0], 30.0,
        "{json}"
    );
    assert_eq!(
        numbers(&[], &file),
        numbers(&[], &glazing_fixture("igsdb_v2_clear_3.json"))
    );
}
