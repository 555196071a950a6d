//! Nothing lost, nothing unbounded (docs/reliability.md): no output replaces one of the run's
//! inputs (named directly or by reference: a catalog's spectral files, an OBJ's MTL) or a
//! device, FIFO or directory; a symbolic link is written through; several files of one result
//! land together or not at all; a stop by SIGINT/SIGTERM leaves no temporary file; inputs that
//! are not regular files or are over their limit are refused before they are read.

use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::util::{
    assert_names, compose, fails, glassdb, mask_from, names, ok, registry_build, repo_path,
    send_signal, write_file,
};

/// Runs `cmd` (no standard input) and returns its output, failing the test if it runs longer
/// than `limit`: an input read without end or a FIFO opened for writing would hang it.
fn run_within(cmd: &mut Command, limit: Duration) -> (Output, String) {
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn the binary under test");
    let start = Instant::now();
    loop {
        if child.try_wait().expect("wait for the binary").is_some() {
            break;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{cmd:?} ran longer than {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let out = child.wait_with_output().expect("collect the output");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (out, stderr)
}

/// Runs `cmd`, which must fail within 60 s with an error (not a panic) naming every one of
/// `parts`; returns its stderr.
fn refused(cmd: &mut Command, parts: &[&str]) -> String {
    refused_within(cmd, Duration::from_secs(60), parts)
}

/// [`refused`] within `limit`.
fn refused_within(cmd: &mut Command, limit: Duration, parts: &[&str]) -> String {
    let (out, stderr) = run_within(cmd, limit);
    assert_eq!(out.status.code(), Some(1), "{cmd:?}:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_names(&stderr, parts);
    stderr
}

/// Asserts that no `.glassdb-tmp-*` file is left in `dir`.
fn assert_no_temporaries(dir: &Path) {
    let left: Vec<String> = names(dir)
        .into_iter()
        .filter(|n| n.starts_with(glassdb_io::TEMP_PREFIX))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

fn mkfifo(path: &Path) {
    let status = Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("run mkfifo");
    assert!(status.success(), "mkfifo {}", path.display());
}

fn is_fifo(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_fifo())
}

/// A catalog in `dir` whose glass 1 has the spectral file `glazing/CLEAR_3.DAT` and glass 2 the
/// angle table `angles.csv` (copies of fixtures); returns the catalog's path.
fn catalog_with_files(dir: &Path) -> PathBuf {
    std::fs::create_dir(dir.join("glazing")).unwrap();
    std::fs::copy(
        repo_path("fixtures/glazing/CLEAR_3.DAT"),
        dir.join("glazing/CLEAR_3.DAT"),
    )
    .unwrap();
    std::fs::copy(
        repo_path("fixtures/atrium/angles_clear.csv"),
        dir.join("angles.csv"),
    )
    .unwrap();
    write_file(
        dir,
        "cat.toml",
        br#"
[[glass]]
id = 1
name = "clear"
spectral = "glazing/CLEAR_3.DAT"

[[glass]]
id = 2
name = "measured"
r0 = [0.07692308, 0.07692308, 0.07692308]
t0 = [0.92307692, 0.92307692, 0.92307692]
angles = "angles.csv"
"#,
    )
}

#[test]
fn registry_build_refuses_to_overwrite_a_file_its_catalog_names() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let catalog = catalog_with_files(d);
    let spectral = d.join("glazing/CLEAR_3.DAT");
    let before = std::fs::read(&spectral).unwrap();
    let angles_before = std::fs::read(d.join("angles.csv")).unwrap();
    std::fs::hard_link(&spectral, d.join("hard.DAT")).unwrap();
    std::os::unix::fs::symlink("angles.csv", d.join("angles_link.csv")).unwrap();
    for out in [
        spectral.clone(),
        d.join("glazing/../glazing/./CLEAR_3.DAT"),
        d.join("hard.DAT"),
        d.join("angles.csv"),
        d.join("angles_link.csv"),
        catalog.clone(),
    ] {
        refused(
            &mut registry_build(&catalog, &out, &[]),
            &["refusing to overwrite the input file"],
        );
    }
    assert_eq!(std::fs::read(&spectral).unwrap(), before);
    assert_eq!(std::fs::read(d.join("angles.csv")).unwrap(), angles_before);
    assert!(
        std::fs::symlink_metadata(d.join("angles_link.csv"))
            .unwrap()
            .file_type()
            .is_symlink()
    );
    // The same catalog builds into a new file.
    ok(&mut registry_build(&catalog, &d.join("registry.json"), &[]));
    assert_no_temporaries(d);
}

/// The room fixture (OBJ, MTL, camera) copied into `dir`; returns the OBJ's path.
fn room_in(dir: &Path) -> PathBuf {
    for f in ["room.obj", "room.mtl", "camera.json"] {
        std::fs::copy(repo_path("fixtures/scene").join(f), dir.join(f)).unwrap();
    }
    dir.join("room.obj")
}

fn mask_cmd(obj: &Path, out: &Path) -> Command {
    let mut c = mask_from(obj, obj.with_file_name("camera.json"));
    c.args(["--glass", "Clear*=1", "--format", "png8", "-o"])
        .arg(out);
    c
}

#[test]
fn mask_refuses_to_overwrite_the_scenes_material_library_camera_or_planes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let obj = room_in(d);
    let mtl = std::fs::read(d.join("room.mtl")).unwrap();
    let camera = std::fs::read(d.join("camera.json")).unwrap();
    refused(
        &mut mask_cmd(&obj, &d.join("room.mtl")),
        &["refusing to overwrite the input file", "room.mtl"],
    );
    refused(
        &mut mask_cmd(&obj, &d.join("./camera.json")),
        &["refusing to overwrite the input file", "camera.json"],
    );
    // The planes file of `mirror`, given with --planes.
    ok(glassdb()
        .arg("mirror")
        .arg(&obj)
        .args(["--glass-material", "Clear*", "--glass-material", "Tinted*"])
        .arg("--out-dir")
        .arg(d.join("virtual")));
    let planes = d.join("virtual/planes.json");
    let planes_before = std::fs::read(&planes).unwrap();
    refused(
        mask_cmd(&obj, &planes).arg("--planes").arg(&planes),
        &["refusing to overwrite the input file", "planes.json"],
    );
    assert_eq!(std::fs::read(d.join("room.mtl")).unwrap(), mtl);
    assert_eq!(std::fs::read(d.join("camera.json")).unwrap(), camera);
    assert_eq!(std::fs::read(&planes).unwrap(), planes_before);
    // Mirror refuses to write a virtual scene over the scene's own MTL (a link named like it).
    let out = d.join("mirror_out");
    std::fs::create_dir(&out).unwrap();
    std::os::unix::fs::symlink("../room.mtl", out.join("plane_0.obj")).unwrap();
    refused(
        glassdb()
            .arg("mirror")
            .arg(&obj)
            .args(["--glass-material", "Clear*"])
            .arg("--out-dir")
            .arg(&out),
        &["refusing to overwrite the input file", "room.mtl"],
    );
    assert_eq!(std::fs::read(d.join("room.mtl")).unwrap(), mtl);
    assert_eq!(names(&out), ["plane_0.obj"]);
}

/// A small angle table for `glassdb fit`.
fn angle_table(dir: &Path) -> PathBuf {
    std::fs::copy(
        repo_path("fixtures/atrium/angles_clear.csv"),
        dir.join("table.csv"),
    )
    .unwrap();
    dir.join("table.csv")
}

fn fit_to(table: &Path, out: &Path) -> Command {
    let mut c = glassdb();
    c.arg("fit").arg(table).arg("-o").arg(out);
    c
}

#[test]
fn outputs_that_are_devices_fifos_or_directories_are_refused_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let table = angle_table(d);
    // /dev/null (tests run as root in CI: writing it once replaced the machine's /dev/null).
    refused(
        &mut fit_to(&table, Path::new("/dev/null")),
        &["/dev/null", "a character device"],
    );
    let null = std::fs::metadata("/dev/null").unwrap();
    assert!(null.file_type().is_char_device(), "/dev/null was replaced");
    // A FIFO: refused without opening it (which would wait for a reader).
    let fifo = d.join("out.fifo");
    mkfifo(&fifo);
    refused(&mut fit_to(&table, &fifo), &["out.fifo", "a FIFO"]);
    assert!(is_fifo(&fifo));
    // A directory, for every writer (here a registry and a mask).
    let sub = d.join("sub.json");
    std::fs::create_dir(&sub).unwrap();
    refused(&mut fit_to(&table, &sub), &["sub.json", "a directory"]);
    let catalog = catalog_with_files(d);
    refused(
        &mut registry_build(&catalog, &fifo, &[]),
        &["out.fifo", "a FIFO"],
    );
    let obj = room_in(d);
    refused(
        &mut mask_cmd(&obj, Path::new("/dev/null")),
        &["/dev/null", "a character device"],
    );
    // /dev/stdout names an open descriptor, not a file.
    refused(
        &mut fit_to(&table, Path::new("/dev/stdout")),
        &["/dev/stdout", "file descriptor"],
    );
    assert!(is_fifo(&fifo) && sub.is_dir());
    assert_no_temporaries(d);
}

#[test]
fn a_symlinked_output_is_written_through_and_the_link_kept() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let table = angle_table(d);
    std::fs::create_dir(d.join("real")).unwrap();
    let real = write_file(&d.join("real"), "fit.json", b"old");
    let link = d.join("fit.json");
    std::os::unix::fs::symlink("real/fit.json", &link).unwrap();
    ok(&mut fit_to(&table, &link));
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink(),
        "the link was replaced"
    );
    let text = std::fs::read_to_string(&real).unwrap();
    assert!(text.contains("\"glasses\""), "{text}");
    assert_no_temporaries(d);
    assert_no_temporaries(&d.join("real"));
    // A dangling link: its target is created.
    let dangling = d.join("new.json");
    std::os::unix::fs::symlink("real/new.json", &dangling).unwrap();
    ok(&mut fit_to(&table, &dangling));
    assert!(d.join("real/new.json").is_file());
}

#[test]
fn mirror_writes_every_file_or_none() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let obj = room_in(d);
    let out = d.join("virtual");
    std::fs::create_dir(&out).unwrap();
    // The second plane's file cannot be written: nothing of the result may land.
    std::fs::create_dir(out.join("plane_1.obj")).unwrap();
    let mirror = |out: &Path| {
        let mut c = glassdb();
        c.arg("mirror")
            .arg(&obj)
            .args(["--glass-material", "Clear*", "--glass-material", "Tinted*"])
            .arg("--out-dir")
            .arg(out);
        c
    };
    refused(&mut mirror(&out), &["plane_1.obj", "a directory"]);
    assert_eq!(names(&out), ["plane_1.obj"]);
    // Old files are kept when a later one fails.
    std::fs::write(out.join("plane_0.obj"), b"old").unwrap();
    refused(&mut mirror(&out), &["plane_1.obj"]);
    assert_eq!(std::fs::read(out.join("plane_0.obj")).unwrap(), b"old");
    assert_eq!(names(&out), ["plane_0.obj", "plane_1.obj"]);
    // Without the obstacle, all three land.
    std::fs::remove_dir(out.join("plane_1.obj")).unwrap();
    ok(&mut mirror(&out));
    assert_eq!(names(&out), ["plane_0.obj", "plane_1.obj", "planes.json"]);
}

#[test]
fn devices_and_fifos_named_as_inputs_are_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let quick = Duration::from_secs(30);
    let fifo = d.join("data.fifo");
    mkfifo(&fifo);
    // A catalog's spectral file.
    for (name, target, kind) in [
        ("zero.toml", "/dev/zero", "a character device"),
        ("urandom.toml", "/dev/urandom", "a character device"),
        ("fifo.toml", "data.fifo", "a FIFO"),
    ] {
        let catalog = write_file(
            d,
            name,
            format!("[[glass]]\nid = 1\nname = \"g\"\nspectral = \"{target}\"\n").as_bytes(),
        );
        let (out, stderr) =
            run_within(&mut registry_build(&catalog, &d.join("r.json"), &[]), quick);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert_names(&stderr, &[target, kind, "not a regular file"]);
    }
    // An OBJ's mtllib.
    let room = std::fs::read_to_string(repo_path("fixtures/scene/room.obj")).unwrap();
    for (name, lib, kind) in [
        ("zero.obj", "/dev/zero", "a character device"),
        ("fifo.obj", "data.fifo", "a FIFO"),
    ] {
        let obj = write_file(
            d,
            name,
            room.replace("mtllib room.mtl", &format!("mtllib {lib}"))
                .as_bytes(),
        );
        let mut c = glassdb();
        c.arg("mirror")
            .arg(&obj)
            .args(["--glass-material", "Clear*", "--out-dir"])
            .arg(d.join("v"));
        refused_within(&mut c, quick, &[lib, kind]);
    }
    // Direct inputs: an angle table, a spectral file, a registry, a camera.
    refused_within(
        glassdb().arg("fit").arg("/dev/zero"),
        quick,
        &["/dev/zero", "a character device"],
    );
    refused_within(
        glassdb().arg("spectral").arg(&fifo),
        quick,
        &["data.fifo", "a FIFO"],
    );
    refused_within(
        glassdb().args(["registry", "check", "/dev/zero"]),
        quick,
        &["/dev/zero", "a character device"],
    );
    let obj = room_in(d);
    let mut c = glassdb();
    c.arg("mask")
        .arg(&obj)
        .args(["--camera", "/dev/urandom", "--glass", "Clear*=1", "-o"])
        .arg(d.join("m.png"));
    refused_within(&mut c, quick, &["/dev/urandom", "a character device"]);
    // Images: compose's passes and mask, a registry build's mask.
    let mut c = compose();
    c.arg("--refl")
        .arg(&fifo)
        .args(["--trans", "/dev/zero", "--mask", "/dev/zero", "-o"])
        .arg(d.join("c.exr"));
    refused_within(&mut c, quick, &["/dev/zero", "a character device"]);
    let catalog = catalog_with_files(d);
    refused_within(
        registry_build(&catalog, &d.join("r.json"), &[]).args(["--mask", "/dev/zero"]),
        quick,
        &["/dev/zero", "a character device"],
    );
    assert!(is_fifo(&fifo));
}

#[test]
fn oversized_inputs_are_refused_from_their_size() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Sparse files: their size is set, their bytes never read (a 400 MB catalog once made the
    // process abort on allocation).
    let big = |name: &str, bytes: u64| {
        let p = d.join(name);
        std::fs::File::create(&p).unwrap().set_len(bytes).unwrap();
        p
    };
    let catalog = big("big.toml", 400 << 20);
    refused(
        &mut registry_build(&catalog, &d.join("r.json"), &[]),
        &[
            "big.toml",
            "it has 419430400 bytes, more than the 16 MiB a catalog may have",
        ],
    );
    let registry = big("big.json", 1 << 30);
    refused(
        glassdb().args(["registry", "check"]).arg(&registry),
        &["big.json", "more than the 64 MiB a JSON file may have"],
    );
    let table = big("big.csv", 100 << 20);
    refused(
        glassdb().arg("fit").arg(&table),
        &["big.csv", "more than the 64 MiB an angle table may have"],
    );
    let obj = big("big.obj", 3 << 30);
    refused(
        glassdb()
            .arg("mirror")
            .arg(&obj)
            .args(["--glass-material", "G*", "--out-dir"])
            .arg(d.join("v")),
        &["big.obj", "more than the 2 GiB an OBJ scene may have"],
    );
}

/// Writes the inputs of a compose that takes a while to encode: `w`×`h` float passes of
/// render-like noise (uncompressed, quick to write) and an 8-bit mask, half glass.
fn slow_compose_inputs(dir: &Path, w: u32, h: u32) {
    use crate::util::write_pass;
    use glassdb_encode::{OutputOptions, parse_exr_compression};
    use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};
    use glassdb_pass::{LinearImage, PassSource, PngBits};
    let n = (w * h) as usize;
    let noise = |i: u64| {
        let mut x = i.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        x ^= x >> 31;
        x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
        x ^= x >> 29;
        (x >> 40) as f32 / (1u64 << 24) as f32
    };
    let pass = |seed: u64| LinearImage {
        width: w,
        height: h,
        rgb: std::array::from_fn(|c| {
            (0..n)
                .map(|i| 0.5 + noise(seed + (i * 3 + c) as u64))
                .collect()
        }),
        alpha: None,
    };
    let opts = OutputOptions {
        exr_compression: Some(parse_exr_compression("none").unwrap()),
        ..OutputOptions::default()
    };
    let src = PassSource::Png {
        bits: PngBits::Eight,
    };
    write_pass(&dir.join("trans.exr"), pass(1), &src, &opts).unwrap();
    write_pass(&dir.join("refl.exr"), pass(1 << 40), &src, &opts).unwrap();
    let mask = MaskImage {
        width: w,
        height: h,
        id: (0..n).map(|i| if i % 2 == 0 { 2 } else { 0 }).collect(),
        cos_theta: CosTheta::Quantized8((0..n).map(|i| (i % 200 + 40) as u8).collect()),
        plane: vec![0; n],
        coverage: None,
    };
    write_mask(&dir.join("mask.png"), &mask, MaskFormat::Png8).unwrap();
}

/// Starts `compose` of the slow inputs in `dir` into `out` (float, zip at its slowest level).
fn start_compose(dir: &Path, out: &Path) -> Child {
    compose()
        .current_dir(dir)
        .args(crate::util::EXAMPLE_INPUTS)
        .args([
            "--data-type",
            "float",
            "--compression",
            "zip",
            "--zip-level",
            "9",
            "-o",
        ])
        .arg(out)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn compose")
}

/// Sends `signal` (`INT` or `TERM`) to a running compose once its output's temporary file
/// exists. Returns the exit code, or `None` when compose finished before the signal could be
/// sent (the test then tries again with a larger image).
fn stop_while_writing(dir: &Path, out: &Path, signal: &str) -> Option<i32> {
    let writing = || {
        names(dir)
            .iter()
            .any(|n| n.starts_with(glassdb_io::TEMP_PREFIX))
    };
    let stopped = signal_when(start_compose(dir, out), writing, signal);
    if stopped.is_none() {
        let _ = std::fs::remove_file(out);
    }
    stopped.map(|(code, _)| code).unwrap_or(None)
}

/// Sends `signal` to `child` once `ready` says so, and waits for it. Returns its exit code and
/// stderr, or `None` when it finished (successfully) before the signal could be sent.
fn signal_when(
    mut child: Child,
    ready: impl Fn() -> bool,
    signal: &str,
) -> Option<(Option<i32>, String)> {
    let start = Instant::now();
    let mut sent = false;
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut stderr = String::new();
            use std::io::Read;
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut stderr)
                .unwrap();
            assert!(!stderr.contains("panicked"), "{stderr}");
            if !sent {
                assert!(status.success(), "compose failed: {stderr}");
                return None;
            }
            return Some((status.code(), stderr));
        }
        if !sent && ready() {
            send_signal(&child, signal);
            sent = true;
        }
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "compose did not finish"
        );
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// Whether this process ignores SIGINT (a background job of a non-interactive shell does, and
/// its children inherit that: they keep ignoring it, as they should).
fn sigint_ignored() -> bool {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("SigIgn:"))
                .and_then(|m| u64::from_str_radix(m.trim(), 16).ok())
        })
        .is_some_and(|mask| mask & 2 != 0)
}

#[test]
fn a_stopped_compose_leaves_no_temporary_file_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (signal, code) in [("TERM", 143), ("INT", 130)] {
        if signal == "INT" && sigint_ignored() {
            eprintln!("SIGINT is ignored by this test process and so by compose: not sent");
            continue;
        }
        let out = d.join(format!("out_{signal}.exr"));
        let mut size = 1024;
        let got = loop {
            slow_compose_inputs(d, size, size);
            if let Some(code) = stop_while_writing(d, &out, signal) {
                break code;
            }
            assert!(size < 4096, "compose always finished before SIG{signal}");
            size *= 2;
        };
        assert_eq!(got, code, "exit code after SIG{signal}");
        assert!(!out.exists(), "SIG{signal}: the unfinished output landed");
        assert_no_temporaries(d);
    }
}

/// Runs a sequence of `frames` frames of the slow inputs in `dir` (hard links `trans.0001.exr`,
/// …) with `--report`, and sends `signal` once the first frame's output has landed. Returns the
/// exit code and stderr, or `None` when the sequence finished before the signal was sent.
fn stop_a_sequence(dir: &Path, frames: u32, signal: &str) -> Option<(Option<i32>, String)> {
    for f in 1..=frames {
        for (name, ext) in [("trans", "exr"), ("refl", "exr"), ("mask", "png")] {
            let link = dir.join(format!("{name}.{f:04}.{ext}"));
            if !link.exists() {
                std::fs::hard_link(dir.join(format!("{name}.{ext}")), link).unwrap();
            }
        }
    }
    let child = compose()
        .current_dir(dir)
        .args(["--refl", "refl.####.exr", "--trans", "trans.####.exr"])
        .args(["--mask", "mask.####.png", "--data-type", "float"])
        .args([
            "--zip-level",
            "9",
            "-o",
            "out.####.exr",
            "--report",
            "r.json",
        ])
        .arg("--frames")
        .arg(format!("1-{frames}"))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn compose");
    let landed = || names(dir).iter().any(|n| n.starts_with("out."));
    signal_when(child, landed, signal)
}

#[test]
fn a_stopped_sequence_writes_its_report() {
    // The report says what a stopped run did: the frames finished (their outputs complete on
    // disk), the ones in flight (interrupted: no output), the ones never started, the signal;
    // and compose exits with 128 + the signal's number. (It was not written at all.)
    for (signal, code) in [("TERM", 143), ("INT", 130)] {
        if signal == "INT" && sigint_ignored() {
            eprintln!("SIGINT is ignored by this test process and so by compose: not sent");
            continue;
        }
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        slow_compose_inputs(d, 256, 256);
        let mut frames = 16;
        let (got, stderr) = loop {
            if let Some(stopped) = stop_a_sequence(d, frames, signal) {
                break stopped;
            }
            assert!(frames < 1024, "compose always finished before SIG{signal}");
            for n in names(d).iter().filter(|n| n.starts_with("out.")) {
                std::fs::remove_file(d.join(n)).unwrap();
            }
            frames *= 4;
        };
        assert_eq!(got, Some(code), "exit code after SIG{signal}: {stderr}");
        assert!(stderr.contains("wrote r.json"), "{stderr}");
        assert_no_temporaries(d);
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("r.json")).unwrap()).unwrap();
        assert_eq!(report["stopped_by"], format!("SIG{signal}"));
        let entries = report["frames"].as_array().unwrap();
        let numbers: Vec<u64> = entries
            .iter()
            .map(|e| e["frame"].as_u64().unwrap())
            .collect();
        assert_eq!(numbers, (1..=u64::from(frames)).collect::<Vec<_>>());
        let mut interrupted = Vec::new();
        for e in entries {
            let out = d.join(e["output"].as_str().unwrap());
            match e["status"].as_str().unwrap() {
                "composed" => assert!(out.exists() && e["seconds"]["encode"].is_number(), "{e}"),
                "interrupted" => interrupted.push(e["frame"].clone()),
                "not-started" => assert!(!out.exists(), "{e}"),
                other => panic!("frame status {other} in a stopped run: {e}"),
            }
        }
        assert!(report["composed"].as_u64().unwrap() >= 1, "{report}");
        assert_eq!(report["interrupted"], serde_json::Value::from(interrupted));
        assert!(report["interrupted"].as_array().unwrap().len() <= 2);
    }
}

/// Error lines quote what they read bounded: a 200 kB CSV field (`glassdb fit`), a 400 kB
/// catalog line (`glassdb registry build`) and a 200 kB spectral unit are cut with an
/// ellipsis and their length (glassdb_io::quoted).
#[test]
fn errors_quote_huge_input_values_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let csv = write_file(
        dir.path(),
        "big.csv",
        format!(
            "angle_deg,T,R\n0,{},0.1\n10,0.8,0.1\n",
            "9x".repeat(100_000)
        )
        .as_bytes(),
    );
    let said = fails(glassdb().arg("fit").arg(&csv));
    assert!(said.len() < 1000, "{} bytes: {:.300}", said.len(), said);
    assert!(
        said.contains("9x9x9x") && said.contains("…` (200000 bytes) is not a number"),
        "{said}"
    );

    let toml = write_file(
        dir.path(),
        "big.toml",
        format!(
            "[[glass]]\nname = \"x\"\nid = 1\nspectral = \"{}\n",
            "a".repeat(400_000)
        )
        .as_bytes(),
    );
    let said = fails(
        glassdb()
            .args(["registry", "build"])
            .arg(&toml)
            .arg("-o")
            .arg(dir.path().join("r.json")),
    );
    assert!(said.len() < 2000, "{} bytes: {:.300}", said.len(), said);
    assert!(said.contains("line 4") && said.contains("bytes)"), "{said}");

    let spectral = write_file(
        dir.path(),
        "big.units.csv",
        format!("wavelength ({}),T\n500,0.5\n", "q".repeat(200_000)).as_bytes(),
    );
    let said = fails(glassdb().arg("spectral").arg(&spectral));
    assert!(said.len() < 1000, "{} bytes: {:.300}", said.len(), said);
}

/// Camera and planes files quote what they read bounded too: serde_json's own message
/// (`invalid type: string "…"` quotes the value whole), a planes file's `format`, a camera's
/// frame keys given twice (`"1"` and `"000…01"`).
#[test]
fn camera_and_planes_errors_quote_huge_values_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let huge = "x".repeat(100_000);
    let camera = std::fs::read_to_string(repo_path("fixtures/scene/camera.json")).unwrap();
    let cameras = [
        serde_json::json!({"origin": huge, "target": [0, 0, 0], "fov_x_deg": 50, "width": 8, "height": 8})
            .to_string(),
        serde_json::json!({"frames": {"1": huge}}).to_string(),
        format!(r#"{{"frames": {{"1": {camera}, "{}1": {camera}}}}}"#, "0".repeat(100_000)),
    ];
    for (k, text) in cameras.iter().enumerate() {
        let cam = write_file(d, &format!("camera{k}.json"), text.as_bytes());
        let said = fails(
            mask_from(repo_path("fixtures/scene/room.obj"), &cam)
                .args(["--glass", "Clear_6mm=1", "-o"])
                .arg(d.join("m.png")),
        );
        assert!(said.len() < 1000, "{} bytes: {:.300}", said.len(), said);
        assert!(said.contains("bytes)"), "{said}");
    }
    let planes = [
        serde_json::json!({"format": "glassdb-planes/1", "planes": [huge]}),
        {
            let atrium = repo_path("fixtures/atrium/virtual/planes.json");
            let mut planes: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(atrium).unwrap()).unwrap();
            planes["format"] = huge.clone().into();
            planes
        },
    ];
    for (k, json) in planes.iter().enumerate() {
        let file = write_file(d, &format!("planes{k}.json"), json.to_string().as_bytes());
        let a = |f: &str| repo_path(&format!("fixtures/atrium/{f}"));
        let said = fails(
            compose()
                .args(["--refl".as_ref(), a("refl_0.exr").as_os_str()])
                .args(["--trans".as_ref(), a("trans.exr").as_os_str()])
                .args(["--mask".as_ref(), a("mask.png").as_os_str()])
                .arg("--planes")
                .arg(&file)
                .arg("-o")
                .arg(d.join("o.png")),
        );
        assert!(said.len() < 1000, "{} bytes: {:.300}", said.len(), said);
        assert!(
            said.contains("planes file") && said.contains("bytes)"),
            "{said}"
        );
    }
}
