//! Reading OBJ scenes (with `tobj`) and writing them back.
//!
//! `tobj` reports errors without a line number, accepts some malformed input silently and
//! forgets the name of a material whose MTL file is missing. So every OBJ is first validated
//! line by line here (errors name file and line), normalised (comments stripped, tabs made
//! spaces, continuation lines joined, statements we do not use dropped) and then handed to
//! `tobj` with a material loader that knows every `usemtl` name, whether or not its MTL file
//! exists. Material *properties* are never needed: the mirror writes an `mtllib` reference to
//! the original files, and the mask only matches material names.
//!
//! `tobj` returns the polygons as written; each is triangulated here by ear clipping in its
//! own plane ([`crate::triangulate`]), or fanned with a [`SceneWarning`] naming its line.
//!
//! `mtllib` may name several files, on one line or on several. Whitespace separates the names;
//! a name containing spaces is either written in double quotes or ends in `.mtl` (words are
//! joined up to the next one ending in `.mtl`, as Blender's importer does, and words left at
//! the end of the line make one name, as `tobj` reads them).

use std::borrow::Cow;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::error::SceneError;
use crate::math::Vec3;
use crate::triangulate::triangulate_polygon;
use crate::warning::SceneWarning;

/// The largest OBJ scene read.
pub const OBJ_FILE: glassdb_io::InputLimit = glassdb_io::InputLimit::gib(2, "an OBJ scene");
/// The largest MTL material library (named by an OBJ's `mtllib`) read.
pub const MTL_FILE: glassdb_io::InputLimit = glassdb_io::InputLimit::mib(64, "an MTL file");

/// Most vertices/faces accepted in one OBJ, so that a hostile file cannot exhaust memory
/// through index arithmetic (the text itself bounds real data).
const MAX_ELEMENTS: usize = 1 << 31;

/// Fanned polygons warned about one by one; the rest are counted in one more warning.
const MAX_POLYGON_WARNINGS: usize = 20;

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
    /// Group or object name (`g`/`o`); `tobj` names ungrouped faces `unnamed_object`.
    pub group: String,
    /// Index into [`Scene::materials`], `None` before any `usemtl`.
    pub material: Option<usize>,
    pub positions: Vec<Vec3>,
    pub texcoords: Vec<[f64; 2]>,
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

/// What the validation pass learned besides the normalised text.
struct ObjScan {
    text: String,
    /// Material library names, each once, with the line that first names it.
    mtllibs: Vec<(String, usize)>,
    usemtl: Vec<String>,
    /// The line of each name's first `usemtl`, parallel to `usemtl`.
    usemtl_lines: Vec<usize>,
    /// The line of every face, in file order.
    face_lines: Vec<usize>,
}

/// OBJ statements that are valid but carry nothing this tool uses (free-form geometry,
/// display attributes, smoothing and merging groups).
const IGNORED_STATEMENTS: &[&str] = &[
    "s",
    "mg",
    "vp",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "usemap",
    "maplib",
    "call",
    "csh",
    "l",
    "p",
];

fn syntax(path: &Path, line: usize, message: impl Into<String>) -> SceneError {
    SceneError::Syntax {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

/// Reads a text file of at most `limit`, turning invalid UTF-8 into an error naming the line.
fn read_text(path: &Path, limit: glassdb_io::InputLimit) -> Result<String, SceneError> {
    let bytes = glassdb_io::read_input(path, limit).map_err(|source| SceneError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let line = 1 + e.as_bytes()[..valid]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        syntax(path, line, "not UTF-8 text (is this an OBJ/MTL file?)")
    })
}

/// Logical lines: comments removed, `\` continuations joined, tabs as spaces; each with the
/// 1-based number of its first physical line. Plain lines are borrowed, not copied.
fn logical_lines(text: &str) -> Vec<(usize, Cow<'_, str>)> {
    let mut out = Vec::new();
    let mut pending: Option<(usize, String)> = None;
    for (i, raw) in text.lines().enumerate() {
        let without_comment = match raw.find('#') {
            Some(k) => &raw[..k],
            None => raw,
        };
        let cleaned: Cow<'_, str> = if without_comment.contains(['\t', '\r', '\u{c}']) {
            Cow::Owned(without_comment.replace(['\t', '\r', '\u{c}'], " "))
        } else {
            Cow::Borrowed(without_comment)
        };
        let trimmed_end = cleaned.trim_end();
        if let Some(stripped) = trimmed_end.strip_suffix('\\') {
            let (lineno, mut acc) = pending.take().unwrap_or((i + 1, String::new()));
            acc.push_str(stripped);
            acc.push(' ');
            pending = Some((lineno, acc));
        } else if let Some((lineno, mut acc)) = pending.take() {
            acc.push_str(&cleaned);
            out.push((lineno, Cow::Owned(acc)));
        } else {
            out.push((i + 1, cleaned));
        }
    }
    if let Some((lineno, acc)) = pending {
        out.push((lineno, Cow::Owned(acc)));
    }
    out
}

/// Splits `s` into at most `N` words; returns them and the total word count.
fn split_words<const N: usize>(s: &str) -> ([&str; N], usize) {
    let mut out = [""; N];
    let mut n = 0;
    for w in s.split_ascii_whitespace() {
        if n < N {
            out[n] = w;
        }
        n += 1;
    }
    (out, n)
}

/// Splits `s` at `sep` into at most `N` parts; returns them and the total part count.
fn split_words_by<const N: usize>(s: &str, sep: char) -> ([&str; N], usize) {
    let mut out = [""; N];
    let mut n = 0;
    for w in s.split(sep) {
        if n < N {
            out[n] = w;
        }
        n += 1;
    }
    (out, n)
}

fn parse_finite(word: &str, path: &Path, line: usize, what: &str) -> Result<f64, SceneError> {
    match word.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(syntax(
            path,
            line,
            format!("{what}: {word:?} is not a finite number"),
        )),
        Err(_) => Err(syntax(
            path,
            line,
            format!("{what}: {word:?} is not a number"),
        )),
    }
}

/// Checks one OBJ index (`1..=count` or `-count..=-1`).
fn check_index(
    word: &str,
    count: usize,
    path: &Path,
    line: usize,
    kind: &str,
) -> Result<(), SceneError> {
    let x: i64 = word.parse().map_err(|_| {
        syntax(
            path,
            line,
            format!("face {kind} index {word:?} is not an integer"),
        )
    })?;
    let ok = if x > 0 {
        (x as u64) <= count as u64
    } else if x < 0 {
        x.unsigned_abs() <= count as u64
    } else {
        false
    };
    if ok {
        Ok(())
    } else {
        Err(syntax(
            path,
            line,
            format!(
                "face {kind} index {x} is out of range (only {count} {kind}s defined so far; OBJ indices start at 1)"
            ),
        ))
    }
}

/// Validates and normalises an OBJ text (see the module docs).
fn scan_obj(text: &str, path: &Path) -> Result<ObjScan, SceneError> {
    let mut out = String::with_capacity(text.len() + 64);
    let (mut nv, mut nvt, mut nvn, mut faces) = (0usize, 0usize, 0usize, 0usize);
    let mut mtllibs: Vec<(String, usize)> = Vec::new();
    let mut usemtl: Vec<String> = Vec::new();
    let mut usemtl_lines = Vec::new();
    let mut face_lines = Vec::new();
    for (line, l) in logical_lines(text) {
        let trimmed = l.trim();
        let mut words = trimmed.split_whitespace();
        let Some(key) = words.next() else { continue };
        let rest = trimmed[key.len()..].trim();
        match key {
            "v" => {
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
                    let _ = writeln!(out, "v {:?} {:?} {:?}", xyz[0] / w, xyz[1] / w, xyz[2] / w);
                } else {
                    if n == 6 {
                        for w in &vals[3..6] {
                            parse_finite(w, path, line, "vertex colour")?;
                        }
                    }
                    // Valid numbers are passed on as written (tobj parses them the same way).
                    for part in ["v ", vals[0], " ", vals[1], " ", vals[2], "\n"] {
                        out.push_str(part);
                    }
                }
                nv += 1;
            }
            "vt" => {
                let (vals, n) = split_words::<4>(rest);
                if n == 0 || n > 3 {
                    return Err(syntax(
                        path,
                        line,
                        format!("texture coordinate needs u [v [w]], found {n} values"),
                    ));
                }
                for w in &vals[..n] {
                    parse_finite(w, path, line, "texture coordinate")?;
                }
                let v = if n >= 2 { vals[1] } else { "0" };
                for part in ["vt ", vals[0], " ", v, "\n"] {
                    out.push_str(part);
                }
                nvt += 1;
            }
            "vn" => {
                let (vals, n) = split_words::<4>(rest);
                if n != 3 {
                    return Err(syntax(
                        path,
                        line,
                        format!("normal needs x y z, found {n} values"),
                    ));
                }
                for w in &vals[..3] {
                    parse_finite(w, path, line, "normal component")?;
                }
                for part in ["vn ", vals[0], " ", vals[1], " ", vals[2], "\n"] {
                    out.push_str(part);
                }
                nvn += 1;
            }
            "f" | "fo" => {
                let mut count = 0usize;
                out.push('f');
                for r in rest.split_ascii_whitespace() {
                    count += 1;
                    let (parts, np) = split_words_by::<3>(r, '/');
                    if np > 3 || parts[0].is_empty() {
                        return Err(syntax(
                            path,
                            line,
                            format!(
                                "malformed face vertex {r:?} (expected v, v/vt, v//vn or v/vt/vn)"
                            ),
                        ));
                    }
                    check_index(parts[0], nv, path, line, "vertex")?;
                    if np >= 2 && !parts[1].is_empty() {
                        check_index(parts[1], nvt, path, line, "texture coordinate")?;
                    }
                    if np == 3 {
                        if parts[2].is_empty() {
                            return Err(syntax(
                                path,
                                line,
                                format!("malformed face vertex {r:?}: empty normal index"),
                            ));
                        }
                        check_index(parts[2], nvn, path, line, "normal")?;
                    }
                    out.push(' ');
                    out.push_str(r);
                }
                out.push('\n');
                if count < 3 {
                    return Err(syntax(
                        path,
                        line,
                        format!("face needs at least 3 vertices, found {count}"),
                    ));
                }
                faces += 1;
                face_lines.push(line);
                if faces > MAX_ELEMENTS || nv > MAX_ELEMENTS {
                    return Err(syntax(path, line, "too many elements"));
                }
            }
            "o" | "g" => {
                let _ = writeln!(out, "{key} {rest}");
            }
            "usemtl" => {
                if rest.is_empty() {
                    return Err(syntax(path, line, "usemtl without a material name"));
                }
                if !usemtl.iter().any(|m| m == rest) {
                    usemtl.push(rest.to_string());
                    usemtl_lines.push(line);
                }
                let _ = writeln!(out, "usemtl {rest}");
            }
            "mtllib" => {
                if rest.is_empty() {
                    return Err(syntax(path, line, "mtllib without a file name"));
                }
                for name in split_mtllib(rest, path, line)? {
                    if !mtllibs.iter().any(|(m, _)| *m == name) {
                        mtllibs.push((name, line));
                    }
                }
            }
            k if IGNORED_STATEMENTS.contains(&k) => {}
            other => {
                return Err(syntax(
                    path,
                    line,
                    format!("unknown OBJ statement {other:?}"),
                ));
            }
        }
    }
    Ok(ObjScan {
        text: out,
        mtllibs,
        usemtl,
        usemtl_lines,
        face_lines,
    })
}

/// The file names of one `mtllib` statement (see the module docs): whitespace-separated,
/// a double-quoted name taken as it is, and unquoted words joined up to one ending in `.mtl`.
fn split_mtllib(rest: &str, path: &Path, line: usize) -> Result<Vec<String>, SceneError> {
    let mut names = Vec::new();
    // Byte offset where the unquoted name being gathered starts.
    let mut pending: Option<usize> = None;
    let mut i = 0;
    let bytes = rest.as_bytes();
    while i < bytes.len() {
        if bytes[i] == b' ' {
            i += 1;
            continue;
        }
        if bytes[i] == b'"' {
            if let Some(start) = pending.take() {
                names.push(rest[start..i].trim_end().to_string());
            }
            let Some(len) = rest[i + 1..].find('"') else {
                return Err(syntax(
                    path,
                    line,
                    "mtllib: a double-quoted file name has no closing quote",
                ));
            };
            let name = &rest[i + 1..i + 1 + len];
            if name.trim().is_empty() {
                return Err(syntax(path, line, "mtllib: empty file name"));
            }
            names.push(name.to_string());
            i += len + 2;
            continue;
        }
        let end = rest[i..].find(' ').map_or(rest.len(), |k| i + k);
        let start = *pending.get_or_insert(i);
        if rest[i..end].to_ascii_lowercase().ends_with(".mtl") {
            names.push(rest[start..end].to_string());
            pending = None;
        }
        i = end;
    }
    if let Some(start) = pending {
        names.push(rest[start..].trim_end().to_string());
    }
    Ok(names)
}

/// Validates an MTL file and returns the material names it defines.
fn scan_mtl(text: &str, path: &Path) -> Result<Vec<String>, SceneError> {
    let mut names = Vec::new();
    for (line, l) in logical_lines(text) {
        let trimmed = l.trim();
        let mut words = trimmed.split_whitespace();
        let Some(key) = words.next() else { continue };
        let rest: Vec<&str> = words.collect();
        match key {
            "newmtl" => {
                let name = trimmed[key.len()..].trim();
                if name.is_empty() {
                    return Err(syntax(path, line, "newmtl without a material name"));
                }
                names.push(name.to_string());
            }
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" => {
                if matches!(rest.first(), Some(&"spectral") | Some(&"xyz")) {
                    continue;
                }
                if rest.len() != 1 && rest.len() != 3 {
                    return Err(syntax(
                        path,
                        line,
                        format!("{key} needs 1 or 3 numbers, found {}", rest.len()),
                    ));
                }
                for w in &rest {
                    parse_finite(w, path, line, key)?;
                }
            }
            "Ns" | "Ni" | "d" | "Tr" | "sharpness" | "illum" => {
                if rest.len() != 1 && !(key == "d" && rest.len() == 2 && rest[0] == "-halo") {
                    return Err(syntax(path, line, format!("{key} needs one number")));
                }
                parse_finite(rest[rest.len() - 1], path, line, key)?;
            }
            _ => {} // texture maps and vendor extensions: not used here
        }
    }
    Ok(names)
}

/// Reads, validates and triangulates an OBJ scene. Polygons are ear-clipped in their plane;
/// one that cannot be (non-planar, self-intersecting) is fanned with a warning.
pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
    let text = read_text(path, OBJ_FILE)?;
    let scan = scan_obj(&text, path)?;
    if scan.face_lines.is_empty() {
        return Err(SceneError::EmptyScene {
            path: path.to_path_buf(),
        });
    }
    let mut warnings = Vec::new();
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut defined: Vec<String> = Vec::new();
    for (lib, line) in &scan.mtllibs {
        let mtl_path = dir.join(lib);
        if !mtl_path.exists() {
            warnings.push(SceneWarning::MissingMaterialLibrary {
                obj: path.to_path_buf(),
                line: *line,
                library: mtl_path,
            });
            continue;
        }
        let mtl_text = read_text(&mtl_path, MTL_FILE)?;
        defined.extend(scan_mtl(&mtl_text, &mtl_path)?);
    }
    if !scan.mtllibs.is_empty() {
        for (m, &line) in scan.usemtl.iter().zip(&scan.usemtl_lines) {
            if !defined.contains(m) {
                warnings.push(SceneWarning::UndefinedMaterial {
                    obj: path.to_path_buf(),
                    line,
                    name: m.clone(),
                });
            }
        }
    }

    // tobj only keeps a `usemtl` name if a loaded library defines it: give it one library
    // defining every used name, so names survive a missing or partial MTL.
    let mut placeholder = String::new();
    for m in &scan.usemtl {
        let _ = writeln!(placeholder, "newmtl {m}");
    }
    let fed = format!("mtllib glassdb-material-names\n{}", scan.text);
    // Polygons as written (`triangulate: false`): they are triangulated below.
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let loaded = std::panic::catch_unwind(|| {
        tobj::load_obj_buf(&mut fed.as_bytes(), &options, |_| {
            tobj::load_mtl_buf(&mut placeholder.as_bytes())
        })
    });
    let (models, materials) = match loaded {
        Ok(Ok((models, materials))) => (models, materials.unwrap_or_default()),
        Ok(Err(e)) => {
            return Err(SceneError::Load {
                path: path.to_path_buf(),
                message: e.to_string(),
            });
        }
        Err(_) => {
            return Err(SceneError::Load {
                path: path.to_path_buf(),
                message: "the OBJ reader panicked".into(),
            });
        }
    };
    let name_index: HashMap<&str, usize> = scan
        .usemtl
        .iter()
        .enumerate()
        .map(|(i, n)| (n.as_str(), i))
        .collect();
    let load_error = |message: &str| SceneError::Load {
        path: path.to_path_buf(),
        message: message.into(),
    };
    // tobj keeps the faces in file order across its models, so they pair with the scan's lines.
    let mut face_lines = scan.face_lines.iter().copied();
    let mut fanned = 0usize;
    let mut meshes = Vec::with_capacity(models.len());
    for model in models {
        let m = model.mesh;
        if m.indices.is_empty() {
            continue;
        }
        let material = m
            .material_id
            .and_then(|id| materials.get(id))
            .and_then(|mat| name_index.get(mat.name.as_str()).copied());
        let positions: Vec<Vec3> = m
            .positions
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let texcoords: Vec<[f64; 2]> = m.texcoords.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
        let normals: Vec<Vec3> = m
            .normals
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let in_range = |idx: &[u32], n: usize| idx.iter().all(|&i| (i as usize) < n);
        let has_t = m.texcoord_indices.len() == m.indices.len();
        let has_n = m.normal_indices.len() == m.indices.len();
        if !in_range(&m.indices, positions.len())
            || (has_t && !in_range(&m.texcoord_indices, texcoords.len()))
            || (has_n && !in_range(&m.normal_indices, normals.len()))
        {
            return Err(load_error("face index out of range after loading"));
        }
        // `face_arities` is empty when every face is a triangle.
        let arities: Cow<'_, [u32]> = if m.face_arities.is_empty() {
            Cow::Owned(vec![3; m.indices.len() / 3])
        } else {
            Cow::Borrowed(&m.face_arities)
        };
        let mut mesh = Mesh {
            group: model.name,
            material,
            positions,
            texcoords,
            normals,
            ..Mesh::default()
        };
        let mut offset = 0usize;
        let mut corners: Vec<Vec3> = Vec::new();
        for &arity in arities.iter() {
            let arity = arity as usize;
            let end = offset + arity;
            let line = face_lines
                .next()
                .ok_or_else(|| load_error("more faces after loading than in the file"))?;
            let v = m
                .indices
                .get(offset..end)
                .ok_or_else(|| load_error("face sizes do not match the indices after loading"))?;
            corners.clear();
            corners.extend(v.iter().map(|&i| mesh.positions[i as usize]));
            let t = triangulate_polygon(&corners);
            if let Some(reason) = t.fallback {
                fanned += 1;
                if fanned <= MAX_POLYGON_WARNINGS {
                    warnings.push(SceneWarning::PolygonFanned {
                        obj: path.to_path_buf(),
                        line,
                        vertices: arity,
                        reason,
                    });
                }
            }
            // Texture-coordinate and normal indices follow the corners.
            let pick = |idx: &[u32], [a, b, c]: [usize; 3]| {
                [idx[offset + a], idx[offset + b], idx[offset + c]]
            };
            for &tri in &t.triangles {
                mesh.triangles.push(pick(&m.indices, tri));
                if has_t {
                    mesh.tex_triangles.push(pick(&m.texcoord_indices, tri));
                }
                if has_n {
                    mesh.normal_triangles.push(pick(&m.normal_indices, tri));
                }
            }
            offset = end;
        }
        if offset != m.indices.len() {
            return Err(load_error(
                "face sizes do not match the indices after loading",
            ));
        }
        meshes.push(mesh);
    }
    if face_lines.next().is_some() {
        return Err(load_error("fewer faces after loading than in the file"));
    }
    if fanned > MAX_POLYGON_WARNINGS {
        warnings.push(SceneWarning::MorePolygonsFanned {
            obj: path.to_path_buf(),
            count: fanned - MAX_POLYGON_WARNINGS,
        });
    }
    let scene = Scene {
        source: path.to_path_buf(),
        mtllibs: scan.mtllibs.into_iter().map(|(name, _)| name).collect(),
        materials: scan.usemtl,
        meshes,
        warnings,
    };
    // Its material libraries, read or missing: no output may replace or create one.
    glassdb_io::declare_inputs(scene.input_files().iter().map(PathBuf::as_path));
    Ok(scene)
}

/// `name` as one `mtllib` argument: as it is when [`split_mtllib`] reads it back as one name,
/// else in double quotes (a name with spaces not ending in `.mtl`, say).
fn mtllib_argument(name: &str) -> Cow<'_, str> {
    let plain = split_mtllib(name, Path::new(""), 0).is_ok_and(|n| n.len() == 1 && n[0] == name);
    if plain || name.contains('"') {
        Cow::Borrowed(name)
    } else {
        Cow::Owned(format!("\"{name}\""))
    }
}

/// Stages meshes as an OBJ into a set of outputs that land together, with `mtllib` lines
/// pointing at `mtllibs` (already expressed relative to the output's directory) and `header`
/// as leading comment lines.
pub fn stage_obj(
    staged: &mut glassdb_io::StagedOutput,
    path: &Path,
    header: &[String],
    mtllibs: &[String],
    materials: &[String],
    meshes: &[Mesh],
) -> Result<(), SceneError> {
    staged.write(path, |w| {
        write_obj_text(w, header, mtllibs, materials, meshes)
    })?;
    Ok(())
}

/// The text of the OBJ [`stage_obj`] writes.
fn write_obj_text<W: std::io::Write>(
    w: &mut W,
    header: &[String],
    mtllibs: &[String],
    materials: &[String],
    meshes: &[Mesh],
) -> std::io::Result<()> {
    for h in header {
        writeln!(w, "# {h}")?;
    }
    for lib in mtllibs {
        writeln!(w, "mtllib {}", mtllib_argument(lib))?;
    }
    let (mut ov, mut ot, mut on) = (1u64, 1u64, 1u64);
    for m in meshes {
        if m.triangles.is_empty() {
            continue;
        }
        writeln!(w, "g {}", m.group)?;
        if let Some(name) = m.material.and_then(|i| materials.get(i)) {
            writeln!(w, "usemtl {name}")?;
        }
        for p in &m.positions {
            writeln!(w, "v {:?} {:?} {:?}", p[0], p[1], p[2])?;
        }
        let has_t = !m.tex_triangles.is_empty();
        let has_n = !m.normal_triangles.is_empty();
        if has_t {
            for t in &m.texcoords {
                writeln!(w, "vt {:?} {:?}", t[0], t[1])?;
            }
        }
        if has_n {
            for n in &m.normals {
                writeln!(w, "vn {:?} {:?} {:?}", n[0], n[1], n[2])?;
            }
        }
        for (k, tri) in m.triangles.iter().enumerate() {
            w.write_all(b"f")?;
            for (c, &corner) in tri.iter().enumerate() {
                let v = ov + corner as u64;
                match (has_t, has_n) {
                    (false, false) => write!(w, " {v}")?,
                    (true, false) => write!(w, " {v}/{}", ot + m.tex_triangles[k][c] as u64)?,
                    (false, true) => write!(w, " {v}//{}", on + m.normal_triangles[k][c] as u64)?,
                    (true, true) => write!(
                        w,
                        " {v}/{}/{}",
                        ot + m.tex_triangles[k][c] as u64,
                        on + m.normal_triangles[k][c] as u64
                    )?,
                }
            }
            w.write_all(b"\n")?;
        }
        ov += m.positions.len() as u64;
        if has_t {
            ot += m.texcoords.len() as u64;
        }
        if has_n {
            on += m.normals.len() as u64;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load_str(obj: &str) -> Result<Scene, SceneError> {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.obj");
        std::fs::write(&p, obj).unwrap();
        load_obj(&p)
    }

    #[test]
    fn syntax_errors_name_file_and_line() {
        let e = load_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("s.obj:4:"), "{e}");
        let e = load_str("v 0 0\n").unwrap_err().to_string();
        assert!(
            e.contains("s.obj:1:") && e.contains("found 2 values"),
            "{e}"
        );
        let e = load_str("v 0 0 0\nv 1 0 0\nv 0 1 0\n\n# c\nf 1 2 4\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("s.obj:6:") && e.contains("out of range"), "{e}");
        let e = load_str("v 0 0 nan\n").unwrap_err().to_string();
        assert!(e.contains("s.obj:1:") && e.contains("finite"), "{e}");
        let e = load_str("v 0 0 0\nbogus 1 2\n").unwrap_err().to_string();
        assert!(
            e.contains("s.obj:2:") && e.contains("unknown OBJ statement"),
            "{e}"
        );
        let e = load_str("v 0 0 0\n").unwrap_err().to_string();
        assert!(e.contains("no faces"), "{e}");
    }

    #[test]
    fn material_names_survive_a_missing_mtl_and_quads_are_split() {
        let s = load_str(
            "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
             g wall\nusemtl Brick\nf 1/1 2/2 3/3 4/4\ng pane\nusemtl Glass_Clear\nf -4 -3 -2 # tail comment\n",
        )
        .unwrap();
        assert_eq!(
            s.materials,
            vec!["Brick".to_string(), "Glass_Clear".to_string()]
        );
        assert_eq!(s.meshes.len(), 2);
        assert_eq!(s.meshes[0].triangles.len(), 2);
        assert_eq!(s.material_name(&s.meshes[1]), "Glass_Clear");
        assert_eq!(s.meshes[1].group, "pane");
        assert_eq!(s.meshes[0].tex_triangles.len(), 2);
        assert!(
            s.warnings.iter().any(|w| w
                .to_string()
                .starts_with(&format!("{}:1: ", s.source.display()))
                && w.to_string().contains("missing.mtl")),
            "{:?}",
            s.warnings
        );
    }

    #[test]
    fn mtl_errors_name_the_mtl_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("m.mtl"), "newmtl A\nKd 1 0\n").unwrap();
        let p = dir.path().join("s.obj");
        std::fs::write(
            &p,
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl A\nf 1 2 3\n",
        )
        .unwrap();
        let e = load_obj(&p).unwrap_err().to_string();
        assert!(e.contains("m.mtl:2:"), "{e}");
    }

    #[test]
    fn weights_short_texcoords_tabs_and_continuations_are_normalised() {
        let s = load_str(
            "v 2 4 6 2\nv\t1 0 0 # trailing comment\nv 0 1 \\\n 0\nvt 0.25\nvt 0.5 0.75 0\nvt 1 1\n\
             usemtl A\nf 1/1 2/2 3/3\n",
        )
        .unwrap();
        let m = &s.meshes[0];
        assert_eq!(
            m.corners(0),
            [[1.0, 2.0, 3.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        );
        let t = m.tex_triangles[0];
        assert_eq!(m.texcoords[t[0] as usize], [0.25, 0.0]);
        assert_eq!(m.texcoords[t[1] as usize], [0.5, 0.75]);
        // A continued line keeps the number of its first line in errors.
        let e = load_str("v 0 0 \\\n x\n").unwrap_err().to_string();
        assert!(e.contains("s.obj:1:"), "{e}");
        let e = load_str("v 1 2 3 0\n").unwrap_err().to_string();
        assert!(e.contains("w is 0"), "{e}");
    }

    /// The U-shaped pane of the triangulation tests (3 × 2, a 1 × 1 notch from the top
    /// middle) as OBJ corners, with texture coordinates (x/3, y/2) and one normal.
    const U_PANE: &str = "v 0 0 0\nv 3 0 0\nv 3 2 0\nv 2 2 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0.6666666666666666 1\nvt 0.6666666666666666 0.5\n\
        vt 0.3333333333333333 0.5\nvt 0.3333333333333333 1\nvt 0 1\nvn 0 0 1\n";

    /// Whether the (x, y) point lies in triangle t of a mesh in the plane z = 0.
    fn covers(m: &Mesh, t: usize, x: [f64; 2]) -> bool {
        let [a, b, c] = m.corners(t);
        let o = |p: Vec3, q: Vec3| (q[0] - p[0]) * (x[1] - p[1]) - (q[1] - p[1]) * (x[0] - p[0]);
        let (o1, o2, o3) = (o(a, b), o(b, c), o(c, a));
        (o1 >= 0.0 && o2 >= 0.0 && o3 >= 0.0) || (o1 <= 0.0 && o2 <= 0.0 && o3 <= 0.0)
    }

    #[test]
    fn a_concave_pane_is_ear_clipped_and_its_attributes_follow_the_corners() {
        for (face, z_sign) in [
            ("f 1/1/1 2/2/1 3/3/1 4/4/1 5/5/1 6/6/1 7/7/1 8/8/1", 1.0),
            ("f 8/8/1 7/7/1 6/6/1 5/5/1 4/4/1 3/3/1 2/2/1 1/1/1", -1.0),
        ] {
            let s = load_str(&format!("{U_PANE}usemtl Glass\n{face}\n")).unwrap();
            assert!(s.warnings.is_empty(), "{:?}", s.warnings);
            let m = &s.meshes[0];
            assert_eq!(m.triangles.len(), 6);
            let mut area = 0.0;
            for t in 0..m.triangles.len() {
                let [a, b, c] = m.corners(t);
                let n = crate::math::triangle_normal_area2(a, b, c);
                // Every triangle keeps the face's winding.
                assert!(n[2] * z_sign > 0.0, "triangle {t} flipped: {n:?}");
                area += n[2].abs() / 2.0;
                // Texture coordinates and normals follow the corners.
                for k in 0..3 {
                    let p = m.positions[m.triangles[t][k] as usize];
                    let uv = m.texcoords[m.tex_triangles[t][k] as usize];
                    assert!(
                        (uv[0] - p[0] / 3.0).abs() < 1e-12 && (uv[1] - p[1] / 2.0).abs() < 1e-12
                    );
                    assert_eq!(
                        m.normals[m.normal_triangles[t][k] as usize],
                        [0.0, 0.0, 1.0]
                    );
                }
            }
            assert!((area - 5.0).abs() < 1e-12, "{area}");
            let covered = |x: [f64; 2]| (0..m.triangles.len()).any(|t| covers(m, t, x));
            for x in [[1.5, 1.5], [1.8, 1.3], [1.2, 1.9], [1.01, 1.01]] {
                assert!(!covered(x), "notch point {x:?} covered");
            }
            for x in [[0.5, 1.9], [2.5, 1.9], [1.5, 0.5], [2.9, 0.1]] {
                assert!(covered(x), "pane point {x:?} missed");
            }
        }
    }

    #[test]
    fn convex_quads_keep_the_fan_of_before() {
        let s =
            load_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\nf 2 5 3\n").unwrap();
        let m = &s.meshes[0];
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]]);
        assert!(s.warnings.is_empty());
    }

    #[test]
    fn polygons_that_cannot_be_ear_clipped_are_fanned_with_a_warning_naming_the_line() {
        // Line 7: a quad bent out of its plane; line 8: a quad whose edges cross.
        let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0.4\nv 0 1 0\nv 2 0 0\nv 1 2 0\n\
                   f 1 2 3 4\nf 1 5 4 6\nf 1 2 4\n";
        let s = load_str(obj).unwrap();
        let m = &s.meshes[0];
        assert_eq!(
            m.triangles,
            vec![[0, 1, 2], [0, 2, 3], [0, 4, 3], [0, 3, 5], [0, 1, 3]]
        );
        let w: Vec<String> = s.warnings.iter().map(ToString::to_string).collect();
        assert_eq!(w.len(), 2, "{w:?}");
        let file = s.source.display().to_string();
        assert!(
            w[0].starts_with(&format!("{file}:7: polygon of 4 vertices is not planar")),
            "{w:?}"
        );
        assert!(
            w[1].starts_with(&format!(
                "{file}:8: polygon of 4 vertices crosses itself (its edges from corners 2 and 4 cross)"
            )),
            "{w:?}"
        );
        assert!(w.iter().all(|x| x.contains("fan-triangulated")), "{w:?}");
        assert!(matches!(
            s.warnings[0],
            SceneWarning::PolygonFanned {
                line: 7,
                vertices: 4,
                reason: crate::FanReason::NonPlanar { .. },
                ..
            }
        ));

        // Many bad polygons: the first ones listed, the rest counted.
        let mut many = String::from("v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\n");
        for _ in 0..MAX_POLYGON_WARNINGS + 5 {
            many.push_str("f 1 2 3 4\n");
        }
        let s = load_str(&many).unwrap();
        assert_eq!(s.warnings.len(), MAX_POLYGON_WARNINGS + 1);
        assert_eq!(
            s.warnings.last().unwrap().to_string(),
            format!(
                "{}: 5 more polygons fan-triangulated (not listed)",
                s.source.display()
            )
        );
    }

    #[test]
    fn mtllib_names_split_at_whitespace_quotes_and_mtl_endings() {
        let p = Path::new("s.obj");
        let split = |t: &str| split_mtllib(t, p, 3).unwrap();
        assert_eq!(split("a.mtl b.mtl"), ["a.mtl", "b.mtl"]);
        assert_eq!(
            split("my scene.mtl  other.MTL"),
            ["my scene.mtl", "other.MTL"]
        );
        assert_eq!(split("\"two  words\" c.mtl"), ["two  words", "c.mtl"]);
        assert_eq!(split("lib \"q.mtl\""), ["lib", "q.mtl"]);
        assert_eq!(split("materials file"), ["materials file"]);
        assert_eq!(split("a.mtl tail"), ["a.mtl", "tail"]);
        // What the mirror writes reads back as the same name.
        for name in [
            "a.mtl",
            "../my stone.mtl",
            "dir/mats",
            "lib a.mtl b",
            " lead.mtl",
        ] {
            assert_eq!(split(&mtllib_argument(name)), [name], "{name}");
        }
        let e = split_mtllib("\"open.mtl", p, 3).unwrap_err().to_string();
        assert!(
            e.starts_with("s.obj:3:") && e.contains("closing quote"),
            "{e}"
        );
    }

    #[test]
    fn several_material_libraries_are_each_validated_and_all_kept() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("a.mtl"), "newmtl Glass\nKd 1 1 1\n").unwrap();
        std::fs::write(d.join("b.mtl"), "newmtl Wood\nKd 0.5 0.3 0.1\n").unwrap();
        std::fs::write(d.join("my lib.mtl"), "newmtl Stone\n").unwrap();
        let p = d.join("s.obj");
        let body = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl Glass\nf 1 2 3\nusemtl Wood\nf 1 3 2\n\
                    usemtl Stone\nf 2 1 3\n";
        std::fs::write(
            &p,
            format!("mtllib a.mtl b.mtl\nmtllib my lib.mtl a.mtl\n{body}"),
        )
        .unwrap();
        let s = load_obj(&p).unwrap();
        assert_eq!(s.mtllibs, ["a.mtl", "b.mtl", "my lib.mtl"]);
        assert!(s.warnings.is_empty(), "{:?}", s.warnings);

        // An error in the second file of a line names that file and its line.
        std::fs::write(d.join("b.mtl"), "newmtl Wood\nKd 0.5 0.3\n").unwrap();
        let e = load_obj(&p).unwrap_err().to_string();
        assert!(e.contains("b.mtl:2:"), "{e}");

        // A missing one is a warning naming the OBJ line; its materials are then undefined
        // (warned at their first usemtl).
        std::fs::remove_file(d.join("b.mtl")).unwrap();
        let s = load_obj(&p).unwrap();
        let w: Vec<String> = s.warnings.iter().map(ToString::to_string).collect();
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(
            w[0].starts_with(&format!("{}:1: material library", p.display())),
            "{w:?}"
        );
        assert!(w[0].contains("b.mtl not found"), "{w:?}");
        assert!(
            w[1].starts_with(&format!("{}:8: material \"Wood\"", p.display())),
            "{w:?}"
        );
        assert_eq!(s.mtllibs, ["a.mtl", "b.mtl", "my lib.mtl"]);
    }
}
