//! `planes.json`, written by `glassdb mirror` beside the virtual scenes (schema in
//! docs/scene.md) and read back by `glassdb mask --planes` so that both agree on plane indices.

use std::collections::BTreeMap;
use std::path::Path;

use glassdb_side::Side;
use serde::{Deserialize, Serialize};

use crate::error::SceneError;
use crate::planes::{Plane, PlaneTolerance};

/// Value of [`PlanesFile::format`].
pub const PLANES_FORMAT: &str = "glassdb-planes/1";

/// The whole file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanesFile {
    /// [`PLANES_FORMAT`].
    pub format: String,
    /// The OBJ the planes were found in.
    pub source: String,
    /// The eye given with `--eye`, if any.
    pub eye: Option<[f64; 3]>,
    /// The tolerance the planes were found with.
    pub tolerance: ToleranceJson,
    /// The planes, in index order.
    pub planes: Vec<PlaneEntry>,
}

/// A [`crate::PlaneTolerance`] as JSON.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ToleranceJson {
    /// Largest angle between face normals on one plane, degrees.
    pub angle_deg: f64,
    /// Largest distance of a face from its plane, scene units.
    pub distance: f64,
}

/// One glass plane and its virtual scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlaneEntry {
    /// 0-based; the plane index stored in masks.
    pub index: usize,
    /// `[a, b, c, d]` of `a·x + b·y + c·z + d = 0`, (a, b, c) a unit normal pointing to the
    /// front of the glass (the side its faces' normals point to).
    pub equation: [f64; 4],
    /// Area of the glass faces on the plane, scene units².
    pub area: f64,
    /// The glass materials on it.
    pub materials: Vec<String>,
    /// Glass triangles on the plane.
    pub triangles: usize,
    /// `"front"` or `"back"`: which face of the glass faces the eye (the kept half-space).
    pub eye_side: Side,
    /// Row-major 4×4 reflection matrix for column vectors `[x, y, z, 1]`.
    pub reflection_matrix: [[f64; 4]; 4],
    /// The virtual scene's OBJ, relative to the planes file.
    pub file: String,
    /// Triangles written to the virtual scene.
    pub triangles_written: usize,
    /// Scene triangles that crossed the plane and were clipped.
    pub triangles_clipped: usize,
    /// A unit's pane groups, in the order the eye meets them, each with its mirror plane and
    /// virtual scene (group 0's is `file`); empty for glass of one group, mirrored about the
    /// face (issue 27).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<crate::pane_groups::GroupEntry>,
}

impl PlanesFile {
    /// Reads a planes file, validating every equation.
    pub fn load(path: &Path) -> Result<PlanesFile, SceneError> {
        let bad = |message: String| SceneError::BadPlanes {
            path: path.to_path_buf(),
            message,
        };
        let file: PlanesFile =
            read_json_file(path, |path, source| SceneError::PlanesJson { path, source })?;
        if file.format != PLANES_FORMAT {
            return Err(bad(format!(
                "format {} is not {PLANES_FORMAT:?}",
                glassdb_io::quoted(&file.format)
            )));
        }
        if file.planes.is_empty() {
            return Err(bad("no planes".into()));
        }
        for (k, p) in file.planes.iter().enumerate() {
            if p.index != k {
                return Err(bad(format!(
                    "plane {k} has index {} (indices must be 0, 1, 2, ... in order)",
                    p.index
                )));
            }
            Plane::from_equation(p.equation).map_err(|e| bad(format!("plane {k}: {e}")))?;
        }
        Ok(file)
    }

    /// The plane equations, unit-normalised.
    pub fn planes(&self) -> Vec<Plane> {
        self.planes
            .iter()
            .filter_map(|p| Plane::from_equation(p.equation).ok())
            .collect()
    }

    /// The side each plane shows the eye, by plane index.
    pub fn sides(&self) -> BTreeMap<usize, Side> {
        self.planes.iter().map(|p| (p.index, p.eye_side)).collect()
    }

    /// The plane tolerances the file was written with.
    pub fn tolerance(&self) -> PlaneTolerance {
        PlaneTolerance {
            angle_deg: self.tolerance.angle_deg,
            distance: self.tolerance.distance,
        }
    }
}

/// Plane sides from a `planes.json` written by `glassdb mirror` (`planes[k].eye_side`), read
/// by [`PlanesFile::load`] (format and plane order checked), for `passes` reflection passes:
/// one per plane of the file, in its order.
pub fn sides_from_planes_json(
    path: &Path,
    passes: usize,
) -> Result<BTreeMap<usize, Side>, SceneError> {
    let file = PlanesFile::load(path)?;
    if file.planes.len() != passes {
        return Err(SceneError::PlaneCountMismatch {
            planes_file: path.to_path_buf(),
            planes: file.planes.len(),
            passes,
        });
    }
    Ok(file.sides())
}

/// A JSON file of at most [`glassdb_io::limits::JSON`] bytes as `T`; `json_error` makes the
/// error of a file that is not valid JSON of that shape (each file kind has its variant).
pub(crate) fn read_json_file<T: serde::de::DeserializeOwned>(
    path: &Path,
    json_error: impl FnOnce(
        std::path::PathBuf,
        glassdb_io::BoundedError<serde_json::Error>,
    ) -> SceneError,
) -> Result<T, SceneError> {
    let text = glassdb_io::read_input_string(path, glassdb_io::limits::JSON).map_err(|source| {
        SceneError::Read {
            path: path.to_path_buf(),
            source,
        }
    })?;
    serde_json::from_str(&text)
        .map_err(|source| json_error(path.to_path_buf(), glassdb_io::BoundedError(source)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planes_json_sides() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("planes.json");
        std::fs::write(&p, planes_json(&["front", "back"], &[0, 1])).unwrap();
        let sides = sides_from_planes_json(&p, 2).unwrap();
        assert_eq!(sides, BTreeMap::from([(0, Side::Front), (1, Side::Back)]));
        // A planes file for another number of planes than the passes given is refused.
        let err = sides_from_planes_json(&p, 3).unwrap_err();
        assert!(
            matches!(
                err,
                SceneError::PlaneCountMismatch {
                    planes: 2,
                    passes: 3,
                    ..
                }
            ),
            "{err:?}"
        );
        assert!(
            err.to_string()
                .contains("2 glass plane(s) but 3 reflection pass(es)"),
            "{err}"
        );
        std::fs::write(&p, r#"{"planes":[{"eye_side":"up"}]}"#).unwrap();
        assert!(
            sides_from_planes_json(&p, 1)
                .unwrap_err()
                .to_string()
                .contains("planes.json")
        );
        // The planes file's reader checks the side names, the format and the plane order.
        for bad in [
            planes_json(&["front", "up"], &[0, 1]),
            planes_json(&["front", "back"], &[1, 0]),
            planes_json(&["front"], &[0]).replace("glassdb-planes/1", "glassdb-planes/9"),
        ] {
            std::fs::write(&p, &bad).unwrap();
            let err = sides_from_planes_json(&p, 2).unwrap_err();
            assert!(
                !matches!(err, SceneError::PlaneCountMismatch { .. })
                    && err.to_string().contains("planes.json"),
                "{err}"
            );
        }
    }

    /// A planes file as `glassdb mirror` writes it, with the given eye sides and plane indices.
    fn planes_json(sides: &[&str], indices: &[usize]) -> String {
        let planes: Vec<String> = sides
            .iter()
            .zip(indices)
            .map(|(side, index)| {
                format!(
                    r#"{{"index":{index},"equation":[0.0,0.0,1.0,{index}.0],"area":1.0,"materials":["glass"],"triangles":2,"eye_side":"{side}","reflection_matrix":[[1.0,0.0,0.0,0.0],[0.0,1.0,0.0,0.0],[0.0,0.0,-1.0,0.0],[0.0,0.0,0.0,1.0]],"file":"virtual_plane_{index}.obj","triangles_written":0,"triangles_clipped":0}}"#
                )
            })
            .collect();
        format!(
            r#"{{"format":"glassdb-planes/1","source":"scene.obj","eye":null,"tolerance":{{"angle_deg":0.5,"distance":0.001}},"planes":[{}]}}"#,
            planes.join(",")
        )
    }
}
