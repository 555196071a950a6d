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
    /// The server could not listen.
    #[error("cannot listen on {address}: {source}")]
    Bind {
        address: String,
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The export folder could not be created or is not a directory.
    #[error("cannot write the export into {}", path.display())]
    ExportDir {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Writing an export file failed.
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
}
