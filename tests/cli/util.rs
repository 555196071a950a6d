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

/// Writes `contents` to `dir/name` and returns the path.
pub fn write_file(dir: &Path, name: &str, contents: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, contents).expect("write test file");
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
