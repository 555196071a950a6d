//! `compose`: the compositor as its own binary (identical to `glassdb compose`).

use std::process::ExitCode;

use clap::Parser;
use glassdb::cmd;

#[derive(Parser)]
#[command(
    name = "compose",
    version,
    about = "Composite reflection and transmission passes through an id + cos θ mask"
)]
struct Cli {
    #[command(flatten)]
    args: cmd::compose::Args,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    cmd::init_process();
    cmd::finish(cmd::compose::run(cli.args))
}
