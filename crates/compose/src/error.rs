//! The one error type of the compositor: one variant per failure a user can act on, each
//! naming the file (and pixel, id, plane or frame) involved.

use std::path::PathBuf;

/// Everything that can go wrong composing one image or a sequence.
#[derive(Debug, thiserror::Error)]
pub enum ComposeError {
    #[error("cannot read {path}")]
    Read {
        path: PathBuf,
        #[source]
        cause: glassdb_io::InputError,
    },
    /// A pass that is not a PNG or EXR this reader can decode (the source's class says whether
    /// it is corrupt, unsupported or too large).
    #[error("{path}")]
    Decode {
        path: PathBuf,
        #[source]
        source: glassdb_image::ImageError,
    },
    #[error(transparent)]
    Mask(#[from] glassdb_mask::MaskError),
    #[error(transparent)]
    Registry(#[from] glassdb_registry::RegistryError),
    /// A pass's colour tag names a space that cannot be composited (data, non-linear, unknown).
    #[error("{path}: {what} is {why}")]
    UnsupportedPassSpace {
        path: PathBuf,
        what: String,
        why: String,
    },
    /// A pass's two colour tags name different spaces.
    #[error(
        "{path}: colorInteropID \"{interop_id}\" and chromaticities {chromaticities:?} name different spaces"
    )]
    ConflictingColourTags {
        path: PathBuf,
        interop_id: String,
        chromaticities: [f32; 8],
    },
    /// The passes of one frame are in different colour spaces.
    #[error(
        "{a} is in {a_space} but {b} is in {b_space}: the passes of a frame must share one space"
    )]
    PassSpacesDisagree {
        a: PathBuf,
        a_space: String,
        b: PathBuf,
        b_space: String,
    },
    /// The registry has no table for the passes' space.
    #[error(
        "{trans} is in {space}, but {registry} has no table in {space_name} (it holds: {})",
        have.join(", ")
    )]
    NoTableForSpace {
        trans: PathBuf,
        space: String,
        space_name: &'static str,
        registry: String,
        have: Vec<String>,
    },
    /// No R, G, B channel triple in an EXR pass.
    #[error(
        "{path} has no R, G, B channels (it has: {}){}",
        available.join(", "),
        if available.iter().any(|c| c == "Y" || c.ends_with(".Y")) {
            ": luminance (Y) and luminance/chroma (Y, RY, BY) images are not composited; convert it to RGB"
        } else {
            ""
        }
    )]
    NoRgb {
        path: PathBuf,
        available: Vec<String>,
    },
    /// Several RGB layers and none chosen.
    #[error("{path} has several RGB layers ({}); choose one", candidates.join(", "))]
    AmbiguousLayer {
        path: PathBuf,
        candidates: Vec<String>,
    },
    #[error("{path} has no RGB layer {layer:?} (it has: {})", candidates.join(", "))]
    LayerNotFound {
        path: PathBuf,
        layer: String,
        candidates: Vec<String>,
    },
    #[error("{path}: the layer's R, G, B channels lie in different parts of the file")]
    SplitLayer { path: PathBuf },
    /// Two inputs of different sizes.
    #[error("{a} is {}×{} but {b} is {}×{}: all passes and the mask must have the same size", a_size.0, a_size.1, b_size.0, b_size.1)]
    SizeMismatch {
        a: PathBuf,
        a_size: (u32, u32),
        b: PathBuf,
        b_size: (u32, u32),
    },
    /// Two inputs whose frames (display windows) differ: they are not images of one frame.
    #[error(
        "{a} frames the display window {a_window} but {b} frames {b_window}: every pass and the mask must be images of the same frame (their data windows may differ)"
    )]
    DisplayWindowMismatch {
        a: PathBuf,
        a_window: glassdb_image::PixelWindow,
        b: PathBuf,
        b_window: glassdb_image::PixelWindow,
    },
    /// Several reflection passes, but the mask does not say which plane each pixel is on.
    #[error(
        "mask {mask} stores no plane per pixel, but {passes} reflection passes were given: every glass pixel would take the first pass"
    )]
    MaskWithoutPlanes { mask: PathBuf, passes: usize },
    /// Glass pixels of a plane that its reflection pass (cropped) does not cover.
    #[error(
        "{pixels} glass pixels of plane {plane} lie outside its reflection pass {pass} (data window {pass_window}); those pixels span {bounds}"
    )]
    GlassOutsidePass {
        plane: usize,
        pass: PathBuf,
        pixels: u64,
        pass_window: glassdb_image::PixelWindow,
        bounds: glassdb_image::PixelWindow,
    },
    /// The transmission file's other channels could not be read to be carried over.
    #[error("cannot carry over the other channels of {path}")]
    KeepChannels {
        path: PathBuf,
        #[source]
        source: glassdb_image::ImageError,
    },
    /// An output layer name EXR cannot hold.
    #[error("{name:?} cannot be an EXR layer name (Latin-1 text, not empty, no dot at either end)")]
    BadLayerName { name: String },
    /// Ids in the mask that the registry does not have.
    #[error(
        "mask {mask} has glass ids with no registry entry in {registry}: {}{}",
        list_counts(ids),
        if *none_known { NONE_KNOWN } else { "" }
    )]
    UnknownIds {
        mask: PathBuf,
        registry: String,
        ids: Vec<(u16, u64)>,
        /// No id of the mask is in the registry (often a mask saved through a colour transform).
        none_known: bool,
    },
    /// A `planes.json` describing another number of planes than the reflection passes given.
    #[error(
        "{planes_file} describes {planes} glass plane(s) but {passes} reflection pass(es) were given: one pass per plane, in the file's order"
    )]
    PlaneCountMismatch {
        planes_file: PathBuf,
        planes: usize,
        passes: usize,
    },
    /// Glass pixels on a plane that has no reflection pass.
    #[error(
        "mask {mask} has {pixels} glass pixels on plane {plane}, but only {passes} reflection pass(es) were given (the k-th pass is plane k)"
    )]
    PlaneWithoutPass {
        mask: PathBuf,
        plane: u16,
        pixels: u64,
        passes: usize,
    },
    /// A reflection file with plane layers (`plane0`, `plane1`, …) that are not numbered 0…N−1.
    #[error("{path}: {problem}; its plane layers: {}", layers.join(", "))]
    PlaneLayers {
        path: PathBuf,
        problem: String,
        layers: Vec<String>,
    },
    /// A compose job without any reflection pass.
    #[error("at least one reflection pass is needed")]
    NoReflectionPass,
    /// An image whose width or height does not fit the pixel buffers.
    #[error("{path}: image too large")]
    TooLarge { path: PathBuf },
    /// An EXR compression name that is not one of OpenEXR's.
    #[error("unknown EXR compression {name:?} (choose one of: {})", known.join(", "))]
    UnknownCompression {
        name: String,
        known: Vec<&'static str>,
    },
    /// A zip level given for a compression that is not zip or zips.
    #[error("a zip level applies to zip and zips output, not {compression}")]
    ZipLevelNotApplicable { compression: &'static str },
    #[error("zip level {level} is out of range (0–9)")]
    ZipLevelOutOfRange { level: u32 },
    /// A `planes.json` could not be read or is not a valid planes file.
    #[error(transparent)]
    PlanesFile(#[from] glassdb_scene::SceneError),
    #[error("cannot tell the output format of {path}: use a .exr or .png extension")]
    OutputExtension { path: PathBuf },
    #[error("cannot encode {path}")]
    Encode {
        path: PathBuf,
        #[source]
        source: glassdb_image::ImageError,
    },
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
    /// The frames report could not be encoded as JSON.
    #[error("cannot encode the frames report {path}")]
    EncodeReport {
        path: PathBuf,
        #[source]
        source: serde_json::Error,
    },
    #[error(transparent)]
    Kernel(#[from] crate::kernel::KernelShapeError),
    /// A frame list that does not parse or is out of range.
    #[error("frame list {spec:?}: {why} (e.g. 1-240 or 1,5,10-20)")]
    FrameList { spec: String, why: String },
    /// A sequence path without the `####` that the frame number replaces.
    #[error("{path} has no #### for the frame number")]
    NoFramePattern { path: PathBuf },
    /// Several frames into one output file.
    #[error(
        "the output {path} has no #### for the frame number, so every frame would overwrite it"
    )]
    OutputWithoutFramePattern { path: PathBuf },
    /// A `.cube` line that cannot be read (docs/colour.md).
    #[error("{path}, line {line}: {problem} (line: {text:?})")]
    CubeSyntax {
        path: PathBuf,
        line: usize,
        text: String,
        problem: String,
    },
    /// A `.cube` file whose header and tables do not agree, or that is no LUT at all.
    #[error("{path}: {problem}")]
    CubeInvalid { path: PathBuf, problem: String },
    /// A `.cube` file too large to be a LUT this reader accepts (checked before reading).
    #[error(
        "{path} is {bytes} bytes; a .cube file of at most {max} bytes is read (LUT_3D_SIZE ≤ 129)"
    )]
    CubeTooLarge { path: PathBuf, bytes: u64, max: u64 },
    /// A frame whose estimated memory (from the inputs' headers) is over the limit.
    #[error(
        "compositing {trans} would hold about {} at once, over the memory limit of {}; the largest shares: {}",
        crate::memory::format_bytes(*estimate),
        crate::memory::format_bytes(*limit),
        list_items(items)
    )]
    MemoryLimit {
        trans: PathBuf,
        estimate: u64,
        limit: u64,
        /// The shares, largest first.
        items: Vec<crate::memory::MemoryItem>,
        /// Bytes of the transmission file's other channels carried over.
        carried: u64,
    },
    /// A view transform asked of an EXR output, which stays scene-linear.
    #[error(
        "a view transform applies to PNG output only, but {path} is EXR, which stays scene-linear"
    )]
    ViewOnExr { path: PathBuf },
}

impl ComposeError {
    /// The image-level class of a decoding or encoding failure, of a pass or of the mask
    /// (`None` for the compositor's own errors).
    pub fn image_error_kind(&self) -> Option<glassdb_image::ImageErrorKind> {
        match self {
            ComposeError::Decode { source, .. }
            | ComposeError::Encode { source, .. }
            | ComposeError::KeepChannels { source, .. } => Some(source.kind()),
            ComposeError::Mask(mask) => mask.image_error_kind(),
            _ => None,
        }
    }
}

/// The shared frame helpers' errors keep compose's own variants (and their hints).
impl From<glassdb_io::FrameError> for ComposeError {
    fn from(e: glassdb_io::FrameError) -> Self {
        match e {
            glassdb_io::FrameError::List { spec, why } => ComposeError::FrameList { spec, why },
            glassdb_io::FrameError::NoPattern { path } => ComposeError::NoFramePattern { path },
        }
    }
}

/// Ids listed in full in the unknown-ids message; the rest are counted.
const LISTED_IDS: usize = 10;

/// Said when none of the mask's ids is in the registry.
const NONE_KNOWN: &str = "; none of the mask's ids is in the registry: if the mask was saved \
    through a colour transform (sRGB or gamma encoding), its values are no longer the ids that \
    were written; save it as raw data";

fn list_counts(ids: &[(u16, u64)]) -> String {
    let mut listed: Vec<String> = ids
        .iter()
        .take(LISTED_IDS)
        .map(|(id, n)| format!("id {id} ({n} pixels)"))
        .collect();
    if ids.len() > LISTED_IDS {
        let rest = &ids[LISTED_IDS..];
        let pixels: u64 = rest.iter().map(|(_, n)| n).sum();
        listed.push(format!("and {} more id(s) ({pixels} pixels)", rest.len()));
    }
    listed.join(", ")
}

/// Memory shares listed in full in the memory-limit message; the rest are counted.
const LISTED_ITEMS: usize = 3;

fn list_items(items: &[crate::memory::MemoryItem]) -> String {
    let mut listed: Vec<String> = items
        .iter()
        .take(LISTED_ITEMS)
        .map(|i| format!("{} {}", i.what, crate::memory::format_bytes(i.bytes)))
        .collect();
    if items.len() > LISTED_ITEMS {
        let rest: u64 = items[LISTED_ITEMS..]
            .iter()
            .map(|i| i.bytes)
            .fold(0, u64::saturating_add);
        listed.push(format!(
            "and {} more ({})",
            items.len() - LISTED_ITEMS,
            crate::memory::format_bytes(rest)
        ));
    }
    listed.join(", ")
}
