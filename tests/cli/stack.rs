//! End-to-end tests of `glassdb stack` and of units in the registry: against LBNL's WINDOW
//! engine (pywincalc 3.3.1, python_oracle/stack_oracle.py) per angle, against colour-science
//! integrating our system spectra, a unit of one layer against the glass itself, and every bad
//! build-up of issue 26 named by its argument or catalog line.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::util::{
    assert_names, element_where, fails_naming, glassdb, glazing_fixture, ok, registry_build,
    repo_path, run_oracle, write_file,
};

/// The angles every comparison uses: 0–80° in 10° steps.
const ANGLES: &str = "0,10,20,30,40,50,60,70,80";

fn glazing(file: &str) -> String {
    let data = repo_path("data/glazing").join(file);
    let path = if data.exists() {
        data
    } else {
        glazing_fixture(file)
    };
    path.display().to_string()
}

/// `glassdb stack LAYER... --angles ANGLES --json [extra]` with the layers' files found in
/// data/glazing (or fixtures/glazing), options kept (`FILE:flip:model=…`).
fn ours(layers: &[&str], extra: &[&str]) -> Value {
    let mut cmd = glassdb();
    cmd.arg("stack");
    for l in layers {
        let (file, opts) = l.split_once(':').map_or((*l, ""), |(f, o)| (f, o));
        let sep = if opts.is_empty() { "" } else { ":" };
        cmd.arg(format!("{}{sep}{opts}", glazing(file)));
    }
    cmd.args(["--angles", ANGLES, "--json"]).args(extra);
    serde_json::from_str(&ok(&mut cmd)).expect("glassdb stack --json is JSON")
}

/// pywincalc on the same layers (`FILE` or `FILE:flip`).
fn theirs(layers: &[&str]) -> Value {
    let mut args: Vec<String> = vec!["window".into(), ANGLES.into()];
    for l in layers {
        let (file, flip) = l.split_once(':').map_or((*l, ""), |(f, o)| (f, o));
        args.push(format!(
            "{}{}",
            glazing(file),
            if flip.contains("flip") { ":flip" } else { "" }
        ));
    }
    let refs: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
    serde_json::from_str(&run_oracle("stack_oracle.py", &refs)).expect("oracle JSON")
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

/// The largest |ours − theirs| of T, Rf, Rb and of the layer absorptances, per method, asserting
/// each within `tol`.
fn compare(name: &str, ours_layers: &[&str], oracle_layers: &[&str], tol: f64) -> [f64; 4] {
    let us = ours(ours_layers, &[]);
    let them = theirs(oracle_layers);
    let mut worst = [0.0f64; 4]; // photopic T/R, photopic absorptance, solar T/R, solar absorptance
    for (m, (key, their_key)) in [("photopic", "PHOTOPIC"), ("solar", "SOLAR")]
        .iter()
        .enumerate()
    {
        for q in ["T", "Rf", "Rb"] {
            let a = numbers(&us[key][q]);
            let b = numbers(&them[their_key][q]);
            assert_eq!(a.len(), b.len(), "{name}: {key} {q}");
            for (i, (x, y)) in a.iter().zip(&b).enumerate() {
                let d = (x - y).abs();
                worst[2 * m] = worst[2 * m].max(d);
                assert!(
                    d <= tol,
                    "{name}: {key} {q} at {}°: glassdb {x:.6} vs pywincalc {y:.6} (|Δ| {d:.2e} > {tol})",
                    10 * i
                );
            }
        }
        for side in ["front", "back"] {
            let ours_abs = us[key]["absorptance"][side].as_array().unwrap();
            let their_abs = them[their_key][format!("absorptance_{side}")]
                .as_array()
                .unwrap();
            for (i, (a, b)) in ours_abs.iter().zip(their_abs).enumerate() {
                for (k, (x, y)) in numbers(a).iter().zip(numbers(b)).enumerate() {
                    let d = (x - y).abs();
                    worst[2 * m + 1] = worst[2 * m + 1].max(d);
                    assert!(
                        d <= tol,
                        "{name}: {key} absorptance of layer {} ({side}) at {}°: {x:.6} vs {y:.6}",
                        k + 1,
                        10 * i
                    );
                }
            }
        }
    }
    eprintln!(
        "{name}: max |Δ| photopic T/R {:.1e}, absorptance {:.1e}; solar T/R {:.1e}, absorptance {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    worst
}

/// Uncoated units: our per-wavelength stack against WINDOW's within 1e-3 (measured: 1e-15, the
/// same arithmetic).
#[test]
fn uncoated_units_match_pywincalc() {
    let double = ["CLEAR_3.DAT", "CLEAR_6.DAT"];
    compare("double clear", &double, &double, 1e-3);
    let triple = ["CLEAR_3.DAT", "CLEAR5.LOF", "CLEAR_6.DAT"];
    compare("triple clear", &triple, &triple, 1e-3);
    let v2 = ["igsdb_v2_clear_3.json", "CLEAR_6.DAT"];
    compare("IGSDB v2 product", &v2, &v2, 1e-3);
}

/// The coated build-ups of the tests below: name and our layers (`:MODEL` stands for the
/// model); pywincalc's layers are the same files without it.
fn coated_cases() -> Vec<(&'static str, Vec<&'static str>)> {
    vec![
        (
            "coated on #2 (Solarban R67, coating on its back)",
            vec!["igsdb_product_10693.json:MODEL", "CLEAR_6.DAT"],
        ),
        (
            "coated on #3 (Energy Advantage low-e, coating on its front)",
            vec!["CLEAR_6.DAT", "LOW-E_5.LOF:MODEL"],
        ),
        (
            "flipped (Energy Advantage turned round: coating on #2)",
            vec!["LOW-E_5.LOF:flip:MODEL", "CLEAR_6.DAT"],
        ),
        (
            "laminate (Vitro SB70 #2 | 0.090 SGP | clear, 13.6 mm)",
            vec!["igsdb_product_11148.json:MODEL", "CLEAR_6.DAT"],
        ),
        (
            "triple (R67 | clear | Stopray)",
            vec![
                "igsdb_product_10693.json:MODEL",
                "CLEAR_6.DAT",
                "nfrc_20748.oag:MODEL",
            ],
        ),
    ]
}

/// Coated layers with the model forced to coated-bronze (pywincalc 3.3.1's rule for every
/// coated layer) within 1e-2: what remains is our renormalisation of the bronze curve to the
/// measured 0° values; with the curve as published (`coated-bronze-published`) the engines
/// agree within 1e-8 (measured 2.4e-9: the wavelengths glassdb merges where two files store
/// one wavelength 1e-5 nm apart), which shows that the renormalisation is the whole difference.
#[test]
fn coated_units_match_pywincalc_with_the_bronze_model() {
    for (model, tol) in [("coated-bronze", 1e-2), ("coated-bronze-published", 1e-8)] {
        for (name, layers) in coated_cases() {
            let us: Vec<String> = layers
                .iter()
                .map(|l| l.replace("MODEL", &format!("model={model}")))
                .collect();
            let us: Vec<&str> = us.iter().map(String::as_str).collect();
            let them: Vec<&str> = layers
                .iter()
                .map(|l| l.trim_end_matches(":MODEL"))
                .collect();
            compare(&format!("{name}, {model}"), &us, &them, tol);
        }
    }
}

/// The colours are colour-science's integration of our per-wavelength system spectra.
#[test]
fn unit_colours_are_colour_sciences_integration_of_the_spectra() {
    for space in ["srgb", "acescg"] {
        let us = ours(
            &["igsdb_product_10693.json", "CLEAR_6.DAT", "nfrc_20748.oag"],
            &["--spectra", "--space", space],
        );
        let mut oracle = std::process::Command::new(crate::util::oracle_python());
        oracle
            .arg(repo_path("python_oracle/stack_oracle.py"))
            .args(["rgb", space])
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped());
        let mut child = oracle.spawn().expect("run the oracle");
        {
            use std::io::Write;
            let mut stdin = child.stdin.take().unwrap();
            stdin.write_all(us.to_string().as_bytes()).unwrap();
        }
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success(), "stack_oracle.py rgb failed");
        let them: Value = serde_json::from_slice(&out.stdout).unwrap();
        for q in ["T", "Rf", "Rb"] {
            for (a, b) in us["rgb"][q]
                .as_array()
                .unwrap()
                .iter()
                .zip(them[q].as_array().unwrap())
            {
                for (x, y) in numbers(a).iter().zip(numbers(b)) {
                    assert!(
                        (x - y).abs() < 1e-9,
                        "{space} {q}: {x} vs colour-science {y}"
                    );
                }
            }
        }
    }
}

/// The pane groups' shares sum to the reflectance, the outer share is the outer pane's own
/// reflectance, and the depths are the panes' mid-planes.
#[test]
fn pane_group_shares_and_depths() {
    let us = ours(&["CLEAR_6.DAT", "CLEAR_6.DAT"], &["--gap", "12.7:argon"]);
    let groups = us["groups"].as_array().unwrap();
    let depths: Vec<f64> = groups
        .iter()
        .map(|g| g["depth_mm"].as_f64().unwrap())
        .collect();
    assert!((depths[0] - 5.715 / 2.0).abs() < 1e-9, "{depths:?}");
    assert!(
        (depths[1] - (5.715 + 12.7 + 5.715 / 2.0)).abs() < 1e-9,
        "{depths:?}"
    );
    assert_eq!(us["gaps"][0]["gas"], "argon");
    let layer_rf = numbers(&us["layers"][0]["photopic"]["Rf"]);
    let rf = numbers(&us["photopic"]["Rf"]);
    for (i, shares) in us["photopic"]["group_shares"]["front"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        let s = numbers(shares);
        assert!((s[0] + s[1] - rf[i]).abs() < 1e-12);
        assert!(
            (s[0] - layer_rf[i]).abs() < 1e-12,
            "outer share is the outer pane's Rf"
        );
        // near normal incidence the inner pane gives about 40 % of a double clear unit's
        // reflectance (issue 27); at grazing the outer pane reflects nearly everything
        if i <= 4 {
            assert!(
                s[1] / rf[i] > 0.35,
                "inner share {} of {} at {}°",
                s[1],
                rf[i],
                10 * i
            );
        }
    }
}

fn catalog_with(dir: &Path, body: &str) -> PathBuf {
    let text = body.replace("GLAZING", &repo_path("data/glazing").display().to_string());
    write_file(dir, "catalog.toml", text.as_bytes())
}

/// `glassdb registry build` of the catalog `body` ([`catalog_with`]) with `extra` flags into
/// `dir/reg.json`: that file and its JSON.
fn registry_with(dir: &Path, body: &str, extra: &[&str]) -> (PathBuf, Value) {
    let catalog = catalog_with(dir, body);
    let out = dir.join("reg.json");
    ok(&mut registry_build(&catalog, &out, extra));
    let reg = read_json(&out);
    (out, reg)
}

fn read_json(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

fn glass(table: &Value, id: u64) -> &Value {
    element_where(&table["glasses"], "id", id)
}

/// A unit of one layer is that layer's registry entry exactly (turned round when flipped).
#[test]
fn a_unit_of_one_layer_is_the_glass_itself() {
    let dir = tempfile::tempdir().unwrap();
    let (_, reg) = registry_with(
        dir.path(),
        r#"
[[glass]]
id = 1
name = "R67"
spectral = "GLAZING/igsdb_product_10693.json"

[[glass]]
id = 2
name = "R67 as a unit"
layers = [{ spectral = "GLAZING/igsdb_product_10693.json" }]

[[glass]]
id = 3
name = "R67 turned round"
layers = [{ spectral = "GLAZING/igsdb_product_10693.json", flip = true }]
"#,
        &["--space", "srgb,acescg"],
    );
    assert_eq!(reg["schema"], 4);
    for table in reg["tables"].as_array().unwrap() {
        let (single, unit, turned) = (glass(table, 1), glass(table, 2), glass(table, 3));
        for key in [
            "r0",
            "t0",
            "r0_back",
            "c_r",
            "c_t",
            "c_r_back",
            "luminous",
            "angle_model",
        ] {
            assert_eq!(single[key], unit[key], "{key}");
        }
        for (a, b) in [
            ("r0", "r0_back"),
            ("c_r", "c_r_back"),
            ("t0", "t0"),
            ("c_t", "c_t"),
        ] {
            assert_eq!(single[a], turned[b], "{a} vs turned {b}");
        }
        assert!(single.get("unit").is_none());
        let u = &unit["unit"];
        assert_eq!(u["elements"].as_array().unwrap().len(), 1);
        assert_eq!(u["groups"][0]["r0"], single["r0"]);
        assert_eq!(turned["unit"]["elements"][0]["flipped"], true);
    }
}

/// A unit in the registry: the system curves are the stack's colours fitted, the pane groups
/// carry their depths and shares, and the unit's record names its layers.
#[test]
fn a_double_unit_in_the_registry() {
    let dir = tempfile::tempdir().unwrap();
    let (out, reg) = registry_with(
        dir.path(),
        r#"
[[glass]]
id = 12
name = "R67 #2 | 12.7 argon | clear 6"
layers = [
    { spectral = "GLAZING/igsdb_product_10693.json" },
    { gap_mm = 12.7, gas = "argon" },
    { spectral = "GLAZING/CLEAR_6.DAT" },
]
"#,
        &[],
    );
    let g = glass(&reg["tables"][0], 12);
    assert_eq!(g["angle_model"]["kind"], "unit");
    let u = &g["unit"];
    assert_eq!(u["elements"][1]["kind"], "gap");
    assert_eq!(u["elements"][1]["gas"], "argon");
    assert_eq!(
        u["elements"][2]["provenance"]["spectral"]["path"],
        format!("{}/CLEAR_6.DAT", repo_path("data/glazing").display())
    );
    let depth = |k: usize| u["groups"][k]["depth_mm"].as_f64().unwrap();
    assert!(
        (depth(0) - 5.664 / 2.0).abs() < 1e-3
            && (depth(1) - (5.664 + 12.7 + 5.715 / 2.0)).abs() < 1e-3
    );
    // the same unit on the command line: the registry's curves are its colours, fitted
    let us = ours(
        &["igsdb_product_10693.json", "CLEAR_6.DAT"],
        &["--gap", "12.7:argon"],
    );
    for (i, a) in [0.0f64, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0]
        .iter()
        .enumerate()
    {
        let cos = a.to_radians().cos();
        for ch in 0..3 {
            for (key, r0, c) in [
                ("T", "t0", "c_t"),
                ("Rf", "r0", "c_r"),
                ("Rb", "r0_back", "c_r_back"),
            ] {
                let reg_v = g[r0][ch].as_f64().unwrap() * curve_at(&g[c][ch], cos);
                let cli = us["rgb"][key][i][ch].as_f64().unwrap();
                assert!(
                    (reg_v - cli).abs() < 0.0025,
                    "{key} {a}° ch {ch}: registry {reg_v} vs stack {cli}"
                );
            }
            let share: f64 = (0..2)
                .map(|k| {
                    let gr = &u["groups"][k];
                    gr["r0"][ch].as_f64().unwrap() * curve_at(&gr["c_r"][ch], cos)
                })
                .sum();
            let r = g["r0"][ch].as_f64().unwrap() * curve_at(&g["c_r"][ch], cos);
            assert!((share - r).abs() < 0.006, "{a}°: shares {share} vs r {r}");
        }
    }
    assert_names(
        &ok(glassdb().args(["registry", "show"]).arg(&out)),
        &["unit", "argon", "pane group"],
    );
}

/// Every bad build-up of issue 26 is an error naming the argument…
#[test]
fn bad_build_ups_on_the_command_line_name_the_argument() {
    let clear = glazing("CLEAR_6.DAT");
    let dir = tempfile::tempdir().unwrap();
    let csv = |name: &str, from: u32, t: f64| {
        let mut text = String::from("wavelength_nm,T,R,Rb\n");
        for k in 0..=20 {
            text.push_str(&format!("{},{t},0.3,0.3\n", from + 110 * k));
        }
        write_file(dir.path(), name, text.as_bytes())
            .display()
            .to_string()
    };
    let dark = format!("{}:thickness=4", csv("dark.csv", 300, 0.0));
    let far = format!("{}:thickness=4", csv("far.csv", 3000, 0.5));
    let stack = |args: &[&str]| {
        let mut cmd = glassdb();
        cmd.arg("stack").args(args);
        cmd
    };
    fails_naming(
        &mut stack(&[&clear, "--gap", "12:flip"]),
        &["--gap 12:flip", "flip on a gap"],
    );
    fails_naming(
        &mut stack(&[&clear, &clear, "--gap", "-3"]),
        &["--gap -3", "positive"],
    );
    fails_naming(
        &mut stack(&[&clear, &clear, "--gap", "NaN"]),
        &["--gap NaN", "positive"],
    );
    fails_naming(
        &mut stack(&[&format!("{clear}:thickness=-2")]),
        &["LAYER 1", "thickness -2"],
    );
    fails_naming(
        &mut stack(&[&format!("{clear}:flp")]),
        &["LAYER 1", "unknown option `flp`"],
    );
    fails_naming(
        &mut stack(&[
            &clear, &clear, &clear, "--gap", "12", "--gap", "6", "--gap", "9",
        ]),
        &["3 --gap values for 3 layers"],
    );
    fails_naming(
        &mut stack(&[&dark, &clear]),
        &[
            "LAYER 1",
            "dark.csv",
            "is opaque but layer 3 lies behind it",
        ],
    );
    fails_naming(
        &mut stack(&[&clear, &far]),
        &["LAYER 2", "far.csv", "does not overlap"],
    );
    fails_naming(
        &mut stack(&[&format!("{clear}:model=opaque"), &clear]),
        &["LAYER 1", "model `opaque` means T = 0"],
    );
}

/// …or its catalog line.
#[test]
fn bad_build_ups_in_a_catalog_name_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("layers = [{ gap_mm = 12 }]", "no glass layer", 3),
        (
            "layers = [\n  { gap_mm = 12 },\n  { spectral = \"GLAZING/CLEAR_6.DAT\" },\n]",
            "gap at the outer end",
            7,
        ),
        (
            "layers = [\n  { spectral = \"GLAZING/CLEAR_6.DAT\" },\n  { gap_mm = 12 },\n]",
            "gap at the inner end",
            8,
        ),
        (
            "layers = [\n  { spectral = \"GLAZING/CLEAR_6.DAT\" },\n  { gap_mm = 12 },\n  { gap_mm = 6 },\n  { spectral = \"GLAZING/CLEAR_6.DAT\" },\n]",
            "two gaps in a row",
            9,
        ),
        (
            "layers = [\n  { spectral = \"GLAZING/CLEAR_6.DAT\" },\n  { gap_mm = 12, flip = true },\n  { spectral = \"GLAZING/CLEAR_6.DAT\" },\n]",
            "a flip on a gap",
            8,
        ),
        (
            "layers = [\n  { spectral = \"GLAZING/CLEAR_6.DAT\" },\n  { gap_mm = -12 },\n  { spectral = \"GLAZING/CLEAR_6.DAT\" },\n]",
            "`gap_mm` = -12 is not a positive",
            8,
        ),
        (
            "layers = [\n  { spectral = \"GLAZING/CLEAR_6.DAT\", thickness_mm = nan },\n  { gap_mm = 12 },\n  { spectral = \"GLAZING/CLEAR_6.DAT\" },\n]",
            "`thickness_mm` = NaN is not a positive",
            7,
        ),
        (
            "layers = [\n  { r0 = [0.9, 0.9, 0.9], t0 = [0.0, 0.0, 0.0], thickness_mm = 4 },\n  { gap_mm = 12 },\n  { spectral = \"GLAZING/CLEAR_6.DAT\" },\n]",
            "is opaque but layer 3 lies behind it",
            7,
        ),
        (
            "layers = [\n  { spectral = \"GLAZING/CLEAR_6.DAT\" },\n  { gap_mm = 12 },\n  { spectral = \"FAR\" },\n]",
            "does not overlap",
            9,
        ),
    ];
    let far = write_file(
        dir.path(),
        "far.csv",
        b"wavelength_nm,T,R,Rb\n3000,0.5,0.1,0.1\n3100,0.5,0.1,0.1\n3200,0.5,0.1,0.1\n3300,0.5,0.1,0.1\n",
    );
    for (layers, want, line) in cases {
        let body = format!(
            "# unit\n\n[[glass]]\nid = 12\nname = \"bad unit\"\n{}\n",
            layers.replace("FAR", &far.display().to_string())
        );
        let catalog = catalog_with(dir.path(), &body);
        let out = dir.path().join("reg.json");
        let err = fails_naming(&mut registry_build(&catalog, &out, &[]), &[want]);
        assert!(
            err.contains(&format!("catalog.toml:{line}:")),
            "line {line}: {err}"
        );
        assert!(!out.exists());
    }
}

/// `glassdb plot stack` draws the unit beside its layers.
#[test]
fn plot_stack_draws_the_unit_and_its_layers() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("unit.png");
    ok(glassdb()
        .args(["plot", "stack"])
        .arg(glazing("igsdb_product_10693.json"))
        .arg(glazing("CLEAR_6.DAT"))
        .args(["--gap", "12.7:argon", "-o"])
        .arg(&out));
    let s = glassdb_plot::inspect::summarize_png(&out).expect("a PNG");
    // three panels side by side: the unit and its two layers, with curves drawn
    assert_eq!((s.width, s.height), (1800, 542), "{s:?}");
    assert!(s.inked_fraction > 0.05 && s.distinct_colours > 20, "{s:?}");
}

/// docs/stack.md's "Six real units" tables are what scripts/stack_table.py writes.
#[test]
fn docs_table_is_current() {
    let mut cmd = std::process::Command::new(crate::util::oracle_python());
    cmd.arg(repo_path("scripts/stack_table.py")).args([
        "--check",
        "--glassdb",
        env!("CARGO_BIN_EXE_glassdb"),
    ]);
    ok(&mut cmd);
}

/// Layers given by a measured angle table alone (grey), by a spectrum with an angle table, and
/// by explicit r0/t0 values: the unit follows the tables' angle dependence and the explicit
/// layer makes it combine per channel.
#[test]
fn units_of_angle_table_and_explicit_layers() {
    let dir = tempfile::tempdir().unwrap();
    let table = repo_path("data/angles/clear_6mm_fresnel.csv");
    let body = format!(
        r#"
[[glass]]
id = 1
name = "two measured panes"
layers = [
    {{ angles = "{t}", thickness_mm = 6 }},
    {{ gap_mm = 16, gas = "krypton" }},
    {{ angles = "{t}", thickness_mm = 6 }},
]

[[glass]]
id = 2
name = "clear with its measured table | explicit grey"
layers = [
    {{ spectral = "GLAZING/CLEAR_6.DAT", angles = "{t}" }},
    {{ gap_mm = 12 }},
    {{ r0 = [0.08, 0.08, 0.08], t0 = [0.5, 0.5, 0.5], thickness_mm = 4 }},
]
"#,
        t = table.display()
    );
    let (_, reg) = registry_with(dir.path(), &body, &[]);
    let table_rows: Vec<(f64, f64, f64)> = std::fs::read_to_string(&table)
        .unwrap()
        .lines()
        .filter(|l| l.chars().next().is_some_and(|c| c.is_ascii_digit()))
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (v[0], v[1], v[2])
        })
        .collect();
    let g = glass(&reg["tables"][0], 1);
    assert_eq!(g["unit"]["elements"][0]["model"], "measured");
    assert_eq!(g["unit"]["elements"][1]["gas"], "krypton");
    // the two-flux unit of two table panes, by hand from the table: T²/(1 − R²), R + T²R/(1 − R²)
    for &(deg, r, t) in table_rows.iter().filter(|(a, ..)| *a <= 80.0) {
        let cos = deg.to_radians().cos();
        let (t_unit, r_unit) = (t * t / (1.0 - r * r), r + t * t * r / (1.0 - r * r));
        for ch in 0..3 {
            let tt = g["t0"][ch].as_f64().unwrap() * curve_at(&g["c_t"][ch], cos);
            let rr = g["r0"][ch].as_f64().unwrap() * curve_at(&g["c_r"][ch], cos);
            assert!(
                (tt - t_unit).abs() < 0.006 && (rr - r_unit).abs() < 0.006,
                "{deg}°: T {tt} vs {t_unit}, R {rr} vs {r_unit}"
            );
        }
    }
    let mixed = glass(&reg["tables"][0], 2);
    assert_eq!(mixed["unit"]["combined"], "per-band");
    assert!(
        mixed["unit"].get("photopic").is_none(),
        "no photopic value without spectra"
    );
    assert_eq!(mixed["unit"]["elements"][0]["model"], "measured");
    // normal incidence: the explicit layer behind clear 6 mm, per channel
    let clear_t = mixed["unit"]["elements"][0]["t0"][1].as_f64().unwrap();
    let clear_rb = mixed["unit"]["elements"][0]["r0_back"][1].as_f64().unwrap();
    let want = clear_t * 0.5 / (1.0 - clear_rb * 0.08);
    assert!((mixed["t0"][1].as_f64().unwrap() - want).abs() < 1e-12);
}

/// A registry curve object (`powers`, `coefficients`) at `cos`: Σ k·cosᵖ, read from the JSON.
fn curve_at(c: &Value, cos: f64) -> f64 {
    let p = c["powers"].as_array().unwrap();
    let k = c["coefficients"].as_array().unwrap();
    p.iter()
        .zip(k)
        .map(|(p, k)| k.as_f64().unwrap() * cos.powi(p.as_u64().unwrap() as i32))
        .sum()
}

/// The readable table puts each value under its title: a right-aligned column's values end
/// where its title ends, a left-aligned column's start where its title starts.
#[test]
fn the_readable_table_puts_each_value_under_its_title() {
    let text = ok(glassdb().args([
        "stack",
        &format!("{}:flip", glazing("LOW-E_5.LOF")),
        &glazing("CLEAR_6.DAT"),
        "--gap",
        "12.7:argon",
        "--angles",
        "0,40,80",
    ]));
    let lines: Vec<Vec<char>> = text.lines().map(|l| l.chars().collect()).collect();
    let header_at = lines
        .iter()
        .position(|l| {
            l.iter()
                .collect::<String>()
                .trim_start()
                .starts_with("θ(°)")
        })
        .unwrap_or_else(|| panic!("no table header in:\n{text}"));
    let header: String = lines[header_at].iter().collect();
    let rows = &lines[header_at + 1..];
    assert_eq!(rows.len(), 3, "{text}");
    let right = [
        "θ(°)", "Tv", "Rv out", "Rv in", "Tsol", "Rsol out", "Rsol in",
    ];
    let left = ["T rgb", "R out rgb", "R in rgb"];
    let mut from = 0;
    for (k, title) in right.iter().chain(&left).enumerate() {
        let byte = from
            + header[from..]
                .find(title)
                .unwrap_or_else(|| panic!("{title}"));
        from = byte + title.len();
        let start = header[..byte].chars().count();
        let end = start + title.chars().count() - 1;
        for row in rows {
            let row_text: String = row.iter().collect();
            let at = |i: usize| row.get(i).copied().unwrap_or(' ');
            let under = if k < right.len() {
                at(end) != ' ' && at(end + 1) == ' '
            } else {
                at(start) != ' ' && at(start - 1) == ' '
            };
            assert!(
                under,
                "`{title}` is not over its value:\n{header}\n{row_text}"
            );
        }
    }
}
