//! Colour spaces end to end: registry tables per space against colour-science, compose picking
//! the table of its passes' space from their headers (a real Blender 5 render whose working
//! space is ACEScg), refusals, output tags, and the standard view's conversion to sRGB.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

use crate::util::{
    atrium_compose, atrium_refl, compose, fails, glassdb, json_rgb, ok, oracle_python,
    read_exr_planes, repo_path, run_oracle, write_file,
};

const ALL_SPACES: [&str; 6] = [
    "srgb",
    "rec2020",
    "acescg",
    "aces2065-1",
    "display-p3",
    "xyz",
];

/// The Blender 5.0.1 render whose working space is ACEScg, and its Rec.709 twin.
fn acescg(file: &str) -> PathBuf {
    repo_path("fixtures/blender/masks/b50_acescg").join(file)
}
fn rec709(file: &str) -> PathBuf {
    repo_path("fixtures/blender/masks/b50").join(file)
}

#[test]
fn registry_tables_in_every_space_match_colour_science() {
    // A real tinted glass (AGC green 4.8 mm, IGSDB 185), one table per space.
    let dir = tempfile::tempdir().unwrap();
    let spectrum = repo_path("data/glazing/913.json");
    let catalog = write_file(
        dir.path(),
        "catalog.toml",
        format!(
            "[[glass]]\nid = 5\nname = \"green\"\nspectral = \"{}\"\nmodel = \"uncoated\"\n",
            spectrum.display()
        )
        .as_bytes(),
    );
    let out = dir.path().join("reg.json");
    ok(glassdb()
        .args(["registry", "build"])
        .arg(&catalog)
        .args(["--space", &ALL_SPACES.join(","), "-o"])
        .arg(&out));
    let reg: Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    let oracle: Value =
        serde_json::from_str(&run_oracle("spectral_oracle.py", &[spectrum.as_os_str()])).unwrap();
    let expected = &oracle[spectrum.to_str().unwrap()];
    let tables = reg["tables"].as_array().unwrap();
    assert_eq!(tables.len(), ALL_SPACES.len());
    for (table, space) in tables.iter().zip(ALL_SPACES) {
        assert_eq!(table["spectral"]["space"], space);
        let g = &table["glasses"][0];
        for (key, quantity) in [
            ("t0", "transmittance"),
            ("r0", "reflectance"),
            ("r0_back", "reflectance_back"),
        ] {
            let want = json_rgb(&expected[quantity]["colorimetric"]["cie1931"]["D65"][space]);
            let got = json_rgb(&g[key]);
            for c in 0..3 {
                assert!(
                    (got[c] - want[c]).abs() <= 1e-9,
                    "{space} {key}[{c}]: {} vs colour-science {}",
                    got[c],
                    want[c]
                );
            }
        }
    }
    // docs/colour.md's table (scripts/colour_table.py) is what this build gives, to its 6 digits.
    let docs = std::fs::read_to_string(repo_path("docs/colour.md")).unwrap();
    for (table, space) in tables.iter().zip(ALL_SPACES) {
        for key in ["t0", "r0"] {
            let v = json_rgb(&table["glasses"][0][key]);
            let cells = format!(
                "(`{space}`) | {key} | {:.6}, {:.6}, {:.6} |",
                v[0], v[1], v[2]
            );
            assert!(
                docs.contains(&cells),
                "docs/colour.md lacks {cells}: rerun scripts/colour_table.py"
            );
        }
    }
    // The spaces differ by more than the tolerance: the test would see a wrong table.
    let t0 = |k: usize| json_rgb(&tables[k]["glasses"][0]["t0"]);
    assert!(
        (t0(0)[0] - t0(2)[0]).abs() > 0.03,
        "{:?} {:?}",
        t0(0),
        t0(2)
    );

    let show = ok(glassdb()
        .args(["registry", "show"])
        .arg(&out)
        .args(["--space", "acescg"]));
    assert!(
        show.contains("6 tables: srgb (default), rec2020, acescg")
            && show.contains("showing the acescg table"),
        "{show}"
    );
    let t = t0(2);
    assert!(
        show.contains(&format!("t0 {:.4} {:.4} {:.4}", t[0], t[1], t[2])),
        "{show}"
    );
    let err = fails(
        glassdb()
            .args(["registry", "show"])
            .arg(&out)
            .args(["--space", "luminous"]),
    );
    assert!(
        err.contains("no table in luminous") && err.contains("aces2065-1"),
        "{err}"
    );
    let err = fails(
        glassdb()
            .args(["registry", "build"])
            .arg(&catalog)
            .args(["--space", "srgb,rec709", "-o"])
            .arg(dir.path().join("twice.json")),
    );
    assert!(err.contains("listed twice"), "{err}");
    let err = fails(
        glassdb()
            .args(["registry", "build"])
            .arg(&catalog)
            .args(["--method", "luminous", "--space", "acescg", "-o"])
            .arg(dir.path().join("lum.json")),
    );
    assert!(err.contains("--method colorimetric"), "{err}");
}

/// `python_oracle/exr_oracle.py COMMAND --NAME VALUE…` run by the oracle Python.
fn exr_oracle(command: &str, options: &[(&str, &Path)]) -> Command {
    let mut cmd = Command::new(oracle_python());
    cmd.arg(repo_path("python_oracle/exr_oracle.py"))
        .arg(command);
    for (name, value) in options {
        cmd.arg(format!("--{name}")).arg(value);
    }
    cmd
}

/// An 8-bit mask the size of `like` with glass `id` at normal incidence inside `rect`.
fn rect_mask(dir: &Path, like: &Path, rect: &str, id: u16) -> PathBuf {
    let out = dir.join(format!("mask_{id}.png"));
    let id = id.to_string();
    let options = [
        ("like", like),
        ("out", out.as_path()),
        ("rect", rect.as_ref()),
        ("id", id.as_ref()),
    ];
    ok(&mut exr_oracle("mask-png", &options));
    out
}

/// The bundled registry's r + t at normal incidence for `id` in `space` (read by the oracle
/// from data/registry.json's JSON, not by glassdb).
fn bundled_gain(id: u16, space: &str) -> String {
    let registry = repo_path("data/registry.json");
    let id = id.to_string();
    let options = [
        ("registry", registry.as_path()),
        ("id", id.as_ref()),
        ("space", space.as_ref()),
    ];
    ok(&mut exr_oracle("gain", &options)).trim().to_string()
}

/// Runs `exr_oracle.py check-composite`; whether it passed, and its stderr.
fn check_composite(input: &Path, output: &Path, mask: &Path, gain: &str) -> (bool, String) {
    let options = [
        ("input", input),
        ("output", output),
        ("mask", mask),
        ("gain", gain.as_ref()),
    ];
    let out = exr_oracle("check-composite", &options).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        matches!(out.status.code(), Some(0 | 1)),
        "oracle failed to run: {stderr}"
    );
    (out.status.success(), stderr)
}

fn header(path: &Path) -> Value {
    serde_json::from_str(&run_oracle(
        "exr_oracle.py",
        &[OsStr::new("header"), path.as_os_str()],
    ))
    .unwrap()
}

#[test]
fn an_acescg_blender_render_composites_with_the_acescg_table_without_a_flag() {
    let dir = tempfile::tempdir().unwrap();
    let trans = acescg("trans.0001.exr");
    let mask = rect_mask(dir.path(), &trans, "20,30,99,89", 5);
    // The pass as both transmission and reflection, through the rectangle mask.
    let run = |extra: &[&str], out: &Path| {
        ok(compose()
            .arg("--trans")
            .arg(&trans)
            .arg("--refl")
            .arg(&trans)
            .arg("--mask")
            .arg(&mask)
            .args(extra)
            .arg("--stats")
            .arg("-o")
            .arg(out))
    };
    // Float output, so that the PNG below can be checked against it without half rounding.
    let out = dir.path().join("out.exr");
    let stats = run(&["--data-type", "float"], &out);
    assert!(
        stats.contains(
            "colour       passes in ACEScg [acescg] (colorInteropID \"lin_ap1_scene\"); registry table acescg"
        ),
        "{stats}"
    );
    // Every glass pixel is the pass times the ACEScg table's r0 + t0 (checked by OpenEXR's own
    // reader); the Rec.709 table's numbers do not fit, so the check can tell them apart.
    let (passed, why) = check_composite(&trans, &out, &mask, &bundled_gain(5, "acescg"));
    assert!(passed, "{why}");
    let (passed, why) = check_composite(&trans, &out, &mask, &bundled_gain(5, "srgb"));
    assert!(!passed && why.contains("MISMATCH"), "{why}");
    // The output stays tagged: its colour part keeps lin_ap1_scene and gains AP1's
    // chromaticities.
    let h = header(&out);
    let part = &h["parts"][0];
    assert_eq!(part["attributes"]["colorInteropID"], "lin_ap1_scene", "{h}");
    let c = part["attributes"]["chromaticities"]
        .as_array()
        .unwrap()
        .clone();
    let c: Vec<f64> = c.iter().map(|v| v.as_f64().unwrap()).collect();
    let ap1 = [0.713, 0.293, 0.165, 0.830, 0.128, 0.044, 0.32168, 0.33767];
    assert!(
        c.iter().zip(ap1).all(|(a, b)| (a - b).abs() < 1e-6),
        "{c:?}"
    );

    // A PNG in the standard view is converted to sRGB's primaries first, as colour-science's
    // RGB_to_RGB does (CAT02), then encoded.
    let png = dir.path().join("out.png");
    let stats = run(&["--png-bits", "16"], &png);
    assert!(
        stats.contains("PNG converted from ACEScg [acescg] to linear Rec.709"),
        "{stats}"
    );
    let options = [
        ("exr", out.as_path()),
        ("png", png.as_path()),
        ("space", Path::new("acescg")),
    ];
    let summary = ok(&mut exr_oracle("check-display", &options));
    assert!(summary.contains("max_code_diff"), "{summary}");

    // --input-space overrides the tag: the Rec.709 table, and the output says so.
    let forced = dir.path().join("forced.exr");
    let stats = run(&["--input-space", "rec709"], &forced);
    assert!(
        stats.contains("(--input-space); registry table srgb"),
        "{stats}"
    );
    let (passed, why) = check_composite(&trans, &forced, &mask, &bundled_gain(5, "srgb"));
    assert!(passed, "{why}");
    assert_eq!(
        header(&forced)["parts"][0]["attributes"]["colorInteropID"],
        "lin_rec709_scene"
    );
}

#[test]
fn untagged_passes_are_rec709_and_say_so() {
    // The bundled atrium (Mitsuba's EXRs carry no colour tag).
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a.exr");
    let stats = ok(atrium_compose(&atrium_refl(), &out).arg("--stats"));
    assert!(
        stats.contains(
            "passes in linear Rec.709 [srgb] (no colour tag, taken as linear Rec.709); registry table srgb"
        ),
        "{stats}"
    );
    // An untagged output stays untagged (OpenEXR's default is Rec.709).
    let h = header(&out);
    assert!(
        h["parts"][0]["attributes"].get("chromaticities").is_none(),
        "{h}"
    );
}

#[test]
fn passes_in_different_spaces_or_without_a_table_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mask = rect_mask(dir.path(), &acescg("trans.0001.exr"), "20,30,99,89", 5);
    let run = |trans: &Path, refl: &Path, registry: Option<&Path>| {
        let mut c = compose();
        c.arg("--trans").arg(trans).arg("--refl").arg(refl);
        c.arg("--mask").arg(&mask);
        if let Some(r) = registry {
            c.arg("--registry").arg(r);
        }
        c.arg("-o").arg(dir.path().join("o.exr"));
        c
    };
    // An ACEScg transmission pass with a Rec.709 reflection pass.
    let err = fails(&mut run(
        &acescg("trans.0001.exr"),
        &rec709("refl_0.0001.exr"),
        None,
    ));
    for part in [
        "b50_acescg/trans.0001.exr",
        "ACEScg",
        "b50/refl_0.0001.exr",
        "linear Rec.709",
        "lin_rec709_scene",
        "--input-space",
    ] {
        assert!(err.contains(part), "{part}: {err}");
    }
    assert!(!dir.path().join("o.exr").exists());
    // A registry with the Rec.709 table only.
    let one = dir.path().join("srgb_only.json");
    ok(glassdb()
        .args(["registry", "build"])
        .arg(repo_path("data/catalog.toml"))
        .arg("-o")
        .arg(&one));
    let err = fails(&mut run(
        &acescg("trans.0001.exr"),
        &acescg("refl_0.0001.exr"),
        Some(&one),
    ));
    for part in [
        "srgb_only.json has no table in acescg",
        "it holds: srgb",
        "--space srgb,acescg",
    ] {
        assert!(err.contains(part), "{part}: {err}");
    }
}

/// Blender's own Rec.709 → ACEScg conversion, inverted (fixtures/blender/masks/README.md,
/// measured from bpy 5.0.1: Bradford through XYZ D65).
const ACESCG_TO_REC709: [[f64; 3]; 3] = [
    [1.70503980, -0.62178440, -0.08326162],
    [-0.13024911, 1.14080608, -0.01054557],
    [-0.02401274, -0.12896716, 1.15297862],
];

/// R, G, B planes of an EXR's first layer (channels ending in .R, .G, .B).
fn rgb_planes(path: &Path) -> [Vec<f64>; 3] {
    let p = read_exr_planes(path);
    ["R", "G", "B"].map(|c| {
        let k = p
            .names
            .iter()
            .position(|n| n == c || n.ends_with(&format!(".{c}")))
            .unwrap_or_else(|| panic!("{}: no {c} in {:?}", path.display(), p.names));
        p.channels[k].clone()
    })
}

fn psnr(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let n = a.len() as f64 * 3.0;
    let mse: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (0..3).map(|c| (x[c] - y[c]).powi(2)).sum::<f64>())
        .sum::<f64>()
        / n;
    10.0 * (1.0 / mse).log10()
}

#[test]
fn the_acescg_render_composited_with_its_table_matches_the_rec709_render() {
    // The README's Blender example on both renders of one scene (Rec.709 and ACEScg working
    // spaces), mask from each render's own Cryptomatte. The ACEScg composite, converted to
    // Rec.709, must match the Rec.709 composite on glass far better than the same passes
    // composited with the Rec.709 table (what glassdb did before it read the tag).
    let dir = tempfile::tempdir().unwrap();
    let composite = |d: &dyn Fn(&str) -> PathBuf, extra: &[&str], out: &str| {
        let out = dir.path().join(out);
        ok(compose()
            .arg("--trans")
            .arg(d("trans.0001.exr"))
            .args(["0", "1", "2"].iter().flat_map(|k| {
                [
                    "--refl".into(),
                    d(&format!("refl_{k}.0001.exr")).into_os_string(),
                ]
            }))
            .arg("--mask")
            .arg(d("beauty.0001.exr"))
            .args(["--mask-cryptomatte", "--mask-glass", "Glass_clear=1"])
            .args([
                "--mask-glass",
                "Tinted*=5",
                "--mask-channels",
                "cos=facing,plane=plane",
            ])
            .args(extra)
            .arg("-o")
            .arg(&out));
        out
    };
    let reference = composite(&rec709, &[], "rec709.exr");
    let right = composite(&acescg, &[], "acescg.exr");
    let wrong = composite(&acescg, &["--input-space", "srgb"], "wrong.exr");
    let to_rec709 = |p: &Path| -> Vec<[f64; 3]> {
        let [r, g, b] = rgb_planes(p);
        (0..r.len())
            .map(|i| {
                let v = [r[i], g[i], b[i]];
                ACESCG_TO_REC709.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
            })
            .collect()
    };
    let [r, g, b] = rgb_planes(&reference);
    let reference: Vec<[f64; 3]> = (0..r.len()).map(|i| [r[i], g[i], b[i]]).collect();
    let [tr, tg, tb] = rgb_planes(&rec709("trans.0001.exr"));
    // Glass: where the Rec.709 composite differs from its transmission pass.
    let glass: Vec<usize> = (0..reference.len())
        .filter(|&i| {
            let t = [tr[i], tg[i], tb[i]];
            (0..3).any(|c| (reference[i][c] - t[c]).abs() > 1e-4)
        })
        .collect();
    assert!(glass.len() > 1000, "{} glass pixels", glass.len());
    let on_glass = |v: &[[f64; 3]]| -> Vec<[f64; 3]> { glass.iter().map(|&i| v[i]).collect() };
    let reference_glass = on_glass(&reference);
    let right_db = psnr(&on_glass(&to_rec709(&right)), &reference_glass);
    let wrong_db = psnr(&on_glass(&to_rec709(&wrong)), &reference_glass);
    eprintln!(
        "glass pixels {}: ACEScg table {right_db:.1} dB, Rec.709 table {wrong_db:.1} dB",
        glass.len()
    );
    assert!(
        right_db > 40.0 && right_db > wrong_db + 6.0,
        "ACEScg table {right_db:.1} dB, Rec.709 table {wrong_db:.1} dB"
    );
}
