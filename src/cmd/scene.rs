//! `glassdb mirror` (virtual scenes of the glass planes) and `glassdb mask` (the id + cos θ
//! mask) from an OBJ scene (docs/scene.md). All logic lives in `glassdb_scene`; this module
//! parses arguments and formats output.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, bail};
use glassdb_io::Progress;
use glassdb_mask::MaskFormat;
use glassdb_scene::{
    CameraSource, CosMode, GlassMapping, MaskJob, MaskPlanes, MaskScene, MirrorRequest,
    PlaneTolerance, RasterOptions, Scene, SceneWarning, label_scene, load_obj, mask_frame,
    mask_frames, write_virtual_scenes,
};

use crate::cmd::progress::Spinner;

#[derive(Debug, clap::Args)]
pub struct MirrorArgs {
    /// The OBJ scene (its MTL libraries are referenced, not copied).
    pub scene: PathBuf,
    /// Glob pattern of glass material names (e.g. "Glass*"); repeatable.
    #[arg(long = "glass-material", value_name = "PATTERN")]
    pub glass_material: Vec<String>,
    /// Glass materials with their registry ids, `PATTERN=ID` (as `glassdb mask --glass`;
    /// repeatable, with or instead of --glass-material): a unit's pane groups each get a
    /// virtual scene, mirrored about the group's mid-plane behind the face (docs/scene.md,
    /// "Units").
    #[arg(long, value_name = "PATTERN=ID")]
    pub glass: Vec<String>,
    /// Registry the --glass ids are read from (default: the bundled one).
    #[arg(long, value_name = "FILE")]
    pub registry: Option<PathBuf>,
    /// One explicit plane a,b,c,d (a·x + b·y + c·z + d = 0) instead of detecting the planes.
    #[arg(long, value_name = "A,B,C,D", allow_hyphen_values = true)]
    pub plane: Option<String>,
    /// The eye x,y,z: keeps each plane's half-space on the eye's side. Default: the side the
    /// glass faces' normals point to.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub eye: Option<String>,
    /// Directory for `plane_<k>.obj` and `planes.json` (created if missing).
    #[arg(long = "out-dir", value_name = "DIR")]
    pub out_dir: PathBuf,
    /// Largest angle between the normals of faces on one plane, degrees.
    #[arg(long, default_value_t = 0.1)]
    pub angle_tolerance_deg: f64,
    /// Largest distance of a face from its plane, scene units (default: 1e-4 of the scene's
    /// bounding-box diagonal).
    #[arg(long)]
    pub distance_tolerance: Option<f64>,
}

/// `glassdb mirror`'s glass patterns (--glass-material's, then --glass's) and each one's pane
/// groups' depths (a --glass id's unit from the registry; none for --glass-material).
fn mirror_glass(args: &MirrorArgs) -> anyhow::Result<(Vec<String>, Vec<Vec<f64>>)> {
    let mut patterns = args.glass_material.clone();
    let mut depths = vec![Vec::new(); patterns.len()];
    if args.glass.is_empty() {
        return Ok((patterns, depths));
    }
    let (registry, label) = super::compose::load_registry(args.registry.as_deref())?;
    let table = registry.default_table();
    for spec in &args.glass {
        let m = GlassMapping::parse(spec).with_context(|| format!("--glass {spec}"))?;
        let Some(g) = table.glasses.iter().find(|g| g.id == m.id) else {
            bail!("--glass {spec}: glass id {} is not in {label}", m.id);
        };
        let unit_depths = match &g.unit {
            Some(u) if u.groups.len() > 1 => u.group_depths_m().with_context(|| {
                format!(
                    "--glass {spec}: unit {} ({}) does not record its pane groups' depths (every layer needs a thickness)",
                    m.id, g.name
                )
            })?,
            _ => Vec::new(),
        };
        patterns.push(m.pattern);
        depths.push(unit_depths);
    }
    Ok((patterns, depths))
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CosArg {
    /// |n · d| of each pixel's centre ray.
    Exact,
    /// The paper's way: cos θ at the nodes of an N×N mesh per pane, interpolated (see --mesh).
    Gouraud,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FormatArg {
    /// 8-bit RGB PNG: R plane, G id (1–255), B cos θ·255.
    Png8,
    /// 16-bit RGB PNG: R plane, G id, B cos θ·65535.
    Png16,
    /// OpenEXR float channels id, cos_theta, plane, coverage.
    Exr,
    /// The paper's binary mask: grey PNG, white = glass (one glass, one plane, no angle;
    /// grey = partial coverage with --samples); compose reads it with --glass ID.
    Binary,
}

#[derive(Debug, clap::Args)]
pub struct MaskArgs {
    /// The OBJ scene.
    pub scene: PathBuf,
    /// Camera JSON (docs/scene.md): origin, target, up or Blender's matrix_world; fov_x_deg or
    /// Blender's focal_length_mm, sensor and sensor_fit; shift_x, shift_y, pixel_aspect; width,
    /// height. Animations: `camera.####.json` (one file per frame, with --frames) or one file
    /// with a "frames" object.
    #[arg(long, value_name = "CAMERA.json")]
    pub camera: PathBuf,
    /// PATTERN=ID: faces whose material matches the glob PATTERN are glass with registration
    /// id ID (1–65535); repeatable, first match wins. Every other face is opaque.
    #[arg(long = "glass", value_name = "PATTERN=ID", required = true)]
    pub glass: Vec<String>,
    /// Output mask: .png (8-bit packed unless --format png16 or binary) or .exr; with several
    /// frames, `####` is replaced by the zero-padded frame number (`mask.####.png`).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Frames of an animation, e.g. `1-24` or `1,5,10-20`: `####` in --camera and -o is
    /// replaced by the zero-padded frame number (default: every frame of a camera file with a
    /// "frames" object).
    #[arg(long, value_name = "LIST")]
    pub frames: Option<String>,
    /// Output format, overriding the one the extension implies.
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
    /// How cos θ is computed.
    #[arg(long, value_enum, default_value = "exact")]
    pub cos: CosArg,
    /// Mesh size N of --cos gouraud (N×N cells per pane).
    #[arg(long, value_name = "N")]
    pub mesh: Option<u32>,
    /// K: a coverage channel from K×K sub-pixel rays (EXR output, or grey edges of a binary mask).
    #[arg(long, value_name = "K", default_value_t = 1)]
    pub samples: u32,
    /// Take the plane indices from a planes.json of `glassdb mirror`, so that they select the
    /// matching reflection passes. Default: detect them as `mirror` does.
    #[arg(long, value_name = "PLANES.json")]
    pub planes: Option<PathBuf>,
    /// Also write each plane's screen rectangle (pixel bounds, Blender render border) to this
    /// JSON file, `####` replaced by the frame number as in -o (docs/scene.md, "Plane bounds").
    #[arg(long, value_name = "BOUNDS.json")]
    pub bounds: Option<PathBuf>,
    /// Registry whose units give --bounds each deeper pane group's rectangle (default: the
    /// bundled one; an id it lacks counts as one group).
    #[arg(long, value_name = "FILE", requires = "bounds")]
    pub registry: Option<PathBuf>,
    /// Plane grouping: largest angle between face normals, degrees.
    #[arg(long, default_value_t = 0.1)]
    pub angle_tolerance_deg: f64,
    /// Plane grouping: largest distance of a face from its plane, scene units (default: 1e-4
    /// of the scene's bounding-box diagonal, or the planes file's tolerance).
    #[arg(long)]
    pub distance_tolerance: Option<f64>,
}

/// Parses `n` comma-separated finite numbers.
fn parse_numbers<const N: usize>(text: &str, what: &str) -> anyhow::Result<[f64; N]> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != N {
        bail!(
            "{what} {text:?}: expected {N} comma-separated numbers, found {}",
            parts.len()
        );
    }
    let mut out = [0.0; N];
    for (k, p) in parts.iter().enumerate() {
        out[k] = p
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .with_context(|| format!("{what} {text:?}: {p:?} is not a finite number"))?;
    }
    Ok(out)
}

fn print_warnings(warnings: &[SceneWarning]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}

pub fn run_mirror(args: MirrorArgs) -> anyhow::Result<ExitCode> {
    let plane = args
        .plane
        .as_deref()
        .map(|p| parse_numbers::<4>(p, "--plane"))
        .transpose()?;
    let eye = args
        .eye
        .as_deref()
        .map(|e| parse_numbers::<3>(e, "--eye"))
        .transpose()?;
    let (glass_patterns, pane_groups) = mirror_glass(&args)?;
    if plane.is_none() && glass_patterns.is_empty() {
        bail!(
            "give the glass materials (--glass-material PATTERN or --glass PATTERN=ID) or one plane (--plane a,b,c,d)"
        );
    }
    let scene = load_obj(&args.scene)?;
    print_warnings(&scene.warnings);
    let mut tolerance = PlaneTolerance::default_for(&scene);
    tolerance.angle_deg = args.angle_tolerance_deg;
    if let Some(d) = args.distance_tolerance {
        tolerance.distance = d;
    }
    let report = write_virtual_scenes(&MirrorRequest {
        scene: &scene,
        glass_patterns,
        explicit_plane: plane,
        eye,
        tolerance,
        out_dir: &args.out_dir,
        pane_groups,
    })
    .map_err(anyhow::Error::new)?;
    outln!(
        "{} glass plane{} in {} ({} triangles; tolerance {}°, {:e} units)",
        report.planes.planes.len(),
        if report.planes.planes.len() == 1 {
            ""
        } else {
            "s"
        },
        args.scene.display(),
        scene.triangle_count(),
        tolerance.angle_deg,
        tolerance.distance
    );
    for (p, stats) in report.planes.planes.iter().zip(&report.stats) {
        let [a, b, c, d] = p.equation;
        outln!(
            "plane {}: {a:.6}x {:+.6}y {:+.6}z {:+.6} = 0  area {:.6}  {} glass triangles  materials [{}]  eye sees the {}  -> {} ({} triangles, {} clipped, {} behind)",
            p.index,
            b,
            c,
            d,
            p.area,
            p.triangles,
            p.materials.join(", "),
            p.eye_side,
            args.out_dir.join(&p.file).display(),
            stats.written,
            stats.clipped,
            stats.behind,
        );
        for g in &p.groups {
            outln!(
                "  pane group {}: {:.1} mm behind the face -> {} ({} triangles, {} clipped)",
                g.group,
                g.depth * 1e3,
                args.out_dir.join(&g.file).display(),
                g.triangles_written,
                g.triangles_clipped
            );
        }
    }
    outln!("wrote {}", report.planes_path.display());
    Ok(ExitCode::SUCCESS)
}

/// The mask format from `--format` or the output's extension.
fn mask_format(output: &Path, format: Option<FormatArg>) -> anyhow::Result<MaskFormat> {
    let by_ext = match glassdb_io::lowercase_extension(output).as_deref() {
        Some("png") => Some(MaskFormat::Png8),
        Some("exr") => Some(MaskFormat::Exr),
        _ => None,
    };
    let chosen = match format {
        Some(FormatArg::Png8) => MaskFormat::Png8,
        Some(FormatArg::Png16) => MaskFormat::Png16,
        Some(FormatArg::Exr) => MaskFormat::Exr,
        Some(FormatArg::Binary) => MaskFormat::Binary,
        None => by_ext.with_context(|| {
            format!(
                "cannot tell the mask format of {}: use a .png or .exr name, or --format",
                output.display()
            )
        })?,
    };
    match (by_ext, chosen) {
        (Some(MaskFormat::Exr), MaskFormat::Png8 | MaskFormat::Png16 | MaskFormat::Binary)
        | (Some(MaskFormat::Png8), MaskFormat::Exr) => {
            bail!(
                "--format does not match the extension of {}",
                output.display()
            )
        }
        _ => Ok(chosen),
    }
}

/// The checks of `glassdb mask`'s arguments (each error names its flag), and what they ask
/// for: the mask format, the raster options, the glass mappings, the camera and its frames.
struct MaskArgsChecked {
    format: MaskFormat,
    options: RasterOptions,
    mappings: Vec<GlassMapping>,
    source: CameraSource,
    frames: Option<Vec<u32>>,
}

impl MaskArgsChecked {
    fn of(args: &MaskArgs) -> anyhow::Result<MaskArgsChecked> {
        let format = mask_format(&args.output, args.format)?;
        if args.samples >= 2 && !matches!(format, MaskFormat::Exr | MaskFormat::Binary) {
            bail!(
                "--samples {} makes a coverage channel, which only an EXR or a binary mask holds: \
                 write a .exr or use --format binary",
                args.samples
            );
        }
        let cos = match (args.cos, args.mesh) {
            (CosArg::Exact, None) => CosMode::Exact,
            (CosArg::Exact, Some(_)) => bail!("--mesh only applies to --cos gouraud"),
            (CosArg::Gouraud, mesh) => CosMode::Gouraud {
                mesh: mesh.unwrap_or(8),
            },
        };
        let options = RasterOptions {
            cos,
            samples: args.samples,
        };
        glassdb_scene::raster::check_options(&options).map_err(anyhow::Error::new)?;
        let mappings = args
            .glass
            .iter()
            .map(|g| GlassMapping::parse(g))
            .collect::<Result<Vec<_>, _>>()?;
        check_mappings(&mappings, format)?;
        let source = CameraSource::open(&args.camera)?;
        let frames = match (&args.frames, source.frames()) {
            (Some(spec), _) => Some(glassdb_io::parse_frame_list(spec)?),
            (None, in_file) => in_file,
        };
        check_frame_patterns(args, &source, frames.as_deref())?;
        Ok(MaskArgsChecked {
            format,
            options,
            mappings,
            source,
            frames,
        })
    }
}

/// The glass mappings fit the mask format: ids of an 8-bit PNG up to 255, one glass in a
/// binary mask.
fn check_mappings(mappings: &[GlassMapping], format: MaskFormat) -> anyhow::Result<()> {
    if format == MaskFormat::Png8
        && let Some(m) = mappings.iter().find(|m| m.id > 255)
    {
        bail!(
            "glass id {} ({}) does not fit an 8-bit PNG mask (ids 1-255): use --format png16 or a .exr output",
            m.id,
            m.pattern
        );
    }
    if format == MaskFormat::Binary && mappings.len() > 1 {
        bail!(
            "a binary mask shows one glass, but {} --glass mappings were given: \
             write a packed PNG or EXR mask for several",
            mappings.len()
        );
    }
    Ok(())
}

/// Frames and `####` agree: an animated camera needs frames, a pattern needs frames, several
/// frames need a pattern, and -o and --bounds both have one or neither.
fn check_frame_patterns(
    args: &MaskArgs,
    source: &CameraSource,
    frames: Option<&[u32]>,
) -> anyhow::Result<()> {
    match frames {
        None if source.is_animated() => bail!(
            "the camera {} has one file per frame: choose the frames with --frames (e.g. 1-24)",
            args.camera.display()
        ),
        None if glassdb_io::is_frame_pattern(&args.output) => bail!(
            "the output {} has #### for a frame number, but there are no frames: give --frames \
             with an animated camera",
            args.output.display()
        ),
        Some(f) if f.len() > 1 && !glassdb_io::is_frame_pattern(&args.output) => bail!(
            "the output {} has no #### for the frame number, so every frame would overwrite it",
            args.output.display()
        ),
        _ => {}
    }
    if let Some(bounds) = &args.bounds
        && glassdb_io::is_frame_pattern(bounds) != glassdb_io::is_frame_pattern(&args.output)
    {
        bail!(
            "--bounds {} and -o {} must both have #### for the frame number, or neither",
            bounds.display(),
            args.output.display()
        );
    }
    Ok(())
}

pub fn run_mask(args: MaskArgs) -> anyhow::Result<ExitCode> {
    let checked = MaskArgsChecked::of(&args)?;
    // Every file the mask is made from: the OBJ, its material libraries (declared as it is
    // read), the planes file and the camera (of each frame, as it is read). No output may
    // replace one.
    glassdb_io::declare_inputs(
        [args.scene.as_path(), args.camera.as_path()]
            .into_iter()
            .chain(args.planes.as_deref()),
    );
    let single = checked.frames.is_none();
    if single {
        glassdb_io::refuse_input_as_output(&args.output)?;
    }

    let spinner = Spinner::on_terminal("mask");
    spinner.stage("load scene");
    let t0 = Instant::now();
    let scene = load_obj(&args.scene)?;
    spinner.suspend(|| print_warnings(&scene.warnings));
    if single {
        glassdb_io::refuse_input_as_output(&args.output)?;
    }
    let planes = match &args.planes {
        Some(path) => MaskPlanes::File {
            path: path.clone(),
            angle_deg: args.angle_tolerance_deg,
            distance: args.distance_tolerance,
        },
        None => MaskPlanes::Detect {
            angle_deg: args.angle_tolerance_deg,
            distance: args.distance_tolerance,
        },
    };
    spinner.stage("label glass planes");
    let gouraud = matches!(checked.options.cos, CosMode::Gouraud { .. });
    let labelled = label_scene(&scene, &checked.mappings, &planes, gouraud)?;
    spinner.suspend(|| {
        for p in &labelled.unmatched_patterns {
            eprintln!("warning: --glass {p} matches no material with faces");
        }
    });
    let t_load = t0.elapsed();
    let job = MaskJob {
        labelled: &labelled,
        cameras: &checked.source,
        options: checked.options,
        format: checked.format,
        output: args.output.clone(),
        bounds: args.bounds.clone(),
        pane_groups: mask_pane_groups(&args, &checked.mappings)?,
    };
    let summary = MaskSummary {
        args: &args,
        scene: &scene,
        labelled: &labelled,
        t_load,
    };
    match &checked.frames {
        None => summary.single(&job, &spinner),
        Some(frames) => summary.frames(&job, frames, &spinner),
    }
}

/// Pane groups of each --glass id that is a unit in the registry, for --bounds' group
/// rectangles (none without --bounds).
fn mask_pane_groups(
    args: &MaskArgs,
    mappings: &[GlassMapping],
) -> anyhow::Result<std::collections::BTreeMap<u16, usize>> {
    if args.bounds.is_none() {
        return Ok(Default::default());
    }
    let (registry, _) = super::compose::load_registry(args.registry.as_deref())?;
    let table = registry.default_table();
    Ok(mappings
        .iter()
        .filter_map(|m| {
            let groups = table.glass(m.id)?.unit.as_ref()?.groups.len();
            (groups > 1).then_some((m.id, groups))
        })
        .collect())
}

/// What `glassdb mask` prints of its scene and masks.
struct MaskSummary<'a> {
    args: &'a MaskArgs,
    scene: &'a Scene,
    labelled: &'a MaskScene,
    t_load: std::time::Duration,
}

impl MaskSummary<'_> {
    /// `N plane(s)`: `""` or `"s"`.
    fn plural(&self) -> &'static str {
        if self.labelled.planes.len() == 1 {
            ""
        } else {
            "s"
        }
    }

    /// One mask, and what it holds.
    fn single(&self, job: &MaskJob<'_>, spinner: &Spinner) -> anyhow::Result<ExitCode> {
        let t1 = Instant::now();
        let mask = mask_frame(job, None, spinner)?;
        let t_raster = t1.elapsed();
        spinner.finish();
        outln!(
            "{}x{} mask of {} ({} triangles, {} glass on {} plane{}; {} in view) -> {}",
            mask.width,
            mask.height,
            self.args.scene.display(),
            self.scene.triangle_count(),
            self.labelled.glass_triangles,
            self.labelled.planes.len(),
            self.plural(),
            mask.drawn,
            self.args.output.display()
        );
        if mask.id_pixels.is_empty() {
            outln!("no glass is visible from this camera");
        }
        for (id, n) in &mask.id_pixels {
            outln!("id {id}: {n} pixels");
        }
        outln!(
            "load {:.3} s, rasterise {:.3} s",
            self.t_load.as_secs_f64(),
            t_raster.as_secs_f64()
        );
        Ok(ExitCode::SUCCESS)
    }

    /// An animation: the scene is labelled once; each frame has its own camera and output. A
    /// frame that fails is reported and the others go on.
    fn frames(
        &self,
        job: &MaskJob<'_>,
        frames: &[u32],
        spinner: &Spinner,
    ) -> anyhow::Result<ExitCode> {
        spinner.suspend(|| {
            outln!(
                "{} ({} triangles, {} glass on {} plane{}), {} frame(s)",
                self.args.scene.display(),
                self.scene.triangle_count(),
                self.labelled.glass_triangles,
                self.labelled.planes.len(),
                self.plural(),
                frames.len()
            )
        });
        let t1 = Instant::now();
        let mut failed: Vec<u32> = Vec::new();
        mask_frames(job, frames, spinner, &mut |frame, result| {
            match result {
                Ok(mask) => {
                    let glass: u64 = mask.id_pixels.values().sum();
                    spinner.suspend(|| {
                        outln!(
                            "frame {frame}: {}x{}, {glass} glass pixels -> {}",
                            mask.width,
                            mask.height,
                            mask.output.display()
                        )
                    });
                }
                Err(e) => {
                    let e = anyhow::Error::new(e);
                    spinner.suspend(|| {
                        eprintln!(
                            "frame {frame}: error: {}",
                            crate::cmd::hints::with_hints(&e)
                        )
                    });
                    failed.push(frame);
                }
            }
            ControlFlow::Continue(())
        });
        spinner.finish();
        outln!(
            "load {:.3} s, rasterise and write {:.3} s",
            self.t_load.as_secs_f64(),
            t1.elapsed().as_secs_f64()
        );
        Ok(crate::cmd::frames_exit(&failed, frames.len()))
    }
}
