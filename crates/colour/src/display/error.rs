//! What can go wrong reading a `.cube` display view.

use std::path::PathBuf;

use glassdb_io::ErrorKind;

/// A `.cube` file that cannot be read or is not a LUT this reader accepts (docs/colour.md).
#[derive(Debug, thiserror::Error)]
pub enum CubeError {
    /// The file could not be read (missing, not a regular file).
    #[error("cannot read {path}")]
    Read {
        /// The `.cube` file.
        path: PathBuf,
        /// Why.
        #[source]
        cause: glassdb_io::InputError,
    },
    /// A `.cube` line that cannot be read.
    #[error("{path}, line {line}: {problem} (line: {text:?})")]
    Syntax {
        /// The `.cube` file.
        path: PathBuf,
        /// The 1-based line number.
        line: usize,
        /// The line's text (its first 80 characters).
        text: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A `.cube` file whose header and tables do not agree, or that is no LUT at all.
    #[error("{path}: {problem}")]
    Invalid {
        /// The `.cube` file.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// A `.cube` file too large to be a LUT this reader accepts (checked before reading).
    #[error(
        "{path} is {bytes} bytes; a .cube file of at most {max} bytes is read (LUT_3D_SIZE ≤ 129)"
    )]
    TooLarge {
        /// The `.cube` file.
        path: PathBuf,
        /// Its size.
        bytes: u64,
        /// The most bytes read ([`super::MAX_CUBE_FILE_BYTES`]).
        max: u64,
    },
}

impl CubeError {
    /// The class of this error: a file that cannot be read is the reader's class, one over the
    /// size limit a limit, anything else invalid.
    pub fn kind(&self) -> ErrorKind {
        match self {
            CubeError::Read { cause, .. } => cause.kind(),
            CubeError::TooLarge { .. } => ErrorKind::Limits,
            CubeError::Syntax { .. } | CubeError::Invalid { .. } => ErrorKind::Invalid,
        }
    }
}
