//! Reading OBJ scenes (with `tobj`) and writing them back.
//!
//! `tobj` reports errors without a line number, accepts some malformed input silently and
//! forgets the name of a material whose MTL file is missing. So every OBJ is first validated
//! line by line here (errors name file and line), normalised (comments stripped, tabs made
//! spaces, continuation lines joined, statements we do not use dropped) and then handed to
//! `tobj` with a material loader that knows every `usemtl` name, whether or not its MTL file
//! exists. Material *properties* are never needed: the mirror writes an `mtllib` reference to
//! the original files, and the mask only matches material names.

use std::borrow::Cow;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use crate::error::SceneError;
use crate::math::Vec3;

/// Most vertices/faces accepted in one OBJ, so that a hostile file cannot exhaust memory
/// through index arithmetic (the text itself bounds real data).
const MAX_ELEMENTS: usize = 1 << 31;

/// A triangulated OBJ scene, one [`Mesh`] per group/object and material run.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    /// The OBJ file it was read from.
    pub source: PathBuf,
    /// `mtllib` arguments as written in the OBJ (relative to its directory).
    pub mtllibs: Vec<String>,
    /// Material names in order of first `usemtl`.
    pub materials: Vec<String>,
    /// The meshes, in file order.
    pub meshes: Vec<Mesh>,
    /// Non-fatal remarks for the user (missing MTL file, undefined material, ...).
    pub warnings: Vec<String>,
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
    /// Position indices per triangle, counter-clockwise seen from the front.
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
    mtllibs: Vec<String>,
    usemtl: Vec<String>,
    faces: usize,
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

/// Reads a text file, turning invalid UTF-8 into an error naming the line.
fn read_text(path: &Path) -> Result<String, SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Read {
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
    let mut mtllibs = Vec::new();
    let mut usemtl: Vec<String> = Vec::new();
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
                }
                let _ = writeln!(out, "usemtl {rest}");
            }
            "mtllib" => {
                if rest.is_empty() {
                    return Err(syntax(path, line, "mtllib without a file name"));
                }
                mtllibs.push(rest.to_string());
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
        faces,
    })
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

/// Reads, validates and triangulates an OBJ scene. Polygons are fan-triangulated.
pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
    let text = read_text(path)?;
    let scan = scan_obj(&text, path)?;
    if scan.faces == 0 {
        return Err(SceneError::EmptyScene {
            path: path.to_path_buf(),
        });
    }
    let mut warnings = Vec::new();
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut defined: Vec<String> = Vec::new();
    for lib in &scan.mtllibs {
        let mtl_path = dir.join(lib);
        if !mtl_path.exists() {
            warnings.push(format!(
                "material library {} not found (material names still used)",
                mtl_path.display()
            ));
            continue;
        }
        let mtl_text = read_text(&mtl_path)?;
        defined.extend(scan_mtl(&mtl_text, &mtl_path)?);
    }
    if !scan.mtllibs.is_empty() {
        for m in &scan.usemtl {
            if !defined.contains(m) {
                warnings.push(format!(
                    "material {m:?} is used but defined in no material library"
                ));
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
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: true,
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
        let tri = |idx: &[u32]| -> Vec<[u32; 3]> {
            idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
        };
        let triangles = tri(&m.indices);
        let tex_triangles = if m.texcoord_indices.len() == m.indices.len() {
            tri(&m.texcoord_indices)
        } else {
            Vec::new()
        };
        let normal_triangles = if m.normal_indices.len() == m.indices.len() {
            tri(&m.normal_indices)
        } else {
            Vec::new()
        };
        let in_range = |t: &[[u32; 3]], n: usize| t.iter().flatten().all(|&i| (i as usize) < n);
        if !in_range(&triangles, positions.len())
            || !in_range(&tex_triangles, texcoords.len())
            || !in_range(&normal_triangles, normals.len())
        {
            return Err(SceneError::Load {
                path: path.to_path_buf(),
                message: "face index out of range after loading".into(),
            });
        }
        meshes.push(Mesh {
            group: model.name,
            material,
            positions,
            texcoords,
            normals,
            triangles,
            tex_triangles,
            normal_triangles,
        });
    }
    Ok(Scene {
        source: path.to_path_buf(),
        mtllibs: scan.mtllibs,
        materials: scan.usemtl,
        meshes,
        warnings,
    })
}

/// Writes meshes as an OBJ (atomically), with `mtllib` lines pointing at `mtllibs` (already
/// expressed relative to the output's directory) and `header` as leading comment lines.
pub fn write_obj(
    path: &Path,
    header: &[String],
    mtllibs: &[String],
    materials: &[String],
    meshes: &[Mesh],
) -> Result<(), SceneError> {
    glassdb_io::write_atomic(path, |w| {
        for h in header {
            writeln!(w, "# {h}")?;
        }
        for lib in mtllibs {
            writeln!(w, "mtllib {lib}")?;
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
                        (false, true) => {
                            write!(w, " {v}//{}", on + m.normal_triangles[k][c] as u64)?
                        }
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
    })?;
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
        assert!(s.warnings.iter().any(|w| w.contains("missing.mtl")));
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
}
