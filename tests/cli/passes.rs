//! Passes as renderers write them (issue 12): inputs placed by their EXR pixel coordinates
//! (OpenEXR's DisplayWindow samples, cropped masks and passes), layers chosen per input
//! (Blender 3.4 single-part and 5.0 multi-part renders, views), alpha, and what the output
//! carries over (windows, attributes, other channels). Outputs are read with the `exr` crate,
//! never with glassdb's own decoder.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use exr::prelude::{FlatSamples, ReadChannels, ReadLayers};
use glassdb_image::{
    ExrImageOut, ExrPartOut, ExrPlane, ExrStorage, ExrWriteOptions, PixelWindow, PlaneSamples,
};
use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};

use std::ffi::OsStr;
use std::process::Command;

use crate::util::{compose, fails, ok, oracle_python, repo_path, run, run_oracle};

/// One part of an EXR as the `exr` crate reads it.
pub(crate) struct Part {
    name: Option<String>,
    data: PixelWindow,
    pub(crate) channels: HashMap<String, Vec<f32>>,
    types: HashMap<String, &'static str>,
    other: HashMap<String, String>,
}

/// Every part of an EXR (largest level), read with the `exr` crate, and the display window
/// and shared text attributes.
pub(crate) fn read_parts(path: &Path) -> (PixelWindow, HashMap<String, String>, Vec<Part>) {
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_file(path)
        .unwrap_or_else(|e| panic!("reading {} with the exr crate: {e}", path.display()));
    let text = |m: &HashMap<exr::meta::attribute::Text, exr::meta::attribute::AttributeValue>| {
        m.iter()
            .filter_map(|(k, v)| match v {
                exr::meta::attribute::AttributeValue::Text(t) => {
                    Some((k.to_string(), t.to_string()))
                }
                _ => None,
            })
            .collect::<HashMap<_, _>>()
    };
    let d = image.attributes.display_window;
    let display = PixelWindow {
        x: d.position.x(),
        y: d.position.y(),
        width: d.size.width(),
        height: d.size.height(),
    };
    let shared = text(&image.attributes.other);
    let parts = image
        .layer_data
        .iter()
        .map(|l| Part {
            name: l.attributes.layer_name.as_ref().map(|t| t.to_string()),
            data: PixelWindow {
                x: l.attributes.layer_position.x(),
                y: l.attributes.layer_position.y(),
                width: l.size.width(),
                height: l.size.height(),
            },
            channels: l
                .channel_data
                .list
                .iter()
                .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
                .collect(),
            types: l
                .channel_data
                .list
                .iter()
                .map(|c| {
                    let ty = match c.sample_data {
                        FlatSamples::F16(_) => "half",
                        FlatSamples::F32(_) => "float",
                        FlatSamples::U32(_) => "uint",
                    };
                    (c.name.to_string(), ty)
                })
                .collect(),
            other: text(&l.attributes.other),
        })
        .collect();
    (display, shared, parts)
}

/// A constant-curve registry (r, t the same at every angle): ids 1 and 5, distinct per channel.
/// Per glass id, its (r, t) per channel.
type GlassValues = HashMap<u16, ([f32; 3], [f32; 3])>;

fn registry(dir: &Path) -> (PathBuf, GlassValues) {
    let c = serde_json::json!({
        "basis": "full", "powers": [0], "coefficients": [1.0], "degree": 0, "rms_error": 0.0,
        "max_abs_error": 0.0, "max_error_angle_deg": 0.0, "condition_number": 1.0, "tolerance": 0.0
    });
    let values: GlassValues = [
        (1, ([0.25, 0.125, 0.0625], [0.5, 0.25, 0.125])),
        (5, ([0.125, 0.25, 0.5], [0.25, 0.5, 0.125])),
    ]
    .into();
    let glasses: Vec<serde_json::Value> = [1u16, 5]
        .iter()
        .map(|id| {
            let (r0, t0) = values[id];
            serde_json::json!({
                "id": id, "name": format!("test glass {id}"), "r0": r0, "t0": t0, "r0_back": r0,
                "c_r": [c, c, c], "c_t": [c, c, c], "c_r_back": [c, c, c],
                "angle_model": {"kind": "measured", "applied": "per-channel"}, "provenance": {}
            })
        })
        .collect();
    let reg =
        serde_json::json!({"schema": 2, "spectral": {"method": "luminous"}, "glasses": glasses});
    let p = dir.join("registry.json");
    std::fs::write(&p, serde_json::to_string_pretty(&reg).unwrap()).unwrap();
    (p, values)
}

/// A new temporary folder holding the constant-curve [`registry`]: the folder, the registry's
/// path and its values.
fn folder_with_registry() -> (tempfile::TempDir, PathBuf, GlassValues) {
    let dir = tempfile::tempdir().unwrap();
    let (reg, values) = registry(dir.path());
    (dir, reg, values)
}

/// OpenEXR's sample image `fixtures/exr_windows/NAME.exr` (t01: full frame, t08: data window
/// larger than the display window).
fn openexr_sample(name: &str) -> PathBuf {
    repo_path(&format!("fixtures/exr_windows/{name}.exr"))
}

/// An 8-bit packed mask PNG of `w × h`, `dir/m.png`: glass `id` at cos θ = 1 inside `rect` (x0,
/// y0, x1, y1 inclusive, in the PNG's pixels), none elsewhere. Returns its path.
fn rect_mask_png(dir: &Path, w: usize, h: usize, rect: [usize; 4], id: u16) -> PathBuf {
    let path = dir.join("m.png");
    let inside = |i: usize| {
        let (x, y) = (i % w, i / w);
        x >= rect[0] && x <= rect[2] && y >= rect[1] && y <= rect[3]
    };
    let n = w * h;
    let mask = MaskImage {
        width: w as u32,
        height: h as u32,
        id: (0..n).map(|i| if inside(i) { id } else { 0 }).collect(),
        cos_theta: CosTheta::Quantized8((0..n).map(|i| if inside(i) { 255 } else { 0 }).collect()),
        plane: vec![0; n],
        coverage: None,
    };
    write_mask(&path, &mask, MaskFormat::Png8).unwrap();
    path
}

/// `compose` of the reflection passes `refl`, the transmission pass `trans` (a path, or
/// `path:LAYER`), the mask and the registry; callers add the output and any other flag.
fn compose_cmd(refl: &[&Path], trans: impl AsRef<OsStr>, mask: &Path, registry: &Path) -> Command {
    let mut c = compose();
    for r in refl {
        c.arg("--refl").arg(r);
    }
    c.arg("--trans").arg(trans).arg("--mask").arg(mask);
    c.arg("--registry").arg(registry);
    c
}

/// Writes `image` with ZIP compression, its converted planes stored as `storage`.
fn write_exr(path: &Path, image: ExrImageOut, storage: ExrStorage) {
    let mut bytes = std::io::Cursor::new(Vec::new());
    let options = ExrWriteOptions {
        storage,
        compression: exr::compression::Compression::ZIP16,
        zip_level: None,
    };
    glassdb_image::write_exr_image(&mut bytes, image, options).unwrap();
    std::fs::write(path, bytes.into_inner()).unwrap();
}

/// The shared attributes of a file framing `display`.
fn attributes_for(display: PixelWindow) -> glassdb_image::ExrImageAttributes {
    glassdb_image::ExrImageAttributes::new(exr::meta::attribute::IntegerBounds::new(
        (display.x, display.y),
        (display.width, display.height),
    ))
}

/// A reflection pass of the constant colour (8, 16, 32) holding `data` inside `display`.
fn write_constant_refl(path: &Path, display: PixelWindow, data: PixelWindow) {
    let n = data.width * data.height;
    let planes = rgb_planes(vec![8.0; n], vec![16.0; n], vec![32.0; n]);
    write_windowed_exr(path, display, data, planes);
}

/// Planes R, G, B for [`write_windowed_exr`].
fn rgb_planes(r: Vec<f32>, g: Vec<f32>, b: Vec<f32>) -> Vec<(&'static str, Vec<f32>)> {
    vec![("R", r), ("G", g), ("B", b)]
}

fn window(x: i32, y: i32, width: usize, height: usize) -> PixelWindow {
    PixelWindow {
        x,
        y,
        width,
        height,
    }
}

/// Writes float planes (name, samples) as one part holding `data` inside `display`.
fn write_windowed_exr(
    path: &Path,
    display: PixelWindow,
    data: PixelWindow,
    planes: Vec<(&str, Vec<f32>)>,
) {
    let image = ExrImageOut {
        display_window: display,
        attributes: attributes_for(display),
        parts: vec![ExrPartOut {
            data_window: data,
            attributes: Default::default(),
            planes: planes
                .into_iter()
                .map(|(n, v)| ExrPlane::new(n, v))
                .collect(),
        }],
    };
    write_exr(path, image, ExrStorage::Float);
}

/// Writes float planes (name, samples) as one part holding the whole `frame`; returns `path`.
fn write_full_frame_exr(
    path: PathBuf,
    frame: PixelWindow,
    planes: Vec<(&str, Vec<f32>)>,
) -> PathBuf {
    write_windowed_exr(&path, frame, frame, planes);
    path
}

/// The sample of `channel` at absolute pixel (x, y) of a part, if its data window holds it.
fn at(part: &Part, channel: &str, x: i64, y: i64) -> Option<f32> {
    part.data.index_of(x, y).map(|i| part.channels[channel][i])
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-6 * b.abs().max(1.0)
}

#[test]
fn cropped_openexr_sample_keeps_its_windows_and_every_pixel_its_place() {
    // OpenEXR's t08: data (30, 40)–(429, 339) in a (0, 0)–(500, 400) frame. The mask covers the
    // display window; its glass rectangle straddles the data window's top-left corner, so
    // pixels in the rectangle but outside the data window must not show up anywhere.
    let (dir, reg, values) = folder_with_registry();
    let t08 = openexr_sample("t08");
    let rect = [10, 20, 120, 90];
    let mask = rect_mask_png(dir.path(), 501, 401, rect, 1);
    let out = dir.path().join("o.exr");
    ok(compose_cmd(&[&t08], &t08, &mask, &reg)
        .args(["--data-type", "float", "-o"])
        .arg(&out));
    let (in_display, _, input) = read_parts(&t08);
    let (out_display, shared, output) = read_parts(&out);
    assert_eq!(out_display, in_display);
    assert_eq!(
        output[0].data, input[0].data,
        "the output keeps the data window"
    );
    let (r0, t0) = values[&1];
    let mut glass = 0;
    for y in 40..340i64 {
        for x in 30..430i64 {
            let in_rect = x >= rect[0] as i64
                && x <= rect[2] as i64
                && y >= rect[1] as i64
                && y <= rect[3] as i64;
            glass += usize::from(in_rect);
            for (c, name) in ["R", "G", "B"].iter().enumerate() {
                let v = at(&input[0], name, x, y).unwrap();
                let want = if in_rect { v * (r0[c] + t0[c]) } else { v };
                let got = at(&output[0], name, x, y).unwrap();
                assert!(
                    close(got, want),
                    "({x}, {y}) {name}: got {got}, want {want}"
                );
            }
        }
    }
    assert_eq!(glass, (120 - 30 + 1) * (90 - 40 + 1));
    // Custom attributes are read back as the part's own or as shared ones, by reader.
    let attr = |k: &str| shared.get(k).or_else(|| output[0].other.get(k)).cloned();
    assert_eq!(
        attr("glassdb/version").as_deref(),
        Some(env!("CARGO_PKG_VERSION"))
    );
    assert_eq!(attr("glassdb/registrySha256").map(|h| h.len()), Some(64));

    // The same composite as the independent Python reader (OpenEXR's own bindings) sees it;
    // the same check fails on t01's pixels (the same values stored at (0, 0)): it sees shifts.
    let gain: Vec<String> = (0..3).map(|c| (r0[c] + t0[c]).to_string()).collect();
    let check = |input: &Path| -> Vec<std::ffi::OsString> {
        let gain = gain.join(",");
        let args: [&OsStr; 9] = [
            "check-composite".as_ref(),
            "--input".as_ref(),
            input.as_os_str(),
            "--output".as_ref(),
            out.as_os_str(),
            "--mask".as_ref(),
            mask.as_os_str(),
            "--gain".as_ref(),
            gain.as_ref(),
        ];
        args.iter().map(|a| a.to_os_string()).collect()
    };
    let args = check(&t08);
    run_oracle(
        "exr_oracle.py",
        &args.iter().map(|a| a.as_os_str()).collect::<Vec<_>>(),
    );
    let shifted = check(&openexr_sample("t01"));
    let (status, _, stderr) = run(Command::new(oracle_python())
        .arg(repo_path("python_oracle/exr_oracle.py"))
        .args(&shifted));
    assert!(
        !status.status.success(),
        "the oracle must see a shifted input: {stderr}"
    );
}

#[test]
fn cropped_mask_and_cropped_reflection_are_placed_by_coordinates() {
    // Full-frame 400×300 passes (OpenEXR's t01); an EXR mask holding only (100, 50)–(149, 89);
    // a reflection pass holding only (90, 40)–(199, 139), filled with a constant.
    let (dir, reg, values) = folder_with_registry();
    let t01 = openexr_sample("t01");
    let frame = PixelWindow::at_origin(400, 300);
    let mask_window = PixelWindow {
        x: 100,
        y: 50,
        width: 50,
        height: 40,
    };
    let mask = dir.path().join("m.exr");
    let n = mask_window.width * mask_window.height;
    write_windowed_exr(
        &mask,
        frame,
        mask_window,
        vec![("id", vec![5.0; n]), ("cos_theta", vec![1.0; n])],
    );
    let refl = dir.path().join("refl.exr");
    write_constant_refl(&refl, frame, window(90, 40, 110, 100));
    let out = dir.path().join("o.exr");
    let cmd = |refl: &Path, out: &Path| {
        let mut c = compose_cmd(&[refl], &t01, &mask, &reg);
        c.args(["--data-type", "float", "-o"]).arg(out);
        c
    };
    ok(&mut cmd(&refl, &out));
    let (_, _, input) = read_parts(&t01);
    let (_, _, output) = read_parts(&out);
    assert_eq!(output[0].data, frame);
    let (r0, t0) = values[&5];
    for y in 0..300i64 {
        for x in 0..400i64 {
            let glass = mask_window.contains(x, y);
            for (c, (name, refl_value)) in [("R", 8.0), ("G", 16.0), ("B", 32.0)].iter().enumerate()
            {
                let v = at(&input[0], name, x, y).unwrap();
                let want = if glass {
                    v * t0[c] + refl_value * r0[c]
                } else {
                    v
                };
                let got = at(&output[0], name, x, y).unwrap();
                assert!(
                    close(got, want),
                    "({x}, {y}) {name}: got {got}, want {want}"
                );
            }
        }
    }

    // A reflection pass that misses part of its plane's glass: refused with the plane, the
    // count and the bounding box, unless told what to do.
    let small_refl = dir.path().join("small.exr");
    write_constant_refl(&small_refl, frame, window(120, 60, 100, 100));
    let refused = dir.path().join("refused.exr");
    let err = fails(&mut cmd(&small_refl, &refused));
    // Outside (120, 60)–(219, 159): x 100–119 for y 50–89, and y 50–59 for x 120–149.
    let outside = 20 * 40 + 30 * 10;
    for part in [
        "plane 0".to_string(),
        format!("{outside} glass pixels"),
        "(120, 60)–(219, 159)".into(),
        "(100, 50)–(149, 89)".into(),
        "--outside-pass".into(),
    ] {
        assert!(err.contains(&part), "{part} missing: {err}");
    }
    assert!(!refused.exists());
    for (mode, keeps_trans) in [("no-reflection", false), ("transmission", true)] {
        let o = dir.path().join(format!("{mode}.exr"));
        let (status, _, stderr) = run(cmd(&small_refl, &o).args(["--outside-pass", mode]));
        assert!(status.status.success(), "{stderr}");
        assert!(
            stderr.contains(&format!("{outside} glass pixels lie outside")),
            "{stderr}"
        );
        let (_, _, got) = read_parts(&o);
        let (x, y) = (100, 50); // glass, outside the small pass
        for (c, name) in ["R", "G", "B"].iter().enumerate() {
            let v = at(&input[0], name, x, y).unwrap();
            let want = if keeps_trans { v } else { v * t0[c] };
            assert!(
                close(at(&got[0], name, x, y).unwrap(), want),
                "{mode} {name}"
            );
        }
    }
}

#[test]
fn frames_that_differ_and_masks_without_planes_are_refused() {
    let (dir, reg, _) = folder_with_registry();
    let t01 = openexr_sample("t01");
    let t08 = openexr_sample("t08");
    let mask = rect_mask_png(dir.path(), 400, 300, [0, 0, 9, 9], 1);
    let err = fails(
        compose_cmd(&[&t08], &t01, &mask, &reg)
            .arg("-o")
            .arg(dir.path().join("o.exr")),
    );
    for part in [
        "t08.exr",
        "(0, 0)–(500, 400)",
        "(0, 0)–(399, 299)",
        "same frame",
    ] {
        assert!(err.contains(part), "{part} missing: {err}");
    }
    // An EXR mask without a plane channel cannot say which of two passes a pixel takes.
    let frame = PixelWindow::at_origin(400, 300);
    let n = 400 * 300;
    let exr_mask = write_full_frame_exr(
        dir.path().join("m.exr"),
        frame,
        vec![("id", vec![1.0; n]), ("cos_theta", vec![1.0; n])],
    );
    let err = fails(
        compose_cmd(&[&t01, &t01], &t01, &exr_mask, &reg)
            .arg("-o")
            .arg(dir.path().join("o2.exr")),
    );
    assert!(
        err.contains("stores no plane per pixel") && err.contains("2 reflection passes"),
        "{err}"
    );
    assert!(err.contains("--mask-channels plane="), "{err}");
}

/// Composites a Blender render with itself as both passes, the mask read from its own Material
/// Index pass and `facing` AOV, and checks every pixel against the render's own channels.
fn blender_composite(dir: &Path, render: &str, extra: &[&str]) -> (PathBuf, PathBuf) {
    let (reg, _) = registry(dir);
    let file = repo_path(render);
    let out = dir.join(format!("{}.exr", render.replace('/', "_")));
    ok(compose_cmd(&[&file], &file, &file, &reg)
        .args(["--mask-channels", "id=IndexMA,cos=facing"])
        .args(["--data-type", "float"])
        .args(extra)
        .arg("-o")
        .arg(&out));
    (file, out)
}

#[test]
fn blender_3_and_5_renders_composite_with_the_same_command_line() {
    let (dir, _, values) = folder_with_registry();
    for (render, multi_part, index) in [
        (
            "fixtures/blender/b34/multilayer.exr",
            false,
            "ViewLayer.IndexMA.X",
        ),
        (
            "fixtures/blender/b50/multilayer.exr",
            true,
            "ViewLayer.Material Index.X",
        ),
    ] {
        let (file, out) = blender_composite(dir.path(), render, &[]);
        let (_, _, input) = read_parts(&file);
        let (_, shared, output) = read_parts(&out);
        assert_eq!(output.len(), input.len(), "{render}: every part is kept");
        assert_eq!(output.len() > 1, multi_part);
        let find = |parts: &[Part], channel: &str| -> usize {
            parts
                .iter()
                .position(|p| p.channels.contains_key(channel))
                .unwrap_or_else(|| panic!("{render}: no {channel}"))
        };
        let (ip, op) = (
            find(&input, "ViewLayer.Combined.R"),
            find(&output, "ViewLayer.Combined.R"),
        );
        let ids = &input[find(&input, index)].channels[index];
        let mut glass = [0usize; 2];
        for (i, &id) in ids.iter().enumerate() {
            let g = values.get(&(id as u16));
            for (c, ch) in ["R", "G", "B"].iter().enumerate() {
                let name = format!("ViewLayer.Combined.{ch}");
                let v = input[ip].channels[&name][i];
                let want = g.map_or(v, |(r0, t0)| v * (r0[c] + t0[c]));
                let got = output[op].channels[&name][i];
                assert!(
                    (got - want).abs() <= 1e-3 * want.abs().max(1e-3),
                    "{render} pixel {i} {ch}: {got} vs {want}"
                );
            }
            if id == 1.0 {
                glass[0] += 1
            }
            if id == 5.0 {
                glass[1] += 1
            }
        }
        assert_eq!(
            glass,
            [687, 109],
            "{render}: the fixture's glass pixel counts (fixtures/blender/README.md)"
        );
        // Other channels and attributes come through unchanged; the Combined alpha too.
        for (channel, part) in [
            ("ViewLayer.Depth.Z", "depth"),
            ("ViewLayer.Combined.A", "alpha"),
            ("ViewLayer.CryptoMaterial00.r", "cryptomatte"),
        ] {
            let (a, b) = (find(&input, channel), find(&output, channel));
            assert_eq!(
                input[a].channels[channel], output[b].channels[channel],
                "{render}: {part}"
            );
            assert_eq!(
                input[a].types[channel], output[b].types[channel],
                "{render}: {part} sample type"
            );
        }
        let renderer_attr = output
            .iter()
            .any(|p| p.other.keys().any(|k| k.starts_with("cryptomatte/")))
            || shared.keys().any(|k| k.starts_with("cryptomatte/"));
        assert!(
            renderer_attr,
            "{render}: the renderer's attributes are kept"
        );
        assert!(output.iter().all(|p| p.name.is_some()) || !multi_part);
    }
}

#[test]
fn a_composite_is_composited_again() {
    // A composite is a transmission pass like any other: its glassdb/* attributes (the run that
    // wrote it) are replaced by this run's, in a single-part file (its attributes carried) and a
    // multi-part one (every part carried). Both once failed at the write: "duplicate attribute
    // name: `glassdb/version`".
    let (dir, reg, values) = folder_with_registry();
    let (r0, t0) = values[&1];
    let t08 = openexr_sample("t08");
    let mask = rect_mask_png(dir.path(), 501, 401, [10, 20, 120, 90], 1);
    let once = dir.path().join("once.exr");
    ok(compose_cmd(&[&t08], &t08, &mask, &reg)
        .args(["--data-type", "float", "-o"])
        .arg(&once));
    let reg2 = dir.path().join("second.json");
    std::fs::copy(&reg, &reg2).unwrap();
    let twice = dir.path().join("twice.exr");
    ok(compose_cmd(&[&t08], &once, &mask, &reg2)
        .args(["--data-type", "float", "-o"])
        .arg(&twice));
    let (_, _, input) = read_parts(&t08);
    let (_, shared, output) = read_parts(&twice);
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        let v = at(&input[0], name, 50, 50).unwrap();
        let want = v * r0[c] + v * (r0[c] + t0[c]) * t0[c];
        let got = at(&output[0], name, 50, 50).unwrap();
        assert!(close(got, want), "{name}: got {got}, want {want}");
    }
    // The attributes are this run's: every copy of them (multi-part files hold them in each
    // part) names the second registry, and the file reads back.
    let provenance_is = |shared: &HashMap<String, String>, parts: &[Part], registry: &Path| {
        let values: Vec<&String> = std::iter::once(shared)
            .chain(parts.iter().map(|p| &p.other))
            .filter_map(|m| m.get("glassdb/registry"))
            .collect();
        assert!(!values.is_empty(), "glassdb/registry is written");
        for v in values {
            assert_eq!(v, &registry.display().to_string());
        }
    };
    provenance_is(&shared, &output, &reg2);

    let render = "fixtures/blender/b50/multilayer.exr";
    let (file, once) = blender_composite(dir.path(), render, &[]);
    let twice = dir.path().join("twice_b50.exr");
    ok(compose_cmd(&[&file], &once, &file, &reg2)
        .args(["--mask-channels", "id=IndexMA,cos=facing"])
        .args(["--data-type", "float", "-o"])
        .arg(&twice));
    let (_, shared, output) = read_parts(&twice);
    assert_eq!(
        output.len(),
        read_parts(&file).2.len(),
        "every part is kept"
    );
    provenance_is(&shared, &output, &reg2);
}

#[test]
fn keep_channels_none_and_an_output_layer() {
    let dir = tempfile::tempdir().unwrap();
    let render = "fixtures/blender/b34/multilayer.exr";
    let (_, only) = blender_composite(dir.path(), render, &["--keep-channels", "none"]);
    let (_, _, parts) = read_parts(&only);
    let mut names: Vec<&String> = parts[0].channels.keys().collect();
    names.sort();
    assert_eq!(names, ["A", "B", "G", "R"]);

    let (file, beside) = blender_composite(dir.path(), render, &["--output-layer", "glassdb"]);
    let (_, _, input) = read_parts(&file);
    let (_, _, output) = read_parts(&beside);
    assert_eq!(
        input[0].channels["ViewLayer.Combined.R"], output[0].channels["ViewLayer.Combined.R"],
        "the original layer stays"
    );
    assert!(
        output[0].channels.contains_key("glassdb.R")
            && output[0].channels.contains_key("glassdb.A")
    );
    let (_, _, replaced) = read_parts(&blender_composite(dir.path(), render, &[]).1);
    assert_eq!(
        replaced[0].channels["ViewLayer.Combined.G"],
        output[0].channels["glassdb.G"]
    );
}

#[test]
fn layers_are_chosen_per_input_by_file_and_flag() {
    // A stereo pair in one part (OpenEXR's multi-view layout: the hero view `left` in the bare
    // channels, `right.*` for the other) as the transmission pass; each view picked by name.
    let (dir, reg, values) = folder_with_registry();
    let frame = PixelWindow::at_origin(4, 2);
    let stereo = dir.path().join("stereo.exr");
    let attributes = glassdb_image::ExrLayerAttributes {
        multi_view_names: Some(vec!["left".into(), "right".into()]),
        ..Default::default()
    };
    let plane = |v: f32| PlaneSamples::Converted(vec![v; 8]);
    let image = ExrImageOut {
        display_window: frame,
        attributes: attributes_for(frame),
        parts: vec![ExrPartOut {
            data_window: frame,
            attributes,
            planes: [
                ("R", 1.0),
                ("G", 2.0),
                ("B", 3.0),
                ("right.R", 10.0),
                ("right.G", 20.0),
                ("right.B", 30.0),
            ]
            .into_iter()
            .map(|(n, v)| ExrPlane {
                name: n.into(),
                samples: plane(v),
                linear: false,
            })
            .collect(),
        }],
    };
    write_exr(&stereo, image, ExrStorage::Float);
    let mask = rect_mask_png(dir.path(), 4, 2, [0, 0, 3, 1], 1);
    let (r0, t0) = values[&1];
    let composite = |trans: String, extra: &[&str]| -> [f32; 3] {
        let out = dir.path().join("o.exr");
        ok(compose_cmd(&[&stereo], &trans, &mask, &reg)
            .args(["--data-type", "float", "--keep-channels", "none"])
            .args(extra)
            .arg("-o")
            .arg(&out));
        let (_, _, p) = read_parts(&out);
        ["R", "G", "B"].map(|c| p[0].channels[c][0])
    };
    let s = stereo.display().to_string();
    // Reflection: the default (hero, left) layer: 1, 2, 3.
    let want = |trans: [f32; 3]| -> [f32; 3] {
        std::array::from_fn(|c| trans[c] * t0[c] + [1.0, 2.0, 3.0][c] * r0[c])
    };
    assert_eq!(
        composite(format!("{s}:right"), &[]),
        want([10.0, 20.0, 30.0])
    );
    assert_eq!(composite(format!("{s}:left"), &[]), want([1.0, 2.0, 3.0]));
    assert_eq!(
        composite(s.clone(), &["--trans-layer", "right"]),
        want([10.0, 20.0, 30.0])
    );
    // FILE:LAYER wins over the flag; --refl-layer applies to the reflection passes.
    let right_refl: [f32; 3] = std::array::from_fn(|c| {
        10.0 * [1.0, 2.0, 3.0][c] * t0[c] + 10.0 * [1.0, 2.0, 3.0][c] * r0[c]
    });
    assert_eq!(
        composite(
            format!("{s}:right"),
            &["--trans-layer", "left", "--refl-layer", "right"]
        ),
        right_refl
    );
    let err = fails(
        compose_cmd(&[&stereo], format!("{s}:centre"), &mask, &reg)
            .arg("-o")
            .arg(dir.path().join("x.exr")),
    );
    assert!(
        err.contains("no RGB layer \"centre\"")
            && err.contains("right")
            && err.contains("--trans-layer"),
        "{err}"
    );
}

#[test]
fn png_alpha_is_straight_and_exr_alpha_premultiplied() {
    // A premultiplied EXR pixel (0.25, 0.25, 0.25, A 0.5) without glass is straight 0.5 in PNG.
    let (dir, reg, _) = folder_with_registry();
    let frame = PixelWindow::at_origin(2, 1);
    let trans = write_full_frame_exr(
        dir.path().join("t.exr"),
        frame,
        vec![
            ("R", vec![0.25, 0.0]),
            ("G", vec![0.25, 0.0]),
            ("B", vec![0.25, 0.0]),
            ("A", vec![0.5, 0.0]),
        ],
    );
    let mask = rect_mask_png(dir.path(), 2, 1, [1, 0, 1, 0], 1);
    let refl = write_full_frame_exr(
        dir.path().join("r.exr"),
        frame,
        rgb_planes(vec![0.0, 0.5], vec![0.0, 0.5], vec![0.0, 0.5]),
    );
    let png = dir.path().join("o.png");
    ok(compose_cmd(&[&refl], &trans, &mask, &reg)
        .args(["--dither", "none", "-o"])
        .arg(&png));
    let planes = crate::util::read_png_planes(&png);
    let srgb = |v: f64| {
        if v <= 0.0031308 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        }
    };
    assert_eq!(
        planes.channels[0][0],
        (srgb(0.5) * 255.0).round(),
        "un-premultiplied"
    );
    assert_eq!(planes.channels[3][0], 128.0);
    // Alpha 0 with a reflection on it: light without coverage is kept as is (as oiiotool does).
    assert_eq!(planes.channels[0][1], (srgb(0.5 * 0.25) * 255.0).round());
    assert_eq!(planes.channels[3][1], 0.0);
}

#[test]
fn half_output_clamps_values_beyond_half_range_and_reads_back() {
    // Finite values beyond ±65504 are stored as the largest half, said with the first pixel,
    // so that the output composites again (an infinity was written, and it came back as
    // non-finite transmission samples).
    let (dir, reg, values) = folder_with_registry();
    let frame = PixelWindow::at_origin(3, 1);
    let trans = write_full_frame_exr(
        dir.path().join("t.exr"),
        frame,
        rgb_planes(vec![1e5, 1.0, 1.0], vec![1.0; 3], vec![-7e4, 1.0, 1.0]),
    );
    let mask = rect_mask_png(dir.path(), 3, 1, [2, 0, 2, 0], 1);
    let half = dir.path().join("half.exr");
    let (_, _, stderr) = run(compose_cmd(&[&trans], &trans, &mask, &reg)
        .args(["--data-type", "half", "-o"])
        .arg(&half));
    assert!(
        stderr.contains("warning: 2 output samples exceed the half-float range")
            && stderr.contains("clamped to ±65504")
            && stderr.contains("the first at pixel (0, 0), channel \"R\": 100000"),
        "{stderr}"
    );
    assert!(stderr.contains("--data-type float"), "{stderr}");
    let (_, _, parts) = read_parts(&half);
    assert_eq!(parts[0].channels["R"][..2], [65504.0, 1.0]);
    assert_eq!(parts[0].channels["B"][..2], [-65504.0, 1.0]);

    // Read back as the transmission pass, and as a reflection pass, by compose.
    let again = dir.path().join("again.exr");
    let (out, _, stderr) = run(compose_cmd(&[&half], &half, &mask, &reg)
        .args(["--data-type", "float", "-o"])
        .arg(&again));
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("NaN or infinite"), "{stderr}");
    let (_, _, parts) = read_parts(&again);
    let (r0, t0) = values[&1];
    assert_eq!(parts[0].channels["R"][..2], [65504.0, 1.0]);
    // Glass: the first composite's gain, applied again (both passes are the first output).
    let gain = r0[1] + t0[1];
    assert!(close(parts[0].channels["G"][2], gain * gain));
}

#[test]
fn every_sample_type_survives_a_keep() {
    // uint channels (object ids) are carried over exactly, not through f32.
    let (dir, reg, _) = folder_with_registry();
    let frame = PixelWindow::at_origin(2, 1);
    let trans = dir.path().join("t.exr");
    let image = ExrImageOut {
        display_window: frame,
        attributes: attributes_for(frame),
        parts: vec![ExrPartOut {
            data_window: frame,
            attributes: Default::default(),
            planes: vec![
                ExrPlane::new("R", vec![1.0; 2]),
                ExrPlane::new("G", vec![1.0; 2]),
                ExrPlane::new("B", vec![1.0; 2]),
                ExrPlane {
                    name: "objectId".into(),
                    samples: PlaneSamples::Exact(FlatSamples::U32(vec![u32::MAX, 16_777_217])),
                    linear: false,
                },
            ],
        }],
    };
    write_exr(&trans, image, ExrStorage::Half);
    let mask = rect_mask_png(dir.path(), 2, 1, [0, 0, 0, 0], 1);
    let out = dir.path().join("o.exr");
    ok(compose_cmd(&[&trans], &trans, &mask, &reg)
        .arg("-o")
        .arg(&out));
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(&out)
        .unwrap();
    let id = image
        .layer_data
        .channel_data
        .list
        .iter()
        .find(|c| c.name.to_string() == "objectId")
        .unwrap();
    assert_eq!(id.sample_data, FlatSamples::U32(vec![u32::MAX, 16_777_217]));
}
