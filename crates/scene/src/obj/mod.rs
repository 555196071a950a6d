//! Reading OBJ scenes and writing them back.
//!
//! An OBJ is read line by line here (`read.rs`): every statement checked and its errors named
//! by file and line, then its faces grouped into meshes by group (`g`/`o`) and material
//! (`usemtl`) runs, each mesh with its own copy of the vertices it uses, in order of first use
//! (as `tobj` and most OBJ readers build them). Comments, tabs and continuation lines are read
//! as OBJ allows; statements this tool does not use are passed over. Material *properties* are
//! never needed: the mirror writes an `mtllib` reference to the original files, and the mask
//! only matches material names; a material library is checked (`text.rs`) and its names are
//! compared with the `usemtl` names, a missing library or material is a warning.
//!
//! Each polygon is triangulated by ear clipping in its own plane ([`crate::triangulate`]), or
//! fanned with a [`SceneWarning`] naming its line.
//!
//! `mtllib` may name several files, on one line or on several. Whitespace separates the names;
//! a name containing spaces is either written in double quotes or ends in `.mtl` (words are
//! joined up to the next one ending in `.mtl`, as Blender's importer does, and words left at
//! the end of the line make one name).

mod read;
mod text;
mod write;

use std::path::{Path, PathBuf};

use crate::error::SceneError;
use crate::math::Vec3;
use crate::warning::SceneWarning;

pub use write::stage_obj;

/// The largest OBJ scene read.
pub const OBJ_FILE: glassdb_io::InputLimit = glassdb_io::InputLimit::gib(2, "an OBJ scene");
/// The largest MTL material library (named by an OBJ's `mtllib`) read.
pub const MTL_FILE: glassdb_io::InputLimit = glassdb_io::InputLimit::mib(64, "an MTL file");

/// A triangulated OBJ scene, one [`Mesh`] per group/object and material run.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    /// The OBJ file it was read from.
    pub source: PathBuf,
    /// The material libraries named by `mtllib` (relative to the OBJ's directory), each once,
    /// in order of first mention (see the module docs for names with spaces).
    pub mtllibs: Vec<String>,
    /// Material names in order of first `usemtl`.
    pub materials: Vec<String>,
    /// The meshes, in file order.
    pub meshes: Vec<Mesh>,
    /// Non-fatal remarks for the user (missing MTL file, undefined material, fanned polygon).
    pub warnings: Vec<SceneWarning>,
}

/// One run of triangles sharing a group name and material, with its own vertex arrays.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    /// Group or object name (`g`/`o`); ungrouped faces are `unnamed_object`.
    pub group: String,
    /// Index into [`Scene::materials`], `None` before any `usemtl`.
    pub material: Option<usize>,
    /// Its vertices, in order of first use.
    pub positions: Vec<Vec3>,
    /// Its texture coordinates, in order of first use.
    pub texcoords: Vec<[f64; 2]>,
    /// Its normals, in order of first use.
    pub normals: Vec<Vec3>,
    /// Position indices per triangle, counter-clockwise seen from the front (each polygon's
    /// triangles keep its winding).
    pub triangles: Vec<[u32; 3]>,
    /// Texture-coordinate indices per triangle (empty when the mesh has none).
    pub tex_triangles: Vec<[u32; 3]>,
    /// Normal indices per triangle (empty when the mesh has none).
    pub normal_triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// The three corner positions of triangle `t`.
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }
}

impl Scene {
    /// The files the scene was read from: the OBJ and each material library it names
    /// (resolved against the OBJ's directory, whether or not it exists). No output may be one.
    pub fn input_files(&self) -> Vec<PathBuf> {
        let dir = self.source.parent().unwrap_or(Path::new(""));
        std::iter::once(self.source.clone())
            .chain(self.mtllibs.iter().map(|lib| dir.join(lib)))
            .collect()
    }

    /// Number of triangles over all meshes.
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.triangles.len()).sum()
    }

    /// Name of the material of `mesh`, or `""` when it has none.
    pub fn material_name(&self, mesh: &Mesh) -> &str {
        mesh.material
            .and_then(|m| self.materials.get(m))
            .map(String::as_str)
            .unwrap_or("")
    }

    /// Axis-aligned bounds of all vertices used by triangles: `(min, max)`.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut any = false;
        for m in &self.meshes {
            if m.triangles.is_empty() {
                continue;
            }
            for p in &m.positions {
                any = true;
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
        any.then_some((lo, hi))
    }

    /// Length of the bounding-box diagonal (scene scale for relative tolerances).
    pub fn diagonal(&self) -> f64 {
        self.bounds()
            .map(|(lo, hi)| crate::math::norm(crate::math::sub(hi, lo)))
            .unwrap_or(0.0)
    }
}

/// Reads, checks and triangulates an OBJ scene. Polygons are ear-clipped in their plane; one
/// that cannot be (non-planar, self-intersecting) is fanned with a warning.
pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
    let text = text::read_text(path, OBJ_FILE)?;
    let reader = read::ObjReader::new(path).read(&text)?;
    if reader.face_count() == 0 {
        return Err(SceneError::EmptyScene {
            path: path.to_path_buf(),
        });
    }
    let mut warnings = text::check_materials(&reader.mtllibs, &reader.used_materials(), path)?;
    let (meshes, mtllibs, materials) = reader.into_meshes(&mut warnings);
    let scene = Scene {
        source: path.to_path_buf(),
        mtllibs,
        materials,
        meshes,
        warnings,
    };
    // Its material libraries, read or missing: no output may replace or create one.
    glassdb_io::declare_inputs(scene.input_files().iter().map(PathBuf::as_path));
    Ok(scene)
}

#[cfg(test)]
mod tests;
