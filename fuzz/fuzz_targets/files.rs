//! Shared by the targets whose parsers read files: the fuzz input written into a fresh
//! temporary folder.

use std::path::Path;

/// Writes each `(name, bytes)` into a new temporary folder and calls `read` with the folder;
/// `read` is not called when the folder or a file cannot be made.
pub fn with_files(files: &[(&str, &[u8])], read: impl FnOnce(&Path)) {
    let Ok(dir) = tempfile::tempdir() else { return };
    for (name, bytes) in files {
        if std::fs::write(dir.path().join(name), bytes).is_err() {
            return;
        }
    }
    read(dir.path());
}
