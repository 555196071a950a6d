//! Frames on a farm (docs/farm.md): `--skip-existing`, `--report frames.json`, the exit code of
//! a sequence with failed frames, and the Open Job Description template of
//! `integrations/farm/` run by `openjd run` (its render step copies the atrium's fixture passes
//! per frame, standing in for a renderer).

use std::path::Path;

use crate::util::{compose, fails, ok, read_exr_planes, repo_path, run};

/// The atrium's passes copied as frames `frames` of a sequence in `dir`
/// (`refl_K.####.exr`, `trans.####.exr`, `mask.####.png`), as a renderer would write them.
fn atrium_frames(dir: &Path, frames: &[u32]) {
    let a = repo_path("fixtures/atrium");
    for &f in frames {
        for name in ["refl_0", "refl_1", "refl_2", "trans"] {
            std::fs::copy(
                a.join(format!("{name}.exr")),
                dir.join(format!("{name}.{f:04}.exr")),
            )
            .unwrap();
        }
        std::fs::copy(a.join("mask.png"), dir.join(format!("mask.{f:04}.png"))).unwrap();
    }
}

/// `compose` over the frame sequence in `dir` into `out.####.exr`.
fn compose_frames(dir: &Path, frames: &str) -> std::process::Command {
    let mut c = compose();
    c.current_dir(dir);
    for k in 0..3 {
        c.arg("--refl").arg(format!("refl_{k}.####.exr"));
    }
    c.args(["--trans", "trans.####.exr", "--mask", "mask.####.png"])
        .arg("--planes")
        .arg(repo_path("fixtures/atrium/virtual/planes.json"))
        .args(["-o", "out.####.exr", "--frames", frames]);
    c
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// (frame, status) of every entry of a frames report.
fn statuses(report: &serde_json::Value) -> Vec<(u64, String)> {
    report["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["frame"].as_u64().unwrap(),
                f["status"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

fn mtime(p: &Path) -> std::time::SystemTime {
    std::fs::metadata(p).unwrap().modified().unwrap()
}

#[test]
fn reruns_skip_complete_frames_and_the_report_says_what_each_frame_did() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    atrium_frames(d, &[1, 2, 3, 5]);
    std::fs::write(d.join("mask.0005.png"), b"\x89PNG\r\n\x1a\nbroken").unwrap();

    // Frame 4 has no inputs, frame 5 a corrupt mask: exit 1, both named, the report written.
    let err = fails(compose_frames(d, "1-5").args(["--report", "r1.json"]));
    assert!(err.contains("2 of 5 frame(s) failed: 4, 5"), "{err}");
    let r1 = json(&d.join("r1.json"));
    assert_eq!(r1["format"], "glassdb-frames-report/1");
    assert_eq!(
        statuses(&r1),
        [
            (1, "composed"),
            (2, "composed"),
            (3, "composed"),
            (4, "failed"),
            (5, "failed")
        ]
        .map(|(f, s)| (f, s.to_string()))
    );
    assert_eq!(r1["failed"], serde_json::json!([4, 5]));
    let f4 = &r1["frames"][3];
    assert!(
        f4["error"].as_str().unwrap().contains("refl_0.0004.exr")
            || f4["error"].as_str().unwrap().contains("0004"),
        "{f4}"
    );
    assert!(
        r1["frames"][4]["error"]
            .as_str()
            .unwrap()
            .contains("mask.0005.png")
    );
    let f1 = &r1["frames"][0];
    assert_eq!(f1["output"], "out.0001.exr");
    assert_eq!(
        f1["inputs"]["trans"],
        "trans.####.exr".replace("####", "0001")
    );
    assert_eq!(f1["inputs"]["refl"][2], "refl_2.0001.exr");
    assert!(f1["seconds"]["wall"].as_f64().unwrap() > 0.0);
    assert!(f1["seconds"]["encode"].as_f64().unwrap() > 0.0);
    assert!(f1["error"].is_null());

    // A truncated output (say, a copy cut short) is not complete; a missing one is composed.
    let out2 = d.join("out.0002.exr");
    let len = std::fs::metadata(&out2).unwrap().len();
    let pixels = read_exr_planes(&out2).channels;
    let bytes = std::fs::read(&out2).unwrap();
    std::fs::write(&out2, &bytes[..(len / 2) as usize]).unwrap();
    std::fs::remove_file(d.join("out.0003.exr")).unwrap();
    let kept = mtime(&d.join("out.0001.exr"));
    std::fs::copy(
        repo_path("fixtures/atrium/mask.png"),
        d.join("mask.0005.png"),
    )
    .unwrap();
    atrium_frames(d, &[4]);
    let stdout = ok(compose_frames(d, "1-5").args(["--skip-existing", "--report", "r2.json"]));
    assert!(stdout.contains("skipped 1 frame(s)"), "{stdout}");
    let r2 = json(&d.join("r2.json"));
    assert_eq!(
        statuses(&r2),
        [
            (1, "skipped"),
            (2, "composed"),
            (3, "composed"),
            (4, "composed"),
            (5, "composed")
        ]
        .map(|(f, s)| (f, s.to_string()))
    );
    assert!(
        r2["frames"][1]["replaced"]
            .as_str()
            .unwrap()
            .contains("incomplete")
    );
    assert!(r2["frames"][0]["seconds"]["decode"].is_null());
    assert_eq!(
        mtime(&d.join("out.0001.exr")),
        kept,
        "a skipped frame is not rewritten"
    );
    assert!(
        read_exr_planes(&out2).channels == pixels,
        "frame 2 composited again, whole"
    );

    // Everything complete: a rerun does nothing and succeeds.
    ok(compose_frames(d, "1-5").args(["--skip-existing", "--report", "r3.json"]));
    let r3 = json(&d.join("r3.json"));
    assert_eq!(r3["skipped"], 5);
    assert_eq!(r3["composed"], 0);

    // The flags address frames: without --frames they are refused by the parser (exit 2).
    let (out, _, stderr) = run(compose().current_dir(d).args([
        "--refl",
        "a.exr",
        "--trans",
        "b.exr",
        "--mask",
        "c.png",
        "--skip-existing",
    ]));
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--frames"), "{stderr}");
}
