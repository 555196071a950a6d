//! `glassdb blender render` / `compose` end to end with Debian's Blender (scripts/test-all
//! installs it): a tiny scene built by scripts/blender/make_glassdb_scene.py, rendered once and
//! shared by the tests. Geometry and planes are checked against the scene's own corners,
//! the masks against Cycles' Material Index through each pixel centre, the composite against
//! the Cycles reference (the same glass seen by the camera) within the noise of its samples.
//! Bad inputs use small stand-in `blender` scripts.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

mod lights;
mod partial;
mod relit;

use crate::util::{
    Planes, fails, fails_naming, glassdb, ok, read_exr_planes, registry_build, repo_path, run,
    send_signal, write_executable, write_file,
};

/// The tiny scene, its facts, Cycles' index renders and two glassdb runs (seeds 0 and 1).
pub(crate) struct Rendered {
    _dir: tempfile::TempDir,
    root: PathBuf,
    blend: PathBuf,
    facts: serde_json::Value,
    /// `glassdb blender render … --reference` with seed 0 and with seed 1.
    pub(crate) runs: [PathBuf; 2],
}

const GLASS: [&str; 2] = ["Glass_clear=1", "Tinted*=5"];

fn blender_program() -> &'static str {
    let found = Command::new("blender")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    assert!(
        found,
        "these tests need Blender 3.4+ on PATH (scripts/test-all installs Debian's `blender`)"
    );
    "blender"
}

/// `glassdb blender render BLEND --glass …` with the test glasses (`GLASS`), into `out`.
fn render_test_glasses(blend: &Path, out: &Path) -> Command {
    let mut cmd = glassdb();
    cmd.args(["blender", "render"]).arg(blend);
    for g in GLASS {
        cmd.args(["--glass", g]);
    }
    cmd.arg("--out-dir").arg(out);
    cmd
}

/// `glassdb blender render BLEND` with the test glasses, 2 threads, `seed` and `extra`.
fn render_run(blend: &Path, out: &Path, seed: u32, extra: &[&str]) {
    ok(render_test_glasses(blend, out)
        .args(["--threads", "2", "--seed"])
        .arg(seed.to_string())
        .args(extra));
}

/// `blender -b OPTIONS… --python-exit-code 1`: Blender in the background, failing when its
/// Python does; the caller adds the script (`-P FILE` or `--python-expr`).
pub(crate) fn background_blender(options: &[&std::ffi::OsStr]) -> Command {
    let mut cmd = Command::new(blender_program());
    cmd.arg("-b")
        .args(options)
        .args(["--python-exit-code", "1"]);
    cmd
}

/// `scripts/blender/make_glassdb_scene.py --scene KIND` saved as `blend`, with `extra` options.
fn make_glassdb_scene(kind: &str, blend: &Path, extra: &[&std::ffi::OsStr]) {
    make_scene("scripts/blender/make_glassdb_scene.py", kind, blend, extra)
}

pub(crate) fn rendered() -> &'static Rendered {
    static R: OnceLock<Rendered> = OnceLock::new();
    R.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().to_path_buf();
        let blend = root.join("tiny.blend");
        let (facts, index) = (root.join("facts.json"), root.join("index"));
        make_scene(
            "scripts/blender/make_glassdb_scene.py",
            "tiny",
            &blend,
            &[
                "--facts".as_ref(),
                facts.as_os_str(),
                "--index".as_ref(),
                index.as_os_str(),
            ],
        );
        let facts = serde_json::from_str(&std::fs::read_to_string(&facts).unwrap()).unwrap();
        let runs = [root.join("run0"), root.join("run1")];
        for (seed, run) in runs.iter().enumerate() {
            render_run(&blend, run, seed as u32, &["--reference"]);
        }
        Rendered {
            _dir: dir,
            root,
            blend,
            facts,
            runs,
        }
    })
}

/// `blender -b … -P SCRIPT -- --scene KIND --out BLEND EXTRA…`: a scene made by one of the
/// repository's scene scripts.
fn make_scene(script: &str, kind: &str, blend: &Path, extra: &[&std::ffi::OsStr]) {
    ok(
        background_blender(&["--factory-startup".as_ref(), "-noaudio".as_ref()])
            .arg("-P")
            .arg(repo_path(script))
            .args(["--", "--scene", kind, "--out"])
            .arg(blend)
            .args(extra),
    );
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn corners(facts: &serde_json::Value, pane: &str) -> Vec<[f64; 3]> {
    facts["panes"][pane]["corners"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| std::array::from_fn(|i| c[i].as_f64().unwrap()))
        .collect()
}

/// The plane through a pane's first three corners, by the cross product: (unit normal, d).
fn plane_of(c: &[[f64; 3]]) -> ([f64; 3], f64) {
    let u: [f64; 3] = std::array::from_fn(|i| c[1][i] - c[0][i]);
    let v: [f64; 3] = std::array::from_fn(|i| c[2][i] - c[0][i]);
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let n = n.map(|x| x / len);
    (n, -(n[0] * c[0][0] + n[1] * c[0][1] + n[2] * c[0][2]))
}

/// The vertices written under `o NAME` in the exported OBJ.
fn obj_vertices(obj: &str, name: &str) -> Vec<[f64; 3]> {
    let mut inside = false;
    let mut out = Vec::new();
    for line in obj.lines() {
        if let Some(o) = line.strip_prefix("o ") {
            inside = o == name;
        } else if inside && let Some(v) = line.strip_prefix("v ") {
            let p: Vec<f64> = v.split_whitespace().map(|x| x.parse().unwrap()).collect();
            out.push([p[0], p[1], p[2]]);
        }
    }
    out
}

#[test]
fn exported_geometry_and_planes_are_the_scenes_own() {
    let r = rendered();
    let dir = &r.runs[0];
    let obj = std::fs::read_to_string(dir.join("scene.obj")).unwrap();
    let planes = json(&dir.join("planes.json"));
    let planes = planes["planes"].as_array().unwrap();
    assert_eq!(planes.len(), 2, "one plane per pane");
    for (k, pane) in ["Pane_clear", "Pane_bronze"].iter().enumerate() {
        let want = corners(&r.facts, pane);
        // Multiples of 1/8: exact in float32 and in the OBJ text.
        assert_eq!(obj_vertices(&obj, pane), want, "{pane} corners");
        let (n, d) = plane_of(&want);
        let eq: Vec<f64> = planes[k]["equation"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let s = if eq[0] * n[0] + eq[1] * n[1] + eq[2] * n[2] < 0.0 {
            -1.0
        } else {
            1.0
        };
        for i in 0..3 {
            assert!((eq[i] - s * n[i]).abs() < 1e-12, "{pane}: {eq:?} vs {n:?}");
        }
        assert!((eq[3] - s * d).abs() < 1e-12, "{pane}: d {} vs {d}", eq[3]);
    }
    // The camera of each frame where the scene put it (float32 in Blender).
    let cams = json(&dir.join("camera.json"));
    for f in ["1", "2"] {
        let m = &cams["frames"][f]["matrix_world"];
        let eye = &r.facts["cameras"][f]["eye"];
        for i in 0..3 {
            let got = m[i][3].as_f64().unwrap();
            assert!(
                (got - eye[i].as_f64().unwrap()).abs() < 1e-6,
                "frame {f} eye"
            );
        }
    }
}

fn channel<'a>(p: &'a Planes, suffix: &str) -> &'a [f64] {
    let k = p
        .names
        .iter()
        .position(|n| n == suffix || n.ends_with(&format!(".{suffix}")))
        .unwrap_or_else(|| panic!("no channel {suffix} in {:?}", p.names));
    &p.channels[k]
}

/// Reads one layer of a multilayer EXR by the name of its channels' prefix.
fn read_exr_layer_channel(path: &Path, name_end: &str) -> (usize, usize, Vec<f64>) {
    let image = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    for layer in &image.layer_data {
        for ch in &layer.channel_data.list {
            if ch.name.to_string().ends_with(name_end) {
                let size = layer.size;
                return (
                    size.width(),
                    size.height(),
                    ch.sample_data.values_as_f32().map(f64::from).collect(),
                );
            }
        }
    }
    panic!("no channel {name_end} in {}", path.display());
}

#[test]
fn masks_match_cycles_material_index() {
    let r = rendered();
    for frame in [1, 2] {
        let mask = read_exr_planes(&r.runs[0].join(format!("mask.{frame:04}.exr")));
        let (w, h, index) = read_exr_layer_channel(
            &r.root.join(format!("index/index.{frame:04}.exr")),
            "IndexMA.X",
        );
        assert_eq!((mask.width, mask.height), (w, h));
        let id = channel(&mask, "id");
        // Coverage by default (`--mask-samples 4`): the pixel's id is its centre's glass, or
        // where the centre misses glass, the glass most of its 16 rays see, with that part
        // as its coverage.
        let coverage = channel(&mask, "coverage");
        let glass = index.iter().filter(|&&v| v > 0.0).count();
        assert!(glass > 200, "frame {frame}: {glass} glass pixels");
        let (mut partial, mut beside) = (0, 0);
        for i in 0..w * h {
            let at = (i % w, i / w);
            if index[i] > 0.0 {
                // The centre is on glass: the same id as Cycles'.
                assert_eq!(id[i], index[i], "frame {frame}: pixel {at:?}'s id");
            } else if id[i] > 0.0 {
                // The centre is not: glass covers part of the pixel only.
                assert!(
                    coverage[i] > 0.0 && coverage[i] < 1.0,
                    "frame {frame}: pixel {at:?} off glass at its centre has coverage {}",
                    coverage[i]
                );
                beside += 1;
            }
            if id[i] > 0.0 && coverage[i] < 1.0 {
                partial += 1;
            }
            assert!((0.0..=1.0).contains(&coverage[i]), "frame {frame} {at:?}");
            if id[i] == 0.0 {
                assert_eq!(coverage[i], 0.0, "frame {frame}: {at:?} without glass");
            }
        }
        // The panes' outlines are partly covered pixels (2 panes, ~40 px of edge each).
        assert!(
            partial > 40 && beside > 0,
            "frame {frame}: {partial} partly covered pixels, {beside} off glass at the centre"
        );
    }
}

#[test]
fn reflection_passes_cover_exactly_their_planes_pixels() {
    let r = rendered();
    let dir = &r.runs[0];
    let record = json(&dir.join("glassdb-blender.json"));
    for f in record["frames"].as_array().unwrap() {
        let mask = read_exr_planes(&dir.join(f["mask"].as_str().unwrap()));
        let (id, plane) = (channel(&mask, "id"), channel(&mask, "plane"));
        for (k, refl) in f["refl"].as_array().unwrap().iter().enumerate() {
            let header =
                exr::meta::MetaData::read_from_file(dir.join(refl.as_str().unwrap()), false)
                    .unwrap();
            let h = &header.headers[0];
            let (x0, y0) = (
                h.own_attributes.layer_position.x(),
                h.own_attributes.layer_position.y(),
            );
            let (bw, bh) = (h.layer_size.width() as i32, h.layer_size.height() as i32);
            let mut bbox: Option<[i32; 4]> = None;
            for i in 0..mask.width * mask.height {
                if id[i] > 0.0 && plane[i] as usize == k {
                    let (x, y) = ((i % mask.width) as i32, (i / mask.width) as i32);
                    let b = bbox.get_or_insert([x, y, x, y]);
                    *b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
                }
            }
            let b = bbox.expect("each plane has glass in the tiny scene");
            assert_eq!(
                [x0, y0, x0 + bw - 1, y0 + bh - 1],
                b,
                "plane {k}: data window"
            );
            let display = h.shared_attributes.display_window;
            assert_eq!(
                (display.size.width(), display.size.height()),
                (mask.width, mask.height)
            );
        }
    }
}

/// Mean |a − b| over the pixels `keep` selects, per channel R, G, B.
fn mean_abs(a: &Planes, b: &Planes, keep: &[bool]) -> [f64; 3] {
    let n = keep.iter().filter(|&&k| k).count() as f64;
    ["R", "G", "B"].map(|c| {
        let (x, y) = (channel(a, c), channel(b, c));
        (0..keep.len())
            .filter(|&i| keep[i])
            .map(|i| (x[i] - y[i]).abs())
            .sum::<f64>()
            / n
    })
}

/// Pixels whose 3 × 3 neighbourhood has one id and one plane (Cycles filters its pixels over
/// 1.5 px, glassdb's mask covers each pixel as a box: edges differ by construction).
fn interior(mask: &Planes, glass: bool) -> Vec<bool> {
    let (w, h) = (mask.width as i64, mask.height as i64);
    let id = channel(mask, "id");
    // A mask of one plane has no plane channel: every glass pixel is plane 0.
    let zeros = vec![0.0; id.len()];
    let plane = if mask.names.iter().any(|n| n == "plane") {
        channel(mask, "plane")
    } else {
        &zeros
    };
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let same = (-1..=1).all(|dy| {
                (-1..=1).all(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    (0..w).contains(&u)
                        && (0..h).contains(&v)
                        && id[(v * w + u) as usize] == id[i as usize]
                        && plane[(v * w + u) as usize] == plane[i as usize]
                })
            });
            same && (id[i as usize] > 0.0) == glass
        })
        .collect()
}

#[test]
fn composite_matches_the_cycles_reference_within_its_noise() {
    let r = rendered();
    assert_within_noise(&r.runs, &[1, 2]);
}

/// Each of `frames` of the two runs (seeds 0 and 1, both with `--reference`): the composite of
/// run 0 against the reference of run 1, inside glass and outside, within the noise measured
/// between the two references. Returns the PSNR in glass per frame (peak 1).
fn assert_within_noise(runs: &[PathBuf; 2], frames: &[u32]) -> Vec<f64> {
    let mut psnr = Vec::new();
    for &frame in frames {
        let name = |run: usize, stem: &str| runs[run].join(format!("{stem}.{frame:04}.exr"));
        let mask = read_exr_planes(&name(0, "mask"));
        let comp = read_exr_planes(&name(0, "composite"));
        let reference = [
            read_exr_planes(&name(0, "reference")),
            read_exr_planes(&name(1, "reference")),
        ];
        for glass in [true, false] {
            let keep = interior(&mask, glass);
            assert!(keep.iter().filter(|&&k| k).count() > 100, "frame {frame}");
            // The noise of the samples, measured: the same reference with two seeds.
            let noise = mean_abs(&reference[0], &reference[1], &keep);
            let err = mean_abs(&comp, &reference[1], &keep);
            for c in 0..3 {
                // Two independent estimates differ by √2 σ; the composite (its own noise plus
                // the reference's) may differ by up to about that, with a quarter for what
                // the method leaves out (glass-to-glass reflections, the ramp).
                assert!(
                    err[c] < 1.25 * noise[c] + 0.002,
                    "frame {frame}, glass {glass}, channel {c}: composite error {} vs noise {}",
                    err[c],
                    noise[c]
                );
            }
            if glass {
                let mse = mean_sq(&comp, &reference[1], &keep);
                psnr.push(10.0 * (1.0 / mse).log10());
            }
        }
    }
    psnr
}

/// Mean (a − b)² over the pixels `keep` selects, all of R, G, B.
fn mean_sq(a: &Planes, b: &Planes, keep: &[bool]) -> f64 {
    let n = keep.iter().filter(|&&k| k).count() as f64 * 3.0;
    ["R", "G", "B"]
        .iter()
        .map(|c| {
            let (x, y) = (channel(a, c), channel(b, c));
            (0..keep.len())
                .filter(|&i| keep[i])
                .map(|i| (x[i] - y[i]).powi(2))
                .sum::<f64>()
        })
        .sum::<f64>()
        / n
}

#[test]
fn compose_dir_recomposites_with_another_registry() {
    let r = rendered();
    let dir = r.root.join("recompose");
    copy_dir(&r.runs[0], &dir);
    let first = read_exr_planes(&dir.join("composite.0001.exr"));
    // The bundled registry again: the same composite, sample for sample, and no warning (the
    // run record names the glasses that lit the passes: the bundled ones).
    let record = json(&dir.join("glassdb-blender.json"));
    let lit_by: Vec<u64> = record["lit_by"]
        .as_array()
        .unwrap_or_else(|| panic!("no lit_by in {record}"))
        .iter()
        .map(|g| g["id"].as_u64().unwrap())
        .collect();
    assert_eq!(lit_by, [1, 5], "{record}");
    let (status, _, stderr) = run(glassdb().args(["blender", "compose"]).arg(&dir));
    assert!(
        status.status.success() && !stderr.contains("warning"),
        "{stderr}"
    );
    let again = read_exr_planes(&dir.join("composite.0001.exr"));
    assert_eq!(first.channels, again.channels);
    // Other glasses with the same ids: the glass pixels and the light through them change.
    let registry = r.root.join("atrium.json");
    ok(&mut registry_build(
        &repo_path("fixtures/atrium/catalog.toml"),
        &registry,
        &[],
    ));
    let (status, out, stderr) = run(glassdb()
        .args(["blender", "compose"])
        .arg(&dir)
        .arg("--registry")
        .arg(&registry));
    assert!(status.status.success(), "{stderr}");
    assert!(out.contains("composited 2 frame(s)"), "{out}");
    // The passes keep the light's path apart: the swap relights the room, so no warning, and
    // the pixels away from glass change too (blender/relit.rs checks by how much).
    assert!(!stderr.contains("warning"), "{stderr}");
    let other = read_exr_planes(&dir.join("composite.0001.exr"));
    let mask = read_exr_planes(&dir.join("mask.0001.exr"));
    let id = channel(&mask, "id");
    let r_other = channel(&other, "R");
    let r_first = channel(&first, "R");
    let changed = |glass: bool| {
        (0..id.len())
            .filter(|&i| (id[i] > 0.0) == glass && r_other[i] != r_first[i])
            .count()
    };
    assert!(
        changed(true) > 100,
        "{} glass pixels changed",
        changed(true)
    );
    assert!(
        changed(false) > 100,
        "{} other pixels changed",
        changed(false)
    );
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

/// A stand-in `blender`: prints `version` for --version, else runs `body` (sh).
fn fake_blender(dir: &Path, version: &str, body: &str) -> PathBuf {
    write_executable(
        dir,
        "blender",
        &format!(
            "#!/bin/sh\ncase \"$*\" in *--version*) echo \"Blender {version}\"; exit 0;; esac\n{body}\n"
        ),
    )
}

/// A stand-in Blender 3.4.1, the oldest `glassdb blender` accepts (see [`fake_blender`]).
fn fake_blender_3_4(dir: &Path, body: &str) -> PathBuf {
    fake_blender(dir, "3.4.1", body)
}

fn render_with(blender: &Path, blend: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut cmd = glassdb();
    cmd.args(["blender", "render"])
        .arg(blend)
        .args(["--glass", "Glass*=1", "--out-dir"])
        .arg(out)
        .arg("--blender")
        .arg(blender)
        .args(extra);
    cmd
}

/// A file that starts like a .blend (the stand-ins never read it).
fn blend_stub(dir: &Path) -> PathBuf {
    write_file(dir, "scene.blend", b"BLENDER-v304RENDH")
}

/// A new temporary folder holding a [`blend_stub`]: the folder and the stub's path.
fn folder_with_blend_stub() -> (tempfile::TempDir, PathBuf) {
    let t = tempfile::tempdir().unwrap();
    let blend = blend_stub(t.path());
    (t, blend)
}

#[test]
fn missing_and_old_blender_are_refused() {
    let (t, blend) = folder_with_blend_stub();
    let out = t.path().join("out");
    fails_naming(
        &mut render_with(&t.path().join("no-such-blender"), &blend, &out, &[]),
        &["cannot run Blender", "no-such-blender"],
    );
    let old = fake_blender(t.path(), "2.93.18", "exit 0");
    fails_naming(
        &mut render_with(&old, &blend, &out, &[]),
        &["Blender 2.93.18", "needs Blender 3.4 or newer"],
    );
    let not_blender = write_executable(t.path(), "not-blender", "#!/bin/sh\necho hello\n");
    fails_naming(
        &mut render_with(&not_blender, &blend, &out, &[]),
        &["did not print a Blender version", "hello"],
    );
}

#[test]
fn a_blender_that_writes_nothing_is_named_with_its_log() {
    // It once said "cannot move …/scene.obj: No such file or directory".
    let (t, blend) = folder_with_blend_stub();
    let out = t.path().join("out");
    let silent = fake_blender_3_4(t.path(), "exit 0");
    fails_naming(
        &mut render_with(&silent, &blend, &out, &[]),
        &[
            "Blender 3.4.1",
            &silent.display().to_string(),
            "exited without an error",
            "wrote no scene export: scene.obj, scene.mtl, camera.json, export.json missing",
            &out.join("blender.log").display().to_string(),
        ],
    );
}

#[test]
fn python_without_bpy_is_refused() {
    let (t, blend) = folder_with_blend_stub();
    let mut cmd = glassdb();
    cmd.args(["blender", "render"])
        .arg(&blend)
        .args(["--glass", "Glass*=1", "--out-dir"])
        .arg(t.path().join("out"))
        .args(["--bpy-python", "python3"]);
    fails_naming(
        &mut cmd,
        &[
            "python3 cannot import the bpy module",
            "No module named",
            "bpy==5.0.1",
        ],
    );
}

#[test]
fn crashing_and_hanging_blender_are_reported() {
    let (t, blend) = folder_with_blend_stub();
    let out = t.path().join("out");
    let crash = fake_blender_3_4(
        t.path(),
        "echo 'Writing: /tmp/blender.crash.txt'\nkill -SEGV $$",
    );
    let err = fails_naming(
        &mut render_with(&crash, &blend, &out, &[]),
        &[
            "Blender (export) failed",
            "killed by signal 11",
            "blender.crash.txt",
        ],
    );
    assert!(err.contains("blender.log"), "{err}");
    let hang = fake_blender_3_4(t.path(), "exec sleep 30");
    let started = std::time::Instant::now();
    fails_naming(
        &mut render_with(&hang, &blend, &out, &["--timeout-s", "1"]),
        &["took longer than 1 s", "was stopped"],
    );
    assert!(started.elapsed().as_secs() < 20);
}

/// Whether process `pid` runs (a zombie no one has reaped yet counts as stopped).
fn running(pid: &str) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| {
        stat.rfind(')')
            .is_some_and(|end| !stat[end + 1..].trim_start().starts_with('Z'))
    })
}

/// Waits up to 20 s for `path` to hold a process id.
fn pid_in(path: &Path) -> String {
    let started = std::time::Instant::now();
    loop {
        if let Ok(text) = std::fs::read_to_string(path)
            && text.ends_with('\n')
        {
            return text.trim().to_string();
        }
        assert!(started.elapsed().as_secs() < 20, "no {}", path.display());
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// Asserts that the processes `pids` stop within 5 s.
fn assert_stop(pids: &[String], what: &str) {
    let started = std::time::Instant::now();
    while pids.iter().any(|p| running(p)) {
        assert!(
            started.elapsed().as_secs() < 5,
            "{what}: still running: {:?}",
            pids.iter().filter(|p| running(p)).collect::<Vec<_>>()
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// A render timed out, or glassdb stopped by SIGTERM or SIGINT, leaves nothing of Blender
/// running: not the stand-in, not the child it started (killed as a process group).
#[cfg(unix)]
#[test]
fn a_stopped_or_timed_out_render_leaves_no_blender_running() {
    let (t, blend) = folder_with_blend_stub();
    let pids = t.path().join("pids");
    let blender = fake_blender_3_4(
        t.path(),
        &format!("sleep 300 &\necho \"$! $$\" > {}\nwait", pids.display()),
    );
    let started = std::time::Instant::now();
    fails_naming(
        &mut render_with(
            &blender,
            &blend,
            &t.path().join("out"),
            &["--timeout-s", "1"],
        ),
        &["took longer than 1 s"],
    );
    assert!(started.elapsed().as_secs() < 20);
    let both: Vec<String> = pid_in(&pids).split(' ').map(str::to_string).collect();
    assert_stop(&both, "--timeout-s");

    for (signal, code) in [("TERM", 143), ("INT", 130)] {
        std::fs::remove_file(&pids).unwrap();
        let mut child = render_with(&blender, &blend, &t.path().join("out"), &[])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let both: Vec<String> = pid_in(&pids).split(' ').map(str::to_string).collect();
        assert!(both.iter().all(|p| running(p)), "{both:?}");
        send_signal(&child, signal);
        assert_eq!(child.wait().unwrap().code(), Some(code), "SIG{signal}");
        assert_stop(&both, &format!("SIG{signal}"));
    }
}

/// A scene whose name starts with `-` reaches Blender as a file (`./-dash.blend`), never as
/// an option: Blender 3.4 reads an argument after `-b` that starts with `-` as an option when
/// it is one (`-P`, `-t`), and warns of the others.
#[test]
fn a_scene_named_like_an_option_reaches_blender_as_a_file() {
    let t = tempfile::tempdir().unwrap();
    let seen = t.path().join("args");
    blend_stub(t.path());
    std::fs::rename(t.path().join("scene.blend"), t.path().join("-P")).unwrap();
    let blender = fake_blender_3_4(
        t.path(),
        &format!("printf '%s\\n' \"$@\" > {}\nexit 1", seen.display()),
    );
    let mut cmd = glassdb();
    cmd.current_dir(t.path())
        .args([
            "blender",
            "render",
            "--glass",
            "Glass*=1",
            "--out-dir",
            "out",
            "--blender",
        ])
        .arg(&blender)
        .args(["--", "-P"]);
    fails(&mut cmd);
    let args = std::fs::read_to_string(&seen).unwrap();
    let args: Vec<&str> = args.lines().collect();
    assert_eq!(&args[..2], ["-b", "./-P"], "{args:?}");
}

#[test]
fn bad_scene_files_and_output_dirs_are_refused() {
    let t = tempfile::tempdir().unwrap();
    let fake = fake_blender_3_4(t.path(), "exit 0");
    let text = t.path().join("notes.blend");
    std::fs::write(&text, "just text").unwrap();
    let out = t.path().join("out");
    fails_naming(
        &mut render_with(&fake, &text, &out, &[]),
        &["notes.blend is not a Blender file", "BLENDER"],
    );
    fails_naming(
        &mut render_with(&fake, &t.path().join("missing.blend"), &out, &[]),
        &["missing.blend is not a Blender file"],
    );
    let blend = blend_stub(t.path());
    fails_naming(
        &mut render_with(&fake, &blend, &out, &["--mask-samples", "0"]),
        &["samples"],
    );
    let file = t.path().join("a-file");
    std::fs::write(&file, "").unwrap();
    fails_naming(
        &mut render_with(&fake, &blend, &file.join("out"), &[]),
        &["cannot create the output directory", "a-file"],
    );
}

/// A stand-in `blender` in `dir` whose export writes the room of fixtures/scene with `camera`
/// as camera.json and `frames` in export.json; its render does nothing.
fn exporting_blender(dir: &Path, camera: &serde_json::Value, frames: &[u32]) -> PathBuf {
    let files = dir.join("export");
    std::fs::create_dir_all(&files).unwrap();
    let obj = std::fs::read_to_string(repo_path("fixtures/scene/room.obj")).unwrap();
    write_file(
        &files,
        "scene.obj",
        obj.replace("mtllib room.mtl", "mtllib scene.mtl")
            .as_bytes(),
    );
    std::fs::copy(
        repo_path("fixtures/scene/room.mtl"),
        files.join("scene.mtl"),
    )
    .unwrap();
    write_file(&files, "camera.json", camera.to_string().as_bytes());
    let export = serde_json::json!({
        "blender": "3.4.1",
        "frames": frames,
        "materials": ["Clear_6mm", "Tinted_Grey", "Concrete", "Wood"],
    });
    write_file(&files, "export.json", export.to_string().as_bytes());
    fake_blender_3_4(
        dir,
        &format!(
            "out=; prev=\nfor a in \"$@\"; do [ \"$prev\" = --out ] && out=$a; prev=$a; done\n\
             if [ -n \"$out\" ]; then mkdir -p \"$out\" && cp '{}'/* \"$out\"/; fi",
            files.display()
        ),
    )
}

#[test]
fn exports_without_frames_or_with_frames_of_two_sizes_are_refused() {
    let (t, blend) = folder_with_blend_stub();
    let cam = json(&repo_path("fixtures/scene/camera.json"));
    let mut small = cam.clone();
    (small["width"], small["height"]) = (80.into(), 60.into());
    let camera = serde_json::json!({ "frames": { "1": cam, "2": small } });
    let render = |blender: &Path, out: &str| {
        let mut cmd = glassdb();
        cmd.args(["blender", "render"])
            .arg(&blend)
            .args(["--glass", "Clear*=1", "--out-dir"])
            .arg(t.path().join(out))
            .arg("--blender")
            .arg(blender);
        cmd
    };
    let dir = t.path().join("none");
    std::fs::create_dir(&dir).unwrap();
    let none = exporting_blender(&dir, &camera, &[]);
    fails_naming(
        &mut render(&none, "out-none"),
        &["export.json", "no frames"],
    );
    let dir = t.path().join("two");
    std::fs::create_dir(&dir).unwrap();
    let two = exporting_blender(&dir, &camera, &[1, 2]);
    fails_naming(
        &mut render(&two, "out-two"),
        &["camera.json", "frame 2 is 80x60, but frame 1 is 160x120"],
    );
    // The first frame alone is fine up to the passes, which the stand-in does not render.
    let dir = t.path().join("one");
    std::fs::create_dir(&dir).unwrap();
    let one = exporting_blender(&dir, &camera, &[1]);
    fails_naming(
        &mut render(&one, "out-one"),
        &["trans.0001.exr", "Blender did not write this pass"],
    );
}

#[test]
fn a_scene_without_the_glass_materials_is_refused() {
    let r = rendered();
    let out = r.root.join("no-glass");
    let err = fails_naming(
        glassdb()
            .args(["blender", "render"])
            .arg(&r.blend)
            .args(["--glass", "Glazing*=1", "--out-dir"])
            .arg(&out),
        &["Glazing*"],
    );
    // The message lists the scene's materials.
    for m in ["Glass_clear", "Tinted_bronze", "Floor"] {
        assert!(err.contains(m), "{err}");
    }
}

/// `scripts/blender/make_default_scene.py --scene KIND` saved as `dir/KIND.blend` (with its
/// facts in `dir/KIND.json`): a scene as people leave it (Blender's factory settings, Cycles).
pub(crate) fn default_scene(dir: &Path, kind: &str) -> PathBuf {
    let blend = dir.join(format!("{kind}.blend"));
    let facts = dir.join(format!("{kind}.json"));
    make_scene(
        "scripts/blender/make_default_scene.py",
        kind,
        &blend,
        &["--facts".as_ref(), facts.as_os_str()],
    );
    blend
}

#[test]
fn a_scene_saved_with_blenders_defaults_renders_without_denoising() {
    // Blender's default scene denoises; Debian's Blender has no OpenImageDenoise ("Build
    // without OpenImageDenoiser"), and denoised passes would not be noise-honest anyway.
    let dir = tempfile::tempdir().unwrap();
    let blend = default_scene(dir.path(), "defaults");
    let out = dir.path().join("run");
    let stdout = ok(glassdb()
        .args(["blender", "render"])
        .arg(&blend)
        .args(["--glass", "Glass=1", "--out-dir"])
        .arg(&out)
        .args(["--frames", "1", "--samples", "4", "--resolution", "64x36"])
        .args(["--threads", "2"]));
    assert!(stdout.contains("denoising off"), "{stdout}");
    let record = json(&out.join("glassdb-blender.json"));
    let overrides = record["overrides"].as_array().expect("the record says");
    assert!(
        overrides
            .iter()
            .any(|o| o.as_str().unwrap().starts_with("denoising off")),
        "{record}"
    );
    let log = std::fs::read_to_string(out.join("blender.log")).unwrap();
    assert!(log.contains("glassdb_blender: denoising off"), "{log}");
    let comp = read_exr_planes(&out.join("composite.0001.exr"));
    assert_eq!((comp.width, comp.height), (64, 36));
    let mask = read_exr_planes(&out.join("mask.0001.exr"));
    assert!(channel(&mask, "id").iter().filter(|&&v| v == 1.0).count() > 50);
}

#[test]
fn animated_objects_lights_and_a_sliding_pane_composite_within_cycles_noise() {
    // Frames 1-3: the window slides along itself (a sliding door), the cube behind it and a box
    // on the camera's side (seen in the reflection) move, the light moves, a post in front of
    // the glass is hidden in frame 1 and shown from frame 2 on; the camera is still.
    // Once refused ("object Cube moves between frames"); now each frame whose objects moved
    // has its own scene, planes and mask.
    let dir = tempfile::tempdir().unwrap();
    let blend = default_scene(dir.path(), "animated");
    let runs = [dir.path().join("run0"), dir.path().join("run1")];
    for (seed, run) in runs.iter().enumerate() {
        let stdout = ok(glassdb()
            .args(["blender", "render"])
            .arg(&blend)
            .args(["--glass", "Glass=1", "--out-dir"])
            .arg(run)
            .args(["--samples", "16", "--resolution", "64x48", "--threads", "2"])
            .args(["--reference", "--seed", &seed.to_string()]));
        assert!(stdout.contains("3 frame(s), 1 glass plane(s)"), "{stdout}");
    }
    let run = &runs[0];
    let export = json(&run.join("export.json"));
    for f in ["2", "3"] {
        let moved = export["moving"][f]["objects"].as_array().unwrap();
        for name in ["Window", "Cube", "Box_behind_camera", "Post"] {
            assert!(moved.iter().any(|m| m == name), "frame {f}: {export}");
        }
    }
    // The sliding pane: the same plane, other pixels, every frame.
    let planes: Vec<serde_json::Value> = ["planes.json", "planes.0002/planes.json"]
        .iter()
        .map(|p| json(&run.join(p)))
        .collect();
    assert_eq!(planes[0]["planes"].as_array().unwrap().len(), 1);
    let equation = |p: &serde_json::Value| -> Vec<f64> {
        p["planes"][0]["equation"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    for (a, b) in equation(&planes[0]).iter().zip(equation(&planes[1])) {
        assert!((a - b).abs() < 1e-6, "{planes:?}");
    }
    let glass = |f: u32| -> Vec<bool> {
        let m = read_exr_planes(&run.join(format!("mask.{f:04}.exr")));
        channel(&m, "id").iter().map(|&v| v > 0.0).collect()
    };
    assert_ne!(glass(1), glass(3), "the pane slid: its pixels differ");
    let psnr = assert_within_noise(&runs, &[1, 2, 3]);
    eprintln!("animated scene, PSNR in glass per frame (dB): {psnr:.2?}");
}

#[test]
fn lamps_show_in_the_reflections_as_the_glass_reflects_them() {
    // The `lamps` scene: a reflective film pane at dusk reflecting a warm area lamp and the
    // low sun's glint (lamps, which camera rays do not see), with a bulb behind the glass that
    // camera rays see and the mirror must not show. Once the reflection pass, rendered by a
    // mirrored camera, had neither lamp (the composite's glass 5.5 too dark in red on average,
    // −21 dB in glass) and would have shown the bulb.
    let dir = tempfile::tempdir().unwrap();
    let blend = dir.path().join("lamps.blend");
    make_scene(
        "scripts/blender/make_glassdb_scene.py",
        "lamps",
        &blend,
        &[],
    );
    let runs = [dir.path().join("run0"), dir.path().join("run1")];
    for (seed, run) in runs.iter().enumerate() {
        ok(glassdb()
            .args(["blender", "render"])
            .arg(&blend)
            .args(["--glass", "Glass_film=10", "--out-dir"])
            .arg(run)
            .args(["--reference", "--threads", "2", "--seed", &seed.to_string()]));
    }
    let psnr = assert_within_noise(&runs, &[1]);
    // The light the glass reflects, summed over the glass: the composite's within a tenth of
    // the reference's (without the lamps it lacks nine tenths of it).
    let mask = read_exr_planes(&runs[0].join("mask.0001.exr"));
    let glass: Vec<bool> = channel(&mask, "id").iter().map(|&v| v > 0.0).collect();
    let comp = read_exr_planes(&runs[0].join("composite.0001.exr"));
    let reference = read_exr_planes(&runs[1].join("reference.0001.exr"));
    let n = glass.iter().filter(|&&g| g).count() as f64;
    let glass_mean = |p: &Planes| {
        ["R", "G", "B"].map(|c| {
            let x = channel(p, c);
            (0..x.len())
                .filter(|&i| glass[i])
                .map(|i| x[i])
                .sum::<f64>()
                / n
        })
    };
    let (c, r) = (glass_mean(&comp), glass_mean(&reference));
    for k in 0..3 {
        assert!(
            (c[k] - r[k]).abs() < 0.1 * r[k],
            "channel {k}: glass mean {} against the reference's {}",
            c[k],
            r[k]
        );
    }
    eprintln!("lamps scene, PSNR in glass (dB): {psnr:.2?}; glass mean {c:.3?} vs {r:.3?}");
}
