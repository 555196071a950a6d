//! Light groups (docs/compose.md, "Light groups"): a frame whose passes are split by light,
//! one layer per group in the transmission pass and in every reflection pass, composited group
//! by group with the registry table of each group's light and summed,
//! `out = Σ_g (trans_g·t_g + refl_g·r_g)` (method eqs. 8–10 per group). One table is exact only
//! for light of its spectrum; a dusk shot's sky and tungsten groups each get theirs
//! (docs/colour.md, "Lights").
//!
//! [`group_passes`] is the reader: which layer of which file is each group's, from the headers
//! alone, refusing a group without a layer and layers without a group. [`compose_light_groups`]
//! runs the frame's phases once per group and writes the sum (and, asked, each group's
//! composite as a layer).

use std::path::Path;

use glassdb_encode::OutputFormat;
use glassdb_image::{ExactExr, ExactPart, FlatSamples};
use glassdb_pass::{CarriedFrame, Carry, ExrCarried, light_group_layers_of};
use glassdb_registry::Registry;

use crate::colour::RegistryLuts;
use crate::composite::Composited;
use crate::memory::MemoryBudget;
use crate::{ComposeError, ComposeJob, ComposeSettings, FrameFiles, FrameReport, InputLayers};

/// A light group and the lookup tables of its light, one per colour basis.
#[derive(Debug)]
pub struct LightGroup {
    /// The group's name, as the passes' layers and the registry's light name it (`sun`).
    pub name: String,
    /// The tables integrated under its light.
    pub luts: RegistryLuts,
}

impl LightGroup {
    /// The groups `names` with the tables of the registry's lights of the same names; an
    /// error naming the group and the registry's lights when one has no table, or when the
    /// list is empty or names a group twice. `registry_label` names the registry in messages.
    pub fn from_registry(
        registry: &Registry,
        names: &[String],
        registry_label: &str,
    ) -> Result<Vec<LightGroup>, ComposeError> {
        if names.is_empty() {
            return Err(ComposeError::LightGroupList("none named".into()));
        }
        let mut groups: Vec<LightGroup> = Vec::with_capacity(names.len());
        for name in names {
            if groups.iter().any(|g| &g.name == name) {
                return Err(ComposeError::LightGroupList(format!("{name} named twice")));
            }
            let luts = RegistryLuts::for_light(registry, name).ok_or_else(|| {
                ComposeError::NoTableForGroup {
                    registry: registry_label.to_string(),
                    group: name.clone(),
                    lights: registry.lights().iter().map(|l| l.describe()).collect(),
                }
            })?;
            groups.push(LightGroup {
                name: name.clone(),
                luts,
            });
        }
        Ok(groups)
    }
}

/// One group's layers in a frame's passes: the transmission pass's, each reflection pass's and
/// each of the units' pane-group passes'.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GroupPasses {
    /// The group.
    pub group: String,
    /// The layer of each input the group is read from.
    pub layers: InputLayers,
    /// The layer of each pane-group pass (`FrameFiles::groups`, in order).
    pub pane_groups: Vec<String>,
}

impl GroupPasses {
    /// `job` reading this group's layer of each pane-group pass (the transmission and plane
    /// passes' layers are the decode settings' [`InputLayers`]).
    pub fn pane_group_job(&self, job: &ComposeJob) -> ComposeJob {
        let mut one = job.clone();
        for (file, layer) in one.inputs.groups.iter_mut().zip(&self.pane_groups) {
            file.layer = Some(layer.clone());
        }
        one
    }
}

/// Each group's layers in `files`' passes (the units' pane-group passes too), from their
/// headers alone, in the order of `groups`:
/// every group must have a layer in every pass ([`ComposeError::GroupWithoutLayer`]), and
/// every group layer of a pass must be one of `groups` ([`ComposeError::GroupWithoutTable`]),
/// so that no light is lost or composited twice. `max_pixels` bounds each header read.
pub fn group_passes(
    files: &FrameFiles,
    groups: &[&str],
    max_pixels: u64,
) -> Result<Vec<GroupPasses>, ComposeError> {
    let layers_of = |path: &Path| -> Result<Vec<String>, ComposeError> {
        let found = light_group_layers_of(path, max_pixels)?;
        let extra: Vec<String> = found
            .iter()
            .filter(|l| !groups.contains(&l.group.as_str()))
            .map(|l| l.group.clone())
            .collect();
        if !extra.is_empty() {
            return Err(ComposeError::GroupWithoutTable {
                path: path.to_path_buf(),
                groups: extra,
                composited: groups.iter().map(|g| g.to_string()).collect(),
            });
        }
        groups
            .iter()
            .map(|&group| {
                found
                    .iter()
                    .find(|l| l.group == group)
                    .map(|l| l.layer.clone())
                    .ok_or_else(|| ComposeError::GroupWithoutLayer {
                        path: path.to_path_buf(),
                        group: group.to_string(),
                        found: found.iter().map(|l| l.group.clone()).collect(),
                    })
            })
            .collect()
    };
    let trans = layers_of(&files.trans)?;
    let refl: Vec<Vec<String>> = files
        .refl
        .iter()
        .map(|p| layers_of(p))
        .collect::<Result<_, _>>()?;
    let pane_groups: Vec<Vec<String>> = files
        .groups
        .iter()
        .map(|g| layers_of(&g.path))
        .collect::<Result<_, _>>()?;
    Ok(groups
        .iter()
        .enumerate()
        .map(|(g, name)| GroupPasses {
            group: name.to_string(),
            layers: InputLayers {
                trans: Some(trans[g].clone()),
                refl: refl.iter().map(|r| Some(r[g].clone())).collect(),
            },
            pane_groups: pane_groups.iter().map(|p| p[g].clone()).collect(),
        })
        .collect())
}

/// Composites a frame split into light groups: each group's passes ([`group_passes`])
/// composited with its own light's tables, in turn (the first decoded whole, each after it
/// read and composited in row bands into the sum, `bands.rs`; the frame's memory limit
/// held per group; the mask decoded once), and the sum written as the
/// output's beauty, with the transmission file's other channels read after the groups (less
/// their layers, never decoded). With
/// `keep_groups` (EXR output only) each group's composite is also written, as a layer of the
/// transmission pass's name for that group (`ViewLayer.Combined_sun.R`, …), so that a
/// compositor can still balance the lights. The report is the first group's, with the output
/// written.
pub fn compose_light_groups(
    job: &ComposeJob,
    settings: &ComposeSettings,
    groups: &[LightGroup],
    keep_groups: bool,
    progress: &dyn glassdb_io::Progress,
) -> Result<FrameReport, ComposeError> {
    let budget = MemoryBudget::new(settings.decode.max_memory);
    compose_light_groups_within(job, settings, groups, keep_groups, &budget, progress)
}

/// [`compose_light_groups`] holding each group's memory from `budget`, which the frames of a
/// sequence share (`glassdb_sequence`), as [`crate::compose_frame_within`].
pub fn compose_light_groups_within(
    job: &ComposeJob,
    settings: &ComposeSettings,
    groups: &[LightGroup],
    keep_groups: bool,
    budget: &MemoryBudget,
    progress: &dyn glassdb_io::Progress,
) -> Result<FrameReport, ComposeError> {
    let bands = crate::bands::BAND_ROWS;
    compose_groups_banded(
        job,
        settings,
        (groups, bands),
        keep_groups,
        budget,
        progress,
    )
}

/// [`compose_light_groups_within`] of `groups`, those after the first composited `band_rows`
/// rows at a time.
pub(crate) fn compose_groups_banded(
    job: &ComposeJob,
    settings: &ComposeSettings,
    (groups, band_rows): (&[LightGroup], usize),
    keep_groups: bool,
    budget: &MemoryBudget,
    progress: &dyn glassdb_io::Progress,
) -> Result<FrameReport, ComposeError> {
    let names: Vec<&str> = groups.iter().map(|g| g.name.as_str()).collect();
    if keep_groups && glassdb_encode::output_format(&job.output)? != OutputFormat::Exr {
        return Err(ComposeError::KeepGroupsNotExr {
            output: job.output.clone(),
        });
    }
    let target = crate::check_job(job, settings)?;
    let passes = group_passes(&job.inputs, &names, settings.decode.pass.max_pixels)?;
    let mut sum: Option<Composited> = None;
    let mut kept: Vec<(String, [Vec<f32>; 3])> = Vec::new();
    let mut timings = crate::StageTimings::default();
    // One mask for every group: decoded with the first group's passes, handed on to the others.
    let mask_slot = crate::decode::MaskOnce::default();
    let mask = (groups.len() > 1).then_some(&mask_slot);
    // What the output carries of the transmission file's other channels is read once the
    // groups are summed, without the group layers; each group decodes its own layer alone.
    let carry_after = target.carry.keep_channels;
    // the frame's memory is estimated with what its output carries by its first composite
    let rest = crate::DecodeTarget {
        carry: Carry::NONE,
        ..target.clone()
    };
    for (group, group_passes) in groups.iter().zip(&passes) {
        let mut one = settings.clone();
        one.decode.layers = group_passes.layers.clone();
        let job = group_passes.pane_group_job(job);
        let layer = || group_passes.layers.trans.clone().unwrap_or_default();
        if let Some(total) = &mut sum {
            // the groups after the first: read and composited in row bands into the sum
            progress.stage(crate::FRAME_STAGES[0]);
            let plan =
                crate::plan::plan_frame(&job.inputs, &one.decode, &group.luts, budget, &rest)?;
            progress.stage(crate::FRAME_STAGES[1]);
            let added = crate::bands::add_in_bands(
                &job.inputs,
                &one,
                plan,
                &mask_slot,
                total,
                keep_groups,
                band_rows,
            )?;
            timings.decode += added.timings.decode;
            timings.compose += added.timings.compose;
            kept.extend(added.own.map(|rgb| (layer(), rgb)));
            continue;
        }
        // the first group: decoded and composited whole, as a frame of one group
        let read = crate::SharedRead {
            carry: if carry_after {
                Carry::NONE
            } else {
                target.carry
            },
            mask,
        };
        let (composited, t) =
            crate::decode_and_composite(&job, &one, &target, &group.luts, budget, read, progress)?;
        timings.decode += t.decode;
        timings.compose += t.compose;
        if keep_groups {
            kept.push((layer(), composited.image.trans.image.rgb.clone()));
        }
        sum = Some(composited);
    }
    drop(mask_slot);
    let mut total = sum.ok_or_else(|| ComposeError::LightGroupList("none named".into()))?;
    if carry_after && let Some(first) = passes.first() {
        let mut opts = settings.decode.pass.clone();
        opts.layer = first.layers.trans.clone();
        total.image.frame = read_carried_after_groups(&job.inputs, &opts, target.carry, &passes)?;
    }
    carry_groups(&mut total.image.frame, &passes, kept);
    crate::write_composited(job, settings, total, timings, progress)
}

/// What the output of a frame split by light carries from its transmission file (`opts` reads
/// the first group's layer) as `carry` says, read once the groups' composites are summed so
/// that it is never held beside a group's passes: its attributes and other channels, less the
/// layers of `groups` (the sum replaces them), which are never decoded.
pub(crate) fn read_carried_after_groups(
    files: &FrameFiles,
    opts: &glassdb_pass::PassReadOptions,
    carry: Carry,
    groups: &[GroupPasses],
) -> Result<CarriedFrame, ComposeError> {
    let layers = group_layers(groups);
    Ok(glassdb_pass::read_carried(
        &files.trans,
        opts,
        carry,
        &|name| in_layers(name, &layers),
    )?)
}

/// The transmission pass's layers of `groups` (`ViewLayer.Combined_sun`, …).
fn group_layers(groups: &[GroupPasses]) -> Vec<String> {
    groups
        .iter()
        .filter_map(|g| g.layers.trans.clone())
        .collect()
}

/// Whether the channel `name` is in one of `layers` (`ViewLayer.Combined_sun.R` is in
/// `ViewLayer.Combined_sun`).
fn in_layers(name: &str, layers: &[String]) -> bool {
    layers.iter().any(|l| {
        name.strip_prefix(l.as_str())
            .is_some_and(|rest| rest.starts_with('.'))
    })
}

/// `total += add`, plane by plane, in f32: the sum of the groups' composites, the next group
/// added to the groups before it (the file and in-memory composites alike, so that they agree
/// bit for bit).
pub(crate) fn add_group_composite(total: &mut [Vec<f32>; 3], add: &[Vec<f32>; 3]) {
    let [r, g, b] = total;
    add_planes([r, g, b], [&add[0], &add[1], &add[2]]);
}

/// `total += add`, plane by plane, in f32, over planes or the rows of a band of them
/// ([`crate::bands`]): every sum of groups is made by this one addition.
pub(crate) fn add_planes(total: [&mut [f32]; 3], add: [&[f32]; 3]) {
    for (t, a) in total.into_iter().zip(add) {
        for (t, a) in t.iter_mut().zip(a) {
            *t += a;
        }
    }
}

/// Drops the group layers `group_layers` (`ViewLayer.Combined_sun`, …) from what `frame`
/// carries over.
fn drop_group_layers(frame: &mut CarriedFrame, group_layers: &[String]) {
    if let Some(ExrCarried::Whole { file, part, .. }) = &mut frame.exr {
        file.parts[*part]
            .channels
            .retain(|(name, _)| !in_layers(name, group_layers));
    }
}

/// What the output carries beside the beauty (the sum): the layers of `groups` in the
/// transmission pass are dropped ([`drop_group_layers`]) and, with `keep_groups`, each
/// group's composite written in their place (`layer.R`, `.G`, `.B`). The sum replaces the
/// file's beauty layer: the one the group layers are split from (`ViewLayer.Combined` for
/// `ViewLayer.Combined_sun`), else bare `R`, `G`, `B`, else it is added: as the Cycles groups'
/// base layer when only the file's attributes are carried, else as bare `R`, `G`, `B`.
pub(crate) fn carry_groups(
    frame: &mut CarriedFrame,
    groups: &[GroupPasses],
    kept: Vec<(String, [Vec<f32>; 3])>,
) {
    drop_group_layers(frame, &group_layers(groups));
    let window = frame.windows.data;
    let n = window.pixel_count() as usize;
    let rgb_names = |layer: &str| -> Vec<String> {
        ["R", "G", "B"]
            .iter()
            .map(|c| {
                if layer.is_empty() {
                    c.to_string()
                } else {
                    format!("{layer}.{c}")
                }
            })
            .collect()
    };
    let attributes_only = matches!(frame.exr, Some(ExrCarried::Attributes { .. }));
    let (mut file, part) = match frame.exr.take() {
        Some(ExrCarried::Whole { file, part, .. }) => (file, part),
        Some(ExrCarried::Attributes { image, part, .. }) => {
            let file = ExactExr {
                attributes: *image,
                parts: vec![ExactPart {
                    attributes: *part,
                    data_window: window,
                    channels: Vec::new(),
                }],
            };
            (file, 0)
        }
        None => return,
    };
    let channels = &mut file.parts[part].channels;
    // the beauty: the layer the first group's is split from (`ViewLayer.Combined` for
    // `ViewLayer.Combined_sun_p0_id1`: the group's name, underscores and all, removed), else
    // bare R, G, B
    let first = groups.first();
    let split_from = first
        .and_then(|g| {
            let layer = g.layers.trans.as_deref()?;
            layer.strip_suffix(g.group.as_str())?.strip_suffix('_')
        })
        .unwrap_or_default()
        .to_string();
    // Nothing carried but the attributes: a Cycles beauty is named as the groups' base.
    let cycles_base = attributes_only
        && first
            .and_then(|g| g.layers.trans.as_deref())
            .and_then(glassdb_pass::light_group_of_layer)
            .is_some_and(|(_, naming)| naming == glassdb_pass::GroupNaming::Cycles);
    let added = if cycles_base {
        split_from.clone()
    } else {
        String::new()
    };
    let beauty = [split_from, String::new()]
        .into_iter()
        .map(|l| rgb_names(&l))
        .find(|names| names.iter().all(|n| channels.iter().any(|(c, _)| c == n)))
        .unwrap_or_else(|| {
            let names = rgb_names(&added);
            for name in &names {
                channels.push((name.clone(), FlatSamples::F32(vec![0.0; n])));
            }
            names
        });
    for (layer, rgb) in kept {
        for (name, plane) in rgb_names(&layer).into_iter().zip(rgb) {
            channels.push((name, FlatSamples::F32(plane)));
        }
    }
    channels.sort_by(|a, b| a.0.cmp(&b.0));
    frame.exr = Some(ExrCarried::Whole {
        file,
        part,
        channel_names: beauty,
    });
}
