//! Meshes written as an OBJ (the mirror's virtual scenes).

use std::borrow::Cow;
use std::path::Path;

use super::Mesh;
use super::text::split_mtllib;
use crate::error::SceneError;

/// `name` as one `mtllib` argument: as it is when [`split_mtllib`] reads it back as one name,
/// else in double quotes (a name with spaces not ending in `.mtl`, say).
pub(super) fn mtllib_argument(name: &str) -> Cow<'_, str> {
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
