//! The errors of `glassdb blender`: one variant per failure a user can act on.

use std::path::{Path, PathBuf};

/// Why a Blender run or its composite failed.
#[derive(Debug, thiserror::Error)]
pub enum BlenderError {
    /// The Blender program could not be started (not installed, not on PATH, not executable).
    #[error("cannot run Blender at {path}")]
    NotFound {
        /// The program.
        path: PathBuf,
        /// Why it could not be started.
        source: std::io::Error,
    },
    /// The Python interpreter given for the `bpy` module cannot import it.
    #[error("{python} cannot import the bpy module (Blender as a Python module): {said}")]
    NoBpyModule {
        /// The interpreter.
        python: PathBuf,
        /// What it printed.
        said: String,
    },
    /// `blender --version` did not say which Blender it is.
    #[error("{path} did not print a Blender version when asked for it (it printed {printed:?})")]
    VersionUnreadable {
        /// The program.
        path: PathBuf,
        /// What it printed.
        printed: String,
    },
    /// `blender --version` (or the `bpy` probe) did not finish in time and was stopped.
    #[error("{path} did not answer within {seconds} s when asked for its Blender version")]
    VersionTimedOut {
        /// The program.
        path: PathBuf,
        /// The time it had.
        seconds: u64,
    },
    /// A Blender older than the oldest one supported.
    #[error(
        "{path} is Blender {found}; glassdb blender needs Blender {}.{} or newer",
        minimum.0, minimum.1
    )]
    TooOld {
        /// The program.
        path: PathBuf,
        /// Its version.
        found: String,
        /// The oldest version supported (major, minor).
        minimum: (u32, u32),
    },
    /// The scene file is missing, not a regular file, or not a .blend file.
    #[error("{path} is not a Blender file: {reason}")]
    NotBlendFile {
        /// The file.
        path: PathBuf,
        /// What it is instead.
        reason: String,
    },
    /// The Blender-side script stopped on a problem of the scene (no camera, a material
    /// missing, an object that moves).
    #[error("Blender ({step}) on {blend}: {message} (log: {log})")]
    Scene {
        /// The step (`export`, `render`).
        step: &'static str,
        /// The scene.
        blend: PathBuf,
        /// What the script said.
        message: String,
        /// Blender's log.
        log: PathBuf,
    },
    /// Blender exited with an error or was killed (a crash).
    #[error("Blender ({step}) failed on {blend}: {status}; the end of its log {log}:\n{tail}")]
    Failed {
        /// The step (`export`, `render`).
        step: &'static str,
        /// The scene.
        blend: PathBuf,
        /// How it ended.
        status: String,
        /// Blender's log.
        log: PathBuf,
        /// The end of the log.
        tail: String,
    },
    /// Blender exited without an error but did not write what the step asked of it (a stand-in
    /// or a broken install that ignores the script).
    #[error(
        "{blender} exited without an error but wrote no scene export: {missing} missing in {dir} (its log: {log})"
    )]
    NothingWritten {
        /// The Blender program run, with its version (`Blender 3.4.1 (/usr/bin/blender)`).
        blender: String,
        /// The files missing, comma-separated.
        missing: String,
        /// Where they should be.
        dir: PathBuf,
        /// Blender's log.
        log: PathBuf,
    },
    /// Blender ran longer than allowed and was stopped.
    #[error(
        "Blender ({step}) on {blend} took longer than {seconds} s and was stopped (log: {log})"
    )]
    TimedOut {
        /// The step (`export`, `render`).
        step: &'static str,
        /// The scene.
        blend: PathBuf,
        /// The time it had.
        seconds: u64,
        /// Blender's log.
        log: PathBuf,
    },
    /// A file or directory of the run could not be created, read or written.
    #[error("cannot {action} {path}")]
    Io {
        /// What was being done.
        action: &'static str,
        /// The file or folder.
        path: PathBuf,
        /// Why it failed.
        source: std::io::Error,
    },
    /// What Blender wrote is not what was asked (a missing pass, a crop of another size).
    #[error("{path}: {message}")]
    BadRender {
        /// The file Blender wrote (or should have).
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A run record (`glassdb-blender.json`) that cannot be used.
    #[error("{path} is not a glassdb blender run record: {message}")]
    BadRecord {
        /// The run record.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A glass id that the registry does not have.
    #[error("glass id {id} (material {material}) is not in {registry}")]
    UnknownGlass {
        /// The id.
        id: u16,
        /// The Blender material mapped to it.
        material: String,
        /// The registry's name.
        registry: String,
    },
    /// A light named twice in the render's lights.
    #[error("light group `{group}` is given a spectrum twice")]
    LightTwice {
        /// The group.
        group: String,
    },
    /// A light given for a group the scene does not have.
    #[error("{blend} has no light group `{group}` ({})", list_groups(groups))]
    UnknownLightGroup {
        /// The group asked for.
        group: String,
        /// The scene.
        blend: PathBuf,
        /// The scene's groups.
        groups: Vec<String>,
    },
    /// A scene light group whose spectrum nothing says.
    #[error(
        "light group `{group}` of {blend} has no spectrum: say its illuminant (GROUP=ILLUMINANT) or set a glassdb_light property on one of its lamps or its world"
    )]
    LightGroupWithoutSpectrum {
        /// The group.
        group: String,
        /// The scene.
        blend: PathBuf,
    },
    /// Emitters in no light group of a scene that has groups: their light would be lost.
    #[error(
        "{blend} has light groups ({}), but these emitters are in none: {}; put each in a group",
        groups.join(", "), emitters.join(", ")
    )]
    UngroupedEmitters {
        /// The scene.
        blend: PathBuf,
        /// The emitters (`lamp Desk`, `world World`).
        emitters: Vec<String>,
        /// The scene's groups.
        groups: Vec<String>,
    },
    /// A `glassdb_light` property that is no illuminant.
    #[error("the glassdb_light property of {holder} ({value:?}) is no illuminant")]
    BadLightProperty {
        /// Its holder.
        holder: String,
        /// Its value.
        value: String,
        /// Why.
        source: Box<glassdb_spectral::SpectralError>,
    },
    /// Two `glassdb_light` properties of one group that name different spectra.
    #[error("light group `{group}`: its glassdb_light properties disagree ({first}; {second})")]
    LightPropertiesDisagree {
        /// The group.
        group: String,
        /// One property.
        first: String,
        /// Another.
        second: String,
    },
    /// A run's light group whose light the registry (of several lights) lacks.
    #[error(
        "light group `{group}` ({illuminant}) has no table in {registry} (its lights: {})",
        lights.join(", ")
    )]
    RegistryLacksLight {
        /// The group.
        group: String,
        /// The group's illuminant.
        illuminant: String,
        /// The registry.
        registry: String,
        /// The registry's lights, described.
        lights: Vec<String>,
    },
    /// A registry light of a group's name but another spectrum.
    #[error(
        "light group `{group}` was rendered as {rendered} ({record}), but {registry}'s light `{group}` is {table}"
    )]
    LightMismatch {
        /// The group.
        group: String,
        /// Its illuminant in the run record.
        rendered: String,
        /// The run record.
        record: PathBuf,
        /// The registry.
        registry: String,
        /// The registry's light of that name, described.
        table: String,
    },
    /// A frame list or option that cannot be used.
    #[error("{0}")]
    BadOption(String),
    /// The scene's planes or masks failed.
    #[error(transparent)]
    Scene3d(#[from] glassdb_scene::SceneError),
    /// A mask could not be written or read.
    #[error(transparent)]
    Mask(#[from] glassdb_mask::MaskError),
    /// A frame could not be composited.
    #[error(transparent)]
    Compose(#[from] glassdb_compose::ComposeError),
    /// A pass could not be read or written.
    #[error(transparent)]
    Image(#[from] glassdb_image::ImageError),
    /// An output could not be written.
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
    /// An input could not be read.
    #[error(transparent)]
    Input(#[from] glassdb_io::InputError),
    /// A registry could not be read.
    #[error(transparent)]
    Registry(#[from] glassdb_registry::RegistryError),
}

/// A scene's light groups in a message.
fn list_groups(groups: &[String]) -> String {
    if groups.is_empty() {
        "it has no light groups: the whole scene is one light".into()
    } else {
        format!("its light groups: {}", groups.join(", "))
    }
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
    /// The class of this error: a wrapped error's own class; a Blender missing, too old or
    /// writing nothing is unsupported, one that does not finish in time a limit, a file of the run that cannot
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
            | BlenderError::TooOld { .. }
            | BlenderError::NothingWritten { .. } => ErrorKind::Unsupported,
            BlenderError::VersionTimedOut { .. } | BlenderError::TimedOut { .. } => {
                ErrorKind::Limits
            }
            BlenderError::Io { .. } | BlenderError::Failed { .. } => ErrorKind::Io,
            _ => ErrorKind::Invalid,
        }
    }
}
