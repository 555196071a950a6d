//! The errors of `glassdb blender`: one variant per failure a user can act on.

use std::path::{Path, PathBuf};

/// Why a Blender run or its composite failed.
#[derive(Debug, thiserror::Error)]
pub enum BlenderError {
    /// The Blender program could not be started (not installed, not on PATH, not executable).
    #[error("cannot run Blender at {path}")]
    NotFound {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The Python interpreter given for the `bpy` module cannot import it.
    #[error("{python} cannot import the bpy module (Blender as a Python module): {said}")]
    NoBpyModule { python: PathBuf, said: String },
    /// `blender --version` did not say which Blender it is.
    #[error("{path} did not print a Blender version when asked for it (it printed {printed:?})")]
    VersionUnreadable { path: PathBuf, printed: String },
    /// `blender --version` (or the `bpy` probe) did not finish in time and was stopped.
    #[error("{path} did not answer within {seconds} s when asked for its Blender version")]
    VersionTimedOut { path: PathBuf, seconds: u64 },
    /// A Blender older than the oldest one supported.
    #[error(
        "{path} is Blender {found}; glassdb blender needs Blender {}.{} or newer",
        minimum.0, minimum.1
    )]
    TooOld {
        path: PathBuf,
        found: String,
        minimum: (u32, u32),
    },
    /// The scene file is missing, not a regular file, or not a .blend file.
    #[error("{path} is not a Blender file: {reason}")]
    NotBlendFile { path: PathBuf, reason: String },
    /// The Blender-side script stopped on a problem of the scene (no camera, a material
    /// missing, an object that moves).
    #[error("Blender ({step}) on {blend}: {message} (log: {log})")]
    Scene {
        step: &'static str,
        blend: PathBuf,
        message: String,
        log: PathBuf,
    },
    /// Blender exited with an error or was killed (a crash).
    #[error("Blender ({step}) failed on {blend}: {status}; the end of its log {log}:\n{tail}")]
    Failed {
        step: &'static str,
        blend: PathBuf,
        status: String,
        log: PathBuf,
        tail: String,
    },
    /// Blender ran longer than allowed and was stopped.
    #[error(
        "Blender ({step}) on {blend} took longer than {seconds} s and was stopped (log: {log})"
    )]
    TimedOut {
        step: &'static str,
        blend: PathBuf,
        seconds: u64,
        log: PathBuf,
    },
    /// A file or directory of the run could not be created, read or written.
    #[error("cannot {action} {path}")]
    Io {
        action: &'static str,
        path: PathBuf,
        source: std::io::Error,
    },
    /// What Blender wrote is not what was asked (a missing pass, a crop of another size).
    #[error("{path}: {message}")]
    BadRender { path: PathBuf, message: String },
    /// A run record (`glassdb-blender.json`) that cannot be used.
    #[error("{path} is not a glassdb blender run record: {message}")]
    BadRecord { path: PathBuf, message: String },
    /// A glass id that the registry does not have.
    #[error("glass id {id} (material {material}) is not in {registry}")]
    UnknownGlass {
        id: u16,
        material: String,
        registry: String,
    },
    /// A frame list or option that cannot be used.
    #[error("{0}")]
    BadOption(String),
    #[error(transparent)]
    Scene3d(#[from] glassdb_scene::SceneError),
    #[error(transparent)]
    Mask(#[from] glassdb_mask::MaskError),
    #[error(transparent)]
    Compose(#[from] glassdb_compose::ComposeError),
    #[error(transparent)]
    Image(#[from] glassdb_image::ImageError),
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
    #[error(transparent)]
    Input(#[from] glassdb_io::InputError),
    #[error(transparent)]
    Registry(#[from] glassdb_registry::RegistryError),
}

impl BlenderError {
    /// [`BlenderError::Io`] for `action` on `path`, as a `map_err` argument.
    pub(crate) fn io(action: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.to_path_buf();
        move |source| BlenderError::Io {
            action,
            path,
            source,
        }
    }
}

impl BlenderError {
    /// The class of this error: a wrapped error's own class; a Blender missing or too old is
    /// unsupported, one that does not finish in time a limit, a file of the run that cannot
    /// be made or moved (or Blender failing) I/O; anything else is a scene, a render or an
    /// option to fix.
    pub fn kind(&self) -> glassdb_io::ErrorKind {
        use glassdb_io::ErrorKind;
        match self {
            BlenderError::Scene3d(e) => e.kind(),
            BlenderError::Mask(e) => e.kind(),
            BlenderError::Compose(e) => e.kind(),
            BlenderError::Image(e) => e.kind(),
            BlenderError::Output(e) => e.kind(),
            BlenderError::Input(e) => e.kind(),
            BlenderError::Registry(e) => e.kind(),
            BlenderError::NotFound { .. }
            | BlenderError::NoBpyModule { .. }
            | BlenderError::VersionUnreadable { .. }
            | BlenderError::TooOld { .. } => ErrorKind::Unsupported,
            BlenderError::VersionTimedOut { .. } | BlenderError::TimedOut { .. } => {
                ErrorKind::Limits
            }
            BlenderError::Io { .. } | BlenderError::Failed { .. } => ErrorKind::Io,
            _ => ErrorKind::Invalid,
        }
    }
}
