//! `glassdb mirror` and `glassdb mask`: under construction (owned by the scene work item).

use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct MirrorArgs {}

#[derive(Debug, clap::Args)]
pub struct MaskArgs {}

pub fn run_mirror(_args: MirrorArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`mirror` is not built yet")
}

pub fn run_mask(_args: MaskArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`mask` is not built yet")
}
