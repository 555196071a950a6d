//! `glassdb mirror` as a library call: find the glass planes, write one virtual scene per
//! plane and `planes.json`.

use glassdb_side::Side;
use std::path::{Component, Path, PathBuf};

use crate::error::SceneError;
use crate::math::Vec3;
use crate::mirror::{MirrorStats, mirror_scene};
use crate::obj::{Mesh, Scene, stage_obj};
use crate::pane_groups::{GroupEntry, group_scene_name, plane_group_depths, shifted};
use crate::planes::{GlassPlane, MaterialMatcher, Plane, PlaneTolerance, detect_planes};
use crate::planes_file::{PLANES_FORMAT, PlaneEntry, PlanesFile, ToleranceJson};

/// What to mirror and where to put it.
#[derive(Debug, Clone)]
pub struct MirrorRequest<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// Glob patterns of the glass materials (may be empty with an explicit plane).
    pub glass_patterns: Vec<String>,
    /// One explicit plane `[a, b, c, d]` instead of detection.
    pub explicit_plane: Option<[f64; 4]>,
    /// The eye: selects the kept half-space of each plane. Without it, the front side.
    pub eye: Option<Vec3>,
    /// How faces are grouped into planes.
    pub tolerance: PlaneTolerance,
    /// Where the virtual scenes and `planes.json` go.
    pub out_dir: &'a Path,
    /// Per glass pattern (as `glass_patterns`), the depths behind the face of its glass's pane
    /// groups, outside first, in scene units (metres): a unit's groups get a virtual scene
    /// each (issue 27). Empty, or one depth: glass of one group, mirrored about the face.
    pub pane_groups: Vec<Vec<f64>>,
}

/// What was written.
#[derive(Debug, Clone)]
pub struct MirrorReport {
    /// The `planes.json` written.
    pub planes_path: PathBuf,
    /// What it holds.
    pub planes: PlanesFile,
    /// Each virtual scene's counts.
    pub stats: Vec<MirrorStats>,
}

/// File name of plane `k`'s virtual scene.
pub fn virtual_scene_name(k: usize) -> String {
    format!("plane_{k}.obj")
}

/// `target` relative to directory `base`, when both resolve; otherwise `target` absolute.
fn relative_to(target: &Path, base: &Path) -> String {
    let (Ok(t), Ok(b)) = (target.canonicalize(), base.canonicalize()) else {
        return std::path::absolute(target)
            .unwrap_or_else(|_| target.to_path_buf())
            .display()
            .to_string();
    };
    let tc: Vec<Component<'_>> = t.components().collect();
    let bc: Vec<Component<'_>> = b.components().collect();
    let common = tc.iter().zip(&bc).take_while(|(x, y)| x == y).count();
    let mut rel = PathBuf::new();
    for _ in common..bc.len() {
        rel.push("..");
    }
    for c in &tc[common..] {
        rel.push(c.as_os_str());
    }
    rel.display().to_string()
}

/// Finds the planes (or takes the explicit one), writes `plane_<k>.obj` for each and
/// `planes.json` into `out_dir` (created if missing). All glass faces are dropped from every
/// virtual scene: reflection passes, like the transmission pass, are rendered without glass.
/// The files land together or not at all (`glassdb_io::StagedOutput`): on any failure none is
/// written, and an `out_dir` this call created is removed again.
pub fn write_virtual_scenes(req: &MirrorRequest<'_>) -> Result<MirrorReport, SceneError> {
    let created = !req.out_dir.exists();
    let result = write_virtual_scenes_staged(req);
    if result.is_err() && created {
        let _ = std::fs::remove_dir(req.out_dir); // only when still empty
    }
    result
}

fn write_virtual_scenes_staged(req: &MirrorRequest<'_>) -> Result<MirrorReport, SceneError> {
    let scene = req.scene;
    req.tolerance.validate()?;
    let glass_table = if req.glass_patterns.is_empty() {
        vec![None; scene.materials.len()]
    } else {
        MaterialMatcher::new(&req.glass_patterns)?.require_faces(scene)?
    };
    let is_glass = |m: Option<usize>| {
        m.and_then(|i| glass_table.get(i).copied().flatten())
            .is_some()
    };
    let planes = glass_planes(req, is_glass)?;
    glassdb_io::create_output_folder(req.out_dir, "output directory")?;
    let mtllibs = mtllibs_from(scene, req.out_dir);
    let mut staged = glassdb_io::StagedOutput::new();
    let mut entries = Vec::with_capacity(planes.len());
    let mut all_stats = Vec::with_capacity(planes.len());
    let matcher = if req.glass_patterns.is_empty() {
        None
    } else {
        Some(MaterialMatcher::new(&req.glass_patterns)?)
    };
    for gp in &planes {
        let (_, eye_side) = kept_side(gp, req.eye, req.tolerance.distance)?;
        let depths = plane_group_depths(gp, matcher.as_ref(), &req.pane_groups, eye_side)?;
        let mut groups = Vec::with_capacity(depths.len());
        let mut first = None;
        for (g, &depth) in depths
            .iter()
            .enumerate()
            .chain(depths.is_empty().then_some((0, &0.0)))
        {
            let mirror_plane = GlassPlane {
                plane: shifted(&gp.plane, depth),
                ..gp.clone()
            };
            let (kept, _) = kept_side(&mirror_plane, req.eye, req.tolerance.distance)?;
            let (meshes, stats) = mirror_scene(scene, &kept, req.tolerance.distance, |m, _| {
                is_glass(scene.meshes[m].material)
            });
            let name = if g == 0 {
                virtual_scene_name(gp.index)
            } else {
                group_scene_name(gp.index, g)
            };
            let file = write_plane_scene(
                &mut staged,
                scene,
                (&mirror_plane, &name),
                eye_side,
                &mtllibs,
                &meshes,
                req.out_dir,
            )?;
            if !depths.is_empty() {
                groups.push(GroupEntry {
                    group: g,
                    depth,
                    equation: mirror_plane.plane.equation(),
                    reflection_matrix: mirror_plane.plane.reflection_matrix(),
                    file: file.clone(),
                    triangles_written: stats.written,
                    triangles_clipped: stats.clipped,
                });
            }
            if g == 0 {
                first = Some((mirror_plane.plane, file, stats));
            }
        }
        let Some((first_plane, file, stats)) = first else {
            continue;
        };
        entries.push(PlaneEntry {
            index: gp.index,
            equation: gp.plane.equation(),
            area: gp.area,
            materials: gp.materials.clone(),
            triangles: gp.triangles,
            eye_side,
            reflection_matrix: first_plane.reflection_matrix(),
            file,
            triangles_written: stats.written,
            triangles_clipped: stats.clipped,
            groups,
        });
        all_stats.push(stats);
    }
    let file = PlanesFile {
        format: PLANES_FORMAT.to_string(),
        source: scene.source.display().to_string(),
        eye: req.eye,
        tolerance: ToleranceJson {
            angle_deg: req.tolerance.angle_deg,
            distance: req.tolerance.distance,
        },
        planes: entries,
    };
    let planes_path = write_planes_file(&mut staged, &file, req.out_dir)?;
    staged.commit()?;
    Ok(MirrorReport {
        planes_path,
        planes: file,
        stats: all_stats,
    })
}

/// The glass planes to mirror across: the explicit one, or those detected among the glass
/// faces; at most as many as a mask's plane index can tell apart.
fn glass_planes(
    req: &MirrorRequest<'_>,
    is_glass: impl Fn(Option<usize>) -> bool,
) -> Result<Vec<GlassPlane>, SceneError> {
    let planes = match req.explicit_plane {
        Some(eq) => vec![explicit_glass_plane(
            req.scene,
            Plane::from_equation(eq)?,
            is_glass,
            req.tolerance.distance,
        )],
        None => {
            if req.glass_patterns.is_empty() {
                return Err(SceneError::NoGlassSelected);
            }
            let patterns = MaterialMatcher::new(&req.glass_patterns)?.describe();
            detect_planes(req.scene, is_glass, req.tolerance, &patterns)?.0
        }
    };
    if planes.len() > u16::MAX as usize {
        return Err(SceneError::BadOption {
            message: format!("{} glass planes: at most 65535 fit a mask", planes.len()),
        });
    }
    Ok(planes)
}

/// The given plane as plane 0, with the area, triangles and materials of the glass faces
/// lying on it (within `distance`).
fn explicit_glass_plane(
    scene: &Scene,
    plane: Plane,
    is_glass: impl Fn(Option<usize>) -> bool,
    distance: f64,
) -> GlassPlane {
    let (mut area, mut triangles, mut materials) = (0.0, 0usize, Vec::<String>::new());
    for mesh in &scene.meshes {
        if !is_glass(mesh.material) {
            continue;
        }
        for t in 0..mesh.triangles.len() {
            let c = mesh.corners(t);
            if c.iter()
                .all(|&p| plane.signed_distance(p).abs() <= distance)
            {
                let a2 = crate::math::triangle_normal_area2(c[0], c[1], c[2]);
                area += 0.5 * crate::math::norm(a2);
                triangles += 1;
                let name = scene.material_name(mesh).to_string();
                if !materials.contains(&name) {
                    materials.push(name);
                }
            }
        }
    }
    GlassPlane {
        index: 0,
        plane,
        area,
        materials,
        triangles,
    }
}

/// The scene's material libraries as the virtual scenes in `out_dir` refer to them.
fn mtllibs_from(scene: &Scene, out_dir: &Path) -> Vec<String> {
    let src_dir = scene
        .source
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let src_dir = if src_dir.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        src_dir
    };
    scene
        .mtllibs
        .iter()
        .map(|lib| relative_to(&src_dir.join(lib), out_dir))
        .collect()
}

/// The plane oriented so that the kept half-space holds the eye (front without an eye), and
/// the side the eye sees. An eye on the plane is an error.
fn kept_side(
    gp: &GlassPlane,
    eye: Option<Vec3>,
    distance: f64,
) -> Result<(Plane, Side), SceneError> {
    let Some(eye) = eye else {
        return Ok((gp.plane, Side::Front));
    };
    let s = gp.plane.signed_distance(eye);
    if s.abs() <= distance {
        return Err(SceneError::EyeOnPlane {
            eye,
            plane: gp.index,
            distance: s,
        });
    }
    Ok(if s > 0.0 {
        (gp.plane, Side::Front)
    } else {
        (gp.plane.flipped(), Side::Back)
    })
}

/// Stages the virtual scene `name` mirrored about `gp`'s plane (a glass plane, or a pane
/// group's mid-plane behind it) for `out_dir`; returns its file name.
fn write_plane_scene(
    staged: &mut glassdb_io::StagedOutput,
    scene: &Scene,
    (gp, name): (&GlassPlane, &str),
    eye_side: Side,
    mtllibs: &[String],
    meshes: &[Mesh],
    out_dir: &Path,
) -> Result<String, SceneError> {
    let path = out_dir.join(name);
    glassdb_io::refuse_input_as_output(&path)?;
    let header = vec![
        format!(
            "virtual scene of {} (glassdb mirror)",
            scene.source.display()
        ),
        format!(
            "mirrored across glass plane {}: {:?}·(x, y, z, 1) = 0, eye side: {eye_side}",
            gp.index,
            gp.plane.equation()
        ),
        "geometry behind the plane removed, faces crossing it clipped, glass faces dropped"
            .to_string(),
    ];
    stage_obj(staged, &path, &header, mtllibs, &scene.materials, meshes)?;
    Ok(name.to_string())
}

/// Stages `planes.json` for `out_dir`; returns its path.
fn write_planes_file(
    staged: &mut glassdb_io::StagedOutput,
    file: &PlanesFile,
    out_dir: &Path,
) -> Result<PathBuf, SceneError> {
    let planes_path = out_dir.join("planes.json");
    glassdb_io::refuse_input_as_output(&planes_path)?;
    let json = serde_json::to_string_pretty(file).map_err(|source| SceneError::EncodeJson {
        path: planes_path.clone(),
        source,
    })?;
    staged.write_bytes(&planes_path, format!("{json}\n").as_bytes())?;
    Ok(planes_path)
}
