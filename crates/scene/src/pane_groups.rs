//! Units' pane groups in the scene (issue 27; docs/scene.md, "Units"). The glass face in the
//! scene is the unit's outer surface #1, its normal pointing outdoors (the glass's front); the
//! unit's layers lie behind it, against the normal. Pane group k reflects about its own
//! mid-plane, `depth_k` behind the face: the face's plane `n·x + d = 0` moved along −n, i.e.
//! `n·x + d + depth_k = 0`. The groups are listed in the order the eye's rays meet them (outer
//! pane first from the front, inner pane first from the back), as compose numbers their
//! passes.

use glassdb_side::Side;
use serde::{Deserialize, Serialize};

use crate::error::SceneError;
use crate::planes::{GlassPlane, MaterialMatcher, Plane};

/// One pane group's mirror plane and virtual scene, as `planes.json` lists it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupEntry {
    /// 0-based, in the order the eye's rays meet the groups (compose's `refl_<plane>_<group>`).
    pub group: usize,
    /// Its mid-plane's depth behind the glass face, along −normal (scene units, metres).
    pub depth: f64,
    /// `[a, b, c, d]` of its mid-plane, the normal the face's.
    pub equation: [f64; 4],
    /// Row-major 4×4 reflection matrix about its mid-plane.
    pub reflection_matrix: [[f64; 4]; 4],
    /// Its virtual scene's OBJ, relative to the planes file.
    pub file: String,
    /// Triangles written to its virtual scene.
    pub triangles_written: usize,
    /// Scene triangles that crossed its plane and were clipped.
    pub triangles_clipped: usize,
}

/// File name of plane `k`'s pane group `g` (g ≥ 1; group 0 is `plane_<k>.obj`).
pub fn group_scene_name(k: usize, g: usize) -> String {
    format!("plane_{k}_group_{g}.obj")
}

/// `plane` moved `depth` along −normal.
pub(crate) fn shifted(plane: &Plane, depth: f64) -> Plane {
    Plane {
        normal: plane.normal,
        d: plane.d + depth,
    }
}

/// The depths (scene units) of plane `gp`'s pane groups in the order an eye on `eye_side`
/// meets them, from the unit of its glass materials (`depths[i]`: the groups of the glass of
/// pattern i, outside first; empty for a glass of one group). Empty when the plane's glass has
/// one group. Glasses of one plane must have one build-up: each group has one mirror plane.
pub(crate) fn plane_group_depths(
    gp: &GlassPlane,
    matcher: Option<&MaterialMatcher>,
    depths: &[Vec<f64>],
    eye_side: Side,
) -> Result<Vec<f64>, SceneError> {
    let Some(matcher) = matcher else {
        return Ok(Vec::new());
    };
    let mut chosen: Option<(&str, &Vec<f64>)> = None;
    for name in &gp.materials {
        let Some(d) = matcher.first_match(name).and_then(|i| depths.get(i)) else {
            continue;
        };
        let d_groups = if d.len() > 1 { d } else { &Vec::new() };
        match chosen {
            None => chosen = Some((name, d)),
            Some((first, c)) => {
                let c_groups = if c.len() > 1 { c } else { &Vec::new() };
                let same = c_groups.len() == d_groups.len()
                    && c_groups
                        .iter()
                        .zip(d_groups)
                        .all(|(a, b)| (a - b).abs() <= 1e-6);
                if !same {
                    return Err(SceneError::BadOption {
                        message: format!(
                            "glass plane {} holds {first} (pane groups at {}) and {name} (at {}): the glasses of one plane must have the same build-up, since each pane group is mirrored about one plane",
                            gp.index,
                            describe(c),
                            describe(d)
                        ),
                    });
                }
            }
        }
    }
    let Some((_, d)) = chosen.filter(|(_, d)| d.len() > 1) else {
        return Ok(Vec::new());
    };
    if let Some(bad) = d.iter().find(|v| !v.is_finite() || **v < 0.0) {
        return Err(SceneError::BadOption {
            message: format!(
                "glass plane {}: a pane group's depth {bad} is not a distance behind the face",
                gp.index
            ),
        });
    }
    Ok(match eye_side {
        Side::Front => d.clone(),
        Side::Back => d.iter().rev().copied().collect(),
    })
}

/// Depths for messages, in millimetres (scene units are metres).
fn describe(d: &[f64]) -> String {
    if d.len() < 2 {
        return "the face (one group)".into();
    }
    let mm: Vec<String> = d.iter().map(|v| format!("{:.1} mm", v * 1e3)).collect();
    mm.join(", ")
}
