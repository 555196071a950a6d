//! The README's two commands, its contract with a newcomer on a fresh clone: the first builds
//! both tools and runs the main job on the bundled data, the second runs every test (and is
//! what CI runs).

use crate::util::{compose, fails, glassdb, ok, repo_path, repo_root};

/// The first two lines of the README's first `sh` block, comments cut.
pub(crate) fn readme_commands() -> (String, String) {
    let readme = std::fs::read_to_string(repo_path("README.md")).unwrap();
    let block = readme
        .split("```sh\n")
        .nth(1)
        .expect("README.md has an sh block");
    let mut lines = block
        .lines()
        .map(|l| l.split(" # ").next().unwrap_or("").trim().to_string());
    (lines.next().unwrap(), lines.next().unwrap())
}

#[test]
fn first_command_builds_both_tools_and_runs_the_main_job() {
    let (first, _) = readme_commands();
    let (build, job) = first
        .split_once("&&")
        .expect("the first command builds, then runs the main job");
    // A plain release build of the root package builds every [[bin]] it declares.
    assert_eq!(build.trim(), "cargo build --release", "{first}");
    let manifest = std::fs::read_to_string(repo_path("Cargo.toml")).unwrap();
    let bins: Vec<&str> = manifest
        .split("[[bin]]")
        .skip(1)
        .filter_map(|section| section.lines().find(|l| l.starts_with("name = ")))
        .map(|l| l.trim_start_matches("name = ").trim_matches('"'))
        .collect();
    assert_eq!(bins, ["glassdb", "compose"]);
    // The main job, with the binary this test was built with and the output in a temporary
    // directory.
    let mut args: Vec<String> = job.split_whitespace().map(str::to_string).collect();
    assert_eq!(args.remove(0), "target/release/compose", "{job}");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("atrium.png");
    let o = args
        .iter()
        .position(|a| a == "-o")
        .expect("the job names its output");
    args[o + 1] = out.display().to_string();
    let stats = ok(compose().args(&args).current_dir(repo_root()));
    assert!(std::fs::metadata(&out).unwrap().len() > 10_000, "{stats}");
    // One line says how to run the tools the build leaves.
    let readme = std::fs::read_to_string(repo_path("README.md")).unwrap();
    for how in ["target/release/glassdb", "cargo install --path ."] {
        assert!(readme.contains(how), "README.md should say `{how}`");
    }
}

#[test]
fn second_command_runs_every_test_as_ci_does() {
    let (_, second) = readme_commands();
    assert_eq!(second, "bash scripts/test-all");
    let ci = std::fs::read_to_string(repo_path(".ci/run")).unwrap();
    assert!(ci.contains("exec bash scripts/test-all"), "{ci}");
}

#[test]
fn registry_build_usage_makes_no_option_look_required() {
    // clap's usage line in an error used to list the options given: `--space <…>` looked
    // required after a forgotten `-o`
    let e = fails(glassdb().args(["registry", "build", "--space", "srgb"]));
    let usage = e
        .lines()
        .find(|l| l.starts_with("Usage:"))
        .unwrap_or_else(|| panic!("no usage line: {e}"));
    assert!(!usage.contains("--space"), "{usage}");
    assert!(
        usage.contains("<CATALOG>") && usage.contains("--output"),
        "{usage}"
    );
}

/// `git status --porcelain` of the repository (untracked files included, ignored ones not).
fn git_status() -> std::collections::BTreeSet<String> {
    let out = std::process::Command::new("git")
        .args(["status", "--porcelain", "--untracked-files=all"])
        .current_dir(repo_root())
        .output()
        .expect("git runs (the tests run in a clone)");
    assert!(out.status.success(), "git status failed");
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::to_string)
        .collect()
}

#[test]
fn the_compose_docs_example_leaves_the_clone_clean() {
    // docs/compose.md's "Try it:" command, run as written from the repository root with the
    // compose this test was built with: its output goes to an ignored folder, so the clone
    // stays as it was.
    let doc = std::fs::read_to_string(repo_path("docs/compose.md")).unwrap();
    let line = doc
        .lines()
        .find(|l| l.starts_with("Try it: `compose "))
        .expect("docs/compose.md has a `Try it:` command");
    let command = line.split('`').nth(1).unwrap();
    let mut args: Vec<&str> = command.split_whitespace().collect();
    assert_eq!(args.remove(0), "compose");
    let out = args[args
        .iter()
        .position(|a| *a == "-o")
        .expect("it names its output")
        + 1];
    let before = git_status();
    ok(compose().args(&args).current_dir(repo_root()));
    let written = repo_root().join(out);
    assert!(written.is_file(), "{command} wrote no {out}");
    let ignored = std::process::Command::new("git")
        .args(["check-ignore", "-q", out])
        .current_dir(repo_root())
        .status()
        .unwrap();
    let after = git_status();
    let _ = std::fs::remove_file(&written);
    assert!(ignored.success(), "{out} is not in an ignored folder");
    let new: Vec<_> = after.difference(&before).collect();
    assert!(new.is_empty(), "`{command}` left {new:?} in the clone");
}

#[test]
fn compose_without_an_output_writes_nothing_and_asks_for_one() {
    // Without -o, compose used to write `<trans>.composite.exr` beside the transmission pass:
    // into the clone's fixtures (or a shared render folder).
    let dir = crate::util::example_copy();
    for mut command in [compose(), {
        let mut g = glassdb();
        g.arg("compose");
        g
    }] {
        let err = fails(
            command
                .current_dir(dir.path())
                .args(crate::util::EXAMPLE_INPUTS),
        );
        assert!(err.contains("--output"), "{err}");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names.len(), 3, "{names:?}");
    }
}
