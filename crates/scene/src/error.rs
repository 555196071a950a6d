//! The one error type of the scene crate: one variant per failure a user can act on.

use std::path::PathBuf;

/// Failures of reading scenes and cameras, finding glass planes, mirroring and rasterising.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene, material library or camera file could not be read.
    #[error("cannot read {path}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why it could not be read.
        source: glassdb_io::InputError,
    },
    /// A line of an OBJ or MTL file is malformed.
    #[error("{path}:{line}: {message}")]
    Syntax {
        /// The OBJ or MTL file.
        path: PathBuf,
        /// The 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The scene has no triangles at all.
    #[error("{path} contains no faces")]
    EmptyScene {
        /// The OBJ.
        path: PathBuf,
    },
    /// No face uses a material matched by the glass patterns.
    #[error(
        "no faces of {path} use a glass material matching {patterns}; materials in the scene: {available}"
    )]
    NoGlassFaces {
        /// The OBJ.
        path: PathBuf,
        /// The patterns, listed.
        patterns: String,
        /// The scene's materials, listed.
        available: String,
    },
    /// A glass pattern is not a valid glob pattern.
    #[error("invalid glass material pattern {pattern:?}: {message}")]
    BadPattern {
        /// The pattern.
        pattern: String,
        /// What is wrong.
        message: String,
    },
    /// A plane equation with a zero (or non-finite) normal, or glass faces that are all degenerate.
    #[error("degenerate plane: {message}")]
    DegeneratePlane {
        /// What is wrong.
        message: String,
    },
    /// The eye lies on the glass plane, so it sees neither side.
    #[error(
        "the eye {eye:?} lies on glass plane {plane} (distance {distance:e}); it sees neither side"
    )]
    EyeOnPlane {
        /// The eye.
        eye: [f64; 3],
        /// The plane.
        plane: usize,
        /// The eye's distance from it.
        distance: f64,
    },
    /// The camera JSON is malformed or describes an impossible camera (the message names the
    /// field; `frame` is the animation frame whose camera it is).
    #[error("camera {path}{}: {message}", frame_suffix(*.frame))]
    BadCamera {
        /// The camera file.
        path: PathBuf,
        /// The frame, in an animation.
        frame: Option<u32>,
        /// What is wrong, naming the field.
        message: String,
    },
    /// An animation has no camera for a frame: its per-frame file does not exist, or the
    /// animation file has no such frame.
    #[error("no camera for frame {frame}: {path} {why}")]
    MissingCameraFrame {
        /// The camera file or pattern.
        path: PathBuf,
        /// The frame.
        frame: u32,
        /// Why there is none.
        why: String,
    },
    /// An animated camera (one per frame) where one camera is needed: no frame was chosen.
    #[error("camera {path} {what}: choose the frames to render")]
    CameraNeedsFrame {
        /// The camera file or pattern.
        path: PathBuf,
        /// What it is.
        what: String,
    },
    /// The requested image is empty or too large to allocate.
    #[error("image size {width}x{height}: {message}")]
    BadImageSize {
        /// The width asked for.
        width: u64,
        /// The height asked for.
        height: u64,
        /// What is wrong.
        message: String,
    },
    /// A `planes.json` is malformed, or a glass face lies on none of its planes.
    #[error("planes file {path}: {message}")]
    BadPlanes {
        /// The planes file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A planes file that is not valid JSON of the planes schema (serde's error gives the line
    /// and column).
    #[error("planes file {path}")]
    PlanesJson {
        /// The planes file.
        path: PathBuf,
        /// serde's error (line and column), shown bounded.
        #[source]
        source: glassdb_io::BoundedError<serde_json::Error>,
    },
    /// A `planes.json` describing another number of planes than the reflection passes given.
    #[error(
        "{planes_file} describes {planes} glass plane(s) but {passes} reflection pass(es) were given: one pass per plane, in the file's order"
    )]
    PlaneCountMismatch {
        /// The planes file.
        planes_file: PathBuf,
        /// The planes it describes.
        planes: usize,
        /// The reflection passes given.
        passes: usize,
    },
    /// A plane-bounds file (`glassdb mask --bounds`) that is not valid JSON of its schema.
    #[error("plane bounds file {path}")]
    BoundsJson {
        /// The plane-bounds file.
        path: PathBuf,
        /// serde's error (line and column), shown bounded.
        #[source]
        source: glassdb_io::BoundedError<serde_json::Error>,
    },
    /// A plane-bounds file with a wrong format tag or a rectangle outside its frame.
    #[error("plane bounds file {path}: {message}")]
    BadBounds {
        /// The plane-bounds file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// An option value is out of range (tolerances, plane count).
    #[error("{message}")]
    BadOption {
        /// What is wrong.
        message: String,
    },
    /// The K of K×K coverage samples per pixel is 0 or above the limit.
    #[error("{samples} samples per pixel side must be between 1 and {max}")]
    SamplesOutOfRange {
        /// K.
        samples: u32,
        /// The largest K.
        max: u32,
    },
    /// The N of the Gouraud N×N mesh is 0 or above the limit.
    #[error("a Gouraud mesh of {mesh}×{mesh} cells must have between 1 and {max} per side")]
    MeshOutOfRange {
        /// N.
        mesh: u32,
        /// The largest N.
        max: u32,
    },
    /// Neither glass materials nor an explicit plane say where the mirrors are.
    #[error("give the glass materials or one plane to mirror across")]
    NoGlassSelected,
    /// A JSON output (`planes.json`, a plane-bounds file) could not be encoded (a non-finite
    /// number).
    #[error("cannot encode {path}")]
    EncodeJson {
        /// The JSON output.
        path: PathBuf,
        /// serde's error.
        source: serde_json::Error,
    },
    /// Writing an output failed (atomic: the target is left as it was).
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
    /// A mask could not be written.
    #[error(transparent)]
    Mask(#[from] glassdb_mask::MaskError),
    /// A frame's file pattern could not be expanded.
    #[error(transparent)]
    Frame(#[from] glassdb_io::FrameError),
}

/// `, frame N` for errors about one frame of an animation.
fn frame_suffix(frame: Option<u32>) -> String {
    frame.map(|f| format!(", frame {f}")).unwrap_or_default()
}

impl SceneError {
    /// The class of this error: a file that cannot be read or written is the reader's or
    /// writer's class; an image size over the limit is a limit; a JSON output that cannot be
    /// encoded is glassdb's bug; anything else is a scene, camera, planes file or option to fix.
    pub fn kind(&self) -> glassdb_io::ErrorKind {
        use glassdb_io::ErrorKind;
        match self {
            SceneError::Read { source, .. } => source.kind(),
            SceneError::Output(e) => e.kind(),
            SceneError::Mask(e) => e.kind(),
            SceneError::Frame(e) => e.kind(),
            SceneError::BadImageSize { .. } => ErrorKind::Limits,
            SceneError::EncodeJson { .. } => ErrorKind::Internal,
            _ => ErrorKind::Invalid,
        }
    }
}
