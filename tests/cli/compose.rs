//! End-to-end tests of the compose commands: hand-computable golden images for every mask
//! format, planes, sides, coverage, PNG and EXR in and out, sequences, and every error case.

use std::path::{Path, PathBuf};

use glassdb_encode::OutputOptions;
use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};
use glassdb_pass::{LinearImage, PassSource, PngBits};

use crate::util::{
    Planes, compose, fails, fails_naming, glassdb, ok, read_exr_planes, read_png_planes, run,
    write_pass, write_rgb,
};

/// A constant curve C = 1 (so r = r0 and t = t0 at every angle).
fn constant_curve() -> serde_json::Value {
    serde_json::json!({
        "basis": "full", "powers": [0], "coefficients": [1.0], "degree": 0, "rms_error": 0.0,
        "max_abs_error": 0.0, "max_error_angle_deg": 0.0, "condition_number": 1.0, "tolerance": 0.0
    })
}

/// A curve C = cos θ (so t = t0·cos θ).
fn cos_curve() -> serde_json::Value {
    serde_json::json!({
        "basis": "paper", "powers": [1], "coefficients": [1.0], "degree": 1, "rms_error": 0.0,
        "max_abs_error": 0.0, "max_error_angle_deg": 0.0, "condition_number": 1.0, "tolerance": 0.0
    })
}

/// A hand-written registry: glass 1 with r = (0.25, 0.125, 0.0625), t = (0.5, 0.25, 0.125)
/// at every angle and back reflectance 0.5; glass 2 with r = 0.25, t = 0.5·cos θ (grey).
fn write_registry(dir: &Path) -> PathBuf {
    let c = constant_curve();
    let glass = |id: u16, r0: [f64; 3], t0: [f64; 3], r0_back: [f64; 3], ct: &serde_json::Value| {
        serde_json::json!({
            "id": id, "name": format!("test glass {id}"), "r0": r0, "t0": t0, "r0_back": r0_back,
            "c_r": [c, c, c], "c_t": [ct, ct, ct], "c_r_back": [c, c, c],
            "angle_model": {"kind": "measured", "applied": "per-channel"},
            "provenance": {}
        })
    };
    let reg = serde_json::json!({
        "schema": 2,
        "spectral": {"method": "luminous"},
        "glasses": [
            glass(1, [0.25, 0.125, 0.0625], [0.5, 0.25, 0.125], [0.5; 3], &c),
            glass(2, [0.25; 3], [0.5; 3], [0.25; 3], &cos_curve()),
        ]
    });
    let p = dir.join("registry.json");
    std::fs::write(&p, serde_json::to_string_pretty(&reg).unwrap()).unwrap();
    p
}

/// The channel of an output EXR whose name is `name` or ends in `.name`, read with the `exr`
/// crate (not with glassdb's own decoder).
fn exr_channel(planes: &Planes, name: &str) -> Vec<f32> {
    let suffix = format!(".{name}");
    let c = planes
        .names
        .iter()
        .position(|n| n == name || n.ends_with(&suffix))
        .unwrap_or_else(|| panic!("no channel {name} in {:?}", planes.names));
    planes.channels[c].iter().map(|&v| v as f32).collect()
}

/// RGB per pixel of an output EXR, read with the `exr` crate.
fn read_rgb(path: &Path) -> Vec<[f32; 3]> {
    let planes = read_exr_planes(path);
    let [r, g, b] = ["R", "G", "B"].map(|n| exr_channel(&planes, n));
    (0..r.len()).map(|i| [r[i], g[i], b[i]]).collect()
}

/// The sample type of an output EXR's R channel, from its header as the `exr` crate reads it.
fn exr_r_sample_type(path: &Path) -> exr::meta::attribute::SampleType {
    let meta = exr::meta::MetaData::read_from_file(path, false).unwrap();
    let channels = &meta.headers[0].channels.list;
    channels
        .iter()
        .find(|c| c.name.to_string() == "R" || c.name.to_string().ends_with(".R"))
        .expect("an R channel")
        .sample_type
}

fn mask8(w: u32, h: u32, id: Vec<u16>, cos: Vec<u8>, plane: Vec<u16>) -> MaskImage {
    MaskImage {
        width: w,
        height: h,
        id,
        cos_theta: CosTheta::Quantized8(cos),
        plane,
        coverage: None,
    }
}

/// A 3×1 mask of glass `id` on plane 0 at every pixel.
fn mask3(id: u16, cos_theta: CosTheta, coverage: Option<Vec<f32>>) -> MaskImage {
    MaskImage {
        width: 3,
        height: 1,
        id: vec![id; 3],
        cos_theta,
        plane: vec![0; 3],
        coverage,
    }
}

/// Writes `mask` as the paper's 8-bit packed PNG.
fn write_mask8(path: &Path, mask: MaskImage) {
    write_mask(path, &mask, MaskFormat::Png8).unwrap();
}

fn assert_close(got: [f32; 3], want: [f32; 3], what: &str) {
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() <= 1e-6 * want[c].abs().max(1.0),
            "{what}: got {got:?}, want {want:?}"
        );
    }
}

/// Trans (1, 2, 4) and refl (8, 8, 8) everywhere on a 3×1 image: pixel 0 no glass, pixels 1, 2
/// glass 1 → R = 1·0.5 + 8·0.25 = 2.5, G = 2·0.25 + 8·0.125 = 1.5, B = 4·0.125 + 8·0.0625 = 1.
struct Golden {
    dir: tempfile::TempDir,
    registry: PathBuf,
    trans: PathBuf,
    refl: PathBuf,
}

fn golden() -> Golden {
    let dir = tempfile::tempdir().unwrap();
    let registry = write_registry(dir.path());
    let trans = dir.path().join("t.exr");
    let refl = dir.path().join("r.exr");
    write_rgb(&trans, 3, 1, &[[1.0, 2.0, 4.0]; 3]);
    write_rgb(&refl, 3, 1, &[[8.0; 3]; 3]);
    Golden {
        dir,
        registry,
        trans,
        refl,
    }
}

const GLASS1: [f32; 3] = [2.5, 1.5, 1.0];
const CLEAR: [f32; 3] = [1.0, 2.0, 4.0];

impl Golden {
    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }
    /// Writes a 3×1 8-bit packed mask `name` (see `mask8`) and returns its path.
    fn mask8(&self, name: &str, id: Vec<u16>, cos: Vec<u8>, plane: Vec<u16>) -> PathBuf {
        let path = self.path(name);
        write_mask8(&path, mask8(3, 1, id, cos, plane));
        path
    }
    /// `compose` of this golden's passes with `mask` into `out`.
    fn cmd(&self, mask: &Path, out: &Path) -> std::process::Command {
        self.cmd_with(&self.refl, &self.trans, mask, out)
    }
    /// `compose` of the given passes and mask with this golden's registry into `out`.
    fn cmd_with(
        &self,
        refl: impl AsRef<Path>,
        trans: impl AsRef<Path>,
        mask: impl AsRef<Path>,
        out: impl AsRef<Path>,
    ) -> std::process::Command {
        let mut c = compose();
        c.arg("--refl").arg(refl.as_ref());
        c.arg("--trans").arg(trans.as_ref());
        c.arg("--mask").arg(mask.as_ref());
        c.arg("--registry").arg(&self.registry);
        c.arg("-o").arg(out.as_ref());
        c
    }
}

#[test]
fn golden_8bit_packed_mask_exr_in_and_out() {
    let g = golden();
    let m = g.mask8("m.png", vec![0, 1, 1], vec![0, 255, 7], vec![0; 3]);
    let out = g.path("o.exr");
    let stdout = ok(&mut g.cmd(&m, &out));
    assert!(stdout.contains("o.exr"), "{stdout}");
    let px = read_rgb(&out);
    assert_eq!(
        px[0], CLEAR,
        "no-glass pixel must be the transmission pass bit for bit"
    );
    assert_close(px[1], GLASS1, "glass pixel");
    assert_close(px[2], GLASS1, "glass pixel");
    // Default output type follows the float transmission pass.
    assert_eq!(
        exr_r_sample_type(&out),
        exr::meta::attribute::SampleType::F32
    );
}

#[test]
fn golden_angle_dependence_with_16bit_and_exr_masks() {
    // Glass 2: t = 0.5·cos θ, r = 0.25. At cos θ = 0.2: R = 1·0.1 + 8·0.25 = 2.1,
    // G = 2·0.1 + 2 = 2.2, B = 4·0.1 + 2 = 2.4.
    let g = golden();
    let want = [2.1, 2.2, 2.4];
    let m16 = g.path("m16.png");
    let m = mask3(2, CosTheta::Quantized16(vec![13107; 3]), None);
    write_mask(&m16, &m, MaskFormat::Png16).unwrap();
    ok(&mut g.cmd(&m16, &g.path("o16.exr")));
    for p in read_rgb(&g.path("o16.exr")) {
        assert_close(p, want, "16-bit mask");
    }
    // EXR mask with a renderer's own channel names.
    let mexr = g.path("aov.exr");
    let mut c = MaskImage {
        cos_theta: CosTheta::Float(vec![0.2; 3]),
        ..m.clone()
    };
    c.plane = vec![0; 3];
    let bytes = glassdb_mask::write_mask_bytes(&mexr, &c, MaskFormat::Exr).unwrap();
    // Rename the channels by rewriting the header names (same length: "id" → "ix" would not
    // be a renderer name, so write with exr directly instead).
    drop(bytes);
    write_named_exr_mask(
        &mexr,
        3,
        1,
        "ViewLayer.IndexMA",
        &[2.0; 3],
        "ViewLayer.Facing",
        &[0.2; 3],
    );
    let out = g.path("oexr.exr");
    ok(g.cmd(&mexr, &out)
        .arg("--mask-channels")
        .arg("id=ViewLayer.IndexMA,cos=ViewLayer.Facing"));
    for p in read_rgb(&out) {
        assert_close(p, want, "EXR mask");
    }
    // Without the names, the error lists the channels the file has.
    let err = fails(&mut g.cmd(&mexr, &g.path("x.exr")));
    assert!(
        err.contains("\"id\"") && err.contains("ViewLayer.IndexMA"),
        "{err}"
    );
}

fn write_named_exr_mask(
    path: &Path,
    w: usize,
    h: usize,
    id_name: &str,
    id: &[f32],
    cos_name: &str,
    cos: &[f32],
) {
    use exr::prelude::*;
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = [
        AnyChannel::new(id_name, FlatSamples::F32(id.to_vec())),
        AnyChannel::new(cos_name, FlatSamples::F32(cos.to_vec())),
    ]
    .into_iter()
    .collect();
    let (attributes, encoding) = (LayerAttributes::default(), Encoding::SMALL_LOSSLESS);
    let layer = Layer::new((w, h), attributes, encoding, AnyChannels::sort(list));
    Image::from_layer(layer).write().to_file(path).unwrap();
}

#[test]
fn golden_binary_mask_uses_normal_incidence_values() {
    // White = glass 1 (r0, t0), black = none.
    let g = golden();
    let m = g.path("bin.png");
    let mut bytes = Vec::new();
    {
        let mut e = png::Encoder::new(&mut bytes, 3, 1);
        e.set_color(png::ColorType::Grayscale);
        e.set_depth(png::BitDepth::Eight);
        let mut w = e.write_header().unwrap();
        w.write_image_data(&[255, 0, 255]).unwrap();
    }
    std::fs::write(&m, bytes).unwrap();
    let out = g.path("o.exr");
    ok(g.cmd(&m, &out).args(["--glass", "1"]));
    let px = read_rgb(&out);
    assert_close(px[0], GLASS1, "white");
    assert_eq!(px[1], CLEAR);
    assert_close(px[2], GLASS1, "white");
    // A grey PNG without --glass is explained.
    let err = fails(&mut g.cmd(&m, &g.path("x.exr")));
    assert!(err.contains("--glass"), "{err}");
    // --glass with an id the registry lacks.
    fails_naming(g.cmd(&m, &g.path("x.exr")).args(["--glass", "9"]), &["9"]);
}

#[test]
fn golden_two_planes_with_back_side() {
    // Pixel 1 on plane 0 (front, r = 0.25/0.125/0.0625), pixel 2 on plane 1 seen from the back
    // (r = 0.5): R = 1·0.5 + 2·0.5 = 1.5, G = 2·0.25 + 2·0.5 = 1.5, B = 4·0.125 + 1 = 1.5.
    let g = golden();
    let r2 = g.path("r2.exr");
    write_rgb(&r2, 3, 1, &[[2.0; 3]; 3]);
    let m = g.mask8("m.png", vec![0, 1, 1], vec![255; 3], vec![0, 0, 1]);
    let out = g.path("o.exr");
    ok(g.cmd(&m, &out)
        .arg("--refl")
        .arg(&r2)
        .args(["--side", "1=back"]));
    let px = read_rgb(&out);
    assert_eq!(px[0], CLEAR);
    assert_close(px[1], GLASS1, "plane 0");
    assert_close(px[2], [1.5, 1.5, 1.5], "plane 1, back");
    // Same through planes.json.
    let planes = g.path("planes.json");
    let plane = |index: usize, side: &str| {
        format!(
            r#"{{"index":{index},"equation":[0.0,0.0,1.0,{index}.0],"area":1.0,"materials":["glass"],"triangles":2,"eye_side":"{side}","reflection_matrix":[[1.0,0.0,0.0,0.0],[0.0,1.0,0.0,0.0],[0.0,0.0,-1.0,0.0],[0.0,0.0,0.0,1.0]],"file":"virtual_plane_{index}.obj","triangles_written":0,"triangles_clipped":0}}"#
        )
    };
    std::fs::write(
        &planes,
        format!(
            r#"{{"format":"glassdb-planes/1","source":"scene.obj","eye":null,"tolerance":{{"angle_deg":0.5,"distance":0.001}},"planes":[{},{}]}}"#,
            plane(0, "front"),
            plane(1, "back")
        ),
    )
    .unwrap();
    let out2 = g.path("o2.exr");
    ok(g.cmd(&m, &out2)
        .arg("--refl")
        .arg(&r2)
        .arg("--planes")
        .arg(&planes));
    assert_eq!(read_rgb(&out2), px);
    // A plane without a reflection pass.
    let err = fails(&mut g.cmd(&m, &g.path("x.exr")));
    assert!(
        err.contains("plane 1") && err.contains("1 glass pixels"),
        "{err}"
    );
}

#[test]
fn golden_coverage_from_exr_mask() {
    // Coverage 0.5 on glass 1: (1 − 0.5)·trans + 0.5·GLASS1 = (1.75, 1.75, 2.5).
    let g = golden();
    let m = g.path("cov.exr");
    let mask = mask3(1, CosTheta::Float(vec![1.0; 3]), Some(vec![0.0, 0.5, 1.0]));
    write_mask(&m, &mask, MaskFormat::Exr).unwrap();
    let out = g.path("o.exr");
    ok(&mut g.cmd(&m, &out));
    let px = read_rgb(&out);
    assert_close(px[0], CLEAR, "coverage 0");
    assert_close(px[1], [1.75, 1.75, 2.5], "coverage 0.5");
    assert_close(px[2], GLASS1, "coverage 1");
}

#[test]
fn png_in_and_out_are_srgb_encoded() {
    // Trans white (code 255 = linear 1), refl black, glass 2 at cos 1: t = 0.5 → linear 0.5 →
    // sRGB 0.735357 → code 188 (no dither). 16-bit output: round(0.735357·65535) = 48192.
    let g = golden();
    let t = g.path("t.png");
    let r = g.path("r.png");
    let src8 = PassSource::Png {
        bits: PngBits::Eight,
    };
    let no_dither = OutputOptions {
        dither: false,
        ..OutputOptions::default()
    };
    write_pass(
        &t,
        LinearImage::filled(2, 1, [1.0; 3], None),
        &src8,
        &no_dither,
    )
    .unwrap();
    write_pass(
        &r,
        LinearImage::filled(2, 1, [0.0; 3], None),
        &src8,
        &no_dither,
    )
    .unwrap();
    let m = g.path("m.png");
    write_mask8(&m, mask8(2, 1, vec![2, 0], vec![255, 0], vec![0; 2]));
    let out = g.path("o.png");
    let mut c = g.cmd_with(&r, &t, &m, &out);
    c.args(["--dither", "none"]);
    ok(&mut c);
    let decoded = read_png_planes(&out);
    assert_eq!(decoded.channels.len(), 3);
    assert_eq!(
        (decoded.channels[0][0], decoded.channels[0][1]),
        (188.0, 255.0)
    );
    let out16 = g.path("o16.png");
    let mut c = g.cmd_with(&r, &t, &m, &out16);
    c.args(["--png-bits", "16"]);
    ok(&mut c);
    let decoded = read_png_planes(&out16);
    assert_eq!(decoded.channels[0][0], 48192.0);
    // --input-transfer linear: code 255 is still 1; a mid code 128 would be 128/255.
    let exr_out = g.path("lin.exr");
    let mut c = g.cmd_with(&r, &t, &m, &exr_out);
    c.args(["--input-transfer", "linear", "--data-type", "float"]);
    ok(&mut c);
    assert_eq!(read_rgb(&exr_out)[0], [0.5; 3]);
}

#[test]
fn half_output_and_every_compression_round_trip() {
    let g = golden();
    let m = g.mask8("m.png", vec![0, 1, 1], vec![0, 255, 7], vec![0; 3]);
    for comp in ["none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a"] {
        let out = g.path(&format!("o_{comp}.exr"));
        ok(g.cmd(&m, &out)
            .args(["--data-type", "half", "--compression", comp]));
        let px = read_rgb(&out);
        // All values are exact in half, and every compression is lossless for them except the
        // lossy ones (pxr24 is lossless for half; b44 is lossy in general but exact on flat data).
        assert_close(px[1], GLASS1, comp);
        assert_eq!(px[0], CLEAR, "{comp}");
    }
    let err = fails(g.cmd(&m, &g.path("x.exr")).args(["--compression", "lzw"]));
    assert!(err.contains("lzw") && err.contains("piz"), "{err}");
    // ZIP levels: the same pixels at every level, stated in the report; a level without a
    // zip compression, or out of range, is refused.
    for (comp, level) in [("zip", "0"), ("zip", "1"), ("zips", "9")] {
        let out = g.path(&format!("o_{comp}_{level}.exr"));
        let stdout = ok(g.cmd(&m, &out).args([
            "--data-type",
            "float",
            "--compression",
            comp,
            "--zip-level",
            level,
        ]));
        assert!(
            stdout.contains(&format!("{comp} level {level}")),
            "{stdout}"
        );
        let px = read_rgb(&out);
        assert_close(px[1], GLASS1, comp);
        assert_eq!(px[0], CLEAR, "{comp} level {level}");
    }
    let err = fails(
        g.cmd(&m, &g.path("x.exr"))
            .args(["--compression", "piz", "--zip-level", "3"]),
    );
    assert!(err.contains("zip") && err.contains("piz"), "{err}");
    fails(g.cmd(&m, &g.path("x.exr")).args(["--zip-level", "10"]));
    assert!(!g.path("x.exr").exists());
}

#[test]
fn multi_layer_exr_pass_chosen_by_name() {
    use exr::prelude::*;
    let g = golden();
    // A Blender-style single-part file: ViewLayer.Combined.{R,G,B,A} and ViewLayer.DiffCol.{R,G,B}.
    let t = g.path("multi.exr");
    let ch = |n: &str, v: f32| AnyChannel::new(n, FlatSamples::F32(vec![v; 3]));
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = [
        ch("ViewLayer.Combined.R", 1.0),
        ch("ViewLayer.Combined.G", 2.0),
        ch("ViewLayer.Combined.B", 4.0),
        ch("ViewLayer.Combined.A", 0.75),
        ch("ViewLayer.DiffCol.R", 9.0),
        ch("ViewLayer.DiffCol.G", 9.0),
        ch("ViewLayer.DiffCol.B", 9.0),
    ]
    .into_iter()
    .collect();
    let layer = Layer::new(
        (3, 1),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    Image::from_layer(layer).write().to_file(&t).unwrap();
    let m = g.mask8("m.png", vec![0, 1, 0], vec![255; 3], vec![0; 3]);
    let run_with = |layer: Option<&str>, out: &Path| {
        let mut c = g.cmd_with(&g.refl, &t, &m, out);
        if let Some(l) = layer {
            c.args(["--layer", l]);
        }
        c
    };
    // Default: the …Combined layer; alpha kept from the transmission pass.
    let out = g.path("o.exr");
    ok(&mut run_with(None, &out));
    assert_eq!(exr_channel(&read_exr_planes(&out), "A"), vec![0.75; 3]);
    let px = read_rgb(&out);
    assert_eq!(px[0], CLEAR);
    assert_close(px[1], GLASS1, "Combined layer");
    // An explicit layer: DiffCol (refl is a plain file, so --layer must match it too → error
    // names the file and its layers).
    let err = fails(&mut run_with(Some("ViewLayer.DiffCol"), &g.path("x.exr")));
    assert!(err.contains("r.exr") && err.contains("(R, G, B)"), "{err}");
}

#[test]
fn default_registry_on_the_bundled_example() {
    let dir = crate::util::example_copy();
    let inputs = crate::util::EXAMPLE_INPUTS;
    let stdout = ok(compose()
        .current_dir(dir.path())
        .args(inputs)
        .args(["-o", "a.exr", "--stats"]));
    assert!(stdout.contains("wrote a.exr"), "{stdout}");
    assert!(
        stdout.contains("decode") && stdout.contains("encode") && stdout.contains("Mpixel/s"),
        "{stdout}"
    );
    assert!(
        stdout.contains("id     2") && stdout.contains("id     6"),
        "{stdout}"
    );
    assert!(dir.path().join("a.exr").exists());
    // `glassdb compose` is the same command.
    let mut via_glassdb = glassdb();
    via_glassdb.current_dir(dir.path()).arg("compose");
    ok(via_glassdb.args(inputs).args(["-o", "b.png"]));
    assert!(dir.path().join("b.png").exists());
}

#[test]
fn sequences_report_bad_frames_and_go_on() {
    let g = golden();
    for f in [1, 2, 4] {
        write_mask8(
            &g.path(&format!("m.{f:04}.png")),
            mask8(3, 1, vec![0, 1, 1], vec![255; 3], vec![0; 3]),
        );
        write_rgb(
            &g.path(&format!("t.{f:04}.exr")),
            3,
            1,
            &[[1.0, 2.0, 4.0]; 3],
        );
    }
    // Frame 3 has no inputs; frame 4's mask is corrupt.
    std::fs::write(g.path("m.0004.png"), b"\x89PNG\r\n\x1a\nbroken").unwrap();
    // `compose` of the frame sequence into `out`, for the frames `range`.
    let frames = |out: &str, range: &str| {
        let mut c = g.cmd_with(
            &g.refl,
            g.path("t.####.exr"),
            g.path("m.####.png"),
            g.path(out),
        );
        c.args(["--frames", range]);
        c
    };
    let err = fails(&mut frames("o.####.exr", "1-4"));
    assert!(
        err.contains("frame 3") && err.contains("t.0003.exr"),
        "{err}"
    );
    assert!(
        err.contains("frame 4") && err.contains("m.0004.png"),
        "{err}"
    );
    assert!(err.contains("2 of 4 frame(s) failed"), "{err}");
    for f in [1, 2] {
        let px = read_rgb(&g.path(&format!("o.{f:04}.exr")));
        assert_close(px[1], GLASS1, "frame");
    }
    assert!(!g.path("o.0003.exr").exists() && !g.path("o.0004.exr").exists());
    // All good frames → exit 0.
    let stdout = ok(&mut frames("p.####.exr", "1-2"));
    assert!(stdout.contains("2 frame(s)"), "{stdout}");
    // An output without #### would be overwritten by every frame.
    fails_naming(&mut frames("same.exr", "1-2"), &["####"]);
}

#[test]
fn passes_of_different_sizes_name_both_files_and_sizes() {
    let g = golden();
    let small = g.path("small.exr");
    write_rgb(&small, 2, 1, &[[1.0; 3]; 2]);
    let m = g.mask8("m.png", vec![0; 3], vec![0; 3], vec![0; 3]);
    let mut c = g.cmd_with(&small, &g.trans, &m, g.path("o.exr"));
    let err = fails(&mut c);
    assert!(
        err.contains("t.exr")
            && err.contains("3×1")
            && err.contains("small.exr")
            && err.contains("2×1"),
        "{err}"
    );
    // A mask of a different size.
    let m2 = g.path("m2.png");
    write_mask8(&m2, mask8(1, 1, vec![0], vec![0], vec![0]));
    let err = fails(&mut g.cmd(&m2, &g.path("o.exr")));
    assert!(err.contains("m2.png") && err.contains("1×1"), "{err}");
    assert!(!g.path("o.exr").exists());
}

#[test]
fn unknown_ids_are_listed_with_pixel_counts_unless_passed_through() {
    let g = golden();
    let m = g.mask8("m.png", vec![7, 1, 7], vec![255; 3], vec![0; 3]);
    let out = g.path("o.exr");
    let err = fails(&mut g.cmd(&m, &out));
    assert!(
        err.contains("id 7 (2 pixels)") && err.contains("--unknown passthrough"),
        "{err}"
    );
    assert!(!out.exists());
    ok(g.cmd(&m, &out).args(["--unknown", "passthrough"]));
    let px = read_rgb(&out);
    assert_eq!(px[0], CLEAR);
    assert_close(px[1], GLASS1, "known id");
    assert_eq!(px[2], CLEAR);
}

#[test]
fn nan_in_a_pass_is_counted_reported_and_propagated() {
    let g = golden();
    write_rgb(
        &g.trans,
        3,
        1,
        &[[f32::NAN, 2.0, 4.0], [1.0, 2.0, 4.0], [1.0, 2.0, 4.0]],
    );
    write_rgb(
        &g.refl,
        3,
        1,
        &[[8.0; 3], [f32::INFINITY, 8.0, 8.0], [8.0; 3]],
    );
    let m = g.mask8("m.png", vec![0, 1, 1], vec![255; 3], vec![0; 3]);
    let out = g.path("o.exr");
    let (o, _stdout, stderr) = run(&mut g.cmd(&m, &out));
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("2 output samples are NaN or infinite")
            && stderr.contains("1 from the transmission pass")
            && stderr.contains("1 from reflection"),
        "{stderr}"
    );
    let px = read_rgb(&out);
    assert!(px[0][0].is_nan() && px[1][0].is_infinite());
    assert_close(px[2], GLASS1, "finite pixel");
}

#[test]
fn unreadable_truncated_and_corrupt_inputs_fail_cleanly() {
    let g = golden();
    let m = g.mask8("m.png", vec![0, 1, 1], vec![255; 3], vec![0; 3]);
    let out = g.path("o.exr");
    // Missing pass.
    let err = fails(&mut g.cmd_with(g.path("missing.exr"), &g.trans, &m, &out));
    assert!(err.contains("missing.exr"), "{err}");
    // Truncated transmission pass, at several lengths.
    let bytes = std::fs::read(&g.trans).unwrap();
    for cut in [4, 40, bytes.len() / 2, bytes.len() - 3] {
        std::fs::write(&g.trans, &bytes[..cut]).unwrap();
        let err = fails(&mut g.cmd(&m, &out));
        assert!(err.contains("t.exr"), "cut {cut}: {err}");
    }
    std::fs::write(&g.trans, &bytes).unwrap();
    // Not an image at all.
    std::fs::write(g.path("junk.png"), b"hello").unwrap();
    let err = fails(&mut g.cmd(&g.path("junk.png"), &out));
    assert!(
        err.contains("junk.png") && err.contains("neither PNG nor OpenEXR"),
        "{err}"
    );
    assert!(!out.exists());
    // Unknown output extension.
    let err = fails(&mut g.cmd(&m, &g.path("o.tiff")));
    assert!(err.contains("o.tiff"), "{err}");
}

#[test]
fn refuses_to_overwrite_an_input_and_keeps_old_output_on_failure() {
    let g = golden();
    let m = g.mask8("m.png", vec![0, 1, 1], vec![255; 3], vec![0; 3]);
    let before = std::fs::read(&g.trans).unwrap();
    let err = fails(&mut g.cmd(&m, &g.trans));
    assert!(
        err.contains("refusing to overwrite") && err.contains("t.exr"),
        "{err}"
    );
    assert_eq!(std::fs::read(&g.trans).unwrap(), before);
    // An existing output survives a failed run untouched.
    let out = g.path("keep.exr");
    std::fs::write(&out, b"old").unwrap();
    std::fs::write(g.path("bad.png"), b"\x89PNG\r\n\x1a\n...").unwrap();
    fails(&mut g.cmd(&g.path("bad.png"), &out));
    assert_eq!(std::fs::read(&out).unwrap(), b"old");
}

#[test]
fn corrupt_pass_and_mask_bytes_never_panic() {
    // Fixed-seed byte flips over a valid EXR, PNG pass and mask; every run must exit cleanly.
    let g = golden();
    let m = g.mask8("m.png", vec![0, 1, 1], vec![255; 3], vec![0; 3]);
    let originals: Vec<(PathBuf, Vec<u8>)> = [&g.trans, &m]
        .iter()
        .map(|p| (p.to_path_buf(), std::fs::read(p).unwrap()))
        .collect();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for round in 0..24 {
        let (path, bytes) = &originals[round % 2];
        let mut b = bytes.clone();
        for _ in 0..(1 + next() % 4) {
            let i = (next() as usize) % b.len();
            b[i] ^= (next() % 255 + 1) as u8;
        }
        std::fs::write(path, &b).unwrap();
        let (o, _, stderr) = run(&mut g.cmd(&m, &g.path("o.exr")));
        assert!(
            !stderr.contains("panicked") && o.status.code() != Some(101),
            "round {round}: {stderr}"
        );
        std::fs::write(path, bytes).unwrap();
    }
}
