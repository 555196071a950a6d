//! The text of OBJ and MTL files: reading it as UTF-8, its logical lines (comments,
//! continuations, tabs), words and numbers, `mtllib` file names, and the checks of a material
//! library.

use std::borrow::Cow;
use std::path::Path;

use crate::error::SceneError;
use crate::warning::SceneWarning;

/// OBJ statements that are valid but carry nothing this tool uses (free-form geometry,
/// display attributes, smoothing and merging groups).
pub(super) const IGNORED_STATEMENTS: &[&str] = &[
    "s",
    "mg",
    "vp",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "usemap",
    "maplib",
    "call",
    "csh",
    "l",
    "p",
];

pub(super) fn syntax(path: &Path, line: usize, message: impl Into<String>) -> SceneError {
    SceneError::Syntax {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

/// Reads a text file of at most `limit`, turning invalid UTF-8 into an error naming the line.
pub(super) fn read_text(path: &Path, limit: glassdb_io::InputLimit) -> Result<String, SceneError> {
    let bytes = glassdb_io::read_input(path, limit).map_err(|source| SceneError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let line = 1 + e.as_bytes()[..valid]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        syntax(path, line, "not UTF-8 text (is this an OBJ/MTL file?)")
    })
}

/// Logical lines: comments removed, `\` continuations joined, tabs as spaces; each with the
/// 1-based number of its first physical line. Plain lines are borrowed, not copied.
pub(super) fn logical_lines(text: &str) -> Vec<(usize, Cow<'_, str>)> {
    let mut out = Vec::new();
    let mut pending: Option<(usize, String)> = None;
    for (i, raw) in text.lines().enumerate() {
        let without_comment = match raw.find('#') {
            Some(k) => &raw[..k],
            None => raw,
        };
        let cleaned: Cow<'_, str> = if without_comment.contains(['\t', '\r', '\u{c}']) {
            Cow::Owned(without_comment.replace(['\t', '\r', '\u{c}'], " "))
        } else {
            Cow::Borrowed(without_comment)
        };
        let trimmed_end = cleaned.trim_end();
        if let Some(stripped) = trimmed_end.strip_suffix('\\') {
            let (lineno, mut acc) = pending.take().unwrap_or((i + 1, String::new()));
            acc.push_str(stripped);
            acc.push(' ');
            pending = Some((lineno, acc));
        } else if let Some((lineno, mut acc)) = pending.take() {
            acc.push_str(&cleaned);
            out.push((lineno, Cow::Owned(acc)));
        } else {
            out.push((i + 1, cleaned));
        }
    }
    if let Some((lineno, acc)) = pending {
        out.push((lineno, Cow::Owned(acc)));
    }
    out
}

/// Splits `s` into at most `N` words; returns them and the total word count.
pub(super) fn split_words<const N: usize>(s: &str) -> ([&str; N], usize) {
    let mut out = [""; N];
    let mut n = 0;
    for w in s.split_ascii_whitespace() {
        if n < N {
            out[n] = w;
        }
        n += 1;
    }
    (out, n)
}

/// Splits `s` at `sep` into at most `N` parts; returns them and the total part count.
pub(super) fn split_words_by<const N: usize>(s: &str, sep: char) -> ([&str; N], usize) {
    let mut out = [""; N];
    let mut n = 0;
    for w in s.split(sep) {
        if n < N {
            out[n] = w;
        }
        n += 1;
    }
    (out, n)
}

pub(super) fn parse_finite(
    word: &str,
    path: &Path,
    line: usize,
    what: &str,
) -> Result<f64, SceneError> {
    match word.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(syntax(
            path,
            line,
            format!("{what}: {word:?} is not a finite number"),
        )),
        Err(_) => Err(syntax(
            path,
            line,
            format!("{what}: {word:?} is not a number"),
        )),
    }
}

/// The file names of one `mtllib` statement (see the module docs): whitespace-separated,
/// a double-quoted name taken as it is, and unquoted words joined up to one ending in `.mtl`.
pub(super) fn split_mtllib(
    rest: &str,
    path: &Path,
    line: usize,
) -> Result<Vec<String>, SceneError> {
    let mut names = Vec::new();
    // Byte offset where the unquoted name being gathered starts.
    let mut pending: Option<usize> = None;
    let mut i = 0;
    let bytes = rest.as_bytes();
    while i < bytes.len() {
        if bytes[i] == b' ' {
            i += 1;
            continue;
        }
        if bytes[i] == b'"' {
            if let Some(start) = pending.take() {
                names.push(rest[start..i].trim_end().to_string());
            }
            let Some(len) = rest[i + 1..].find('"') else {
                return Err(syntax(
                    path,
                    line,
                    "mtllib: a double-quoted file name has no closing quote",
                ));
            };
            let name = &rest[i + 1..i + 1 + len];
            if name.trim().is_empty() {
                return Err(syntax(path, line, "mtllib: empty file name"));
            }
            names.push(name.to_string());
            i += len + 2;
            continue;
        }
        let end = rest[i..].find(' ').map_or(rest.len(), |k| i + k);
        let start = *pending.get_or_insert(i);
        if rest[i..end].to_ascii_lowercase().ends_with(".mtl") {
            names.push(rest[start..end].to_string());
            pending = None;
        }
        i = end;
    }
    if let Some(start) = pending {
        names.push(rest[start..].trim_end().to_string());
    }
    Ok(names)
}

/// Validates an MTL file and returns the material names it defines.
pub(super) fn scan_mtl(text: &str, path: &Path) -> Result<Vec<String>, SceneError> {
    let mut names = Vec::new();
    for (line, l) in logical_lines(text) {
        let trimmed = l.trim();
        let mut words = trimmed.split_whitespace();
        let Some(key) = words.next() else { continue };
        let rest: Vec<&str> = words.collect();
        match key {
            "newmtl" => {
                let name = trimmed[key.len()..].trim();
                if name.is_empty() {
                    return Err(syntax(path, line, "newmtl without a material name"));
                }
                names.push(name.to_string());
            }
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" => {
                if matches!(rest.first(), Some(&"spectral") | Some(&"xyz")) {
                    continue;
                }
                if rest.len() != 1 && rest.len() != 3 {
                    return Err(syntax(
                        path,
                        line,
                        format!("{key} needs 1 or 3 numbers, found {}", rest.len()),
                    ));
                }
                for w in &rest {
                    parse_finite(w, path, line, key)?;
                }
            }
            "Ns" | "Ni" | "d" | "Tr" | "sharpness" | "illum" => {
                if rest.len() != 1 && !(key == "d" && rest.len() == 2 && rest[0] == "-halo") {
                    return Err(syntax(path, line, format!("{key} needs one number")));
                }
                parse_finite(rest[rest.len() - 1], path, line, key)?;
            }
            _ => {} // texture maps and vendor extensions: not used here
        }
    }
    Ok(names)
}

/// Reads and checks every material library `mtllibs` names (beside the OBJ `path`) and warns
/// of a missing one and of a `usemtl` name (with its line) that the libraries there are do not
/// define.
pub(super) fn check_materials(
    mtllibs: &[(String, usize)],
    used: &[(&str, usize)],
    path: &Path,
) -> Result<Vec<SceneWarning>, SceneError> {
    let mut warnings = Vec::new();
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut defined: Vec<String> = Vec::new();
    for (lib, line) in mtllibs {
        let mtl_path = dir.join(lib);
        if !mtl_path.exists() {
            warnings.push(SceneWarning::MissingMaterialLibrary {
                obj: path.to_path_buf(),
                line: *line,
                library: mtl_path,
            });
            continue;
        }
        let mtl_text = read_text(&mtl_path, super::MTL_FILE)?;
        defined.extend(scan_mtl(&mtl_text, &mtl_path)?);
    }
    if !mtllibs.is_empty() {
        for &(m, line) in used {
            if !defined.iter().any(|d| d == m) {
                warnings.push(SceneWarning::UndefinedMaterial {
                    obj: path.to_path_buf(),
                    line,
                    name: m.to_string(),
                });
            }
        }
    }
    Ok(warnings)
}
