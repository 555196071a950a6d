//! `glassdb blender compose` on passes that keep the light's path apart (issue 28,
//! docs/compose.md "Relit swap"): a frame whose run record names its light parts is composited
//! with them ([`glassdb_compose::compose_light_parts`]), so that a swap relights the room;
//! the swap warnings then say only what the relit swap cannot fix.

use std::path::Path;

use glassdb_compose::light_parts::LightParts;
use glassdb_compose::{ComposeJob, ComposeSettings, PartTables, RelitReport};

use crate::BlenderError;
use crate::job::RunRecord;
use crate::pipeline::RegistryChoice;
use crate::scene_lights::LightTables;
use crate::swap::{SwapWarning, swap_warnings};

/// Frame `job` composited with the light parts of `dir/name` (a file name the run record
/// checked), each part with the registry light `lights` chose for its scene group.
pub(crate) fn compose_frame_parts(
    dir: &Path,
    name: &str,
    job: &ComposeJob,
    settings: &ComposeSettings,
    tables: &PartTables,
    lights: &LightTables,
) -> Result<RelitReport, BlenderError> {
    let path = dir.join(name);
    let mut parts = glassdb_compose::read_light_parts(&path)?;
    choose_part_lights(&mut parts, lights, &path)?;
    let label = path.display().to_string();
    Ok(glassdb_compose::compose_light_parts(
        job,
        settings,
        tables,
        &parts,
        &label,
        &glassdb_io::NoProgress,
    )?)
}

/// Each part's `light` (its scene group, as the render wrote it) replaced by the registry light
/// that composites it; a part of a group the run record does not have is refused. A run
/// without scene groups keeps its parts as they are.
fn choose_part_lights(
    parts: &mut LightParts,
    lights: &LightTables,
    path: &Path,
) -> Result<(), BlenderError> {
    if lights.groups.is_empty() {
        return Ok(());
    }
    for part in &mut parts.parts {
        let Some(group) = &part.light else { continue };
        if !lights.groups.iter().any(|(g, _)| g == group) {
            return Err(BlenderError::BadRecord {
                path: path.to_path_buf(),
                message: format!(
                    "part {} is of light group `{group}`, which the run's lights do not name",
                    part.group
                ),
            });
        }
        part.light = lights.light_of(group);
    }
    Ok(())
}

/// [`swap_warnings`] for a run whose frames may carry light parts: none when every frame has
/// them (the swap relights the room), else the warnings of the passes without a split.
pub fn swap_warnings_relit(record: &RunRecord, registry: &RegistryChoice) -> Vec<SwapWarning> {
    if !record.frames.is_empty() && record.frames.iter().all(|f| f.light_parts.is_some()) {
        return Vec::new();
    }
    swap_warnings(record, registry)
}
