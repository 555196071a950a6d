//! The OBJ reader against hand-written scenes.

use super::read::MAX_POLYGON_WARNINGS;
use super::text::split_mtllib;
use super::write::mtllib_argument;
use super::*;

fn load_str(obj: &str) -> Result<Scene, SceneError> {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.obj");
    std::fs::write(&p, obj).unwrap();
    load_obj(&p)
}

/// Loading `obj` fails with a message that contains each of `needles`.
#[track_caller]
fn assert_load_error(obj: &str, needles: &[&str]) {
    let e = load_str(obj).unwrap_err().to_string();
    for needle in needles {
        assert!(e.contains(needle), "{needle:?} not in {e}");
    }
}

#[test]
fn syntax_errors_name_file_and_line() {
    assert_load_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", &["s.obj:4:"]);
    assert_load_error("v 0 0\n", &["s.obj:1:", "found 2 values"]);
    assert_load_error(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\n\n# c\nf 1 2 4\n",
        &["s.obj:6:", "out of range"],
    );
    assert_load_error("v 0 0 nan\n", &["s.obj:1:", "finite"]);
    assert_load_error(
        "v 0 0 0\nbogus 1 2\n",
        &["s.obj:2:", "unknown OBJ statement"],
    );
    assert_load_error("v 0 0 0\n", &["no faces"]);
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
    assert_load_error("v 0 0 \\\n x\n", &["s.obj:1:"]);
    assert_load_error("v 1 2 3 0\n", &["w is 0"]);
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
                assert!((uv[0] - p[0] / 3.0).abs() < 1e-12 && (uv[1] - p[1] / 2.0).abs() < 1e-12);
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
    let s = load_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\nf 2 5 3\n").unwrap();
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
