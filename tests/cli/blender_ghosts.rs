//! The double image in `glassdb blender render` (issue 27), end to end with Debian's Blender on
//! a tiny scene of scripts/blender/make_ghost_scene.py (128 × 96): a window of the bundled
//! double unit 11 with two emissive bars in front of it. The pane-group pass is the scene
//! mirrored about the inner pane's mid-plane (the bars' images where Blender's own projection
//! of their mirror images puts them); the composite with ghosts is closer to Cycles rendering
//! the same window as two real panes than one pass per plane (`--surfaces 1`) is;
//! `glassdb mask --bounds` gives the group's rectangle the run cropped to.

use std::path::{Path, PathBuf};

use crate::blender::background_blender;
use crate::util::{Planes, compose_frame, glassdb, mask_from, ok, read_exr_planes, repo_path};

/// `make_ghost_scene.py --panes PANES` saved in `dir`, with its facts.
pub(crate) fn ghost_scene(dir: &Path, panes: &str) -> (PathBuf, serde_json::Value) {
    let blend = dir.join(format!("{panes}.blend"));
    let facts = dir.join(format!("{panes}.json"));
    ok(
        background_blender(&["--factory-startup".as_ref(), "-noaudio".as_ref()])
            .arg("-P")
            .arg(repo_path("scripts/blender/make_ghost_scene.py"))
            .args(["--", "--panes", panes, "--size", "128x96", "--out"])
            .arg(&blend)
            .arg("--facts")
            .arg(&facts),
    );
    let facts = serde_json::from_str(&std::fs::read_to_string(&facts).unwrap()).unwrap();
    (blend, facts)
}

/// `glassdb blender render BLEND --glass GLASS --out-dir OUT` (seed 0, 2 threads) with `extra`;
/// its stdout.
pub(crate) fn render(blend: &Path, glass: &str, out: &Path, extra: &[&str]) -> String {
    ok(glassdb()
        .args(["blender", "render"])
        .arg(blend)
        .args(["--glass", glass, "--out-dir"])
        .arg(out)
        .args(["--threads", "2", "--seed", "0"])
        .args(extra))
}

/// The `unit` scene built in `d` and rendered with the bundled double unit 11 into `d/run`
/// with `extra`: the scene's facts, the run folder and the render's stdout.
fn render_unit_11(d: &Path, extra: &[&str]) -> (serde_json::Value, PathBuf, String) {
    let (unit, facts) = ghost_scene(d, "unit");
    let run = d.join("run");
    let stdout = render(&unit, "Unit=11", &run, extra);
    (facts, run, stdout)
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Channel `name` of the beauty: bare, or of `ViewLayer.Combined` in a pass split by the
/// light's path (docs/blender.md, "Light parts").
pub(crate) fn channel<'a>(p: &'a Planes, name: &str) -> &'a [f64] {
    let split = format!("ViewLayer.Combined.{name}");
    let k = p
        .names
        .iter()
        .position(|n| n == name)
        .or_else(|| p.names.iter().position(|n| *n == split))
        .unwrap_or_else(|| panic!("no channel {name} or {split} in {:?}", p.names));
    &p.channels[k]
}

/// R + G + B of a frame-sized image at pixel `i`.
fn luminance(p: &Planes, i: usize) -> f64 {
    ["R", "G", "B"].iter().map(|c| channel(p, c)[i]).sum()
}

/// The centroid column (frame pixels, centres at x + 0.5) of the bright part of a cropped pass
/// whose data window starts at frame column `x0`, over the frame columns `cols` of the rows
/// `rows` (frame rows; the pass starts at frame row `y0`), above the median of those rows.
fn centroid_x(
    pass: &Planes,
    (x0, y0): (usize, usize),
    cols: std::ops::Range<usize>,
    rows: std::ops::Range<usize>,
) -> f64 {
    let mut profile: Vec<f64> = cols
        .clone()
        .map(|x| {
            rows.clone()
                .map(|y| luminance(pass, (y - y0) * pass.width + (x - x0)))
                .sum()
        })
        .collect();
    let mut sorted = profile.clone();
    sorted.sort_by(f64::total_cmp);
    let floor = sorted[sorted.len() / 2];
    for v in &mut profile {
        *v = (*v - floor).max(0.0);
    }
    let total: f64 = profile.iter().sum();
    assert!(total > 0.0, "nothing bright in columns {cols:?}");
    cols.zip(&profile)
        .map(|(x, v)| (x as f64 + 0.5) * v)
        .sum::<f64>()
        / total
}

/// Mean square error over the pixels where `keep`, all three channels.
fn mse(a: &Planes, b: &Planes, keep: &[bool]) -> f64 {
    let (mut sum, mut n) = (0.0, 0);
    for c in ["R", "G", "B"] {
        let (a, b) = (channel(a, c), channel(b, c));
        for i in (0..keep.len()).filter(|&i| keep[i]) {
            sum += (a[i] - b[i]).powi(2);
            n += 1;
        }
    }
    sum / n as f64
}

/// Glass pixels of the mask fully covered and with all 8 neighbours glass too (the panes of
/// the two-pane reference lie a few millimetres behind the unit's face).
fn glass_interior(mask: &Planes) -> Vec<bool> {
    let (w, h) = (mask.width, mask.height);
    let id = channel(mask, "id");
    let glass = |x: usize, y: usize| id[y * w + x] > 0.0;
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            x > 0
                && y > 0
                && x + 1 < w
                && y + 1 < h
                && (y - 1..=y + 1).all(|yy| (x - 1..=x + 1).all(|xx| glass(xx, yy)))
        })
        .collect()
}

#[test]
fn a_double_unit_renders_each_panes_reflection_at_its_depth() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (facts, run, stdout) = render_unit_11(d, &["--samples", "16"]);
    assert!(
        stdout.contains("pane groups: 1 reflection pass(es) of units' deeper panes"),
        "{stdout}"
    );
    // The record: the inner pane's pass, at the registry's depth of unit 11's inner pane.
    let record = json(&run.join("glassdb-blender.json"));
    let frame = &record["frames"][0];
    let group = &frame["groups"][0];
    assert_eq!(
        (&group["plane"], &group["group"], &group["file"]),
        (&0.into(), &1.into(), &"refl_0_1.0001.exr".into()),
        "{record}"
    );
    let depth_mm = facts["depths_mm"][1].as_f64().unwrap();
    assert!((group["depth_m"].as_f64().unwrap() * 1e3 - depth_mm).abs() < 1e-6);

    // Each bar's image in the outer and the inner pane's pass, against Blender's projection of
    // the bar mirrored about each pane's mid-plane.
    let origin = |b: &serde_json::Value| {
        (
            b["x"].as_u64().unwrap() as usize,
            b["y"].as_u64().unwrap() as usize,
        )
    };
    let passes = [
        (
            read_exr_planes(&run.join("refl_0.0001.exr")),
            origin(&frame["bounds"][0]),
        ),
        (
            read_exr_planes(&run.join("refl_0_1.0001.exr")),
            origin(&group["bounds"]),
        ),
    ];
    let (w, h) = (128.0, 96.0);
    let images = &facts["mirror_images_uv"];
    let key = |depth: f64| format!("{depth:.4}");
    let depths = [facts["depths_mm"][0].as_f64().unwrap(), depth_mm];
    let rows = 44..52;
    for bar in ["Bar_warm", "Bar_cool"] {
        let predicted: Vec<f64> = depths
            .iter()
            .map(|&dm| images[key(dm)][bar][0].as_f64().unwrap() * w)
            .collect();
        let v = images[key(depths[0])][bar][1].as_f64().unwrap();
        assert!(((1.0 - v) * h - 48.0).abs() < 1.0, "{bar}: v {v}");
        let lo = predicted[1].floor() as usize - 6;
        let hi = predicted[0].ceil() as usize + 6;
        let measured: Vec<f64> = passes
            .iter()
            .map(|(p, o)| centroid_x(p, *o, lo..hi, rows.clone()))
            .collect();
        let (offset, predicted_offset) = (measured[0] - measured[1], predicted[0] - predicted[1]);
        eprintln!(
            "{bar}: images at {measured:.2?} px, predicted {predicted:.2?}; ghost offset {offset:.2} px, predicted {predicted_offset:.2}"
        );
        assert!(
            predicted_offset > 2.0,
            "the scene shows a ghost: {predicted_offset}"
        );
        for (m, p) in measured.iter().zip(&predicted) {
            assert!((m - p).abs() < 0.5, "{bar}: image at {m}, predicted {p}");
        }
        assert!((offset - predicted_offset).abs() < 0.5, "{bar}: {offset}");
    }

    // Against Cycles with two real panes (clear 6 mm at the unit's pane depths): the composite
    // with ghosts beats one pass per plane by far.
    let (two, _) = ghost_scene(d, "two");
    let reference = d.join("reference");
    render(
        &two,
        "Pane=2",
        &reference,
        &["--samples", "128", "--reference", "--no-composite"],
    );
    let one_pass = d.join("surfaces1.exr");
    ok(compose_frame(
        &[run.join("refl_0.0001.exr")],
        &run.join("trans.0001.exr"),
        &run.join("mask.0001.exr"),
        &one_pass,
    )
    .args(["--surfaces", "1"]));
    let keep = glass_interior(&read_exr_planes(&run.join("mask.0001.exr")));
    assert!(keep.iter().filter(|&&k| k).count() > 5000);
    let want = read_exr_planes(&reference.join("reference.0001.exr"));
    let ghosts = mse(
        &read_exr_planes(&run.join("composite.0001.exr")),
        &want,
        &keep,
    );
    let single = mse(&read_exr_planes(&one_pass), &want, &keep);
    eprintln!("in-glass MSE against two real panes: ghosts {ghosts:.5}, --surfaces 1 {single:.5}");
    assert!(ghosts < 0.25 * single, "ghosts {ghosts}, one pass {single}");

    // `glassdb blender compose` reads the group pass back from the record: the same frame.
    let first = read_exr_planes(&run.join("composite.0001.exr"));
    ok(glassdb().args(["blender", "compose"]).arg(&run));
    assert_eq!(
        first.channels,
        read_exr_planes(&run.join("composite.0001.exr")).channels
    );

    // `glassdb mask --bounds`: the group's rectangle, the one the run cropped its pass to.
    ok(mask_from(run.join("scene.obj"), run.join("camera.json"))
        .args(["--glass", "Unit=11", "--frames", "1", "--samples", "4"])
        .arg("--planes")
        .arg(run.join("planes.json"))
        .arg("-o")
        .arg(d.join("mask.####.exr"))
        .arg("--bounds")
        .arg(d.join("bounds.####.json")));
    let b = json(&d.join("bounds.0001.json"));
    let g = &b["planes"][0]["groups"][0];
    assert_eq!(g["group"], 1, "{b}");
    let rect = &group["bounds"];
    let x = |k: &str| rect[k].as_i64().unwrap();
    assert_eq!(
        g["data_window"],
        serde_json::json!([
            x("x"),
            x("y"),
            x("x") + x("width") - 1,
            x("y") + x("height") - 1
        ]),
        "{b}"
    );
}

#[test]
fn surfaces_1_renders_one_pass_per_plane_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (_, run, stdout) = render_unit_11(
        d,
        &["--samples", "2", "--resolution", "48x36", "--surfaces", "1"],
    );
    assert!(
        stdout.contains("--surfaces 1: a unit's panes beyond"),
        "{stdout}"
    );
    assert!(stdout.contains("no double image"), "{stdout}");
    assert!(!run.join("refl_0_1.0001.exr").exists());
    let record = json(&run.join("glassdb-blender.json"));
    assert_eq!(record["surfaces"], 1, "{record}");
    assert!(record["frames"][0].get("groups").is_none(), "{record}");
    // Recompositing keeps the run's one pass per plane.
    let again = ok(glassdb().args(["blender", "compose"]).arg(&run));
    assert!(again.contains("composited 1 frame(s)"), "{again}");
}
