//! What a path names, for messages that refuse an input or output that is not a regular file.

use std::fs::FileType;
use std::path::Path;

/// The kind of a file system entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// A regular file.
    Regular,
    /// A directory.
    Directory,
    /// A character device (`/dev/zero`).
    CharDevice,
    /// A block device.
    BlockDevice,
    /// A FIFO (named pipe).
    Fifo,
    /// A socket.
    Socket,
    /// A symbolic link.
    Symlink,
    /// A link to an open file descriptor (`/dev/stdout`, `/dev/fd/N`, `/proc/self/fd/N`): it
    /// names whatever the descriptor is (a terminal, a pipe), not a file to replace.
    DescriptorLink,
    /// Anything else.
    Other,
}

impl FileKind {
    /// The kind of `t` (not following a symbolic link: `t` says what it is).
    pub fn of(t: &FileType) -> FileKind {
        #[cfg(unix)]
        use std::os::unix::fs::FileTypeExt;
        /// A test of a file type and the kind it names.
        type Test = (fn(&FileType) -> bool, FileKind);
        // Tested in this order; the first test that holds names the kind.
        let tests: &[Test] = &[
            (FileType::is_file, FileKind::Regular),
            (FileType::is_dir, FileKind::Directory),
            (FileType::is_symlink, FileKind::Symlink),
            #[cfg(unix)]
            (FileType::is_char_device, FileKind::CharDevice),
            #[cfg(unix)]
            (FileType::is_block_device, FileKind::BlockDevice),
            #[cfg(unix)]
            (FileType::is_fifo, FileKind::Fifo),
            #[cfg(unix)]
            (FileType::is_socket, FileKind::Socket),
        ];
        tests
            .iter()
            .find(|(is, _)| is(t))
            .map_or(FileKind::Other, |&(_, kind)| kind)
    }
}

impl std::fmt::Display for FileKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            FileKind::Regular => "a regular file",
            FileKind::Directory => "a directory",
            FileKind::CharDevice => "a character device",
            FileKind::BlockDevice => "a block device",
            FileKind::Fifo => "a FIFO (named pipe)",
            FileKind::Socket => "a socket",
            FileKind::Symlink => "a symbolic link",
            FileKind::DescriptorLink => "a link to an open file descriptor (such as /dev/stdout)",
            FileKind::Other => "not a file",
        })
    }
}

/// The extension of `path` in lower case (`None`: no extension, or not UTF-8): what readers and
/// writers choose a format by.
pub fn lowercase_extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}
