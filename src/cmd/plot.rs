//! `glassdb plot fit|registry|mask|spectral|stack`: figures for reviewing fits, registries, masks and
//! spectra. PNG or SVG by the `-o` extension (default: a PNG named after the input, in the
//! current directory). All drawing is in `glassdb_plot`.

use glassdb_registry::ColourBasis;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use glassdb_plot::plots::fit::{FitPlotOptions, fit_figure_from_fit_file, fit_figure_from_table};
use glassdb_plot::plots::mask::{MaskChannel, MaskPlotOptions, MaskQuantity, mask_figure};
use glassdb_plot::plots::registry::{RegistryPlotOptions, registry_figure};
use glassdb_plot::plots::spectral::{SpectralPlotOptions, spectral_figure};

use crate::cmd::spectral::SpectralSettingsArgs;
use glassdb_plot::{Figure, save};

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub what: PlotCommand,
}

#[derive(Debug, clap::Subcommand)]
pub enum PlotCommand {
    /// Measured points and fitted r(θ), t(θ) per glass with residuals below (an angle-table
    /// CSV is fitted as `glassdb fit` does; a fit JSON is drawn as is; a registry JSON is drawn
    /// per channel as `plot registry` does).
    Fit(FitArgs),
    /// r and t against angle for every glass of a registry, one colour per channel.
    Registry(RegistryArgs),
    /// The reflectance each glass pixel of a mask gets, as a heat map with a colour bar.
    Mask(MaskArgs),
    /// τ(λ), ρ(λ) over the visible range, the method's colour-matching functions beneath and
    /// the resulting channel values marked.
    Spectral(SpectralArgs),
    /// A unit's photopic T, Rf, Rb against angle beside each of its layers' (the build-up as
    /// `glassdb stack` takes it).
    Stack(StackPlotArgs),
}

#[derive(Debug, clap::Args)]
pub struct StackPlotArgs {
    #[command(flatten)]
    pub stack: crate::cmd::stack::StackArgs,
    #[command(flatten)]
    pub out: OutputArgs,
}

/// Output options shared by every figure.
#[derive(Debug, clap::Args)]
pub struct OutputArgs {
    /// Output file; `.png` or `.svg` picks the format (default: INPUT-STEM-KIND.png here).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
pub struct FitArgs {
    /// Angle table (CSV), fit file (`glassdb fit -o`, JSON) or registry (JSON).
    pub input: PathBuf,
    /// Measured angle table to overlay on a fit file's curves (points and residuals).
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// R and T in the table are in percent.
    #[arg(long)]
    pub percent: bool,
    /// Fixed degree (default: the automatic choice of `glassdb fit`).
    #[arg(long)]
    pub degree: Option<u32>,
    /// Tolerance of the automatic degree choice (max |fit − measured|, fraction).
    #[arg(long, default_value_t = glassdb_fit::DEFAULT_TOL)]
    pub tol: f64,
    /// Highest degree of the automatic choice.
    #[arg(long, default_value_t = glassdb_fit::DEFAULT_MAX_DEGREE)]
    pub max_degree: u32,
    /// Also draw the paper basis (powers 1…n, no constant; dashed) beside the full basis.
    #[arg(long)]
    pub compare_paper: bool,
    /// Only this glass (repeatable; by name).
    #[arg(long = "glass")]
    pub glasses: Vec<String>,
    #[command(flatten)]
    pub out: OutputArgs,
}

#[derive(Debug, clap::Args)]
pub struct RegistryArgs {
    /// Registry JSON (`glassdb registry build -o`).
    pub registry: PathBuf,
    /// Only this glass id (repeatable).
    #[arg(long = "id")]
    pub ids: Vec<u16>,
    /// The registry table to draw: an RGB space (srgb, acescg, …), paper-rgb or luminous
    /// (default: its first table).
    #[arg(long, value_name = "SPACE")]
    pub space: Option<ColourBasis>,
    #[command(flatten)]
    pub out: OutputArgs,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum QuantityArg {
    Reflectance,
    Transmittance,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum ChannelArg {
    /// Rec.709 luminance of the three channels.
    Luminance,
    R,
    G,
    B,
}

#[derive(Debug, clap::Args)]
pub struct MaskArgs {
    /// Mask (PNG 8/16-bit packed, or EXR with id and cos_theta channels).
    pub mask: PathBuf,
    /// Registry JSON giving each id's curves.
    #[arg(long)]
    pub registry: PathBuf,
    /// Which value to map.
    #[arg(long, value_enum, default_value = "reflectance")]
    pub quantity: QuantityArg,
    /// Which channel (or their luminance).
    #[arg(long, value_enum, default_value = "luminance")]
    pub channel: ChannelArg,
    /// `K=back`: plane K shows the glass's back face (repeatable; as in compose).
    #[arg(long = "side", value_name = "K=front|back")]
    pub sides: Vec<String>,
    /// Read the PNG as the paper's binary mask (white = glass) with this glass id.
    #[arg(long)]
    pub glass: Option<u16>,
    /// The registry table to evaluate: an RGB space (srgb, acescg, …), paper-rgb or luminous
    /// (default: its first table).
    #[arg(long, value_name = "SPACE")]
    pub space: Option<ColourBasis>,
    #[command(flatten)]
    pub out: OutputArgs,
}

#[derive(Debug, clap::Args)]
pub struct SpectralArgs {
    /// Spectral data (any format `glassdb spectral` reads).
    pub file: PathBuf,
    #[command(flatten)]
    pub settings: SpectralSettingsArgs,
    #[command(flatten)]
    pub out: OutputArgs,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.what {
        PlotCommand::Fit(a) => run_fit(a),
        PlotCommand::Registry(a) => run_registry(a),
        PlotCommand::Mask(a) => run_mask(a),
        PlotCommand::Spectral(a) => run_spectral(a),
        PlotCommand::Stack(a) => run_stack(a),
    }
}

/// The output path: `-o`, or `STEM-KIND.png` in the current directory.
fn output_path(out: &OutputArgs, input: &Path, kind: &str) -> PathBuf {
    out.output.clone().unwrap_or_else(|| {
        let stem = input
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "plot".into());
        PathBuf::from(format!("{stem}-{kind}.png"))
    })
}

fn write<F: Figure>(fig: &F, output: &Path, inputs: &[&Path]) -> anyhow::Result<ExitCode> {
    glassdb_io::declare_inputs(inputs.iter().copied());
    glassdb_io::refuse_input_as_output(output)?;
    let format =
        save(fig, output).with_context(|| format!("cannot plot to {}", output.display()))?;
    let (w, h) = fig.size();
    eprintln!("wrote {} ({w}×{h} px, {format:?})", output.display());
    Ok(ExitCode::SUCCESS)
}

/// True when the file looks like JSON (first non-blank byte `{`).
fn looks_like_json(path: &Path) -> anyhow::Result<bool> {
    let bytes = glassdb_io::read_input(path, glassdb_fit::ANGLE_TABLE_FILE)
        .with_context(|| format!("cannot read {}", path.display()))?;
    Ok(bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{'))
}

/// True when a JSON file is a registry (it has the top-level `schema` key).
fn is_registry_json(path: &Path) -> bool {
    glassdb_io::read_input(path, glassdb_io::limits::JSON)
        .ok()
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        .is_some_and(|v| v.get("schema").is_some())
}

fn run_fit(a: FitArgs) -> anyhow::Result<ExitCode> {
    let output = output_path(&a.out, &a.input, "fit");
    if looks_like_json(&a.input)? && is_registry_json(&a.input) {
        if a.data.is_some() {
            bail!(
                "--data overlays a measured table on a fit file; {} is a registry",
                a.input.display()
            );
        }
        let fig = registry_figure(&a.input, &RegistryPlotOptions::default())?;
        return write(&fig, &output, &[&a.input]);
    }
    let opts = FitPlotOptions {
        percent: a.percent,
        degree: a.degree,
        tol: a.tol,
        max_degree: a.max_degree,
        compare_paper: a.compare_paper,
        glasses: a.glasses,
    };
    if looks_like_json(&a.input)? {
        if a.compare_paper {
            bail!(
                "--compare-paper fits a measured table; {} is already a fit file",
                a.input.display()
            );
        }
        let fig = fit_figure_from_fit_file(&a.input, a.data.as_deref(), &opts)?;
        let data: Vec<&Path> = a.data.iter().map(PathBuf::as_path).collect();
        write(&fig, &output, &[&[a.input.as_path()][..], &data].concat())
    } else {
        if a.data.is_some() {
            bail!(
                "--data goes with a fit file; {} is a measured table already",
                a.input.display()
            );
        }
        let fig = fit_figure_from_table(&a.input, &opts)?;
        write(&fig, &output, &[&a.input])
    }
}

fn run_registry(a: RegistryArgs) -> anyhow::Result<ExitCode> {
    let output = output_path(&a.out, &a.registry, "registry");
    let fig = registry_figure(
        &a.registry,
        &RegistryPlotOptions {
            ids: a.ids,
            basis: a.space,
        },
    )?;
    write(&fig, &output, &[&a.registry])
}

/// Parses `K=back` / `K=front` into the plane index and whether it is the back face.
fn parse_side(s: &str) -> anyhow::Result<(u16, bool)> {
    let (k, side) = s
        .split_once('=')
        .with_context(|| format!("--side {s}: expected K=front or K=back"))?;
    let k: u16 = k
        .trim()
        .parse()
        .with_context(|| format!("--side {s}: plane index `{k}` is not a number 0–65535"))?;
    match side.parse::<glassdb_registry::Side>() {
        Ok(side) => Ok((k, side == glassdb_registry::Side::Back)),
        Err(_) => bail!("--side {s}: side `{}` must be front or back", side.trim()),
    }
}

fn run_mask(a: MaskArgs) -> anyhow::Result<ExitCode> {
    let output = output_path(&a.out, &a.mask, "mask");
    let mut opts = MaskPlotOptions {
        basis: a.space,
        quantity: match a.quantity {
            QuantityArg::Reflectance => MaskQuantity::Reflectance,
            QuantityArg::Transmittance => MaskQuantity::Transmittance,
        },
        channel: match a.channel {
            ChannelArg::Luminance => MaskChannel::Luminance,
            ChannelArg::R => MaskChannel::R,
            ChannelArg::G => MaskChannel::G,
            ChannelArg::B => MaskChannel::B,
        },
        ..MaskPlotOptions::default()
    };
    for s in &a.sides {
        let (k, back) = parse_side(s)?;
        opts.back_planes.retain(|&p| p != k);
        if back {
            opts.back_planes.push(k);
        }
    }
    opts.read.binary_glass_id = a.glass;
    let fig = mask_figure(&a.mask, &a.registry, &opts)?;
    write(&fig, &output, &[&a.mask, &a.registry])
}

fn run_spectral(a: SpectralArgs) -> anyhow::Result<ExitCode> {
    let output = output_path(&a.out, &a.file, "spectral");
    let opts = SpectralPlotOptions {
        settings: a.settings.settings()?,
        read: a.settings.read_options(),
    };
    let fig = spectral_figure(&a.file, &opts)?;
    write(&fig, &output, &[&a.file])
}

fn run_stack(a: StackPlotArgs) -> anyhow::Result<ExitCode> {
    let first = PathBuf::from(&a.stack.layers[0]);
    let output = output_path(&a.out, &first, "stack");
    let built = a.stack.build()?;
    let labels: Vec<String> = a
        .stack
        .layers
        .iter()
        .map(|l| {
            Path::new(l)
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_else(|| l.clone())
        })
        .collect();
    let title = format!("Unit: {}", labels.join(" | "));
    let fig = glassdb_plot::plots::stack::stack_figure(&built.stack, &labels, &title)?;
    let files: Vec<PathBuf> = a
        .stack
        .layers
        .iter()
        .enumerate()
        .map(|(i, l)| crate::cmd::stack::parse_layer(l, i + 1).map(|p| p.file))
        .collect::<anyhow::Result<_>>()?;
    let inputs: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    write(&fig, &output, &inputs)
}
