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

/// `compose --light-groups` reads each light group's own layer of the units' pane-group passes
/// (issue 29 with issue 27): the composite is the sum of each group composited from files that
/// hold its layers only, and the pane-group pass weighs in with each group's value.
#[test]
fn light_groups_read_each_groups_layer_of_the_pane_group_passes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let registry = d.join("lights.json");
    ok(&mut crate::util::registry_build(
        &crate::util::repo_path("data/catalog.toml"),
        &registry,
        &["--light", "sun=D65", "--light", "warm=A"],
    ));
    let (sun, warm) = ("ViewLayer.Combined_sun.", "ViewLayer.Combined_warm.");
    // (file, sun's value, warm's value): the group pass's light differs from the plane pass's
    let rendered = [
        ("trans", 0.5, 0.125),
        ("refl_0", 1.0, 0.5),
        ("refl_0_1", 0.25, 2.0),
    ];
    let files = |name: &str, passes: &[(&str, f32, f32)], layers: &[(&str, usize)]| {
        passes
            .iter()
            .map(|(pass, s, w)| {
                let p = d.join(format!("{pass}_{name}.exr"));
                let values: Vec<(&str, f32)> = layers
                    .iter()
                    .map(|&(prefix, k)| (prefix, if k == 0 { *s } else { *w }))
                    .collect();
                write_layers(&p, &values);
                p
            })
            .collect::<Vec<PathBuf>>()
    };
    let compose_groups = |inputs: &[PathBuf], groups: &str, out: &Path| {
        let mut c = compose();
        c.arg("--registry").arg(&registry);
        c.arg("--trans")
            .arg(&inputs[0])
            .arg("--refl")
            .arg(&inputs[1]);
        c.arg("--refl-group")
            .arg(format!("0.1={}", inputs[2].display()));
        c.arg("--mask").arg(unit_mask(d));
        c.args(["--light-groups", groups, "--data-type", "float", "-o"])
            .arg(out);
        ok(&mut c);
        beauty_g(out)
    };
    let both = compose_groups(
        &files("both", &rendered, &[(sun, 0), (warm, 1)]),
        "sun,warm",
        &d.join("both.exr"),
    );
    let alone: Vec<[f64; 2]> = [("sun", sun, 0), ("warm", warm, 1)]
        .iter()
        .map(|&(group, prefix, k)| {
            compose_groups(
                &files(group, &rendered, &[(prefix, k)]),
                group,
                &d.join(format!("{group}.exr")),
            )
        })
        .collect();
    for px in 0..2 {
        let sum = alone[0][px] + alone[1][px];
        assert!(
            (both[px] - sum).abs() <= 1e-6 * sum.abs().max(1.0),
            "pixel {px}: the groups' composite {}, the sum of each alone {sum}",
            both[px]
        );
    }
    // without the warm light in the deeper pane's pass the glass pixel loses that ghost
    let no_warm_ghost = [rendered[0], rendered[1], ("refl_0_1", 0.25, 0.0)];
    let without = compose_groups(
        &files("no_ghost", &no_warm_ghost, &[(sun, 0), (warm, 1)]),
        "sun,warm",
        &d.join("no_ghost.exr"),
    );
    assert!(
        both[0] - without[0] > 1e-2,
        "glass pixel: {} without the warm ghost, {} with it",
        without[0],
        both[0]
    );
    assert!((both[1] - without[1]).abs() <= 1e-6, "no glass: unchanged");
}

/// The G samples of a light-groups composite's beauty (`ViewLayer.Combined.G`, else `G`).
fn beauty_g(out: &Path) -> [f64; 2] {
    let p = read_exr_planes(out);
    let k = ["ViewLayer.Combined.G", "G"]
        .iter()
        .find_map(|name| p.names.iter().position(|n| n == name))
        .unwrap_or_else(|| panic!("{}: no beauty G in {:?}", out.display(), p.names));
    [p.channels[k][0], p.channels[k][1]]
}

/// The bundled registry's depths (m) of unit `id`'s pane groups, outside first.
fn registry_depths(id: u64) -> Vec<f64> {
    let reg: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(crate::util::repo_path("data/registry.json")).unwrap(),
    )
    .unwrap();
    let tables = reg["tables"]
        .as_array()
        .map_or_else(|| vec![&reg], |t| t.iter().collect());
    let glass = tables
        .iter()
        .flat_map(|t| t["glasses"].as_array().unwrap())
        .find(|g| g["id"].as_u64() == Some(id))
        .unwrap();
    glass["unit"]["groups"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g["depth_mm"].as_f64().unwrap() * 1e-3)
        .collect()
}

/// OBJ vertex positions.
fn vertices(path: &Path) -> Vec<[f64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
fn mirror_writes_a_virtual_scene_per_pane_group_at_its_depth() {
    let dir = tempfile::tempdir().unwrap();
    let room = crate::util::repo_path("fixtures/scene/room.obj");
    let mono = dir.path().join("mono");
    let units = dir.path().join("units");
    let eye = ["--eye", "0.3,1.2,4"];
    let run = |glass: &[&str], out: &Path| {
        let mut c = crate::util::glassdb();
        c.arg("mirror")
            .arg(&room)
            .args(glass)
            .args(eye)
            .arg("--out-dir")
            .arg(out);
        ok(&mut c)
    };
    run(
        &["--glass-material", "Clear*", "--glass-material", "Tinted*"],
        &mono,
    );
    // The facade (plane 0, z = 0, eye in front) a double unit; the side window monolithic.
    let text = run(&["--glass", "Clear*=11", "--glass", "Tinted*=2"], &units);
    assert!(text.contains("pane group 1:"), "{text}");
    let depths = registry_depths(11);
    assert_eq!(depths.len(), 2);
    let planes: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(units.join("planes.json")).unwrap()).unwrap();
    let facade = &planes["planes"][0];
    let groups = facade["groups"].as_array().unwrap();
    assert_eq!(groups.len(), 2);
    // The face is surface #1, its normal outdoors (+z): group k's mid-plane is z = −depth_k.
    assert_eq!(facade["equation"], serde_json::json!([0.0, 0.0, 1.0, 0.0]));
    for (g, want) in groups.iter().zip(&depths) {
        assert!((g["depth"].as_f64().unwrap() - want).abs() < 1e-12, "{g}");
        assert!(
            (g["equation"][3].as_f64().unwrap() - want).abs() < 1e-12,
            "{g}"
        );
    }
    assert_eq!(groups[1]["file"], "plane_0_group_1.obj");
    // Each group's scene is the room mirrored about z = −depth: mirrored back, every vertex is
    // one of the room's in front of that plane, or a clipped corner on it.
    let original = vertices(&room);
    for (file, depth) in [
        ("plane_0.obj", depths[0]),
        ("plane_0_group_1.obj", depths[1]),
    ] {
        let v = vertices(&units.join(file));
        assert!(!v.is_empty(), "{file}");
        for a in &v {
            let back = [a[0], a[1], -a[2] - 2.0 * depth];
            assert!(
                back[2] >= -depth - 1e-9,
                "{file}: {a:?} is behind its mirror plane"
            );
            let on_plane = (back[2] + depth).abs() < 1e-9;
            let in_room = original
                .iter()
                .any(|o| (0..3).all(|k| (o[k] - back[k]).abs() < 1e-9));
            assert!(
                on_plane || in_room,
                "{file}: {a:?} (mirrored back {back:?})"
            );
        }
    }
    let mono_face = vertices(&mono.join("plane_0.obj"));
    assert!(
        mono_face.iter().any(|v| v[2].abs() < 1e-12),
        "the face's own scene at z = 0"
    );
    // The monolithic side window: no groups, the same scene as before.
    assert!(planes["planes"][1].get("groups").is_none());
    assert_eq!(
        std::fs::read_to_string(units.join("plane_1.obj")).unwrap(),
        std::fs::read_to_string(mono.join("plane_1.obj")).unwrap()
    );
    // An eye indoors (behind the face) meets the inner pane first.
    let inside = dir.path().join("inside");
    let mut c = crate::util::glassdb();
    c.arg("mirror")
        .arg(&room)
        .args(["--glass", "Clear*=11", "--eye", "0.3,1.2,-1", "--out-dir"])
        .arg(&inside);
    ok(&mut c);
    let planes: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(inside.join("planes.json")).unwrap())
            .unwrap();
    let facade = &planes["planes"][0];
    assert_eq!(facade["eye_side"], "back");
    let seen: Vec<f64> = facade["groups"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g["depth"].as_f64().unwrap())
        .collect();
    assert_eq!(seen, vec![depths[1], depths[0]]);
}
