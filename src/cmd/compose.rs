//! `glassdb compose`: under construction (owned by the compose work item).

use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`compose` is not built yet")
}
