//! `glassdb spectral`: under construction (owned by the spectral work item).

use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`spectral` is not built yet")
}
