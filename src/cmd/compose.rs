//! `compose` / `glassdb compose`: reflection and transmission passes through an id + cos θ mask
//! (docs/compose.md). All logic lives in `glassdb_compose`; this module parses arguments,
//! prints the report and drives the progress display (stages of one frame, or a bar over the
//! frames of a sequence).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::bail;
use glassdb_colour::DisplayView;
use glassdb_compose::colour::{RegistryLuts, SpaceSource};
use glassdb_compose::{
    ComposeJob, ComposeSettings, FrameReport, OutsidePolicy, UnknownIds,
    compose_frame_with_progress,
};
use glassdb_encode::{ExrDataType, OutputOptions, parse_exr_compression};
use glassdb_pass::PngBits;
use glassdb_registry::{ColourBasis, Registry};
use glassdb_sequence::{
    FrameDone, FrameOutcome, FrameTables, FramesReport, SequenceOptions, SequenceProgress,
};

use crate::cmd::inputs::FrameInputArgs;
use crate::cmd::progress::Spinner;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub inputs: FrameInputArgs,
    /// Registry JSON (`glassdb registry build`); default: the bundled data/registry.json (built
    /// from data/catalog.toml).
    #[arg(long, value_name = "JSON")]
    pub registry: Option<PathBuf>,
    /// Output, .exr or .png (required: a default beside the passes would write into a render
    /// or source folder); with --frames, a pattern with ####.
    #[arg(short, long, value_name = "FILE", required = true)]
    pub output: PathBuf,
    /// Glass pixels of a plane that its (cropped) reflection pass does not cover: refuse
    /// (`error`), composite them without reflection (`no-reflection`), or leave them as the
    /// transmission pass (`transmission`).
    #[arg(long, value_enum, default_value_t = OutsideArg::Error)]
    pub outside_pass: OutsideArg,
    /// EXR output: keep the transmission file's other channels and parts (`all`: Z, AOVs,
    /// other views) or write only the composite (`none`). Its attributes are always kept.
    #[arg(long, value_enum, default_value_t = KeepArg::All)]
    pub keep_channels: KeepArg,
    /// EXR output: write the composite as a new layer NAME (`NAME.R`, …) beside the original
    /// channels instead of replacing the transmission pass's RGB.
    #[arg(long, value_name = "NAME")]
    pub output_layer: Option<String>,
    /// Composite a frame split by light: each light group's layers (Cycles'
    /// `ViewLayer.Combined_GROUP`, V-Ray's `VRayLightSelect_GROUP`, Corona's
    /// `CShading_LightSelect_GROUP`, or `LightSelect_GROUP`) in every pass, with the registry's
    /// table of the light of the same name (`glassdb registry build --light GROUP=…`), and
    /// write the sum (docs/compose.md, "Light groups")
    #[arg(long, value_name = "GROUP,...", value_delimiter = ',')]
    pub light_groups: Vec<String>,
    /// Composite a frame whose passes keep the light's path apart with its light parts
    /// (`light_parts.json`, written by `glassdb blender render`): each part scaled by what the
    /// glass of the aperture it came through passes, so that a swap relights the room
    /// (docs/compose.md, "Relit swap"); with --frames, a pattern with ####
    #[arg(long, value_name = "FILE", conflicts_with = "light_groups")]
    pub light_parts: Option<PathBuf>,
    /// With --light-groups, EXR output: also write each group's composite as a layer of its
    /// group's name, so that the lights can still be balanced afterwards
    #[arg(long, requires = "light_groups")]
    pub keep_groups: bool,
    /// Read the mask as the paper's binary mask (white = glass, black = not) showing glass ID
    /// at its normal-incidence values.
    #[arg(long, value_name = "ID")]
    pub glass: Option<u16>,
    /// Mask ids with no registry entry: refuse (`error`) or leave the pixels as the
    /// transmission pass (`passthrough`).
    #[arg(long, value_enum, default_value_t = UnknownArg::Error)]
    pub unknown: UnknownArg,
    /// EXR output sample type (default: the transmission pass's).
    #[arg(long, value_enum)]
    pub data_type: Option<DataTypeArg>,
    /// EXR output compression: none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab
    /// (default zip).
    #[arg(long, value_name = "NAME")]
    pub compression: Option<String>,
    /// zlib level of zip and zips EXR output: 1 is fastest (files about 5 % larger), 9 smallest
    /// [default: 4, OpenEXR's].
    #[arg(long, value_name = "0-9", value_parser = clap::value_parser!(u32).range(0..=9))]
    pub zip_level: Option<u32>,
    /// PNG output bits per sample (default: the transmission pass's, 8 for EXR input).
    #[arg(long, value_parser = ["8", "16"])]
    pub png_bits: Option<String>,
    /// View transform of PNG output: `standard` (the sRGB transfer, clipped) or a `.cube` LUT
    /// (1D, 3D, or a 1D shaper then 3D, e.g. AgX, Filmic or ACES baked by `ociobakelut --format
    /// resolve_cube`; docs/colour.md) whose output is display-encoded. EXR output stays
    /// scene-linear, so --view with a .exr output is refused. [default: standard]
    #[arg(long, value_name = "standard|FILE.cube")]
    pub view: Option<String>,
    /// Dither for 8-bit PNG output.
    #[arg(long, value_enum, default_value_t = DitherArg::Ordered)]
    pub dither: DitherArg,
    /// With --frames: leave a frame whose output already exists and is complete (a regular
    /// file that decodes whole), so that a rerun composites only what is missing
    /// (docs/farm.md).
    #[arg(long, requires = "frames")]
    pub skip_existing: bool,
    /// With --frames: write a JSON report of every frame (status, inputs, output, seconds,
    /// error) to FILE, atomically, also when frames fail (docs/farm.md).
    #[arg(long, value_name = "FILE.json", requires = "frames")]
    pub report: Option<PathBuf>,
    /// Print per-stage timings, megapixels per second, per-id pixel counts and the cos θ range.
    #[arg(long)]
    pub stats: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum OutsideArg {
    Error,
    NoReflection,
    Transmission,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum KeepArg {
    All,
    None,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum UnknownArg {
    Error,
    Passthrough,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DataTypeArg {
    Half,
    Float,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DitherArg {
    Ordered,
    None,
}

/// The registry at `path`, or the bundled one, with the label outputs and messages name it by.
pub fn load_registry(path: Option<&Path>) -> anyhow::Result<(Registry, String)> {
    Ok(match path {
        Some(p) => (
            Registry::from_json_file(p).map_err(anyhow::Error::new)?,
            p.display().to_string(),
        ),
        None => (
            glassdb_registry::default_registry()?,
            "the bundled catalog".to_string(),
        ),
    })
}

fn settings_from(args: &Args) -> anyhow::Result<(ComposeSettings, RegistryLuts)> {
    let (registry, label) = load_registry(args.registry.as_deref())?;
    let luts = RegistryLuts::new(&registry);
    if let Some(id) = args.glass
        && registry.default_table().glass(id).is_none()
    {
        bail!("--glass {id}: {label} has no glass with id {id}");
    }
    let output = output_options(args, &registry, &label)?;
    let outside = match args.outside_pass {
        OutsideArg::Error => OutsidePolicy::Error,
        OutsideArg::NoReflection => OutsidePolicy::NoReflection,
        OutsideArg::Transmission => OutsidePolicy::Transmission,
    };
    let unknown = match args.unknown {
        UnknownArg::Error => UnknownIds::Error,
        UnknownArg::Passthrough => UnknownIds::Passthrough,
    };
    let mut decode = args.inputs.decode_settings(outside, unknown, label)?;
    // A binary mask's glass (--glass).
    decode.mask.binary_glass_id = args.glass;
    let settings = ComposeSettings {
        decode,
        plane_sides: args.inputs.plane_sides()?,
        output,
    };
    Ok((settings, luts))
}

/// How the composite is written: the encoding flags, the view, and glassdb's provenance (its
/// version, the registry and its hash).
fn output_options(args: &Args, registry: &Registry, label: &str) -> anyhow::Result<OutputOptions> {
    let registry_sha256 = registry.content_sha256()?;
    Ok(OutputOptions {
        exr_data_type: args.data_type.map(|d| match d {
            DataTypeArg::Half => ExrDataType::Half,
            DataTypeArg::Float => ExrDataType::Float,
        }),
        exr_compression: args
            .compression
            .as_deref()
            .map(parse_exr_compression)
            .transpose()?,
        exr_zip_level: args.zip_level,
        png_bits: args.png_bits.as_deref().map(|b| {
            if b == "16" {
                PngBits::Sixteen
            } else {
                PngBits::Eight
            }
        }),
        dither: args.dither == DitherArg::Ordered,
        view: args
            .view
            .as_deref()
            .map(DisplayView::from_arg)
            .transpose()?,
        keep_channels: args.keep_channels == KeepArg::All,
        output_layer: args.output_layer.clone(),
        provenance: vec![
            (
                "glassdb/version".to_string(),
                env!("CARGO_PKG_VERSION").to_string(),
            ),
            ("glassdb/registry".to_string(), label.to_string()),
            ("glassdb/registrySha256".to_string(), registry_sha256),
        ],
    })
}

pub(crate) fn print_stats(r: &FrameReport, luts: &RegistryLuts, limit: u64) {
    let colour = &r.colour;
    let Some(lut) = luts.get(colour.table.basis) else {
        return;
    };
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let t = &r.timings;
    outln!(
        "image        {}×{} ({:.2} Mpixel), {} reflection pass(es)",
        r.width,
        r.height,
        f64::from(r.width) * f64::from(r.height) / 1e6,
        r.planes
    );
    if r.group_passes > 0 {
        outln!(
            "pane groups  {} reflection pass(es) of units' deeper pane groups",
            r.group_passes
        );
    }
    if r.folded_pixels > 0 {
        outln!(
            "pane groups  {} pixels of units composited with their deeper pane groups' reflectance on a nearer group's pass (--surfaces): no double image there",
            r.folded_pixels
        );
    }
    if r.windows.data != r.windows.display {
        outln!(
            "windows      data {} in display {}",
            r.windows.data,
            r.windows.display
        );
    }
    outln!(
        "memory       about {} at once, estimated from the headers (limit {})",
        glassdb_compose::memory::format_bytes(r.memory.total),
        glassdb_compose::memory::format_bytes(limit)
    );
    if r.output.kept_channels > 0 {
        outln!(
            "kept         {} other channel(s) of the transmission file",
            r.output.kept_channels
        );
    }
    let table_note = match colour.table.basis {
        ColourBasis::Luminous => " (grey: the same in every space)",
        ColourBasis::PaperRgb => " (the paper's CIE 1931 RGB, not a renderer's space)",
        ColourBasis::Space(_) => "",
    };
    // The passes' space as the command line names how it was known.
    let source = match &colour.space.source {
        SpaceSource::Declared => "--input-space".to_string(),
        other => other.to_string(),
    };
    outln!(
        "colour       passes in {} ({source}); registry table {}{table_note}",
        glassdb_compose::colour::space_label(colour.space.space),
        colour.table.basis
    );
    if colour.converted_for_display {
        outln!(
            "             PNG converted from {} to linear Rec.709 (CAT02) for the standard view",
            glassdb_compose::colour::space_label(colour.space.space)
        );
    }
    outln!(
        "decode       {:9.1} ms  (all inputs, in parallel)",
        ms(t.decode)
    );
    outln!("compose      {:9.1} ms", ms(t.compose));
    outln!(
        "encode       {:9.1} ms  ({}, {} bytes)",
        ms(t.encode),
        r.output.encoding,
        r.output.bytes
    );
    outln!(
        "total        {:9.1} ms  ({:.1} Mpixel/s)",
        ms(t.total()),
        r.megapixels_per_second()
    );
    let glass: u64 = r.id_counts.values().sum();
    outln!("glass pixels {glass}");
    for (id, n) in &r.id_counts {
        let known = if lut.contains(*id) {
            ""
        } else {
            "  (not in registry: passed through)"
        };
        outln!("  id {id:5}   {n} pixels{known}");
    }
    match r.cos_range {
        Some((lo, hi)) => outln!(
            "cos θ        {lo:.4} – {hi:.4}  (θ {:.1}° – {:.1}°)",
            hi.clamp(-1.0, 1.0).acos().to_degrees(),
            lo.clamp(-1.0, 1.0).acos().to_degrees()
        ),
        None => outln!("cos θ        (no glass pixels)"),
    }
    outln!(
        "fine-table interpolation error (16-bit/float masks): {:.2e}",
        lut.fine_table_error
    );
}

fn report_nonfinite(r: &FrameReport, label: &str) {
    if r.output.half_overflow > 0 {
        let first = r
            .output
            .first_half_overflow
            .as_ref()
            .map_or(String::new(), |s| {
                format!(
                    " (the first at pixel ({}, {}), channel {}: {})",
                    s.x,
                    s.y,
                    glassdb_io::quoted(&s.channel),
                    s.value
                )
            });
        eprintln!(
            "warning: {label}{} output samples exceed the half-float range and were clamped to ±65504, the largest half{first}; write float (--data-type float) to keep them",
            r.output.half_overflow
        );
    }
    if r.outside_pixels > 0 {
        eprintln!(
            "warning: {label}{} glass pixels lie outside their plane's reflection pass (composited as --outside-pass says)",
            r.outside_pixels
        );
    }
    let c = &r.counts;
    if c.nonfinite_output > 0 {
        eprintln!(
            "warning: {label}{} output samples are NaN or infinite ({} from the transmission pass, {} from reflection passes); they are kept, not hidden",
            c.nonfinite_output, c.nonfinite_trans, c.nonfinite_refl
        );
    }
}

pub fn run(mut args: Args) -> anyhow::Result<ExitCode> {
    args.inputs.expand_plane_layers()?;
    let (settings, luts) = settings_from(&args)?;
    let job = ComposeJob {
        inputs: args.inputs.files(),
        output: args.output.clone(),
    };
    if let Some(record) = &args.light_parts {
        return crate::cmd::relight::run(&args, record, &job, &settings, &luts);
    }
    if !args.light_groups.is_empty() {
        return run_light_groups(&args, &job, &settings);
    }
    let first = match &args.inputs.frames {
        Some(spec) => glassdb_io::parse_frame_list(spec)?
            .first()
            .map(|&f| job.for_frame(f))
            .transpose()?,
        None => Some(job.clone()),
    };
    let unsplit = first.is_some_and(|first| {
        crate::cmd::relight::warn_split(&first.inputs.trans, settings.decode.pass.max_pixels)
    });
    let code = match &args.inputs.frames {
        None => run_frame(&args, &job, &settings, &luts),
        Some(spec) => run_sequence(&args, spec, &job, &settings, FrameTables::One(&luts)),
    }?;
    // after the output: a closed standard output must not stop it being written
    if args.stats && unsplit {
        crate::cmd::relight::print_unsplit_note();
    }
    Ok(code)
}

/// A frame split by light (`--light-groups`), each group with its light's tables; with
/// `--frames`, every frame of the patterns so.
fn run_light_groups(
    args: &Args,
    job: &ComposeJob,
    settings: &ComposeSettings,
) -> anyhow::Result<ExitCode> {
    let (registry, label) = load_registry(args.registry.as_deref())?;
    let groups = glassdb_compose::LightGroup::from_registry(&registry, &args.light_groups, &label)?;
    if let Some(spec) = &args.inputs.frames {
        let tables = FrameTables::LightGroups {
            groups: &groups,
            keep_groups: args.keep_groups,
        };
        return run_sequence(args, spec, job, settings, tables);
    }
    let spinner = Spinner::on_terminal("compose");
    let report =
        glassdb_compose::compose_light_groups(job, settings, &groups, args.keep_groups, &spinner)?;
    spinner.finish();
    report_nonfinite(&report, "");
    outln!(
        "wrote {} ({}×{}, {}; light groups {})",
        report.output.path.display(),
        report.width,
        report.height,
        report.output.encoding,
        args.light_groups.join(", ")
    );
    Ok(ExitCode::SUCCESS)
}

/// One frame, with a spinner naming its stage.
fn run_frame(
    args: &Args,
    job: &ComposeJob,
    settings: &ComposeSettings,
    luts: &RegistryLuts,
) -> anyhow::Result<ExitCode> {
    let spinner = Spinner::on_terminal("compose");
    let report = compose_frame_with_progress(job, settings, luts, &spinner)?;
    spinner.finish();
    report_nonfinite(&report, "");
    if args.stats {
        print_stats(&report, luts, settings.decode.max_memory);
    }
    outln!(
        "wrote {} ({}×{}, {})",
        report.output.path.display(),
        report.width,
        report.height,
        report.output.encoding
    );
    Ok(ExitCode::SUCCESS)
}

/// A bar over the frames of a sequence, on a terminal's stderr only.
fn frames_bar(frames: usize) -> Option<indicatif::ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new(frames as u64);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{bar:40} {pos}/{len} frames, {elapsed} elapsed, ETA {eta}",
    ) {
        bar.set_style(style);
    }
    Some(bar)
}

/// What a finished frame of a sequence says on stderr (besides its warnings, printed here):
/// why it was composited again, or its error.
fn frame_line(o: &FrameOutcome) -> Option<String> {
    match &o.result {
        Ok(FrameDone::Composed { report, replaced }) => {
            report_nonfinite(report, &format!("frame {}: ", o.frame));
            replaced
                .as_ref()
                .map(|why| format!("frame {}: composited again: {why}", o.frame))
        }
        Ok(FrameDone::Skipped) => None,
        Err(e) => Some(format!(
            "frame {}: error: {}",
            o.frame,
            glassdb_io::ErrorChain(e)
        )),
    }
}

/// Every frame of `spec`, two in flight, with a bar; the report when asked.
fn run_sequence(
    args: &Args,
    spec: &str,
    job: &ComposeJob,
    settings: &ComposeSettings,
    tables: FrameTables<'_>,
) -> anyhow::Result<ExitCode> {
    let frames = glassdb_io::parse_frame_list(spec)?;
    let bar = frames_bar(frames.len());
    let on_done = |o: &FrameOutcome| {
        match (&bar, frame_line(o)) {
            (Some(b), Some(l)) => b.println(l),
            (None, Some(l)) => eprintln!("{l}"),
            _ => {}
        }
        if let Some(b) = &bar {
            b.inc(1);
        }
    };
    if let Some(report) = &args.report {
        // The report is an output like the frames: it may not replace an input.
        glassdb_io::declare_inputs(job.inputs.paths());
        glassdb_io::refuse_input_as_output(report)?;
    }
    let options = SequenceOptions {
        skip_existing: args.skip_existing,
    };
    let progress = std::sync::Arc::new(SequenceProgress::new(job, &frames));
    // A stop by a signal still writes the report: what was finished, what it interrupted.
    let _report_on_stop = args
        .report
        .clone()
        .map(|path| glassdb_io::on_stop(report_on_stop(path, progress.clone())));
    let outcomes = glassdb_sequence::compose_sequence(
        job, &frames, settings, tables, options, &progress, &on_done,
    )?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    if let Some(report) = &args.report {
        FramesReport::from_outcomes(&outcomes).write(report)?;
    }
    report_sequence(args, &outcomes, frames.len(), tables, settings)
}

/// Writes the frames report of a sequence stopped by a signal (the exit code's).
fn report_on_stop(
    path: PathBuf,
    progress: std::sync::Arc<SequenceProgress>,
) -> impl FnOnce(i32) + Send {
    move |code| {
        let signal = super::stop_signal_name(code);
        let report = progress.stopped_report(signal);
        match report.write(&path) {
            Ok(()) => eprintln!(
                "wrote {} (stopped by {signal}: {} frame(s) composed, {} skipped, {} failed, interrupted: {:?})",
                path.display(),
                report.composed,
                report.skipped,
                report.failed.len(),
                report.interrupted
            ),
            Err(e) => eprintln!(
                "error: cannot write the frames report: {}",
                glassdb_io::ErrorChain(&e)
            ),
        }
    }
}

/// The end of a sequence: each frame's stats when asked, what was written and skipped, and
/// the exit code (the failed frames listed).
fn report_sequence(
    args: &Args,
    outcomes: &[FrameOutcome],
    requested: usize,
    tables: FrameTables<'_>,
    settings: &ComposeSettings,
) -> anyhow::Result<ExitCode> {
    let failed: Vec<u32> = outcomes
        .iter()
        .filter(|o| o.result.is_err())
        .map(|o| o.frame)
        .collect();
    let done: Vec<&FrameReport> = outcomes.iter().filter_map(FrameOutcome::report).collect();
    let skipped = outcomes
        .iter()
        .filter(|o| matches!(o.result, Ok(FrameDone::Skipped)))
        .count();
    if let (true, Some(luts)) = (args.stats, tables.report_luts()) {
        for o in outcomes {
            if let Some(r) = o.report() {
                outln!("--- frame {}", o.frame);
                print_stats(r, luts, settings.decode.max_memory);
            }
        }
    }
    if let (Some(first), Some(last)) = (done.first(), done.last()) {
        outln!(
            "wrote {} frame(s): {} … {}",
            done.len(),
            first.output.path.display(),
            last.output.path.display()
        );
    }
    if skipped > 0 {
        outln!("skipped {skipped} frame(s) whose output is complete");
    }
    Ok(crate::cmd::frames_exit(&failed, requested))
}
