//! The scene's own light groups as lights (issue 29, docs/blender.md "Light groups"): frame 2
//! of the `relit` scene (the daylit room seen from outside through both windows) with two sun
//! lamps and the world in group `sun` and a warm bulb and area lamp inside in group `warm`
//! (scripts/blender/make_light_groups_scene.py), rendered at 64 × 48 with 16 samples, one
//! thread, seed 0, with and without the light split, `--light sun=D65 --light warm=A`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use super::{background_blender, channel, copy_dir, json, make_glassdb_scene, render_test_glasses};
use crate::util::{
    Planes, element_where, fails_naming, glassdb, json_rgb, max_abs_diff, ok, read_exr_planes,
    registry_build, repo_path,
};

struct GroupRuns {
    _dir: tempfile::TempDir,
    root: PathBuf,
    /// The `relit` scene without light groups.
    relit: PathBuf,
    /// With the groups.
    groups: PathBuf,
    split: PathBuf,
    off: PathBuf,
    /// Registries of the bundled catalog: sun=D65 warm=A; the same with warm's glasses the
    /// sun's.
    two: PathBuf,
    same: PathBuf,
}

/// `make_light_groups_scene.py` run on `relit`, saved as `out`, with `extra` options.
fn make_groups_scene(relit: &Path, out: &Path, extra: &[&str]) {
    ok(
        background_blender(&["-noaudio".as_ref(), relit.as_os_str()])
            .arg("-P")
            .arg(repo_path("scripts/blender/make_light_groups_scene.py"))
            .args(["--", "--out"])
            .arg(out)
            .args(extra),
    );
}

/// `glassdb blender render BLEND` of frame 2 at 64 × 48, 16 samples, one thread, seed 0.
fn render(blend: &Path, out: &Path, extra: &[&str]) -> Command {
    render_at(blend, out, ("64x48", "16"), extra)
}

/// `glassdb blender render BLEND` of frame 2 at `(WxH, samples)`, one thread, seed 0.
fn render_at(blend: &Path, out: &Path, (size, samples): (&str, &str), extra: &[&str]) -> Command {
    let mut cmd = render_test_glasses(blend, out);
    cmd.args(["--frames", "2", "--resolution", size, "--samples", samples])
        .args(["--threads", "1", "--seed", "0"])
        .args(extra);
    cmd
}

const LIGHTS: [&str; 4] = ["--light", "sun=D65", "--light", "warm=A"];

fn group_runs() -> &'static GroupRuns {
    static R: OnceLock<GroupRuns> = OnceLock::new();
    R.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().to_path_buf();
        let relit = root.join("relit.blend");
        make_glassdb_scene("relit", &relit, &[]);
        let groups = root.join("groups.blend");
        make_groups_scene(&relit, &groups, &[]);
        let two = root.join("two.json");
        bundled_registry_under(&two, &LIGHTS);
        // `warm` says A but holds the sun's (D65) numbers: compositing with it is the one-table
        // composite exactly when each group takes its own light's table.
        let mut reg = json(&two);
        let tables = reg["tables"].as_array_mut().unwrap();
        let sun = tables.iter().find(|t| t["light"] == "sun").unwrap()["glasses"].clone();
        for t in tables.iter_mut().filter(|t| t["light"] == "warm") {
            t["glasses"] = sun.clone();
        }
        let same = root.join("same.json");
        std::fs::write(&same, serde_json::to_string_pretty(&reg).unwrap()).unwrap();
        let (split, off) = (root.join("split"), root.join("off"));
        let reg = ["--registry", two.to_str().unwrap()];
        ok(&mut render(&groups, &split, &[&LIGHTS[..], &reg].concat()));
        let off_args = [&LIGHTS[..], &reg, &["--light-split", "off"]].concat();
        ok(&mut render(&groups, &off, &off_args));
        GroupRuns {
            _dir: dir,
            root,
            relit,
            groups,
            split,
            off,
            two,
            same,
        }
    })
}

/// The bundled catalog's registry built into `out` with the `--light NAME=ILLUMINANT` options
/// `lights`.
fn bundled_registry_under(out: &Path, lights: &[&str]) {
    ok(&mut registry_build(
        &repo_path("data/catalog.toml"),
        out,
        lights,
    ));
}

fn frame2(dir: &Path, stem: &str) -> Planes {
    read_exr_planes(&dir.join(format!("{stem}.0002.exr")))
}

/// The run record's lights: each scene group with its illuminant.
fn assert_lights(record: &serde_json::Value) {
    let lights = record["lights"].as_array().unwrap();
    let said: Vec<(&str, &str)> = lights
        .iter()
        .map(|l| {
            (
                l["group"].as_str().unwrap(),
                l["illuminant"].as_str().unwrap(),
            )
        })
        .collect();
    assert_eq!(said, [("sun", "D65"), ("warm", "A")], "{record}");
}

/// Every pass's beauty is the sum of its group layers `groups` (to half-float precision).
fn assert_beauty_is_the_sum(dir: &Path, groups: &[String]) {
    for pass in ["trans", "refl_0", "refl_1"] {
        let p = frame2(dir, pass);
        let layers = p
            .names
            .iter()
            .filter(|n| n.starts_with("ViewLayer.Combined_") && n.ends_with(".R"))
            .count();
        assert_eq!(layers, groups.len(), "{pass}: {:?}", p.names);
        for c in ["R", "G", "B"] {
            let beauty = channel(&p, &format!("ViewLayer.Combined.{c}"));
            let parts: Vec<&[f64]> = groups
                .iter()
                .map(|g| channel(&p, &format!("ViewLayer.Combined_{g}.{c}")))
                .collect();
            for (i, b) in beauty.iter().enumerate() {
                let sum: f64 = parts.iter().map(|l| l[i]).sum();
                assert!(
                    (sum - b).abs() <= 3e-3 * b.abs().max(1.0),
                    "{pass} pixel {i} {c}: groups sum to {sum}, beauty {b}"
                );
            }
        }
    }
}

/// Towards a sun lamp of Blender rotation (x, 0, z) degrees (XYZ Euler): R·(0, 0, 1).
fn towards_sun(x_deg: f64, z_deg: f64) -> [f64; 3] {
    let (a, c) = (x_deg.to_radians(), z_deg.to_radians());
    [a.sin() * c.sin(), -a.sin() * c.cos(), a.cos()]
}

/// With the split: each source split by scene group (two suns and the world of `sun`, the
/// interior lamps of `warm`), each part's light its group, the suns' directions their lamps',
/// and every pass's beauty the sum of its parts.
#[test]
fn split_sources_are_split_by_scene_light_group() {
    let r = group_runs();
    let record = json(&r.split.join("glassdb-blender.json"));
    assert_lights(&record);
    assert!(record.get("group_layers").is_none(), "{record}");
    let parts = json(&r.split.join("light_parts.0002.json"));
    let parts = parts["parts"].as_array().unwrap();
    let groups: Vec<String> = parts
        .iter()
        .map(|p| p["group"].as_str().unwrap().to_string())
        .collect();
    let mut want = Vec::new();
    for source in ["sun0_sun", "sun1_sun", "sky_sun", "other_warm"] {
        want.push(source.to_string());
        want.push(format!("{source}_p0_id1"));
        want.push(format!("{source}_p1_id5"));
    }
    assert_eq!(groups, want);
    let mut suns = Vec::new();
    for p in parts {
        let group = p["group"].as_str().unwrap();
        let light = if group.starts_with("other_warm") {
            "warm"
        } else {
            "sun"
        };
        assert_eq!(p["light"], light, "{p}");
        let kind = p["source"]["kind"].as_str().unwrap();
        assert_eq!(kind, &group[..3].replace("oth", "other"), "{p}");
        if p["through"].is_null() && kind == "sun" {
            let d: Vec<f64> = (0..3)
                .map(|i| p["source"]["direction_to_sun"][i].as_f64().unwrap())
                .collect();
            suns.push(d);
        }
    }
    // scripts/blender: Sun at (50°, 0, 135°), Sun_low at (70°, 0, 160°), in either order.
    let want = [towards_sun(50.0, 135.0), towards_sun(70.0, 160.0)];
    let close = |a: &[f64], b: &[f64; 3]| (0..3).all(|i| (a[i] - b[i]).abs() < 1e-5);
    assert!(
        (close(&suns[0], &want[0]) && close(&suns[1], &want[1]))
            || (close(&suns[0], &want[1]) && close(&suns[1], &want[0])),
        "{suns:?} vs {want:?}"
    );
    assert_beauty_is_the_sum(&r.split, &groups);
    // The warm interior is seen through the windows.
    let trans = frame2(&r.split, "trans");
    let warm = channel(&trans, "ViewLayer.Combined_other_warm.R");
    assert!(warm.iter().filter(|&&v| v > 0.01).count() > 50);
}

/// Without the split: every pass holds a layer per scene group, their sum the beauty, and the
/// record says so.
#[test]
fn without_the_split_every_pass_has_a_layer_per_scene_group() {
    let r = group_runs();
    let record = json(&r.off.join("glassdb-blender.json"));
    assert_lights(&record);
    assert_eq!(record["group_layers"], true, "{record}");
    assert!(record["frames"][0].get("light_parts").is_none());
    assert_beauty_is_the_sum(&r.off, &["sun".into(), "warm".into()]);
    let trans = frame2(&r.off, "trans");
    for g in ["sun", "warm"] {
        let l = channel(&trans, &format!("ViewLayer.Combined_{g}.G"));
        assert!(l.iter().filter(|&&v| v > 0.01).count() > 50, "{g} is empty");
    }
}

/// `run` composited again with `registry` in a copy under `name`; returns (stdout, frame 2).
fn recompose(run: &Path, name: &str, registry: &Path) -> (String, Planes) {
    let to = group_runs().root.join(name);
    copy_dir(run, &to);
    let out = ok(&mut compose(&to, registry));
    (out, frame2(&to, "composite"))
}

/// `glassdb blender compose DIR --registry REGISTRY`.
fn compose(dir: &Path, registry: &Path) -> Command {
    let mut cmd = glassdb();
    cmd.args(["blender", "compose"])
        .arg(dir)
        .arg("--registry")
        .arg(registry);
    cmd
}

/// Each glass's t0 in the registry `path` under light `light`.
fn t0(path: &Path, light: &str, id: u64) -> [f64; 3] {
    let reg = json(path);
    let g = element_where(
        &element_where(&reg["tables"], "light", light)["glasses"],
        "id",
        id,
    );
    json_rgb(&g["t0"])
}

/// Each group composites with its light's table: the one-light registry (the bundled D65 one)
/// gives the same composite as a registry whose `warm` (A) holds D65's numbers, and the one whose
/// `warm` is A differs from it only through the warm light, in the direction of t0 under A
/// against D65 on the tinted glass (id 5), with the split and without.
#[test]
fn each_light_group_composites_with_its_lights_table() {
    let r = group_runs();
    let one = repo_path("data/registry.json");
    let dt = {
        let (a, d) = (t0(&r.two, "warm", 5), t0(&r.two, "sun", 5));
        [0, 1, 2].map(|c| a[c] - d[c])
    };
    assert!(dt.iter().all(|d| d.abs() > 0.004), "{dt:?}");
    for run in [&r.split, &r.off] {
        let tag = run.file_name().unwrap().to_str().unwrap();
        let (said, one_table) = recompose(run, &format!("{tag}_one"), &one);
        assert!(said.contains("lights: one table for all lights"), "{said}");
        let (said, same) = recompose(run, &format!("{tag}_same"), &r.same);
        assert!(said.contains("sun -> sun, warm -> warm"), "{said}");
        let (_, two) = recompose(run, &format!("{tag}_two"), &r.two);
        for c in ["R", "G", "B"] {
            let (a, b) = (channel(&one_table, c), channel(&same, c));
            assert_eq!(a.len(), b.len(), "{tag} {c}");
            let worst = max_abs_diff(a, b);
            assert!(
                worst < 1e-3,
                "{tag} {c}: one table vs warm with D65's numbers: {worst}"
            );
        }
        let mask = frame2(run, "mask");
        let id = channel(&mask, "id");
        let tinted: Vec<usize> = (0..id.len()).filter(|&i| id[i] == 5.0).collect();
        assert!(tinted.len() > 20, "{tag}: {} tinted pixels", tinted.len());
        for (k, c) in ["R", "G", "B"].into_iter().enumerate() {
            let (a, b) = (channel(&two, c), channel(&one_table, c));
            let mean = tinted.iter().map(|&i| a[i] - b[i]).sum::<f64>() / tinted.len() as f64;
            eprintln!(
                "{tag} {c}: warm=A − one table on id 5: {mean:.5} (Δt0 {:.4})",
                dt[k]
            );
            if dt[k].abs() > 0.004 {
                assert!(
                    mean * dt[k] > 0.0 && mean.abs() > 1e-4,
                    "{tag} {c}: mean change {mean} against Δt0 {}",
                    dt[k]
                );
            }
        }
    }
}

/// Light groups that cannot be composited are refused by name: a `--light` for a group the
/// scene lacks (or for a scene without groups), a group without a spectrum, an emitter in no
/// group, a registry without the group's light or with another spectrum for it. A
/// `glassdb_light` property replaces the flag.
#[test]
fn bad_light_groups_are_refused_by_name() {
    let r = group_runs();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    fn with<'a>(extra: &[&'a str]) -> Vec<&'a str> {
        [&LIGHTS[..], extra].concat()
    }
    fails_naming(
        &mut render(&r.groups, &out, &with(&["--light", "led=A"])),
        &["no light group `led`", "sun, warm"],
    );
    fails_naming(
        &mut render(&r.groups, &out, &["--light", "sun=D65"]),
        &["`warm`", "no spectrum", "--light warm="],
    );
    fails_naming(
        &mut render(&r.relit, &out, &["--light", "sun=D65"]),
        &["no light group `sun`", "has no light groups"],
    );
    let led = tmp.path().join("led.json");
    bundled_registry_under(&led, &["--light", "sun=D65", "--light", "led=LED-B3"]);
    fails_naming(
        &mut render(
            &r.groups,
            &out,
            &with(&["--registry", led.to_str().unwrap()]),
        ),
        &["`warm` (A) has no table in", "led.json", "led (LED-B3)"],
    );
    // The same registry refused at compose, and a light of the group's name with another
    // spectrum.
    let copy = tmp.path().join("copy");
    copy_dir(&r.split, &copy);
    fails_naming(&mut compose(&copy, &led), &["`warm`", "led.json"]);
    let d50 = tmp.path().join("d50.json");
    bundled_registry_under(&d50, &["--light", "sun=D65", "--light", "warm=D50"]);
    fails_naming(
        &mut compose(&copy, &d50),
        &["`warm` was rendered as A", "d50.json", "warm (D50)"],
    );
    let ungrouped = tmp.path().join("ungrouped.blend");
    make_groups_scene(&r.relit, &ungrouped, &["--ungrouped"]);
    fails_naming(
        &mut render(&ungrouped, &out, &LIGHTS),
        &["lamp Desk", "in none"],
    );
    // The property says warm's spectrum; the smallest run that writes a record.
    let property = tmp.path().join("property.blend");
    make_groups_scene(&r.relit, &property, &["--property"]);
    let small = tmp.path().join("small");
    let extra = [
        "--light",
        "sun=D65",
        "--light-split",
        "off",
        "--no-composite",
    ];
    ok(&mut render_at(&property, &small, ("16x12", "1"), &extra));
    let record = json(&small.join("glassdb-blender.json"));
    assert_lights(&record);
    assert_eq!(
        record["lights"][1]["from"],
        "lamp Bulb's glassdb_light property"
    );
}
