//! The virtual image of a plane mirror (method.md section 3, eqs. 4–7): the scene's front
//! half-space, clipped at the plane, reflected across it, with winding and normals fixed so
//! that faces still face outwards.

use std::collections::HashMap;

use crate::math::{self, Vec3};
use crate::obj::{Mesh, Scene};
use crate::planes::Plane;

/// What happened to the triangles of the scene.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MirrorStats {
    /// Triangles entirely in the kept half-space (or in the plane), mirrored whole.
    pub kept: usize,
    /// Triangles crossing the plane, clipped to their part in the kept half-space.
    pub clipped: usize,
    /// Triangles entirely behind the plane.
    pub behind: usize,
    /// Triangles dropped by the caller (the glass faces).
    pub dropped: usize,
    /// Triangles written (a clipped triangle can become two).
    pub written: usize,
}

const UNSET: u32 = u32::MAX;

/// (position, texcoord, normal) indices of one OBJ corner.
type CornerIndices = (u32, u32, u32);

/// One corner of a polygon being clipped: either an original vertex (its indices) or a new
/// point on an edge, with interpolated attributes.
#[derive(Clone, Copy)]
struct Corner {
    s: f64,
    pos: Vec3,
    tex: Option<[f64; 2]>,
    nrm: Option<Vec3>,
    /// Original (position, texcoord, normal) indices; `None` for points made by clipping.
    orig: Option<CornerIndices>,
    /// For points made by clipping: the edge they lie on (its corners' indices, sorted), so
    /// that the triangles sharing the edge share the point.
    edge: Option<[CornerIndices; 2]>,
}

struct Builder<'a> {
    src: &'a Mesh,
    out: Mesh,
    pos_map: IndexMap,
    tex_map: IndexMap,
    nrm_map: IndexMap,
    has_t: bool,
    has_n: bool,
    crossings: HashMap<[CornerIndices; 2], CornerIndices>,
}

impl Builder<'_> {
    fn index_of(&mut self, c: &Corner) -> (u32, u32, u32) {
        match c.orig {
            Some((p, t, n)) => {
                let pi = self
                    .pos_map
                    .index(&mut self.out.positions, &self.src.positions, p);
                let ti = if self.has_t {
                    self.tex_map
                        .index(&mut self.out.texcoords, &self.src.texcoords, t)
                } else {
                    0
                };
                let ni = if self.has_n {
                    self.nrm_map
                        .index(&mut self.out.normals, &self.src.normals, n)
                } else {
                    0
                };
                (pi, ti, ni)
            }
            None => {
                if let Some(ix) = c.edge.and_then(|e| self.crossings.get(&e)) {
                    return *ix;
                }
                let pi = push_index(&mut self.out.positions, c.pos);
                let mut ti = 0;
                if let (true, Some(t)) = (self.has_t, c.tex) {
                    ti = push_index(&mut self.out.texcoords, t);
                }
                let mut ni = 0;
                if let (true, Some(n)) = (self.has_n, c.nrm) {
                    ni = push_index(&mut self.out.normals, n);
                }
                if let Some(e) = c.edge {
                    self.crossings.insert(e, (pi, ti, ni));
                }
                (pi, ti, ni)
            }
        }
    }

    fn emit(&mut self, a: &Corner, b: &Corner, c: &Corner) {
        let (ia, ib, ic) = (self.index_of(a), self.index_of(b), self.index_of(c));
        self.out.triangles.push([ia.0, ib.0, ic.0]);
        if self.has_t {
            self.out.tex_triangles.push([ia.1, ib.1, ic.1]);
        }
        if self.has_n {
            self.out.normal_triangles.push([ia.2, ib.2, ic.2]);
        }
    }
}

/// Source index → output index of one vertex attribute (positions, texcoords or normals), so
/// that each source value used is copied to the output once.
struct IndexMap(Vec<u32>);

impl IndexMap {
    /// A map over `len` source values, none copied yet.
    fn new(len: usize) -> IndexMap {
        IndexMap(vec![UNSET; len])
    }

    /// The output index of source value `i`, copying `src[i]` to `out` on first use.
    fn index<T: Copy>(&mut self, out: &mut Vec<T>, src: &[T], i: u32) -> u32 {
        let slot = &mut self.0[i as usize];
        if *slot == UNSET {
            *slot = push_index(out, src[i as usize]);
        }
        *slot
    }
}

/// Appends `value` to `out` and returns its index there.
fn push_index<T>(out: &mut Vec<T>, value: T) -> u32 {
    out.push(value);
    (out.len() - 1) as u32
}

/// The point where edge a→b crosses the plane (`a.s`, `b.s` of opposite signs), attributes
/// interpolated linearly and the position projected exactly onto the plane. Computed from the
/// edge's corners in a fixed order, so both triangles sharing the edge get the same point.
fn crossing(plane: &Plane, a: &Corner, b: &Corner) -> Corner {
    let (a, b) = if a.orig <= b.orig { (a, b) } else { (b, a) };
    let edge = match (a.orig, b.orig) {
        (Some(x), Some(y)) => Some([x, y]),
        _ => None,
    };
    let t = a.s / (a.s - b.s);
    let p = math::lerp(a.pos, b.pos, t);
    let pos = math::sub(p, math::scale(plane.normal, plane.signed_distance(p)));
    let tex = match (a.tex, b.tex) {
        (Some(x), Some(y)) => Some([x[0] + t * (y[0] - x[0]), x[1] + t * (y[1] - x[1])]),
        _ => None,
    };
    let nrm = match (a.nrm, b.nrm) {
        (Some(x), Some(y)) => {
            let m = math::lerp(x, y, t);
            Some(math::normalize(m).unwrap_or(m))
        }
        _ => None,
    };
    Corner {
        s: 0.0,
        pos,
        tex,
        nrm,
        orig: None,
        edge,
    }
}

/// Where a triangle lies against the plane, and so what was emitted for it.
enum TriangleFate {
    /// Entirely in the kept half-space (or in the plane): emitted whole.
    Kept,
    /// Crossing the plane: its part in the kept half-space emitted (one or two triangles).
    Clipped,
    /// Entirely behind the plane: nothing emitted.
    Behind,
}

impl<'a> Builder<'a> {
    fn new(src: &'a Mesh) -> Builder<'a> {
        let has_t = !src.tex_triangles.is_empty();
        let has_n = !src.normal_triangles.is_empty();
        Builder {
            src,
            out: Mesh {
                group: src.group.clone(),
                material: src.material,
                ..Default::default()
            },
            pos_map: IndexMap::new(src.positions.len()),
            tex_map: IndexMap::new(if has_t { src.texcoords.len() } else { 0 }),
            nrm_map: IndexMap::new(if has_n { src.normals.len() } else { 0 }),
            has_t,
            has_n,
            crossings: HashMap::new(),
        }
    }

    /// The corners of triangle `t` with their signed distances to `plane` (0 within `eps`).
    fn corners(&self, t: usize, plane: &Plane, eps: f64) -> [Corner; 3] {
        let src = self.src;
        let tri = src.triangles[t];
        std::array::from_fn(|k| {
            let p = src.positions[tri[k] as usize];
            let s = plane.signed_distance(p);
            let ti = if self.has_t {
                src.tex_triangles[t][k]
            } else {
                0
            };
            let ni = if self.has_n {
                src.normal_triangles[t][k]
            } else {
                0
            };
            Corner {
                s: if s.abs() <= eps { 0.0 } else { s },
                pos: p,
                tex: self.has_t.then(|| src.texcoords[ti as usize]),
                nrm: self.has_n.then(|| src.normals[ni as usize]),
                orig: Some((tri[k], ti, ni)),
                edge: None,
            }
        })
    }

    /// Emits the part of the triangle in the kept half-space (`s ≥ 0`).
    fn keep_front(&mut self, plane: &Plane, corners: &[Corner; 3]) -> TriangleFate {
        let any_front = corners.iter().any(|c| c.s > 0.0);
        let any_back = corners.iter().any(|c| c.s < 0.0);
        if !any_back {
            self.emit(&corners[0], &corners[1], &corners[2]);
            return TriangleFate::Kept;
        }
        if !any_front {
            return TriangleFate::Behind;
        }
        // Sutherland–Hodgman against one plane: a triangle gives a triangle or a quad.
        let mut poly: Vec<Corner> = Vec::with_capacity(4);
        for k in 0..3 {
            let cur = &corners[k];
            let next = &corners[(k + 1) % 3];
            if cur.s >= 0.0 {
                poly.push(*cur);
            }
            if (cur.s > 0.0 && next.s < 0.0) || (cur.s < 0.0 && next.s > 0.0) {
                poly.push(crossing(plane, cur, next));
            }
        }
        for k in 1..poly.len().saturating_sub(1) {
            self.emit(&poly[0], &poly[k], &poly[k + 1]);
        }
        TriangleFate::Clipped
    }
}

/// Reflects a mesh across `plane`, then reverses the winding: a reflection flips handedness,
/// so reversing the corner order keeps each face's winding normal equal to its mirrored
/// outward normal.
fn reflect_mesh(out: &mut Mesh, plane: &Plane) {
    for p in &mut out.positions {
        *p = plane.reflect_point(*p);
    }
    for n in &mut out.normals {
        *n = plane.reflect_direction(*n);
    }
    for tri in out
        .triangles
        .iter_mut()
        .chain(out.tex_triangles.iter_mut())
        .chain(out.normal_triangles.iter_mut())
    {
        tri.swap(1, 2);
    }
}

/// Mirrors `scene` across `plane`, keeping the half-space where `plane.signed_distance ≥ 0`
/// (orient the plane so that the eye is on its positive side). Vertices within `eps` of the
/// plane count as on it. `drop(mesh, triangle)` removes triangles (the glass itself).
pub fn mirror_scene(
    scene: &Scene,
    plane: &Plane,
    eps: f64,
    drop: impl Fn(usize, usize) -> bool,
) -> (Vec<Mesh>, MirrorStats) {
    let mut stats = MirrorStats::default();
    let mut meshes = Vec::with_capacity(scene.meshes.len());
    for (mi, src) in scene.meshes.iter().enumerate() {
        let mut b = Builder::new(src);
        for t in 0..src.triangles.len() {
            if drop(mi, t) {
                stats.dropped += 1;
                continue;
            }
            let corners = b.corners(t, plane, eps);
            match b.keep_front(plane, &corners) {
                TriangleFate::Kept => stats.kept += 1,
                TriangleFate::Clipped => stats.clipped += 1,
                TriangleFate::Behind => stats.behind += 1,
            }
        }
        let mut out = b.out;
        reflect_mesh(&mut out, plane);
        stats.written += out.triangles.len();
        if !out.triangles.is_empty() {
            meshes.push(out);
        }
    }
    (meshes, stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{cross, dot, sub};

    fn scene_of(mesh: Mesh) -> Scene {
        Scene {
            meshes: vec![mesh],
            materials: vec!["M".into()],
            ..Default::default()
        }
    }

    fn area(m: &Mesh) -> f64 {
        (0..m.triangles.len())
            .map(|t| {
                let [a, b, c] = m.corners(t);
                0.5 * math::norm(cross(sub(b, a), sub(c, a)))
            })
            .sum()
    }

    #[test]
    fn clipping_keeps_exactly_the_front_part() {
        // Triangle (−1,0,0), (3,0,0), (−1,4,0) crosses the plane x = 0 (kept side x ≥ 0).
        let mesh = Mesh {
            group: "g".into(),
            material: Some(0),
            positions: vec![[-1.0, 0.0, 0.0], [3.0, 0.0, 0.0], [-1.0, 4.0, 0.0]],
            texcoords: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            triangles: vec![[0, 1, 2]],
            tex_triangles: vec![[0, 1, 2]],
            ..Default::default()
        };
        let plane = Plane::from_equation([1.0, 0.0, 0.0, 0.0]).unwrap();
        let (out, stats) = mirror_scene(&scene_of(mesh), &plane, 1e-12, |_, _| false);
        assert_eq!(stats.clipped, 1);
        // The kept part is the triangle (0,0,0), (3,0,0), (0,3,0): area 4.5; mirrored to x ≤ 0.
        assert!((area(&out[0]) - 4.5).abs() < 1e-12);
        for p in &out[0].positions {
            assert!(p[0] <= 1e-15, "{p:?}");
        }
        // The new corners lie exactly on the plane and carry interpolated texture coordinates:
        // (0,0,0) is 1/4 along the first edge → u = 0.25; (0,3,0) is 3/4 along edge 2→3 → (0.25, 0.75).
        let on_plane: Vec<usize> = (0..out[0].positions.len())
            .filter(|&i| out[0].positions[i][0] == 0.0)
            .collect();
        assert_eq!(on_plane.len(), 2);
        let uv: Vec<[f64; 2]> = out[0].texcoords.clone();
        assert!(
            uv.iter()
                .any(|t| (t[0] - 0.25).abs() < 1e-15 && t[1].abs() < 1e-15),
            "{uv:?}"
        );
        assert!(
            uv.iter()
                .any(|t| (t[0] - 0.25).abs() < 1e-15 && (t[1] - 0.75).abs() < 1e-15),
            "{uv:?}"
        );
    }

    #[test]
    fn winding_and_normals_face_outwards_after_mirroring() {
        // A triangle in front of the plane z = 0 facing +x, with matching vertex normals.
        let mesh = Mesh {
            group: "g".into(),
            material: Some(0),
            positions: vec![[1.0, 0.0, 1.0], [1.0, 1.0, 1.0], [1.0, 0.0, 2.0]],
            normals: vec![[1.0, 0.0, 0.0]],
            triangles: vec![[0, 1, 2]],
            normal_triangles: vec![[0, 0, 0]],
            ..Default::default()
        };
        let [a, b, c] = mesh.corners(0);
        let winding_before = cross(sub(b, a), sub(c, a));
        assert!(winding_before[0] > 0.0);
        // Mirror across the plane x + z = 0.5 (oblique).
        let plane = Plane::from_equation([1.0, 0.0, 1.0, -0.5]).unwrap();
        let (out, _) = mirror_scene(&scene_of(mesh), &plane, 1e-12, |_, _| false);
        let m = &out[0];
        let [a2, b2, c2] = m.corners(0);
        let w = math::normalize(cross(sub(b2, a2), sub(c2, a2))).unwrap();
        let expect = plane.reflect_direction([1.0, 0.0, 0.0]);
        // Mirrored x̂ across n = (1,0,1)/√2 is (0,0,−1).
        assert!((expect[0]).abs() < 1e-15 && (expect[2] + 1.0).abs() < 1e-15);
        assert!(
            dot(w, expect) > 1.0 - 1e-12,
            "winding normal {w:?} vs {expect:?}"
        );
        assert!(dot(m.normals[0], expect) > 1.0 - 1e-12);
    }

    #[test]
    fn mirroring_twice_is_the_identity() {
        let mesh = Mesh {
            group: "g".into(),
            material: Some(0),
            positions: vec![[0.3, 1.7, 2.0], [1.1, 0.2, 3.5], [-0.4, 2.2, 4.0]],
            triangles: vec![[0, 1, 2]],
            ..Default::default()
        };
        let plane = Plane::from_equation([0.2, -0.3, -1.0, 0.5]).unwrap();
        let plane = if plane.signed_distance([0.3, 1.7, 2.0]) < 0.0 {
            plane.flipped()
        } else {
            plane
        };
        let scene = scene_of(mesh.clone());
        let (once, _) = mirror_scene(&scene, &plane, 1e-12, |_, _| false);
        let (twice, _) = mirror_scene(
            &scene_of(once[0].clone()),
            &plane.flipped(),
            1e-12,
            |_, _| false,
        );
        for t in 0..1 {
            let orig = mesh.corners(t);
            let back = twice[0].corners(t);
            for k in 0..3 {
                for i in 0..3 {
                    assert!(
                        (orig[k][i] - back[k][i]).abs() < 1e-12,
                        "{orig:?} vs {back:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn triangles_sharing_a_clipped_edge_share_the_new_vertex() {
        // The square [−1, 1]² at z = 0 as two triangles with the diagonal (−1,−1)–(1,1),
        // cut by the plane x = 0.3: the diagonal's crossing (0.3, 0.3) must be one vertex.
        let mesh = Mesh {
            group: "g".into(),
            material: Some(0),
            positions: vec![
                [-1.0, -1.0, 0.0],
                [1.0, -1.0, 0.0],
                [1.0, 1.0, 0.0],
                [-1.0, 1.0, 0.0],
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            ..Default::default()
        };
        let plane = Plane::from_equation([1.0, 0.0, 0.0, -0.3]).unwrap();
        let (out, stats) = mirror_scene(&scene_of(mesh), &plane, 1e-12, |_, _| false);
        assert_eq!(stats.clipped, 2);
        let p = &out[0].positions;
        for a in 0..p.len() {
            for b in a + 1..p.len() {
                assert_ne!(p[a], p[b], "duplicate vertex {:?}", p[a]);
            }
        }
        // Kept: x in [0.3, 1] of the square, area 0.7 × 2.
        assert!((area(&out[0]) - 1.4).abs() < 1e-12);
    }
}
