//! Bounded input: every file a glassdb tool reads goes through [`read_input`], which refuses
//! what is not a regular file (a directory, a device such as `/dev/zero`, a FIFO, a socket)
//! and a file over the limit of its kind ([`limits`]), checking the file's metadata before
//! reading a byte and bounding the read itself too, so that no input is read without end.
//!
//! [`InputError`] says what is wrong without repeating the path: each library wraps it in its
//! own error variant, which names the file (`cannot read cat.toml: it is a FIFO …`).

use std::fs::{File, Metadata};
use std::io::Read;
use std::path::Path;

use crate::ErrorKind;
use crate::kind::FileKind;
use crate::registry;

/// The most bytes one kind of input may have, and what that kind is called in messages. Each
/// library declares the limit of the kinds of file it reads (docs/reliability.md lists them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InputLimit {
    /// The most bytes a file of this kind may have.
    pub bytes: u64,
    /// The kind, as a message names it: `a catalog`, `an OBJ scene`.
    pub what: &'static str,
}

impl InputLimit {
    /// A limit of `mib` MiB for files called `what` in messages.
    pub const fn mib(mib: u64, what: &'static str) -> InputLimit {
        InputLimit {
            bytes: mib * limits::MIB,
            what,
        }
    }

    /// A limit of `gib` GiB for files called `what` in messages.
    pub const fn gib(gib: u64, what: &'static str) -> InputLimit {
        InputLimit {
            bytes: gib * limits::GIB,
            what,
        }
    }

    /// The limit as people write it: `16 MiB`, `2 GiB`, `1500 bytes`.
    pub fn size_text(&self) -> String {
        byte_size_text(self.bytes)
    }
}

/// The limit of the one kind of input that is a format rather than one library's file: a JSON
/// document (a registry, a fit file, a `planes.json`, a run record). Every other kind's limit
/// is declared by the library that reads it.
pub mod limits {
    use super::InputLimit;

    pub(super) const MIB: u64 = 1 << 20;
    pub(super) const GIB: u64 = 1 << 30;

    /// A JSON document: a registry, a fit file, a `planes.json`.
    pub const JSON: InputLimit = InputLimit::mib(64, "a JSON file");
}

/// `n` bytes as people write them: `16 MiB`, `2 GiB`, `1500 bytes`.
fn byte_size_text(n: u64) -> String {
    use limits::{GIB, MIB};
    if n >= GIB && n.is_multiple_of(GIB) {
        format!("{} GiB", n / GIB)
    } else if n >= MIB && n.is_multiple_of(MIB) {
        format!("{} MiB", n / MIB)
    } else {
        format!("{n} bytes")
    }
}

fn size_text(size: &Option<u64>) -> String {
    match size {
        Some(n) => format!("it has {n} bytes,"),
        None => "it grew while being read, to".to_string(),
    }
}

/// Why an input could not be read. The messages do not repeat the path: the error that wraps
/// this one names the file.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// Opening or reading failed (no such file, permission denied, an I/O error).
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// The path names something that is not a regular file and would be read without end or
    /// not at all (a directory, `/dev/zero`, a FIFO, a socket).
    #[error("it is {kind}, not a regular file")]
    NotAFile {
        /// What it is.
        kind: FileKind,
    },
    /// The file is over the limit of its kind (see [`limits`]); nothing was read.
    #[error(
        "{} more than the {} {} may have",
        size_text(size),
        byte_size_text(limit.bytes),
        limit.what
    )]
    TooLarge {
        /// Its size from its metadata (`None` when it grew past the limit while being read).
        size: Option<u64>,
        /// The limit of its kind.
        limit: InputLimit,
    },
    /// The file was read as text but is not UTF-8.
    #[error("it is not UTF-8 text (byte {valid_up_to} is not)")]
    NotUtf8 {
        /// The first byte that is not UTF-8.
        valid_up_to: usize,
    },
}

impl InputError {
    /// The class of this error: a missing or unreadable file is I/O, a file over its limit
    /// (or too large to hold) is a limit, a device or a non-UTF-8 text is invalid input.
    pub fn kind(&self) -> ErrorKind {
        match self {
            InputError::Io(e) if e.kind() == std::io::ErrorKind::OutOfMemory => ErrorKind::Limits,
            InputError::Io(_) => ErrorKind::Io,
            InputError::TooLarge { .. } => ErrorKind::Limits,
            InputError::NotAFile { .. } | InputError::NotUtf8 { .. } => ErrorKind::Invalid,
        }
    }
}

/// Refuses what is not a regular file, or one over `limit`.
fn check(meta: &Metadata, limit: InputLimit) -> Result<(), InputError> {
    let kind = FileKind::of(&meta.file_type());
    if kind != FileKind::Regular {
        return Err(InputError::NotAFile { kind });
    }
    if meta.len() > limit.bytes {
        return Err(InputError::TooLarge {
            size: Some(meta.len()),
            limit,
        });
    }
    Ok(())
}

/// Opens `path` for reading without blocking on a FIFO that appeared since it was checked.
fn open(path: &Path) -> std::io::Result<File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    options.open(path)
}

/// Reads the whole of the regular file `path`, of at most `limit.bytes` bytes. Refuses a path
/// that is not a regular file (following symbolic links) and a file over the limit from its
/// metadata before opening it, checks the opened file again, and reads at most
/// `limit.bytes + 1` bytes whatever the metadata said. With [`crate::protect_inputs`], the file
/// is recorded as an input that no output of this process may replace.
pub fn read_input(path: &Path, limit: InputLimit) -> Result<Vec<u8>, InputError> {
    let (file, len) = open_checked(path, limit)?;
    read_open_input(file, len, limit)
}

/// Reads an earlier output of the command, with the checks of [`read_input`], to see whether
/// it is complete (`compose --skip-existing`): it is **not** recorded as an input, so the
/// command may still replace it.
pub fn read_previous_output(path: &Path, limit: InputLimit) -> Result<Vec<u8>, InputError> {
    let (file, meta) = open_unrecorded(path, limit)?;
    read_open_input(file, meta.len(), limit)
}

/// Reads at most `limit.bytes` of `file` (of `len` bytes by its metadata), refusing more: the
/// rest of an input opened with [`open_input`] (from where it stands) when the whole file turns
/// out to be needed.
pub fn read_open_input(
    file: impl Read,
    len: u64,
    limit: InputLimit,
) -> Result<Vec<u8>, InputError> {
    let mut bytes = Vec::new();
    let expected = usize::try_from(len).unwrap_or(usize::MAX);
    bytes.try_reserve_exact(expected).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::OutOfMemory,
            format!("cannot allocate {len} bytes to read it"),
        )
    })?;
    file.take(limit.bytes + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit.bytes {
        return Err(InputError::TooLarge { size: None, limit });
    }
    Ok(bytes)
}

/// Opens the regular file `path` to read part of it (an image's header), with the checks of
/// [`read_input`]: not a directory, device or FIFO, within `limit`; the reader returned stops
/// after `limit.bytes`. Returns it with the file's size. Recorded as an input as by
/// [`read_input`].
pub fn open_input(
    path: &Path,
    limit: InputLimit,
) -> Result<(std::io::Take<File>, u64), InputError> {
    let (file, len) = open_checked(path, limit)?;
    Ok((file.take(limit.bytes), len))
}

/// The checks both readers make: `path` refused from its metadata, opened without blocking,
/// checked again as opened, and recorded as an input. Returns the file and its size.
fn open_checked(path: &Path, limit: InputLimit) -> Result<(File, u64), InputError> {
    let (file, meta) = open_unrecorded(path, limit)?;
    registry::record_input(path, &meta);
    Ok((file, meta.len()))
}

/// The checks of [`open_checked`] without recording the file as an input; returns the file
/// and its metadata as opened.
fn open_unrecorded(path: &Path, limit: InputLimit) -> Result<(File, Metadata), InputError> {
    check(&std::fs::metadata(path)?, limit)?;
    let file = open(path)?;
    let meta = file.metadata()?;
    check(&meta, limit)?;
    Ok((file, meta))
}

/// [`read_input`] of a text file: its bytes must be UTF-8.
pub fn read_input_string(path: &Path, limit: InputLimit) -> Result<String, InputError> {
    let bytes = read_input(path, limit)?;
    String::from_utf8(bytes).map_err(|e| InputError::NotUtf8 {
        valid_up_to: e.utf8_error().valid_up_to(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: InputLimit = InputLimit {
        bytes: 10,
        what: "a test file",
    };

    #[test]
    fn regular_files_within_the_limit_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        std::fs::write(&p, b"0123456789").unwrap();
        assert_eq!(read_input(&p, SMALL).unwrap(), b"0123456789");
        assert_eq!(read_input_string(&p, SMALL).unwrap(), "0123456789");
    }

    #[test]
    fn files_over_the_limit_are_refused_from_their_size() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("big.txt");
        let f = File::create(&p).unwrap();
        f.set_len(1 << 40).unwrap(); // sparse: a terabyte that is never read
        let e = read_input(&p, SMALL).unwrap_err();
        assert!(
            matches!(e, InputError::TooLarge { size: Some(n), .. } if n == 1 << 40),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "it has 1099511627776 bytes, more than the 10 bytes a test file may have"
        );
        assert_eq!(
            InputError::TooLarge {
                size: Some(20 << 20),
                limit: InputLimit::mib(16, "a catalog")
            }
            .to_string(),
            "it has 20971520 bytes, more than the 16 MiB a catalog may have"
        );
    }

    #[cfg(unix)]
    #[test]
    fn devices_directories_and_fifos_are_refused_without_reading() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_input(dir.path(), SMALL).unwrap_err();
        assert!(
            matches!(
                e,
                InputError::NotAFile {
                    kind: FileKind::Directory
                }
            ),
            "{e:?}"
        );
        let e = read_input(Path::new("/dev/zero"), SMALL).unwrap_err();
        assert_eq!(
            e.to_string(),
            "it is a character device, not a regular file"
        );
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            // Opening a FIFO for reading would wait for a writer: it must be refused first.
            let e = read_input(&fifo, SMALL).unwrap_err();
            assert!(e.to_string().contains("a FIFO"), "{e}");
        }
        // A symbolic link is followed: to a regular file it reads, to a device it is refused.
        let link = dir.path().join("zero");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        assert!(matches!(
            read_input(&link, SMALL),
            Err(InputError::NotAFile {
                kind: FileKind::CharDevice
            })
        ));
    }

    #[test]
    fn missing_files_keep_the_os_error() {
        let e = read_input(Path::new("/nonexistent-glassdb/x"), SMALL).unwrap_err();
        let InputError::Io(io) = &e else {
            panic!("{e:?}")
        };
        assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
    }

    #[test]
    fn invalid_utf8_is_named_by_its_byte() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        std::fs::write(&p, b"ab\xffcd").unwrap();
        let e = read_input_string(&p, SMALL).unwrap_err();
        assert!(matches!(e, InputError::NotUtf8 { valid_up_to: 2 }), "{e:?}");
    }

    #[test]
    fn limits_read_as_sizes() {
        assert_eq!(InputLimit::gib(2, "an OBJ scene").size_text(), "2 GiB");
        assert_eq!(InputLimit::mib(16, "a catalog").size_text(), "16 MiB");
        assert_eq!(byte_size_text(1500), "1500 bytes");
    }
}
