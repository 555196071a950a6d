//! `glassdb mask` as a library call: label the scene's triangles with glass ids, planes and
//! panes, rasterise, and turn the result into a [`glassdb_mask::MaskImage`].

use std::collections::HashMap;

use glassdb_mask::{CosCode, CosTheta, MaskImage};

use crate::error::SceneError;
use crate::math;
use crate::obj::Scene;
use crate::planes::{MaterialMatcher, Plane, PlaneTolerance, assign_to_planes, detect_planes};
use crate::raster::{GlassLabel, PaneRect, RasterOutput, RasterScene};

pub use glassdb_mask::GlassMapping;

/// Where the plane indices come from.
#[derive(Debug, Clone)]
pub enum PlaneSource {
    /// Detect the planes of the glass faces (same rule and order as `glassdb mirror`).
    Detect(PlaneTolerance),
    /// Use these planes (from a `planes.json`); every glass face must lie on one.
    Given {
        /// The planes, by index.
        planes: Vec<Plane>,
        /// How far a glass face may lie from its plane.
        tolerance: PlaneTolerance,
    },
}

/// The labelled scene plus what the user should know about it.
#[derive(Debug, Clone)]
pub struct MaskScene {
    /// The triangles, labelled, as the rasteriser draws them.
    pub raster: RasterScene,
    /// The planes, by index.
    pub planes: Vec<Plane>,
    /// Patterns that matched no material with faces.
    pub unmatched_patterns: Vec<String>,
    /// Triangles drawn as glass.
    pub glass_triangles: usize,
}

/// Disjoint sets over triangle indices (panes: glass triangles of one plane sharing a vertex).
struct Dsu(Vec<u32>);

impl Dsu {
    fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let p = self.0[x as usize];
            self.0[x as usize] = self.0[p as usize];
            x = p;
        }
        x
    }
    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb) as usize] = ra.min(rb);
        }
    }
}

/// In-plane unit axes (u, v) with u × v = n.
fn plane_axes(n: math::Vec3) -> (math::Vec3, math::Vec3) {
    let k = (0..3)
        .min_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let u = math::normalize(math::cross(e, n)).unwrap_or([1.0, 0.0, 0.0]);
    (u, math::cross(n, u))
}

/// Labels every triangle of `scene`: glass (by `mappings`, first match wins) with its id,
/// plane and (with `panes`) pane; everything else opaque.
pub fn build_mask_scene(
    scene: &Scene,
    mappings: &[GlassMapping],
    source: &PlaneSource,
    panes: bool,
) -> Result<MaskScene, SceneError> {
    let patterns: Vec<&str> = mappings.iter().map(|m| m.pattern.as_str()).collect();
    let matcher = MaterialMatcher::new(&patterns)?;
    let table = matcher.require_faces(scene)?;
    let id_of = |m: Option<usize>| {
        m.and_then(|i| table.get(i).copied().flatten())
            .map(|k| mappings[k].id)
    };
    let (planes, assignment) = glass_planes(scene, source, &matcher, |m| id_of(m).is_some())?;
    let unmatched_patterns = unmatched_patterns(scene, mappings, &table);
    let (mut raster, glass_tris) = scene_geometry(scene, &assignment, id_of);
    let pane_of = if panes {
        find_panes(&mut raster, &glass_tris, &planes)
    } else {
        vec![0u32; glass_tris.len()]
    };
    label_glass(&mut raster, &glass_tris, &pane_of, &planes);
    Ok(MaskScene {
        raster,
        planes,
        unmatched_patterns,
        glass_triangles: glass_tris.len(),
    })
}

/// Each mesh's triangles' plane (`None`: not glass), mesh by mesh.
type PlaneAssignment = Vec<Vec<Option<usize>>>;

/// The glass planes (detected, or given with every glass face assigned to one) and each mesh's
/// triangles' plane (`None`: not glass).
fn glass_planes(
    scene: &Scene,
    source: &PlaneSource,
    matcher: &MaterialMatcher,
    is_glass: impl Fn(Option<usize>) -> bool,
) -> Result<(Vec<Plane>, PlaneAssignment), SceneError> {
    let (planes, assignment) = match source {
        PlaneSource::Detect(tol) => {
            let (gp, a) = detect_planes(scene, is_glass, *tol, &matcher.describe())?;
            (gp.into_iter().map(|g| g.plane).collect::<Vec<_>>(), a)
        }
        PlaneSource::Given { planes, tolerance } => (
            planes.clone(),
            assign_to_planes(scene, is_glass, planes, *tolerance)?,
        ),
    };
    if planes.len() > u16::MAX as usize + 1 {
        return Err(SceneError::BadOption {
            message: format!(
                "{} glass planes: a mask holds plane indices up to 65535",
                planes.len()
            ),
        });
    }
    Ok((planes, assignment))
}

/// The mappings (`PATTERN=ID`) whose pattern matched no material with faces.
fn unmatched_patterns(
    scene: &Scene,
    mappings: &[GlassMapping],
    table: &[Option<usize>],
) -> Vec<String> {
    let used: Vec<bool> = (0..mappings.len())
        .map(|k| {
            scene
                .meshes
                .iter()
                .any(|m| !m.triangles.is_empty() && m.material.and_then(|i| table[i]) == Some(k))
        })
        .collect();
    mappings
        .iter()
        .zip(&used)
        .filter(|(_, u)| !**u)
        .map(|(m, _)| format!("{}={}", m.pattern, m.id))
        .collect()
}

/// Every mesh's positions and triangles in one list, every triangle opaque, and the glass
/// triangles: (global triangle, id, plane).
fn scene_geometry(
    scene: &Scene,
    assignment: &[Vec<Option<usize>>],
    id_of: impl Fn(Option<usize>) -> Option<u16>,
) -> (RasterScene, Vec<(u32, u16, u16)>) {
    let total = scene.triangle_count();
    let mut raster = RasterScene {
        positions: Vec::with_capacity(scene.meshes.iter().map(|m| m.positions.len()).sum()),
        triangles: Vec::with_capacity(total),
        labels: vec![0; total],
        glass: Vec::new(),
        panes: Vec::new(),
    };
    let mut glass_tris: Vec<(u32, u16, u16)> = Vec::new();
    for (mesh, row) in scene.meshes.iter().zip(assignment) {
        let base = raster.positions.len() as u32;
        raster.positions.extend_from_slice(&mesh.positions);
        let id = id_of(mesh.material);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let g = raster.triangles.len() as u32;
            raster
                .triangles
                .push([tri[0] + base, tri[1] + base, tri[2] + base]);
            if let (Some(id), Some(p)) = (id, row[t]) {
                glass_tris.push((g, id, p as u16));
            }
        }
    }
    (raster, glass_tris)
}

/// Panes: glass triangles of one plane connected through shared corner positions, each with
/// its rectangle in its plane. Returns each glass triangle's pane.
fn find_panes(
    raster: &mut RasterScene,
    glass_tris: &[(u32, u16, u16)],
    planes: &[Plane],
) -> Vec<u32> {
    let mut dsu = Dsu((0..glass_tris.len() as u32).collect());
    let mut first: HashMap<(u16, [u64; 3]), u32> = HashMap::new();
    for (k, &(g, _, plane)) in glass_tris.iter().enumerate() {
        for &v in &raster.triangles[g as usize] {
            let p = raster.positions[v as usize];
            let key = (plane, [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()]);
            match first.get(&key) {
                Some(&o) => dsu.union(o, k as u32),
                None => {
                    first.insert(key, k as u32);
                }
            }
        }
    }
    let mut pane_of = vec![0u32; glass_tris.len()];
    let mut root_to_pane: HashMap<u32, u32> = HashMap::new();
    let mut bounds: Vec<[f64; 4]> = Vec::new();
    for k in 0..glass_tris.len() {
        let root = dsu.find(k as u32);
        let (g, _, plane) = glass_tris[k];
        let pane = *root_to_pane.entry(root).or_insert_with(|| {
            bounds.push([
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ]);
            raster.panes.push(pane_in_plane(&planes[plane as usize]));
            (raster.panes.len() - 1) as u32
        });
        pane_of[k] = pane;
        let r = raster.panes[pane as usize];
        let b = &mut bounds[pane as usize];
        for &vi in &raster.triangles[g as usize] {
            let rel = math::sub(raster.positions[vi as usize], r.origin);
            let (su, sv) = (math::dot(rel, r.u), math::dot(rel, r.v));
            b[0] = b[0].min(su);
            b[1] = b[1].min(sv);
            b[2] = b[2].max(su);
            b[3] = b[3].max(sv);
        }
    }
    for (r, b) in raster.panes.iter_mut().zip(&bounds) {
        r.u_min = b[0];
        r.v_min = b[1];
        r.u_len = (b[2] - b[0]).max(1e-300);
        r.v_len = (b[3] - b[1]).max(1e-300);
    }
    pane_of
}

/// A pane of `plane` before its extent is known: the plane's point nearest the origin and two
/// in-plane axes.
fn pane_in_plane(plane: &Plane) -> PaneRect {
    let (u, v) = plane_axes(plane.normal);
    PaneRect {
        origin: math::scale(plane.normal, -plane.d),
        u,
        v,
        u_min: 0.0,
        v_min: 0.0,
        u_len: 0.0,
        v_len: 0.0,
    }
}

/// Gives every glass triangle the label of its (id, plane, pane).
fn label_glass(
    raster: &mut RasterScene,
    glass_tris: &[(u32, u16, u16)],
    pane_of: &[u32],
    planes: &[Plane],
) {
    let mut label_of: HashMap<(u16, u16, u32), u32> = HashMap::new();
    for (k, &(g, id, plane)) in glass_tris.iter().enumerate() {
        let pane = pane_of[k];
        let label = *label_of.entry((id, plane, pane)).or_insert_with(|| {
            let pl = planes[plane as usize];
            raster.glass.push(GlassLabel {
                id,
                plane,
                normal: pl.normal,
                d: pl.d,
                pane,
            });
            raster.glass.len() as u32
        });
        raster.labels[g as usize] = label;
    }
}

/// How cos θ is stored in the mask.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CosEncoding {
    /// 8-bit codes of [`CosCode::Bits8`]: code = round(cos θ · 255).
    Quantized8,
    /// 16-bit codes of [`CosCode::Bits16`]: code = round(cos θ · 65535).
    Quantized16,
    /// cos θ as f32.
    Float,
}

/// The rasteriser output as a [`MaskImage`] with cos θ encoded as asked.
pub fn to_mask_image(out: RasterOutput, enc: CosEncoding) -> MaskImage {
    let cos_theta = match enc {
        CosEncoding::Quantized8 => CosTheta::Quantized8(
            out.cos_theta
                .iter()
                .map(|&c| CosCode::encode8(f64::from(c)))
                .collect(),
        ),
        CosEncoding::Quantized16 => CosTheta::Quantized16(
            out.cos_theta
                .iter()
                .map(|&c| CosCode::Bits16.encode(f64::from(c)))
                .collect(),
        ),
        CosEncoding::Float => CosTheta::Float(out.cos_theta),
    };
    MaskImage {
        width: out.width,
        height: out.height,
        id: out.id,
        cos_theta,
        plane: out.plane,
        coverage: out.coverage,
    }
}
