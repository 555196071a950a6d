//! Units' pane groups in compose (issue 27): a unit of the bundled catalog needs a reflection
//! pass per pane group unless `--surfaces 1`; each group's pass is weighted by its share, from
//! separate files or from the layers `planeK.groupG` of one EXR.

use std::path::{Path, PathBuf};

use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};

use crate::util::{compose, fails_naming, ok, read_exr_planes};

/// Writes a 2 × 1 float EXR of grey `v` (channels `prefix`R, G, B, one layer per entry).
fn write_layers(path: &Path, layers: &[(&str, f32)]) {
    use exr::prelude::*;
    let mut list: Vec<AnyChannel<FlatSamples>> = Vec::new();
    for (prefix, v) in layers {
        for c in ["R", "G", "B"] {
            list.push(AnyChannel::new(
                format!("{prefix}{c}").as_str(),
                FlatSamples::F32(vec![*v; 2]),
            ));
        }
    }
    let channels = AnyChannels::sort(list.into_iter().collect());
    let layer = Layer::new(
        (2, 1),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

fn grey(dir: &Path, name: &str, v: f32) -> PathBuf {
    let p = dir.join(name);
    write_layers(&p, &[("", v)]);
    p
}

/// Glass 11 (double clear 6 | 12.7 air | 6) at normal incidence on plane 0, and no glass.
fn unit_mask(dir: &Path) -> PathBuf {
    let p = dir.join("mask.png");
    let m = MaskImage {
        width: 2,
        height: 1,
        id: vec![11, 0],
        cos_theta: CosTheta::Quantized8(vec![255, 0]),
        plane: vec![0, 0],
        coverage: None,
    };
    write_mask(&p, &m, MaskFormat::Png8).unwrap();
    p
}

/// `compose` of plane pass `refl` over a transmission pass of 1 with the unit mask.
fn cmd(dir: &Path, refl: &Path, out: &Path, extra: &[&str]) -> std::process::Command {
    let mut c = compose();
    c.arg("--refl").arg(refl);
    c.arg("--trans").arg(grey(dir, "t.exr", 1.0));
    c.arg("--mask").arg(unit_mask(dir));
    c.arg("-o").arg(out);
    c.args(extra);
    c
}

/// The G sample of pixel 0 of an output.
fn glass_pixel(out: &Path) -> f64 {
    let p = read_exr_planes(out);
    let g = p.names.iter().position(|n| n == "G").unwrap();
    p.channels[g][0]
}

#[test]
fn a_unit_composites_each_pane_groups_pass_with_its_share() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (one, zero) = (grey(d, "refl_0.exr", 1.0), grey(d, "black.exr", 0.0));
    // Without its inner pane's pass: refused, naming the group and the way out.
    let err = fails_naming(
        &mut cmd(d, &one, &d.join("x.exr"), &[]),
        &[
            "glass 11",
            "pane group 1",
            "refl_0_1",
            "--refl-group 0.1=",
            "--surfaces 1",
        ],
    );
    assert!(!d.join("x.exr").exists(), "{err}");
    // One pass per plane: the unit's whole r on it, and the stats say so.
    let s1 = d.join("s1.exr");
    let stats = ok(&mut cmd(d, &one, &s1, &["--surfaces", "1", "--stats"]));
    assert!(
        stats.contains("1 pixels of units composited with their deeper"),
        "{stats}"
    );
    let t = d.join("t_only.exr");
    ok(&mut cmd(d, &zero, &t, &["--surfaces", "1"]));
    let r = glass_pixel(&s1) - glass_pixel(&t);
    // The inner pane's pass black: what is left is the outer pane's share; the inner pane
    // gives 44 % of a clear double unit's reflectance at 0° (docs/stack.md, WINDOW's algebra).
    let ghost_black = d.join("gb.exr");
    let group = format!("0.1={}", zero.display());
    ok(&mut cmd(d, &one, &ghost_black, &["--refl-group", &group]));
    let inner = (glass_pixel(&s1) - glass_pixel(&ghost_black)) / r;
    assert!((0.40..0.48).contains(&inner), "inner pane's share {inner}");
    // The same image in both groups: the one-pass composite.
    let same = d.join("same.exr");
    let group = format!("0.1={}", one.display());
    ok(&mut cmd(d, &one, &same, &["--refl-group", &group]));
    assert!((glass_pixel(&same) - glass_pixel(&s1)).abs() < 1e-6);
    // One EXR with layers plane0 and plane0.group1: as the two files.
    let multi = d.join("refl_multi.exr");
    write_layers(&multi, &[("plane0.", 1.0), ("plane0.group1.", 0.0)]);
    let from_layers = d.join("layers.exr");
    ok(&mut cmd(d, &multi, &from_layers, &[]));
    assert_eq!(glass_pixel(&from_layers), glass_pixel(&ghost_black));
    // Malformed and misplaced group passes.
    for (spec, names) in [
        ("0.0=x.exr", &["--refl-group", "GROUP 1 or more"][..]),
        ("zero=x.exr", &["--refl-group", "PLANE.GROUP=FILE"][..]),
    ] {
        fails_naming(
            &mut cmd(d, &one, &d.join("y.exr"), &["--refl-group", spec]),
            names,
        );
    }
    let group = format!("3.1={}", zero.display());
    fails_naming(
        &mut cmd(d, &one, &d.join("y.exr"), &["--refl-group", &group]),
        &["pane group 1 of plane 3", "only 1 plane pass"],
    );
}

