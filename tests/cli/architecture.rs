//! The redesign's rules, checked on the source tree: libraries know nothing of argv (no error
//! message names a command-line flag; the binaries add the hint), and the crate edges follow
//! meaning (docs/architecture.md).

use std::path::Path;

use crate::util::repo_path;

/// Every `.rs` file under `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Whether `text` names a long option (`--word`).
fn names_a_flag(text: &str) -> bool {
    text.match_indices("--").any(|(i, _)| {
        text[i + 2..]
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_lowercase())
    })
}

#[test]
fn library_error_messages_name_no_command_line_flag() {
    let mut files = Vec::new();
    for crate_dir in std::fs::read_dir(repo_path("crates")).unwrap() {
        let src = crate_dir.unwrap().path().join("src");
        if src.is_dir() {
            rust_files(&src, &mut files);
        }
    }
    let mut offenders = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        // The text of each `#[error(...)]` attribute, which may span lines.
        for (start, _) in text.match_indices("#[error(") {
            let end = text[start..].find(")]").map_or(text.len(), |e| start + e);
            let message = &text[start..end];
            if names_a_flag(message) {
                let line = text[..start].lines().count() + 1;
                offenders.push(format!("{}:{line}: {message}", file.display()));
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "library error messages that name a flag (the binary's hints module adds those):\n{}",
        offenders.join("\n")
    );
}

/// The `glassdb-*` crates a crate's `[dependencies]` table names.
fn workspace_dependencies(crate_name: &str) -> Vec<String> {
    let manifest =
        std::fs::read_to_string(repo_path("crates").join(crate_name).join("Cargo.toml")).unwrap();
    let deps = manifest
        .split("[dependencies]")
        .nth(1)
        .unwrap_or_default()
        .split("\n[")
        .next()
        .unwrap_or_default();
    deps.lines()
        .filter_map(|l| l.split(['.', ' ', '=']).next())
        .filter(|name| name.starts_with("glassdb-"))
        .map(String::from)
        .collect()
}

#[test]
fn crate_edges_follow_meaning() {
    let compose = workspace_dependencies("compose");
    for forbidden in ["glassdb-fit", "glassdb-spectral", "glassdb-plot"] {
        assert!(
            !compose.iter().any(|d| d == forbidden),
            "the compositor depends on {forbidden}: {compose:?}"
        );
    }
    assert!(compose.iter().any(|d| d == "glassdb-image"), "{compose:?}");
    let registry = workspace_dependencies("registry");
    assert!(
        !registry.iter().any(|d| d == "glassdb-mask"),
        "the registry depends on masks: {registry:?}"
    );
    let plot = workspace_dependencies("plot");
    assert!(
        !plot
            .iter()
            .any(|d| d == "glassdb-report" || d == "glassdb-scene"),
        "the plot library depends on the report or the scene: {plot:?}"
    );
    let stack = workspace_dependencies("stack");
    assert!(
        !stack
            .iter()
            .any(|d| d == "glassdb-registry" || d == "glassdb-io"),
        "the stack engine depends on the registry or on files: {stack:?}"
    );
    let mask = workspace_dependencies("mask");
    assert!(
        !mask.iter().any(|d| d == "glassdb-registry"),
        "masks depend on the registry: {mask:?}"
    );
}
