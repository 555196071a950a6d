//! The one error type of the compositor: one variant per failure a user can act on, each
//! naming the file (and pixel, id, plane or frame) involved.

use std::path::PathBuf;

use glassdb_io::ErrorKind;

/// Everything that can go wrong composing one image or a sequence.
#[derive(Debug, thiserror::Error)]
pub enum ComposeError {
    /// A pass could not be read (its own error names the file).
    #[error(transparent)]
    Pass(#[from] glassdb_pass::PassError),
    /// The mask could not be read.
    #[error(transparent)]
    Mask(#[from] glassdb_mask::MaskError),
    /// The output could not be written, or would not be (checked before any work).
    #[error(transparent)]
    Encode(#[from] glassdb_encode::EncodeError),
    /// A pass's colour tag names a space that cannot be composited (data, non-linear, unknown).
    #[error("{path}: {what} is {why}")]
    UnsupportedPassSpace {
        /// The pass.
        path: PathBuf,
        /// The tag and its value.
        what: String,
        /// Why it cannot be composited.
        why: String,
    },
    /// A pass's two colour tags name different spaces.
    #[error(
        "{path}: colorInteropID \"{interop_id}\" and chromaticities {chromaticities:?} name different spaces"
    )]
    ConflictingColourTags {
        /// The pass.
        path: PathBuf,
        /// Its `colorInteropID`.
        interop_id: String,
        /// Its `chromaticities`.
        chromaticities: [f32; 8],
    },
    /// The passes of one frame are in different colour spaces.
    #[error(
        "{a} is in {a_space} but {b} is in {b_space}: the passes of a frame must share one space"
    )]
    PassSpacesDisagree {
        /// The first file (the transmission pass).
        a: PathBuf,
        /// Its space.
        a_space: String,
        /// The file that disagrees.
        b: PathBuf,
        /// Its space.
        b_space: String,
    },
    /// The registry has no table for the passes' space.
    #[error(
        "{trans} is in {space}, but {registry} has no table in {space_name} (it holds: {})",
        have.join(", ")
    )]
    NoTableForSpace {
        /// The transmission pass.
        trans: PathBuf,
        /// The passes' space and how it was known.
        space: String,
        /// glassdb's name of that space.
        space_name: &'static str,
        /// The registry's name.
        registry: String,
        /// The tables it holds.
        have: Vec<String>,
    },
    /// Two inputs of different sizes.
    #[error("{a} is {}×{} but {b} is {}×{}: all passes and the mask must have the same size", a_size.0, a_size.1, b_size.0, b_size.1)]
    SizeMismatch {
        /// The first file (the transmission pass).
        a: PathBuf,
        /// Its size.
        a_size: (u32, u32),
        /// The file that disagrees.
        b: PathBuf,
        /// Its size.
        b_size: (u32, u32),
    },
    /// Two inputs whose frames (display windows) differ: they are not images of one frame.
    #[error(
        "{a} frames the display window {a_window} but {b} frames {b_window}: every pass and the mask must be images of the same frame (their data windows may differ)"
    )]
    DisplayWindowMismatch {
        /// The first file (the transmission pass).
        a: PathBuf,
        /// Its display window.
        a_window: glassdb_image::PixelWindow,
        /// The file that disagrees.
        b: PathBuf,
        /// Its display window.
        b_window: glassdb_image::PixelWindow,
    },
    /// Several reflection passes, but the mask does not say which plane each pixel is on.
    #[error(
        "mask {mask} stores no plane per pixel, but {passes} reflection passes were given: every glass pixel would take the first pass"
    )]
    MaskWithoutPlanes {
        /// The mask.
        mask: PathBuf,
        /// How many reflection passes were given.
        passes: usize,
    },
    /// Glass pixels of a plane that its reflection pass (cropped) does not cover.
    #[error(
        "{pixels} glass pixels of plane {plane} lie outside its reflection pass {pass} (data window {pass_window}); those pixels span {bounds}"
    )]
    GlassOutsidePass {
        /// The plane.
        plane: usize,
        /// Its reflection pass.
        pass: PathBuf,
        /// How many glass pixels.
        pixels: u64,
        /// The pass's data window.
        pass_window: glassdb_image::PixelWindow,
        /// The bounding box of those pixels.
        bounds: glassdb_image::PixelWindow,
    },
    /// Ids in the mask that the registry does not have.
    #[error(
        "mask {mask} has glass ids with no registry entry in {registry}: {}{}",
        list_counts(ids),
        if *none_known { NONE_KNOWN } else { "" }
    )]
    UnknownIds {
        /// The mask.
        mask: PathBuf,
        /// The registry's name.
        registry: String,
        /// The ids and their pixel counts.
        ids: Vec<(u16, u64)>,
        /// No id of the mask is in the registry (often a mask saved through a colour transform).
        none_known: bool,
    },
    /// Glass pixels on a plane that has no reflection pass.
    #[error(
        "mask {mask} has {pixels} glass pixels on plane {plane}, but only {passes} reflection pass(es) were given (the k-th pass is plane k)"
    )]
    PlaneWithoutPass {
        /// The mask.
        mask: PathBuf,
        /// The plane.
        plane: u16,
        /// How many glass pixels.
        pixels: u64,
        /// How many reflection passes were given.
        passes: usize,
    },
    /// A light group composited without a layer in one of the passes.
    #[error(
        "{path} has no layer for light group {group:?} (its light groups: {})",
        if found.is_empty() { "none".to_string() } else { found.join(", ") }
    )]
    GroupWithoutLayer {
        /// The pass.
        path: PathBuf,
        /// The group asked for.
        group: String,
        /// The groups the pass has.
        found: Vec<String>,
    },
    /// Light groups in a pass that no table is given for: leaving them out would lose their
    /// light.
    #[error(
        "{path} has light groups without a table: {} (the groups composited: {})",
        groups.join(", "),
        composited.join(", ")
    )]
    GroupWithoutTable {
        /// The pass.
        path: PathBuf,
        /// Its groups that are not composited.
        groups: Vec<String>,
        /// The groups composited.
        composited: Vec<String>,
    },
    /// A registry with no table under a light group's light.
    #[error("{registry} has no table for light group {group:?} (its lights: {})", lights.join(", "))]
    NoTableForGroup {
        /// The registry's name.
        registry: String,
        /// The group.
        group: String,
        /// The lights it has (`warm (A)`).
        lights: Vec<String>,
    },
    /// A light-parts record that cannot be used (docs/compose.md, "Relit swap").
    #[error("light parts {record}: {problem}")]
    LightPartsRecord {
        /// The record (its path, or what gave it).
        record: String,
        /// What is wrong.
        problem: String,
    },
    /// A light part through an aperture whose glass id the registry has no table for.
    #[error(
        "light part {group:?} came through glass id {id} on plane {plane}, which {registry} does not have"
    )]
    LightPartUnknownId {
        /// The part's group.
        group: String,
        /// The aperture's glass id.
        id: u32,
        /// The aperture's plane.
        plane: usize,
        /// The registry's name.
        registry: String,
    },
    /// A light part with no layer in one of the passes: its light would be lost.
    #[error(
        "{path} has no layer for light part {group:?} (its light groups: {})",
        if found.is_empty() { "none".to_string() } else { found.join(", ") }
    )]
    PartWithoutLayer {
        /// The pass.
        path: PathBuf,
        /// The part's group.
        group: String,
        /// The groups the pass has.
        found: Vec<String>,
    },
    /// Light-group layers of a pass that no light part names: leaving them out would lose
    /// their light, and nothing says which glass they came through.
    #[error(
        "{path} has light-group layers without a light part: {} (the parts: {})",
        groups.join(", "),
        parts.join(", ")
    )]
    LayerWithoutPart {
        /// The pass.
        path: PathBuf,
        /// Its groups no part names.
        groups: Vec<String>,
        /// The parts' groups.
        parts: Vec<String>,
    },
    /// A light part through an aperture on a plane the frame's mask does not have.
    #[error(
        "light part {group:?} came through plane {plane}, but {mask} has {planes} plane(s) (0 to {})",
        planes.saturating_sub(1)
    )]
    AperturePlaneNotInMask {
        /// The part's group.
        group: String,
        /// The aperture's plane.
        plane: usize,
        /// The mask.
        mask: PathBuf,
        /// How many planes the frame has (its reflection passes).
        planes: usize,
    },
    /// Light groups asked for with none named, or one named twice.
    #[error("light groups: {0}")]
    LightGroupList(String),
    /// A light group's layer of the transmission pass holds other pixels than the first
    /// group's (the frame), so that the groups' composites cannot be summed pixel by pixel.
    #[error(
        "{path}: layer {layer} holds the pixels {window}, but the frame (the first light group's layer) is {frame}: every group's layer must hold the same pixels"
    )]
    GroupWindowMismatch {
        /// The transmission pass.
        path: PathBuf,
        /// The group's layer.
        layer: String,
        /// Its data window.
        window: glassdb_image::PixelWindow,
        /// The frame's data window.
        frame: glassdb_image::PixelWindow,
    },
    /// Each group's composite kept as a layer of a PNG output, which has none.
    #[error("{output}: each light group's composite is kept as a layer of an EXR output only")]
    KeepGroupsNotExr {
        /// The output.
        output: PathBuf,
    },
    /// A unit on a plane without the reflection pass of one of its pane groups.
    #[error(
        "mask {mask} has {pixels} pixels of glass {id} (a unit of {groups} pane groups) on plane {plane}, but no reflection pass of its pane group {group} was given: the scene mirrored about that group's mid-plane (a file refl_{plane}_{group}, or a layer plane{plane}.group{group} of a multi-part file), beside the plane's own pass {}",
        plane_pass.display()
    )]
    GroupWithoutPass {
        /// The mask.
        mask: PathBuf,
        /// The plane.
        plane: u16,
        /// The pane group without a pass (1 or more).
        group: usize,
        /// The unit.
        id: u16,
        /// Its pane groups.
        groups: usize,
        /// Its pixels on the plane.
        pixels: u64,
        /// The plane's own pass.
        plane_pass: PathBuf,
    },
    /// A pane group's pass on a plane without a pass of its own, or numbered 0.
    #[error(
        "{} is given as the reflection pass of pane group {group} of plane {plane}, but {}",
        pass.display(),
        if *group == 0 { "group 0 is the plane's own pass".to_string() } else { format!("only {planes} plane pass(es) were given (planes count from 0)") }
    )]
    GroupPassWithoutPlane {
        /// The pass.
        pass: PathBuf,
        /// Its plane.
        plane: usize,
        /// Its group.
        group: usize,
        /// Plane passes given.
        planes: usize,
    },
    /// Two passes for one pane group of one plane.
    #[error(
        "pane group {group} of plane {plane} is given twice: {} and {}",
        first.display(),
        second.display()
    )]
    GroupPassTwice {
        /// The plane.
        plane: usize,
        /// The group.
        group: usize,
        /// The first pass.
        first: PathBuf,
        /// The second.
        second: PathBuf,
    },
    /// A compose job without any reflection pass.
    #[error("at least one reflection pass is needed")]
    NoReflectionPass,
    /// An output that is one of the inputs.
    #[error(transparent)]
    Output(#[from] glassdb_io::OutputError),
    /// Buffers that do not fit the kernel's frame (a bug: they are placed before).
    #[error(transparent)]
    Kernel(#[from] crate::kernel::KernelShapeError),
    /// A frame whose estimated memory (from the inputs' headers) is over the limit.
    #[error(
        "compositing {trans} would hold about {} at once, over the memory limit of {}; the largest shares: {}",
        crate::memory::format_bytes(*estimate),
        crate::memory::format_bytes(*limit),
        list_items(items)
    )]
    MemoryLimit {
        /// The transmission pass.
        trans: PathBuf,
        /// The estimate, in bytes.
        estimate: u64,
        /// The limit, in bytes.
        limit: u64,
        /// The shares, largest first.
        items: Vec<crate::memory::MemoryItem>,
        /// Bytes of the transmission file's other channels carried over.
        carried: u64,
    },
}

impl ComposeError {
    /// The class of this error: a wrapped error's own class; inputs that do not make one
    /// frame (sizes, windows, ids, planes, colour tags) are invalid; a space glassdb or the
    /// registry has no table for is unsupported; a frame over the memory limit is a limit.
    pub fn kind(&self) -> ErrorKind {
        match self {
            ComposeError::Pass(e) => e.kind(),
            ComposeError::Mask(e) => e.kind(),
            ComposeError::Encode(e) => e.kind(),
            ComposeError::Output(e) => e.kind(),
            ComposeError::Kernel(_) => ErrorKind::Internal,
            ComposeError::MemoryLimit { .. } => ErrorKind::Limits,
            ComposeError::UnsupportedPassSpace { .. } | ComposeError::NoTableForSpace { .. } => {
                ErrorKind::Unsupported
            }
            ComposeError::ConflictingColourTags { .. }
            | ComposeError::PassSpacesDisagree { .. }
            | ComposeError::SizeMismatch { .. }
            | ComposeError::DisplayWindowMismatch { .. }
            | ComposeError::MaskWithoutPlanes { .. }
            | ComposeError::GlassOutsidePass { .. }
            | ComposeError::UnknownIds { .. }
            | ComposeError::PlaneWithoutPass { .. }
            | ComposeError::GroupWithoutLayer { .. }
            | ComposeError::GroupWithoutTable { .. }
            | ComposeError::NoTableForGroup { .. }
            | ComposeError::LightGroupList(_)
            | ComposeError::GroupWindowMismatch { .. }
            | ComposeError::LightPartsRecord { .. }
            | ComposeError::LightPartUnknownId { .. }
            | ComposeError::PartWithoutLayer { .. }
            | ComposeError::LayerWithoutPart { .. }
            | ComposeError::AperturePlaneNotInMask { .. }
            | ComposeError::KeepGroupsNotExr { .. }
            | ComposeError::GroupWithoutPass { .. }
            | ComposeError::GroupPassWithoutPlane { .. }
            | ComposeError::GroupPassTwice { .. }
            | ComposeError::NoReflectionPass => ErrorKind::Invalid,
        }
    }

    /// The image-level class of a decoding or encoding failure, of a pass or of the mask
    /// (`None` for the compositor's own errors).
    pub fn image_error_kind(&self) -> Option<glassdb_image::ImageErrorKind> {
        match self {
            ComposeError::Pass(e) => e.image_error_kind(),
            ComposeError::Encode(glassdb_encode::EncodeError::Encode { source, .. }) => {
                Some(source.kind())
            }
            ComposeError::Mask(mask) => mask.image_error_kind(),
            _ => None,
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
