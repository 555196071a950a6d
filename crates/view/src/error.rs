//! What can go wrong in the viewer, one variant per failure a user can act on.

use std::path::PathBuf;

/// The viewer's errors.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// A frame's inputs could not be read, placed or checked (the compositor's own error).
    #[error(transparent)]
    Compose(#[from] glassdb_compose::ComposeError),
    /// Frames of a sequence store cos θ differently (the page's shader reads one kind).
    #[error(
        "frame {frame}: the mask {} stores cos θ as {found}, but the first frame's as {first}; a sequence must use one mask kind",
        mask.display()
    )]
    MaskKindChanges {
        frame: u32,
        mask: PathBuf,
        found: &'static str,
        first: &'static str,
    },
    /// A glass choice is not `ID:PRODUCT`.
    #[error("glass choice {spec:?}: {why}")]
    GlassSpec { spec: String, why: String },
    /// No candidate product matches a name.
    #[error("no product matches {name:?}; the candidates are: {candidates}")]
    UnknownProduct { name: String, candidates: String },
    /// Several candidate products match a name.
    #[error("{name:?} matches several products: {matches}; give more of the name")]
    AmbiguousProduct { name: String, matches: String },
    /// The id a choice names is not a glass the registry knows.
    #[error("glass id {id} is not in the registry's table, so it has no slot to swap")]
    UnknownGlassId { id: u16 },
    /// The address given to listen on does not resolve.
    #[error("cannot find the address of {host:?} to listen on")]
    Resolve {
        host: String,
        source: std::io::Error,
    },
    /// The server could not listen (the port is taken, the address is not this machine's, the
    /// port needs privileges): the cause says which.
    #[error("cannot listen on {address}")]
    Bind {
        address: String,
        source: std::io::Error,
    },
    /// No session token could be drawn from the system's random source.
    #[error("cannot draw the page's session token from the system's random source")]
    SessionToken { source: getrandom::Error },
    /// The export folder could not be created or read.
    #[error("cannot write the export into {}", path.display())]
    ExportDir {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The export folder names something that is not a folder.
    #[error(
        "cannot export into {}: it is {kind}, not a folder (the export writes index.html and its data into a folder, created if missing)",
        path.display()
    )]
    ExportNotAFolder {
        path: PathBuf,
        kind: glassdb_io::FileKind,
    },
    /// The export folder holds things that are not a previous export.
    #[error(
        "{} is not empty and holds no previous export (it has {entries}); an export there would replace its index.html and other files",
        path.display()
    )]
    ExportFolderInUse { path: PathBuf, entries: String },
    /// Writing an export file failed.
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
}
