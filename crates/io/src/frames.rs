//! Frame sequences shared by the tools that make or read animations (`compose`, `glassdb mask`):
//! file patterns with a `#` run for the frame number (`r.####.exr` → `r.0007.exr`) and frame
//! lists (`1-240`, `1,5,10-20`).

use std::path::{Path, PathBuf};

/// Most frames one list may name.
pub const MAX_FRAMES: u64 = 1_000_000;

/// A frame list that does not parse, or a path without the `#` run a frame number replaces.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    /// A frame list that does not parse or is out of range.
    #[error("frame list {spec:?}: {why} (e.g. 1-240 or 1,5,10-20)")]
    List {
        /// The list as given.
        spec: String,
        /// What is wrong with it.
        why: String,
    },
    /// A path without the `####` that the frame number replaces.
    #[error("{path} has no #### for the frame number")]
    NoPattern {
        /// The path.
        path: PathBuf,
    },
}

impl FrameError {
    /// The class of this error: always invalid input (a frame list or a path to fix).
    pub fn kind(&self) -> crate::ErrorKind {
        crate::ErrorKind::Invalid
    }
}

/// Whether `pattern` contains a `#` run.
pub fn is_frame_pattern(pattern: &Path) -> bool {
    pattern.to_string_lossy().contains('#')
}

/// Replaces the last run of `#` in `pattern` by `frame`, zero-padded to the run's length.
pub fn expand_frame_pattern(pattern: &Path, frame: u32) -> Result<PathBuf, FrameError> {
    let s = pattern.to_string_lossy();
    let end = s.rfind('#').ok_or_else(|| FrameError::NoPattern {
        path: pattern.to_path_buf(),
    })? + 1;
    let start = s[..end].trim_end_matches('#').len();
    let width = end - start;
    Ok(PathBuf::from(format!(
        "{}{:0width$}{}",
        &s[..start],
        frame,
        &s[end..],
        width = width
    )))
}

/// Parses a frame list: `N`, `A-B`, comma-separated, e.g. `1-240` or `1,5,10-20`; returns the
/// frames sorted, without repeats.
pub fn parse_frame_list(spec: &str) -> Result<Vec<u32>, FrameError> {
    let bad = |why: &str| FrameError::List {
        spec: spec.to_string(),
        why: why.to_string(),
    };
    let mut frames = Vec::new();
    for item in spec.split(',') {
        let item = item.trim();
        let (a, b) = match item.split_once('-') {
            Some((a, b)) => (a.trim(), b.trim()),
            None => (item, item),
        };
        let a: u32 = a.parse().map_err(|_| bad("not a frame number"))?;
        let b: u32 = b.parse().map_err(|_| bad("not a frame number"))?;
        if b < a {
            return Err(bad("a range ends before it starts"));
        }
        if frames.len() as u64 + u64::from(b - a) + 1 > MAX_FRAMES {
            return Err(bad("more than a million frames"));
        }
        frames.extend(a..=b);
    }
    frames.sort_unstable();
    frames.dedup();
    Ok(frames)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_expand_with_padding() {
        assert_eq!(
            expand_frame_pattern(Path::new("r.####.exr"), 7).unwrap(),
            PathBuf::from("r.0007.exr")
        );
        assert_eq!(
            expand_frame_pattern(Path::new("d#/t.##.png"), 123).unwrap(),
            PathBuf::from("d#/t.123.png")
        );
        assert!(matches!(
            expand_frame_pattern(Path::new("r.exr"), 1),
            Err(FrameError::NoPattern { .. })
        ));
        assert!(is_frame_pattern(Path::new("cam.####.json")));
        assert!(!is_frame_pattern(Path::new("cam.json")));
    }

    #[test]
    fn frame_lists() {
        assert_eq!(parse_frame_list("1-3").unwrap(), vec![1, 2, 3]);
        assert_eq!(parse_frame_list("5, 1-2,2").unwrap(), vec![1, 2, 5]);
        assert!(parse_frame_list("3-1").is_err());
        assert!(parse_frame_list("a").is_err());
        assert!(parse_frame_list("0-4000000").is_err());
    }
}
