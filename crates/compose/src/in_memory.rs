//! Frames held in memory: a host application's arrays (the Python package, a compositor's
//! plug-in) composited with the same table choice, the same checks of ids and planes and the
//! same kernel as a frame read from files (`compose_frame`), with no file read or written. The
//! passes cover the same pixels as the mask (the frame); the result is the transmission pass's
//! planes composited in place, the samples `compose` writes to a float EXR.

use std::collections::BTreeMap;
use std::path::Path;

use glassdb_colour::RgbSpace;
use glassdb_image::PixelWindow;
use glassdb_mask::MaskImage;

use crate::colour::{ChosenTable, PassSpace, RegistryLuts, SpaceSource};
use crate::kernel::KernelCounts;
use crate::{ComposeError, ComposeSettings, composite, decode};

/// One frame in memory: planes of `mask.width × mask.height` samples, row-major, row 0 at the
/// top, linear and premultiplied as `glassdb_pass` decodes a pass.
#[derive(Debug, Clone)]
pub struct MemoryFrame {
    /// The transmission pass's R, G, B planes (composited in place).
    pub trans: [Vec<f32>; 3],
    /// The reflection passes' R, G, B planes; the k-th belongs to plane k of the mask.
    pub refl: Vec<[Vec<f32>; 3]>,
    /// The id + cos θ mask.
    pub mask: MaskImage,
    /// The passes' linear RGB space; `None`: untagged (linear Rec.709, as an untagged file).
    pub space: Option<RgbSpace>,
}

/// What [`compose_in_memory`] labels the arrays by in its messages (there are no files).
#[derive(Debug, Clone)]
pub struct MemoryLabels {
    /// The transmission pass.
    pub trans: String,
    /// The mask.
    pub mask: String,
}

/// The composite of a [`MemoryFrame`] and what its report says.
#[derive(Debug, Clone)]
pub struct MemoryComposite {
    /// The composite's R, G, B planes (the transmission pass's, composited).
    pub rgb: [Vec<f32>; 3],
    /// The passes' space and how it was known.
    pub space: PassSpace,
    /// The registry table composited with.
    pub table: ChosenTable,
    /// Glass pixels per id (id 0 not counted).
    pub id_counts: BTreeMap<u16, u64>,
    /// What the kernel counted.
    pub counts: KernelCounts,
}

/// Composites a frame held in memory as [`crate::compose_frame`] composites one read from
/// files: the registry table for the passes' space (`luts`), ids and planes checked as
/// `settings.decode` says (unknown ids, a plane without a reflection pass), each plane with its
/// side from `settings.plane_sides`, then the kernel in place. The reflection passes hold the
/// whole frame, so no glass lies outside them. There are no pane-group passes: a unit (glass
/// of more than one pane group) is refused as `compose` refuses one without its group passes
/// ([`crate::ComposeError::GroupWithoutPass`]), unless `settings.decode.max_groups` is 1
/// (`--surfaces 1`: its plane's pass takes every pane group's share).
pub fn compose_in_memory(
    frame: MemoryFrame,
    settings: &ComposeSettings,
    luts: &RegistryLuts,
    labels: &MemoryLabels,
) -> Result<MemoryComposite, ComposeError> {
    let MemoryFrame {
        trans,
        refl,
        mask,
        space,
    } = frame;
    compose_planes(trans, &refl, &mask, space, settings, luts, labels)
}

/// One light group of a frame held in memory: its passes (as [`MemoryFrame`]'s) and the
/// tables of its light.
#[derive(Debug)]
pub struct MemoryGroup<'a> {
    /// The tables of the group's light.
    pub luts: &'a RegistryLuts,
    /// The group's transmission pass: R, G, B planes.
    pub trans: [Vec<f32>; 3],
    /// The group's reflection passes, one per plane of the mask.
    pub refl: Vec<[Vec<f32>; 3]>,
}

/// Composites a frame held in memory split into light groups as [`crate::compose_light_groups`]
/// composites one read from files: each group composited alone with its light's tables
/// ([`compose_in_memory`]), in turn (a group's planes are taken from `groups` when its turn
/// comes), and the groups summed in their order, `Σ_g (trans_g·t_g + refl_g·r_g)`. The counts
/// are the first group's. An error when `groups` is empty.
pub fn compose_light_groups_in_memory<'a>(
    groups: impl IntoIterator<Item = MemoryGroup<'a>>,
    mask: &MaskImage,
    space: Option<RgbSpace>,
    settings: &ComposeSettings,
    labels: &MemoryLabels,
) -> Result<MemoryComposite, ComposeError> {
    let mut sum: Option<MemoryComposite> = None;
    for group in groups {
        let one = compose_planes(
            group.trans,
            &group.refl,
            mask,
            space,
            settings,
            group.luts,
            labels,
        )?;
        match &mut sum {
            None => sum = Some(one),
            Some(total) => crate::light_groups::add_group_composite(&mut total.rgb, &one.rgb),
        }
    }
    sum.ok_or_else(|| ComposeError::LightGroupList("none named".into()))
}

/// [`compose_in_memory`] of a frame's parts.
fn compose_planes(
    mut trans: [Vec<f32>; 3],
    refl: &[[Vec<f32>; 3]],
    mask: &MaskImage,
    space: Option<RgbSpace>,
    settings: &ComposeSettings,
    luts: &RegistryLuts,
    labels: &MemoryLabels,
) -> Result<MemoryComposite, ComposeError> {
    if refl.is_empty() {
        return Err(ComposeError::NoReflectionPass);
    }
    let space = match space {
        Some(space) => PassSpace {
            space,
            source: SpaceSource::Declared,
        },
        None => PassSpace {
            space: RgbSpace::Srgb,
            source: SpaceSource::Untagged,
        },
    };
    let (table, lut) = luts.for_space(
        &space,
        Path::new(&labels.trans),
        &settings.decode.registry_label,
    )?;
    let id_counts = mask.id_pixel_counts();
    decode::check_inputs(
        Path::new(&labels.mask),
        &settings.decode,
        lut,
        refl.len(),
        mask,
        &id_counts,
    )?;
    let whole = PixelWindow::at_origin(mask.width as usize, mask.height as usize);
    // There are no pane-group passes in memory: a unit is refused as `compose` refuses one
    // without its --refl-group passes, unless `max_groups` (`--surfaces 1`) folds its deeper
    // groups into the plane's pass.
    let files = crate::FrameFiles {
        refl: (0..refl.len())
            .map(|k| format!("refl[{k}]").into())
            .collect(),
        groups: Vec::new(),
        trans: labels.trans.clone().into(),
        mask: labels.mask.clone().into(),
    };
    crate::pane_groups::check_group_passes(&files, &settings.decode, lut, mask, &[], &[], &whole)?;
    let [r, g, b] = &mut trans;
    let counts = composite::run_kernel(
        [r, g, b],
        refl.iter().map(|p| (p, whole)),
        &[],
        mask,
        lut,
        settings,
    )?;
    Ok(MemoryComposite {
        rgb: trans,
        space,
        table,
        id_counts,
        counts,
    })
}

/// Pixels per parallel task of the layout conversions.
const LAYOUT_CHUNK: usize = 1 << 14;

/// Interleaved samples (`channels` per pixel: R, G, B, then A when 4; row-major, as a host's
/// (H, W, C) array holds them) as the R, G, B planes the compositor works on, and the alpha
/// plane when there is one. `samples` holds whole pixels (the caller checks its length).
pub fn planes_from_interleaved(
    samples: &[f32],
    channels: usize,
) -> ([Vec<f32>; 3], Option<Vec<f32>>) {
    use rayon::prelude::*;
    let pixels = samples.len() / channels.max(1);
    let mut planes: [Vec<f32>; 4] = std::array::from_fn(|c| {
        if c < channels.min(4) {
            vec![0.0; pixels]
        } else {
            Vec::new()
        }
    });
    let [r, g, b, a] = &mut planes;
    let with_alpha = channels >= 4;
    r.par_chunks_mut(LAYOUT_CHUNK)
        .zip(g.par_chunks_mut(LAYOUT_CHUNK))
        .zip(b.par_chunks_mut(LAYOUT_CHUNK))
        .zip(samples.par_chunks(LAYOUT_CHUNK * channels))
        .for_each(|(((r, g), b), src)| {
            for (i, px) in src.chunks_exact(channels).enumerate() {
                r[i] = px[0];
                g[i] = px[1];
                b[i] = px[2];
            }
        });
    if with_alpha {
        a.par_chunks_mut(LAYOUT_CHUNK)
            .zip(samples.par_chunks(LAYOUT_CHUNK * channels))
            .for_each(|(a, src)| {
                for (v, px) in a.iter_mut().zip(src.chunks_exact(channels)) {
                    *v = px[3];
                }
            });
    }
    let [r, g, b, a] = planes;
    ([r, g, b], with_alpha.then_some(a))
}

/// R, G, B planes (and alpha) interleaved into (H, W, C) samples, C = 3 or 4 with alpha: the
/// layout [`planes_from_interleaved`] reads.
pub fn interleave(rgb: &[Vec<f32>; 3], alpha: Option<&[f32]>) -> Vec<f32> {
    use rayon::prelude::*;
    let channels = if alpha.is_some() { 4 } else { 3 };
    let pixels = rgb[0].len();
    let mut out = vec![0.0f32; pixels * channels];
    out.par_chunks_mut(LAYOUT_CHUNK * channels)
        .enumerate()
        .for_each(|(k, dst)| {
            let start = k * LAYOUT_CHUNK;
            for (i, px) in dst.chunks_exact_mut(channels).enumerate() {
                let j = start + i;
                px[0] = rgb[0][j];
                px[1] = rgb[1][j];
                px[2] = rgb[2][j];
                if let Some(a) = alpha {
                    px[3] = a[j];
                }
            }
        });
    out
}
