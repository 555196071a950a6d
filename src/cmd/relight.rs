//! `glassdb compose --light-parts FILE`: a frame (or each frame of --frames) composited with its
//! light parts, so that a swap relights the room (docs/compose.md, "Relit swap"). All logic
//! lives in `glassdb_compose` ([`glassdb_compose::compose_light_parts`]); this module reads the
//! record per frame, prints each part's factors under --stats, and says when passes split by
//! light are composited without their record, or when passes without a split cannot be relit.

use std::path::Path;
use std::process::ExitCode;

use anyhow::bail;
use glassdb_compose::colour::RegistryLuts;
use glassdb_compose::light_parts::{LightPart, LightSource};
use glassdb_compose::{ComposeJob, ComposeSettings, FactorKind, PartFactor, PartTables};

use crate::cmd::compose::{Args, load_registry, print_stats};
use crate::cmd::progress::Spinner;

/// `compose --light-parts`: one frame, or every frame of --frames in turn (the record's `#`
/// run expanded per frame like the passes').
pub fn run(
    args: &Args,
    record: &Path,
    job: &ComposeJob,
    settings: &ComposeSettings,
    luts: &RegistryLuts,
) -> anyhow::Result<ExitCode> {
    if args.skip_existing || args.report.is_some() {
        bail!("--light-parts: --skip-existing and --report are not supported with light parts yet");
    }
    let (registry, label) = load_registry(args.registry.as_deref())?;
    let tables = PartTables::new(&registry, &label);
    let Some(spec) = &args.inputs.frames else {
        if glassdb_io::is_frame_pattern(record) {
            bail!(
                "--light-parts {}: a pattern with # needs --frames",
                record.display()
            );
        }
        return run_frame(args, record, job, settings, luts, &tables).map(|()| ExitCode::SUCCESS);
    };
    let frames = glassdb_io::parse_frame_list(spec)?;
    let mut failed = Vec::new();
    for &frame in &frames {
        let one = job.for_frame(frame)?;
        let parts = if glassdb_io::is_frame_pattern(record) {
            glassdb_io::expand_frame_pattern(record, frame)?
        } else {
            record.to_path_buf()
        };
        if args.stats {
            outln!("--- frame {frame}");
        }
        if let Err(e) = run_frame(args, &parts, &one, settings, luts, &tables) {
            eprintln!(
                "frame {frame}: error: {}",
                crate::cmd::hints::with_hints(&e)
            );
            failed.push(frame);
        }
    }
    Ok(crate::cmd::frames_exit(&failed, frames.len()))
}

fn run_frame(
    args: &Args,
    record: &Path,
    job: &ComposeJob,
    settings: &ComposeSettings,
    luts: &RegistryLuts,
    tables: &PartTables,
) -> anyhow::Result<()> {
    let parts = glassdb_compose::read_light_parts(record)?;
    let spinner = Spinner::on_terminal("compose");
    let report = glassdb_compose::compose_light_parts(
        job,
        settings,
        tables,
        &parts,
        &record.display().to_string(),
        &spinner,
    )?;
    spinner.finish();
    if args.stats {
        print_stats(&report.frame, luts, settings.decode.max_memory);
        print_factors(record, &parts.parts, &report.factors);
    }
    outln!(
        "wrote {} ({}×{}, {}; relit by {} light part(s) of {})",
        report.frame.output.path.display(),
        report.frame.width,
        report.frame.height,
        report.frame.output.encoding,
        report.factors.len(),
        record.display()
    );
    Ok(())
}

/// Each part, what its light came through and its factor per channel.
fn print_factors(record: &Path, parts: &[LightPart], factors: &[PartFactor]) {
    outln!("light parts  {} ({})", factors.len(), record.display());
    for (part, f) in parts.iter().zip(factors) {
        let source = match part.source {
            LightSource::Sun { .. } => "sun",
            LightSource::Sky => "sky",
            LightSource::Other => "other",
        };
        let how = match f.kind {
            FactorKind::Unglazed => "met no glazing: 1".to_string(),
            FactorKind::Sun {
                id,
                plane,
                cos_theta,
                side,
            } => format!(
                "through glass id {id} on plane {plane} at θ {:.1}° ({side:?} face): t(θ)",
                cos_theta.clamp(-1.0, 1.0).acos().to_degrees()
            ),
            FactorKind::Diffuse { id, plane } => {
                format!("through glass id {id} on plane {plane}: hemispherical t_dif")
            }
        };
        let light = f
            .light
            .as_deref()
            .map_or(String::new(), |l| format!(", light {l}"));
        outln!(
            "  {:<20} {source}{light}, {how}  factor R {:.4} G {:.4} B {:.4}",
            f.group,
            f.factor[0],
            f.factor[1],
            f.factor[2]
        );
    }
}

/// What a plain composite (no --light-parts, no --light-groups) says of the passes' light
/// split, from the transmission pass's header: a warning when the passes are split by light
/// groups (their record would relight the room; without it the light that came through the
/// glazing is scaled by no glass). Returns whether they are not split (`--stats` then says so,
/// [`print_unsplit_note`]).
pub fn warn_split(trans: &Path, max_pixels: u64) -> bool {
    let Ok(groups) = glassdb_pass::light_group_layers_of(trans, max_pixels) else {
        return false;
    };
    if groups.is_empty() {
        return true;
    }
    let names: Vec<&str> = groups.iter().map(|g| g.group.as_str()).collect();
    eprintln!(
        "warning: {} is split by light ({}) but composited as one image: if these are light parts (glassdb \
         blender's light split, rendered with the glazing clear to light), the light that came through the \
         glazing is scaled by no glass: give --light-parts FILE (light_parts.####.json) to relight the room; \
         if they are light groups of different spectra, give --light-groups",
        trans.display(),
        names.join(", ")
    );
    false
}

/// `--stats`' line for passes without a light-path split: what a swap cannot change.
pub fn print_unsplit_note() {
    outln!(
        "light        not split by the light's path: a glass swap changes the glass pixels only; the light \
         that came through the glazing (sun patches, sky light, what is seen through the glass) keeps the \
         render's glass"
    );
}

/// `glassdb blender compose`'s line per frame relit by its light parts: each part's factors.
pub fn print_blender_factors(frames: &[(u32, Vec<PartFactor>)]) {
    for (frame, factors) in frames {
        let parts: Vec<String> = factors
            .iter()
            .map(|f| {
                format!(
                    "{} ×({:.3}, {:.3}, {:.3})",
                    f.group, f.factor[0], f.factor[1], f.factor[2]
                )
            })
            .collect();
        outln!(
            "frame {frame}: relit by {} light part(s): {}",
            factors.len(),
            parts.join(", ")
        );
    }
}
