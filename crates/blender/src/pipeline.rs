//! `glassdb blender render` and `glassdb blender compose`: from a .blend file to
//! `DIR/composite.####.exr`, and re-compositing a finished run with other glasses.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use glassdb_colour::RgbSpace;
use glassdb_compose::colour::RegistryLuts;
use glassdb_compose::{ComposeJob, ComposeSettings, FrameReport};
use glassdb_image::{
    ExrImageOut, ExrPartOut, ExrPlane, ExrStorage, ExrWriteOptions, PixelWindow, PlaneSamples,
};
use glassdb_io::Progress;
use glassdb_mask::{GlassMapping, MaskFormat, PlaneBounds};
use glassdb_registry::{ColourBasis, Registry, Side};
use glassdb_scene::{
    CameraSource, CosEncoding, CosMode, MirrorRequest, PlaneSource, PlaneTolerance, RasterOptions,
    build_mask_scene, load_obj, rasterize, to_mask_image, write_virtual_scenes,
};

use crate::BlenderError;
use crate::job::{
    ExportInfo, FrameRecord, PixelBounds, RECORD_FORMAT, RECORD_NAME, RunRecord, ScriptFrame,
    ScriptJob, ScriptPlane,
};
use crate::program::{Blender, BlenderRun, check_blend_file, children_cpu_seconds};
use crate::thin_pane::ThinPane;

/// The Blender-side script, embedded so that the binary needs nothing else.
pub const SCRIPT: &str = include_str!("../../../integrations/blender/glassdb_blender.py");
/// The run's working folder inside the output directory (removed when the run succeeds).
const STAGING: &str = ".glassdb-blender";
/// Blender's log in the output directory.
pub const LOG_NAME: &str = "blender.log";

/// What `glassdb blender render` is asked to do.
#[derive(Debug, Clone)]
pub struct RenderRequest {
    pub blend: PathBuf,
    /// `PATTERN=ID`: Blender materials that are glass, and their registry ids.
    pub glass: Vec<String>,
    /// Frames to render, or the scene's frame range.
    pub frames: Option<Vec<u32>>,
    pub out_dir: PathBuf,
    pub samples: Option<u32>,
    /// `(width, height)`, or the scene's.
    pub resolution: Option<(u32, u32)>,
    /// The Blender program, or `blender` on PATH.
    pub blender: Option<PathBuf>,
    /// A Python interpreter with the `bpy` module, used instead of a Blender executable.
    pub bpy_python: Option<PathBuf>,
    /// Longest time one Blender run may take.
    pub timeout: Duration,
    pub seed: u32,
    pub threads: Option<u32>,
    /// K×K rays per pixel for the masks' glass coverage (1: the pixel centre only, no
    /// coverage channel).
    pub mask_samples: u32,
    /// Also render the Cycles reference (the glass as a thin pane seen by the camera) as
    /// `reference.####.exr`.
    pub reference: bool,
}

/// The registry and how it is named in messages and outputs.
#[derive(Debug, Clone)]
pub struct RegistryChoice {
    pub registry: Registry,
    pub label: String,
}

/// What a run did, for the command's report.
#[derive(Debug)]
pub struct RenderReport {
    pub blender: Blender,
    pub record: RunRecord,
    pub planes: usize,
    pub glass_materials: Vec<(String, u16)>,
    /// Wall seconds of each step: Blender's export, passes and reference; glassdb's planes
    /// and masks.
    pub export_s: f64,
    pub render_s: f64,
    pub reference_s: f64,
    pub mask_s: f64,
    /// CPU seconds (user + system) of Blender's passes and of its reference render
    /// ([`children_cpu_seconds`]), where the system says.
    pub render_cpu_s: Option<f64>,
    pub reference_cpu_s: Option<f64>,
    pub compose: ComposeReport,
}

/// The composites of a run.
#[derive(Debug)]
pub struct ComposeReport {
    pub frames: Vec<(u32, FrameReport)>,
    pub seconds: f64,
}

/// Pattern names of the frame's files.
fn frame_name(stem: &str, frame: u32) -> String {
    format!("{stem}.{frame:04}.exr")
}

/// Renders `request.blend` through Blender and composites every frame (module docs).
pub fn render(
    request: &RenderRequest,
    registry: &RegistryChoice,
    progress: &dyn Progress,
) -> Result<RenderReport, BlenderError> {
    let mappings = request
        .glass
        .iter()
        .map(|g| GlassMapping::parse(g))
        .collect::<Result<Vec<_>, _>>()?;
    if mappings.is_empty() {
        return Err(BlenderError::BadOption(
            "no glass given: name the glass materials and their registry ids (PATTERN=ID)".into(),
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
    let dir = &request.out_dir;
    std::fs::create_dir_all(dir).map_err(BlenderError::io("create the output directory", dir))?;
    let log = dir.join(LOG_NAME);
    std::fs::write(&log, "").map_err(BlenderError::io("write", &log))?;
    let staging = dir.join(STAGING);
    std::fs::create_dir_all(&staging).map_err(BlenderError::io("create", &staging))?;
    let script = staging.join("glassdb_blender.py");
    std::fs::write(&script, SCRIPT).map_err(BlenderError::io("write", &script))?;
    let run = |step: &'static str, args: Vec<String>| {
        blender.run(&BlenderRun {
            step,
            blend: &request.blend,
            script: &script,
            args,
            log: &log,
            timeout: request.timeout,
        })
    };
    let resolution = request.resolution.map(|(w, h)| format!("{w}x{h}"));

    // 1. Blender exports the scene and the camera of every frame.
    progress.stage("export");
    let t = Instant::now();
    let export_dir = staging.join("export");
    let mut args = vec!["export".into(), "--out".into(), path_arg(&export_dir)];
    if let Some(frames) = &request.frames {
        args.extend(["--frames".into(), join_frames(frames)]);
    }
    if let Some(r) = &resolution {
        args.extend(["--resolution".into(), r.clone()]);
    }
    run("export", args)?;
    for name in ["scene.obj", "scene.mtl", "camera.json", "export.json"] {
        let from = export_dir.join(name);
        std::fs::rename(&from, dir.join(name)).map_err(BlenderError::io("move", &from))?;
    }
    let info: ExportInfo = {
        let path = dir.join("export.json");
        let text = glassdb_io::read_input_string(&path, glassdb_io::limits::JSON)?;
        serde_json::from_str(&text).map_err(|e| BlenderError::BadRender {
            path: path.clone(),
            message: e.to_string(),
        })?
    };
    let export_s = t.elapsed().as_secs_f64();

    // 2. Planes, masks and each plane's pixels, by glassdb's own geometry.
    progress.stage("planes and masks");
    let t = Instant::now();
    let scene = load_obj(&dir.join("scene.obj"))?;
    let cameras = CameraSource::open(&dir.join("camera.json"))?;
    let Some(&first_frame) = info.frames.first() else {
        return Err(BlenderError::BadRender {
            path: dir.join("export.json"),
            message: "no frames to render (the scene's frame range or --frames is empty)".into(),
        });
    };
    let first = cameras.camera(Some(first_frame))?;
    let report = write_virtual_scenes(&MirrorRequest {
        scene: &scene,
        glass_patterns: mappings.iter().map(|m| m.pattern.clone()).collect(),
        explicit_plane: None,
        eye: Some(first.origin),
        tolerance: PlaneTolerance::default_for(&scene),
        out_dir: dir,
    })?;
    let planes = report.planes.planes();
    let labelled = build_mask_scene(
        &scene,
        &mappings,
        &PlaneSource::Given {
            planes: planes.clone(),
            tolerance: report.planes.tolerance(),
        },
        false,
    )?;
    let glass_materials = glass_of_materials(&info.materials, &mappings)?;
    let table = registry
        .registry
        .table(ColourBasis::Space(RgbSpace::Srgb))
        .unwrap_or_else(|| registry.registry.default_table());
    let panes = glass_materials
        .iter()
        .map(|(material, id)| {
            table
                .glass(*id)
                .map(|g| ThinPane::of(material, g))
                .ok_or_else(|| BlenderError::UnknownGlass {
                    id: *id,
                    material: material.clone(),
                    registry: registry.label.clone(),
                })
        })
        .collect::<Result<Vec<_>, _>>()?;

    let mut frames = Vec::new();
    let mut script_frames = Vec::new();
    // Each frame's plane rectangles, where its crops go.
    let mut crops = Vec::new();
    // The first frame's size, which every frame must have.
    let mut size = None;
    for &frame in &info.frames {
        let camera = cameras.camera(Some(frame))?;
        let mask = to_mask_image(
            rasterize(&labelled.raster, &camera, &options)?,
            CosEncoding::Float,
        );
        let (width, height) = *size.get_or_insert((mask.width, mask.height));
        if (mask.width, mask.height) != (width, height) {
            return Err(BlenderError::BadRender {
                path: dir.join("camera.json"),
                message: format!(
                    "frame {frame} is {}x{}, but frame {first_frame} is {width}x{height}; \
                     every frame of a run must have one size",
                    mask.width, mask.height
                ),
            });
        }
        let rectangles = plane_rectangles(&mask, planes.len());
        let mask_name = frame_name("mask", frame);
        glassdb_mask::write_mask(&dir.join(&mask_name), &mask, MaskFormat::Exr)?;
        let refl: Vec<String> = (0..planes.len())
            .map(|k| frame_name(&format!("refl_{k}"), frame))
            .collect();
        let mut sides = Vec::new();
        let mut script_planes = Vec::new();
        for (k, plane) in planes.iter().enumerate() {
            let front = plane.signed_distance(camera.origin) >= 0.0;
            sides.push(if front { Side::Front } else { Side::Back });
            let facing = if front { *plane } else { plane.flipped() };
            if let Some(r) = rectangles[k] {
                script_planes.push(ScriptPlane {
                    index: k,
                    equation: facing.equation(),
                    tolerance: report.planes.tolerance.distance,
                    border: r.blender_border(width, height),
                    output: staging.join(&refl[k]),
                });
            }
        }
        script_frames.push(ScriptFrame {
            frame,
            trans: staging.join(frame_name("trans", frame)),
            planes: script_planes,
        });
        let windows: Vec<Option<PixelWindow>> =
            rectangles.iter().map(|r| r.map(|r| r.window())).collect();
        frames.push(FrameRecord {
            frame,
            trans: frame_name("trans", frame),
            mask: mask_name,
            refl,
            sides,
            bounds: windows.iter().map(|w| w.map(PixelBounds::from)).collect(),
            composite: frame_name("composite", frame),
        });
        crops.push(windows);
    }
    let (width, height) = size.unwrap_or_default();
    let mask_s = t.elapsed().as_secs_f64();

    // 3. Blender renders the transmission and reflection passes.
    progress.stage("render passes");
    let t = Instant::now();
    let cpu = children_cpu_seconds();
    let job = ScriptJob {
        resolution: resolution.clone(),
        samples: request.samples,
        seed: request.seed,
        threads: request.threads,
        reference: false,
        glass: panes.clone(),
        frames: script_frames,
    };
    run_job(&run, &staging.join("job.json"), "render", &job)?;
    for ((f, script), windows) in frames.iter().zip(&job.frames).zip(&crops) {
        rename(&script.trans, &dir.join(&f.trans))?;
        for (refl, window) in f.refl.iter().zip(windows) {
            let target = dir.join(refl);
            match window {
                Some(w) => place_crop(&staging.join(refl), &target, *w, width, height)?,
                None => write_unused_pass(&target, width, height)?,
            }
        }
    }
    let render_s = t.elapsed().as_secs_f64();
    let render_cpu_s = cpu_since(cpu);
    let record = RunRecord {
        format: RECORD_FORMAT.into(),
        blend: request.blend.display().to_string(),
        blender: blender.version.clone(),
        glass: request.glass.clone(),
        samples: request.samples,
        width,
        height,
        frames,
    };
    let record_path = dir.join(RECORD_NAME);
    let text = serde_json::to_string_pretty(&record).map_err(|e| BlenderError::BadRecord {
        path: record_path.clone(),
        message: e.to_string(),
    })?;
    glassdb_io::write_bytes_atomic(&record_path, format!("{text}\n").as_bytes())?;

    // The Cycles reference: the same shader seen by the camera, no passes.
    let mut reference_s = 0.0;
    let mut reference_cpu_s = None;
    if request.reference {
        progress.stage("render reference");
        let t = Instant::now();
        let cpu = children_cpu_seconds();
        let job = ScriptJob {
            reference: true,
            frames: record
                .frames
                .iter()
                .map(|f| ScriptFrame {
                    frame: f.frame,
                    trans: staging.join(frame_name("reference", f.frame)),
                    planes: Vec::new(),
                })
                .collect(),
            ..job
        };
        run_job(&run, &staging.join("reference_job.json"), "reference", &job)?;
        for f in &job.frames {
            rename(&f.trans, &dir.join(frame_name("reference", f.frame)))?;
        }
        reference_s = t.elapsed().as_secs_f64();
        reference_cpu_s = cpu_since(cpu);
    }

    // 4. The composites.
    progress.stage("composite");
    let compose = compose_record(dir, &record, registry)?;
    std::fs::remove_dir_all(&staging).map_err(BlenderError::io("remove", &staging))?;
    Ok(RenderReport {
        blender,
        record,
        planes: planes.len(),
        glass_materials,
        export_s,
        render_s,
        reference_s,
        mask_s,
        render_cpu_s,
        reference_cpu_s,
        compose,
    })
}

/// Children's CPU seconds since `before`.
fn cpu_since(before: Option<f64>) -> Option<f64> {
    Some(children_cpu_seconds()? - before?)
}

/// Writes the job and has Blender render it.
fn run_job(
    run: &dyn Fn(&'static str, Vec<String>) -> Result<(), BlenderError>,
    path: &Path,
    step: &'static str,
    job: &ScriptJob,
) -> Result<(), BlenderError> {
    let text = serde_json::to_string(job).map_err(|e| BlenderError::BadRecord {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    std::fs::write(path, text).map_err(BlenderError::io("write", path))?;
    run(step, vec!["render".into(), "--job".into(), path_arg(path)])
}

/// Refuses a pass that Blender did not write.
fn check_written(pass: &Path) -> Result<(), BlenderError> {
    if pass.is_file() {
        Ok(())
    } else {
        Err(BlenderError::BadRender {
            path: pass.to_path_buf(),
            message: "Blender did not write this pass".into(),
        })
    }
}

fn rename(from: &Path, to: &Path) -> Result<(), BlenderError> {
    check_written(from)?;
    std::fs::rename(from, to).map_err(BlenderError::io("move", from))
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

/// Each Blender material that a `--glass` pattern matches (first match wins), with its id.
fn glass_of_materials(
    materials: &[String],
    mappings: &[GlassMapping],
) -> Result<Vec<(String, u16)>, BlenderError> {
    let patterns: Vec<&str> = mappings.iter().map(|m| m.pattern.as_str()).collect();
    let matcher = glassdb_scene::MaterialMatcher::new(&patterns)?;
    Ok(materials
        .iter()
        .filter_map(|m| matcher.first_match(m).map(|k| (m.clone(), mappings[k].id)))
        .collect())
}

/// Each plane's glass rectangle from the mask (glassdb-mask's `plane_bounds`), `None` where a
/// plane has no glass in the frame.
fn plane_rectangles(mask: &glassdb_mask::MaskImage, planes: usize) -> Vec<Option<PlaneBounds>> {
    let found = mask.plane_bounds();
    (0..planes)
        .map(|k| u16::try_from(k).ok().and_then(|k| found.get(&k)).copied())
        .collect()
}

/// The passes are written as compose writes by default: half float, ZIP.
const EXR_OPTIONS: ExrWriteOptions = ExrWriteOptions {
    storage: ExrStorage::Half,
    compression: glassdb_compose::io::DEFAULT_EXR_COMPRESSION,
    zip_level: None,
};

/// Writes Blender's cropped render `from` (its window reset to the origin, docs/compose.md)
/// to `to` with its data window at `window` in the `width × height` frame, samples unchanged.
fn place_crop(
    from: &Path,
    to: &Path,
    window: PixelWindow,
    width: u32,
    height: u32,
) -> Result<(), BlenderError> {
    let bad = |message: String| BlenderError::BadRender {
        path: from.to_path_buf(),
        message,
    };
    check_written(from)?;
    let bytes = glassdb_io::read_input(from, glassdb_io::limits::IMAGE)?;
    let exact = glassdb_image::read_exr_exact(&bytes, glassdb_image::DEFAULT_MAX_PIXELS)?;
    let parts = exact.parts.len();
    let Ok([part]) = <[_; 1]>::try_from(exact.parts) else {
        return Err(bad(format!("{parts} parts, expected one")));
    };
    let got = (part.data_window.width, part.data_window.height);
    if got != (window.width, window.height) {
        return Err(bad(format!(
            "the render is {}x{}, but the border asked for {}x{}",
            got.0, got.1, window.width, window.height
        )));
    }
    let image = ExrImageOut {
        display_window: PixelWindow::at_origin(width as usize, height as usize),
        attributes: exact.attributes,
        parts: vec![ExrPartOut {
            data_window: window,
            attributes: part.attributes,
            planes: part
                .channels
                .into_iter()
                .map(|(name, samples)| ExrPlane {
                    name,
                    samples: PlaneSamples::Exact(samples),
                    linear: false,
                })
                .collect(),
        }],
    };
    write_exr(to, image)
}

fn write_exr(to: &Path, image: ExrImageOut) -> Result<(), BlenderError> {
    glassdb_io::write_atomic(to, |w| {
        glassdb_image::write_exr_image(w, image, EXR_OPTIONS)
            .map(|_| ())
            .map_err(std::io::Error::other)
    })?;
    Ok(())
}

/// The pass of a plane without glass in a frame (the compositor wants one per plane and never
/// reads its pixels): one black pixel at the frame's corner.
fn write_unused_pass(to: &Path, width: u32, height: u32) -> Result<(), BlenderError> {
    let planes = ["A", "B", "G", "R"]
        .iter()
        .map(|c| ExrPlane::new(c, vec![0.0]))
        .collect();
    let display = PixelWindow::at_origin(width as usize, height as usize);
    write_exr(
        to,
        ExrImageOut {
            display_window: display,
            attributes: glassdb_image::ExrImageAttributes::with_size((
                width as usize,
                height as usize,
            )),
            parts: vec![ExrPartOut {
                data_window: PixelWindow::at_origin(1, 1),
                attributes: Default::default(),
                planes,
            }],
        },
    )
}

/// Composites every frame of a run record in `dir` with `registry`.
pub fn compose_record(
    dir: &Path,
    record: &RunRecord,
    registry: &RegistryChoice,
) -> Result<ComposeReport, BlenderError> {
    let t = Instant::now();
    let luts = RegistryLuts::new(&registry.registry);
    let mut frames = Vec::new();
    for f in &record.frames {
        let settings = ComposeSettings {
            plane_sides: f
                .sides
                .iter()
                .copied()
                .enumerate()
                .collect::<BTreeMap<_, _>>(),
            registry_label: registry.label.clone(),
            ..ComposeSettings::default()
        };
        let job = ComposeJob {
            refl: f.refl.iter().map(|r| dir.join(r)).collect(),
            trans: dir.join(&f.trans),
            mask: dir.join(&f.mask),
            output: dir.join(&f.composite),
        };
        frames.push((
            f.frame,
            glassdb_compose::compose_frame(&job, &settings, &luts)?,
        ));
    }
    Ok(ComposeReport {
        frames,
        seconds: t.elapsed().as_secs_f64(),
    })
}

/// `glassdb blender compose DIR`: the run's frames composited again with `registry`.
pub fn compose_dir(dir: &Path, registry: &RegistryChoice) -> Result<ComposeReport, BlenderError> {
    let record = RunRecord::load(dir)?;
    compose_record(dir, &record, registry)
}
