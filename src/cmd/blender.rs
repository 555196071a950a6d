//! `glassdb blender render` / `glassdb blender compose`: a .blend scene to composited glazing
//! (docs/blender.md). The work is in `glassdb-blender`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use clap::{Args as ClapArgs, Subcommand};
use glassdb_blender::{ComposeReport, RegistryChoice, RenderRequest};

use crate::cmd::progress::Spinner;

#[derive(ClapArgs, Debug)]
pub struct Args {
    #[command(subcommand)]
    pub command: BlenderCommand,
}

#[derive(Subcommand, Debug)]
pub enum BlenderCommand {
    /// Render a .blend file's passes with Blender (headless) and composite every frame into
    /// DIR/composite.####.exr.
    Render(Box<RenderArgs>),
    /// Composite an existing `glassdb blender render` output again (other glasses), without
    /// Blender.
    Compose(ComposeArgs),
}

#[derive(ClapArgs, Debug)]
pub struct RenderArgs {
    /// The Blender scene.
    pub blend: PathBuf,
    /// Glass materials and their registry ids, `PATTERN=ID` (e.g. 'Glass_6mm*=1'); repeatable,
    /// first match wins.
    #[arg(long, required = true)]
    pub glass: Vec<String>,
    /// Frames (`1-24`, `1,5,10-20`); default: the scene's frame range.
    #[arg(long)]
    pub frames: Option<String>,
    /// Directory for the passes, masks, planes.json, cameras and composites.
    #[arg(long)]
    pub out_dir: PathBuf,
    /// Cycles samples per pixel (default: the scene's).
    #[arg(long)]
    pub samples: Option<u32>,
    /// Image size `WxH` (default: the scene's resolution × %).
    #[arg(long)]
    pub resolution: Option<String>,
    /// The Blender program (default: `blender` on PATH); 3.4 or newer.
    #[arg(long)]
    pub blender: Option<PathBuf>,
    /// Run Blender as the `bpy` module of this Python interpreter (PyPI `bpy` 4.2–5.0 on
    /// Python 3.11) instead of a Blender executable.
    #[arg(long, value_name = "PYTHON", conflicts_with = "blender")]
    pub bpy_python: Option<PathBuf>,
    /// Registry JSON (default: the bundled one).
    #[arg(long)]
    pub registry: Option<PathBuf>,
    /// Longest time one Blender run (export, passes) may take, in seconds.
    #[arg(long, default_value_t = 3600)]
    pub timeout_s: u64,
    /// Cycles seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Blender's render threads (default: Blender's choice).
    #[arg(long)]
    pub threads: Option<u32>,
    /// K×K rays per pixel for the masks' glass coverage at pane edges, which compose blends
    /// by (1: the pixel centre only, no coverage: edge pixels all glass or none).
    #[arg(long, default_value_t = glassdb_blender::DEFAULT_MASK_SAMPLES)]
    pub mask_samples: u32,
    /// Also render the Cycles reference (the glass as a thin pane the camera sees, no passes)
    /// as DIR/reference.####.exr, for validation.
    #[arg(long)]
    pub reference: bool,
    /// Keep the light's path apart in the passes (`on`, the default): Cycles light groups for
    /// the sun, sky and other emitters, and each pass rendered once per aperture (the glass of
    /// one id on one plane) plus once with all glazing opaque to light, so that a swap
    /// (`glassdb blender compose DIR --registry B.json`) relights the room: (A+1)(1+P) renders
    /// per frame instead of 1+P for A apertures and P reflection passes. `off`: each pass once,
    /// lit through the render's glass (a swap leaves the room lit by it).
    #[arg(long, value_enum, default_value_t = LightSplit::On)]
    pub light_split: LightSplit,
    /// Leave the lamps out of the reflection passes (each pass sees them as the scene's
    /// camera visibility says), as before they were shown there as the glass reflects them.
    #[arg(long)]
    pub no_lamps_in_reflections: bool,
    /// Stop after the passes, masks and run record: `glassdb blender compose DIR` composites
    /// them (a farm's render step, then its composite step).
    #[arg(long)]
    pub no_composite: bool,
    /// N: render at most N of a unit's pane groups as reflection passes of their own (default:
    /// all: each pane's reflection at its depth, the double image); `--surfaces 1` renders one
    /// pass per plane, the deeper panes' reflectance added to it (faster, no double image).
    #[arg(long, value_name = "N")]
    pub surfaces: Option<std::num::NonZeroUsize>,
    /// The spectrum of one of the scene's Cycles light groups, `GROUP=ILLUMINANT` (a CIE
    /// illuminant as `registry build --light` takes it, or an SPD CSV file); repeatable. Every
    /// group needs one, or a `glassdb_light` custom property on one of its lamps or its world;
    /// each group is composited with the registry's table of its light. A scene without light
    /// groups is one light.
    #[arg(long = "light", value_name = "GROUP=ILLUMINANT")]
    pub lights: Vec<String>,
}

/// `--light-split`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSplit {
    On,
    Off,
}

#[derive(ClapArgs, Debug)]
pub struct ComposeArgs {
    /// The output directory of `glassdb blender render`.
    pub dir: PathBuf,
    /// Registry JSON (default: the bundled one).
    #[arg(long)]
    pub registry: Option<PathBuf>,
}

/// `--registry`, or the bundled catalog, as `glassdb compose` loads and names it.
fn registry_choice(path: &Option<PathBuf>) -> anyhow::Result<RegistryChoice> {
    let (registry, label) = crate::cmd::compose::load_registry(path.as_deref())?;
    Ok(RegistryChoice { registry, label })
}

fn parse_resolution(text: &str) -> anyhow::Result<(u32, u32)> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .with_context(|| format!("--resolution {text}: give WxH, e.g. 320x240"))?;
    let size = |s: &str| -> anyhow::Result<u32> {
        let v: u32 = s
            .trim()
            .parse()
            .with_context(|| format!("--resolution {text}: {s:?} is not a whole number"))?;
        anyhow::ensure!(v > 0, "--resolution {text}: sizes must be at least 1");
        Ok(v)
    };
    let (w, h) = (size(w)?, size(h)?);
    glassdb_scene::camera::check_image_size(w, h)?;
    Ok((w, h))
}

fn print_composites(dir: &std::path::Path, report: &ComposeReport) {
    for (frame, f) in &report.frames {
        let glass: u64 = f.id_counts.values().sum();
        outln!(
            "frame {frame}: {}x{}, {glass} glass pixels on {} plane(s) -> {}",
            f.width,
            f.height,
            f.planes,
            f.output.path.display()
        );
    }
    outln!(
        "composited {} frame(s) in {} in {:.3} s",
        report.frames.len(),
        dir.display(),
        report.seconds
    );
    for w in &report.swap {
        eprintln!("warning: {w}");
    }
    if let Some(note) = &report.lights.one_table {
        outln!("lights: {note}");
    } else if !report.lights.groups.is_empty() {
        outln!(
            "lights: each light group composited with its registry light's tables ({})",
            report
                .lights
                .groups
                .iter()
                .map(|(g, l)| format!("{g} -> {}", l.as_deref().unwrap_or("the default light")))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    crate::cmd::relight::print_blender_factors(&report.light_parts);
}

/// What the run did with units' pane groups (issue 27): the group passes rendered, and what
/// `--surfaces` folded into a nearer group's pass.
fn print_pane_groups(report: &glassdb_blender::RenderReport) {
    let passes: usize = report.record.frames.iter().map(|f| f.groups.len()).sum();
    if passes > 0 {
        outln!(
            "pane groups: {passes} reflection pass(es) of units' deeper panes, each mirrored about its pane's mid-plane (the double image)"
        );
    }
    let folded: u64 = report
        .compose
        .frames
        .iter()
        .map(|(_, f)| f.folded_pixels)
        .sum();
    let Some(n) = report.record.surfaces else {
        return;
    };
    // Composited: say it only where units' panes were folded; otherwise compose folds later.
    if folded > 0 || report.compose.frames.is_empty() {
        let pixels = if folded > 0 {
            format!(" ({folded} glass pixels)")
        } else {
            String::new()
        };
        outln!(
            "pane groups: --surfaces {n}: a unit's panes beyond the first {n} get no pass of their own; their reflectance is added to pane {n}'s pass{pixels}, so there is no double image there"
        );
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.command {
        BlenderCommand::Render(a) => run_render(*a),
        BlenderCommand::Compose(a) => {
            let registry = registry_choice(&a.registry)?;
            let report = glassdb_blender::compose_dir(&a.dir, &registry)?;
            print_composites(&a.dir, &report);
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn run_render(a: RenderArgs) -> anyhow::Result<ExitCode> {
    let registry = registry_choice(&a.registry)?;
    let frames = a
        .frames
        .as_deref()
        .map(glassdb_io::parse_frame_list)
        .transpose()?;
    anyhow::ensure!(a.samples != Some(0), "--samples must be at least 1");
    let request = RenderRequest {
        blend: a.blend,
        glass: a.glass,
        frames,
        out_dir: a.out_dir.clone(),
        samples: a.samples,
        resolution: a.resolution.as_deref().map(parse_resolution).transpose()?,
        blender: a.blender,
        bpy_python: a.bpy_python,
        timeout: Duration::from_secs(a.timeout_s.max(1)),
        seed: a.seed,
        threads: a.threads,
        reference: a.reference,
        lamps_in_reflections: !a.no_lamps_in_reflections,
        mask_samples: a.mask_samples,
        light_split: a.light_split == LightSplit::On,
        composite: !a.no_composite,
        surfaces: a.surfaces,
        lights: a
            .lights
            .iter()
            .map(|l| glassdb_registry::NamedLight::parse(l))
            .collect::<Result<_, _>>()
            .context("--light")?,
    };
    let spinner = Spinner::on_terminal("blender");
    let report = glassdb_blender::render(&request, &registry, &spinner)?;
    spinner.finish();
    outln!(
        "Blender {} ({}): {} frame(s), {} glass plane(s); glass materials {}",
        report.blender.version,
        report.blender.path.display(),
        report.record.frames.len(),
        report.planes,
        report
            .glass_materials
            .iter()
            .map(|(m, id)| format!("{m}={id}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let (renders, unsplit) = report.renders;
    if request.light_split {
        outln!(
            "passes: light split: {renders} Blender renders ({unsplit} with --light-split off, \
             whose swaps leave the room lit by the rendered glass)"
        );
    }
    if !report.record.lights.is_empty() {
        outln!(
            "lights: the scene's light groups {}{}",
            glassdb_blender::scene_lights::describe_lights(&report.record.lights),
            if report.record.group_layers {
                "; every pass holds a ViewLayer.Combined_<group> layer per group"
            } else {
                "; each light-split source split by them"
            }
        );
    }
    for o in &report.record.overrides {
        outln!("passes: {o}");
    }
    print_pane_groups(&report);
    if request.composite {
        print_composites(&a.out_dir, &report.compose);
    } else {
        outln!(
            "passes, masks and {} ready in {}; composite with: glassdb blender compose {}",
            glassdb_blender::job::RECORD_NAME,
            a.out_dir.display(),
            a.out_dir.display()
        );
    }
    outln!(
        "Blender export {:.2} s, passes {:.2} s{}; planes and masks {:.3} s",
        report.export_s,
        report.render.wall_s,
        if request.reference {
            format!(", reference {:.2} s", report.reference.wall_s)
        } else {
            String::new()
        },
        report.mask_s
    );
    if let Some(cpu) = report.render.cpu_s {
        out!("Blender CPU: passes {cpu:.2} s");
        if let Some(r) = report.reference.cpu_s {
            out!(", reference {r:.2} s");
        }
        outln!();
    }
    Ok(ExitCode::SUCCESS)
}
