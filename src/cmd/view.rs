//! `glassdb view`: the glass-swap viewer (docs/viewer.md). All logic lives in `glassdb_view`;
//! this module parses arguments, prints the URL and serves, or writes an export and exits.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use glassdb_colour::CubeLut;
use glassdb_compose::{DecodeSettings, FrameFiles, OutsidePolicy, UnknownIds};
use glassdb_view::export::ExportFolder;
use glassdb_view::server::ViewServer;
use glassdb_view::{Viewer, ViewerFrame, ViewerInputs};

use crate::cmd::compose::load_registry;
use crate::cmd::inputs::FrameInputArgs;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// A `glassdb blender render` output folder: its frames, passes, masks and sides from its
    /// glassdb-blender.json (instead of --trans, --refl and --mask).
    #[arg(value_name = "DIR", conflicts_with = "FrameInputArgs")]
    pub run_dir: Option<PathBuf>,
    #[command(flatten)]
    pub inputs: Option<FrameInputArgs>,
    /// Registry JSON whose records are the candidate products and the glasses' first choice
    /// (default: the bundled registry, every product of data/catalog.toml).
    #[arg(long, value_name = "JSON", conflicts_with = "catalog")]
    pub registry: Option<PathBuf>,
    /// Build the candidates from this catalog at start (docs/registry.md), with the tables the
    /// bundled registry has (its spectral method in each of its spaces), instead of --registry.
    #[arg(long, value_name = "TOML")]
    pub catalog: Option<PathBuf>,
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
    /// Let --export / --export-dir write into a folder that holds things other than a previous
    /// export (the export's own file names in it are replaced; links are replaced, never
    /// followed).
    #[arg(long)]
    pub force: bool,
    /// The export's first products, `ID:PRODUCT,…` (a product's name, a unique part of it, or
    /// its registry id); the served page takes them as its `glass` URL parameter.
    #[arg(long, value_name = "ID:PRODUCT,...")]
    pub glass: Option<String>,
    /// The export's first exposure, in stops.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub ev: f64,
}

pub fn run(mut args: Args) -> anyhow::Result<ExitCode> {
    let (registry, label) = match &args.catalog {
        Some(catalog) => (
            registry_from_catalog(catalog)?,
            catalog.display().to_string(),
        ),
        None => load_registry(args.registry.as_deref())?,
    };
    let catalog_inputs = match &args.catalog {
        Some(c) => glassdb_registry::catalog_inputs(c).map_err(anyhow::Error::new)?,
        None => Vec::new(),
    };
    // The catalog's files: no export may replace one.
    glassdb_io::declare_inputs(catalog_inputs.iter().map(PathBuf::as_path));
    let (frames, settings) = match (&args.run_dir, &mut args.inputs) {
        (Some(dir), _) => (
            blender_run_frames(dir)?,
            DecodeSettings {
                registry_label: label,
                ..DecodeSettings::default()
            },
        ),
        (None, Some(inputs)) => {
            inputs.expand_plane_layers()?;
            let settings =
                inputs.decode_settings(OutsidePolicy::Error, UnknownIds::Error, label)?;
            let frames = ViewerFrame::sequence(
                &inputs.files(),
                &inputs.frame_numbers()?,
                &inputs.plane_sides()?,
            )?;
            (frames, settings)
        }
        (None, None) => bail!(
            "nothing to view: give a `glassdb blender render` output folder, or the passes and the mask (--trans, --refl, --mask)"
        ),
    };
    let viewer = Viewer::open(ViewerInputs {
        frames,
        settings,
        registry,
        display_views: args
            .view
            .iter()
            .map(|p| CubeLut::read(p))
            .collect::<Result<_, _>>()?,
        unit_catalog: unit_catalog(args.catalog.as_deref()),
    })?;
    let choices = match &args.glass {
        Some(spec) => viewer.parse_choices(spec).context("--glass")?,
        None => Vec::new(),
    };
    let folder = |dir: &PathBuf| ExportFolder {
        dir: dir.clone(),
        force: args.force,
    };
    if let Some(dir) = &args.export {
        let summary =
            glassdb_view::export::write_export(&viewer, &folder(dir), &choices, args.ev, &[])?;
        outln!(
            "wrote {} ({} files, {:.2} MB)",
            dir.join("index.html").display(),
            summary.files,
            summary.bytes as f64 / 1e6
        );
        return Ok(ExitCode::SUCCESS);
    }
    let export = args.export_dir.as_ref().map(folder);
    if let Some(export) = &export {
        export.check().context("--export-dir")?;
    }
    let server = ViewServer::bind(viewer, &args.bind, args.port, export)?;
    if server.reachable_from_other_machines() {
        eprintln!(
            "warning: --bind {} can be reached from other machines: anyone who reaches this \
             port sees the frames and the paths of the inputs{}. Serve 127.0.0.1 (the default) \
             unless this network is trusted.",
            args.bind,
            if args.export_dir.is_some() {
                ", and with the page's token can write the export folder"
            } else {
                ""
            }
        );
    }
    let query = if choices.is_empty() {
        String::new()
    } else {
        // The --glass text as given: the page resolves the names itself.
        format!(
            "?glass={}",
            percent_encode(args.glass.as_deref().unwrap_or_default())
        )
    };
    outln!("serving {}{query}", server.url());
    outln!("(Ctrl-C stops the viewer)");
    server.run();
    Ok(ExitCode::SUCCESS)
}

/// The frames of a `glassdb blender render` output folder, from its run record: each frame's
/// passes, mask and sides (the camera may see a plane from either side as it moves).
fn blender_run_frames(dir: &Path) -> anyhow::Result<Vec<ViewerFrame>> {
    let record_path = dir.join(glassdb_blender::job::RECORD_NAME);
    if !dir.is_dir() {
        bail!(
            "{}: no such folder (glassdb view DIR opens a `glassdb blender render` output folder)",
            dir.display()
        );
    }
    if !record_path.is_file() {
        bail!(
            "{} holds no {}: it is not a `glassdb blender render` output folder (to view passes, give --trans, --refl and --mask)",
            dir.display(),
            glassdb_blender::job::RECORD_NAME
        );
    }
    let record = glassdb_blender::RunRecord::load(dir)?;
    // A product change on the page is a glass swap: say what it cannot change (issue 28).
    if record.frames.iter().any(|f| f.light_parts.is_none()) {
        eprintln!(
            "note: {}'s passes keep no light-path split: a product chosen on the page re-tints the glass pixels only; the light that came into the scene through the glazing stays that of the glasses the passes were rendered with",
            dir.display()
        );
    }
    if record.frames.is_empty() {
        bail!(
            "{}: the run records no frame",
            dir.join(glassdb_blender::job::RECORD_NAME).display()
        );
    }
    record
        .frames
        .iter()
        .map(|f| {
            Ok(ViewerFrame {
                label: f.frame.to_string(),
                files: FrameFiles {
                    refl: f.refl.iter().map(|r| dir.join(r)).collect(),
                    // units' deeper pane groups: the page composites each with its share
                    groups: f.group_pass_files(dir),
                    trans: dir.join(&f.trans),
                    mask: dir.join(&f.mask),
                },
                plane_sides: f.sides.iter().copied().enumerate().collect(),
                // the frame's light parts: a product change then relights the room too
                light_parts: f
                    .light_parts
                    .as_ref()
                    .map(|name| glassdb_compose::read_light_parts(&dir.join(name)))
                    .transpose()?,
            })
        })
        .collect()
}

/// The catalog the page builds units from: --catalog, else the bundled catalog where this
/// glassdb was built from (none when that source tree is gone: the page then builds no units).
fn unit_catalog(catalog: Option<&Path>) -> Option<PathBuf> {
    match catalog {
        Some(c) => Some(c.to_path_buf()),
        None => {
            let bundled = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/catalog.toml");
            bundled.is_file().then_some(bundled)
        }
    }
}

/// A registry built from `catalog` with the bundled registry's tables: its spectral method in
/// each of its spaces, so that passes in any of those spaces find their table.
fn registry_from_catalog(catalog: &Path) -> anyhow::Result<glassdb_registry::Registry> {
    let bundled = glassdb_registry::default_registry()?;
    let opts = glassdb_registry::BuildOptions::with_tables_of(&bundled);
    glassdb_registry::build_registry(catalog, &opts)
        .map_err(anyhow::Error::new)
        .with_context(|| format!("building the candidates from {}", catalog.display()))
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
