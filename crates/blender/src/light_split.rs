//! The passes split by the light's path (issue 28, docs/blender.md "Light parts"), so that a
//! glass swap relights the room. Blender renders each pass once per light-split state with
//! Cycles light groups by source (each sun lamp, the world as `sky`, every other emitter as
//! `other`): state 0 with every glazing opaque to light rays, state k with aperture k's glazing
//! (the faces of one glass id on one plane) clear to light rays and the others opaque; camera
//! rays see what they see without the split. With the same seed, paths that met no glazing are
//! the same in every state, so the part of source `s` through aperture k is exactly
//! `state_k[s] − state_0[s]` and the unglazed part is `state_0[s]`. glassdb assembles each pass
//! as one multilayer EXR, a `ViewLayer.Combined_<group>` layer per part (the beauty
//! `ViewLayer.Combined` their sum: every glazing clear), and writes the frame's
//! [`LightParts`] record (`light_parts.####.json`) for compose to scale each part by the glass
//! it came through. Renders per frame go from `1 + P` to `(A + 1)(1 + P)` for `A` apertures and
//! `P` reflection passes.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use glassdb_compose::light_parts::{
    Aperture, LIGHT_PARTS_FORMAT, LightPart, LightParts, LightSource,
};
use glassdb_image::{ExrImageOut, ExrPartOut, ExrPlane, PixelWindow};
use glassdb_scene::MaskScene;
use serde::{Deserialize, Serialize};

use crate::BlenderError;
use crate::geometry::Masks;
use crate::job::{ScriptFrame, ScriptJob};
use crate::pipeline::Workspace;

/// Pattern name of a frame's light-parts record.
pub(crate) fn light_parts_name(frame: u32) -> String {
    format!("light_parts.{frame:04}.json")
}

/// The layer of light group `group` in an assembled pass (Cycles' naming).
pub fn group_layer(group: &str) -> String {
    format!("ViewLayer.Combined_{group}")
}

/// An aperture as the Blender-side script opens it: the glass of one id on one plane.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScriptAperture {
    /// The plane's index (planes.json).
    pub plane: usize,
    /// The glass's registry id.
    pub id: u16,
    /// `[a, b, c, d]` of the plane, (a, b, c) its unit normal (planes.json's orientation).
    pub equation: [f64; 4],
    /// Distance within which a shading point counts as on the plane.
    pub tolerance: f64,
    /// The Blender materials of this glass id.
    pub materials: Vec<String>,
}

impl ScriptAperture {
    /// The suffix of its parts' groups: `p<plane>_id<id>`.
    fn suffix(&self) -> String {
        format!("p{}_id{}", self.plane, self.id)
    }
}

/// The apertures of a labelled scene: each (plane, glass id) that has glass faces, in plane
/// then id order, with the materials of that id among `glass_materials`.
pub(crate) fn apertures(
    labelled: &MaskScene,
    glass_materials: &[(String, u16)],
    tolerance: f64,
) -> Vec<ScriptAperture> {
    let used: BTreeSet<u32> = labelled.raster.labels.iter().copied().collect();
    let mut found: Vec<ScriptAperture> = Vec::new();
    for (k, label) in labelled.raster.glass.iter().enumerate() {
        let plane = usize::from(label.plane);
        if !used.contains(&(k as u32 + 1))
            || found.iter().any(|a| (a.plane, a.id) == (plane, label.id))
        {
            continue;
        }
        let [a, b, c] = label.normal;
        found.push(ScriptAperture {
            plane,
            id: label.id,
            equation: [a, b, c, label.d],
            tolerance,
            materials: glass_materials
                .iter()
                .filter(|(_, id)| *id == label.id)
                .map(|(m, _)| m.clone())
                .collect(),
        });
    }
    found.sort_by_key(|a| (a.plane, a.id));
    found
}

/// The pass `path` as Blender renders it in light-split state `state`:
/// `trans.0001.exr` → `trans.0001.s2.exr` (the script's `split_path`).
pub(crate) fn split_path(path: &Path, state: usize) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    path.with_file_name(format!("{stem}.s{state}.exr"))
}

/// Where the script writes a frame's light sources.
pub(crate) fn lights_path(staging: &Path, frame: u32) -> PathBuf {
    staging.join(format!("lights.{frame:04}.json"))
}

/// A frame's light sources as the script writes them.
#[derive(Debug, Clone, Deserialize)]
struct FrameLights {
    /// Each sun lamp: its group and the direction towards it.
    suns: Vec<SunLamp>,
    /// Every light group rendered, in order: a source, split by the scene's light groups.
    sources: Vec<ScriptSource>,
}

impl FrameLights {
    /// The sources' light groups, in order.
    fn groups(&self) -> Vec<String> {
        self.sources.iter().map(|s| s.group.clone()).collect()
    }
}

/// One light group of a light-split render: a source of one scene light group.
#[derive(Debug, Clone, Deserialize)]
struct ScriptSource {
    /// The Cycles light group rendered (`sun`, `sky`, `other`; with scene groups
    /// `<source>_<scene group>`: `other_warm`, `sun0_sun`).
    group: String,
    /// What emits it.
    kind: SourceKind,
    /// The scene light group it belongs to (`None`: a scene without groups).
    #[serde(default)]
    light: Option<String>,
}

/// The kind of a [`ScriptSource`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
enum SourceKind {
    Sun,
    Sky,
    Other,
}

#[derive(Debug, Clone, Deserialize)]
struct SunLamp {
    group: String,
    direction_to_sun: [f64; 3],
}

/// Blender's pass renders of `frames`, with the split (`light_split`) or without, and without
/// it: `(A + 1)(1 + P)` or `1 + P` per frame, A apertures, P reflection passes.
pub(crate) fn render_counts(frames: &[ScriptFrame], light_split: bool) -> (usize, usize) {
    let unsplit: usize = frames.iter().map(|f| 1 + f.planes.len()).sum();
    let split: usize = frames
        .iter()
        .map(|f| (f.apertures.len() + 1) * (1 + f.planes.len()))
        .sum();
    (if light_split { split } else { unsplit }, unsplit)
}

/// Asks the script for each frame's light sources (the job's frames already hold their
/// apertures).
pub(crate) fn prepare_job(staging: &Path, job: &mut ScriptJob) {
    for f in &mut job.frames {
        f.lights = Some(lights_path(staging, f.frame));
    }
}

/// Every frame's passes of a light-split render assembled into the output folder (the
/// transmission pass over the frame, each reflection pass at its plane's pixels), and its
/// light parts written beside them and named in `masks`' frame records.
pub(crate) fn place_split_passes(
    work: &Workspace<'_>,
    masks: &mut Masks,
    job: &ScriptJob,
) -> Result<(), BlenderError> {
    let size = masks.size;
    for ((record, script), windows) in masks.frames.iter_mut().zip(&job.frames).zip(&masks.crops) {
        let mut passes = vec![SplitPass {
            rendered: script.trans.clone(),
            target: work.dir.join(&record.trans),
            window: Some(PixelWindow::at_origin(size.0 as usize, size.1 as usize)),
        }];
        for (refl, window) in record.refl.iter().zip(windows) {
            passes.push(SplitPass {
                rendered: work.staging.join(refl),
                target: work.dir.join(refl),
                window: *window,
            });
        }
        // A unit's deeper pane groups (issue 27): split like every other reflection pass.
        for g in &record.groups {
            passes.push(SplitPass {
                rendered: work.staging.join(&g.file),
                target: work.dir.join(&g.file),
                window: Some(g.bounds.window()),
            });
        }
        let lights = lights_path(&work.staging, script.frame);
        let parts = assemble_frame(script, &lights, &passes, size)?;
        let name = light_parts_name(script.frame);
        let path = work.dir.join(&name);
        let text = serde_json::to_string_pretty(&parts).map_err(|e| BlenderError::BadRecord {
            path: path.clone(),
            message: e.to_string(),
        })?;
        glassdb_io::write_bytes_atomic(&path, format!("{text}\n").as_bytes())?;
        record.light_parts = Some(name);
    }
    Ok(())
}

/// One pass of a frame: what Blender wrote (before [`split_path`]), where it goes, and the
/// pixels it covers in the frame (`None`: a plane without glass in this frame).
pub(crate) struct SplitPass {
    pub(crate) rendered: PathBuf,
    pub(crate) target: PathBuf,
    pub(crate) window: Option<PixelWindow>,
}

/// A state's render: each group's R, G, B and the beauty's alpha.
pub(crate) struct StateImage {
    pub(crate) window: PixelWindow,
    pub(crate) groups: Vec<[Vec<f32>; 3]>,
    pub(crate) alpha: Vec<f32>,
}

/// Reads state `state` of `pass` with the light groups `groups`.
pub(crate) fn read_state(pass: &Path, groups: &[String]) -> Result<StateImage, BlenderError> {
    let bad = |message: String| BlenderError::BadRender {
        path: pass.to_path_buf(),
        message,
    };
    let bytes = glassdb_io::read_input(pass, glassdb_image::IMAGE_FILE)?;
    let exact = glassdb_image::read_exr_exact(&bytes, glassdb_image::DEFAULT_MAX_PIXELS)?;
    let nparts = exact.parts.len();
    let Ok([part]) = <[_; 1]>::try_from(exact.parts) else {
        return Err(bad(format!("{nparts} parts, expected one")));
    };
    let find = |layer: &str, c: &str| -> Result<Vec<f32>, BlenderError> {
        let end = format!("{layer}.{c}");
        let (_, samples) = part
            .channels
            .iter()
            .find(|(n, _)| n == &end || n.ends_with(&format!(".{end}")))
            .ok_or_else(|| {
                bad(format!(
                    "no channel {end} (the light groups are {}; channels {})",
                    groups.join(", "),
                    part.channels
                        .iter()
                        .map(|(n, _)| n.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
        Ok(to_f32(samples))
    };
    let mut rgb = Vec::new();
    for g in groups {
        let layer = format!("Combined_{g}");
        rgb.push([find(&layer, "R")?, find(&layer, "G")?, find(&layer, "B")?]);
    }
    Ok(StateImage {
        window: part.data_window,
        alpha: find("Combined", "A")?,
        groups: rgb,
    })
}

fn to_f32(samples: &glassdb_image::FlatSamples) -> Vec<f32> {
    use glassdb_image::FlatSamples;
    match samples {
        FlatSamples::F16(v) => v.iter().map(|h| h.to_f32()).collect(),
        FlatSamples::F32(v) => v.clone(),
        FlatSamples::U32(v) => v.iter().map(|&u| u as f32).collect(),
    }
}

/// Assembles frame `frame`'s split passes (`passes`, each rendered in every state of
/// `frame.apertures`) into their targets and returns the frame's light parts. A source whose
/// light reaches no pass in any state (no emitter of it) has no parts.
pub(crate) fn assemble_frame(
    frame: &ScriptFrame,
    lights: &Path,
    passes: &[SplitPass],
    (width, height): (u32, u32),
) -> Result<LightParts, BlenderError> {
    let states = frame.apertures.len() + 1;
    for pass in passes.iter().filter(|p| p.window.is_some()) {
        for s in 0..states {
            let path = split_path(&pass.rendered, s);
            if !path.is_file() {
                return Err(BlenderError::BadRender {
                    message: format!(
                        "Blender did not write this pass (light-split state {s} of {})",
                        pass.rendered
                            .file_name()
                            .unwrap_or_default()
                            .to_string_lossy()
                    ),
                    path,
                });
            }
        }
    }
    let text = glassdb_io::read_input_string(lights, glassdb_io::limits::JSON)?;
    let lights: FrameLights = serde_json::from_str(&text).map_err(|e| BlenderError::BadRender {
        path: lights.to_path_buf(),
        message: e.to_string(),
    })?;
    let groups = lights.groups();
    // First the sources that carry light anywhere, so that every pass has the same layers.
    let mut lit = vec![false; groups.len()];
    for pass in passes.iter().filter(|p| p.window.is_some()) {
        for s in 0..states {
            let image = read_state(&split_path(&pass.rendered, s), &groups)?;
            for (g, rgb) in image.groups.iter().enumerate() {
                lit[g] |= rgb.iter().flatten().any(|&v| v != 0.0);
            }
        }
    }
    let kept: Vec<usize> = (0..groups.len()).filter(|&g| lit[g]).collect();
    let record = parts_record(&lights, &kept, &frame.apertures)?;
    let names: Vec<&str> = record.parts.iter().map(|p| p.group.as_str()).collect();
    for pass in passes {
        let image = match pass.window {
            Some(window) => assembled_pass(pass, window, &groups, &kept, states)?,
            None => unused_pass(&names),
        };
        write_pass(&pass.target, image, &names, (width, height))?;
    }
    Ok(record)
}

/// The frame's record: per kept source its unglazed part, then one per aperture.
fn parts_record(
    lights: &FrameLights,
    kept: &[usize],
    apertures: &[ScriptAperture],
) -> Result<LightParts, BlenderError> {
    let mut parts = Vec::new();
    for &g in kept {
        let script = &lights.sources[g];
        let group = &script.group;
        let source = match script.kind {
            SourceKind::Sky => LightSource::Sky,
            SourceKind::Other => LightSource::Other,
            SourceKind::Sun => LightSource::Sun {
                direction_to_sun: lights
                    .suns
                    .iter()
                    .find(|s| &s.group == group)
                    .map(|s| s.direction_to_sun)
                    .unwrap_or([0.0, 0.0, 1.0]),
            },
        };
        parts.push(LightPart {
            group: group.clone(),
            source,
            through: None,
            light: script.light.clone(),
        });
        for a in apertures {
            parts.push(LightPart {
                group: format!("{group}_{}", a.suffix()),
                source,
                through: Some(Aperture {
                    plane: a.plane,
                    normal: [a.equation[0], a.equation[1], a.equation[2]],
                    id: u32::from(a.id),
                }),
                light: script.light.clone(),
            });
        }
    }
    let record = LightParts {
        format: LIGHT_PARTS_FORMAT.into(),
        parts,
    };
    if let Err(problem) = record.check() {
        return Err(BlenderError::BadRecord {
            path: PathBuf::from("light_parts.json"),
            message: problem.0,
        });
    }
    Ok(record)
}

/// A pass's parts (in the record's order) and alpha over `window`.
pub(crate) struct Assembled {
    pub(crate) window: PixelWindow,
    pub(crate) parts: Vec<[Vec<f32>; 3]>,
    pub(crate) alpha: Vec<f32>,
}

/// The parts of one pass: state 0's group for the unglazed part, state k's minus state 0's for
/// the part through aperture k.
fn assembled_pass(
    pass: &SplitPass,
    window: PixelWindow,
    groups: &[String],
    kept: &[usize],
    states: usize,
) -> Result<Assembled, BlenderError> {
    let mut images = (0..states)
        .map(|s| read_state(&split_path(&pass.rendered, s), groups))
        .collect::<Result<Vec<_>, _>>()?;
    for (s, image) in images.iter().enumerate() {
        let got = (image.window.width, image.window.height);
        if got != (window.width, window.height) {
            return Err(BlenderError::BadRender {
                path: split_path(&pass.rendered, s),
                message: format!(
                    "the render is {}x{}, but its pixels are {}x{}",
                    got.0, got.1, window.width, window.height
                ),
            });
        }
    }
    let mut parts = Vec::new();
    for &g in kept {
        let base = &images[0].groups[g];
        parts.push(base.clone());
        for image in &images[1..] {
            let through = &image.groups[g];
            parts.push(std::array::from_fn(|c| {
                through[c]
                    .iter()
                    .zip(&base[c])
                    .map(|(t, b)| t - b)
                    .collect()
            }));
        }
    }
    Ok(Assembled {
        window,
        parts,
        alpha: images.swap_remove(0).alpha,
    })
}

/// A plane without glass in the frame: one black pixel in every layer.
fn unused_pass(names: &[&str]) -> Assembled {
    Assembled {
        window: PixelWindow::at_origin(1, 1),
        parts: names
            .iter()
            .map(|_| [vec![0.0], vec![0.0], vec![0.0]])
            .collect(),
        alpha: vec![0.0],
    }
}

/// Writes `image` to `to` (atomically): a layer per part and the beauty, their sum.
pub(crate) fn write_pass(
    to: &Path,
    image: Assembled,
    names: &[&str],
    (width, height): (u32, u32),
) -> Result<(), BlenderError> {
    let n = image.alpha.len();
    let mut beauty = [vec![0.0f32; n], vec![0.0f32; n], vec![0.0f32; n]];
    let mut planes = Vec::new();
    for (name, rgb) in names.iter().zip(image.parts) {
        for (c, samples) in rgb.into_iter().enumerate() {
            for (b, v) in beauty[c].iter_mut().zip(&samples) {
                *b += v;
            }
            planes.push(ExrPlane::new(
                &format!("{}.{}", group_layer(name), ["R", "G", "B"][c]),
                samples,
            ));
        }
    }
    for (c, samples) in beauty.into_iter().enumerate() {
        planes.push(ExrPlane::new(
            &format!("ViewLayer.Combined.{}", ["R", "G", "B"][c]),
            samples,
        ));
    }
    planes.push(ExrPlane::new("ViewLayer.Combined.A", image.alpha));
    let size = (width as usize, height as usize);
    crate::passes::write_exr(
        to,
        ExrImageOut {
            display_window: PixelWindow::at_origin(size.0, size.1),
            attributes: glassdb_image::ExrImageAttributes::with_size(size),
            parts: vec![ExrPartOut {
                data_window: image.window,
                attributes: Default::default(),
                planes,
            }],
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_paths_are_the_scripts() {
        assert_eq!(
            split_path(Path::new("/a/b/trans.0001.exr"), 2),
            Path::new("/a/b/trans.0001.s2.exr")
        );
    }

    #[test]
    fn parts_are_each_source_unglazed_then_through_each_aperture() {
        let lights = FrameLights {
            suns: vec![SunLamp {
                group: "sun".into(),
                direction_to_sun: [0.0, -0.6, 0.8],
            }],
            sources: [
                ("sun", SourceKind::Sun),
                ("sky", SourceKind::Sky),
                ("other", SourceKind::Other),
            ]
            .into_iter()
            .map(|(group, kind)| ScriptSource {
                group: group.into(),
                kind,
                light: None,
            })
            .collect(),
        };
        let aperture = |plane, id| ScriptAperture {
            plane,
            id,
            equation: [0.0, 1.0, 0.0, -2.0],
            tolerance: 1e-3,
            materials: vec!["Glass".into()],
        };
        let record = parts_record(&lights, &[0, 1], &[aperture(0, 1), aperture(1, 5)]).unwrap();
        let groups: Vec<&str> = record.parts.iter().map(|p| p.group.as_str()).collect();
        assert_eq!(
            groups,
            [
                "sun",
                "sun_p0_id1",
                "sun_p1_id5",
                "sky",
                "sky_p0_id1",
                "sky_p1_id5"
            ]
        );
        assert_eq!(
            record.parts[1].source,
            LightSource::Sun {
                direction_to_sun: [0.0, -0.6, 0.8]
            }
        );
        assert_eq!(record.parts[5].through.unwrap().id, 5);
        assert_eq!(record.parts[3].through, None);
    }

    /// With the scene's light groups each source names its group, and its parts carry it as
    /// their light; the kind, not the name, says what the source is.
    #[test]
    fn parts_of_scene_group_sources_carry_their_light() {
        let source = |group: &str, kind, light: &str| ScriptSource {
            group: group.into(),
            kind,
            light: Some(light.into()),
        };
        let lights = FrameLights {
            suns: vec![SunLamp {
                group: "sun0_sun".into(),
                direction_to_sun: [0.0, 0.0, 1.0],
            }],
            sources: vec![
                source("sun0_sun", SourceKind::Sun, "sun"),
                source("sky_sun", SourceKind::Sky, "sun"),
                source("other_warm", SourceKind::Other, "warm"),
            ],
        };
        let aperture = ScriptAperture {
            plane: 0,
            id: 1,
            equation: [0.0, 1.0, 0.0, -2.0],
            tolerance: 1e-3,
            materials: vec!["Glass".into()],
        };
        let record = parts_record(&lights, &[0, 2], &[aperture]).unwrap();
        let said: Vec<(&str, Option<&str>, LightSource)> = record
            .parts
            .iter()
            .map(|p| (p.group.as_str(), p.light.as_deref(), p.source))
            .collect();
        let sun = LightSource::Sun {
            direction_to_sun: [0.0, 0.0, 1.0],
        };
        assert_eq!(
            said,
            [
                ("sun0_sun", Some("sun"), sun),
                ("sun0_sun_p0_id1", Some("sun"), sun),
                ("other_warm", Some("warm"), LightSource::Other),
                ("other_warm_p0_id1", Some("warm"), LightSource::Other),
            ]
        );
    }
}
