//! `glassdb registry`: under construction (owned by the registry work item).

use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`registry` is not built yet")
}
