//! The OBJ statements read into vertex lists and runs of faces, and the runs built into
//! meshes.

use std::collections::HashMap;
use std::path::Path;

use super::Mesh;
use super::text::{
    IGNORED_STATEMENTS, logical_lines, parse_finite, split_mtllib, split_words, split_words_by,
    syntax,
};
use crate::error::SceneError;
use crate::math::Vec3;
use crate::triangulate::triangulate_polygon;
use crate::warning::SceneWarning;

/// Most vertices/faces accepted in one OBJ, so that a hostile file cannot exhaust memory
/// through index arithmetic (the text itself bounds real data).
const MAX_ELEMENTS: usize = 1 << 31;

/// Fanned polygons warned about one by one; the rest are counted in one more warning.
pub(super) const MAX_POLYGON_WARNINGS: usize = 20;

/// One corner of a face as written: 0-based indices into the file's vertex, texture-coordinate
/// and normal lists (negative OBJ indices already resolved).
#[derive(Debug, Clone, Copy)]
struct Corner {
    v: usize,
    vt: Option<usize>,
    vn: Option<usize>,
}

/// A finished run of faces sharing a group name and material (a mesh to be), with whether
/// the file had texture coordinates and normals when it ended: a corner without its own index
/// then takes the mesh's first or previous one, as OBJ readers such as `tobj` do.
struct FaceRun {
    group: String,
    material: Option<usize>,
    /// `(first corner, corner count, line)` per face, into `corners`.
    faces: Vec<(usize, usize, usize)>,
    corners: Vec<Corner>,
    with_texcoords: bool,
    with_normals: bool,
}

/// The OBJ read statement by statement: every value checked and named by its line, the
/// vertex lists and the faces grouped into runs by group (`g`, `o`) and material (`usemtl`).
pub(super) struct ObjReader<'a> {
    path: &'a Path,
    positions: Vec<Vec3>,
    texcoords: Vec<[f64; 2]>,
    normals: Vec<Vec3>,
    /// Material library names, each once, with the line that first names it.
    pub(super) mtllibs: Vec<(String, usize)>,
    /// Material names in order of first `usemtl`, and the line of each.
    materials: Vec<String>,
    material_lines: Vec<usize>,
    /// The current run's group and material, and its faces so far.
    group: String,
    material: Option<usize>,
    current: FaceRun,
    runs: Vec<FaceRun>,
    faces: usize,
}

/// The group name of faces before any `g` or `o` (as `tobj` names them).
const UNNAMED_GROUP: &str = "unnamed_object";

impl<'a> ObjReader<'a> {
    pub(super) fn new(path: &'a Path) -> ObjReader<'a> {
        ObjReader {
            path,
            positions: Vec::new(),
            texcoords: Vec::new(),
            normals: Vec::new(),
            mtllibs: Vec::new(),
            materials: Vec::new(),
            material_lines: Vec::new(),
            group: UNNAMED_GROUP.to_string(),
            material: None,
            current: FaceRun::empty(),
            runs: Vec::new(),
            faces: 0,
        }
    }

    /// Reads every logical line of `text`.
    pub(super) fn read(mut self, text: &str) -> Result<ObjReader<'a>, SceneError> {
        for (line, l) in logical_lines(text) {
            let trimmed = l.trim();
            let mut words = trimmed.split_whitespace();
            let Some(key) = words.next() else { continue };
            let rest = trimmed[key.len()..].trim();
            self.statement(key, rest, line)?;
        }
        self.end_run();
        Ok(self)
    }

    fn statement(&mut self, key: &str, rest: &str, line: usize) -> Result<(), SceneError> {
        match key {
            "v" => self.vertex(rest, line),
            "vt" => self.texcoord(rest, line),
            "vn" => self.normal(rest, line),
            "f" | "fo" => self.face(rest, line),
            "o" | "g" => {
                if !self.current.faces.is_empty() {
                    self.end_run();
                }
                self.group = if rest.is_empty() {
                    UNNAMED_GROUP.to_string()
                } else {
                    rest.to_string()
                };
                Ok(())
            }
            "usemtl" => self.use_material(rest, line),
            "mtllib" => {
                if rest.is_empty() {
                    return Err(syntax(self.path, line, "mtllib without a file name"));
                }
                for name in split_mtllib(rest, self.path, line)? {
                    if !self.mtllibs.iter().any(|(m, _)| *m == name) {
                        self.mtllibs.push((name, line));
                    }
                }
                Ok(())
            }
            k if IGNORED_STATEMENTS.contains(&k) => Ok(()),
            other => Err(syntax(
                self.path,
                line,
                format!("unknown OBJ statement {other:?}"),
            )),
        }
    }

    /// `v x y z`, `v x y z w` (divided by w) or `v x y z r g b` (colour checked, not kept).
    fn vertex(&mut self, rest: &str, line: usize) -> Result<(), SceneError> {
        let path = self.path;
        let (vals, n) = split_words::<7>(rest);
        if !(n == 3 || n == 4 || n == 6) {
            return Err(syntax(
                path,
                line,
                format!("vertex needs x y z [w] or x y z r g b, found {n} values"),
            ));
        }
        let mut xyz = [0.0; 3];
        for (k, w) in vals.iter().take(3).enumerate() {
            xyz[k] = parse_finite(w, path, line, "vertex coordinate")?;
        }
        if n == 4 {
            let w = parse_finite(vals[3], path, line, "vertex weight w")?;
            if w == 0.0 {
                return Err(syntax(path, line, "vertex weight w is 0"));
            }
            xyz = xyz.map(|c| c / w);
        } else if n == 6 {
            for w in &vals[3..6] {
                parse_finite(w, path, line, "vertex colour")?;
            }
        }
        self.positions.push(xyz);
        Ok(())
    }

    /// `vt u [v [w]]`: (u, v), v 0 when absent.
    fn texcoord(&mut self, rest: &str, line: usize) -> Result<(), SceneError> {
        let (vals, n) = split_words::<4>(rest);
        if n == 0 || n > 3 {
            return Err(syntax(
                self.path,
                line,
                format!("texture coordinate needs u [v [w]], found {n} values"),
            ));
        }
        let mut uv = [0.0; 3];
        for (k, w) in vals[..n].iter().enumerate() {
            uv[k] = parse_finite(w, self.path, line, "texture coordinate")?;
        }
        self.texcoords.push([uv[0], uv[1]]);
        Ok(())
    }

    /// `vn x y z`.
    fn normal(&mut self, rest: &str, line: usize) -> Result<(), SceneError> {
        let (vals, n) = split_words::<4>(rest);
        if n != 3 {
            return Err(syntax(
                self.path,
                line,
                format!("normal needs x y z, found {n} values"),
            ));
        }
        let mut xyz = [0.0; 3];
        for (k, w) in vals[..3].iter().enumerate() {
            xyz[k] = parse_finite(w, self.path, line, "normal component")?;
        }
        self.normals.push(xyz);
        Ok(())
    }

    /// `f v v v …` with `v`, `v/vt`, `v//vn` or `v/vt/vn` corners, each index checked against
    /// the lists so far.
    fn face(&mut self, rest: &str, line: usize) -> Result<(), SceneError> {
        let path = self.path;
        let first = self.current.corners.len();
        for r in rest.split_ascii_whitespace() {
            let (parts, np) = split_words_by::<3>(r, '/');
            if np > 3 || parts[0].is_empty() {
                return Err(syntax(
                    path,
                    line,
                    format!("malformed face vertex {r:?} (expected v, v/vt, v//vn or v/vt/vn)"),
                ));
            }
            let v = resolve_index(parts[0], self.positions.len(), path, line, "vertex")?;
            let vt = match parts[1] {
                "" => None,
                word => Some(resolve_index(
                    word,
                    self.texcoords.len(),
                    path,
                    line,
                    "texture coordinate",
                )?),
            };
            let vn = match (np, parts[2]) {
                (3, "") => {
                    return Err(syntax(
                        path,
                        line,
                        format!("malformed face vertex {r:?}: empty normal index"),
                    ));
                }
                (3, word) => Some(resolve_index(
                    word,
                    self.normals.len(),
                    path,
                    line,
                    "normal",
                )?),
                _ => None,
            };
            self.current.corners.push(Corner { v, vt, vn });
        }
        let count = self.current.corners.len() - first;
        if count < 3 {
            return Err(syntax(
                path,
                line,
                format!("face needs at least 3 vertices, found {count}"),
            ));
        }
        self.current.faces.push((first, count, line));
        self.faces += 1;
        if self.faces > MAX_ELEMENTS || self.positions.len() > MAX_ELEMENTS {
            return Err(syntax(path, line, "too many elements"));
        }
        Ok(())
    }

    /// `usemtl NAME`: a new material ends the run of faces so far.
    fn use_material(&mut self, rest: &str, line: usize) -> Result<(), SceneError> {
        if rest.is_empty() {
            return Err(syntax(self.path, line, "usemtl without a material name"));
        }
        let index = match self.materials.iter().position(|m| m == rest) {
            Some(i) => i,
            None => {
                self.materials.push(rest.to_string());
                self.material_lines.push(line);
                self.materials.len() - 1
            }
        };
        if self.material != Some(index) && !self.current.faces.is_empty() {
            self.end_run();
        }
        self.material = Some(index);
        Ok(())
    }

    /// Faces read.
    pub(super) fn face_count(&self) -> usize {
        self.faces
    }

    /// Each material name `usemtl` uses, with the line of its first use.
    pub(super) fn used_materials(&self) -> Vec<(&str, usize)> {
        self.materials
            .iter()
            .map(String::as_str)
            .zip(self.material_lines.iter().copied())
            .collect()
    }

    /// The meshes (one per run of faces that has any, in file order) and the material library
    /// and material names; fanned polygons are warned of in `warnings`.
    pub(super) fn into_meshes(
        mut self,
        warnings: &mut Vec<SceneWarning>,
    ) -> (Vec<Mesh>, Vec<String>, Vec<String>) {
        let runs = std::mem::take(&mut self.runs);
        let mut fanned = 0usize;
        let meshes = runs
            .into_iter()
            .filter(|run| !run.faces.is_empty())
            .map(|run| build_mesh(run, &self, warnings, &mut fanned))
            .collect();
        if fanned > MAX_POLYGON_WARNINGS {
            warnings.push(SceneWarning::MorePolygonsFanned {
                obj: self.path.to_path_buf(),
                count: fanned - MAX_POLYGON_WARNINGS,
            });
        }
        let mtllibs = self.mtllibs.into_iter().map(|(name, _)| name).collect();
        (meshes, mtllibs, self.materials)
    }

    /// Ends the current run of faces (kept even when empty; an empty run makes no mesh).
    fn end_run(&mut self) {
        let mut run = std::mem::replace(&mut self.current, FaceRun::empty());
        run.group = self.group.clone();
        run.material = self.material;
        run.with_texcoords = !self.texcoords.is_empty();
        run.with_normals = !self.normals.is_empty();
        self.runs.push(run);
    }
}

impl FaceRun {
    fn empty() -> FaceRun {
        FaceRun {
            group: String::new(),
            material: None,
            faces: Vec::new(),
            corners: Vec::new(),
            with_texcoords: false,
            with_normals: false,
        }
    }
}

/// One OBJ index (`1..=count` or `-count..=-1`) as a 0-based index.
fn resolve_index(
    word: &str,
    count: usize,
    path: &Path,
    line: usize,
    kind: &str,
) -> Result<usize, SceneError> {
    let x: i64 = word.parse().map_err(|_| {
        syntax(
            path,
            line,
            format!("face {kind} index {word:?} is not an integer"),
        )
    })?;
    let resolved = if x > 0 && (x as u64) <= count as u64 {
        Some(x as usize - 1)
    } else if x < 0 && x.unsigned_abs() <= count as u64 {
        Some(count - x.unsigned_abs() as usize)
    } else {
        None
    };
    resolved.ok_or_else(|| {
        syntax(
            path,
            line,
            format!(
                "face {kind} index {x} is out of range (only {count} {kind}s defined so far; OBJ indices start at 1)"
            ),
        )
    })
}

/// A mesh's own copy of the file's entries it uses, each once in order of first use, and
/// each corner's index into it.
struct Remap<T: Copy> {
    used: HashMap<usize, u32>,
    values: Vec<T>,
    indices: Vec<u32>,
}

impl<T: Copy> Remap<T> {
    fn new() -> Remap<T> {
        Remap {
            used: HashMap::new(),
            values: Vec::new(),
            indices: Vec::new(),
        }
    }

    /// Entry `i` of `all` for the next corner.
    fn push(&mut self, i: usize, all: &[T]) {
        let next = self.used.len() as u32;
        let local = *self.used.entry(i).or_insert_with(|| {
            self.values.push(all[i]);
            next
        });
        self.indices.push(local);
    }

    /// For a corner without an index: the mesh's first entry of `all` when it has none yet,
    /// else the previous corner's.
    fn push_missing(&mut self, all: &[T]) {
        match self.indices.last() {
            Some(&last) => self.indices.push(last),
            None => self.push(0, all),
        }
    }
}

/// The mesh of one run of faces, each polygon triangulated in its plane (or fanned, with a
/// warning counted in `fanned`).
fn build_mesh(
    run: FaceRun,
    reader: &ObjReader<'_>,
    warnings: &mut Vec<SceneWarning>,
    fanned: &mut usize,
) -> Mesh {
    let mut positions = Remap::new();
    let mut texcoords = Remap::new();
    let mut normals = Remap::new();
    for c in &run.corners {
        positions.push(c.v, &reader.positions);
        if run.with_texcoords {
            match c.vt {
                Some(t) => texcoords.push(t, &reader.texcoords),
                None => texcoords.push_missing(&reader.texcoords),
            }
        }
        if run.with_normals {
            match c.vn {
                Some(n) => normals.push(n, &reader.normals),
                None => normals.push_missing(&reader.normals),
            }
        }
    }
    let mut mesh = Mesh {
        group: run.group,
        material: run.material,
        positions: positions.values,
        texcoords: texcoords.values,
        normals: normals.values,
        ..Mesh::default()
    };
    let mut corners: Vec<Vec3> = Vec::new();
    for &(first, count, line) in &run.faces {
        corners.clear();
        corners.extend(
            positions.indices[first..first + count]
                .iter()
                .map(|&i| mesh.positions[i as usize]),
        );
        let t = triangulate_polygon(&corners);
        if let Some(reason) = t.fallback {
            *fanned += 1;
            if *fanned <= MAX_POLYGON_WARNINGS {
                warnings.push(SceneWarning::PolygonFanned {
                    obj: reader.path.to_path_buf(),
                    line,
                    vertices: count,
                    reason,
                });
            }
        }
        // Texture-coordinate and normal indices follow the corners.
        let pick =
            |idx: &[u32], [a, b, c]: [usize; 3]| [idx[first + a], idx[first + b], idx[first + c]];
        for &tri in &t.triangles {
            mesh.triangles.push(pick(&positions.indices, tri));
            if run.with_texcoords {
                mesh.tex_triangles.push(pick(&texcoords.indices, tri));
            }
            if run.with_normals {
                mesh.normal_triangles.push(pick(&normals.indices, tri));
            }
        }
    }
    mesh
}
