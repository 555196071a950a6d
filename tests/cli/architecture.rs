//! The design's rules, checked on the source tree (docs/architecture.md): libraries know
//! nothing of argv (no string literal of library code names a command-line flag; the binary
//! adds the hints), the crate edges follow meaning (checked on `cargo metadata`, through every
//! path of the graph), every library warns on an undocumented public item, and no function is
//! over 120 lines.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use proc_macro2::{Delimiter, TokenStream, TokenTree};
use syn::visit::Visit;

use crate::util::repo_path;

/// Every `.rs` file under `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The source files of the library crates and of the binaries, without their test files
/// (`tests.rs` beside the code; a `#[cfg(test)] mod` inside a file is skipped by the checks).
fn source_files(libraries: bool, binaries: bool) -> Vec<(String, PathBuf)> {
    let mut out = Vec::new();
    if libraries {
        for crate_dir in std::fs::read_dir(repo_path("crates")).unwrap() {
            let dir = crate_dir.unwrap().path();
            let name = dir.file_name().unwrap().to_string_lossy().into_owned();
            let mut files = Vec::new();
            if dir.join("src").is_dir() {
                rust_files(&dir.join("src"), &mut files);
            }
            out.extend(files.into_iter().map(|f| (format!("glassdb-{name}"), f)));
        }
    }
    if binaries {
        let mut files = Vec::new();
        rust_files(&repo_path("src"), &mut files);
        out.extend(files.into_iter().map(|f| ("glassdb".to_string(), f)));
    }
    out.retain(|(_, f)| f.file_name().is_none_or(|n| n != "tests.rs"));
    out.sort();
    out
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

/// Whether `text` is one word of another program's command line (`--factory-startup` for
/// Blender, `--out` for the Blender-side script): an argument handed on, not a message.
fn is_one_argument(text: &str) -> bool {
    text.starts_with('-') && !text.contains(char::is_whitespace)
}

/// Every string literal of `tokens` outside doc comments and `#[cfg(test)]` modules, with
/// its line: messages (also those inside `format!`, `#[error(…)]` and other macros), names
/// and arguments alike.
fn string_literals(tokens: TokenStream, out: &mut Vec<(usize, String)>) {
    let tokens: Vec<TokenTree> = tokens.into_iter().collect();
    let mut i = 0;
    while i < tokens.len() {
        match &tokens[i] {
            TokenTree::Punct(p) if p.as_char() == '#' => {
                // `#[…]` or `#![…]`: a doc comment is skipped; `#[cfg(test)] mod x { … }` too.
                let j = i
                    + 1
                    + usize::from(
                        matches!(&tokens.get(i + 1), Some(TokenTree::Punct(p)) if p.as_char() == '!'),
                    );
                if let Some(TokenTree::Group(g)) = tokens.get(j)
                    && g.delimiter() == Delimiter::Bracket
                {
                    let inner = g.stream().to_string();
                    if inner.starts_with("doc") {
                        i = j + 1;
                        continue;
                    }
                    if inner.replace(' ', "") == "cfg(test)"
                        && matches!(tokens.get(j + 1), Some(TokenTree::Ident(m)) if m == "mod")
                    {
                        // `mod name { … }`, or `mod name;` (a test file, not read here).
                        i = j
                            + 3
                            + usize::from(matches!(tokens.get(j + 3), Some(TokenTree::Group(_))));
                        continue;
                    }
                }
                i += 1;
            }
            TokenTree::Group(g) => {
                string_literals(g.stream(), out);
                i += 1;
            }
            TokenTree::Literal(lit) => {
                if let Ok(s) = syn::parse_str::<syn::LitStr>(&lit.to_string()) {
                    out.push((lit.span().start().line, s.value()));
                }
                i += 1;
            }
            TokenTree::Ident(_) | TokenTree::Punct(_) => i += 1,
        }
    }
}

/// Text a library records in the files it writes, saying how a file was made (as the report
/// quotes the commands behind its figures): a fit file's warnings keep that the fit was
/// refused and written with `--force` (file, literal).
const RECORDED_IN_OUTPUT_FILES: [(&str, &str); 1] =
    [("crates/fit/src/glass.rs", "written with --force: {finding}")];

#[test]
fn no_string_literal_of_library_code_names_a_command_line_flag() {
    let mut offenders = Vec::new();
    for (krate, file) in source_files(true, false) {
        // The report writes docs/accuracy.md, which quotes the commands behind its figures.
        if krate == "glassdb-report" {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        let tokens: TokenStream = text.parse().unwrap();
        let mut literals = Vec::new();
        string_literals(tokens, &mut literals);
        let rel = file.strip_prefix(repo_path("")).unwrap_or(&file);
        for (line, value) in literals {
            let recorded = RECORDED_IN_OUTPUT_FILES
                .iter()
                .any(|(f, text)| rel == Path::new(f) && value == *text);
            if names_a_flag(&value) && !is_one_argument(&value) && !recorded {
                offenders.push(format!("{}:{line}: {value:?}", file.display()));
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "library strings that name a command-line flag (the binary's hints module adds those):\n{}",
        offenders.join("\n")
    );
}

/// The longest a function may be, in lines from `fn` to its closing brace.
const MAX_FUNCTION_LINES: usize = 120;

/// The functions of a file (free, in impls and default methods of traits) outside
/// `#[cfg(test)]` modules, with their length in lines.
struct FunctionLengths(Vec<(String, usize)>);

impl FunctionLengths {
    fn add(&mut self, name: &syn::Ident, fn_token: &syn::token::Fn, block: &syn::Block) {
        let first = fn_token.span.start().line;
        let last = block.brace_token.span.close().end().line;
        self.0.push((name.to_string(), last + 1 - first));
    }
}

impl<'ast> Visit<'ast> for FunctionLengths {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        let test_only = m.attrs.iter().any(|a| {
            a.path().is_ident("cfg")
                && a.meta
                    .require_list()
                    .is_ok_and(|l| l.tokens.to_string() == "test")
        });
        if !test_only {
            syn::visit::visit_item_mod(self, m);
        }
    }
    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        self.add(&f.sig.ident, &f.sig.fn_token, &f.block);
        syn::visit::visit_item_fn(self, f);
    }
    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        self.add(&f.sig.ident, &f.sig.fn_token, &f.block);
        syn::visit::visit_impl_item_fn(self, f);
    }
    fn visit_trait_item_fn(&mut self, f: &'ast syn::TraitItemFn) {
        if let Some(block) = &f.default {
            self.add(&f.sig.ident, &f.sig.fn_token, block);
        }
        syn::visit::visit_trait_item_fn(self, f);
    }
}

#[test]
fn no_function_of_library_or_binary_code_is_over_120_lines() {
    let mut long = Vec::new();
    for (_, file) in source_files(true, true) {
        let text = std::fs::read_to_string(&file).unwrap();
        let syntax = syn::parse_file(&text).unwrap();
        let mut lengths = FunctionLengths(Vec::new());
        lengths.visit_file(&syntax);
        let rel = file
            .strip_prefix(repo_path(""))
            .unwrap_or(&file)
            .display()
            .to_string();
        for (name, lines) in lengths.0 {
            let at = format!("{rel}: {name}");
            if lines > MAX_FUNCTION_LINES {
                long.push(format!("{at} ({lines} lines)"));
            }
        }
    }
    assert!(
        long.is_empty(),
        "functions over {MAX_FUNCTION_LINES} lines (split them into their phases):\n{}",
        long.join("\n")
    );
}

/// The largest a library file may be, in lines (test files apart).
const MAX_FILE_LINES: usize = 700;

#[test]
fn no_library_file_is_over_700_lines() {
    let mut long = Vec::new();
    for (_, file) in source_files(true, false) {
        let rel = file
            .strip_prefix(repo_path(""))
            .unwrap_or(&file)
            .display()
            .to_string();
        let lines = std::fs::read_to_string(&file).unwrap().lines().count();
        if lines > MAX_FILE_LINES {
            long.push(format!("{rel} ({lines} lines)"));
        }
    }
    assert!(
        long.is_empty(),
        "library files over {MAX_FILE_LINES} lines:\n{}",
        long.join("\n")
    );
}

#[test]
fn every_library_warns_on_undocumented_public_items() {
    let mut quiet = Vec::new();
    for crate_dir in std::fs::read_dir(repo_path("crates")).unwrap() {
        let lib = crate_dir.unwrap().path().join("src/lib.rs");
        let text = std::fs::read_to_string(&lib).unwrap();
        if !text.contains("#![warn(missing_docs)]") && !text.contains("#![deny(missing_docs)]") {
            quiet.push(lib.display().to_string());
        }
    }
    assert!(quiet.is_empty(), "no missing_docs lint in: {quiet:?}");
}

/// The names of a file's public enums named `…Error`, and of the types whose inherent impl has
/// a `kind` method.
fn error_enums_and_kinds(syntax: &syn::File) -> (Vec<String>, Vec<String>) {
    let mut enums = Vec::new();
    let mut kinds = Vec::new();
    for item in &syntax.items {
        match item {
            syn::Item::Enum(e)
                if matches!(e.vis, syn::Visibility::Public(_))
                    && e.ident.to_string().ends_with("Error") =>
            {
                enums.push(e.ident.to_string());
            }
            syn::Item::Impl(i) if i.trait_.is_none() => {
                let has_kind = i
                    .items
                    .iter()
                    .any(|it| matches!(it, syn::ImplItem::Fn(f) if f.sig.ident == "kind"));
                if let (true, syn::Type::Path(t)) = (has_kind, &*i.self_ty)
                    && let Some(last) = t.path.segments.last()
                {
                    kinds.push(last.ident.to_string());
                }
            }
            _ => {}
        }
    }
    (enums, kinds)
}

/// Every library's error type (the public `…Error` enums of its `error.rs`, or of all its
/// files where it has none) has a `kind()` (invalid, unsupported, limits, I/O, internal) that the binaries, the
/// viewer and the farm report act on; only the side of a pane, which cannot fail but in
/// parsing, has none.
#[test]
fn every_library_error_has_a_kind() {
    // per crate: its error enums (and whether each is in an `error.rs`), the types with a kind
    type ErrorsAndKinds = (Vec<(String, bool)>, BTreeSet<String>);
    let mut per_crate: BTreeMap<String, ErrorsAndKinds> = BTreeMap::new();
    for (krate, file) in source_files(true, false) {
        let syntax = syn::parse_file(&std::fs::read_to_string(&file).unwrap()).unwrap();
        let (enums, kinds) = error_enums_and_kinds(&syntax);
        let in_error_rs = file.file_name().is_some_and(|n| n == "error.rs");
        let entry = per_crate.entry(krate).or_default();
        entry.0.extend(enums.into_iter().map(|e| (e, in_error_rs)));
        entry.1.extend(kinds);
    }
    let mut missing = Vec::new();
    for (krate, (enums, kinds)) in &per_crate {
        let has_error_rs = enums.iter().any(|(_, in_error)| *in_error);
        let main: Vec<&String> = enums
            .iter()
            .filter(|(_, in_error)| *in_error || !has_error_rs)
            .map(|(e, _)| e)
            .collect();
        if main.is_empty() && krate != "glassdb-side" {
            missing.push(format!("{krate}: no error type found"));
        }
        for e in main {
            if !kinds.contains(e) {
                missing.push(format!("{krate}: {e} has no kind()"));
            }
        }
    }
    assert!(per_crate.contains_key("glassdb-stack"), "{per_crate:?}");
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

/// The glassdb crates each workspace crate depends on, directly (normal dependencies), from
/// `cargo metadata`.
fn direct_edges() -> BTreeMap<String, BTreeSet<String>> {
    let metadata = crate::util::ok(
        std::process::Command::new(env!("CARGO"))
            .args([
                "metadata",
                "--format-version",
                "1",
                "--no-deps",
                "--offline",
            ])
            .current_dir(repo_path("")),
    );
    let meta: serde_json::Value = serde_json::from_str(&metadata).unwrap();
    let mut edges = BTreeMap::new();
    for package in meta["packages"].as_array().unwrap() {
        let name = package["name"].as_str().unwrap().to_string();
        let deps: BTreeSet<String> = package["dependencies"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|d| d["kind"].is_null())
            .filter_map(|d| d["name"].as_str())
            .filter(|d| d.starts_with("glassdb"))
            .map(String::from)
            .collect();
        edges.insert(name, deps);
    }
    edges
}

/// Every glassdb crate `krate` depends on through any path of `edges`.
fn reachable(edges: &BTreeMap<String, BTreeSet<String>>, krate: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut todo = vec![krate.to_string()];
    while let Some(k) = todo.pop() {
        for d in edges.get(&k).into_iter().flatten() {
            if seen.insert(d.clone()) {
                todo.push(d.clone());
            }
        }
    }
    seen
}

#[test]
fn crate_edges_follow_meaning() {
    let edges = direct_edges();
    // (crate, what it must not reach through any path, why)
    let rules: [(&str, &[&str], &str); 13] = [
        (
            "glassdb-compose",
            &["glassdb-plot", "glassdb-scene"],
            "the compositor reads prebuilt tables and the passes, never scenes or figures",
        ),
        (
            "glassdb-registry",
            &["glassdb-mask"],
            "the registry does not depend on masks",
        ),
        (
            "glassdb-mask",
            &["glassdb-registry"],
            "masks do not depend on the registry",
        ),
        (
            "glassdb-scene",
            &["glassdb-registry"],
            "scenes need only the side of a pane (glassdb-side)",
        ),
        (
            "glassdb-plot",
            &["glassdb-report", "glassdb-scene"],
            "the plot library depends on neither the report nor the scene",
        ),
        (
            "glassdb-colour",
            &["glassdb-spectral"],
            "colour spaces know nothing of spectra",
        ),
        (
            "glassdb-pass",
            &[
                "glassdb-compose",
                "glassdb-encode",
                "glassdb-registry",
                "glassdb-mask",
            ],
            "passes are read without the compositor",
        ),
        (
            "glassdb-encode",
            &["glassdb-compose", "glassdb-registry", "glassdb-mask"],
            "outputs are written without the compositor",
        ),
        (
            "glassdb-view",
            &["glassdb-sequence", "glassdb-blender", "glassdb-scene"],
            "the viewer stands on the compositor's decode only",
        ),
        (
            "glassdb-blender",
            &["glassdb-view", "glassdb-sequence", "glassdb-report"],
            "the Blender pipeline stands on compose, scene and mask",
        ),
        (
            "glassdb-image",
            &["glassdb-mask", "glassdb-colour", "glassdb-pass"],
            "images know nothing of what they hold",
        ),
        (
            "glassdb-side",
            &["glassdb-io"],
            "the side of a pane stands on nothing",
        ),
        (
            "glassdb-stack",
            &["glassdb-registry", "glassdb-image", "glassdb-scene"],
            "the stack engine combines layers; the registry reads the files and builds on it",
        ),
    ];
    let mut broken = Vec::new();
    for (krate, forbidden, why) in rules {
        assert!(edges.contains_key(krate), "no crate {krate}: {edges:?}");
        let reach = reachable(&edges, krate);
        for f in forbidden {
            if reach.contains(*f) {
                broken.push(format!("{krate} reaches {f}: {why}"));
            }
        }
    }
    // The compositor names neither the fitter nor the spectral crate: it reaches the curve
    // type through the registry's records only, and nothing at its start fits or integrates.
    for f in ["glassdb-fit", "glassdb-spectral"] {
        if edges["glassdb-compose"].contains(f) {
            broken.push(format!("glassdb-compose depends on {f} directly"));
        }
    }
    // The foundations depend on no other glassdb crate but io.
    for krate in ["glassdb-io", "glassdb-side"] {
        if !reachable(&edges, krate).is_empty() {
            broken.push(format!("{krate} depends on {:?}", reachable(&edges, krate)));
        }
    }
    // No library depends on a front-end's crate (only the binary does).
    for front in [
        "glassdb-view",
        "glassdb-blender",
        "glassdb-report",
        "glassdb-sequence",
    ] {
        for (krate, deps) in &edges {
            if krate != "glassdb" && deps.contains(front) {
                broken.push(format!("{krate} depends on the front-end crate {front}"));
            }
        }
    }
    assert!(
        reachable(&edges, "glassdb-compose").contains("glassdb-image"),
        "{edges:?}"
    );
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}

/// The stack engine reads no file (the registry and the binary read the layers and hand it
/// their data): of glassdb-io it uses the error class and the names macro (`enum_names!`, which
/// writes `name`, `from_name` and `Display`) only, and nothing of `std::fs`.
#[test]
fn the_stack_engine_reads_no_file() {
    let mut offenders = Vec::new();
    for (krate, file) in source_files(true, false) {
        if krate != "glassdb-stack" {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let io_use = line.match_indices("glassdb_io::").any(|(i, m)| {
                let item = &line[i + m.len()..];
                !(item.starts_with("ErrorKind") || item.starts_with("enum_names!"))
            });
            if io_use || line.contains("std::fs") {
                offenders.push(format!("{}:{}: {}", file.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(offenders.is_empty(), "{}", offenders.join("\n"));
}
