//! `glassdb view`: the glass-swap viewer (docs/viewer.md). All logic lives in `glassdb_view`;
//! this module parses arguments, prints the URL and serves, or writes an export and exits.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use glassdb_compose::io::PassReadOptions;
use glassdb_compose::pixels::InputTransfer;
use glassdb_compose::view::CubeLut;
use glassdb_compose::{
    ComposeJob, ComposeSettings, InputLayers, OutsidePolicy, UnknownIds, sequence,
};
use glassdb_mask::{ExrMaskChannels, MaskReadOptions};
use glassdb_spectral::RgbSpace;
use glassdb_view::server::ViewServer;
use glassdb_view::{Viewer, ViewerInputs};

use crate::cmd::compose::{
    default_max_memory, load_registry, parse_mask_channels, parse_size, plane_sides, split_layer,
};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Reflection pass (EXR or PNG; `FILE.exr:LAYER` picks its layer); repeat, the k-th is
    /// plane k of the mask.
    #[arg(long, required = true, value_name = "FILE[:LAYER]")]
    pub refl: Vec<PathBuf>,
    /// Transmission pass (the scene without glass).
    #[arg(long, value_name = "FILE[:LAYER]")]
    pub trans: PathBuf,
    /// Glass mask: 8-bit or 16-bit RGB PNG, or an EXR with `id` and `cos_theta` channels
    /// (docs/mask.md).
    #[arg(long, value_name = "FILE[:LAYER]")]
    pub mask: PathBuf,
    /// EXR mask channel names, e.g. `id=IndexMA,cos=facing` (keys id, cos, plane, coverage).
    #[arg(long, value_name = "KEY=NAME,...")]
    pub mask_channels: Option<String>,
    /// `planes.json` from `glassdb mirror`: the side of every plane (--side overrides it).
    #[arg(long, value_name = "JSON")]
    pub planes: Option<PathBuf>,
    /// Plane K shows the glass's back face (`K=back`) or front face (`K=front`).
    #[arg(long, value_name = "K=SIDE")]
    pub side: Vec<String>,
    /// Registry JSON whose records are the candidate products and the glasses' first choice
    /// (default: the bundled registry, every product of data/catalog.toml).
    #[arg(long, value_name = "JSON", conflicts_with = "catalog")]
    pub registry: Option<PathBuf>,
    /// Build the candidates from this catalog at start (docs/registry.md), with the tables the
    /// bundled registry has (its spectral method in each of its spaces), instead of --registry.
    #[arg(long, value_name = "TOML")]
    pub catalog: Option<PathBuf>,
    /// EXR layer of every pass without its own.
    #[arg(long, value_name = "NAME")]
    pub layer: Option<String>,
    /// The passes' linear RGB space, over what their headers say (as compose's --input-space).
    #[arg(long, value_name = "SPACE")]
    pub input_space: Option<RgbSpace>,
    /// Frames of an animation, e.g. `1-24`: `####` in --refl, --trans and --mask is replaced by
    /// the zero-padded frame number; the page gets a frame slider.
    #[arg(long, value_name = "LIST")]
    pub frames: Option<String>,
    /// A `.cube` view the page offers beside `standard` (repeat for several; docs/colour.md):
    /// as compose's --view, its output is display-encoded.
    #[arg(long, value_name = "FILE.cube")]
    pub view: Vec<PathBuf>,
    /// Address to listen on. The default serves this machine only.
    #[arg(long, default_value = "127.0.0.1", value_name = "ADDRESS")]
    pub bind: String,
    /// Port to listen on; 0 picks a free one.
    #[arg(long, default_value_t = 8000)]
    pub port: u16,
    /// Write the self-contained page (HTML, script, passes, every candidate product's table)
    /// into this folder and exit instead of serving.
    #[arg(long, value_name = "DIR")]
    pub export: Option<PathBuf>,
    /// Folder the page's "export" button writes into (without it the button is disabled).
    #[arg(long, value_name = "DIR")]
    pub export_dir: Option<PathBuf>,
    /// The export's first products, `ID:PRODUCT,…` (a product's name, a unique part of it, or
    /// its registry id); the served page takes them as its `glass` URL parameter.
    #[arg(long, value_name = "ID:PRODUCT,...")]
    pub glass: Option<String>,
    /// The export's first exposure, in stops.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub ev: f64,
    /// Refuse inputs with more pixels than this (checked before decoding).
    #[arg(long, value_name = "N", default_value_t = glassdb_mask::DEFAULT_MAX_PIXELS)]
    pub max_pixels: u64,
    /// Refuse a frame that would hold more memory than SIZE (as compose's --max-memory).
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    pub max_memory: Option<u64>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (registry, label) = match &args.catalog {
        Some(catalog) => (
            registry_from_catalog(catalog)?,
            catalog.display().to_string(),
        ),
        None => load_registry(args.registry.as_deref())?,
    };
    let mut protected: Vec<PathBuf> = match &args.catalog {
        Some(c) => glassdb_registry::catalog_inputs(c).map_err(anyhow::Error::new)?,
        None => Vec::new(),
    };
    let plane_sides = plane_sides(args.planes.as_deref(), &args.side, args.refl.len())?;
    let settings = ComposeSettings {
        pass: PassReadOptions {
            layer: args.layer.clone(),
            transfer: InputTransfer::Srgb,
            max_pixels: args.max_pixels,
        },
        layers: InputLayers {
            trans: split_layer(&args.trans).1,
            refl: args.refl.iter().map(|r| split_layer(r).1).collect(),
        },
        mask: MaskReadOptions {
            exr_channels: match &args.mask_channels {
                Some(s) => parse_mask_channels(s)?,
                None => ExrMaskChannels::default(),
            },
            max_pixels: args.max_pixels,
            layer: split_layer(&args.mask).1,
            ..MaskReadOptions::default()
        },
        outside: OutsidePolicy::Error,
        plane_sides,
        unknown: UnknownIds::Error,
        output: Default::default(),
        registry_label: label,
        protected: {
            protected.extend(
                args.registry
                    .iter()
                    .chain(&args.planes)
                    .chain(&args.view)
                    .cloned(),
            );
            protected
        },
        input_space: args.input_space,
        max_memory: args.max_memory.unwrap_or_else(default_max_memory),
    };
    let trans = split_layer(&args.trans).0;
    let job = ComposeJob {
        refl: args.refl.iter().map(|r| split_layer(r).0).collect(),
        // Never written (the viewer only decodes the inputs); the frame's memory estimate
        // counts encoding it as the PNG the page shows.
        output: trans.with_extension("viewer.png"),
        trans,
        mask: split_layer(&args.mask).0,
    };
    let frames = match &args.frames {
        Some(spec) => sequence::parse_frames(spec)?,
        None => Vec::new(),
    };
    let viewer = Viewer::open(ViewerInputs {
        job,
        frames,
        settings,
        registry,
        views: args
            .view
            .iter()
            .map(|p| CubeLut::read(p))
            .collect::<Result<_, _>>()?,
    })?;
    let choices = match &args.glass {
        Some(spec) => viewer.parse_choices(spec).context("--glass")?,
        None => Vec::new(),
    };
    if let Some(dir) = &args.export {
        glassdb_view::export::write_export(&viewer, dir, &choices, args.ev)?;
        outln!("wrote {}", dir.join("index.html").display());
        return Ok(ExitCode::SUCCESS);
    }
    let server = ViewServer::bind(viewer, &args.bind, args.port, args.export_dir.clone())?;
    let query = if choices.is_empty() {
        String::new()
    } else {
        format!("?glass={}", percent_encode(&server_choices(&args)))
    };
    outln!("serving {}{query}", server.url());
    outln!("(Ctrl-C stops the viewer)");
    server.run();
    Ok(ExitCode::SUCCESS)
}

/// A registry built from `catalog` with the bundled registry's tables: its spectral method in
/// each of its spaces, so that passes in any of those spaces find their table.
fn registry_from_catalog(catalog: &std::path::Path) -> anyhow::Result<glassdb_registry::Registry> {
    let bundled = glassdb_registry::default_registry()?;
    let opts = glassdb_registry::BuildOptions {
        tables: bundled.tables().iter().map(|t| t.spectral).collect(),
        ..Default::default()
    };
    glassdb_registry::build_registry(catalog, &opts)
        .map_err(anyhow::Error::new)
        .with_context(|| format!("building the candidates from {}", catalog.display()))
}

/// The `--glass` text as given (the page resolves the names itself).
fn server_choices(args: &Args) -> String {
    args.glass.clone().unwrap_or_default()
}

/// Percent-encodes everything but unreserved characters, `,` and `:` (a URL's query).
fn percent_encode(text: &str) -> String {
    let mut out = String::new();
    for b in text.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~,:".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}
