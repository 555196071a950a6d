//! Glassdb's own geometry of a `glassdb blender render` run, per frame: the planes, the masks,
//! each plane's side and pixel rectangle, and the glass as thin panes for Blender. Frames whose
//! objects are where the first frame has them share its scene; a frame whose objects moved
//! (an animated object, a sliding door) has its own (`scene.NNNN.obj`, `planes.NNNN/`).

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use glassdb_image::PixelWindow;
use glassdb_mask::{GlassMapping, MaskFormat};
use glassdb_scene::{
    CameraSource, FrameMask, MaskJob, MaskPlanes, MirrorRequest, PlaneSource, PlaneTolerance,
    label_scene, load_obj, mask_frames, write_virtual_scenes,
};
use glassdb_side::Side;

use crate::BlenderError;
use crate::job::{ExportInfo, FrameRecord, GroupPassRecord, PixelBounds, ScriptFrame, ScriptPlane};
use crate::pipeline::{RegistryChoice, Workspace, frame_name, moving_obj_name};
use crate::thin_pane::ThinPane;

/// The planes, masks and each plane's pixels of every frame, and what Blender renders next.
pub struct Masks {
    /// Glass planes found.
    pub(crate) planes: usize,
    /// Each glass material and its registry id.
    pub(crate) glass_materials: Vec<(String, u16)>,
    /// The glass as the thin-pane shader draws it.
    pub(crate) panes: Vec<ThinPane>,
    /// Each frame's files, sides and plane rectangles.
    pub(crate) frames: Vec<FrameRecord>,
    /// What Blender renders of each frame.
    pub(crate) script_frames: Vec<ScriptFrame>,
    /// Each frame's plane rectangles, where its crops go.
    pub(crate) crops: Vec<Vec<Option<PixelWindow>>>,
    /// The frames' size.
    pub(crate) size: (u32, u32),
}

/// glassdb's own geometry, per frame: the planes (`glassdb mirror`'s detection, from the
/// frame's eye; `planes.json` from the first frame, `planes.NNNN/planes.json` for a frame whose
/// objects moved), the mask (`glassdb_scene::mask_frames`, float EXR), each plane's side and
/// pixel rectangle, and the glass as thin panes for Blender. Frames whose geometry is the first
/// frame's share its scene, planes and labelling.
pub fn planes_and_masks(
    work: &Workspace<'_>,
    info: &ExportInfo,
    registry: &RegistryChoice,
) -> Result<Masks, BlenderError> {
    let dir = &work.dir;
    let cameras = CameraSource::open(&dir.join("camera.json"))?;
    let Some(&first_frame) = info.frames.first() else {
        return Err(BlenderError::BadRender {
            path: dir.join("export.json"),
            message:
                "no frames to render (the scene's frame range, or the frames asked for, is empty)"
                    .into(),
        });
    };
    let glass_materials = glass_of_materials(&info.materials, &work.mappings)?;
    let panes = thin_panes(&glass_materials, registry)?;
    let units = RunUnits::of(work, registry)?;
    let mut frames = FramesOfMasks {
        work,
        planes: Vec::new(),
        plane_depths: Vec::new(),
        tolerance: 0.0,
        apertures: Vec::new(),
        first_frame,
        size: None,
        records: Vec::new(),
        script_frames: Vec::new(),
        crops: Vec::new(),
        error: None,
    };
    let mut planes_found = 0;
    for group in scene_groups(info, dir) {
        let scene = load_obj(&group.obj)?;
        let eye = cameras.camera(Some(group.frames[0]))?.origin;
        let report = write_virtual_scenes(&MirrorRequest {
            scene: &scene,
            glass_patterns: work.mappings.iter().map(|m| m.pattern.clone()).collect(),
            explicit_plane: None,
            eye: Some(eye),
            tolerance: PlaneTolerance::default_for(&scene),
            out_dir: &group.planes_dir,
            pane_groups: units.depths.clone(),
        })?;
        frames.planes = report.planes.planes();
        frames.plane_depths = report
            .planes
            .planes
            .iter()
            .map(|p| outer_first(&p.groups))
            .collect();
        frames.tolerance = report.planes.tolerance.distance;
        planes_found = planes_found.max(frames.planes.len());
        let source = PlaneSource::Given {
            planes: frames.planes.clone(),
            tolerance: report.planes.tolerance(),
        };
        let labelled = label_scene(&scene, &work.mappings, &MaskPlanes::Given(source), false)?;
        drop(scene);
        frames.apertures =
            crate::light_split::apertures(&labelled, &glass_materials, frames.tolerance);
        let job = MaskJob {
            labelled: &labelled,
            cameras: &cameras,
            options: work.options,
            format: MaskFormat::Exr,
            output: dir.join("mask.####.exr"),
            bounds: None,
            pane_groups: units.counts.clone(),
        };
        mask_frames(
            &job,
            &group.frames,
            &glassdb_io::NoProgress,
            &mut |frame, mask| match mask
                .map_err(BlenderError::from)
                .and_then(|m| frames.add(frame, &m))
            {
                Ok(()) => ControlFlow::Continue(()),
                Err(e) => {
                    frames.error = Some(e);
                    ControlFlow::Break(())
                }
            },
        );
        if let Some(e) = frames.error.take() {
            return Err(e);
        }
    }
    frames.sort();
    Ok(Masks {
        planes: planes_found,
        glass_materials,
        panes,
        frames: frames.records,
        script_frames: frames.script_frames,
        crops: frames.crops,
        size: frames.size.unwrap_or_default(),
    })
}

/// Frames that share one exported scene: its OBJ and where its planes go.
struct SceneGroup {
    obj: PathBuf,
    planes_dir: PathBuf,
    frames: Vec<u32>,
}

/// The first frame's scene with every frame whose geometry is the same, then one group per
/// frame whose objects moved.
fn scene_groups(info: &ExportInfo, dir: &Path) -> Vec<SceneGroup> {
    let still = SceneGroup {
        obj: dir.join("scene.obj"),
        planes_dir: dir.to_path_buf(),
        frames: info
            .frames
            .iter()
            .copied()
            .filter(|f| !info.moving.contains_key(f))
            .collect(),
    };
    let moving = info.moving.keys().map(|&f| SceneGroup {
        obj: dir.join(moving_obj_name(f)),
        planes_dir: dir.join(format!("planes.{f:04}")),
        frames: vec![f],
    });
    std::iter::once(still)
        .chain(moving)
        .filter(|g| !g.frames.is_empty())
        .collect()
}

/// The frames' records and render jobs, gathered mask by mask.
struct FramesOfMasks<'w, 'a> {
    work: &'w Workspace<'a>,
    /// The planes of the frames being added.
    planes: Vec<glassdb_scene::Plane>,
    /// Each plane's pane-group depths behind its face, outer group first (empty: the glass is
    /// not a unit, mirrored about the face).
    plane_depths: Vec<Vec<f64>>,
    /// planes.json's distance tolerance.
    tolerance: f64,
    /// The apertures of the frames being added.
    apertures: Vec<crate::light_split::ScriptAperture>,
    first_frame: u32,
    /// The first frame's size, which every frame must have.
    size: Option<(u32, u32)>,
    records: Vec<FrameRecord>,
    script_frames: Vec<ScriptFrame>,
    crops: Vec<Vec<Option<PixelWindow>>>,
    error: Option<BlenderError>,
}

impl FramesOfMasks<'_, '_> {
    /// Puts the frames in frame order (they are added scene by scene).
    fn sort(&mut self) {
        let mut all: Vec<_> = std::mem::take(&mut self.records)
            .into_iter()
            .zip(std::mem::take(&mut self.script_frames))
            .zip(std::mem::take(&mut self.crops))
            .collect();
        all.sort_by_key(|((r, _), _)| r.frame);
        for ((r, s), c) in all {
            self.records.push(r);
            self.script_frames.push(s);
            self.crops.push(c);
        }
    }

    /// Adds frame `frame`, whose mask is `mask`: each plane's side (from the camera) and glass
    /// rectangle, where Blender renders its crop.
    fn add(&mut self, frame: u32, mask: &FrameMask) -> Result<(), BlenderError> {
        let (width, height) = *self.size.get_or_insert((mask.width, mask.height));
        if (mask.width, mask.height) != (width, height) {
            return Err(BlenderError::BadRender {
                path: self.work.dir.join("camera.json"),
                message: format!(
                    "frame {frame} is {}x{}, but frame {} is {width}x{height}; \
                     every frame of a run must have one size",
                    mask.width, mask.height, self.first_frame
                ),
            });
        }
        let rectangles: Vec<_> = (0..self.planes.len())
            .map(|k| {
                u16::try_from(k)
                    .ok()
                    .and_then(|k| mask.plane_bounds.get(&k))
            })
            .collect();
        let refl: Vec<String> = (0..self.planes.len())
            .map(|k| frame_name(&format!("refl_{k}"), frame))
            .collect();
        let mut sides = Vec::new();
        let mut script_planes = Vec::new();
        let mut groups = Vec::new();
        for (k, plane) in self.planes.iter().enumerate() {
            let front = plane.signed_distance(mask.camera_origin) >= 0.0;
            sides.push(if front { Side::Front } else { Side::Back });
            let mirrors = self.mirror_planes(k, front);
            if let Some(r) = rectangles[k] {
                let (facing, depth) = mirrors[0];
                script_planes.push(ScriptPlane {
                    index: k,
                    equation: facing.equation(),
                    tolerance: self.tolerance + depth,
                    border: r.blender_border(width, height),
                    output: self.work.staging.join(&refl[k]),
                });
            }
            let deeper = mirrors.iter().enumerate().skip(1).filter_map(|(g, m)| {
                let b = mask.group_bounds.get(&(u16::try_from(k).ok()?, g))?;
                Some((g, m, b))
            });
            for (g, &(facing, depth), b) in deeper {
                let file = frame_name(&format!("refl_{k}_{g}"), frame);
                script_planes.push(ScriptPlane {
                    index: k,
                    equation: facing.equation(),
                    tolerance: self.tolerance + depth,
                    border: b.blender_border(width, height),
                    output: self.work.staging.join(&file),
                });
                groups.push(GroupPassRecord {
                    plane: k,
                    group: g,
                    file,
                    depth_m: depth,
                    bounds: PixelBounds::from(b.window()),
                });
            }
        }
        self.script_frames.push(ScriptFrame {
            frame,
            trans: self.work.staging.join(frame_name("trans", frame)),
            planes: script_planes,
            apertures: self.apertures.clone(),
            lights: None,
        });
        let windows: Vec<Option<PixelWindow>> =
            rectangles.iter().map(|r| r.map(|r| r.window())).collect();
        self.records.push(FrameRecord {
            frame,
            trans: frame_name("trans", frame),
            mask: frame_name("mask", frame),
            refl,
            sides,
            bounds: windows.iter().map(|w| w.map(PixelBounds::from)).collect(),
            composite: frame_name("composite", frame),
            light_parts: None,
            groups,
        });
        self.crops.push(windows);
        Ok(())
    }
}

impl FramesOfMasks<'_, '_> {
    /// Plane `k`'s mirror planes facing the camera ([`mirror_planes`]).
    fn mirror_planes(&self, k: usize, front: bool) -> Vec<(glassdb_scene::Plane, f64)> {
        let depths = self.plane_depths.get(k).map_or(&[][..], Vec::as_slice);
        mirror_planes(&self.planes[k], depths, front, self.work.surfaces())
    }
}

/// The mirror planes of `plane` (its normal to the glass's front) facing a camera on its front
/// (`front`) or back, each with its depth behind the face: one per pane group at
/// `depths_outer_first`, in the order the camera's rays meet them (from the back the inner
/// pane first), at most `surfaces` of them; the face itself for glass of one group.
fn mirror_planes(
    plane: &glassdb_scene::Plane,
    depths_outer_first: &[f64],
    front: bool,
    surfaces: usize,
) -> Vec<(glassdb_scene::Plane, f64)> {
    let mut depths = depths_outer_first.to_vec();
    if !front {
        depths.reverse();
    }
    if depths.is_empty() {
        depths.push(0.0);
    }
    depths.truncate(surfaces.max(1));
    depths
        .into_iter()
        .map(|depth| {
            let shifted = glassdb_scene::Plane {
                normal: plane.normal,
                d: plane.d + depth,
            };
            (if front { shifted } else { shifted.flipped() }, depth)
        })
        .collect()
}

/// A plane's pane-group depths from planes.json, outer group first (the file lists them in the
/// order its eye meets them).
fn outer_first(groups: &[glassdb_scene::GroupEntry]) -> Vec<f64> {
    let mut depths: Vec<f64> = groups.iter().map(|g| g.depth).collect();
    depths.sort_by(f64::total_cmp);
    depths
}

/// The registry's units among the run's glass (issue 27).
struct RunUnits {
    /// Per `--glass` mapping, its unit's pane-group depths behind surface #1 (metres, outer
    /// first; empty for glass of one group), where `glassdb mirror` puts the mirror planes.
    depths: Vec<Vec<f64>>,
    /// Pane groups of each glass id that is a unit of two or more, for the masks' group
    /// rectangles.
    counts: std::collections::BTreeMap<u16, usize>,
}

impl RunUnits {
    /// The units of `work`'s glass mappings in the registry's table. With one pass per plane
    /// (`--surfaces 1`) every plane is mirrored about its face, as before pane groups (so a
    /// plane may hold glasses of different build-ups); otherwise a unit that does not record
    /// its groups' depths is refused.
    fn of(work: &Workspace<'_>, registry: &RegistryChoice) -> Result<RunUnits, BlenderError> {
        let table = registry.registry.default_table();
        let mut units = RunUnits {
            depths: Vec::new(),
            counts: Default::default(),
        };
        for m in &work.mappings {
            let unit = table
                .glass(m.id)
                .and_then(|g| g.unit.as_ref().map(|u| (g, u)))
                .filter(|(_, u)| u.groups.len() > 1);
            let Some((glass, unit)) = unit else {
                units.depths.push(Vec::new());
                continue;
            };
            units.counts.insert(m.id, unit.groups.len());
            match unit.group_depths_m() {
                _ if work.surfaces() == 1 => units.depths.push(Vec::new()),
                Some(d) => units.depths.push(d),
                None => {
                    return Err(BlenderError::BadOption(format!(
                        "glass {}={}: unit {} ({}) in {} does not record its pane groups' \
                         depths (every layer needs a thickness), so its deeper panes' \
                         reflections cannot be placed; render it with one pass per plane",
                        m.pattern, m.id, m.id, glass.name, registry.label
                    )));
                }
            }
        }
        Ok(units)
    }
}

/// Each glass material's registry record as the thin-pane shader's tables (the registry's
/// linear Rec.709 table, else its default one).
fn thin_panes(
    glass_materials: &[(String, u16)],
    registry: &RegistryChoice,
) -> Result<Vec<ThinPane>, BlenderError> {
    let table = crate::swap::shader_table(registry);
    glass_materials
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
        .collect()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The face z = 0 (normal +z, outdoors) of a unit with groups 3 and 21 mm behind it.
    #[test]
    fn mirror_planes_follow_the_cameras_rays_into_the_unit() {
        let face = glassdb_scene::Plane::from_equation([0.0, 0.0, 1.0, 0.0]).unwrap();
        let depths = [0.003, 0.021];
        let eq = |v: Vec<(glassdb_scene::Plane, f64)>| -> Vec<([f64; 4], f64)> {
            v.into_iter().map(|(p, d)| (p.equation(), d)).collect()
        };
        // From outdoors: the outer pane first, each mid-plane below the face, facing +z.
        assert_eq!(
            eq(mirror_planes(&face, &depths, true, usize::MAX)),
            [
                ([0.0, 0.0, 1.0, 0.003], 0.003),
                ([0.0, 0.0, 1.0, 0.021], 0.021)
            ]
        );
        // From indoors: the inner pane first, facing −z (the camera on the positive side).
        assert_eq!(
            eq(mirror_planes(&face, &depths, false, usize::MAX)),
            [
                ([0.0, 0.0, -1.0, -0.021], 0.021),
                ([0.0, 0.0, -1.0, -0.003], 0.003)
            ]
        );
        // --surfaces 1: the first group only; glass of one group: the face.
        assert_eq!(
            eq(mirror_planes(&face, &depths, false, 1)),
            [([0.0, 0.0, -1.0, -0.021], 0.021)]
        );
        assert_eq!(
            eq(mirror_planes(&face, &[], true, usize::MAX)),
            [([0.0, 0.0, 1.0, 0.0], 0.0)]
        );
    }
}
