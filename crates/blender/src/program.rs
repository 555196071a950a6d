//! The Blender program: finding it, its version, and running it headless with a time limit and
//! its output captured in a log file.

use std::fs::{File, OpenOptions};
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use glassdb_io::ChildGroup;

use crate::BlenderError;

/// The oldest Blender supported (Debian 12's 3.4; its Cycles, EXR and Python API are what the
/// script was measured on).
pub const MINIMUM_VERSION: (u32, u32) = (3, 4);
/// Exit code of the Blender-side script when the scene itself is the problem.
const SCENE_EXIT_CODE: i32 = 3;
/// What the Blender-side script writes before a scene problem.
const SCENE_ERROR_PREFIX: &str = "glassdb_blender: error: ";
/// How long `blender --version` may take.
const VERSION_TIMEOUT: Duration = Duration::from_secs(120);
/// Bytes of the log shown when Blender fails.
const LOG_TAIL_BYTES: u64 = 2000;

/// Python run by a `bpy` interpreter: opens the .blend (argv[1]), then runs the script
/// (argv[2]) as `__main__` with Blender's own argv (`… -- ARGS`), as `blender -b BLEND -P SCRIPT`
/// would; an exception exits 1, as `--python-exit-code 1` does.
const BPY_LAUNCHER: &str = "\
import runpy, sys, traceback
import bpy
blend, script = sys.argv[1], sys.argv[2]
bpy.ops.wm.open_mainfile(filepath=blend, load_ui=False)
sys.argv = ['blender', '-b', blend, '-P', script] + sys.argv[3:]
try:
    runpy.run_path(script, run_name='__main__')
except SystemExit:
    raise
except BaseException:
    traceback.print_exc()
    sys.exit(1)
";

/// Prints `Blender VERSION` from a `bpy` interpreter, or `no bpy: WHY` (on stdout, which is
/// the stream read).
const BPY_VERSION: &str = "\
import sys
try:
    import bpy
except Exception as e:
    print('no bpy:', type(e).__name__, e)
    sys.exit(1)
print('Blender', bpy.app.version_string)
";

/// How Blender is run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Launcher {
    /// Blender's own executable, headless (`blender -b`).
    Executable,
    /// A Python interpreter with the `bpy` module (Blender as a Python module, PyPI `bpy`).
    BpyModule,
}

/// A Blender program that answered `--version` with a supported version.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Blender {
    /// The Blender executable, or the Python interpreter that has `bpy`.
    pub path: PathBuf,
    /// How it is run.
    pub launcher: Launcher,
    /// As Blender prints it (`3.4.1`).
    pub version: String,
}

/// One headless run: the scene, the script and its arguments, the log and the time limit.
#[derive(Debug, Clone)]
pub struct BlenderRun<'a> {
    /// What the run does, for messages (`export`, `render`).
    pub step: &'static str,
    /// The scene.
    pub blend: &'a Path,
    /// The Blender-side script.
    pub script: &'a Path,
    /// The script's arguments.
    pub args: Vec<String>,
    /// Blender's stdout and stderr are appended here.
    pub log: &'a Path,
    /// The longest it may take.
    pub timeout: Duration,
}

/// `major.minor` from the first line of `blender --version` (`Blender 3.4.1`, `Blender 4.2.0 LTS`).
pub fn parse_version(printed: &str) -> Option<(String, (u32, u32))> {
    let line = printed
        .lines()
        .find(|l| l.trim_start().starts_with("Blender "))?;
    let version = line
        .trim_start()
        .strip_prefix("Blender ")?
        .split_whitespace()
        .next()?;
    let mut parts = version.split('.');
    let major = parts.next()?.parse().ok()?;
    let minor = parts.next()?.parse().ok()?;
    Some((version.to_string(), (major, minor)))
}

impl Blender {
    /// The Blender at `path`, or `blender` from PATH; refused when it cannot run or is older
    /// than [`MINIMUM_VERSION`].
    pub fn find(path: Option<&Path>) -> Result<Blender, BlenderError> {
        let path = path.map_or_else(|| PathBuf::from("blender"), Path::to_path_buf);
        Self::find_with(path, Launcher::Executable)
    }

    /// Blender as the `bpy` module of the Python interpreter `python` (PyPI `bpy`, e.g. 4.2–5.0
    /// on Python 3.11); refused when it cannot import `bpy` or the version is too old.
    pub fn find_bpy(python: &Path) -> Result<Blender, BlenderError> {
        Self::find_with(python.to_path_buf(), Launcher::BpyModule)
    }

    fn find_with(path: PathBuf, launcher: Launcher) -> Result<Blender, BlenderError> {
        let printed = Self::ask_version(&path, launcher, VERSION_TIMEOUT)?;
        if launcher == Launcher::BpyModule
            && let Some(said) = printed.lines().find_map(|l| l.strip_prefix("no bpy: "))
        {
            return Err(BlenderError::NoBpyModule {
                python: path,
                said: said.chars().take(300).collect(),
            });
        }
        let Some((version, number)) = parse_version(&printed) else {
            return Err(BlenderError::VersionUnreadable {
                path,
                printed: printed.chars().take(200).collect(),
            });
        };
        if number < MINIMUM_VERSION {
            return Err(BlenderError::TooOld {
                path,
                found: version,
                minimum: MINIMUM_VERSION,
            });
        }
        Ok(Blender {
            path,
            launcher,
            version,
        })
    }

    /// What `path` prints on stdout when asked for its version (at most 1 MiB, lossily decoded);
    /// stopped, and refused, when it takes longer than `limit`.
    fn ask_version(
        path: &Path,
        launcher: Launcher,
        limit: Duration,
    ) -> Result<String, BlenderError> {
        let mut command = Command::new(path);
        match launcher {
            Launcher::Executable => command.args(["-b", "--factory-startup", "--version"]),
            Launcher::BpyModule => command.args(["-c", BPY_VERSION]),
        };
        let mut child = ChildGroup::spawn(
            command
                .stdin(Stdio::null())
                .stdout(Stdio::piped())
                .stderr(Stdio::null()),
        )
        .map_err(|source| BlenderError::NotFound {
            path: path.to_path_buf(),
            source,
        })?;
        let started = Instant::now();
        // Read on a thread, so that the time limit holds while the program says nothing;
        // bounded, so that a program printing without end is stopped by the limit too.
        let (sender, said) = mpsc::channel();
        if let Some(out) = child.child().stdout.take() {
            std::thread::spawn(move || {
                let mut bytes = Vec::new();
                let _ = out.take(1 << 20).read_to_end(&mut bytes);
                let _ = sender.send(bytes);
            });
        }
        let timed_out = || BlenderError::VersionTimedOut {
            path: path.to_path_buf(),
            seconds: limit.as_secs(),
        };
        wait_with_timeout(&mut child, limit, Duration::from_millis(20))
            .map_err(BlenderError::io("wait for", path))?
            .ok_or_else(timed_out)?;
        // The program has exited; a process it started may still hold its output open.
        let bytes = match said.recv_timeout(limit.saturating_sub(started.elapsed())) {
            Ok(bytes) => bytes,
            Err(mpsc::RecvTimeoutError::Timeout) => return Err(timed_out()),
            Err(mpsc::RecvTimeoutError::Disconnected) => Vec::new(),
        };
        Ok(String::from_utf8_lossy(&bytes).into_owned())
    }

    /// Runs `blender -b BLEND --factory-startup -noaudio --python-exit-code 1 -P SCRIPT -- ARGS`
    /// (or the same through a `bpy` interpreter), its output appended to the log, stopped after the time limit.
    pub fn run(&self, run: &BlenderRun<'_>) -> Result<(), BlenderError> {
        let io = BlenderError::io;
        let mut log = OpenOptions::new()
            .create(true)
            .append(true)
            .open(run.log)
            .map_err(io("write the log", run.log))?;
        let start = log
            .seek(SeekFrom::End(0))
            .map_err(io("write the log", run.log))?;
        writeln!(
            log,
            "== glassdb blender {}: {} ==",
            run.step,
            self.path.display()
        )
        .map_err(io("write the log", run.log))?;
        let err_log = log.try_clone().map_err(io("write the log", run.log))?;
        let mut command = Command::new(&self.path);
        match self.launcher {
            Launcher::Executable => command.arg("-b").arg(not_an_option(run.blend)).args([
                "--factory-startup",
                "-noaudio",
                "--python-exit-code",
                "1",
                "-P",
            ]),
            Launcher::BpyModule => command.args(["-c", BPY_LAUNCHER]).arg(run.blend),
        };
        // In a process group of its own: on the time limit, or when glassdb is stopped, the
        // group is killed, with whatever Blender started.
        let mut child = ChildGroup::spawn(
            command
                .arg(run.script)
                .arg("--")
                .args(&run.args)
                .stdin(Stdio::null())
                .stdout(Stdio::from(log))
                .stderr(Stdio::from(err_log)),
        )
        .map_err(|source| BlenderError::NotFound {
            path: self.path.clone(),
            source,
        })?;
        let Some(status) = wait_with_timeout(&mut child, run.timeout, Duration::from_millis(50))
            .map_err(io("wait for Blender", &self.path))?
        else {
            return Err(BlenderError::TimedOut {
                step: run.step,
                blend: run.blend.to_path_buf(),
                seconds: run.timeout.as_secs(),
                log: run.log.to_path_buf(),
            });
        };
        if status.success() {
            return Ok(());
        }
        let tail = log_since(run.log, start);
        if status.code() == Some(SCENE_EXIT_CODE)
            && let Some(message) = tail
                .lines()
                .rev()
                .find_map(|l| l.strip_prefix(SCENE_ERROR_PREFIX))
        {
            return Err(BlenderError::Scene {
                step: run.step,
                blend: run.blend.to_path_buf(),
                message: message.to_string(),
                log: run.log.to_path_buf(),
            });
        }
        Err(BlenderError::Failed {
            step: run.step,
            blend: run.blend.to_path_buf(),
            status: describe_status(status),
            log: run.log.to_path_buf(),
            tail: last_bytes(&tail, LOG_TAIL_BYTES as usize),
        })
    }
}

/// Waits for `child` to exit, looking every `poll`; past `limit` its whole process group is
/// killed (and it is reaped) and the answer is `None`.
pub(crate) fn wait_with_timeout(
    child: &mut ChildGroup,
    limit: Duration,
    poll: Duration,
) -> io::Result<Option<ExitStatus>> {
    let started = Instant::now();
    loop {
        match child.try_wait() {
            Ok(Some(status)) => return Ok(Some(status)),
            Ok(None) if started.elapsed() <= limit => std::thread::sleep(poll),
            waited => {
                child.kill();
                return waited.map(|_| None);
            }
        }
    }
}

/// A path Blender's argument parser cannot take for an option: one that starts with `-` is
/// given as `./-…` (Blender 3.4 reads `-dash.blend` after `-b` as an unknown option).
fn not_an_option(path: &Path) -> PathBuf {
    if path.as_os_str().as_encoded_bytes().starts_with(b"-") {
        Path::new(".").join(path)
    } else {
        path.to_path_buf()
    }
}

/// CPU seconds (user + system) of the child processes this process has waited for so far
/// (every Blender run), from `/proc/self/stat` (Linux; fields `cutime` and `cstime` in clock
/// ticks of 1/100 s, Linux's USER_HZ); `None` where that file cannot be read.
pub fn children_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // After the command name in parentheses: field 3 (state) onwards.
    let fields: Vec<&str> = stat[stat.rfind(')')? + 1..].split_whitespace().collect();
    let cutime: f64 = fields.get(13)?.parse().ok()?;
    let cstime: f64 = fields.get(14)?.parse().ok()?;
    Some((cutime + cstime) / 100.0)
}

/// "exit code 1" or "killed by signal 11 (a crash)".
fn describe_status(status: ExitStatus) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        if let Some(signal) = status.signal() {
            return format!("killed by signal {signal} (a crash)");
        }
    }
    match status.code() {
        Some(code) => format!("exit code {code}"),
        None => "stopped".to_string(),
    }
}

/// What the log holds from byte `start` on (at most a few MiB, lossily decoded).
fn log_since(log: &Path, start: u64) -> String {
    let mut text = Vec::new();
    if let Ok(mut f) = File::open(log)
        && f.seek(SeekFrom::Start(start)).is_ok()
    {
        let _ = f.take(4 << 20).read_to_end(&mut text);
    }
    String::from_utf8_lossy(&text).into_owned()
}

/// The last `n` bytes of `text`, cut at a character boundary.
fn last_bytes(text: &str, n: usize) -> String {
    let mut cut = text.len().saturating_sub(n);
    while !text.is_char_boundary(cut) {
        cut += 1;
    }
    text[cut..].trim().to_string()
}

/// Refuses a scene that is missing, not a regular file, or not a .blend file (plain, gzip or
/// zstd compressed): Blender itself would go on with its default scene.
pub fn check_blend_file(path: &Path) -> Result<(), BlenderError> {
    let not = |reason: String| BlenderError::NotBlendFile {
        path: path.to_path_buf(),
        reason,
    };
    let meta = std::fs::metadata(path).map_err(|e| not(e.to_string()))?;
    if !meta.is_file() {
        return Err(not("not a regular file".into()));
    }
    let mut head = [0u8; 7];
    let mut f = File::open(path).map_err(|e| not(e.to_string()))?;
    f.read_exact(&mut head)
        .map_err(|_| not("shorter than a .blend header".into()))?;
    let blend = &head == b"BLENDER";
    let gzip = head.starts_with(&[0x1f, 0x8b]);
    let zstd = head.starts_with(&[0x28, 0xb5, 0x2f, 0xfd]);
    if blend || gzip || zstd {
        Ok(())
    } else {
        Err(not(
            "it does not start with BLENDER (nor is it a compressed .blend)".into(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn versions_as_blender_prints_them() {
        assert_eq!(
            parse_version("Blender 3.4.1\n\tbuild date: ..."),
            Some(("3.4.1".into(), (3, 4)))
        );
        assert_eq!(
            parse_version("Color management...\nBlender 4.2.0 LTS\n"),
            Some(("4.2.0".into(), (4, 2)))
        );
        assert_eq!(parse_version("bash: blender: not found"), None);
        assert!(parse_version("Blender 2.93.1").unwrap().1 < MINIMUM_VERSION);
    }

    #[test]
    fn children_cpu_counts_a_waited_child() {
        let before = children_cpu_seconds().expect("Linux /proc");
        // A child that spins for a while on the CPU.
        let status = Command::new("sh")
            .args(["-c", "i=0; while [ $i -lt 200000 ]; do i=$((i+1)); done"])
            .status()
            .unwrap();
        assert!(status.success());
        let after = children_cpu_seconds().unwrap();
        assert!(after > before, "{before} -> {after}");
    }

    /// A stand-in program in a fresh directory, running `body` (sh). Written by a child
    /// process: a file this process had open for writing can be inherited by a child another
    /// test thread forks at that moment, and running it then fails (ETXTBSY).
    fn script(body: &str) -> (tempfile::TempDir, PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("blender");
        let status = Command::new("sh")
            .args([
                "-c",
                "printf '#!/bin/sh\\n%s\\n' \"$2\" > \"$1\" && chmod 755 \"$1\"",
            ])
            .arg("sh")
            .arg(&path)
            .arg(body)
            .status()
            .unwrap();
        assert!(status.success());
        (dir, path)
    }

    #[test]
    fn a_version_probe_that_hangs_is_stopped() {
        // Silent, or silent after its version: stopped at the limit.
        for body in ["sleep 30", "echo Blender 3.4.1; exec sleep 30"] {
            let (_dir, path) = script(body);
            let started = Instant::now();
            let err = Blender::ask_version(&path, Launcher::Executable, Duration::from_secs(1))
                .map(|printed| printed.len())
                .unwrap_err();
            assert!(
                matches!(&err, BlenderError::VersionTimedOut { path: p, seconds: 1 } if *p == path),
                "{body}: {err}"
            );
            assert!(started.elapsed() < Duration::from_secs(10), "{body}");
        }
        // Printing without end: read up to 1 MiB, then the pipe closes on it.
        let (_dir, path) = script("exec yes");
        let printed =
            Blender::ask_version(&path, Launcher::Executable, Duration::from_secs(30)).unwrap();
        assert_eq!(printed.len(), 1 << 20);
        let (_dir, path) = script("echo Blender 3.4.1");
        let printed =
            Blender::ask_version(&path, Launcher::Executable, Duration::from_secs(10)).unwrap();
        assert_eq!(parse_version(&printed), Some(("3.4.1".into(), (3, 4))));
    }

    #[test]
    fn waiting_kills_past_the_limit() {
        let mut child = ChildGroup::spawn(Command::new("sleep").arg("30")).unwrap();
        let started = Instant::now();
        let waited = wait_with_timeout(
            &mut child,
            Duration::from_millis(200),
            Duration::from_millis(10),
        );
        assert!(waited.unwrap().is_none());
        assert!(started.elapsed() < Duration::from_secs(5));
        // Killed and reaped.
        assert!(child.child().try_wait().unwrap().is_some());
        let mut quick = ChildGroup::spawn(&mut Command::new("true")).unwrap();
        let status = wait_with_timeout(
            &mut quick,
            Duration::from_secs(10),
            Duration::from_millis(10),
        );
        assert!(status.unwrap().unwrap().success());
    }

    #[test]
    fn log_tail_cuts_at_a_character() {
        assert_eq!(last_bytes("aé b", 3), "b");
        assert_eq!(last_bytes("short", 100), "short");
    }
}
