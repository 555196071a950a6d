//! `glassdb blender compose` on passes that keep the light's path apart (issue 28,
//! docs/compose.md "Relit swap"): a frame whose run record names its light parts is composited
//! with them ([`glassdb_compose::compose_light_parts`]), so that a swap relights the room;
//! the swap warnings then say only what the relit swap cannot fix.

use std::path::Path;

use glassdb_compose::{ComposeJob, ComposeSettings, PartTables, RelitReport};

use crate::BlenderError;
use crate::job::RunRecord;
use crate::pipeline::RegistryChoice;
use crate::swap::{SwapWarning, swap_warnings};

/// Frame `job` composited with the light parts of `dir/name` (a file name the run record
/// checked).
pub(crate) fn compose_frame_parts(
    dir: &Path,
    name: &str,
    job: &ComposeJob,
    settings: &ComposeSettings,
    tables: &PartTables,
) -> Result<RelitReport, BlenderError> {
    let path = dir.join(name);
    let parts = glassdb_compose::read_light_parts(&path)?;
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

/// [`swap_warnings`] for a run whose frames may carry light parts: none when every frame has
/// them (the swap relights the room), else the warnings of the passes without a split.
pub fn swap_warnings_relit(record: &RunRecord, registry: &RegistryChoice) -> Vec<SwapWarning> {
    if !record.frames.is_empty() && record.frames.iter().all(|f| f.light_parts.is_some()) {
        return Vec::new();
    }
    swap_warnings(record, registry)
}
