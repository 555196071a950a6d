//! Helpers for driving the built binaries.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository root (where `data/` and `fixtures/` live).
pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A path inside the repository.
pub fn repo_path(rel: &str) -> PathBuf {
    repo_root().join(rel)
}

/// A file of `fixtures/glazing`, the spectral files of the tests
/// (fixtures/glazing/README.md).
pub fn glazing_fixture(name: &str) -> PathBuf {
    repo_path("fixtures/glazing").join(name)
}

/// A `Command` for the built `glassdb` binary.
pub fn glassdb() -> Command {
    Command::new(env!("CARGO_BIN_EXE_glassdb"))
}

/// A `Command` for the built `compose` binary.
pub fn compose() -> Command {
    Command::new(env!("CARGO_BIN_EXE_compose"))
}

/// Runs a command and returns its output, with stdout/stderr as strings.
pub fn run(cmd: &mut Command) -> (Output, String, String) {
    let out = cmd.output().expect("failed to spawn the binary under test");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (out, stdout, stderr)
}

/// Asserts success and returns stdout.
pub fn ok(cmd: &mut Command) -> String {
    let (out, stdout, stderr) = run(cmd);
    assert!(
        out.status.success(),
        "command failed: {:?}\nstdout:\n{stdout}\nstderr:\n{stderr}",
        cmd
    );
    stdout
}

/// Asserts a non-zero exit without a panic and returns stderr.
pub fn fails(cmd: &mut Command) -> String {
    let (out, stdout, stderr) = run(cmd);
    assert!(
        !out.status.success(),
        "command unexpectedly succeeded: {:?}\nstdout:\n{stdout}",
        cmd
    );
    assert!(
        !stderr.contains("panicked"),
        "the binary panicked: {stderr}"
    );
    assert_ne!(
        out.status.code(),
        Some(101),
        "exit code 101 means a panic: {stderr}"
    );
    stderr
}

/// Runs a command that must fail (see [`fails`]), asserts that its stderr names every one of
/// `parts` and returns the stderr.
pub fn fails_naming(cmd: &mut Command, parts: &[&str]) -> String {
    let stderr = fails(cmd);
    assert_names(&stderr, parts);
    stderr
}

/// Asserts that `text` (a command's output or an error message) contains every one of `parts`.
pub fn assert_names(text: &str, parts: &[&str]) {
    for part in parts {
        assert!(text.contains(part), "lacks {part:?}:\n{text}");
    }
}

/// The text of the repository's file `rel` (a doc) after the first `marker`; panics naming both
/// when the marker is not there.
pub fn doc_after(rel: &str, marker: &str) -> String {
    let doc = std::fs::read_to_string(repo_path(rel)).unwrap();
    match doc.split_once(marker) {
        Some((_, after)) => after.to_string(),
        None => panic!("{rel} has no {marker:?}"),
    }
}

/// `glassdb registry build <catalog> -o <out> [extra…]`.
pub fn registry_build(catalog: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut cmd = glassdb();
    cmd.args(["registry", "build"])
        .arg(catalog)
        .arg("-o")
        .arg(out)
        .args(extra);
    cmd
}

/// The statistics every fitted curve of a fit file or a registry carries besides its powers and
/// coefficients.
pub const CURVE_FIT_STATS: [&str; 5] = [
    "degree",
    "rms_error",
    "max_abs_error",
    "max_error_angle_deg",
    "condition_number",
];

/// Writes `contents` to `dir/name` and returns the path.
pub fn write_file(dir: &Path, name: &str, contents: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, contents).expect("write test file");
    p
}

/// Writes the shell script `text` as the executable `dir/name`. A child process writes it: a
/// file this process had open for writing can be inherited by a child another test thread
/// forks at that moment, and running the script then fails with ETXTBSY.
pub fn write_executable(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    let status = Command::new("sh")
        .args(["-c", "printf '%s' \"$2\" > \"$1\" && chmod 755 \"$1\""])
        .arg("sh")
        .arg(&p)
        .arg(text)
        .status()
        .expect("run sh to write a test script");
    assert!(status.success(), "writing {}", p.display());
    p
}

/// The Python interpreter that has the pinned oracles (colour-science, pywincalc, mpmath).
/// `scripts/test-all` (the README's test command, and CI) sets `GLASSDB_PYTHON`; failing to
/// find it is a test failure, never a skip, so an oracle comparison cannot silently vanish.
pub fn oracle_python() -> PathBuf {
    if let Some(p) = std::env::var_os("GLASSDB_PYTHON") {
        return PathBuf::from(p);
    }
    let venv = repo_path(".venv/bin/python");
    assert!(
        venv.exists(),
        "no oracle Python: run `bash scripts/test-all` (it installs .venv) or set GLASSDB_PYTHON"
    );
    venv
}

/// Runs `python_oracle/<script>` with the oracle Python and the given arguments; asserts
/// success and returns stdout.
pub fn run_oracle(script: &str, args: &[&std::ffi::OsStr]) -> String {
    let mut cmd = Command::new(oracle_python());
    cmd.arg(repo_path("python_oracle").join(script)).args(args);
    let (out, stdout, stderr) = run(&mut cmd);
    assert!(out.status.success(), "oracle {script} failed:\n{stderr}");
    stdout
}

/// Whether committed reference files are to be regenerated instead of checked
/// (`GLASSDB_MAKE_REF=1 cargo test …`, resvg's `MAKE_REF` convention). A test that honours it
/// writes what it measured or produced over the committed file and passes; `git diff` then shows
/// what changed.
pub fn make_ref() -> bool {
    std::env::var_os("GLASSDB_MAKE_REF").is_some_and(|v| v == "1")
}

/// Where failing image comparisons leave their diff images (`target/test-diffs/`).
pub fn diff_dir() -> PathBuf {
    let dir = repo_path("target/test-diffs");
    std::fs::create_dir_all(&dir).expect("create target/test-diffs");
    dir
}

/// An image to compare: planar channels of `width * height` samples each, row 0 at the top.
pub struct Planes {
    pub width: usize,
    pub height: usize,
    /// Channel names, for messages.
    pub names: Vec<String>,
    pub channels: Vec<Vec<f64>>,
}

/// Asserts that `got` and `want` have the same size and channels and that every sample agrees
/// within `tolerance`. On failure writes `target/test-diffs/<name>.png`: per pixel the largest
/// channel difference, white where it exceeds the tolerance, grey scaled to the tolerance below
/// it, so the failing region can be seen.
pub fn assert_images_match(name: &str, got: &Planes, want: &Planes, tolerance: f64) {
    assert_eq!(
        (got.width, got.height),
        (want.width, want.height),
        "{name}: image sizes differ"
    );
    assert_eq!(got.names, want.names, "{name}: channels differ");
    let n = got.width * got.height;
    let mut worst = vec![0.0f64; n];
    let mut first_bad: Option<(usize, usize, f64, f64)> = None;
    let mut bad = 0usize;
    for (c, (g, w)) in got.channels.iter().zip(&want.channels).enumerate() {
        assert_eq!((g.len(), w.len()), (n, n), "{name}: channel {c} length");
        for i in 0..n {
            let d = (g[i] - w[i]).abs();
            let d = if d.is_nan() { f64::INFINITY } else { d };
            if d > tolerance {
                bad += 1;
                first_bad.get_or_insert((i, c, g[i], w[i]));
            }
            worst[i] = worst[i].max(d);
        }
    }
    let Some((i, c, g, w)) = first_bad else {
        return;
    };
    let path = write_diff_image(name, got.width, got.height, &worst, tolerance);
    panic!(
        "{name}: {bad} samples differ by more than {tolerance}; first at pixel (x {}, y {}) \
         channel {}: got {g}, want {w}; diff image: {}",
        i % got.width,
        i / got.width,
        got.names[c],
        path.display()
    );
}

/// Writes `target/test-diffs/<name>.png` from a per-pixel difference: white where it exceeds
/// `tolerance`, grey scaled to the tolerance below it (black: equal). Encoded by glassdb's one
/// PNG encoder (what is checked here is never read back through it). Returns the path.
pub fn write_diff_image(
    name: &str,
    width: usize,
    height: usize,
    per_pixel: &[f64],
    tolerance: f64,
) -> PathBuf {
    let path = diff_dir().join(format!("{name}.png"));
    let grey: Vec<u8> = per_pixel
        .iter()
        .map(|&d| {
            if d.is_nan() || d > tolerance {
                255
            } else if tolerance > 0.0 {
                (d / tolerance * 200.0).round() as u8
            } else {
                0
            }
        })
        .collect();
    let options = glassdb_image::PngEncodeOptions {
        compression: glassdb_image::PngCompression::Fast,
        srgb_chunk: false,
    };
    let bytes = glassdb_image::encode_png(
        width as u32,
        height as u32,
        glassdb_image::PngColor::Grey,
        glassdb_image::PngSampleSlice::U8(&grey),
        options,
    )
    .expect("encode the diff image");
    std::fs::write(&path, bytes).expect("write the diff image");
    path
}

/// Every channel of an EXR's first layer as f64 planes, read with the `exr` crate (not with
/// glassdb's own codecs), sorted by channel name.
pub fn read_exr_planes(path: &Path) -> Planes {
    let image = exr::prelude::read_first_flat_layer_from_file(path)
        .unwrap_or_else(|e| panic!("reading {} with the exr crate: {e}", path.display()));
    let layer = &image.layer_data;
    let size = layer.size;
    let mut names = Vec::new();
    let mut channels = Vec::new();
    for ch in &layer.channel_data.list {
        names.push(ch.name.to_string());
        channels.push(ch.sample_data.values_as_f32().map(f64::from).collect());
    }
    Planes {
        width: size.width(),
        height: size.height(),
        names,
        channels,
    }
}

/// A PNG's samples as planes (grey, grey+alpha, RGB or RGBA; 8 or 16 bits, values as stored),
/// read with the `png` crate (not with glassdb's own codecs).
pub fn read_png_planes(path: &Path) -> Planes {
    let file =
        std::fs::File::open(path).unwrap_or_else(|e| panic!("opening {}: {e}", path.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap_or_else(|e| panic!("{}: PNG header: {e}", path.display()));
    let mut buf = vec![0; reader.output_buffer_size().expect("PNG size")];
    let info = reader
        .next_frame(&mut buf)
        .unwrap_or_else(|e| panic!("{}: PNG data: {e}", path.display()));
    let names: Vec<String> = match info.color_type {
        png::ColorType::Grayscale => vec!["Y"],
        png::ColorType::GrayscaleAlpha => vec!["Y", "A"],
        png::ColorType::Rgb => vec!["R", "G", "B"],
        png::ColorType::Rgba => vec!["R", "G", "B", "A"],
        png::ColorType::Indexed => panic!("{}: indexed PNG", path.display()),
    }
    .into_iter()
    .map(String::from)
    .collect();
    let (w, h) = (info.width as usize, info.height as usize);
    let k = names.len();
    let samples: Vec<f64> = match info.bit_depth {
        png::BitDepth::Eight => buf[..w * h * k].iter().map(|&b| f64::from(b)).collect(),
        png::BitDepth::Sixteen => buf[..w * h * k * 2]
            .chunks_exact(2)
            .map(|b| f64::from(u16::from_be_bytes([b[0], b[1]])))
            .collect(),
        other => panic!("{}: {other:?}-bit PNG", path.display()),
    };
    let channels = (0..k)
        .map(|c| samples.iter().skip(c).step_by(k).copied().collect())
        .collect();
    Planes {
        width: w,
        height: h,
        names,
        channels,
    }
}

/// Writes `image` to `path` as glassdb writes an output of the whole frame (format from the
/// extension), the defaults taken from `src`.
pub fn write_pass(
    path: &Path,
    image: glassdb_pass::LinearImage,
    src: &glassdb_pass::PassSource,
    opts: &glassdb_encode::OutputOptions,
) -> Result<glassdb_encode::WrittenOutput, glassdb_encode::EncodeError> {
    let frame = glassdb_pass::CarriedFrame::whole(image.width, image.height);
    glassdb_encode::write_output(path, image, frame, src, opts)
}

/// The source a float RGB EXR pass is written like (ZIP16, channels R, G, B, no layer).
fn float_src() -> glassdb_pass::PassSource {
    glassdb_pass::PassSource::Exr {
        sample_type: glassdb_image::ExrSampleType::Float,
        compression: exr::compression::Compression::ZIP16,
        layer: String::new(),
        part: 0,
        channel_names: vec!["R".into(), "G".into(), "B".into()],
    }
}

/// Writes a float EXR (or PNG, by extension) from per-pixel RGB values, row-major.
pub fn write_rgb(path: &Path, w: u32, h: u32, px: &[[f32; 3]]) {
    let img = glassdb_pass::LinearImage {
        width: w,
        height: h,
        rgb: [0, 1, 2].map(|c| px.iter().map(|p| p[c]).collect()),
        alpha: None,
    };
    let opts = glassdb_encode::OutputOptions {
        exr_data_type: Some(glassdb_encode::ExrDataType::Float),
        dither: false,
        ..glassdb_encode::OutputOptions::default()
    };
    write_pass(path, img, &float_src(), &opts).unwrap();
}

/// The bundled example's inputs as `compose` takes them, relative to [`example_copy`]'s folder.
pub const EXAMPLE_INPUTS: [&str; 6] = [
    "--refl",
    "refl.exr",
    "--trans",
    "trans.exr",
    "--mask",
    "mask.png",
];

/// The atrium's three reflection passes as one multi-part EXR at `out`, each part cropped to
/// its plane's glass (written by OpenEXR, `plane_parts.py`), then 1×1 parts up to `pad` parts.
pub fn atrium_planes_file(out: &Path, pad: Option<usize>) -> PathBuf {
    let a = |f: &str| repo_path("fixtures/atrium").join(f);
    let mut args: Vec<std::ffi::OsString> = vec![
        "parts".into(),
        "--mask".into(),
        a("mask.png").into(),
        "--out".into(),
        out.into(),
    ];
    if let Some(parts) = pad {
        args.extend(["--pad".into(), parts.to_string().into()]);
    }
    args.extend((0..3).map(|k| a(&format!("refl_{k}.exr")).into_os_string()));
    let refs: Vec<&std::ffi::OsStr> = args.iter().map(|s| s.as_os_str()).collect();
    run_oracle("plane_parts.py", &refs);
    out.to_path_buf()
}

/// A temporary folder holding a copy of `fixtures/example`'s passes and mask.
pub fn example_copy() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for f in ["refl.exr", "trans.exr", "mask.png"] {
        std::fs::copy(repo_path("fixtures/example").join(f), dir.path().join(f)).unwrap();
    }
    dir
}

/// `compose` of the atrium's transmission pass and mask (with its planes.json) with the
/// reflection passes `refl`, into `out`.
pub fn atrium_compose(refl: &[PathBuf], out: &Path) -> Command {
    let a = repo_path("fixtures/atrium");
    let mut c = compose_frame(refl, &a.join("trans.exr"), &a.join("mask.png"), out);
    c.arg("--planes").arg(a.join("virtual/planes.json"));
    c
}

/// The JSON triple `v` (`[r, g, b]`) as numbers; panics showing it when it is not one.
pub fn json_rgb(v: &serde_json::Value) -> [f64; 3] {
    [0, 1, 2].map(|c| {
        v[c].as_f64()
            .unwrap_or_else(|| panic!("not an RGB triple of numbers: {v}"))
    })
}

/// The largest |a − b| over the pairs of `a` and `b` (0 for none; a NaN difference is passed
/// over, as `f64::max` does).
pub fn max_abs_diff<'a>(
    a: impl IntoIterator<Item = &'a f64>,
    b: impl IntoIterator<Item = &'a f64>,
) -> f64 {
    a.into_iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// `glassdb mask OBJ --camera CAMERA`: callers add the glasses, the output and any other flag.
pub fn mask_from(obj: impl AsRef<std::ffi::OsStr>, camera: impl AsRef<std::ffi::OsStr>) -> Command {
    let mut c = glassdb();
    c.arg("mask").arg(obj).arg("--camera").arg(camera);
    c
}

/// `compose --refl R… --trans TRANS --mask MASK -o OUT`: one frame's composite.
pub fn compose_frame(refl: &[PathBuf], trans: &Path, mask: &Path, out: &Path) -> Command {
    let mut c = compose();
    for r in refl {
        c.arg("--refl").arg(r);
    }
    c.arg("--trans")
        .arg(trans)
        .arg("--mask")
        .arg(mask)
        .arg("-o")
        .arg(out);
    c
}

/// The atrium's three reflection passes.
pub fn atrium_refl() -> Vec<PathBuf> {
    (0..3)
        .map(|k| repo_path(&format!("fixtures/atrium/refl_{k}.exr")))
        .collect()
}

/// The names in `dir`, sorted.
pub fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The element of the JSON array `items` whose `key` is `value`; panics naming it when none is.
pub fn element_where<'a, V>(
    items: &'a serde_json::Value,
    key: &str,
    value: V,
) -> &'a serde_json::Value
where
    V: std::fmt::Display,
    serde_json::Value: PartialEq<V>,
{
    elements(items)
        .iter()
        .find(|e| e[key] == value)
        .unwrap_or_else(|| panic!("no element with {key} {value} in {items}"))
}

/// The elements of the JSON array `items`; panics showing it when it is not an array.
pub fn elements(items: &serde_json::Value) -> &[serde_json::Value] {
    items
        .as_array()
        .unwrap_or_else(|| panic!("not an array: {items}"))
}

/// The string `key` of each element of the JSON array `items`.
pub fn strings_of<'a>(items: &'a serde_json::Value, key: &str) -> Vec<&'a str> {
    elements(items)
        .iter()
        .map(|e| {
            e[key]
                .as_str()
                .unwrap_or_else(|| panic!("no string {key} in {e}"))
        })
        .collect()
}

/// Sends `SIG<signal>` (`TERM`, `INT`, …) to a started child with `kill`.
pub fn send_signal(child: &std::process::Child, signal: &str) {
    let status = Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(child.id().to_string())
        .status()
        .unwrap();
    assert!(status.success(), "kill -{signal}");
}
