//! End-to-end tests of the registry commands (`glassdb registry build|show|check`) and the
//! pywincalc 3.3.1 oracle comparison (python_oracle/registry_oracle.py).

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use glassdb_mask::{CosTheta, MaskFormat, MaskImage};

use crate::util::{
    CURVE_FIT_STATS, element_where, fails, glassdb, make_ref, ok, registry_build as build,
    repo_path, repo_root, run_oracle, write_file,
};

const EXPLICIT_GLASS: &str = "r0 = [0.08, 0.08, 0.08]\nt0 = [0.85, 0.86, 0.84]\n";

fn glazing(file: &str) -> String {
    repo_path("data/glazing").join(file).display().to_string()
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("read registry")).expect("registry is JSON")
}

/// `C(cos θ) = Σ c_k cos^p_k θ` evaluated from the JSON, independently of the crate.
fn curve(v: &serde_json::Value, cos: f64) -> f64 {
    let powers = v["powers"].as_array().expect("powers");
    let coefs = v["coefficients"].as_array().expect("coefficients");
    powers
        .iter()
        .zip(coefs)
        .map(|(p, c)| c.as_f64().unwrap() * cos.powi(p.as_u64().unwrap() as i32))
        .sum()
}

/// The ids of a registry's glasses (its first table's), in file order.
fn glass_ids(reg: &serde_json::Value) -> Vec<u64> {
    let glasses = reg["tables"][0]["glasses"].as_array().unwrap();
    glasses.iter().map(|g| g["id"].as_u64().unwrap()).collect()
}

fn glass_by_name<'a>(reg: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    element_where(&reg["tables"][0]["glasses"], "name", name)
}

#[test]
fn bad_catalogs_give_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("reg.json");
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "duplicate id",
            format!("[[glass]]\nid = 4\nname = \"a\"\n{EXPLICIT_GLASS}[[glass]]\nid = 4\nname = \"b\"\n{EXPLICIT_GLASS}"),
            "id 4 is used twice: by \"a\" and by \"b\"",
        ),
        ("id 0", format!("[[glass]]\nid = 0\nname = \"nothing\"\n{EXPLICIT_GLASS}"), "id 0"),
        ("id too large", format!("[[glass]]\nid = 65536\nname = \"big\"\n{EXPLICIT_GLASS}"), "outside 1–65535"),
        (
            "missing file",
            "[[glass]]\nid = 1\nname = \"gone\"\nspectral = \"no/such/file.DAT\"\n".to_string(),
            "no/such/file.DAT",
        ),
        (
            "unknown key",
            format!("[[glass]]\nid = 1\nname = \"a\"\n{EXPLICIT_GLASS}thickness = 4\n"),
            "unknown field `thickness`",
        ),
        ("wrong type", format!("[[glass]]\nid = \"7\"\nname = \"a\"\n{EXPLICIT_GLASS}"), "invalid type"),
        (
            "wrong type in array",
            "[[glass]]\nid = 1\nname = \"a\"\nr0 = [\"x\", 0.1, 0.1]\nt0 = [0.8, 0.8, 0.8]\n".to_string(),
            "invalid type",
        ),
        ("not TOML", "[[glass]\nid = 1\n".to_string(), "catalog.toml"),
        (
            "unknown model",
            format!("[[glass]]\nid = 1\nname = \"a\"\n{EXPLICIT_GLASS}model = \"frosted\"\n"),
            "unknown variant `frosted`",
        ),
        (
            "energy-violating explicit glass",
            "[[glass]]\nid = 1\nname = \"too bright\"\nr0 = [0.2, 0.2, 0.2]\nt0 = [0.9, 0.7, 0.7]\n".to_string(),
            "r0 + t0 = 0.2 + 0.9 > 1 in channel R",
        ),
    ];
    for (what, text, want) in cases {
        let catalog = write_file(dir.path(), "catalog.toml", text.as_bytes());
        let err = fails(&mut build(&catalog, &out, &[]));
        assert!(err.contains(want), "{what}: stderr lacks {want:?}:\n{err}");
        assert!(!out.exists(), "{what}: an output was written");
    }
}

#[test]
fn missing_catalog_and_non_utf8_catalog_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("reg.json");
    let err = fails(&mut build(&dir.path().join("nope.toml"), &out, &[]));
    assert!(err.contains("nope.toml"), "{err}");
    let bin = write_file(
        dir.path(),
        "bin.toml",
        b"[[glass]]\nid = 1\nname = \"\xff\"\n",
    );
    let err = fails(&mut build(&bin, &out, &[]));
    assert!(err.contains("bin.toml") && err.contains("UTF-8"), "{err}");
    // Bad option values are refused before any work.
    let catalog = explicit_catalog(dir.path(), &[1]);
    let err = fails(&mut build(&catalog, &out, &["--method", "magic"]));
    assert!(err.contains("--method"), "{err}");
    let err = fails(&mut build(&catalog, &out, &["--illuminant", "F99"]));
    assert!(err.contains("--illuminant"), "{err}");
    assert!(!out.exists());
}

#[test]
fn energy_violating_spectrum_is_refused_naming_the_wavelength() {
    let dir = tempfile::tempdir().unwrap();
    // A CSV spectrum whose T + R exceeds 1 at 550 nm.
    let mut csv = String::from("wavelength_nm,T,R\n");
    for wl in (300..=800).step_by(10) {
        let r = if wl == 550 { 0.3 } else { 0.08 };
        csv.push_str(&format!("{wl},0.85,{r}\n"));
    }
    write_file(dir.path(), "bright.csv", csv.as_bytes());
    let catalog = write_file(
        dir.path(),
        "catalog.toml",
        b"[[glass]]\nid = 2\nname = \"bright\"\nspectral = \"bright.csv\"\nmodel = \"uncoated\"\n",
    );
    let err = fails(&mut build(&catalog, &dir.path().join("r.json"), &[]));
    assert!(err.contains("550 nm") && err.contains("bright"), "{err}");
}

/// A registry whose curves violate r + t ≤ 1: r0 = 0.1 with C_r = 5 − 4 cos θ and t0 = 0.85
/// with C_t = 1. By hand: r + t = 1.35 − 0.4 cos θ exceeds 1 + (0.002 + 0.002) where
/// cos θ < 0.865, i.e. beyond 30.11°; the first angle of the 0.25° validation grid there is
/// 30.25°.
fn violating_registry() -> String {
    let curve = |powers: &str, coefs: &str| {
        format!(
            r#"{{"basis": "full", "powers": {powers}, "coefficients": {coefs}, "degree": 1, "rms_error": 0.0,
               "max_abs_error": 0.0, "max_error_angle_deg": 0.0, "condition_number": 1.0, "tolerance": 0.002}}"#
        )
    };
    let cr = curve("[0, 1]", "[5.0, -4.0]");
    let ct = curve("[0]", "[1.0]");
    let crb = curve("[0, 1, 2]", "[0.0, 0.0, 1.0]");
    format!(
        r#"{{"schema": 2, "spectral": {{"method": "colorimetric"}}, "glasses": [{{
            "id": 7, "name": "leaky", "r0": [0.1, 0.1, 0.1], "t0": [0.85, 0.85, 0.85], "r0_back": [0.1, 0.1, 0.1],
            "c_r": [{cr}, {cr}, {cr}], "c_t": [{ct}, {ct}, {ct}], "c_r_back": [{crb}, {crb}, {crb}],
            "angle_model": {{"kind": "uncoated", "applied": "per-channel"}}, "provenance": {{}}}}]}}"#
    )
}

#[test]
fn check_rejects_an_energy_violating_registry_naming_glass_and_angle() {
    let dir = tempfile::tempdir().unwrap();
    let reg = write_file(dir.path(), "leaky.json", violating_registry().as_bytes());
    let err = fails(glassdb().args(["registry", "check"]).arg(&reg));
    assert!(err.contains("id 7 (\"leaky\")"), "{err}");
    assert!(err.contains("at 30.25°") && err.contains("r + t"), "{err}");
    // show refuses it too (it validates on load).
    fails(glassdb().args(["registry", "show"]).arg(&reg));
}

#[test]
fn check_rejects_malformed_registries() {
    let dir = tempfile::tempdir().unwrap();
    let good = violating_registry().replace("[5.0, -4.0]", "[1.0, 0.0]");
    let cases = [
        ("not JSON", "{\"schema\": 1,\n \"glasses\": [", "line 2"),
        (
            "schema 1",
            "{\"schema\": 1, \"glasses\": []}",
            "schema 1 is not supported",
        ),
        (
            "schema 1, the command that rebuilds it",
            "{\"schema\": 1, \"glasses\": []}",
            "rebuild it: glassdb registry build CATALOG.toml -o ",
        ),
        ("id 0", &good.replace("\"id\": 7", "\"id\": 0"), "id 0"),
        (
            "NaN-like",
            &good.replace("[0.85, 0.85, 0.85]", "[0.85, 1e999, 0.85]"),
            "registry",
        ),
        (
            "r0 > 1",
            &good.replace("\"r0\": [0.1, 0.1, 0.1]", "\"r0\": [0.1, 1.5, 0.1]"),
            "r0 channel G = 1.5",
        ),
        (
            "curve shape",
            &good.replace("\"coefficients\": [1.0]", "\"coefficients\": [1.0, 2.0]"),
            "1 powers but 2 coefficients",
        ),
    ];
    for (what, text, want) in cases {
        let reg = write_file(dir.path(), "bad.json", text.as_bytes());
        let err = fails(glassdb().args(["registry", "check"]).arg(&reg));
        assert!(err.contains(want), "{what}: stderr lacks {want:?}:\n{err}");
    }
    // The repaired registry passes, and two duplicates of one id do not.
    let reg = write_file(dir.path(), "good.json", good.as_bytes());
    ok(glassdb().args(["registry", "check"]).arg(&reg));
    let v: serde_json::Value = serde_json::from_str(&good).unwrap();
    let mut dup = v.clone();
    let g = dup["glasses"][0].clone();
    dup["glasses"].as_array_mut().unwrap().push(g);
    let reg = write_file(dir.path(), "dup.json", dup.to_string().as_bytes());
    let err = fails(glassdb().args(["registry", "check"]).arg(&reg));
    assert!(err.contains("id 7 is used twice"), "{err}");
}

/// A catalog of three glasses listed out of id order: id 3 from CLEAR_3.DAT, id 1 from
/// LOW-E_5.LOF and id 200 given as RGB.
fn clear_lowe_grey_catalog(dir: &Path) -> PathBuf {
    let text = format!(
        "[[glass]]\nid = 3\nname = \"Clear 3\"\nspectral = \"{}\"\n\n[[glass]]\nid = 1\nname = \"Low-e\"\nspectral = \"{}\"\n\n[[glass]]\nid = 200\nname = \"Grey RGB\"\nr0 = [0.05, 0.05, 0.06]\nt0 = [0.4, 0.42, 0.45]\n",
        glazing("CLEAR_3.DAT"),
        glazing("LOW-E_5.LOF")
    );
    write_file(dir, "catalog.toml", text.as_bytes())
}

#[test]
fn build_show_check_and_json_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let catalog = clear_lowe_grey_catalog(dir.path());
    let out = dir.path().join("reg.json");
    ok(&mut build(&catalog, &out, &["--method", "luminous"]));
    let reg = read_json(&out);
    assert_eq!(reg["schema"], 4);
    assert_eq!(reg["tables"][0]["spectral"]["method"], "luminous");
    assert_eq!(glass_ids(&reg), [1, 3, 200], "glasses are sorted by id");
    let clear = glass_by_name(&reg, "Clear 3");
    // pywincalc 3.3.1 gives Tvis 0.899, Rf,vis 0.083 for CLEAR_3.DAT (data/glazing/README.md).
    assert!(
        (clear["t0"][1].as_f64().unwrap() - 0.899).abs() < 0.001,
        "{}",
        clear["t0"]
    );
    assert!(
        (clear["r0"][1].as_f64().unwrap() - 0.083).abs() < 0.001,
        "{}",
        clear["r0"]
    );
    assert_eq!(clear["angle_model"]["kind"], "uncoated");
    assert_eq!(
        clear["provenance"]["spectral"]["sha256"]
            .as_str()
            .unwrap()
            .len(),
        64
    );
    let lowe = glass_by_name(&reg, "Low-e");
    assert_eq!(lowe["angle_model"]["kind"], "coated");
    // Coated glass keeps both sides: Rf,vis 0.115 and Rb,vis 0.109 (pywincalc, README/oracle).
    assert!(
        (lowe["r0"][1].as_f64().unwrap() - lowe["r0_back"][1].as_f64().unwrap() - 0.006).abs()
            < 0.002
    );
    for g in reg["tables"][0]["glasses"].as_array().unwrap() {
        for key in ["c_r", "c_t", "c_r_back"] {
            for ch in 0..3 {
                let c = &g[key][ch];
                assert!((curve(c, 1.0) - 1.0).abs() < 1e-9, "{key}: C(0°) must be 1");
                for k in ["powers", "coefficients"].iter().chain(&CURVE_FIT_STATS) {
                    assert!(!c[k].is_null(), "{key} lacks {k}");
                }
            }
        }
    }

    // Round trip: load + write gives the same bytes, through the library API.
    let loaded = glassdb_registry::Registry::from_json_file(&out).unwrap();
    let again = dir.path().join("again.json");
    loaded.write_json(&again).unwrap();
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
    assert_eq!(
        glassdb_registry::Registry::from_json_file(&again).unwrap(),
        loaded
    );

    let stdout = ok(glassdb().args(["registry", "check"]).arg(&out));
    assert!(stdout.contains("ok"), "{stdout}");
    let show = ok(glassdb().args(["registry", "show"]).arg(&out));
    for want in [
        "id     1",
        "id   200",
        "Clear 3",
        "τv 0.899",
        "45°",
        "75°",
        "uncoated",
        "no spectrum",
    ] {
        assert!(show.contains(want), "show lacks {want:?}:\n{show}");
    }

    // Output equal to the catalog is refused; an unwritable output leaves nothing behind.
    fails(&mut build(&catalog, &catalog, &[]));
    let err = fails(&mut build(
        &catalog,
        Path::new("/nonexistent-dir-glassdb/reg.json"),
        &[],
    ));
    assert!(err.contains("/nonexistent-dir-glassdb/reg.json"), "{err}");
}

/// Writes a mask with the given id per pixel (cos θ = 1) in `format`.
fn write_mask(path: &Path, ids: &[u16], format: MaskFormat) {
    let n = ids.len();
    let cos = match format {
        MaskFormat::Png8 | MaskFormat::Binary => CosTheta::Quantized8(vec![255; n]),
        MaskFormat::Png16 => CosTheta::Quantized16(vec![65535; n]),
        MaskFormat::Exr => CosTheta::Float(vec![1.0; n]),
    };
    let mask = MaskImage {
        width: n as u32,
        height: 1,
        id: ids.to_vec(),
        cos_theta: cos,
        plane: vec![0; n],
        coverage: None,
    };
    glassdb_mask::write_mask(path, &mask, format).expect("write test mask");
}

fn explicit_catalog(dir: &Path, ids: &[u16]) -> PathBuf {
    let mut text = String::new();
    for id in ids {
        text.push_str(&format!(
            "[[glass]]\nid = {id}\nname = \"glass {id}\"\n{EXPLICIT_GLASS}\n"
        ));
    }
    write_file(dir, "catalog.toml", text.as_bytes())
}

#[test]
fn mask_filtered_build_keeps_only_the_ids_in_use() {
    let dir = tempfile::tempdir().unwrap();
    let catalog = explicit_catalog(dir.path(), &[1, 2, 5, 9]);
    let m1 = dir.path().join("a.png");
    let m2 = dir.path().join("b.png");
    write_mask(&m1, &[0, 5, 5, 0, 1], MaskFormat::Png8);
    write_mask(&m2, &[0, 0, 5, 0], MaskFormat::Png8);
    let out = dir.path().join("reg.json");
    ok(&mut build(
        &catalog,
        &out,
        &[
            "--mask",
            m1.to_str().unwrap(),
            "--mask",
            m2.to_str().unwrap(),
        ],
    ));
    let reg = read_json(&out);
    assert_eq!(glass_ids(&reg), [1, 5]);

    // Ids in the masks but not in the catalog: an error listing ids and pixel counts.
    let m3 = dir.path().join("c.png");
    write_mask(&m3, &[3, 3, 3, 7, 1, 0], MaskFormat::Png8);
    let err = fails(&mut build(
        &catalog,
        &dir.path().join("x.json"),
        &["--mask", m3.to_str().unwrap()],
    ));
    assert!(
        err.contains("id 3 (3 pixels)") && err.contains("id 7 (1 pixels)"),
        "{err}"
    );
    assert!(!err.contains("id 1 ("), "{err}");

    // A catalog id above 255 cannot be addressed by an 8-bit mask ...
    let catalog = explicit_catalog(dir.path(), &[1, 300]);
    let err = fails(&mut build(
        &catalog,
        &dir.path().join("y.json"),
        &["--mask", m1.to_str().unwrap()],
    ));
    assert!(err.contains("id 300") && err.contains("8-bit"), "{err}");
    // ... but can by a 16-bit one.
    let m16 = dir.path().join("d.png");
    write_mask(&m16, &[300, 0, 1], MaskFormat::Png16);
    ok(&mut build(
        &catalog,
        &dir.path().join("z.json"),
        &["--mask", m16.to_str().unwrap()],
    ));

    // An unreadable mask names the file.
    let junk = write_file(dir.path(), "junk.png", b"not a png");
    let err = fails(&mut build(
        &catalog,
        &dir.path().join("w.json"),
        &["--mask", junk.to_str().unwrap()],
    ));
    assert!(err.contains("junk.png"), "{err}");
}

/// The spaces of the bundled registry's tables: Blender 5's three working spaces and ACES's
/// interchange space.
const BUNDLED_SPACES: &str = "srgb,acescg,rec2020,aces2065-1";

/// `data/registry.json` (the bundled default) is exactly what the documented command builds
/// from `data/catalog.toml`; `GLASSDB_MAKE_REF=1` rewrites it instead.
#[test]
fn bundled_registry_json_rebuilds_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("registry.json");
    ok(glassdb()
        .current_dir(repo_root())
        .args([
            "registry",
            "build",
            "data/catalog.toml",
            "--space",
            BUNDLED_SPACES,
            "-o",
        ])
        .arg(&out));
    let fresh = std::fs::read(&out).unwrap();
    let committed = repo_path("data/registry.json");
    if make_ref() {
        std::fs::write(&committed, &fresh).unwrap();
    }
    assert!(
        fresh == std::fs::read(&committed).unwrap(),
        "data/registry.json differs from `glassdb registry build data/catalog.toml --space {BUNDLED_SPACES} -o data/registry.json` \
         (run from the repository root); regenerate it with GLASSDB_MAKE_REF=1 cargo test --test cli bundled_registry_json"
    );
    // Nothing machine-specific: paths are relative to the repository or to the catalog.
    let text = String::from_utf8(fresh).unwrap();
    let root = repo_root().display().to_string();
    assert!(!text.contains(&root), "absolute path in data/registry.json");
    assert_eq!(
        glassdb_registry::default_registry().unwrap(),
        glassdb_registry::Registry::from_json_str(&text, "fresh").unwrap()
    );
}

#[test]
fn bundled_default_registry_builds_and_validates() {
    let reg = glassdb_registry::default_registry().expect("bundled catalog builds");
    let table = reg.default_table();
    let ids: Vec<u16> = table.glasses.iter().map(|g| g.id).collect();
    for id in [1, 2, 4, 5, 6] {
        assert!(ids.contains(&id), "bundled registry lacks id {id}: {ids:?}");
    }
    reg.validate().unwrap();
    // Clear 3 mm under D65/sRGB: τv 0.899 (README); G close to it, R below (iron absorbs red).
    let clear = table.glass(1).unwrap();
    assert!((clear.luminous.unwrap().transmittance - 0.899).abs() < 0.001);
    assert!(clear.t0[0] < clear.t0[1]);
    // The command-line build of the same catalog gives the same registry numbers.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("default.json");
    ok(&mut build(&repo_path("data/catalog.toml"), &out, &[]));
    let disk = glassdb_registry::Registry::from_json_file(&out).unwrap();
    let disk = disk.default_table();
    assert_eq!(disk.glasses.len(), table.glasses.len());
    for (a, b) in disk.glasses.iter().zip(&table.glasses) {
        assert_eq!((a.id, a.r0, a.t0, &a.c_r), (b.id, b.r0, b.t0, &b.c_r));
    }
}

const ORACLE_ANGLES: &str = "0,10,20,30,40,50,60,70,75,80";

/// The luminous registry of `fixtures/registry/oracle.toml` (the products compared with
/// pywincalc), built in `dir`.
fn oracle_registry(dir: &Path) -> serde_json::Value {
    let out = dir.join("lum.json");
    ok(&mut build(
        &repo_path("fixtures/registry/oracle.toml"),
        &out,
        &["--method", "luminous"],
    ));
    read_json(&out)
}

/// pywincalc's values of `files` per angle of `ORACLE_ANGLES`.
fn oracle(files: &[&str]) -> serde_json::Value {
    oracle_run(ORACLE_ANGLES, files)
}

/// `registry_oracle.py FIRST FILES…` (FIRST: the angles, or `hemispherical`), its JSON.
fn oracle_run(first: &str, files: &[&str]) -> serde_json::Value {
    let mut args: Vec<std::ffi::OsString> = vec![first.into()];
    args.extend(files.iter().map(|f| std::ffi::OsString::from(glazing(f))));
    let refs: Vec<&OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    serde_json::from_str(&run_oracle("registry_oracle.py", &refs)).expect("oracle JSON")
}

/// Uncoated glass: our per-wavelength Fresnel model, integrated photopically and fitted, against
/// WINDOW's engine (pywincalc 3.3.1), photopic T(θ), Rf(θ), Rb(θ): within 0.003 from 0 to 80°.
#[test]
fn uncoated_glass_matches_pywincalc() {
    let dir = tempfile::tempdir().unwrap();
    let reg = oracle_registry(dir.path());
    let files = ["CLEAR_3.DAT", "CLEAR_6.DAT", "CLEAR5.LOF"];
    let o = oracle(&files);
    for f in files {
        let g = glass_by_name(&reg, f);
        assert_eq!(g["angle_model"]["kind"], "uncoated", "{f}");
        let w = &o[f];
        for (i, a) in w["angle_deg"].as_array().unwrap().iter().enumerate() {
            let cos = a.as_f64().unwrap().to_radians().cos();
            for ch in 0..3 {
                let t = g["t0"][ch].as_f64().unwrap() * curve(&g["c_t"][ch], cos);
                let rf = g["r0"][ch].as_f64().unwrap() * curve(&g["c_r"][ch], cos);
                let rb = g["r0_back"][ch].as_f64().unwrap() * curve(&g["c_r_back"][ch], cos);
                for (name, ours, theirs) in [
                    ("T", t, &w["T"][i]),
                    ("Rf", rf, &w["Rf"][i]),
                    ("Rb", rb, &w["Rb"][i]),
                ] {
                    let theirs = theirs.as_f64().unwrap();
                    assert!(
                        (ours - theirs).abs() <= 0.003,
                        "{f} {name} at {a}°: ours {ours:.5}, pywincalc {theirs:.5}"
                    );
                }
            }
        }
    }
}

/// Coated glass with the bronze curve (what pywincalc 3.3.1 applies to every coated layer):
/// our curves are renormalised to pass through T0, R0 at 0° (docs/registry.md), so undo that
/// with the published WINDOW-4 numbers before comparing: T_raw = τ(0°)·T, and
/// R_raw = R + ρ(0°)·(1 − R0)·(1 − ρ̂(θ)), ρ̂ = (ρ − ρ(0°))/(1 − ρ(0°)), exact because the photopic
/// integral is linear and the curve is one for all wavelengths.
#[test]
fn coated_bronze_glass_matches_pywincalc() {
    let dir = tempfile::tempdir().unwrap();
    let files = [
        "LOW-E_5.LOF",
        "CSR42_3.afg",
        "nfrc_20748.oag",
        "nfrc_9223.json",
    ];
    let reg = bronze_registry(dir.path(), &files);
    let o = oracle(&files);
    let (rho, tau1, rho1) = (bronze_rho, bronze_tau(1.0), bronze_rho(1.0));
    for f in files {
        let g = glass_by_name(&reg, f);
        let w = &o[f];
        for (i, a) in w["angle_deg"].as_array().unwrap().iter().enumerate() {
            let a = a.as_f64().unwrap();
            if a == 0.0 {
                continue; // pywincalc reports the measured normal values at 0°
            }
            let cos = a.to_radians().cos();
            let rho_hat = (rho(cos) - rho1) / (1.0 - rho1);
            let t = tau1 * g["t0"][1].as_f64().unwrap() * curve(&g["c_t"][1], cos);
            let back = |key: &str, c: &str| {
                let r0 = g[key][1].as_f64().unwrap();
                r0 * curve(&g[c][1], cos) + rho1 * (1.0 - r0) * (1.0 - rho_hat)
            };
            for (name, ours, theirs) in [
                ("T", t, &w["T"][i]),
                ("Rf", back("r0", "c_r"), &w["Rf"][i]),
                ("Rb", back("r0_back", "c_r_back"), &w["Rb"][i]),
            ] {
                let theirs = theirs.as_f64().unwrap();
                assert!(
                    (ours - theirs).abs() <= 0.003,
                    "{f} {name} at {a}°: ours {ours:.5}, pywincalc {theirs:.5}"
                );
            }
        }
    }
}

/// A luminous registry of `files`, each a single pane with the WINDOW-4 bronze curve (what
/// pywincalc 3.3.1 applies to every coated layer).
fn bronze_registry(dir: &Path, files: &[&str]) -> serde_json::Value {
    let mut text = String::new();
    for (i, f) in files.iter().enumerate() {
        text.push_str(&format!(
            "[[glass]]\nid = {}\nname = \"{f}\"\nspectral = \"{}\"\nmodel = \"coated-bronze\"\n\n",
            i + 1,
            glazing(f)
        ));
    }
    let catalog = write_file(dir, "bronze.toml", text.as_bytes());
    let out = dir.join("bronze.json");
    ok(&mut build(&catalog, &out, &["--method", "luminous"]));
    read_json(&out)
}

fn bronze_poly(c: &[f64; 5], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, k| acc * x + k)
}

/// WINDOW-4's bronze τ(cos θ), as published.
fn bronze_tau(x: f64) -> f64 {
    bronze_poly(&[-0.002, 2.813, -2.341, -0.05725, 0.599], x)
}

/// WINDOW-4's bronze ρ(cos θ) = R(cos θ) − τ(cos θ), as published.
fn bronze_rho(x: f64) -> f64 {
    bronze_poly(&[0.997, -1.868, 6.513, -7.862, 3.225], x) - bronze_tau(x)
}

/// `2∫₀¹ f(μ) μ dμ` by Simpson's rule on 2000 intervals (the hemispherical integral of a curve
/// of cos θ, independently of the crate).
fn hemispherical_of(f: impl Fn(f64) -> f64) -> f64 {
    let n = 2000;
    let h = 1.0 / n as f64;
    (0..=n)
        .map(|i| {
            let mu = i as f64 * h;
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * h / 3.0 * 2.0 * f(mu) * mu
        })
        .sum()
}

/// WINDOW's trapezoidal rule over θ at 0, 10, …, 90° (how pywincalc 3.3.1 integrates its
/// diffuse-diffuse values) of a curve of cos θ.
fn window_trapezoid_of(f: impl Fn(f64) -> f64) -> f64 {
    let h = 10f64.to_radians();
    (0..=9)
        .map(|i| {
            let theta = i as f64 * h;
            let w = if i == 0 || i == 9 { 0.5 } else { 1.0 };
            w * h * 2.0 * f(theta.cos()) * theta.cos() * theta.sin()
        })
        .sum()
}

/// The hemispherical values every glass now stores (`t_dif`, `r_dif` of both faces) against
/// WINDOW's engine (pywincalc 3.3.1) on single panes. WINDOW integrates its diffuse-diffuse
/// values by the trapezoidal rule at 10° steps, 0.004–0.005 low for clear glass; so two checks
/// per value: against the same integral of WINDOW's direct values by Simpson at 1° (the
/// quadrature gone: what is left is the angle model's and the fit's difference), and WINDOW's own
/// diffuse-diffuse number against our curves integrated by WINDOW's rule (tolerances below). Uncoated
/// panes as they are; coated ones with the bronze curve, undone as in
/// `coated_bronze_glass_matches_pywincalc` (linear in the curves, so in their integrals).
#[test]
fn hemispherical_values_match_pywincalc() {
    let dir = tempfile::tempdir().unwrap();
    let uncoated = oracle_registry(dir.path());
    let coated = ["LOW-E_5.LOF", "nfrc_9223.json"];
    let bronze = bronze_registry(dir.path(), &coated);
    let files = [
        "CLEAR_3.DAT",
        "CLEAR_6.DAT",
        "CLEAR5.LOF",
        coated[0],
        coated[1],
    ];
    let o = oracle_run("hemispherical", &files);
    for f in files {
        let is_coated = coated.contains(&f);
        let g = glass_by_name(if is_coated { &bronze } else { &uncoated }, f);
        let h = &g["hemispherical"];
        // Uncoated panes: both sides of one Fresnel model (measured: within 6e-5). Coated ones:
        // WINDOW's per-wavelength bronze against our per-channel fit of it, which the per-angle
        // test allows 0.003 (measured: 1.6e-3 in Rb of the dark film nfrc_9223, 3.4e-5 on LOW-E_5).
        let tol = if is_coated { 2e-3 } else { 1e-4 };
        let (w, fine) = (&o[f]["window"], &o[f]["fine"]);
        assert_eq!(w["T"], w["Tb"], "{f}: WINDOW's t_dif differs by side");
        // WINDOW's τ·t and R + ρ1(1 − R0)(1 − ρ̂) for a coated pane (the identity otherwise).
        let (tau1, rho1) = (bronze_tau(1.0), bronze_rho(1.0));
        let rho_hat = |x: f64| (bronze_rho(x) - rho1) / (1.0 - rho1);
        for ch in 0..3 {
            let at = |v: &serde_json::Value| v[ch].as_f64().unwrap();
            let t_curve = |x: f64| at(&g["t0"]) * curve(&g["c_t"][ch], x);
            let t_raw = |x: f64| {
                if is_coated {
                    tau1 * t_curve(x)
                } else {
                    t_curve(x)
                }
            };
            let t_dif = if is_coated {
                tau1 * at(&h["transmittance"])
            } else {
                at(&h["transmittance"])
            };
            let mut checks = vec![("T", t_dif, window_trapezoid_of(t_raw), "T")];
            for (name, key, r0, c) in [
                ("Rf", "reflectance", "r0", "c_r"),
                ("Rb", "reflectance_back", "r0_back", "c_r_back"),
            ] {
                let r0 = at(&g[r0]);
                let extra = |x: f64| {
                    if is_coated {
                        rho1 * (1.0 - r0) * (1.0 - rho_hat(x))
                    } else {
                        0.0
                    }
                };
                let r_dif = at(&h[key]) + hemispherical_of(extra);
                let r_raw = |x: f64| r0 * curve(&g[c][ch], x) + extra(x);
                checks.push((name, r_dif, window_trapezoid_of(r_raw), name));
            }
            for (name, ours, ours_by_window_rule, key) in checks {
                let fine = fine[key].as_f64().unwrap();
                let window = w[key].as_f64().unwrap();
                assert!(
                    (ours - fine).abs() <= tol,
                    "{f} {name}_dif: ours {ours:.5}, pywincalc's direct values integrated {fine:.5}"
                );
                assert!(
                    (ours_by_window_rule - window).abs() <= tol,
                    "{f} {name}_dif by WINDOW's rule: ours {ours_by_window_rule:.5}, pywincalc {window:.5}"
                );
            }
        }
    }
}
