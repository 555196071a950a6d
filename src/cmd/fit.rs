//! `glassdb fit` and `glassdb eval`: under construction (owned by the fit work item).

use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct FitArgs {}

#[derive(Debug, clap::Args)]
pub struct EvalArgs {}

pub fn run_fit(_args: FitArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`fit` is not built yet")
}

pub fn run_eval(_args: EvalArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`eval` is not built yet")
}
