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
        /// The output.
        path: PathBuf,
        /// Why it failed.
        source: std::io::Error,
    },
    /// Writing the content failed (disk full, I/O error, or the producer reported an error).
    #[error("cannot write {path}")]
    Write {
        /// The output.
        path: PathBuf,
        /// Why it failed.
        source: std::io::Error,
    },
    /// The finished temporary file could not be renamed over the target.
    #[error("cannot move the finished output into place at {path}")]
    Persist {
        /// The output.
        path: PathBuf,
        /// Why it failed.
        source: std::io::Error,
    },
    /// The directory the output goes into does not exist ([`write_atomic`] creates none; see
    /// [`create_output_dirs`]).
    #[error("cannot write {path}: the directory {dir} does not exist")]
    MissingDirectory {
        /// The output.
        path: PathBuf,
        /// The folder that does not exist.
        dir: PathBuf,
    },
    /// A folder an output goes into could not be created ([`create_output_dirs`]).
    #[error("cannot create the folder {dir} for {path}")]
    CreateDirectory {
        /// The output.
        path: PathBuf,
        /// The folder.
        dir: PathBuf,
        /// Why it failed.
        source: std::io::Error,
    },
    /// A folder that is itself an output (a run's output folder, a report's figures folder)
    /// could not be created ([`create_output_folder`]).
    #[error("cannot create the {what} {path}")]
    CreateFolder {
        /// What the folder is for, as the message names it ("output directory").
        what: &'static str,
        /// The folder.
        path: PathBuf,
        /// Why it failed.
        source: std::io::Error,
    },
    /// The output is one of the run's own inputs (the same file, whatever the spelling, link
    /// or hard link).
    #[error(
        "refusing to overwrite the input file {} with the output{}",
        input.display(),
        if input == path { String::new() } else { format!(" {} (the same file)", path.display()) }
    )]
    OutputIsInput {
        /// The output.
        path: PathBuf,
        /// The input it names.
        input: PathBuf,
    },
    /// The output exists and is not a regular file (a directory, a device such as `/dev/null`,
    /// a FIFO, a socket, a link to an open file descriptor): it is never replaced.
    #[error("cannot write {path}: it is {kind}; an output must be a regular file or a new name")]
    NotAFile {
        /// The output.
        path: PathBuf,
        /// What it is.
        kind: FileKind,
    },
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
            | OutputError::MissingDirectory { .. }
            | OutputError::CreateDirectory { .. }
            | OutputError::CreateFolder { .. } => ErrorKind::Io,
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

/// The regular file or new name `path` is, without following a symbolic link: a link at
/// `path` is itself what the output replaces (for folders whose entries must not lead
/// elsewhere, as an export's). Refuses an existing entry of any other kind.
fn own_target(path: &Path) -> Result<PathBuf, OutputError> {
    match std::fs::symlink_metadata(path) {
        Err(_) => Ok(path.to_path_buf()),
        Ok(meta) => match FileKind::of(&meta.file_type()) {
            FileKind::Regular | FileKind::Symlink => Ok(path.to_path_buf()),
            kind => Err(OutputError::NotAFile {
                path: path.to_path_buf(),
                kind,
            }),
        },
    }
}

/// What an output does with a symbolic link where it is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Links {
    /// Writes through it: the file it leads to is replaced and the link kept.
    Follow,
    /// Replaces the link itself; what it leads to is never opened.
    Replace,
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
fn stage<F>(path: &Path, links: Links, produce: F) -> Result<StagedFile, OutputError>
where
    F: FnOnce(&mut BufWriter<SyncingFile<'_>>) -> std::io::Result<()>,
{
    let target = match links {
        Links::Follow => resolve_target(path)?,
        Links::Replace => own_target(path)?,
    };
    // A link that is replaced leaves what it leads to alone, input or not.
    let replaced_link = links == Links::Replace
        && std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if !replaced_link {
        refuse_input_as_output(path)?;
    }
    let dir = registry::parent_dir(&target).to_path_buf();
    if !dir.is_dir() {
        return Err(OutputError::MissingDirectory {
            path: path.to_path_buf(),
            dir,
        });
    }
    // A replaced file keeps its mode; a new one gets what any other tool would give it
    // (0666 masked by the umask), not a temporary file's private 0600.
    let permissions = match std::fs::symlink_metadata(&target)
        .ok()
        .filter(|m| m.is_file())
    {
        Some(meta) => meta.permissions(),
        #[cfg(unix)]
        None => {
            use std::os::unix::fs::PermissionsExt;
            std::fs::Permissions::from_mode(0o666)
        }
        #[cfg(not(unix))]
        None => std::fs::File::open(&dir)
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
    let staged = stage(path, Links::Follow, produce)?;
    staged
        .temp
        .persist(&staged.target)
        .map_err(|source| OutputError::Persist {
            path: staged.path,
            source,
        })
}

/// Creates the folders `path` goes into where they are missing (as `mkdir -p`: concurrent
/// runs creating the same folders both succeed), for commands whose outputs name their folders
/// (`compose -o comp/out.####.exr --report reports/…`); the file itself is then written with
/// [`write_atomic`]: a temporary file in that folder, renamed.
pub fn create_output_dirs(path: &Path) -> Result<(), OutputError> {
    let dir = registry::parent_dir(path);
    std::fs::create_dir_all(dir).map_err(|source| OutputError::CreateDirectory {
        path: path.to_path_buf(),
        dir: dir.to_path_buf(),
        source,
    })
}

/// Creates the folder `dir` that a command writes its outputs into, and the folders above it,
/// where they are missing (as `mkdir -p`); `what` names the folder in the error
/// ("output directory").
pub fn create_output_folder(dir: &Path, what: &'static str) -> Result<(), OutputError> {
    std::fs::create_dir_all(dir).map_err(|source| OutputError::CreateFolder {
        what,
        path: dir.to_path_buf(),
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
    /// An empty set of outputs.
    pub fn new() -> Self {
        Self::default()
    }

    /// Writes the content of `path` to its temporary file (see [`write_atomic`]).
    pub fn write<F>(&mut self, path: &Path, produce: F) -> Result<(), OutputError>
    where
        F: FnOnce(&mut BufWriter<SyncingFile<'_>>) -> std::io::Result<()>,
    {
        self.files.push(stage(path, Links::Follow, produce)?);
        Ok(())
    }

    /// As [`StagedOutput::write_bytes`], but a symbolic link at `path` is replaced by the file
    /// rather than written through: nothing outside `path`'s folder is touched, whatever links
    /// someone placed in it (the viewer's export folder).
    pub fn write_bytes_replacing_link(
        &mut self,
        path: &Path,
        bytes: &[u8],
    ) -> Result<(), OutputError> {
        self.write_replacing_link(path, |w| w.write_all(bytes))
    }

    /// As [`StagedOutput::write`], but a symbolic link at `path` is replaced by the file rather
    /// than written through (see [`StagedOutput::write_bytes_replacing_link`]).
    pub fn write_replacing_link<F>(&mut self, path: &Path, produce: F) -> Result<(), OutputError>
    where
        F: FnOnce(&mut BufWriter<SyncingFile<'_>>) -> std::io::Result<()>,
    {
        self.files.push(stage(path, Links::Replace, produce)?);
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

#[cfg(test)]
mod tests;
