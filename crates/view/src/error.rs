//! What can go wrong in the viewer, one variant per failure a user can act on.

use std::path::PathBuf;

use glassdb_io::ErrorKind;

/// The viewer's errors.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// A frame's inputs could not be read, placed or checked (the compositor's own error).
    #[error(transparent)]
    Compose(#[from] glassdb_compose::ComposeError),
    /// A frame's file pattern could not be expanded.
    #[error(transparent)]
    Frame(#[from] glassdb_io::FrameError),
    /// Frames of a sequence store cos θ differently (the page's shader reads one kind).
    #[error(
        "frame {frame}: the mask {} stores cos θ as {found}, but the first frame's as {first}; a sequence must use one mask kind",
        mask.display()
    )]
    MaskKindChanges {
        /// The frame's label (its number).
        frame: String,
        /// Its mask.
        mask: PathBuf,
        /// How it stores cos θ.
        found: &'static str,
        /// How the first frame's mask does.
        first: &'static str,
    },
    /// The catalog units are built from on the page cannot be loaded.
    #[error("cannot load the catalog that units are built from")]
    UnitCatalog(#[source] glassdb_registry::RegistryError),
    /// A unit the page asked for cannot be built (the stack engine's or the catalog's error).
    #[error("cannot build the unit")]
    Unit(#[source] glassdb_registry::RegistryError),
    /// Building a unit failed inside glassdb (a bug: the engine panicked on this choice).
    #[error("building the unit failed inside glassdb (please report the unit chosen)")]
    UnitPanicked,
    /// A unit request from the page is malformed (element 0: the request as a whole).
    #[error("{}{why}", if *element == 0 { String::new() } else { format!("element {element} of the unit: ") })]
    UnitRequest {
        /// The element (1-based; 0 for the whole request).
        element: usize,
        /// What is wrong.
        why: String,
    },
    /// The viewer was given no frame.
    #[error("no frame to show")]
    NoFrames,
    /// A frame index beyond the frames.
    #[error("there is no frame {index} (the viewer has {frames}, counted from 0)")]
    NoSuchFrame {
        /// The index asked for.
        index: usize,
        /// How many frames there are.
        frames: usize,
    },
    /// A glass choice is not `ID:PRODUCT`.
    #[error("glass choice {spec:?}: {why}")]
    GlassSpec {
        /// The choice as given.
        spec: String,
        /// What is wrong with it.
        why: String,
    },
    /// No candidate product matches a name.
    #[error("no product matches {name:?}; the candidates are: {candidates}")]
    UnknownProduct {
        /// The name given.
        name: String,
        /// Every product, listed.
        candidates: String,
    },
    /// Several candidate products match a name.
    #[error("{name:?} matches several products: {matches}; give more of the name")]
    AmbiguousProduct {
        /// The name given.
        name: String,
        /// The products it matches, listed.
        matches: String,
    },
    /// The id a choice names is not a glass the registry knows.
    #[error("glass id {id} is not in the registry's table, so it has no slot to swap")]
    UnknownGlassId {
        /// The id.
        id: u16,
    },
    /// The address given to listen on does not resolve.
    #[error("cannot find the address of {host:?} to listen on")]
    Resolve {
        /// The host name given.
        host: String,
        /// The resolver's error.
        source: std::io::Error,
    },
    /// The server could not listen (the port is taken, the address is not this machine's, the
    /// port needs privileges): the cause says which.
    #[error("cannot listen on {address}")]
    Bind {
        /// `host:port`.
        address: String,
        /// Why it could not.
        source: std::io::Error,
    },
    /// No session token could be drawn from the system's random source.
    #[error("cannot draw the page's session token from the system's random source")]
    SessionToken {
        /// The random source's error.
        source: getrandom::Error,
    },
    /// The export folder could not be created or read.
    #[error("cannot write the export into {}", path.display())]
    ExportDir {
        /// The folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The export folder names something that is not a folder.
    #[error(
        "cannot export into {}: it is {kind}, not a folder (the export writes index.html and its data into a folder, created if missing)",
        path.display()
    )]
    ExportNotAFolder {
        /// The export folder given.
        path: PathBuf,
        /// What it is instead.
        kind: glassdb_io::FileKind,
    },
    /// The export folder holds things that are not a previous export.
    #[error(
        "{} is not empty and holds no previous export (it has {entries}); an export there would replace its index.html and other files",
        path.display()
    )]
    ExportFolderInUse {
        /// The export folder given.
        path: PathBuf,
        /// Some of what it holds, listed.
        entries: String,
    },
    /// Writing an export file failed.
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
}

impl ViewError {
    /// The class of this error: a frame's own (compose's) class; a bad choice on the page, a
    /// mask kind that changes, an address that does not resolve or an export folder that is
    /// not one (or not an export's) is invalid; the server's, the random source's and the
    /// export's file failures are I/O.
    pub fn kind(&self) -> ErrorKind {
        match self {
            ViewError::Compose(e) => e.kind(),
            ViewError::Frame(e) => e.kind(),
            ViewError::Output(e) => e.kind(),
            ViewError::UnitCatalog(e) | ViewError::Unit(e) => e.kind(),
            ViewError::UnitPanicked => ErrorKind::Internal,
            ViewError::Bind { .. }
            | ViewError::ExportDir { .. }
            | ViewError::SessionToken { .. } => ErrorKind::Io,
            ViewError::MaskKindChanges { .. }
            | ViewError::NoFrames
            | ViewError::NoSuchFrame { .. }
            | ViewError::UnitRequest { .. }
            | ViewError::Resolve { .. }
            | ViewError::ExportNotAFolder { .. }
            | ViewError::ExportFolderInUse { .. }
            | ViewError::GlassSpec { .. }
            | ViewError::UnknownProduct { .. }
            | ViewError::AmbiguousProduct { .. }
            | ViewError::UnknownGlassId { .. } => ErrorKind::Invalid,
        }
    }

    /// The HTTP status the server answers this error with, by its kind: 422 for a frame whose
    /// files cannot be composited as they are (invalid or unsupported: they must be fixed),
    /// 503 for one over a limit (the machine may manage it later, or with a higher limit), 500
    /// for a file that could not be read or glassdb's own failure.
    pub fn http_status(&self) -> u16 {
        match self.kind() {
            ErrorKind::Invalid | ErrorKind::Unsupported => 422,
            ErrorKind::Limits => 503,
            ErrorKind::Io | ErrorKind::Internal => 500,
        }
    }
}
