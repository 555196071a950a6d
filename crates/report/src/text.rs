//! How numbers and paths are written in the page.

use std::path::{Component, Path, PathBuf};

/// An error and the angle where it occurs.
pub(crate) fn fmt_err((e, a): (f64, f64)) -> String {
    format!("{} ({a:.1}°)", sci(e))
}

/// A compact error: 3 significant digits, scientific below 0.01.
pub(crate) fn sci(e: f64) -> String {
    if !e.is_finite() {
        return format!("{e}");
    }
    if e == 0.0 {
        "0".into()
    } else if e < 0.01 {
        format!("{e:.2e}")
    } else {
        format!("{e:.3}")
    }
}

/// An RGB triple to 4 decimals.
pub(crate) fn fmt_rgb(v: [f64; 3]) -> String {
    format!("{:.4} {:.4} {:.4}", v[0], v[1], v[2])
}

/// `path` relative to `root` when it lies under it (for the page's text).
pub(crate) fn shown(root: &Path, path: &Path) -> String {
    let strip = |p: &Path| {
        p.components()
            .filter(|c| !matches!(c, Component::CurDir))
            .collect::<PathBuf>()
    };
    match strip(path).strip_prefix(strip(root)) {
        Ok(rel) => rel.display().to_string(),
        Err(_) => path.display().to_string(),
    }
}

/// The file name of `path` as text (empty when it has none).
pub(crate) fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default()
}
