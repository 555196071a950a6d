//! Values that must not pass unchecked, and the command line's behaviour on a closed pipe:
//! registry tolerances above the cap, fit files with unphysical normal values, spectra whose
//! integrated values create light (refused by `glassdb spectral` with the registry build's own
//! message), the wrong kind of file for `glassdb eval`, and `… | head`.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};

use crate::util::{
    assert_names, compose, fails, fails_naming, glassdb, ok, registry_build, repo_path, write_file,
};

/// A curve C = 1 with the given recorded tolerance.
fn constant_curve(tolerance: f64) -> serde_json::Value {
    serde_json::json!({
        "basis": "full", "powers": [0], "coefficients": [1.0], "degree": 0, "rms_error": 0.0,
        "max_abs_error": 0.0, "max_error_angle_deg": 0.0, "condition_number": 1.0,
        "tolerance": tolerance
    })
}

/// A one-glass registry with r = 0.1 and t = 0.95 at every angle (r + t = 1.05), whose
/// transmittance curves record `tolerance`.
fn leaky_registry(tolerance: f64) -> String {
    let c = constant_curve(0.002);
    let t = constant_curve(tolerance);
    serde_json::json!({
        "schema": 3,
        "tables": [{
            "spectral": {"method": "colorimetric"},
            "glasses": [{
                "id": 3, "name": "leaky", "r0": [0.1, 0.1, 0.1], "t0": [0.95, 0.95, 0.95],
                "r0_back": [0.1, 0.1, 0.1], "c_r": [c, c, c], "c_t": [t, t, t],
                "c_r_back": [c, c, c],
                "angle_model": {"kind": "measured", "applied": "per-channel"},
                "provenance": {}
            }]
        }]
    })
    .to_string()
}

#[test]
fn a_registry_cannot_widen_its_own_validation_tolerance() {
    let dir = tempfile::tempdir().unwrap();
    // Tolerance 10 would let r + t = 1.05 pass: refused, naming file, glass and curve.
    let reg = write_file(dir.path(), "wide.json", leaky_registry(10.0).as_bytes());
    let names = [
        "wide.json",
        "id 3 (\"leaky\")",
        "c_t[0] (R)",
        "tolerance 10",
        "above the largest validation tolerance 0.01",
    ];
    let err = fails_naming(glassdb().args(["registry", "check"]).arg(&reg), &names);
    assert!(err.contains("rebuild it from its catalog"), "{err}");
    fails_naming(glassdb().args(["registry", "show"]).arg(&reg), &names);
    let example = repo_path("fixtures/example");
    let mut c = compose();
    c.arg("--registry").arg(&reg);
    for (flag, file) in [
        ("--refl", "refl.exr"),
        ("--trans", "trans.exr"),
        ("--mask", "mask.png"),
    ] {
        c.arg(flag).arg(example.join(file));
    }
    fails_naming(c.arg("-o").arg(dir.path().join("o.exr")), &names);
    // At the cap the tolerance is accepted, and the energy check refuses the curves themselves.
    let reg = write_file(dir.path(), "cap.json", leaky_registry(0.01).as_bytes());
    let err = fails(glassdb().args(["registry", "check"]).arg(&reg));
    assert_names(&err, &["cap.json", "r + t", "energy is not conserved"]);
    // The builder refuses a fit tolerance above the cap.
    let catalog = write_file(
        dir.path(),
        "catalog.toml",
        b"[[glass]]\nid = 1\nname = \"g\"\nr0 = [0.1, 0.1, 0.1]\nt0 = [0.8, 0.8, 0.8]\n",
    );
    let out = dir.path().join("r.json");
    fails_naming(
        &mut registry_build(&catalog, &out, &["--tol", "0.5"]),
        &["fit tolerance 0.5", "--tol"],
    );
    assert!(!out.exists());
}

/// A fit file with one glass: reflectance `r_normal`·1 and transmittance 0.8·(1.5 cos θ −
/// 0.5 cos² θ), the reflectance curve claiming `max_abs_error`.
fn fit_file(r_normal: &str, max_abs_error: f64) -> String {
    format!(
        r#"{{"glasses": [{{"name": "g",
  "reflectance": {{"normal": {r_normal}, "basis": "full", "powers": [0], "coefficients": [1.0],
    "degree": 0, "rms_error": 0, "max_abs_error": {max_abs_error}, "max_error_angle_deg": 0,
    "condition_number": 1}},
  "transmittance": {{"normal": 0.8, "basis": "paper", "powers": [1, 2], "coefficients": [1.5, -0.5],
    "degree": 2, "rms_error": 0, "max_abs_error": 0, "max_error_angle_deg": 0,
    "condition_number": 1}}}}]}}"#
    )
}

#[test]
fn eval_refuses_unphysical_fit_files() {
    let dir = tempfile::tempdir().unwrap();
    let good = write_file(dir.path(), "good.json", fit_file("0.1", 0.0).as_bytes());
    let out = ok(glassdb().arg("eval").arg(&good).args(["--angles", "0"]));
    assert!(
        out.contains("0.100000") && out.contains("0.800000"),
        "{out}"
    );
    for (name, normal, shown) in [("two.json", "2", "2.0"), ("huge.json", "1e308", "1e308")] {
        let p = write_file(dir.path(), name, fit_file(normal, 0.0).as_bytes());
        let outside = format!("the normal value {shown} is outside [0, 1]");
        let parts = [name, "glass `g`, reflectance", &outside];
        let mut eval = glassdb();
        let (res, stdout, _) = crate::util::run(eval.arg("eval").arg(&p));
        assert!(!res.status.success() && stdout.is_empty(), "{stdout}");
        fails_naming(glassdb().arg("eval").arg(&p), &parts);
    }
    // r + t = 0.3 + 0.8 at 0°: over 1 by more than the tolerances, however large the file
    // says its fit error is (capped at 0.01).
    let p = write_file(dir.path(), "sum.json", fit_file("0.3", 10.0).as_bytes());
    let parts = [
        "sum.json",
        "glass `g`",
        "r + t > 1",
        "worst at 0°",
        "1.20e-2",
    ];
    fails_naming(glassdb().arg("eval").arg(&p), &parts);
    // A recorded data range outside 0–90° (or inverted) does not take the check away.
    for (name, lo, hi) in [("away.json", 100, 120), ("inverted.json", 80, 10)] {
        let range =
            format!(r#""condition_number": 1, "angle_min_deg": {lo}, "angle_max_deg": {hi}"#);
        let text = fit_file("0.3", 0.0).replace(r#""condition_number": 1"#, &range);
        let p = write_file(dir.path(), name, text.as_bytes());
        fails_naming(
            glassdb().arg("eval").arg(&p),
            &[name, "glass `g`", "r + t > 1"],
        );
    }
}

#[test]
fn eval_on_a_registry_says_what_the_file_is_and_what_reads_it() {
    let reg = repo_path("data/registry.json");
    let parts = [
        "data/registry.json is a glassdb glass registry, not a fit file",
        "hint: a registry is read by `glassdb registry show`",
    ];
    fails_naming(glassdb().arg("eval").arg(&reg), &parts);
}

/// `T` 0.3 below 450 nm and 0.85 from 600 nm, nothing in between, R = Rb = 0.08: every sample
/// conserves energy, but the spline across the 150 nm gap does not.
fn gap_csv() -> String {
    let mut csv = String::from("wavelength_nm,T,R,Rb\n");
    for wl in (300..=2500).step_by(10).filter(|w| !(460..600).contains(w)) {
        let t = if wl >= 600 { 0.85 } else { 0.3 };
        csv.push_str(&format!("{wl},{t},0.08,0.08\n"));
    }
    csv
}

/// The part of an error after its file name: the message the library gave.
fn message_after<'a>(stderr: &'a str, marker: &str) -> &'a str {
    let start = stderr
        .find(marker)
        .unwrap_or_else(|| panic!("{marker}: {stderr}"));
    stderr[start..].lines().next().unwrap_or_default()
}

#[test]
fn spectral_refuses_a_gapped_spectrum_with_the_registry_builds_message() {
    let dir = tempfile::tempdir().unwrap();
    let csv = write_file(dir.path(), "gap.csv", gap_csv().as_bytes());
    let spectral = fails(glassdb().arg("spectral").arg(&csv));
    let message = message_after(&spectral, "channel R: integrated transmittance");
    assert_names(message, &["energy is not conserved", "150 nm, 450–600 nm"]);
    let catalog = write_file(
        dir.path(),
        "catalog.toml",
        b"[[glass]]\nid = 1\nname = \"gap\"\nspectral = \"gap.csv\"\n",
    );
    let out = dir.path().join("r.json");
    let mut build = registry_build(&catalog, &out, &[]);
    let registry = fails(&mut build);
    assert!(registry.contains(message), "{message}\n{registry}");
    assert!(!out.exists());
    // T + R > 1 at one wavelength (the catalog's file rewritten): the same message from both.
    let bright: String = (300..=800)
        .step_by(10)
        .map(|wl| format!("{wl},0.85,{}\n", if wl == 550 { 0.3 } else { 0.08 }))
        .collect();
    let path = write_file(
        dir.path(),
        "gap.csv",
        format!("wavelength_nm,T,R\n{bright}").as_bytes(),
    );
    let spectral = fails(glassdb().arg("spectral").arg(&path));
    let message = message_after(&spectral, "at 550 nm");
    assert!(message.contains("more light out than in"), "{message}");
    assert!(fails(&mut build).contains(message), "{message}");
}

/// Runs `cmd` with its stdout a pipe whose reader goes away at once, before the command
/// writes anything; returns its exit status and stderr.
fn with_closed_stdout(cmd: &mut Command) -> (ExitStatus, String) {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("wait");
    (
        out.status,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn assert_quiet_exit(what: &str, (status, stderr): (ExitStatus, String)) {
    assert!(
        status.success() && stderr.is_empty(),
        "{what}: {status:?}, stderr:\n{stderr}"
    );
}

#[test]
fn a_closed_pipe_ends_every_binary_quietly() {
    let registry = repo_path("data/registry.json");
    let mut show = glassdb();
    show.args(["registry", "show"]).arg(&registry);
    assert_quiet_exit("registry show", with_closed_stdout(&mut show));
    // `head -1`: the reader takes one line of a long output (far more than a pipe buffers)
    // and goes away while the command is still writing.
    let dir = tempfile::tempdir().unwrap();
    let fits = write_file(dir.path(), "f.json", fit_file("0.1", 0.0).as_bytes());
    let mut child = glassdb()
        .arg("eval")
        .arg(&fits)
        .args(["--angles", "0:90:0.001"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    let stdout = child.stdout.take().unwrap();
    BufReader::new(stdout).read_line(&mut first).unwrap();
    assert_eq!(first, "glass g\n");
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_quiet_exit("eval | head -1", (out.status, stderr));
    // The compose binary: the output is written, then the report meets the closed pipe.
    let example = repo_path("fixtures/example");
    let output = dir.path().join("o.png");
    let mut c = compose();
    for (flag, file) in [
        ("--refl", "refl.exr"),
        ("--trans", "trans.exr"),
        ("--mask", "mask.png"),
    ] {
        c.arg(flag).arg(example.join(file));
    }
    c.arg("-o").arg(&output).arg("--stats");
    assert_quiet_exit("compose", with_closed_stdout(&mut c));
    assert!(Path::new(&output).exists());
}
