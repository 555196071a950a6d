//! `glassdb blender render` and `glassdb blender compose`: from a .blend file to
//! `DIR/composite.####.exr`, and re-compositing a finished run with other glasses.
//!
//! [`render`] runs its phases in order, each a function: [`Workspace::prepare`] (checks, the
//! program, the output and staging folders), [`export_scene`] (Blender exports the scene and
//! every frame's camera), [`planes_and_masks`] (glassdb's planes, masks and each plane's pixels
//! per frame, through `glassdb_scene::mask_frames`), [`render_passes`] (Blender renders the passes;
//! glassdb places the crops), [`render_reference`] (optional) and [`compose_record`].

use std::collections::BTreeMap;
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use glassdb_compose::colour::RegistryLuts;
use glassdb_compose::{ComposeJob, ComposeSettings, DecodeSettings, FrameFiles, FrameReport};
use glassdb_io::Progress;
use glassdb_mask::GlassMapping;
use glassdb_registry::{NamedLight, Registry};
use glassdb_scene::{CosMode, RasterOptions};

use crate::BlenderError;
use crate::geometry::{Masks, planes_and_masks};
use crate::job::{
    ExportInfo, FrameRecord, RECORD_FORMAT, RECORD_NAME, RunRecord, ScriptFrame, ScriptJob,
};
use crate::passes::{place_crop, rename, write_unused_pass};
use crate::program::{Blender, BlenderRun, check_blend_file, children_cpu_seconds};
use crate::scene_lights::SceneLight;

/// The Blender-side script, embedded so that the binary needs nothing else.
pub const SCRIPT: &str = include_str!("../../../integrations/blender/glassdb_blender.py");
/// The run's working folder inside the output directory (removed when the run succeeds).
const STAGING: &str = ".glassdb-blender";
/// Blender's log in the output directory.
pub const LOG_NAME: &str = "blender.log";

/// K of the masks' K×K coverage rays per pixel by default: 4 (16 rays and the centre). Centre
/// sampling leaves the glass part of a pane-edge pixel untinted (or tints all of it), which a
/// swap to a dark glass shows as outlines; with coverage compose blends an edge pixel by its
/// glass fraction (method eq. 10). docs/blender.md, "Pane edges", has what it gains and costs.
pub const DEFAULT_MASK_SAMPLES: u32 = 4;

/// What `glassdb blender render` is asked to do.
#[derive(Debug, Clone)]
pub struct RenderRequest {
    /// The scene.
    pub blend: PathBuf,
    /// `PATTERN=ID`: Blender materials that are glass, and their registry ids.
    pub glass: Vec<String>,
    /// Frames to render, or the scene's frame range.
    pub frames: Option<Vec<u32>>,
    /// Where the run's files go.
    pub out_dir: PathBuf,
    /// Cycles samples per pixel, or the scene's.
    pub samples: Option<u32>,
    /// `(width, height)`, or the scene's.
    pub resolution: Option<(u32, u32)>,
    /// The Blender program, or `blender` on PATH.
    pub blender: Option<PathBuf>,
    /// A Python interpreter with the `bpy` module, used instead of a Blender executable.
    pub bpy_python: Option<PathBuf>,
    /// Longest time one Blender run may take.
    pub timeout: Duration,
    /// Cycles' seed.
    pub seed: u32,
    /// Render threads, or Blender's choice.
    pub threads: Option<u32>,
    /// K×K rays per pixel for the masks' glass coverage (1: the pixel centre only, no
    /// coverage channel); [`DEFAULT_MASK_SAMPLES`] unless asked otherwise.
    pub mask_samples: u32,
    /// Also render the Cycles reference (the glass as a thin pane seen by the camera) as
    /// `reference.####.exr`.
    pub reference: bool,
    /// Keep the light's path apart in the passes ([`crate::light_split`]): light groups by
    /// source and one render per aperture, so that a swap relights the room; `false` renders
    /// each pass once, lit through the render's glass (a swap then leaves the room as lit).
    pub light_split: bool,
    /// Show the lamps (point, spot, area, sun) in the reflection passes as the real glass
    /// reflects them (docs/blender.md "Lamps in reflections"); off: each pass sees the lamps as
    /// the scene's camera visibility says, as before.
    pub lamps_in_reflections: bool,
    /// Composite every frame at the end (else the run stops at its passes, masks and record,
    /// for [`compose_dir`] to composite: a farm's render and composite steps).
    pub composite: bool,
    /// How many of a unit's pane groups get a reflection pass of their own (`--surfaces N`;
    /// `None`: all, issue 27's double image); the deeper groups' reflectance is composited on
    /// the last one's pass (`Some(1)`: one pass per plane, no double image).
    pub surfaces: Option<NonZeroUsize>,
    /// The spectrum of each of the scene's light groups (`GROUP=ILLUMINANT`, issue 29,
    /// [`crate::scene_lights`]); a group not named here takes its `glassdb_light` property.
    pub lights: Vec<NamedLight>,
}

/// The registry and how it is named in messages and outputs.
#[derive(Debug, Clone)]
pub struct RegistryChoice {
    /// The registry.
    pub registry: Registry,
    /// Its name in messages (its path, or "the bundled catalog").
    pub label: String,
}

/// What a run did, for the command's report.
#[derive(Debug)]
pub struct RenderReport {
    /// The Blender that rendered.
    pub blender: Blender,
    /// The run record written.
    pub record: RunRecord,
    /// Glass planes found.
    pub planes: usize,
    /// Each glass material and its registry id.
    pub glass_materials: Vec<(String, u16)>,
    /// Wall seconds of Blender's export.
    pub export_s: f64,
    /// Wall seconds of glassdb's planes and masks.
    pub mask_s: f64,
    /// The time of Blender's passes.
    pub render: BlenderTime,
    /// The time of Blender's reference render (0 s when none was asked for).
    pub reference: BlenderTime,
    /// The composites.
    pub compose: ComposeReport,
    /// Blender's pass renders over all frames, and how many the same frames take without the
    /// light split (`(A + 1)(1 + P)` against `1 + P` per frame: A apertures, P reflection
    /// passes).
    pub renders: (usize, usize),
}

/// The time one Blender stage took.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BlenderTime {
    /// Wall seconds.
    pub wall_s: f64,
    /// CPU seconds (user + system) of Blender ([`children_cpu_seconds`]), where the system
    /// says.
    pub cpu_s: Option<f64>,
}

impl BlenderTime {
    /// Runs `stage`, and the time it took.
    fn of<T>(
        stage: impl FnOnce() -> Result<T, BlenderError>,
    ) -> Result<(T, BlenderTime), BlenderError> {
        let t = Instant::now();
        let cpu = children_cpu_seconds();
        let out = stage()?;
        let wall_s = t.elapsed().as_secs_f64();
        let cpu_s = children_cpu_seconds()
            .zip(cpu)
            .map(|(after, before)| after - before);
        Ok((out, BlenderTime { wall_s, cpu_s }))
    }
}

/// The composites of a run.
#[derive(Debug)]
pub struct ComposeReport {
    /// Each frame's composite.
    pub frames: Vec<(u32, FrameReport)>,
    /// What compositing with this registry leaves lit by the render's glasses
    /// ([`crate::swap_warnings`]); empty when the glasses are the render's.
    pub swap: Vec<crate::SwapWarning>,
    /// Wall seconds of them all.
    pub seconds: f64,
    /// The factors of each frame composited with its light parts (the relit swap,
    /// [`crate::relit`]), by frame.
    pub light_parts: Vec<(u32, Vec<glassdb_compose::PartFactor>)>,
    /// The registry light that composited each of the scene's light groups, and whether the
    /// registry's one light composited them all ([`crate::scene_lights::light_tables`]).
    pub lights: crate::scene_lights::LightTables,
}

/// Pattern names of the frame's files.
pub(crate) fn frame_name(stem: &str, frame: u32) -> String {
    format!("{stem}.{frame:04}.exr")
}

/// Renders `request.blend` through Blender and composites every frame (module docs).
pub fn render(
    request: &RenderRequest,
    registry: &RegistryChoice,
    progress: &dyn Progress,
) -> Result<RenderReport, BlenderError> {
    let work = Workspace::prepare(request)?;

    progress.stage("export");
    let t = Instant::now();
    let info = export_scene(&work)?;
    let export_s = t.elapsed().as_secs_f64();
    let lights = crate::scene_lights::resolve_scene_lights(
        &info.light_groups,
        &request.lights,
        &request.blend,
    )?;
    if request.composite {
        // A registry that cannot composite the groups is refused before anything renders.
        crate::scene_lights::light_tables(&lights, registry, &work.dir.join(RECORD_NAME))?;
    }

    progress.stage("planes and masks");
    let t = Instant::now();
    let mut masks = planes_and_masks(&work, &info, registry)?;
    let mask_s = t.elapsed().as_secs_f64();

    let renders = crate::light_split::render_counts(&masks.script_frames, request.light_split);
    progress.stage("render passes");
    let (job, render_time) = BlenderTime::of(|| render_passes(&work, &mut masks, &lights))?;
    let lit_by = crate::swap::pass_glasses(masks.glass_materials.iter().map(|m| m.1), registry);
    let record = write_record(
        &work,
        masks.frames,
        masks.size,
        info.overrides(),
        lit_by,
        lights,
    )?;

    let mut reference_time = BlenderTime::default();
    if request.reference {
        progress.stage("render reference");
        reference_time = BlenderTime::of(|| render_reference(&work, &record, job, registry))?.1;
    }

    let compose = if request.composite {
        progress.stage("composite");
        compose_record(&work.dir, &record, registry)?
    } else {
        ComposeReport {
            frames: Vec::new(),
            swap: Vec::new(),
            seconds: 0.0,
            light_parts: Vec::new(),
            lights: crate::scene_lights::LightTables::default(),
        }
    };
    std::fs::remove_dir_all(&work.staging).map_err(BlenderError::io("remove", &work.staging))?;
    Ok(RenderReport {
        blender: work.blender,
        record,
        planes: masks.planes,
        glass_materials: masks.glass_materials,
        export_s,
        mask_s,
        render: render_time,
        reference: reference_time,
        compose,
        renders,
    })
}

/// What every phase of a run shares: the request, its glass, the program and the folders.
pub struct Workspace<'a> {
    pub(crate) request: &'a RenderRequest,
    pub(crate) mappings: Vec<GlassMapping>,
    pub(crate) options: RasterOptions,
    pub(crate) blender: Blender,
    pub(crate) dir: PathBuf,
    pub(crate) staging: PathBuf,
    pub(crate) script: PathBuf,
    pub(crate) log: PathBuf,
}

impl<'a> Workspace<'a> {
    /// Checks the request (glass mappings, mask samples, the .blend file), finds Blender, and
    /// makes the output folder, its empty log and the staging folder with the script.
    pub fn prepare(request: &'a RenderRequest) -> Result<Workspace<'a>, BlenderError> {
        let mappings = request
            .glass
            .iter()
            .map(|g| GlassMapping::parse(g))
            .collect::<Result<Vec<_>, _>>()?;
        if mappings.is_empty() {
            return Err(BlenderError::BadOption(
                "no glass given: name the glass materials and their registry ids (PATTERN=ID)"
                    .into(),
            ));
        }
        let options = RasterOptions {
            cos: CosMode::Exact,
            samples: request.mask_samples,
        };
        glassdb_scene::raster::check_options(&options)?;
        check_blend_file(&request.blend)?;
        let blender = match &request.bpy_python {
            Some(python) => Blender::find_bpy(python)?,
            None => Blender::find(request.blender.as_deref())?,
        };
        let dir = request.out_dir.clone();
        std::fs::create_dir_all(&dir)
            .map_err(BlenderError::io("create the output directory", &dir))?;
        let log = dir.join(LOG_NAME);
        std::fs::write(&log, "").map_err(BlenderError::io("write", &log))?;
        let staging = dir.join(STAGING);
        std::fs::create_dir_all(&staging).map_err(BlenderError::io("create", &staging))?;
        let script = staging.join("glassdb_blender.py");
        std::fs::write(&script, SCRIPT).map_err(BlenderError::io("write", &script))?;
        Ok(Workspace {
            request,
            mappings,
            options,
            blender,
            dir,
            staging,
            script,
            log,
        })
    }

    /// Runs the Blender-side script in `step` with `args`.
    fn run(&self, step: &'static str, args: Vec<String>) -> Result<(), BlenderError> {
        self.blender.run(&BlenderRun {
            step,
            blend: &self.request.blend,
            script: &self.script,
            args,
            log: &self.log,
            timeout: self.request.timeout,
        })
    }

    /// The most pane groups of a unit rendered as passes of their own (`--surfaces`).
    pub(crate) fn surfaces(&self) -> usize {
        self.request.surfaces.map_or(usize::MAX, NonZeroUsize::get)
    }

    /// `WxH` of the request, if it sets one.
    fn resolution(&self) -> Option<String> {
        self.request.resolution.map(|(w, h)| format!("{w}x{h}"))
    }
}

/// Blender exports the scene (`scene.obj`, `scene.mtl`), the camera of every frame
/// (`camera.json`) and what else glassdb needs (`export.json`) into the output folder.
pub fn export_scene(work: &Workspace<'_>) -> Result<ExportInfo, BlenderError> {
    let export_dir = work.staging.join("export");
    let mut args = vec!["export".into(), "--out".into(), path_arg(&export_dir)];
    if let Some(frames) = &work.request.frames {
        args.extend(["--frames".into(), join_frames(frames)]);
    }
    if let Some(r) = work.resolution() {
        args.extend(["--resolution".into(), r]);
    }
    work.run("export", args)?;
    let names = ["scene.obj", "scene.mtl", "camera.json", "export.json"];
    let missing: Vec<&str> = names
        .into_iter()
        .filter(|n| !export_dir.join(n).is_file())
        .collect();
    if !missing.is_empty() {
        return Err(BlenderError::NothingWritten {
            blender: format!(
                "Blender {} ({})",
                work.blender.version,
                work.blender.path.display()
            ),
            missing: missing.join(", "),
            dir: export_dir,
            log: work.log.clone(),
        });
    }
    for name in names {
        let from = export_dir.join(name);
        std::fs::rename(&from, work.dir.join(name)).map_err(BlenderError::io("move", &from))?;
    }
    let path = work.dir.join("export.json");
    let text = glassdb_io::read_input_string(&path, glassdb_io::limits::JSON)?;
    let info: ExportInfo = serde_json::from_str(&text).map_err(|e| BlenderError::BadRender {
        path: path.clone(),
        message: e.to_string(),
    })?;
    for &frame in info.moving.keys() {
        let from = export_dir.join(moving_obj_name(frame));
        std::fs::rename(&from, work.dir.join(moving_obj_name(frame)))
            .map_err(BlenderError::io("move", &from))?;
    }
    Ok(info)
}

/// The OBJ of a frame whose geometry differs from the first frame's.
pub(crate) fn moving_obj_name(frame: u32) -> String {
    format!("scene.{frame:04}.obj")
}

/// Blender renders every frame's transmission pass and one cropped reflection pass per plane
/// with glass; glassdb moves them into the output folder, each crop placed at its pixel
/// rectangle (a plane without glass gets a one-pixel pass); with the light split, each pass
/// is assembled from its light-split renders and each frame gets its light parts
/// ([`crate::light_split`]); the scene's light groups `lights` split the sources further, or,
/// without the split, give every pass a layer per group. Returns the job it rendered.
pub fn render_passes(
    work: &Workspace<'_>,
    masks: &mut Masks,
    lights: &[SceneLight],
) -> Result<ScriptJob, BlenderError> {
    let request = work.request;
    let mut job = ScriptJob {
        resolution: work.resolution(),
        samples: request.samples,
        seed: request.seed,
        threads: request.threads,
        reference: false,
        lamps_in_reflections: request.lamps_in_reflections,
        glass: masks.panes.clone(),
        frames: masks.script_frames.clone(),
        light_split: request.light_split,
        light_groups: false,
        scene_groups: lights.iter().map(|l| l.group.clone()).collect(),
    };
    if request.light_split {
        crate::light_split::prepare_job(&work.staging, &mut job);
    }
    run_job(work, &work.staging.join("job.json"), "render", &job)?;
    if request.light_split {
        crate::light_split::place_split_passes(work, masks, &job)?;
        return Ok(job);
    }
    let (width, height) = masks.size;
    for ((f, script), windows) in masks.frames.iter().zip(&job.frames).zip(&masks.crops) {
        rename(&script.trans, &work.dir.join(&f.trans))?;
        for (refl, window) in f.refl.iter().zip(windows) {
            let target = work.dir.join(refl);
            match window {
                Some(w) => place_crop(&work.staging.join(refl), &target, *w, width, height)?,
                None => write_unused_pass(&target, width, height, &job.scene_groups)?,
            }
        }
        place_group_passes(work, f, masks.size)?;
    }
    Ok(job)
}

/// Places the frame's pane-group passes (issue 27), each crop at its group's rectangle.
fn place_group_passes(
    work: &Workspace<'_>,
    frame: &FrameRecord,
    (width, height): (u32, u32),
) -> Result<(), BlenderError> {
    for g in &frame.groups {
        let (from, to) = (work.staging.join(&g.file), work.dir.join(&g.file));
        place_crop(&from, &to, g.bounds.window(), width, height)?;
    }
    Ok(())
}

/// Writes the run record `glassdb-blender.json` of `frames`, `size` pixels each.
fn write_record(
    work: &Workspace<'_>,
    frames: Vec<FrameRecord>,
    (width, height): (u32, u32),
    overrides: Vec<String>,
    lit_by: Vec<crate::swap::PassGlass>,
    lights: Vec<SceneLight>,
) -> Result<RunRecord, BlenderError> {
    let request = work.request;
    let record = RunRecord {
        format: RECORD_FORMAT.into(),
        blend: request.blend.display().to_string(),
        blender: work.blender.version.clone(),
        glass: request.glass.clone(),
        samples: request.samples,
        width,
        height,
        overrides,
        frames,
        lit_by,
        surfaces: request.surfaces,
        group_layers: !request.light_split && !lights.is_empty(),
        lights,
    };
    let record_path = work.dir.join(RECORD_NAME);
    let text = serde_json::to_string_pretty(&record).map_err(|e| BlenderError::BadRecord {
        path: record_path.clone(),
        message: e.to_string(),
    })?;
    glassdb_io::write_bytes_atomic(&record_path, format!("{text}\n").as_bytes())?;
    Ok(record)
}

/// The Cycles reference: the same shader seen by the camera, no passes
/// (`reference.####.exr`); `job` is the passes' job, whose settings it keeps. With the scene's
/// light groups and a registry of several lights, one render per group with the glass of its
/// light (`crate::reference_lights`).
pub fn render_reference(
    work: &Workspace<'_>,
    record: &RunRecord,
    job: ScriptJob,
    registry: &RegistryChoice,
) -> Result<(), BlenderError> {
    let by_light = crate::reference_lights::panes_by_light(record, &job.glass, registry)?;
    if !by_light.is_empty() {
        let jobs = crate::reference_lights::jobs(&work.staging, record, &job, &by_light);
        for (k, job) in jobs.iter().enumerate() {
            let path = work.staging.join(format!("reference_job_{k}.json"));
            run_job(work, &path, "reference", job)?;
        }
        return crate::reference_lights::assemble(&work.staging, &work.dir, record, &by_light);
    }
    let job = ScriptJob {
        reference: true,
        frames: record
            .frames
            .iter()
            .map(|f| ScriptFrame {
                frame: f.frame,
                trans: work.staging.join(frame_name("reference", f.frame)),
                planes: Vec::new(),
                apertures: Vec::new(),
                lights: None,
            })
            .collect(),
        light_split: false,
        light_groups: true,
        ..job
    };
    run_job(
        work,
        &work.staging.join("reference_job.json"),
        "reference",
        &job,
    )?;
    for f in &job.frames {
        rename(&f.trans, &work.dir.join(frame_name("reference", f.frame)))?;
    }
    Ok(())
}

/// Writes the job and has Blender render it.
fn run_job(
    work: &Workspace<'_>,
    path: &Path,
    step: &'static str,
    job: &ScriptJob,
) -> Result<(), BlenderError> {
    let text = serde_json::to_string(job).map_err(|e| BlenderError::BadRecord {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    std::fs::write(path, text).map_err(BlenderError::io("write", path))?;
    work.run(step, vec!["render".into(), "--job".into(), path_arg(path)])
}

fn path_arg(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

fn join_frames(frames: &[u32]) -> String {
    frames
        .iter()
        .map(u32::to_string)
        .collect::<Vec<_>>()
        .join(",")
}

/// Composites every frame of a run record in `dir` with `registry`.
pub fn compose_record(
    dir: &Path,
    record: &RunRecord,
    registry: &RegistryChoice,
) -> Result<ComposeReport, BlenderError> {
    let t = Instant::now();
    let luts = RegistryLuts::new(&registry.registry);
    let tables = glassdb_compose::PartTables::new(&registry.registry, &registry.label);
    let lights =
        crate::scene_lights::light_tables(&record.lights, registry, &dir.join(RECORD_NAME))?;
    let groups = if record.group_layers {
        crate::scene_lights::compose_groups(&lights, &registry.registry)
    } else {
        Vec::new()
    };
    let mut frames = Vec::new();
    let mut light_parts = Vec::new();
    for f in &record.frames {
        let settings = ComposeSettings {
            decode: DecodeSettings {
                registry_label: registry.label.clone(),
                // The run's `--surfaces`: a unit's groups beyond it are composited on the last
                // group rendered.
                max_groups: record.surfaces,
                ..DecodeSettings::default()
            },
            plane_sides: f
                .sides
                .iter()
                .copied()
                .enumerate()
                .collect::<BTreeMap<_, _>>(),
            ..ComposeSettings::default()
        };
        let job = ComposeJob {
            inputs: FrameFiles {
                refl: f.refl.iter().map(|r| dir.join(r)).collect(),
                groups: f.group_pass_files(dir),
                trans: dir.join(&f.trans),
                mask: dir.join(&f.mask),
            },
            output: dir.join(&f.composite),
        };
        let report = match &f.light_parts {
            Some(name) => {
                let relit = crate::relit::compose_frame_parts(
                    dir, name, &job, &settings, &tables, &lights,
                )?;
                light_parts.push((f.frame, relit.factors));
                relit.frame
            }
            None if !groups.is_empty() => glassdb_compose::compose_light_groups(
                &job,
                &settings,
                &groups,
                false,
                &glassdb_io::NoProgress,
            )?,
            None => glassdb_compose::compose_frame(&job, &settings, &luts)?,
        };
        frames.push((f.frame, report));
    }
    Ok(ComposeReport {
        frames,
        swap: crate::relit::swap_warnings_relit(record, registry),
        seconds: t.elapsed().as_secs_f64(),
        light_parts,
        lights,
    })
}

/// `glassdb blender compose DIR`: the run's frames composited again with `registry`.
pub fn compose_dir(dir: &Path, registry: &RegistryChoice) -> Result<ComposeReport, BlenderError> {
    let record = RunRecord::load(dir)?;
    compose_record(dir, &record, registry)
}
