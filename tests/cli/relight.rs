//! End-to-end tests of the relit swap (`compose --light-parts`, docs/compose.md "Relit swap"):
//! synthetic passes split into light parts (small EXRs with `ViewLayer.Combined_<group>`
//! layers, written here so that no Blender is needed), composited and compared with the
//! method computed in the test from the registry's own evaluation.

use std::path::Path;

use glassdb_colour::RgbSpace;
use glassdb_image::{ExrPlane, ExrStorage, ExrWriteOptions};
use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};
use glassdb_registry::{ColourBasis, GlassRecord};
use glassdb_side::Side;

use crate::util::{compose, fails_naming, ok, read_exr_planes, run};

const W: usize = 6;
const H: usize = 4;
const N: usize = W * H;
/// The parts: an interior lamp, the sun and the sky through glass on plane 0.
const GROUPS: [&str; 3] = ["interior", "sun_p0", "sky_p0"];
/// Towards the sun; the plane's normal is +z.
const SUN: [f64; 3] = [0.4, -0.3, 0.8];

/// The bundled registry's linear Rec.709 table's first glass (the table untagged passes take).
fn glass() -> GlassRecord {
    let reg = glassdb_registry::default_registry().unwrap();
    let table = reg
        .table(ColourBasis::Space(RgbSpace::Srgb))
        .expect("a linear Rec.709 table");
    table.glasses[0].clone()
}

/// The value of group `g`, channel `c`, pixel `i` in pass `pass` (0: transmission, 1:
/// reflection) of frame `frame`: distinct, positive, smooth.
fn value(frame: u32, pass: usize, g: usize, c: usize, i: usize) -> f32 {
    0.05 + 0.1 * g as f32
        + 0.03 * c as f32
        + 0.01 * i as f32
        + 0.2 * pass as f32
        + 0.07 * frame as f32
}

/// A float EXR with one `ViewLayer.Combined_<group>` per group and, when `beauty`, their sum as
/// `ViewLayer.Combined`.
fn write_split(path: &Path, frame: u32, pass: usize, groups: &[&str], beauty: bool) {
    let mut planes = Vec::new();
    for (c, ch) in ["R", "G", "B"].iter().enumerate() {
        let mut sum = vec![0f32; N];
        for (g, group) in groups.iter().enumerate() {
            let v: Vec<f32> = (0..N).map(|i| value(frame, pass, g, c, i)).collect();
            sum.iter_mut().zip(&v).for_each(|(s, x)| *s += x);
            planes.push(ExrPlane::new(
                &format!("ViewLayer.Combined_{group}.{ch}"),
                v,
            ));
        }
        if beauty {
            planes.push(ExrPlane::new(&format!("ViewLayer.Combined.{ch}"), sum));
        }
    }
    let options = ExrWriteOptions {
        storage: ExrStorage::Float,
        compression: exr::compression::Compression::ZIP16,
        zip_level: None,
    };
    let file = std::fs::File::create(path).unwrap();
    glassdb_image::write_exr_planes(file, W, H, planes, options).unwrap();
}

/// The mask: glass `id` on plane 0 in the left half, 8-bit cos θ codes varying per pixel.
fn mask(id: u16) -> MaskImage {
    MaskImage {
        width: W as u32,
        height: H as u32,
        id: (0..N).map(|i| if i % W < W / 2 { id } else { 0 }).collect(),
        cos_theta: CosTheta::Quantized8((0..N).map(|i| 40 + 9 * i as u8).collect()),
        plane: vec![0; N],
        coverage: None,
    }
}

fn parts_json(id: u16, extra: &[&str]) -> String {
    // the record lists the sun first: a group name with underscores names the first layer
    let mut parts = vec![
        serde_json::json!({"group": GROUPS[1], "source": {"kind": "sun", "direction_to_sun": SUN},
            "through": {"plane": 0, "normal": [0.0, 0.0, 1.0], "id": id}}),
        serde_json::json!({"group": GROUPS[2], "source": {"kind": "sky"},
            "through": {"plane": 0, "normal": [0.0, 0.0, 1.0], "id": id}}),
        serde_json::json!({"group": GROUPS[0], "source": {"kind": "other"}}),
    ];
    for g in extra {
        parts.push(serde_json::json!({"group": g, "source": {"kind": "other"}}));
    }
    serde_json::json!({"format": "glassdb-light-parts/1", "parts": parts}).to_string()
}

/// Frames 1 and 2 of split passes, masks and light parts in `dir`.
fn write_frames(dir: &Path, id: u16) {
    for frame in [1u32, 2] {
        write_split(
            &dir.join(format!("t.{frame:04}.exr")),
            frame,
            0,
            &GROUPS,
            true,
        );
        write_split(
            &dir.join(format!("r.{frame:04}.exr")),
            frame,
            1,
            &GROUPS,
            true,
        );
        write_mask(
            &dir.join(format!("m.{frame:04}.png")),
            &mask(id),
            MaskFormat::Png8,
        )
        .unwrap();
        std::fs::write(dir.join(format!("lp.{frame:04}.json")), parts_json(id, &[])).unwrap();
    }
}

fn compose_in(dir: &Path, frame: &str) -> std::process::Command {
    let mut cmd = compose();
    cmd.current_dir(dir).args([
        "--trans",
        &format!("t.{frame}.exr"),
        "--refl",
        &format!("r.{frame}.exr"),
        "--mask",
        &format!("m.{frame}.png"),
        "--data-type",
        "float",
    ]);
    cmd
}

/// Each part's factor computed here: 1; t at the sun's angle (cos θ = n·d/|d| by hand, the
/// front); t_dif by the midpoint rule on the registry's evaluation.
fn factors(g: &GlassRecord) -> [[f64; 3]; 3] {
    let cos_sun = SUN[2] / (SUN.iter().map(|x| x * x).sum::<f64>()).sqrt();
    let (_, t_sun) = g.eval(Side::Front, cos_sun);
    let mut t_dif = [0.0; 3];
    let n = 20_000;
    for k in 0..n {
        let mu = (k as f64 + 0.5) / n as f64;
        let (_, t) = g.eval(Side::Front, mu);
        for c in 0..3 {
            t_dif[c] += 2.0 * t[c] * mu / n as f64;
        }
    }
    [[1.0; 3], t_sun, t_dif]
}

/// `compose --light-parts` over two frames is, per pixel, Σ_p f_p·(trans_p·t + refl_p·r) with
/// r, t at the pixel's cos θ and f_p computed here; `--stats` lists each part's factors.
#[test]
fn light_parts_relight_every_pixel_by_the_glass_each_part_came_through() {
    let dir = tempfile::tempdir().unwrap();
    let g = glass();
    write_frames(dir.path(), g.id);
    let out = ok(compose_in(dir.path(), "####").args([
        "--light-parts",
        "lp.####.json",
        "--frames",
        "1-2",
        "--stats",
        "-o",
        "out.####.exr",
    ]));
    for group in GROUPS {
        assert!(out.contains(&format!("  {group}")), "{out}");
    }
    assert!(
        out.contains("hemispherical t_dif") && out.contains("factor R"),
        "{out}"
    );
    let f = factors(&g);
    let m = mask(g.id);
    for frame in [1u32, 2] {
        let planes = read_exr_planes(&dir.path().join(format!("out.{frame:04}.exr")));
        for (c, ch) in ["R", "G", "B"].iter().enumerate() {
            let k = planes
                .names
                .iter()
                .position(|n| n == &format!("ViewLayer.Combined.{ch}"))
                .unwrap_or_else(|| panic!("{:?}", planes.names));
            for i in 0..N {
                let glass_here = m.id[i] != 0;
                let CosTheta::Quantized8(codes) = &m.cos_theta else {
                    unreachable!()
                };
                let (r, t) = g.eval(Side::Front, f64::from(codes[i]) / 255.0);
                let mut want = 0.0;
                for (p, fp) in f.iter().enumerate() {
                    let trans = f64::from(value(frame, 0, p, c, i));
                    let refl = f64::from(value(frame, 1, p, c, i));
                    want += fp[c]
                        * if glass_here {
                            trans * t[c] + refl * r[c]
                        } else {
                            trans
                        };
                }
                let got = planes.channels[k][i];
                assert!(
                    (got - want).abs() < 2e-5 * (1.0 + want),
                    "frame {frame} {ch} pixel {i}: {got} vs {want}"
                );
            }
        }
        assert_eq!(
            planes.names,
            [
                "ViewLayer.Combined.B",
                "ViewLayer.Combined.G",
                "ViewLayer.Combined.R"
            ],
            "the relit beauty alone: the parts' layers are not carried"
        );
    }
}

/// A part the passes lack, a layer no part names, an aperture off the mask's planes and a
/// record that is not JSON are errors naming them and the file.
#[test]
fn light_parts_and_layers_must_match() {
    let dir = tempfile::tempdir().unwrap();
    let g = glass();
    write_frames(dir.path(), g.id);
    let p = dir.path();
    let run_with = |name: &str, text: String| {
        std::fs::write(p.join(name), text).unwrap();
        let mut cmd = compose_in(p, "0001");
        cmd.args(["--light-parts", name, "-o", "o.exr"]);
        cmd
    };
    fails_naming(
        &mut run_with("more.json", parts_json(g.id, &["lamp"])),
        &["t.0001.exr", "no layer for light part \"lamp\""],
    );
    let fewer =
        parts_json(g.id, &[]).replace(r#",{"group":"interior","source":{"kind":"other"}}"#, "");
    assert!(!fewer.contains("interior"), "{fewer}");
    fails_naming(
        &mut run_with("fewer.json", fewer),
        &["t.0001.exr", "without a light part: interior"],
    );
    let off = parts_json(g.id, &[]).replace(r#""plane":0"#, r#""plane":4"#);
    fails_naming(
        &mut run_with("off.json", off),
        &["came through plane 4", "m.0001.png"],
    );
    fails_naming(
        &mut run_with("bad.json", "{ not json".into()),
        &["bad.json", "line 1"],
    );
    assert!(!p.join("o.exr").exists());
}

/// Passes split by light composited without their record warn, naming what is left unscaled;
/// passes without a split say under --stats that a swap cannot relight them.
#[test]
fn split_passes_without_their_record_and_unsplit_passes_say_so() {
    let dir = tempfile::tempdir().unwrap();
    let g = glass();
    write_frames(dir.path(), g.id);
    let (out, _, stderr) = run(compose_in(dir.path(), "0001").args([
        "--layer",
        "ViewLayer.Combined",
        "-o",
        "plain.exr",
    ]));
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("is split by light (interior, sky_p0, sun_p0)")
            && stderr.contains("--light-parts"),
        "{stderr}"
    );
    let one = dir.path().join("one.exr");
    // a pass without group layers
    crate::util::write_rgb(&one, W as u32, H as u32, &vec![[0.5f32; 3]; N]);
    let mut cmd2 = compose();
    cmd2.current_dir(dir.path()).args([
        "--trans",
        "one.exr",
        "--refl",
        "one.exr",
        "--mask",
        "m.0001.png",
        "--stats",
        "-o",
        "unsplit.exr",
    ]);
    let stdout = ok(&mut cmd2);
    assert!(
        stdout.contains("not split by the light's path") && stdout.contains("glass pixels only"),
        "{stdout}"
    );
}

/// A `glassdb blender` folder of the two synthetic frames: its run record names each frame's
/// light parts when `relit`; the passes were "rendered" with a glass named otherwise.
fn write_blender_dir(dir: &Path, g: &GlassRecord, relit: bool) {
    write_frames(dir, g.id);
    let frames: Vec<serde_json::Value> = [1u32, 2]
        .iter()
        .map(|f| {
            let mut v = serde_json::json!({
                "frame": f, "trans": format!("t.{f:04}.exr"), "mask": format!("m.{f:04}.png"),
                "refl": [format!("r.{f:04}.exr")], "sides": ["front"], "bounds": [null],
                "composite": format!("composite.{f:04}.exr"),
            });
            if relit {
                v["light_parts"] = format!("lp.{f:04}.json").into();
            }
            v
        })
        .collect();
    let record = serde_json::json!({
        "format": "glassdb-blender/1", "blend": "room.blend", "blender": "3.4.1",
        "glass": ["Glass=1"], "samples": 8, "width": W, "height": H, "overrides": [],
        "frames": frames,
        "lit_by": [{"id": g.id, "name": "another glass", "t0": [0.5, 0.5, 0.5], "t_dif": [0.4, 0.4, 0.4]}],
    });
    std::fs::write(dir.join("glassdb-blender.json"), record.to_string()).unwrap();
}

/// `glassdb blender compose DIR` composites a frame with its light parts when the run record
/// names them (the same image as `compose --light-parts`, each part's factors printed, no
/// warning that the room keeps the old glass), and warns as before when it does not.
#[test]
fn blender_compose_relights_frames_whose_record_names_their_light_parts() {
    let dir = tempfile::tempdir().unwrap();
    let g = glass();
    write_blender_dir(dir.path(), &g, true);
    let (out, stdout, stderr) = run(crate::util::glassdb()
        .args(["blender", "compose"])
        .arg(dir.path()));
    assert!(out.status.success(), "{stderr}");
    assert!(
        stdout.contains("frame 1: relit by 3 light part(s): sun_p0 ×(")
            && stdout.contains("interior ×(1.000, 1.000, 1.000)"),
        "{stdout}"
    );
    assert!(!stderr.contains("only its pixels change"), "{stderr}");
    ok(compose_in(dir.path(), "0001").args(["--light-parts", "lp.0001.json", "-o", "cli.exr"]));
    let a = read_exr_planes(&dir.path().join("composite.0001.exr"));
    let b = read_exr_planes(&dir.path().join("cli.exr"));
    let rgb = |p: &crate::util::Planes| -> Vec<Vec<f64>> {
        ["R", "G", "B"]
            .iter()
            .map(|c| {
                let k = p
                    .names
                    .iter()
                    .position(|n| n == &format!("ViewLayer.Combined.{c}"))
                    .unwrap();
                p.channels[k].clone()
            })
            .collect()
    };
    assert_eq!(rgb(&a), rgb(&b));

    let old = tempfile::tempdir().unwrap();
    write_blender_dir(old.path(), &g, false);
    let (out, stdout, stderr) = run(crate::util::glassdb()
        .args(["blender", "compose"])
        .arg(old.path()));
    assert!(out.status.success(), "{stderr}");
    assert!(!stdout.contains("relit by"), "{stdout}");
    assert!(stderr.contains("only its pixels change"), "{stderr}");
}

/// `glassdb view DIR` on a run whose record names light parts: a product chosen on the page
/// rescales the room's light too, giving `compose --light-parts`'s pixels with that product
/// (8-bit PNG, standard view, undithered), not the glass-pixels-only swap; a part's exposure
/// slider scales its factor by 2^EV.
#[test]
fn a_product_chosen_in_the_viewer_relights_the_room_as_compose_does() {
    let dir = tempfile::tempdir().unwrap();
    let g = glass();
    write_blender_dir(dir.path(), &g, true);
    // the darkest product of the table the page composites with
    let reg = glassdb_registry::default_registry().unwrap();
    let table = reg.table(ColourBasis::Space(RgbSpace::Srgb)).unwrap();
    let (index, dark) = table
        .glasses
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.t0[1].total_cmp(&b.1.t0[1]))
        .unwrap();
    assert!(dark.t0[1] < 0.5 * g.t0[1], "{} vs {}", dark.name, g.name);
    let swapped = crate::viewer::swapped_registry(
        &crate::util::repo_path("data/registry.json"),
        dir.path(),
        g.id,
        &dark.name,
    );
    let png = |name: &str, relit: bool| -> Vec<[f64; 3]> {
        let mut cmd = compose_in(dir.path(), "0001");
        cmd.args(["--dither", "none", "--registry"]).arg(&swapped);
        if relit {
            cmd.args(["--light-parts", "lp.0001.json"]);
        } else {
            cmd.args(["--layer", "ViewLayer.Combined"]);
        }
        ok(cmd.arg("-o").arg(name));
        let p = crate::util::read_png_planes(&dir.path().join(name));
        (0..p.width * p.height)
            .map(|i| [0, 1, 2].map(|c| p.channels[c][i]))
            .collect()
    };
    let relit = png("relit.png", true);
    let glass_only = png("glass_only.png", false);

    let export = dir.path().join("export");
    ok(crate::util::glassdb()
        .arg("view")
        .arg(dir.path())
        .arg("--export")
        .arg(&export));
    let url = format!("file://{}", export.join("index.html").display());
    let choose = format!(
        "window.glassdb.choose({}, {index}); return Array.from(atob(window.glassdb.readPixels()), (c) => c.charCodeAt(0));",
        g.id
    );
    let ev = "window.glassdb.setPartEv('interior', 1); return window.glassdb.partFactors();";
    let out = crate::util::run_oracle(
        "viewer_driver.py",
        &[
            "layout".as_ref(),
            url.as_ref(),
            "--run".as_ref(),
            "return window.glassdb.partFactors();".as_ref(),
            "--run".as_ref(),
            choose.as_ref(),
            "--run".as_ref(),
            "return window.glassdb.partFactors();".as_ref(),
            "--run".as_ref(),
            ev.as_ref(),
        ],
    );
    let report: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    let results = &report["results"];
    let bytes: Vec<f64> = results[1]
        .as_array()
        .unwrap_or_else(|| panic!("{report}"))
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let canvas: Vec<[f64; 3]> = bytes.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect();
    let worst = |a: &[[f64; 3]], b: &[[f64; 3]]| {
        a.iter()
            .zip(b)
            .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()))
            .fold(0.0, f64::max)
    };
    assert!(worst(&canvas, &relit) <= 1.0, "{canvas:?}\n{relit:?}");
    assert!(
        worst(&canvas, &glass_only) >= 10.0,
        "the room did not change"
    );
    // factors: the sky part's is t_dif of the product, before and after the choice
    let sky = |r: &serde_json::Value| r[1]["A"][1].as_f64().unwrap();
    assert!((sky(&results[0]) - g.t_dif()[1]).abs() < 1e-6, "{report}");
    assert!(
        (sky(&results[2]) - dark.t_dif()[1]).abs() < 1e-6,
        "{report}"
    );
    let interior = results[3][2]["A"][0].as_f64().unwrap();
    assert!((interior - 2.0).abs() < 1e-12, "{report}");
}
