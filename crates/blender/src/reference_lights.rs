//! The Cycles reference of a run with the scene's light groups (issue 29, docs/blender.md
//! "Light groups"), when the registry has a table per light: the thin pane is tabulated per
//! RGB channel under one illuminant, so one render cannot show the warm light through the
//! glass of the A table and the sun through the glass of the D65 table at once. Blender renders
//! the reference once per scene group with the glass of that group's light, the scene's own
//! groups as light groups; glassdb keeps group g's layer from render g and writes the
//! reference as those layers and their sum (`reference.####.exr`). Every render has the same
//! seed, so each layer is what Cycles renders of its group's light with its group's glass.

use std::path::{Path, PathBuf};

use crate::BlenderError;
use crate::job::{RunRecord, ScriptFrame, ScriptJob};
use crate::light_split::{Assembled, read_state, write_pass};
use crate::pipeline::{RegistryChoice, frame_name};
use crate::thin_pane::ThinPane;

/// Each scene group and the glass of its light (the thin panes of `panes` under that light),
/// or none when the run has no groups or the registry composites them with one table.
pub(crate) fn panes_by_light(
    record: &RunRecord,
    panes: &[ThinPane],
    registry: &RegistryChoice,
) -> Result<Vec<(String, Vec<ThinPane>)>, BlenderError> {
    if record.lights.is_empty() || registry.registry.lights().len() < 2 {
        return Ok(Vec::new());
    }
    let basis = crate::swap::shader_table(registry).basis();
    record
        .lights
        .iter()
        .map(|light| {
            let table = registry
                .registry
                .table_under(basis, &light.group, &registry.label)?;
            let panes = panes
                .iter()
                .map(|p| {
                    table
                        .glass(p.id)
                        .map(|g| ThinPane::of(&p.material, g))
                        .ok_or_else(|| BlenderError::UnknownGlass {
                            id: p.id,
                            material: p.material.clone(),
                            registry: format!("{} (light {})", registry.label, light.group),
                        })
                })
                .collect::<Result<Vec<_>, _>>()?;
            Ok((light.group.clone(), panes))
        })
        .collect()
}

/// Where the reference of light group `k` goes in `staging`.
fn light_reference(staging: &Path, group: &str, frame: u32) -> PathBuf {
    staging.join(frame_name(&format!("reference_{group}"), frame))
}

/// The reference jobs, one per group of `by_light`, from `job` (the passes' job).
pub(crate) fn jobs(
    staging: &Path,
    record: &RunRecord,
    job: &ScriptJob,
    by_light: &[(String, Vec<ThinPane>)],
) -> Vec<ScriptJob> {
    by_light
        .iter()
        .map(|(group, panes)| ScriptJob {
            reference: true,
            glass: panes.clone(),
            frames: record
                .frames
                .iter()
                .map(|f| ScriptFrame {
                    frame: f.frame,
                    trans: light_reference(staging, group, f.frame),
                    planes: Vec::new(),
                    apertures: Vec::new(),
                    lights: None,
                })
                .collect(),
            light_split: false,
            light_groups: false,
            scene_groups: record.lights.iter().map(|l| l.group.clone()).collect(),
            ..job.clone()
        })
        .collect()
}

/// Each frame's reference from the groups' renders: group g's layer of render g, and their sum
/// as the beauty (alpha from the first render), written to `dir/reference.####.exr`.
pub(crate) fn assemble(
    staging: &Path,
    dir: &Path,
    record: &RunRecord,
    by_light: &[(String, Vec<ThinPane>)],
) -> Result<(), BlenderError> {
    let groups: Vec<String> = by_light.iter().map(|(g, _)| g.clone()).collect();
    let names: Vec<&str> = groups.iter().map(String::as_str).collect();
    for f in &record.frames {
        let mut parts = Vec::with_capacity(groups.len());
        let mut first: Option<(glassdb_image::PixelWindow, Vec<f32>)> = None;
        for (k, group) in groups.iter().enumerate() {
            let path = light_reference(staging, group, f.frame);
            let mut image = read_state(&path, &groups)?;
            match &first {
                None => first = Some((image.window, std::mem::take(&mut image.alpha))),
                Some((w, _))
                    if (w.width, w.height) != (image.window.width, image.window.height) =>
                {
                    return Err(BlenderError::BadRender {
                        path,
                        message: format!(
                            "{}x{}, but the reference of light {} is {}x{}",
                            image.window.width, image.window.height, groups[0], w.width, w.height
                        ),
                    });
                }
                Some(_) => {}
            }
            parts.push(image.groups.swap_remove(k));
        }
        let (window, alpha) = first.expect("a run with lights has groups");
        write_pass(
            &dir.join(frame_name("reference", f.frame)),
            Assembled {
                window,
                parts,
                alpha,
            },
            &names,
            (record.width, record.height),
        )?;
    }
    Ok(())
}
