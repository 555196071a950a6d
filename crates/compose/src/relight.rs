//! The relit swap (issue 28, docs/compose.md "Relit swap"): a frame whose passes keep the
//! light's path apart ([`crate::light_parts`]) composited with the glass applied to the light it
//! passes. Each part's factor, per RGB channel, is what the glass of its aperture lets through
//! ([`part_factors`]): 1 for light that met no glazing, `t(id, θ_sun)` for the sun (cos θ =
//! |n·d_sun|, from the same lookup table the kernel uses for that id), the hemispherical
//! `t_dif(id)` for sky and other light. The composite is linear in the passes, so
//! `Σ_p f_p·(trans_p·t + refl_p·r) = (Σ_p f_p·trans_p)·t + (Σ_p f_p·refl_p)·r`:
//! [`compose_light_parts`] reads each pass once as the weighted sum of its part layers
//! ([`glassdb_pass::LightMix`]), decodes the mask once and composites once per registry light.

use std::path::Path;
use std::time::Instant;

use glassdb_pass::{Carry, LightMix};
use glassdb_registry::{Registry, RegistryTable};
use glassdb_side::Side;

use crate::bands::add_in_bands;
use crate::colour::RegistryLuts;
use crate::composite::Composited;
use crate::light_groups::{GroupPasses, carry_groups, group_passes, read_carried_after_groups};
use crate::light_parts::{LightPart, LightParts, LightSource};
use crate::lut::{FINE_STEPS, GlassLut};
use crate::memory::MemoryBudget;
use crate::{
    ComposeError, ComposeJob, ComposeSettings, FRAME_STAGES, FrameFiles, FrameReport, InputLayers,
    StageTimings,
};

/// How a part's factor was found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FactorKind {
    /// Light that met no glazing: 1.
    Unglazed,
    /// The sun through an aperture: `t(id, θ)` seen from the side the sun is on.
    Sun {
        /// The aperture's glass id.
        id: u16,
        /// The aperture's plane.
        plane: usize,
        /// `|n·d_sun|` with both unit vectors.
        cos_theta: f64,
        /// The face the sunlight enters (the front when `n·d_sun ≥ 0`).
        side: Side,
    },
    /// Sky or other light through an aperture: the hemispherical `t_dif(id)`.
    Diffuse {
        /// The aperture's glass id.
        id: u16,
        /// The aperture's plane.
        plane: usize,
    },
}

/// One light part's factor: what its aperture's glass lets through, per channel.
#[derive(Debug, Clone, PartialEq)]
pub struct PartFactor {
    /// The part's light group.
    pub group: String,
    /// Its R, G, B factors, in the passes' colour space (the chosen table's).
    pub factor: [f32; 3],
    /// How it was found.
    pub kind: FactorKind,
    /// The registry light whose tables composite it (`None`: the default light).
    pub light: Option<String>,
}

/// The glass data a factor needs, for one registry table: `t(θ)` from the kernel's lookup table
/// and `t_dif` per channel.
pub struct ApertureGlass<'a> {
    /// The lookup table the kernel composites with.
    pub lut: &'a GlassLut,
    /// The registry table whose records give `t_dif` (their stored hemispherical value);
    /// `None`, or an id it has no record of: `t_dif` integrated from `lut`.
    pub table: Option<&'a RegistryTable>,
    /// The registry's name for messages.
    pub registry: &'a str,
}

/// Each part's factor, in the order of `parts`: checks that every aperture lies on one of the
/// frame's `planes` planes (`mask` names the mask in the error) and that the registry has its
/// glass id.
pub fn part_factors(
    parts: &[&LightPart],
    planes: usize,
    mask: &Path,
    glass: &ApertureGlass<'_>,
) -> Result<Vec<PartFactor>, ComposeError> {
    parts
        .iter()
        .map(|part| part_factor(part, planes, mask, glass))
        .collect()
}

fn part_factor(
    part: &LightPart,
    planes: usize,
    mask: &Path,
    glass: &ApertureGlass<'_>,
) -> Result<PartFactor, ComposeError> {
    let done = |factor: [f32; 3], kind| PartFactor {
        group: part.group.clone(),
        factor,
        kind,
        light: part.light.clone(),
    };
    let Some(aperture) = part.through else {
        return Ok(done([1.0; 3], FactorKind::Unglazed));
    };
    if aperture.plane >= planes {
        return Err(ComposeError::AperturePlaneNotInMask {
            group: part.group.clone(),
            plane: aperture.plane,
            mask: mask.to_path_buf(),
            planes,
        });
    }
    let unknown = || ComposeError::LightPartUnknownId {
        group: part.group.clone(),
        id: aperture.id,
        plane: aperture.plane,
        registry: glass.registry.to_string(),
    };
    let id = u16::try_from(aperture.id).map_err(|_| unknown())?;
    if !glass.lut.contains(id) {
        return Err(unknown());
    }
    match part.source {
        LightSource::Sun { direction_to_sun } => {
            let n = aperture.normal;
            let d = direction_to_sun;
            let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
            let dot = (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / len;
            let side = if dot >= 0.0 { Side::Front } else { Side::Back };
            let cos_theta = dot.abs().min(1.0);
            let t = glass
                .lut
                .side(id, side)
                .ok_or_else(unknown)?
                .at_cos(cos_theta as f32)
                .t;
            Ok(done(
                t,
                FactorKind::Sun {
                    id,
                    plane: aperture.plane,
                    cos_theta,
                    side,
                },
            ))
        }
        LightSource::Sky | LightSource::Other => {
            let t_dif = glass
                .table
                .and_then(|t| t.glass(id))
                .map(|g| g.t_dif())
                .or_else(|| glass.lut.side(id, Side::Front).map(lut_t_dif))
                .ok_or_else(unknown)?;
            Ok(done(
                t_dif.map(|v| v as f32),
                FactorKind::Diffuse {
                    id,
                    plane: aperture.plane,
                },
            ))
        }
    }
}

/// `t_dif = 2∫₀¹ t(μ) μ dμ` from a lookup table's fine table (trapezoids), for a table given
/// built without its registry records ([`RegistryLuts::single`]).
fn lut_t_dif(side: &crate::lut::GlassSideLut) -> [f64; 3] {
    let h = 1.0 / FINE_STEPS as f64;
    let mut out = [0.0; 3];
    for (i, e) in side.fine.iter().enumerate() {
        let mu = i as f64 * h;
        let w = if i == 0 || i == FINE_STEPS { 0.5 } else { 1.0 };
        for (o, t) in out.iter_mut().zip(e.t) {
            *o += 2.0 * w * h * mu * f64::from(t);
        }
    }
    out
}

/// The registry's lookup tables per light, built once for a run and shared by its frames: the
/// default light's, and each named light's.
#[derive(Debug)]
pub struct PartTables {
    default: RegistryLuts,
    lights: Vec<(String, RegistryLuts)>,
    lights_described: Vec<String>,
    registry: String,
}

impl PartTables {
    /// The tables of `registry` (each built when a frame first needs it); `label` names it in
    /// messages.
    pub fn new(registry: &Registry, label: &str) -> PartTables {
        let lights = registry.lights();
        PartTables {
            default: RegistryLuts::new(registry),
            lights: lights
                .iter()
                .filter_map(|l| l.name)
                .filter_map(|name| {
                    Some((name.to_string(), RegistryLuts::for_light(registry, name)?))
                })
                .collect(),
            lights_described: lights.iter().map(|l| l.describe()).collect(),
            registry: label.to_string(),
        }
    }

    /// The tables for a part's `light`.
    fn get(&self, part: &LightPart) -> Result<&RegistryLuts, ComposeError> {
        match &part.light {
            None => Ok(&self.default),
            Some(name) => self
                .lights
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, l)| l)
                .ok_or_else(|| ComposeError::NoTableForGroup {
                    registry: self.registry.clone(),
                    group: part.group.clone(),
                    lights: self.lights_described.clone(),
                }),
        }
    }
}

/// What composing a frame with its light parts did.
#[derive(Debug, Clone, PartialEq)]
pub struct RelitReport {
    /// The frame's report (the output written, timings, counts of the first light's pass).
    pub frame: FrameReport,
    /// Each part's factor, in the record's order.
    pub factors: Vec<PartFactor>,
}

/// Reads and checks a light-parts record (`light_parts.json`): JSON of at most
/// [`glassdb_io::limits::JSON`], [`LightParts::check`]ed; an error names the file and,
/// for bad JSON, the line and column.
pub fn read_light_parts(path: &Path) -> Result<LightParts, ComposeError> {
    let bad = |problem: String| ComposeError::LightPartsRecord {
        record: path.display().to_string(),
        problem,
    };
    let text = glassdb_io::read_input_string(path, glassdb_io::limits::JSON)
        .map_err(|e| bad(glassdb_io::ErrorChain(&e).to_string()))?;
    let parts: LightParts = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
    parts.check().map_err(|p| bad(p.0))?;
    Ok(parts)
}

/// Each light part's layers in `files`' passes, from their headers alone, in the order of
/// `groups`: a part without a layer in some pass ([`ComposeError::PartWithoutLayer`]) or a
/// pass's light-group layer without a part ([`ComposeError::LayerWithoutPart`]) is refused, so
/// that no light is lost or left with the old glass; pane-group passes included.
pub fn part_passes(
    files: &FrameFiles,
    groups: &[&str],
    max_pixels: u64,
) -> Result<Vec<GroupPasses>, ComposeError> {
    let as_parts = |e: ComposeError| match e {
        ComposeError::GroupWithoutLayer { path, group, found } => {
            ComposeError::PartWithoutLayer { path, group, found }
        }
        ComposeError::GroupWithoutTable {
            path,
            groups,
            composited,
        } => ComposeError::LayerWithoutPart {
            path,
            groups,
            parts: composited,
        },
        other => other,
    };
    group_passes(files, groups, max_pixels).map_err(as_parts)
}

/// Composites a frame with its light parts (docs/compose.md, "Relit swap"): checks the record
/// and that the passes' light-group layers are exactly its parts, then, per registry light
/// (the parts' `light`), plans the frame, computes the parts' factors from the table chosen for
/// the passes' space ([`part_factors`]), reads each pass once as the factor-weighted sum of the
/// parts' layers, decodes the mask and composites once; the lights' composites are summed and
/// written as the output's beauty (the passes' group layers are not carried over).
/// `record` names the record in messages.
pub fn compose_light_parts(
    job: &ComposeJob,
    settings: &ComposeSettings,
    tables: &PartTables,
    parts: &LightParts,
    record: &str,
    progress: &dyn glassdb_io::Progress,
) -> Result<RelitReport, ComposeError> {
    parts.check().map_err(|p| ComposeError::LightPartsRecord {
        record: record.to_string(),
        problem: p.0,
    })?;
    let mut target = crate::check_job(job, settings)?;
    let names: Vec<&str> = parts.parts.iter().map(|p| p.group.as_str()).collect();
    let passes = part_passes(&job.inputs, &names, settings.decode.pass.max_pixels)?;
    if target.carry.keep_channels
        && !carries_more_than_parts(&job.inputs.trans, &passes, &settings.decode.pass)?
    {
        // Nothing to carry but the beauty the relit sum replaces: read the parts alone.
        target.carry.keep_channels = false;
    }
    let planes = job.inputs.refl.len();
    let budget = MemoryBudget::new(settings.decode.max_memory);
    let mut lights: Vec<(Option<&str>, Vec<&LightPart>)> = Vec::new();
    for part in &parts.parts {
        match lights.iter_mut().find(|(l, _)| *l == part.light.as_deref()) {
            Some((_, members)) => members.push(part),
            None => lights.push((part.light.as_deref(), vec![part])),
        }
    }
    let carry_after = target.carry.keep_channels;
    let mut first_trans = None;
    let mut factors: Vec<PartFactor> = Vec::with_capacity(parts.parts.len());
    let mut sum: Option<Composited> = None;
    let mut timings = StageTimings::default();
    let [decode_stage, composite_stage, _] = FRAME_STAGES;
    // One mask for every light: decoded with the first light's passes, handed on to the others.
    let mask_slot = crate::decode::MaskOnce::default();
    let mask_once = (lights.len() > 1).then_some(&mask_slot);
    for (k, (_, members)) in lights.iter().enumerate() {
        let luts = tables.get(members[0])?;
        let mut one = settings.clone();
        one.decode.layers = InputLayers::default();
        one.decode.pass.light_mix = Some(LightMix {
            weights: members
                .iter()
                .map(|p| (p.group.clone(), [1.0; 3]))
                .collect(),
        });
        progress.stage(decode_stage);
        let t0 = Instant::now();
        let mut plan = crate::plan::plan_frame(&job.inputs, &one.decode, luts, &budget, &target)?;
        let glass = ApertureGlass {
            lut: plan.lut,
            table: luts.table(plan.table.basis),
            registry: &settings.decode.registry_label,
        };
        let these = part_factors(members, planes, &job.inputs.mask, &glass)?;
        let mix = LightMix {
            weights: these.iter().map(|f| (f.group.clone(), f.factor)).collect(),
        };
        plan.reads.trans.light_mix = Some(mix.clone());
        for r in &mut plan.reads.refl {
            r.light_mix = Some(mix.clone());
        }
        factors.extend(these);
        // what the output carries of the transmission file's other channels is read once the
        // lights are summed; each light decodes its parts alone
        if k == 0 && carry_after {
            first_trans = Some(plan.reads.trans.clone());
        }
        let carry = if k == 0 && !carry_after {
            target.carry
        } else {
            Carry::NONE
        };
        if let Some(total) = &mut sum {
            // the lights after the first: read and composited in row bands into the sum
            progress.stage(composite_stage);
            let band_rows = crate::bands::BAND_ROWS;
            let t = add_in_bands(&job.inputs, &one, plan, &mask_slot, total, false, band_rows)?;
            timings.decode += t0.elapsed() - t.timings.compose;
            timings.compose += t.timings.compose;
            continue;
        }
        let frame =
            crate::decode::decode_planned(&job.inputs, &one.decode, plan, carry, mask_once)?;
        timings.decode += t0.elapsed();
        progress.stage(composite_stage);
        let t1 = Instant::now();
        sum = Some(crate::composite::composite(frame, &one, mask_once)?);
        timings.compose += t1.elapsed();
    }
    drop(mask_slot);
    let mut total = sum.ok_or_else(|| ComposeError::LightPartsRecord {
        record: record.to_string(),
        problem: "no parts".into(),
    })?;
    if let Some(opts) = first_trans {
        total.image.frame = read_carried_after_groups(&job.inputs, &opts, target.carry, &passes)?;
    }
    carry_groups(&mut total.image.frame, &passes, Vec::new());
    let frame = crate::write_composited(job, settings, total, timings, progress)?;
    // the record's order
    let factors = parts
        .parts
        .iter()
        .filter_map(|p| factors.iter().find(|f| f.group == p.group).cloned())
        .collect();
    Ok(RelitReport { frame, factors })
}

/// Whether the transmission file holds channels other than the parts' layers and the beauty
/// they are split from (the layer named as the first part's without `_<group>`), from its
/// header: only then are its other channels carried into the output.
fn carries_more_than_parts(
    trans: &Path,
    passes: &[GroupPasses],
    pass: &glassdb_pass::PassReadOptions,
) -> Result<bool, ComposeError> {
    let opts = glassdb_pass::PassReadOptions {
        light_mix: Some(LightMix {
            weights: passes.iter().map(|g| (g.group.clone(), [1.0; 3])).collect(),
        }),
        ..pass.clone()
    };
    let header = glassdb_pass::read_pass_header(trans, &opts)?;
    let layers: Vec<&str> = passes
        .iter()
        .filter_map(|g| g.layers.trans.as_deref())
        .collect();
    let beauty = passes.first().and_then(|g| {
        g.layers
            .trans
            .as_deref()?
            .strip_suffix(g.group.as_str())?
            .strip_suffix('_')
    });
    let in_layer = |name: &str, layer: &str| {
        name.strip_prefix(layer)
            .is_some_and(|rest| rest.starts_with('.'))
    };
    Ok(glassdb_image::all_channel_names(&header.parts)
        .iter()
        .any(|name| {
            !layers.iter().any(|l| in_layer(name, l)) && !beauty.is_some_and(|b| in_layer(name, b))
        }))
}

#[cfg(test)]
#[path = "relight_tests.rs"]
mod tests;
