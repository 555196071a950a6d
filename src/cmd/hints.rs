//! The command-line hints: libraries say what is wrong, only the binary knows which flag or
//! command fixes it. [`hints`] walks an error's whole cause chain and matches the library
//! error variants that one flag or command answers; [`super::finish`] prints each as `hint:`.

use glassdb_colour::CubeError;
use glassdb_compose::ComposeError;
use glassdb_encode::EncodeError;
use glassdb_fit::{FileContent, FitError};
use glassdb_mask::MaskError;
use glassdb_pass::PassError;
use glassdb_plot::PlotError;
use glassdb_registry::RegistryError;
use glassdb_scene::SceneError;
use glassdb_sequence::SequenceError;
use glassdb_spectral::SpectralError;
use glassdb_view::ViewError;

/// The hints for every error in `err`'s cause chain, outermost first, without repeats.
pub fn hints(err: &anyhow::Error) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for cause in err.chain() {
        if let Some(h) = hint(cause)
            && !out.contains(&h)
        {
            out.push(h);
        }
    }
    out
}

/// The kind of `err` (`glassdb_io::ErrorKind`): that of the first glassdb error in its cause
/// chain, outermost first (each library's error knows the kind of what it wraps); `None` when
/// no glassdb library made it (an argument the binary refused).
pub fn kind(err: &anyhow::Error) -> Option<glassdb_io::ErrorKind> {
    err.chain().find_map(error_kind)
}

/// The kind of one cause, if a glassdb library made it.
fn error_kind(cause: &(dyn std::error::Error + 'static)) -> Option<glassdb_io::ErrorKind> {
    macro_rules! kind_of {
        ($($t:ty),* $(,)?) => {
            $(if let Some(e) = cause.downcast_ref::<$t>() {
                return Some(e.kind());
            })*
        };
    }
    kind_of!(
        FitError,
        SpectralError,
        RegistryError,
        MaskError,
        SceneError,
        ComposeError,
        PassError,
        EncodeError,
        CubeError,
        SequenceError,
        ViewError,
        PlotError,
        glassdb_report::ReportError,
        glassdb_blender::BlenderError,
        glassdb_image::ImageError,
        glassdb_io::InputError,
        glassdb_io::OutputError,
        glassdb_io::FrameError,
    );
    None
}

/// The error message followed by its hints in parentheses, on one line (for reports that list
/// several failures).
pub fn with_hints(err: &anyhow::Error) -> String {
    let hints = hints(err);
    if hints.is_empty() {
        format!("{err:#}")
    } else {
        format!("{err:#} ({})", hints.join("; "))
    }
}

fn hint(cause: &(dyn std::error::Error + 'static)) -> Option<String> {
    if let Some(e) = cause.downcast_ref::<FitError>() {
        return fit_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<SpectralError>() {
        return spectral_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<RegistryError>() {
        return registry_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<MaskError>() {
        return mask_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<SceneError>() {
        return scene_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<ComposeError>() {
        return compose_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<PassError>() {
        return pass_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<EncodeError>() {
        return encode_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<CubeError>() {
        return cube_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<SequenceError>() {
        return sequence_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<ViewError>() {
        return view_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<PlotError>() {
        return plot_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<glassdb_blender::BlenderError>() {
        return blender_hint(e);
    }
    if let Some(e) = cause.downcast_ref::<glassdb_io::FrameError>() {
        return frame_hint(e);
    }
    None
}

/// Plot errors wrap the readers' errors transparently (their `source` skips the wrapped error
/// itself), so the wrapped error is matched here.
fn plot_hint(e: &PlotError) -> Option<String> {
    match e {
        PlotError::Fit(e) => fit_hint(e),
        PlotError::Spectral(e) => spectral_hint(e),
        PlotError::Registry(e) => registry_hint(e),
        PlotError::Mask(e) => mask_hint(e),
        _ => None,
    }
}

fn fit_hint(e: &FitError) -> Option<String> {
    const FIT_FILES: &str = "`glassdb eval` reads the fit files that `glassdb fit -o` writes";
    match e {
        FitError::AboveOneInFractions { .. } => {
            Some("if the table is in percent, pass --percent".into())
        }
        FitError::OtherFile {
            kind: FileContent::Registry,
            ..
        } => Some(format!(
            "a registry is read by `glassdb registry show`, `glassdb registry check`, \
             `glassdb plot registry` and `glassdb compose --registry`; {FIT_FILES}"
        )),
        FitError::OtherFile {
            kind: FileContent::Planes,
            ..
        } => Some(format!(
            "a planes file is read by `glassdb compose --planes` and `glassdb mask --planes`; \
             {FIT_FILES}"
        )),
        _ => super::fit::hint(e),
    }
}

fn spectral_hint(e: &SpectralError) -> Option<String> {
    match e {
        SpectralError::AboveOneInFractions { .. } => {
            Some("if the file is in percent, pass --percent".into())
        }
        SpectralError::FractionsReadAsPercent { .. } => Some("drop --percent".into()),
        SpectralError::PartialCoverage { .. } => {
            Some("pass --extrapolate to hold the end values constant outside the data".into())
        }
        _ => None,
    }
}

fn registry_hint(e: &RegistryError) -> Option<String> {
    match e {
        RegistryError::FitTolerance { max, .. } => {
            Some(format!("give --tol a value above 0 and at most {max}"))
        }
        RegistryError::ToleranceTooLarge { source_name, .. } => Some(format!(
            "rebuild it from its catalog: glassdb registry build CATALOG.toml -o {source_name}"
        )),
        RegistryError::SchemaVersion { source_name, .. } => Some(format!(
            "rebuild it: glassdb registry build CATALOG.toml -o {source_name}"
        )),
        _ => None,
    }
}

fn mask_hint(e: &MaskError) -> Option<String> {
    match e {
        MaskError::BinaryMaskNotPng { .. } => {
            Some("--glass ID reads a binary PNG mask; drop it for an EXR mask".into())
        }
        MaskError::GreyPngWithoutGlassId { .. } => {
            Some("give the glass id of a binary mask with --glass ID".into())
        }
        _ => None,
    }
}

fn scene_hint(e: &SceneError) -> Option<String> {
    match e {
        SceneError::SamplesOutOfRange { .. } => Some("set it with --samples".into()),
        SceneError::MeshOutOfRange { .. } => Some("set it with --mesh".into()),
        SceneError::NoGlassSelected => {
            Some("pass --glass-material PATTERN or --plane a,b,c,d".into())
        }
        SceneError::CameraNeedsFrame { .. } => {
            Some("choose the frames with --frames (e.g. 1-24)".into())
        }
        SceneError::PlaneCountMismatch { .. } => {
            Some("give one --refl per plane of --planes, in its order".into())
        }
        // Transparent wrappers: their `source` skips the wrapped error itself.
        SceneError::Mask(e) => mask_hint(e),
        SceneError::Frame(e) => frame_hint(e),
        _ => None,
    }
}

fn frame_hint(e: &glassdb_io::FrameError) -> Option<String> {
    match e {
        glassdb_io::FrameError::List { .. } => Some("check --frames".into()),
        glassdb_io::FrameError::NoPattern { .. } => None,
    }
}

fn sequence_hint(e: &SequenceError) -> Option<String> {
    match e {
        // Transparent wrappers: their `source` skips the wrapped error itself.
        SequenceError::Compose(e) => compose_hint(e),
        SequenceError::Frame(e) => frame_hint(e),
        _ => None,
    }
}

fn pass_hint(e: &PassError) -> Option<String> {
    match e {
        PassError::AmbiguousLayer { .. } | PassError::LayerNotFound { .. } => Some(
            "choose a layer with FILE.exr:LAYER, --trans-layer / --refl-layer, or --layer for \
             every pass"
                .into(),
        ),
        PassError::KeepChannels { .. } => {
            Some("--keep-channels none writes only the composite".into())
        }
        _ => None,
    }
}

fn encode_hint(e: &EncodeError) -> Option<String> {
    match e {
        EncodeError::BadLayerName { .. } => Some("check --output-layer".into()),
        EncodeError::ViewOnExr { .. } => Some(
            "write a .png (-o NAME.png) to see --view, or drop --view and apply the view to the \
             EXR in your viewer or compositor (OCIO)"
                .into(),
        ),
        EncodeError::ZipLevelNotApplicable { .. } | EncodeError::ZipLevelOutOfRange { .. } => {
            Some("--zip-level sets it".into())
        }
        _ => None,
    }
}

fn cube_hint(e: &CubeError) -> Option<String> {
    match e {
        CubeError::Syntax { .. } | CubeError::Invalid { .. } | CubeError::TooLarge { .. } => Some(
            "--view takes `standard` or a .cube LUT, e.g. baked by ociobakelut --format \
             resolve_cube (docs/colour.md)"
                .into(),
        ),
        CubeError::Read { .. } => None,
    }
}

fn compose_hint(e: &ComposeError) -> Option<String> {
    match e {
        // Transparent wrappers: their `source` skips the wrapped error itself.
        ComposeError::Mask(e) => mask_hint(e),
        ComposeError::Pass(e) => pass_hint(e),
        ComposeError::Encode(e) => encode_hint(e),
        ComposeError::DisplayWindowMismatch { .. } => Some(
            "render every pass and the mask with the same resolution (a render border or crop \
             may change the data window, not the display window)"
                .into(),
        ),
        ComposeError::MaskWithoutPlanes { .. } => Some(format!(
            "name the mask's plane channel with --mask-channels plane=NAME, or give one --refl; \
             {OLD_RUN_MASKS}"
        )),
        ComposeError::GlassOutsidePass { .. } => Some(
            "render the pass over its plane's whole screen rectangle, or choose \
             --outside-pass no-reflection or --outside-pass transmission"
                .into(),
        ),
        ComposeError::UnknownIds { .. } => Some(
            "add them to the registry, or pass --unknown passthrough to leave those pixels as \
             the transmission pass"
                .into(),
        ),
        ComposeError::PlaneWithoutPass { .. } => {
            Some("repeat --refl: the k-th is the pass of plane k".into())
        }
        ComposeError::GroupWithoutPass { plane, group, .. } => Some(format!(
            "give it with --refl-group {plane}.{group}=FILE, or composite one pass per plane with --surfaces 1 (the deeper panes' reflectance added to it, no double image)"
        )),
        ComposeError::GroupPassWithoutPlane { .. } | ComposeError::GroupPassTwice { .. } => Some(
            "--refl-group K.G=FILE: K a plane with its own --refl, G 1 or more, each once".into(),
        ),
        ComposeError::NoReflectionPass => Some("give one with --refl".into()),
        ComposeError::NoTableForGroup { group, .. } => Some(format!(
            "build the registry with a light of each group's name: glassdb registry build \
             CATALOG --light {group}=ILLUMINANT (D65, A, LED-B3, … or an SPD .csv)"
        )),
        ComposeError::GroupWithoutTable { groups, .. } => Some(format!(
            "name every light group of the passes in --light-groups (add {})",
            groups.join(",")
        )),
        ComposeError::GroupWithoutLayer { .. } => Some(
            "--light-groups names the passes' light groups: each must be a layer of every pass"
                .into(),
        ),
        ComposeError::UnsupportedPassSpace { .. } | ComposeError::ConflictingColourTags { .. } => {
            Some(
                "if the pixels are scene-linear RGB, say in which space with --input-space \
                 (srgb, rec2020, acescg, aces2065-1, display-p3, xyz)"
                    .into(),
            )
        }
        ComposeError::PassSpacesDisagree { .. } => Some(
            "render every pass in one working space; if a tag is wrong, --input-space SPACE \
             declares the space of every pass"
                .into(),
        ),
        ComposeError::NoTableForSpace { space_name, .. } => Some(format!(
            "build the registry with that space too: glassdb registry build CATALOG --space \
             srgb,{space_name} -o REGISTRY.json (docs/colour.md); if the passes' tag is wrong, \
             --input-space declares their space"
        )),
        ComposeError::MemoryLimit {
            estimate, carried, ..
        } => {
            // Worth saying when the carried channels are a large share.
            let carried = *carried > estimate / 4;
            Some(format!(
                "if the machine has the memory, raise the limit with --max-memory SIZE (e.g. \
                 --max-memory 16G){}",
                if carried {
                    "; --keep-channels none leaves the other channels out"
                } else {
                    ""
                }
            ))
        }
        _ => None,
    }
}

/// A `glassdb blender render` run whose EXR masks lack the plane channel: made before the masks
/// always stored it (commit 51761fc), which nothing but a new render fixes.
const OLD_RUN_MASKS: &str = "a `glassdb blender render` run whose masks have no plane channel \
     was rendered before the masks always stored it: render it again with glassdb blender render \
     (its masks cannot be repaired by compose)";

fn blender_hint(e: &glassdb_blender::BlenderError) -> Option<String> {
    use glassdb_blender::BlenderError as B;
    Some(match e {
        B::Compose(ComposeError::MaskWithoutPlanes { .. }) => OLD_RUN_MASKS.into(),
        B::NotFound { .. } | B::VersionUnreadable { .. } => {
            "install Blender 3.4 or newer (Debian: apt-get install blender), or give its path \
             with --blender PATH"
                .into()
        }
        B::TooOld { .. } => "give a newer Blender with --blender PATH".into(),
        B::NoBpyModule { .. } => "install it in a Python 3.11 environment (python3.11 -m venv \
             ENV && ENV/bin/pip install bpy==5.0.1) and give ENV/bin/python, or use a Blender \
             executable (--blender PATH)"
            .into(),
        B::TimedOut { .. } => {
            "raise --timeout-s, or render less: --samples, --resolution, --frames".into()
        }
        B::LightGroupWithoutSpectrum { group, .. } => {
            format!("give --light {group}=ILLUMINANT (e.g. D65 for daylight, A for tungsten)")
        }
        B::UnknownLightGroup { .. } => {
            "--light takes the scene's own Cycles light groups (Object/World > Shading > Light \
             Group); a scene without groups is one light and takes no --light"
                .into()
        }
        B::RegistryLacksLight { group, .. } | B::LightMismatch { group, .. } => format!(
            "build the registry with that light (glassdb registry build … --light \
             {group}=ILLUMINANT), or give a registry of one light to composite every group with \
             its table"
        ),
        B::UngroupedEmitters { .. } => {
            "set each emitter's Light Group (Object Properties > Shading), or clear every \
             group to render the scene as one light"
                .into()
        }
        B::UnknownGlass { .. } => {
            "give a registry with that id (--registry), or map the material to another id with \
             --glass"
                .into()
        }
        _ => return None,
    })
}

/// `glassdb view`: its compose errors (the viewer has no --unknown or --outside-pass) and its own.
fn view_hint(e: &ViewError) -> Option<String> {
    match e {
        ViewError::Compose(ComposeError::UnknownIds { .. }) => Some(
            "the viewer swaps products of the registry's glass ids: add the ids to a registry \
             (glassdb registry build) and give it with --registry"
                .into(),
        ),
        ViewError::Compose(ComposeError::GlassOutsidePass { .. }) => Some(
            "the viewer needs every glass pixel inside its plane's reflection pass; render the \
             pass over the whole pane"
                .into(),
        ),
        ViewError::Compose(ComposeError::Pass(
            PassError::AmbiguousLayer { .. } | PassError::LayerNotFound { .. },
        )) => Some("choose a layer with FILE.exr:LAYER or --layer".into()),
        ViewError::Compose(c) => compose_hint(c),
        ViewError::Bind { source, .. } => match source.kind() {
            std::io::ErrorKind::AddrInUse => Some(
                "another program may be listening there; --port 0 picks a free port".into(),
            ),
            std::io::ErrorKind::AddrNotAvailable => Some(
                "--bind takes an address of this machine (127.0.0.1, the default, serves this \
                 machine only)"
                    .into(),
            ),
            std::io::ErrorKind::PermissionDenied => {
                Some("ports below 1024 need privileges; --port 0 picks a free port".into())
            }
            _ => None,
        },
        ViewError::Resolve { .. } => Some(
            "--bind takes an IP address or a name of this machine (127.0.0.1, the default, \
             serves this machine only)"
                .into(),
        ),
        ViewError::ExportFolderInUse { .. } => Some(
            "choose a new or empty folder, or pass --force to write into this one".into(),
        ),
        ViewError::UnknownProduct { .. } | ViewError::AmbiguousProduct { .. } => Some(
            "--glass takes ID:PRODUCT with a product's name, a part only it has, or its registry id"
                .into(),
        ),
        ViewError::MaskKindChanges { .. } => {
            Some("write every frame's mask the same way (8-bit PNG, 16-bit PNG or EXR)".into())
        }
        ViewError::Frame(e) => frame_hint(e),
        ViewError::GlassSpec { .. }
        | ViewError::NoFrames
        | ViewError::NoSuchFrame { .. }
        | ViewError::UnitCatalog(_)
        | ViewError::Unit(_)
        | ViewError::UnitPanicked
        | ViewError::UnitRequest { .. }
        | ViewError::UnknownGlassId { .. }
        | ViewError::ExportDir { .. }
        | ViewError::ExportNotAFolder { .. }
        | ViewError::SessionToken { .. }
        | ViewError::Output(_) => None,
    }
}
