//! Frames on a farm (docs/farm.md): `--skip-existing`, `--report frames.json`, the exit code of
//! a sequence with failed frames, the output folders compose creates, and the Open Job
//! Description templates of `integrations/farm/` run by `openjd run`: the compose template (its
//! render step copies the atrium's fixture passes per frame, standing in for a renderer) and
//! the Blender shot's, and docs/farm.md's commands as written.

use std::path::{Path, PathBuf};

use crate::util::{
    atrium_compose, atrium_refl, compose, fails, fails_naming, ok, oracle_python, read_exr_planes,
    repo_path, run, run_oracle,
};

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
    compose_frames_to(dir, frames, "out.####.exr")
}

/// `compose` over the frame sequence in `dir` into `output`.
fn compose_frames_to(dir: &Path, frames: &str, output: &str) -> std::process::Command {
    let mut c = compose();
    c.current_dir(dir);
    for k in 0..3 {
        c.arg("--refl").arg(format!("refl_{k}.####.exr"));
    }
    c.args(["--trans", "trans.####.exr", "--mask", "mask.####.png"])
        .arg("--planes")
        .arg(repo_path("fixtures/atrium/virtual/planes.json"))
        .args(["-o", output, "--frames", frames]);
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

/// `openjd run` of the bundled template with `params`, in the oracle venv (python_oracle's
/// requirements pin openjd-cli). Returns the output and the run's log.
fn openjd_run(params: &[(&str, String)]) -> (std::process::Output, String) {
    let openjd = oracle_python().with_file_name("openjd");
    let mut c = std::process::Command::new(&openjd);
    c.arg("run")
        .arg(repo_path("integrations/farm/openjd/glassdb-composite.yaml"))
        .args(["--extensions", "TASK_CHUNKING"]);
    for (k, v) in params {
        c.arg("-p").arg(format!("{k}={v}"));
    }
    let (out, stdout, stderr) = run(&mut c);
    (out, format!("{stdout}\n{stderr}"))
}

/// Asserts that the composites `frames` of `output` (a `####` pattern in `dir`), each made of a
/// copy of the atrium's passes, are what `compose` makes of those passes by hand.
fn assert_frames_are_atriums(dir: &Path, output: &str, frames: std::ops::RangeInclusive<u32>) {
    let by_hand = dir.join("by_hand.exr");
    ok(&mut atrium_compose(&atrium_refl(), &by_hand));
    let want = read_exr_planes(&by_hand).channels;
    for f in frames {
        let got = read_exr_planes(&dir.join(output.replace("####", &format!("{f:04}"))));
        assert!(
            got.channels == want,
            "frame {f} differs from compose by hand"
        );
    }
}

#[test]
fn the_open_job_description_template_renders_then_composites_in_chunks() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let atrium = repo_path("fixtures/atrium");
    // The render step's command: the atrium's fixture passes copied as the chunk's frames (a
    // stand-in for a renderer such as `glassdb blender render`); frame 4 is never "rendered".
    let render = format!(
        "for f in $(seq $FRAME_START $FRAME_END); do [ $f = 4 ] && continue; n=$(printf %04d $f); \
         for p in refl_0 refl_1 refl_2 trans; do cp {a}/$p.exr $p.$n.exr; done; \
         cp {a}/mask.png mask.$n.png; done",
        a = atrium.display()
    );
    let planes = atrium.join("virtual/planes.json");
    let params = |frames: &str| {
        vec![
            ("Frames", frames.to_string()),
            ("ChunkSize", "2".to_string()),
            ("WorkDir", d.display().to_string()),
            ("RenderCommand", render.clone()),
            ("Glassdb", env!("CARGO_BIN_EXE_glassdb").to_string()),
            (
                "ComposeArgs",
                format!(
                    "--refl refl_0.####.exr --refl refl_1.####.exr --refl refl_2.####.exr \
                     --trans trans.####.exr --mask mask.####.png --planes {}",
                    planes.display()
                ),
            ),
        ]
    };
    let (out, log) = openjd_run(&params("1-3"));
    assert!(out.status.success(), "{log}");
    assert!(
        log.contains("Chunks run: 4"),
        "2 render + 2 composite chunks: {log}"
    );
    assert_frames_are_atriums(d, "composite/out.####.exr", 1..=3);
    let chunk = json(&d.join("reports/frames.1-2.json"));
    assert_eq!(
        statuses(&chunk),
        vec![(1, "composed".to_string()), (2, "composed".to_string())]
    );

    // Frames 1-4: frame 4 has no passes, so its chunk fails (and with it the job); the
    // chunk's report says that frame 3 was complete and kept, and why frame 4 failed.
    let (out, log) = openjd_run(&params("1-4"));
    assert!(!out.status.success(), "{log}");
    let chunk = json(&d.join("reports/frames.3-4.json"));
    assert_eq!(
        statuses(&chunk),
        vec![(3, "skipped".to_string()), (4, "failed".to_string())]
    );
    assert!(
        chunk["frames"][1]["error"]
            .as_str()
            .unwrap()
            .contains("0004"),
        "{chunk}"
    );
    assert_eq!(
        statuses(&json(&d.join("reports/frames.1-2.json"))),
        vec![(1, "skipped".to_string()), (2, "skipped".to_string())]
    );
}

#[test]
fn one_file_holds_every_planes_reflection_cropped_to_its_glass() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = repo_path("fixtures/atrium");
    let refl = atrium_refl();
    let oracle = |args: &[&std::ffi::OsStr]| {
        run_oracle(
            "plane_parts.py",
            &args
                .iter()
                .copied()
                .chain(refl.iter().map(|p| p.as_os_str()))
                .collect::<Vec<_>>(),
        )
    };
    // Written by OpenEXR itself: parts plane0..2, each cropped to its plane's glass; and one
    // part with layers plane0..2 over the whole frame.
    let parts = d.join("planes.exr");
    let windows = oracle(&[
        "parts".as_ref(),
        "--mask".as_ref(),
        a.join("mask.png").as_os_str(),
        "--out".as_ref(),
        parts.as_os_str(),
    ]);
    let windows: Vec<[i64; 4]> = serde_json::from_str(windows.trim()).unwrap();
    let cropped: u64 = windows
        .iter()
        .map(|w| ((w[2] - w[0] + 1) * (w[3] - w[1] + 1)) as u64)
        .sum();
    assert!(
        cropped < 3 * 320 * 240 / 2,
        "the parts are crops: {windows:?}"
    );
    let layers = d.join("layers.exr");
    oracle(&["layers".as_ref(), "--out".as_ref(), layers.as_os_str()]);

    let composite = |refl: &[PathBuf], out: &str| atrium_compose(refl, &d.join(out));
    ok(&mut composite(&refl, "separate.exr"));
    let stdout = ok(composite(std::slice::from_ref(&parts), "out_parts.exr").arg("--stats"));
    assert!(stdout.contains("3 reflection pass(es)"), "{stdout}");
    ok(&mut composite(
        std::slice::from_ref(&layers),
        "out_layers.exr",
    ));
    let want = read_exr_planes(&d.join("separate.exr")).channels;
    for out in ["out_parts.exr", "out_layers.exr"] {
        assert!(
            read_exr_planes(&d.join(out)).channels == want,
            "{out} differs from the separate passes"
        );
    }

    // Plane layers must count from 0: plane1 and plane2 alone name the missing plane 0.
    let gap = d.join("gap.exr");
    run_oracle(
        "plane_parts.py",
        &[
            "layers".as_ref(),
            "--first".as_ref(),
            "1".as_ref(),
            "--out".as_ref(),
            gap.as_os_str(),
            refl[1].as_os_str(),
            refl[2].as_os_str(),
        ],
    );
    let err = fails(&mut composite(std::slice::from_ref(&gap), "gap_out.exr"));
    assert!(
        err.contains("plane 0 is missing") && err.contains("gap.exr"),
        "{err}"
    );
}

#[test]
fn compose_creates_the_folders_of_its_outputs_and_report() {
    // docs/farm.md's `-o comp/out.####.exr --report reports/…` in a shot folder that has
    // neither folder yet: every frame used to fail ("the directory comp does not exist").
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    atrium_frames(d, &[1, 2]);
    let mut c = compose_frames_to(d, "1-2", "comp/a/out.####.exr");
    let out = ok(c.args(["--report", "reports/b/frames.1-2.json"]));
    for f in [1, 2] {
        assert!(d.join(format!("comp/a/out.{f:04}.exr")).is_file(), "{out}");
    }
    let report = json(&d.join("reports/b/frames.1-2.json"));
    assert_eq!(
        statuses(&report),
        vec![(1, "composed".to_string()), (2, "composed".to_string())]
    );
    // One frame, into a new folder; no temporary file is left in it.
    ok(&mut atrium_compose(
        &atrium_refl(),
        &d.join("single/x/out.png"),
    ));
    let names: Vec<_> = std::fs::read_dir(d.join("single/x"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["out.png"]);
    // A run that fails makes no folder.
    fails(
        compose()
            .current_dir(d)
            .args(["--refl", "refl_0.0009.exr", "--trans", "trans.0009.exr"])
            .args(["--mask", "mask.0001.png", "-o", "never/out.exr"]),
    );
    assert!(!d.join("never").exists());
    // A folder that cannot be made is named.
    std::fs::write(d.join("file"), "").unwrap();
    fails_naming(
        &mut atrium_compose(&atrium_refl(), &d.join("file/sub/out.exr")),
        &["file/sub"],
    );
}

/// The indented command of docs/farm.md that starts with `start`, its continuation lines
/// joined (backslashes dropped).
fn docs_command(start: &str) -> String {
    let doc = std::fs::read_to_string(repo_path("docs/farm.md")).unwrap();
    let mut lines = doc
        .lines()
        .skip_while(|l| !l.trim_start().starts_with(start));
    let mut command = String::new();
    for line in lines.by_ref() {
        let line = line.trim();
        match line.strip_suffix('\\') {
            Some(part) => command.push_str(part),
            None => {
                command.push_str(line);
                break;
            }
        }
    }
    assert!(!command.is_empty(), "docs/farm.md has no `{start}` command");
    command
}

/// Replaces the value after `key` (up to the next space) in a command of docs/farm.md with
/// `value`, quoted: the values a test cannot take as written (240 frames in /shots/atrium).
fn set_docs_value(command: &mut String, key: &str, value: &str) {
    let at = command
        .find(key)
        .unwrap_or_else(|| panic!("no {key}: {command}"))
        + key.len();
    let end = command[at..].find(' ').map_or(command.len(), |e| at + e);
    command.replace_range(at..end, &format!("'{value}'"));
}

#[test]
fn the_docs_standalone_compose_runs_as_written() {
    // docs/farm.md's `compose …` as written, in a shot folder holding the atrium's passes as
    // frames 101-108 and its planes.json: comp/ and reports/ do not exist yet.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    atrium_frames(d, &(101..=108).collect::<Vec<_>>());
    std::fs::copy(
        repo_path("fixtures/atrium/virtual/planes.json"),
        d.join("planes.json"),
    )
    .unwrap();
    let command = docs_command("compose --refl");
    let args: Vec<&str> = command.split_whitespace().skip(1).collect();
    ok(compose().current_dir(d).args(&args));
    let report = json(&d.join("reports/frames.101-108.json"));
    let composed: Vec<(u64, String)> = (101..=108).map(|f| (f, "composed".into())).collect();
    assert_eq!(statuses(&report), composed);
    // A farm's retry: every frame is complete and kept.
    ok(compose().current_dir(d).args(&args));
    let report = json(&d.join("reports/frames.101-108.json"));
    assert!(
        statuses(&report).iter().all(|(_, s)| s == "skipped"),
        "{report}"
    );
}

#[test]
fn the_docs_blender_shot_renders_then_composites_each_once() {
    // docs/farm.md's `openjd run …/glassdb-blender.yaml` as written, but for two frames in
    // chunks of one, a work folder of its own and a small, quick render.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let blend = crate::blender::default_scene(d, "defaults");
    std::fs::rename(&blend, d.join("scene.blend")).unwrap();
    let mut command = docs_command("openjd run integrations/farm/openjd/glassdb-blender.yaml");
    // The parameters a test cannot take as written (1-240 frames in /shots/atrium).
    set_docs_value(&mut command, "Frames=", "1-2");
    set_docs_value(&mut command, "ChunkSize=", "1");
    set_docs_value(&mut command, "WorkDir=", &d.display().to_string());
    // A small, quick render: flags added to RenderArgs="…".
    let at = command.find("RenderArgs=\"").expect("RenderArgs") + "RenderArgs=\"".len();
    let close = at + command[at..].find('"').unwrap();
    command.insert_str(close, " --samples 4 --resolution 64x36 --threads 2");
    let openjd = oracle_python().with_file_name("openjd");
    let script = format!(
        "{} -p Glassdb='{}'",
        command.replacen("openjd", &openjd.display().to_string(), 1),
        env!("CARGO_BIN_EXE_glassdb")
    );
    let (out, stdout, stderr) = run(std::process::Command::new("bash")
        .args(["-c", &script])
        .current_dir(crate::util::repo_root()));
    let log = format!("{script}\n{stdout}\n{stderr}");
    assert!(out.status.success(), "{log}");
    assert!(
        log.contains("Chunks run: 4"),
        "2 render + 2 composite chunks: {log}"
    );
    // Render tasks stop at the passes; each frame is composited once, by its composite task.
    assert_eq!(log.matches("ready in").count(), 2, "{log}");
    assert_eq!(log.matches("composited 1 frame(s)").count(), 2, "{log}");
    let composites: Vec<PathBuf> = std::fs::read_dir(d.join("glassdb"))
        .unwrap()
        .flat_map(|chunk| std::fs::read_dir(chunk.unwrap().path()).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("composite.")
        })
        .collect();
    assert_eq!(composites.len(), 2, "{composites:?}");
}

/// A one-node Slurm cluster on this machine, in `dir` (`scripts/slurm_local_cluster.sh`: its
/// own munged, slurmctld and slurmd, as root); its daemons are stopped when it is dropped, a
/// failed assertion included.
struct LocalSlurm {
    dir: PathBuf,
}

impl LocalSlurm {
    /// Starts the cluster; a machine without Slurm, or a test run that is not root, fails here
    /// with the script's message (install slurm-wlm and munge; run as root, as CI does).
    fn start(dir: PathBuf) -> LocalSlurm {
        std::fs::create_dir_all(&dir).unwrap();
        // Made before the start, so that a half-started cluster is stopped too.
        let cluster = LocalSlurm { dir };
        let (out, stdout, stderr) = run(&mut cluster.script("start"));
        assert!(
            out.status.success(),
            "the localhost Slurm cluster did not start (`bash scripts/test-all` installs \
             slurm-wlm and munge, and CI runs it as root):\n{stdout}{stderr}"
        );
        cluster
    }

    fn script(&self, action: &str) -> std::process::Command {
        let mut c = std::process::Command::new("bash");
        c.arg(repo_path("scripts/slurm_local_cluster.sh"))
            .arg(action)
            .arg(&self.dir);
        c
    }

    /// `program` run against this cluster (`SLURM_CONF`), with the Slurm tools and the built
    /// `glassdb` on `PATH`, as a user who installed both would have them.
    fn command(&self, program: &str) -> std::process::Command {
        let bin = Path::new(env!("CARGO_BIN_EXE_glassdb")).parent().unwrap();
        let path = std::env::var("PATH").unwrap_or_default();
        let mut c = std::process::Command::new(program);
        c.env("SLURM_CONF", self.dir.join("slurm.conf"))
            .env("PATH", format!("{}:/usr/sbin:/sbin:{path}", bin.display()));
        c
    }

    /// stdout of `program args…` against this cluster (a failure is part of the text).
    fn query(&self, program: &str, args: &[&str]) -> String {
        let (out, stdout, stderr) = run(self.command(program).args(args));
        format!(
            "$ {program} {}\n{stdout}{stderr}{}",
            args.join(" "),
            out.status
        )
    }

    /// What to read when a job went wrong: the queue, the jobs, each task's output in
    /// `work_dir` and the daemons' logs.
    fn diagnosis(&self, jobs: &str, work_dir: &Path) -> String {
        let mut text = self.query("squeue", &["-a"]);
        text += &self.query("scontrol", &["-o", "show", "job", jobs]);
        for entry in std::fs::read_dir(work_dir).unwrap() {
            let path = entry.unwrap().path();
            if path
                .file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("slurm-")
            {
                let output = std::fs::read_to_string(&path).unwrap_or_default();
                text += &format!("--- {}\n{output}", path.display());
            }
        }
        text + &run(&mut self.script("logs")).1
    }
}

impl Drop for LocalSlurm {
    fn drop(&mut self) {
        let (out, _, stderr) = run(&mut self.script("stop"));
        if !out.status.success() {
            eprintln!(
                "stopping the Slurm cluster in {}: {stderr}",
                self.dir.display()
            );
        }
    }
}

/// (array task, state, start, end) of each task of a job array, by task.
fn array_tasks(cluster: &LocalSlurm, job: &str) -> Vec<(u32, String, String, String)> {
    let text = cluster.query("scontrol", &["-o", "show", "job", job]);
    let mut tasks: Vec<_> = text
        .lines()
        .filter(|l| l.contains("ArrayTaskId="))
        .map(|line| {
            let field = |key: &str| {
                line.split(' ')
                    .find_map(|f| f.strip_prefix(key))
                    .unwrap_or_else(|| panic!("no {key} in {line}"))
                    .to_string()
            };
            let task = field("ArrayTaskId=").parse().unwrap();
            (
                task,
                field("JobState="),
                field("StartTime="),
                field("EndTime="),
            )
        })
        .collect();
    tasks.sort();
    tasks
}

#[test]
fn the_docs_slurm_submission_runs_on_a_localhost_cluster() {
    // docs/farm.md's `… integrations/farm/slurm/submit.sh --partition=render` as written, on a
    // one-node cluster of this machine, but for frames 1-3 in chunks of 2 (the last chunk is
    // one frame) in a shot folder of its own; its `render_passes.sh` copies the atrium's
    // fixture passes per frame, standing in for a renderer.
    let dir = tempfile::tempdir().unwrap();
    let shot = dir.path().join("shot");
    std::fs::create_dir(&shot).unwrap();
    let a = repo_path("fixtures/atrium");
    crate::util::write_executable(
        &shot,
        "render_passes.sh",
        &format!(
            "#!/bin/sh\nset -e\nfor f in $(seq \"$1\" \"$2\"); do n=$(printf %04d $f)\n\
             for p in refl_0 refl_1 refl_2 trans; do cp {a}/$p.exr $p.$n.exr; done\n\
             cp {a}/mask.png mask.$n.png\ndone\n",
            a = a.display()
        ),
    );
    std::fs::copy(a.join("virtual/planes.json"), shot.join("planes.json")).unwrap();
    let mut command = docs_command("FRAME_FIRST=");
    set_docs_value(&mut command, "FRAME_LAST=", "3");
    set_docs_value(&mut command, "CHUNK_SIZE=", "2");
    set_docs_value(&mut command, "WORK_DIR=", &shot.display().to_string());

    let cluster = LocalSlurm::start(dir.path().join("cluster"));
    let submitted = std::time::Instant::now();
    let mut submit = cluster.command("bash");
    let stdout = ok(submit
        .args(["-c", &command])
        .current_dir(crate::util::repo_root()));
    // submit.sh prints `render JOB composite JOB`.
    let ids: Vec<&str> = stdout.split_whitespace().collect();
    let [_, render, _, composite] = ids[..] else {
        panic!("submit.sh printed {stdout:?}, not `render JOB composite JOB`");
    };
    let jobs = format!("{render},{composite}");
    // Both arrays leave the queue within 3 minutes (about 12 s on an idle 2-core machine).
    let limit = std::time::Duration::from_secs(180);
    loop {
        let queue = cluster.query("squeue", &["-h", "-j", &jobs]);
        if queue.lines().count() == 2 && queue.ends_with("exit status: 0") {
            break; // the command line and its status: no job left
        }
        assert!(
            submitted.elapsed() < limit,
            "the Slurm jobs {jobs} are still queued after {limit:?}:\n{}",
            cluster.diagnosis(&jobs, &shot)
        );
        std::thread::sleep(std::time::Duration::from_millis(300));
    }
    eprintln!(
        "Slurm: both arrays out of the queue {:.1} s after submission",
        submitted.elapsed().as_secs_f64()
    );

    // Two tasks each, all completed; composite task K started when render task K had ended
    // (aftercorr; the times are whole seconds).
    let (renders, composites) = (
        array_tasks(&cluster, render),
        array_tasks(&cluster, composite),
    );
    let diagnosis = || cluster.diagnosis(&jobs, &shot);
    assert_eq!(renders.len(), 2, "{renders:?}\n{}", diagnosis());
    assert_eq!(composites.len(), 2, "{composites:?}\n{}", diagnosis());
    for (r, c) in renders.iter().zip(&composites) {
        assert!(
            r.0 == c.0 && r.1 == "COMPLETED" && c.1 == "COMPLETED" && c.2 >= r.3,
            "render task {r:?}, composite task {c:?}\n{}",
            diagnosis()
        );
    }
    // Every frame is what compose makes of the same passes by hand; each chunk's report says
    // its frames were composed.
    assert_frames_are_atriums(&shot, "comp/out.####.exr", 1..=3);
    for (chunk, frames) in [("1-2", vec![1, 2]), ("3-3", vec![3])] {
        let report = json(&shot.join(format!("reports/frames.{chunk}.json")));
        let composed: Vec<(u64, String)> = frames.iter().map(|&f| (f, "composed".into())).collect();
        assert_eq!(statuses(&report), composed, "{report}");
    }
}
