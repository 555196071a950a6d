//! A frame's light parts on the page (issue 28, docs/viewer.md "Relit swap"): each part's
//! passes, decoded and placed as `compose` decodes them, for the GPU, and what the page needs to
//! compute each part's factor for any product chosen ([`PagePart`]): the part's source, the
//! aperture's glass id and plane, and for the sun its cos θ and the face it enters. A product
//! change then rescales the room's light with a factor per part (no decode, no upload of
//! passes), and the page's per-part exposure sliders (light mixing, issue 29) are the same
//! factors.

use glassdb_compose::colour::RegistryLuts;
use glassdb_compose::light_parts::{LightPart, LightSource};
use glassdb_compose::memory::MemoryBudget;
use glassdb_compose::{
    ApertureGlass, ComposeError, DecodeSettings, DecodeTarget, FactorKind, FrameFiles, InputLayers,
    decode_frame, part_factors, part_passes,
};
use glassdb_pass::LightMix;
use glassdb_side::Side;
use serde::Serialize;

use crate::ViewError;
use crate::data;
use crate::scene::{FrameData, ViewerFrame};

/// One light part as the page computes its factor: `kind` `unglazed` (1), `sun` (t at
/// `cos_theta` seen from `side`, from the chosen product's table) or `diffuse` (the chosen
/// product's `t_dif`) of the product chosen for glass `id`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PagePart {
    /// The part's light group.
    pub group: String,
    /// `sun`, `sky` or `other`.
    pub source: &'static str,
    /// `unglazed`, `sun` or `diffuse`.
    pub kind: &'static str,
    /// The aperture's glass id.
    pub id: Option<u16>,
    /// The aperture's plane.
    pub plane: Option<usize>,
    /// The sun's `|n·d|`.
    pub cos_theta: Option<f64>,
    /// The face the sunlight enters.
    pub side: Option<Side>,
    /// Its factor with the glass of the registry (the page's starting products).
    pub factor: [f32; 3],
}

/// `data` with the light parts of `frame` (none: as it is): each part's passes decoded alone
/// (each pass read as that part's layer, [`LightMix`] of one part, as
/// [`glassdb_compose::compose_light_parts`] reads them; [`glassdb_compose::part_passes`] checks
/// them against the record), one part at a time, and its [`PagePart`]. A part's passes are the
/// transmission, each pixel's plane's reflection and, where `data` composites pane groups apart
/// (`PageFrame::groups`), its groups' ([`data::part_bytes`]).
pub fn with_parts(
    mut data: FrameData,
    frame: &ViewerFrame,
    settings: &DecodeSettings,
    luts: &RegistryLuts,
    budget: &MemoryBudget,
) -> Result<FrameData, ViewError> {
    let Some(parts) = &frame.light_parts else {
        return Ok(data);
    };
    parts.check().map_err(|p| ComposeError::LightPartsRecord {
        record: format!("frame {}", frame.label),
        problem: p.0,
    })?;
    let names: Vec<&str> = parts.parts.iter().map(|p| p.group.as_str()).collect();
    part_passes(&frame.files, &names, settings.pass.max_pixels)?;
    // The pane groups' passes the page composites apart, and no others.
    let groups_apart = !data.info.groups.is_empty();
    let files = FrameFiles {
        groups: if groups_apart {
            frame.files.groups.clone()
        } else {
            Vec::new()
        },
        ..frame.files.clone()
    };
    let mut bytes = Vec::new();
    let mut page = Vec::new();
    for name in names {
        let mut one = settings.clone();
        one.layers = InputLayers::default();
        one.pass.light_mix = Some(LightMix {
            weights: vec![(name.to_string(), [1.0; 3])],
        });
        let decoded = decode_frame(&files, &one, luts, budget, &DecodeTarget::display())?;
        if page.is_empty() {
            let glass = ApertureGlass {
                lut: decoded.lut,
                table: luts.table(decoded.table.basis),
                registry: &settings.registry_label,
            };
            let refs: Vec<&LightPart> = parts.parts.iter().collect();
            let factors = part_factors(&refs, files.refl.len(), &files.mask, &glass)?;
            page = parts
                .parts
                .iter()
                .zip(factors)
                .map(|(part, f)| page_part(part, f.kind, f.factor))
                .collect();
        }
        bytes.extend(data::part_bytes(&decoded, groups_apart));
    }
    data.parts = bytes;
    data.info.parts = page;
    Ok(data)
}

fn page_part(part: &LightPart, kind: FactorKind, factor: [f32; 3]) -> PagePart {
    let source = match part.source {
        LightSource::Sun { .. } => "sun",
        LightSource::Sky => "sky",
        LightSource::Other => "other",
    };
    let (kind, id, plane, cos_theta, side) = match kind {
        FactorKind::Unglazed => ("unglazed", None, None, None, None),
        FactorKind::Sun {
            id,
            plane,
            cos_theta,
            side,
        } => ("sun", Some(id), Some(plane), Some(cos_theta), Some(side)),
        FactorKind::Diffuse { id, plane } => ("diffuse", Some(id), Some(plane), None, None),
    };
    PagePart {
        group: part.group.clone(),
        source,
        kind,
        id,
        plane,
        cos_theta,
        side,
        factor,
    }
}
