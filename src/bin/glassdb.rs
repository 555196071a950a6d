//! `glassdb`: fit, spectral, stack, registry, compose, mirror and mask in one binary.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use glassdb::cmd;

#[derive(Parser)]
#[command(
    name = "glassdb",
    version,
    about = "Architectural glass optical data and glazing compositor"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Fit angle-dependence polynomials C_r, C_t to a measured angle table.
    Fit(cmd::fit::FitArgs),
    /// Evaluate fitted curves (a `glassdb fit` JSON) at given angles.
    Eval(cmd::fit::EvalArgs),
    /// Spectral data to per-channel and luminous values.
    Spectral(cmd::spectral::Args),
    /// The optics of an insulated glazing unit from its layers, per wavelength and angle.
    Stack(cmd::stack::Args),
    /// Build, show and check the id-indexed glass table of a scene.
    Registry(cmd::registry::Args),
    /// Composite reflection and transmission passes through a mask (same as the `compose` binary).
    Compose(Box<cmd::compose::Args>),
    /// Mirror an OBJ scene across its glass planes (the virtual image for reflection passes).
    Mirror(cmd::scene::MirrorArgs),
    /// Rasterise the id + cos θ mask of an OBJ scene from a camera.
    Mask(cmd::scene::MaskArgs),
    /// Plot fits, spectra, a registry or a mask's reflectance (PNG or SVG).
    Plot(cmd::plot::Args),
    /// Regenerate the speed-against-error tables of docs/accuracy.md.
    Report(cmd::report::Args),
    /// Render a .blend scene's passes with Blender and composite them; re-composite a render.
    Blender(cmd::blender::Args),
    /// Serve the glass-swap viewer: pick products per glass and see the composite at once.
    View(Box<cmd::view::Args>),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    cmd::init_process();
    let result = match cli.command {
        Command::Fit(a) => cmd::fit::run_fit(a),
        Command::Eval(a) => cmd::fit::run_eval(a),
        Command::Spectral(a) => cmd::spectral::run(a),
        Command::Stack(a) => cmd::stack::run(a),
        Command::Registry(a) => cmd::registry::run(a),
        Command::Compose(a) => cmd::compose::run(*a),
        Command::Mirror(a) => cmd::scene::run_mirror(a),
        Command::Mask(a) => cmd::scene::run_mask(a),
        Command::Plot(a) => cmd::plot::run(a),
        Command::Report(a) => cmd::report::run(a),
        Command::Blender(a) => cmd::blender::run(a),
        Command::View(a) => cmd::view::run(*a),
    };
    cmd::finish(result)
}
