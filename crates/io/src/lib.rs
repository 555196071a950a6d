//! Atomic output for every glassdb tool: a file is written to a temporary file in the target's
//! own directory and renamed over the target only when complete, so a failed run never leaves a
//! half-written or lost output. [`frames`]: frame patterns and frame lists of animations.
//! [`progress`]: the observer through which libraries report the progress of long work.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

pub mod frames;
pub use frames::{FrameError, expand_frame_pattern, is_frame_pattern, parse_frame_list};
pub mod progress;
pub use progress::{NoProgress, Progress, StageLog};

/// Failures of [`write_atomic`] and [`refuse_input_as_output`], each naming the path involved.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The directory the output goes into does not exist or cannot take a temporary file.
    #[error("cannot create a temporary file beside {path}")]
    CreateTemp {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Writing the content failed (disk full, I/O error, or the producer reported an error).
    #[error("cannot write {path}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The finished temporary file could not be renamed over the target.
    #[error("cannot move the finished output into place at {path}")]
    Persist {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The directory the output goes into does not exist (outputs never create directories).
    #[error("cannot write {path}: the directory {dir} does not exist")]
    MissingDirectory { path: PathBuf, dir: PathBuf },
    /// The output path names one of the run's own inputs.
    #[error("refusing to overwrite the input file {path} with the output")]
    OutputIsInput { path: PathBuf },
}

/// Writes a file atomically: `produce` writes into a buffered temporary file beside `path`,
/// which is flushed, synced and renamed over `path` only if `produce` returns `Ok`.
/// On any error the temporary file is removed and `path` is left as it was.
pub fn write_atomic<F>(path: &Path, produce: F) -> Result<(), OutputError>
where
    F: FnOnce(&mut BufWriter<&mut File>) -> std::io::Result<()>,
{
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(OutputError::MissingDirectory {
            path: path.to_path_buf(),
            dir,
        });
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(".glassdb-tmp-");
    // A replaced file keeps its mode; a new one gets what any other tool would give it
    // (0666 masked by the umask), not the temporary file's private 0600.
    if let Ok(meta) = std::fs::metadata(path) {
        builder.permissions(meta.permissions());
    } else {
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
    }
    let mut tmp = builder
        .tempfile_in(&dir)
        .map_err(|source| OutputError::CreateTemp {
            path: path.to_path_buf(),
            source,
        })?;
    {
        let file = tmp.as_file_mut();
        let mut w = BufWriter::new(file);
        let write_err = |source| OutputError::Write {
            path: path.to_path_buf(),
            source,
        };
        produce(&mut w).map_err(write_err)?;
        w.flush().map_err(write_err)?;
    }
    tmp.as_file()
        .sync_all()
        .map_err(|source| OutputError::Write {
            path: path.to_path_buf(),
            source,
        })?;
    tmp.persist(path).map_err(|e| OutputError::Persist {
        path: path.to_path_buf(),
        source: e.error,
    })?;
    Ok(())
}

/// Writes `bytes` atomically to `path` (see [`write_atomic`]).
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_atomic(path, |w| w.write_all(bytes))
}

/// Errors if `output` is the same file as any of `inputs` (compared after resolving links,
/// so `./a.exr` and `a.exr` match). Inputs that do not exist are ignored.
pub fn refuse_input_as_output<'a, I>(output: &Path, inputs: I) -> Result<(), OutputError>
where
    I: IntoIterator<Item = &'a Path>,
{
    let Ok(out) = output.canonicalize() else {
        return Ok(()); // the output does not exist yet, so it cannot be an input
    };
    for input in inputs {
        if input.canonicalize().is_ok_and(|i| i == out) {
            return Err(OutputError::OutputIsInput {
                path: output.to_path_buf(),
            });
        }
    }
    Ok(())
}

/// Displays an error with its causes as `outer: cause: root`, as `anyhow`'s `{:#}` does, for
/// messages that are printed or written without going through `anyhow`.
pub struct ErrorChain<'a>(pub &'a (dyn std::error::Error + 'static));

impl std::fmt::Display for ErrorChain<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)?;
        let mut cause = self.0.source();
        while let Some(c) = cause {
            write!(f, ": {c}")?;
            cause = c.source();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_producer_leaves_target_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.txt");
        std::fs::write(&target, b"old").unwrap();
        let r = write_atomic(&target, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("producer failed"))
        });
        assert!(matches!(r, Err(OutputError::Write { .. })));
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(leftovers.len(), 1, "temporary file was not cleaned up");
    }

    #[test]
    fn missing_or_unusable_directory_is_named_and_each_cause_printed_once() {
        let err =
            write_bytes_atomic(Path::new("/nonexistent-dir-glassdb/x.json"), b"{}").unwrap_err();
        assert!(
            matches!(err, OutputError::MissingDirectory { .. }),
            "{err:?}"
        );
        // A directory that exists but takes no new files (even for root): the OS reason once.
        let target = Path::new("/proc/self/x.json");
        if target.parent().is_some_and(Path::is_dir) {
            let err = write_bytes_atomic(target, b"{}").unwrap_err();
            let text = ErrorChain(&err).to_string();
            assert!(
                text.starts_with("cannot create a temporary file beside /proc/self/x.json: "),
                "{text}"
            );
            assert_eq!(text.matches("(os error").count(), 1, "{text}");
        }
    }

    #[test]
    fn success_replaces_target() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.txt");
        write_bytes_atomic(&target, b"new").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
    }

    #[cfg(unix)]
    #[test]
    fn new_output_is_not_private_and_replaced_output_keeps_its_mode() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let fresh = dir.path().join("fresh.txt");
        write_bytes_atomic(&fresh, b"x").unwrap();
        let mode = std::fs::metadata(&fresh).unwrap().permissions().mode() & 0o777;
        // Any usual umask (022, 002, 077 aside) leaves the owner read+write; the private
        // temporary-file mode 0600 must not leak unless the umask itself asks for it.
        assert_eq!(mode & 0o600, 0o600, "mode {mode:o}");
        let kept = dir.path().join("kept.txt");
        std::fs::write(&kept, b"old").unwrap();
        std::fs::set_permissions(&kept, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_bytes_atomic(&kept, b"new").unwrap();
        let mode = std::fs::metadata(&kept).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640, "mode {mode:o}");
    }

    #[test]
    fn missing_directory_is_an_error_naming_the_path() {
        let r = write_bytes_atomic(Path::new("/nonexistent-dir-glassdb/x.json"), b"{}");
        let msg = r.unwrap_err().to_string();
        assert!(msg.contains("/nonexistent-dir-glassdb/x.json"), "{msg}");
    }

    #[test]
    fn output_equal_to_input_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.exr");
        std::fs::write(&a, b"x").unwrap();
        let dotted = dir.path().join(".").join("a.exr");
        assert!(refuse_input_as_output(&dotted, [a.as_path()]).is_err());
        let b = dir.path().join("b.exr");
        assert!(refuse_input_as_output(&b, [a.as_path()]).is_ok());
    }
}
