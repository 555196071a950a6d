//! Atomic output: a file is written to a temporary file in its target's own directory and
//! renamed over the target only when complete, so a failed or stopped run never leaves a
//! half-written or lost output. [`StagedOutput`] does the same for several files that make one
//! result: all of them land, or none.
//!
//! An output must be a regular file or a new name: an existing directory, device (`/dev/null`),
//! FIFO or socket is refused, never replaced. A symbolic link is written through: its target
//! file is replaced atomically and the link kept. A link to an open file descriptor
//! (`/dev/stdout`, `/dev/fd/N`) names no file and is refused. An output may not be one of the
//! process's inputs ([`refuse_input_as_output`]), compared by identity.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use tempfile::TempPath;

use crate::ErrorKind;
use crate::kind::FileKind;
use crate::registry::{self, FileId, LiveTemp, State, TEMP_PREFIX};

/// Failures of [`write_atomic`], [`StagedOutput`] and [`refuse_input_as_output`], each naming
/// the path involved.
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
    /// The output is one of the run's own inputs (the same file, whatever the spelling, link
    /// or hard link).
    #[error(
        "refusing to overwrite the input file {} with the output{}",
        input.display(),
        if input == path { String::new() } else { format!(" {} (the same file)", path.display()) }
    )]
    OutputIsInput { path: PathBuf, input: PathBuf },
    /// The output exists and is not a regular file (a directory, a device such as `/dev/null`,
    /// a FIFO, a socket, a link to an open file descriptor): it is never replaced.
    #[error("cannot write {path}: it is {kind}; an output must be a regular file or a new name")]
    NotAFile { path: PathBuf, kind: FileKind },
}

impl OutputError {
    /// The class of this error: an output that is an input or not a regular file is invalid,
    /// every other failure is I/O.
    pub fn kind(&self) -> ErrorKind {
        match self {
            OutputError::OutputIsInput { .. } | OutputError::NotAFile { .. } => ErrorKind::Invalid,
            OutputError::CreateTemp { .. }
            | OutputError::Write { .. }
            | OutputError::Persist { .. }
            | OutputError::MissingDirectory { .. } => ErrorKind::Io,
        }
    }
}

/// How many symbolic links an output path may pass through.
const MAX_LINKS: usize = 40;

/// Whether `p` lies where the system keeps links to open file descriptors.
fn is_descriptor_link(p: &Path) -> bool {
    p.starts_with("/proc") || p.starts_with("/dev/fd")
}

/// The regular file that writing `path` replaces or creates: `path` itself, or the file its
/// symbolic links lead to. Refuses an existing target that is not a regular file.
fn resolve_target(path: &Path) -> Result<PathBuf, OutputError> {
    let not_a_file = |kind| OutputError::NotAFile {
        path: path.to_path_buf(),
        kind,
    };
    let mut current = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        // Nothing there: a new file (also at the end of a dangling link). Other failures
        // (permissions) surface when the temporary file is created.
        let Ok(meta) = std::fs::symlink_metadata(&current) else {
            return Ok(current);
        };
        match FileKind::of(&meta.file_type()) {
            FileKind::Regular => return Ok(current),
            FileKind::Symlink => {
                if is_descriptor_link(&current) {
                    return Err(not_a_file(FileKind::DescriptorLink));
                }
                let link = std::fs::read_link(&current).map_err(|source| OutputError::Write {
                    path: path.to_path_buf(),
                    source,
                })?;
                current = match current.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                };
                if is_descriptor_link(&current) {
                    return Err(not_a_file(FileKind::DescriptorLink));
                }
            }
            kind => return Err(not_a_file(kind)),
        }
    }
    Err(OutputError::Write {
        path: path.to_path_buf(),
        source: std::io::Error::other("too many levels of symbolic links"),
    })
}

/// A finished temporary file waiting to be renamed over its target.
#[derive(Debug)]
struct StagedFile {
    /// The output as named.
    path: PathBuf,
    /// The regular file it replaces or creates (links followed).
    target: PathBuf,
    temp: LiveTemp,
}

/// Writes `produce`'s content to a temporary file beside `path`'s target, flushed and synced.
fn stage<F>(path: &Path, produce: F) -> Result<StagedFile, OutputError>
where
    F: FnOnce(&mut BufWriter<SyncingFile<'_>>) -> std::io::Result<()>,
{
    let target = resolve_target(path)?;
    refuse_input_as_output(path)?;
    let dir = registry::parent_dir(&target).to_path_buf();
    if !dir.is_dir() {
        return Err(OutputError::MissingDirectory {
            path: path.to_path_buf(),
            dir,
        });
    }
    // A replaced file keeps its mode; a new one gets what any other tool would give it
    // (0666 masked by the umask), not a temporary file's private 0600.
    let permissions = match std::fs::metadata(&target) {
        Ok(meta) => meta.permissions(),
        #[cfg(unix)]
        Err(_) => {
            use std::os::unix::fs::PermissionsExt;
            std::fs::Permissions::from_mode(0o666)
        }
        #[cfg(not(unix))]
        Err(_) => std::fs::File::open(&dir)
            .and_then(|f| f.metadata())
            .map(|m| m.permissions())
            .map_err(|source| OutputError::CreateTemp {
                path: path.to_path_buf(),
                source,
            })?,
    };
    let (mut file, temp) =
        LiveTemp::create(&dir, permissions).map_err(|source| OutputError::CreateTemp {
            path: path.to_path_buf(),
            source,
        })?;
    let write_err = |source| OutputError::Write {
        path: path.to_path_buf(),
        source,
    };
    {
        let mut w = BufWriter::new(SyncingFile::new(&mut file));
        produce(&mut w).map_err(write_err)?;
        w.flush().map_err(write_err)?;
    }
    file.sync_all().map_err(write_err)?;
    Ok(StagedFile {
        path: path.to_path_buf(),
        target,
        temp,
    })
}

/// An output's temporary file that starts writing its data to disk as it goes: after every
/// [`SyncingFile::SYNC_EVERY`] bytes it waits for them to reach the disk (`sync_data`), so
/// that the `fsync` before the rename, which nothing else overlaps, has only the last few
/// megabytes left to write (a 93 MB frame: 35 ms of idle cores at the end otherwise).
pub struct SyncingFile<'a> {
    file: &'a mut File,
    unsynced: u64,
}

impl<'a> SyncingFile<'a> {
    /// Bytes written between two `sync_data` calls.
    pub const SYNC_EVERY: u64 = 16 << 20;

    fn new(file: &'a mut File) -> Self {
        Self { file, unsynced: 0 }
    }
}

impl Write for SyncingFile<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(buf)?;
        self.unsynced += n as u64;
        if self.unsynced >= Self::SYNC_EVERY {
            self.file.sync_data()?;
            self.unsynced = 0;
        }
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

impl std::io::Seek for SyncingFile<'_> {
    fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
        self.file.seek(pos)
    }
}

/// Writes a file atomically: `produce` writes into a buffered temporary file beside `path`,
/// which is flushed, synced and renamed over `path` only if `produce` returns `Ok`.
/// On any error the temporary file is removed and `path` is left as it was. The checks of the
/// module docs apply: an existing `path` must be a regular file (or a link to one, written
/// through), and not a file this process read or declared ([`crate::protect_inputs`]).
pub fn write_atomic<F>(path: &Path, produce: F) -> Result<(), OutputError>
where
    F: FnOnce(&mut BufWriter<SyncingFile<'_>>) -> std::io::Result<()>,
{
    let staged = stage(path, produce)?;
    staged
        .temp
        .persist(&staged.target)
        .map_err(|source| OutputError::Persist {
            path: staged.path,
            source,
        })
}

/// Writes `bytes` atomically to `path` (see [`write_atomic`]).
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_atomic(path, |w| w.write_all(bytes))
}

/// Several files that make one result, landing whole or not at all: each is written to its own
/// temporary file beside its target as [`write_atomic`] does, and only [`StagedOutput::commit`]
/// renames them, all in one go. A failure before it, or dropping the staged output, removes
/// every temporary file and renames nothing; a rename that fails during the commit puts back
/// the files already renamed (the old content of each replaced target is kept aside, as a
/// hard link or a copy, until the commit is done).
#[derive(Debug, Default)]
pub struct StagedOutput {
    files: Vec<StagedFile>,
}

impl StagedOutput {
    pub fn new() -> Self {
        Self::default()
    }

    /// Writes the content of `path` to its temporary file (see [`write_atomic`]).
    pub fn write<F>(&mut self, path: &Path, produce: F) -> Result<(), OutputError>
    where
        F: FnOnce(&mut BufWriter<SyncingFile<'_>>) -> std::io::Result<()>,
    {
        self.files.push(stage(path, produce)?);
        Ok(())
    }

    /// Writes `bytes` as the content of `path` (see [`StagedOutput::write`]).
    pub fn write_bytes(&mut self, path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
        self.write(path, |w| w.write_all(bytes))
    }

    /// The outputs staged so far, as named.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.files.iter().map(|f| f.path.as_path())
    }

    /// Renames every temporary file over its target. A stop by a signal waits until the
    /// commit is done (or refuses it before it starts).
    pub fn commit(self) -> Result<(), OutputError> {
        let mut files = self.files;
        let result = {
            let mut s = registry::state();
            commit_locked(&mut files, &mut s)
        };
        drop(files); // removes the temporary files not renamed (after a failure)
        result
    }
}

/// A copy of the existing regular file `target` under a temporary name beside it: a hard
/// link, or where the file system has none, a copy of its bytes.
fn keep_aside(target: &Path) -> std::io::Result<TempPath> {
    let dir = registry::parent_dir(target);
    let builder = {
        let mut b = tempfile::Builder::new();
        b.prefix(TEMP_PREFIX);
        b
    };
    let linked = builder.make_in(dir, |p| std::fs::hard_link(target, p));
    let kept = match linked {
        Ok(t) => t,
        Err(_) => builder.make_in(dir, |p| {
            let mut out = std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(p)?;
            std::io::copy(&mut File::open(target)?, &mut out)?;
            out.sync_all()
        })?,
    };
    Ok(kept.into_temp_path())
}

fn commit_locked(files: &mut [StagedFile], s: &mut State) -> Result<(), OutputError> {
    let mut kept: Vec<Option<TempPath>> = Vec::with_capacity(files.len());
    for f in files.iter() {
        let exists = std::fs::symlink_metadata(&f.target).is_ok_and(|m| m.is_file());
        kept.push(if exists {
            Some(
                keep_aside(&f.target).map_err(|source| OutputError::Persist {
                    path: f.path.clone(),
                    source,
                })?,
            )
        } else {
            None
        });
    }
    for i in 0..files.len() {
        let (done, rest) = files.split_at_mut(i);
        let f = &mut rest[0];
        if let Err(source) = f.temp.persist_locked(&f.target, s) {
            for (j, g) in done.iter().enumerate().rev() {
                match kept[j].take() {
                    Some(old) => {
                        let _ = old.persist(&g.target);
                    }
                    None => {
                        let _ = std::fs::remove_file(&g.target);
                    }
                }
            }
            return Err(OutputError::Persist {
                path: f.path.clone(),
                source,
            });
        }
    }
    Ok(()) // dropping `kept` removes the old contents' extra names
}

/// Refuses `output` when it is (by identity) a file this process has read or declared as an
/// input ([`crate::protect_inputs`], [`crate::declare_inputs`]). Files are compared by
/// identity: device and inode where the file exists, so that hard links, symbolic links and
/// spellings such as `./a/../a` all match; else canonical directory and name.
pub fn refuse_input_as_output(output: &Path) -> Result<(), OutputError> {
    let Some(out) = FileId::of_path(output) else {
        return Ok(()); // not even its directory exists: it cannot be an input
    };
    match registry::input_matching(&out) {
        Some(input) => Err(OutputError::OutputIsInput {
            path: output.to_path_buf(),
            input,
        }),
        None => Ok(()),
    }
}

/// The first of `inputs` that is (by identity, as [`refuse_input_as_output`] compares) the
/// file `output` names.
#[cfg(test)]
fn same_file_as<'a>(output: &Path, inputs: &[&'a Path]) -> Option<&'a Path> {
    let out = FileId::of_path(output)?;
    inputs
        .iter()
        .copied()
        .find(|input| FileId::of_path(input).as_ref() == Some(&out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ErrorChain;

    /// A file larger than [`SyncingFile::SYNC_EVERY`], with a seek back over written bytes
    /// (as an EXR's offset table is written last), lands exactly as written.
    #[test]
    fn a_large_file_written_with_syncs_and_a_seek_back_is_exact() {
        use std::io::{Seek, SeekFrom};
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.bin");
        let len = SyncingFile::SYNC_EVERY as usize * 2 + 12_345;
        let expected: Vec<u8> = (0..len).map(|i| (i * 7 % 251) as u8).collect();
        write_atomic(&path, |w| {
            w.write_all(&[0; 8])?;
            w.write_all(&expected[8..])?;
            w.seek(SeekFrom::Start(0))?;
            w.write_all(&expected[..8])
        })
        .unwrap();
        assert!(std::fs::read(&path).unwrap() == expected);
        assert_eq!(names(dir.path()), ["big.bin"]);
    }

    /// The names in `dir`, sorted.
    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

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
        assert_eq!(names(dir.path()), ["out.txt"], "temporary file left");
        assert!(
            !registry::live_temporaries()
                .iter()
                .any(|p| p.starts_with(dir.path())),
            "a removed temporary file is still recorded"
        );
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
        assert_eq!(names(dir.path()), ["out.txt"]);
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
        assert!(same_file_as(&dotted, &[a.as_path()]).is_some());
        let b = dir.path().join("b.exr");
        assert!(same_file_as(&b, &[a.as_path()]).is_none());
    }

    #[cfg(unix)]
    #[test]
    fn inputs_are_matched_through_links_and_spellings() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let a = dir.path().join("sub/a.dat");
        std::fs::write(&a, b"x").unwrap();
        let hard = dir.path().join("hard.dat");
        std::fs::hard_link(&a, &hard).unwrap();
        let soft = dir.path().join("soft.dat");
        std::os::unix::fs::symlink(&a, &soft).unwrap();
        let dotted = dir.path().join("sub/../sub/./a.dat");
        for out in [&hard, &soft, &dotted] {
            let input = same_file_as(out, &[a.as_path()]).unwrap();
            let e = OutputError::OutputIsInput {
                path: out.to_path_buf(),
                input: input.to_path_buf(),
            };
            assert!(
                e.to_string().starts_with(&format!(
                    "refusing to overwrite the input file {}",
                    a.display()
                )),
                "{e}"
            );
        }
        // A new name beside an input that does not exist yet either: compared by path.
        let new = dir.path().join("sub/new.dat");
        let new_dotted = dir.path().join("sub/../sub/new.dat");
        assert!(same_file_as(&new_dotted, &[new.as_path()]).is_some());
    }

    #[cfg(unix)]
    #[test]
    fn outputs_that_are_not_regular_files_are_refused_and_kept() {
        use std::os::unix::fs::FileTypeExt;
        let e = write_bytes_atomic(Path::new("/dev/null"), b"x").unwrap_err();
        assert_eq!(
            e.to_string(),
            "cannot write /dev/null: it is a character device; an output must be a regular \
             file or a new name"
        );
        assert!(
            std::fs::metadata("/dev/null")
                .unwrap()
                .file_type()
                .is_char_device()
        );
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let e = write_bytes_atomic(&sub, b"x").unwrap_err();
        assert!(
            matches!(
                e,
                OutputError::NotAFile {
                    kind: FileKind::Directory,
                    ..
                }
            ),
            "{e:?}"
        );
        let e = write_bytes_atomic(Path::new("/dev/stdout"), b"x").unwrap_err();
        assert!(
            matches!(
                e,
                OutputError::NotAFile {
                    kind: FileKind::DescriptorLink,
                    ..
                }
            ),
            "{e:?}"
        );
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let e = write_bytes_atomic(&fifo, b"x").unwrap_err();
            assert!(e.to_string().contains("a FIFO"), "{e}");
            assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        }
        assert!(
            !names(dir.path()).iter().any(|n| n.starts_with(TEMP_PREFIX)),
            "{:?}",
            names(dir.path())
        );
    }

    #[cfg(unix)]
    #[test]
    fn symbolic_links_are_written_through() {
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.txt");
        std::fs::write(&real, b"old").unwrap();
        let link = dir.path().join("link.txt");
        std::os::unix::fs::symlink("real.txt", &link).unwrap();
        write_bytes_atomic(&link, b"new").unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
        // A dangling link: its target is created.
        let dangling = dir.path().join("dangling.txt");
        std::os::unix::fs::symlink("made.txt", &dangling).unwrap();
        write_bytes_atomic(&dangling, b"made").unwrap();
        assert_eq!(std::fs::read(dir.path().join("made.txt")).unwrap(), b"made");
        // A link to a device: refused, the device kept.
        let null = dir.path().join("null");
        std::os::unix::fs::symlink("/dev/null", &null).unwrap();
        assert!(matches!(
            write_bytes_atomic(&null, b"x"),
            Err(OutputError::NotAFile {
                kind: FileKind::CharDevice,
                ..
            })
        ));
        // A loop.
        let a = dir.path().join("loop_a");
        let b = dir.path().join("loop_b");
        std::os::unix::fs::symlink(&b, &a).unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        assert!(write_bytes_atomic(&a, b"x").is_err());
    }

    #[test]
    fn staged_outputs_land_together() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.txt");
        let b = dir.path().join("b.txt");
        std::fs::write(&a, b"old a").unwrap();
        let mut staged = StagedOutput::new();
        staged.write_bytes(&a, b"new a").unwrap();
        staged.write_bytes(&b, b"new b").unwrap();
        assert_eq!(
            std::fs::read(&a).unwrap(),
            b"old a",
            "renamed before the commit"
        );
        assert!(!b.exists());
        staged.commit().unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"new a");
        assert_eq!(std::fs::read(&b).unwrap(), b"new b");
        assert_eq!(names(dir.path()), ["a.txt", "b.txt"]);
    }

    #[test]
    fn a_failing_staged_file_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.txt");
        let b = dir.path().join("b");
        std::fs::create_dir(&b).unwrap();
        let mut staged = StagedOutput::new();
        staged.write_bytes(&a, b"a").unwrap();
        assert!(staged.write_bytes(&b, b"b").is_err());
        drop(staged);
        assert_eq!(names(dir.path()), ["b"]);
    }

    #[cfg(unix)]
    #[test]
    fn a_failing_rename_puts_back_the_files_renamed_before() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.txt");
        let b = dir.path().join("b.txt");
        let c = dir.path().join("c.txt");
        std::fs::write(&a, b"old a").unwrap();
        let mut staged = StagedOutput::new();
        staged.write_bytes(&a, b"new a").unwrap();
        staged.write_bytes(&c, b"new c").unwrap();
        staged.write_bytes(&b, b"new b").unwrap();
        // After staging, b becomes a non-empty directory: its rename fails.
        std::fs::create_dir(&b).unwrap();
        std::fs::write(b.join("x"), b"").unwrap();
        let e = staged.commit().unwrap_err();
        assert!(matches!(e, OutputError::Persist { .. }), "{e:?}");
        assert_eq!(std::fs::read(&a).unwrap(), b"old a");
        assert!(!c.exists());
        assert_eq!(names(dir.path()), ["a.txt", "b.txt"]);
    }
}
