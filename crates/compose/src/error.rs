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
        cause: std::io::Error,
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
    /// No R, G, B channel triple in an EXR pass.
    #[error("{path} has no R, G, B channels (it has: {})", available.join(", "))]
    NoRgb {
        path: PathBuf,
        available: Vec<String>,
    },
    /// Several RGB layers and none chosen.
    #[error("{path} has several RGB layers ({}); choose one with --layer", candidates.join(", "))]
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
    /// Ids in the mask that the registry does not have.
    #[error(
        "mask {mask} has glass ids with no registry entry in {registry}: {} (add them to the registry, or pass --unknown passthrough to leave those pixels as the transmission pass)",
        list_counts(ids)
    )]
    UnknownIds {
        mask: PathBuf,
        registry: String,
        ids: Vec<(u16, u64)>,
    },
    /// Glass pixels on a plane that has no reflection pass.
    #[error(
        "mask {mask} has {pixels} glass pixels on plane {plane}, but only {passes} reflection pass(es) were given (--refl repeats: the k-th is plane k)"
    )]
    PlaneWithoutPass {
        mask: PathBuf,
        plane: u16,
        pixels: u64,
        passes: usize,
    },
    #[error("{0}")]
    BadOption(String),
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
    #[error(transparent)]
    Kernel(#[from] crate::kernel::KernelShapeError),
    #[error("{0}")]
    Sequence(String),
}

impl ComposeError {
    /// The image-level class of a decoding or encoding failure, of a pass or of the mask
    /// (`None` for the compositor's own errors).
    pub fn image_error_kind(&self) -> Option<glassdb_image::ImageErrorKind> {
        match self {
            ComposeError::Decode { source, .. } | ComposeError::Encode { source, .. } => {
                Some(source.kind())
            }
            ComposeError::Mask(mask) => mask.image_error_kind(),
            _ => None,
        }
    }
}

fn list_counts(ids: &[(u16, u64)]) -> String {
    ids.iter()
        .map(|(id, n)| format!("id {id} ({n} pixels)"))
        .collect::<Vec<_>>()
        .join(", ")
}
