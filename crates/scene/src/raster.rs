//! The z-buffer mask rasteriser (method.md section 5): every triangle of the scene is drawn;
//! glass triangles write their label (registration id, plane, pane), every other triangle
//! writes 0 and so hides the glass behind it (section 5.1). cos θ comes from the pixel-centre
//! ray: exactly, `|n · d̂|`, or the paper's way (section 6): at the nodes of an N×N mesh per
//! pane, Gouraud-interpolated in screen space.
//!
//! Layout: vertices are transformed once, triangles are clipped at the near plane, projected
//! and binned into bands of rows; bands are rasterised in parallel (rayon), each with its own
//! depth buffer of `1/z` (linear in screen space, so depth is perspective-correct). Edges are
//! evaluated in a canonical vertex order with a tie rule, so two triangles sharing an edge
//! cover every sample on it exactly once (no cracks in a pane made of several triangles).

use rayon::prelude::*;

use crate::camera::Camera;
use crate::error::SceneError;
use crate::math::{self, Vec3};

/// How cos θ is computed for a glass pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CosMode {
    /// `|n · d̂|` for the pixel-centre ray d̂: exact per pixel.
    Exact,
    /// The paper's way: cos θ at the nodes of an N×N mesh over each pane's bounding
    /// rectangle, linearly interpolated over the mesh triangles in screen space (Gouraud).
    Gouraud { mesh: u32 },
}

/// What a glass label stands for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlassLabel {
    /// Registration id (1…65535).
    pub id: u16,
    /// Plane index.
    pub plane: u16,
    /// Unit plane normal.
    pub normal: Vec3,
    /// Plane offset `d` of `n·X + d = 0`.
    pub d: f64,
    /// Index into [`RasterScene::panes`] (Gouraud only).
    pub pane: u32,
}

/// A pane's rectangle in its plane, over which the Gouraud mesh is laid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaneRect {
    /// A point of the plane (origin of the in-plane axes).
    pub origin: Vec3,
    /// Unit in-plane axes.
    pub u: Vec3,
    pub v: Vec3,
    pub u_min: f64,
    pub v_min: f64,
    pub u_len: f64,
    pub v_len: f64,
}

/// The geometry the rasteriser draws: one triangle soup with a label per triangle
/// (0: opaque, k ≥ 1: `glass[k − 1]`).
#[derive(Debug, Clone, Default)]
pub struct RasterScene {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub labels: Vec<u32>,
    pub glass: Vec<GlassLabel>,
    pub panes: Vec<PaneRect>,
}

/// Options of one rasterisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RasterOptions {
    pub cos: CosMode,
    /// K: coverage from K×K sub-pixel samples when K ≥ 2; 1 = pixel centres only.
    pub samples: u32,
}

/// The mask in memory, row-major with row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct RasterOutput {
    pub width: u32,
    pub height: u32,
    pub id: Vec<u16>,
    pub plane: Vec<u16>,
    /// cos θ in [0, 1]; 0 where there is no glass.
    pub cos_theta: Vec<f32>,
    /// Fraction of the K×K samples showing the pixel's glass (K ≥ 2 only).
    pub coverage: Option<Vec<f32>>,
    /// Triangles that reached the binning stage (in front of the camera and on screen).
    pub triangles_drawn: usize,
}

/// Largest K accepted for `--samples`.
pub const MAX_SAMPLES: u32 = 16;
/// Largest Gouraud mesh N accepted.
pub const MAX_MESH: u32 = 4096;

/// A triangle after clipping and projection, oriented counter-clockwise in image space.
#[derive(Debug, Clone, Copy)]
struct Setup {
    x: [f64; 3],
    y: [f64; 3],
    /// 1/depth at the corners.
    w: [f64; 3],
    inv_area2: f64,
    label: u32,
    /// Pixel bounding box, inclusive.
    i0: u32,
    i1: u32,
    j0: u32,
    j1: u32,
}

/// The edge function of edge a→b, `E(p) = (bx − ax)(py − ay) − (by − ay)(px − ax)`, set up
/// with the two endpoints in a canonical order (and the sign carried separately, which is
/// exact), so that the two triangles sharing an edge get bitwise opposite values at every
/// sample, plus the tie rule for samples exactly on the edge.
#[derive(Debug, Clone, Copy)]
struct CanonicalEdge {
    ax: f64,
    ay: f64,
    /// sign · (bx − ax) and sign · (by − ay) of the canonical endpoints.
    s_dx: f64,
    s_dy: f64,
    /// Whether a sample with E = 0 belongs to this triangle: exactly one of the two
    /// triangles sharing the edge owns it.
    owned: bool,
}

impl CanonicalEdge {
    #[inline(always)]
    fn new(ax: f64, ay: f64, bx: f64, by: f64) -> CanonicalEdge {
        let dy = by - ay;
        let owned = dy > 0.0 || (dy == 0.0 && bx - ax < 0.0);
        if (ax, ay) < (bx, by) {
            CanonicalEdge {
                ax,
                ay,
                s_dx: bx - ax,
                s_dy: by - ay,
                owned,
            }
        } else {
            CanonicalEdge {
                ax: bx,
                ay: by,
                s_dx: -(ax - bx),
                s_dy: -(ay - by),
                owned,
            }
        }
    }

    /// The row term `sign · (bx − ax)(py − ay)`.
    #[inline(always)]
    fn row(&self, py: f64) -> f64 {
        self.s_dx * (py - self.ay)
    }

    /// `E(px, py)` from the row term.
    #[inline(always)]
    fn eval(&self, row: f64, px: f64) -> f64 {
        row - self.s_dy * (px - self.ax)
    }
}

/// Clips a camera-space polygon against depth ≥ near (Sutherland–Hodgman).
fn clip_near(poly: &[Vec3], near: f64) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(4);
    for k in 0..poly.len() {
        let a = poly[k];
        let b = poly[(k + 1) % poly.len()];
        let (ia, ib) = (a[2] >= near, b[2] >= near);
        if ia {
            out.push(a);
        }
        if ia != ib {
            let t = (near - a[2]) / (b[2] - a[2]);
            let mut p = math::lerp(a, b, t);
            p[2] = near;
            out.push(p);
        }
    }
    out
}

fn make_setup(cam: &Camera, c: [Vec3; 3], label: u32) -> Option<Setup> {
    let p: [[f64; 2]; 3] = std::array::from_fn(|k| cam.project(c[k]));
    let mut x = [p[0][0], p[1][0], p[2][0]];
    let mut y = [p[0][1], p[1][1], p[2][1]];
    let mut w = [1.0 / c[0][2], 1.0 / c[1][2], 1.0 / c[2][2]];
    let area2 = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    if !(area2.is_finite() && area2 != 0.0) {
        return None; // edge-on or degenerate: covers no sample
    }
    if area2 < 0.0 {
        x.swap(1, 2);
        y.swap(1, 2);
        w.swap(1, 2);
    }
    let (wf, hf) = (cam.width as f64, cam.height as f64);
    let xmin = x[0].min(x[1]).min(x[2]);
    let xmax = x[0].max(x[1]).max(x[2]);
    let ymin = y[0].min(y[1]).min(y[2]);
    let ymax = y[0].max(y[1]).max(y[2]);
    if xmax < 0.0 || ymax < 0.0 || xmin > wf || ymin > hf {
        return None;
    }
    let clampi = |v: f64, hi: u32| -> u32 { v.floor().clamp(0.0, (hi - 1) as f64) as u32 };
    Some(Setup {
        x,
        y,
        w,
        inv_area2: 1.0 / area2.abs(),
        label,
        i0: clampi(xmin, cam.width),
        i1: clampi(xmax, cam.width),
        j0: clampi(ymin, cam.height),
        j1: clampi(ymax, cam.height),
    })
}

/// Sub-pixel sample offsets: the K×K grid `((a + ½)/K, (b + ½)/K)`, then the pixel centre
/// if the grid lacks it (even K). Returns (offsets, index of the centre sample).
fn sample_offsets(k: u32) -> (Vec<[f64; 2]>, usize) {
    let mut offs = Vec::with_capacity((k * k + 1) as usize);
    for b in 0..k {
        for a in 0..k {
            offs.push([(a as f64 + 0.5) / k as f64, (b as f64 + 0.5) / k as f64]);
        }
    }
    if k % 2 == 1 {
        let h = (k / 2) as usize;
        (offs, h * k as usize + h)
    } else {
        offs.push([0.5, 0.5]);
        let c = offs.len() - 1;
        (offs, c)
    }
}

/// Gouraud data of one pane for the current camera.
struct PaneMesh {
    rect: PaneRect,
    n: u32,
    /// cos θ at the (n+1)² nodes, row-major in (v, u).
    node_cos: Vec<f64>,
    /// Image position of each node, `None` when it is behind the near plane.
    node_xy: Vec<Option<[f64; 2]>>,
}

impl PaneMesh {
    fn new(rect: PaneRect, normal: Vec3, n: u32, cam: &Camera, near: f64) -> PaneMesh {
        let nn = (n + 1) as usize;
        let mut node_cos = Vec::with_capacity(nn * nn);
        let mut node_xy = Vec::with_capacity(nn * nn);
        for b in 0..nn {
            for a in 0..nn {
                let p = Self::node(&rect, n, a, b);
                let dir = math::normalize(math::sub(p, cam.origin)).unwrap_or(cam.forward);
                node_cos.push(math::dot(normal, dir).abs());
                let c = cam.to_camera(p);
                node_xy.push((c[2] >= near).then(|| cam.project(c)));
            }
        }
        PaneMesh {
            rect,
            n,
            node_cos,
            node_xy,
        }
    }

    fn node(rect: &PaneRect, n: u32, a: usize, b: usize) -> Vec3 {
        let su = rect.u_min + rect.u_len * a as f64 / n as f64;
        let sv = rect.v_min + rect.v_len * b as f64 / n as f64;
        math::add(
            rect.origin,
            math::add(math::scale(rect.u, su), math::scale(rect.v, sv)),
        )
    }

    /// Gouraud cos θ at image point (px, py) whose ray meets the plane at `hit`.
    fn cos_at(&self, hit: Vec3, px: f64, py: f64) -> f64 {
        let r = &self.rect;
        let n = self.n as f64;
        let rel = math::sub(hit, r.origin);
        let a = ((math::dot(rel, r.u) - r.u_min) / r.u_len * n).clamp(0.0, n);
        let b = ((math::dot(rel, r.v) - r.v_min) / r.v_len * n).clamp(0.0, n);
        let ci = (a.floor() as u32).min(self.n - 1) as usize;
        let cj = (b.floor() as u32).min(self.n - 1) as usize;
        let (fa, fb) = (a - ci as f64, b - cj as f64);
        let nn = self.n as usize + 1;
        let idx = |i: usize, j: usize| j * nn + i;
        // Each cell is split along its (1,0)–(0,1) diagonal.
        let (nodes, plane_w) = if fa + fb <= 1.0 {
            (
                [idx(ci, cj), idx(ci + 1, cj), idx(ci, cj + 1)],
                [1.0 - fa - fb, fa, fb],
            )
        } else {
            (
                [idx(ci + 1, cj + 1), idx(ci, cj + 1), idx(ci + 1, cj)],
                [fa + fb - 1.0, 1.0 - fa, 1.0 - fb],
            )
        };
        let xy: Option<Vec<[f64; 2]>> = nodes.iter().map(|&k| self.node_xy[k]).collect();
        let weights = match xy {
            Some(q) => {
                // Screen-space barycentrics: what 1990s Gouraud shading interpolated.
                let area2 = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                    - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
                if area2.abs() > 1e-300 {
                    let l1 = ((px - q[0][0]) * (q[2][1] - q[0][1])
                        - (q[2][0] - q[0][0]) * (py - q[0][1]))
                        / area2;
                    let l2 = ((q[1][0] - q[0][0]) * (py - q[0][1])
                        - (px - q[0][0]) * (q[1][1] - q[0][1]))
                        / area2;
                    [1.0 - l1 - l2, l1, l2]
                } else {
                    plane_w
                }
            }
            None => plane_w, // a node behind the camera: interpolate in the plane instead
        };
        let c: f64 = (0..3).map(|k| weights[k] * self.node_cos[nodes[k]]).sum();
        c.clamp(0.0, 1.0)
    }
}

/// Checks the rasteriser options.
pub fn check_options(opts: &RasterOptions) -> Result<(), SceneError> {
    if opts.samples == 0 || opts.samples > MAX_SAMPLES {
        return Err(SceneError::BadOption {
            message: format!(
                "--samples {} must be between 1 and {MAX_SAMPLES}",
                opts.samples
            ),
        });
    }
    if let CosMode::Gouraud { mesh } = opts.cos
        && (mesh == 0 || mesh > MAX_MESH)
    {
        return Err(SceneError::BadOption {
            message: format!("--mesh {mesh} must be between 1 and {MAX_MESH}"),
        });
    }
    Ok(())
}

/// Rows per band (the unit of parallel work).
const BAND_ROWS: u32 = 8;

/// Rasterises the labelled scene from `cam`.
pub fn rasterize(
    scene: &RasterScene,
    cam: &Camera,
    opts: &RasterOptions,
) -> Result<RasterOutput, SceneError> {
    check_options(opts)?;
    crate::camera::check_image_size(cam.width, cam.height)?;
    let (w, h) = (cam.width, cam.height);

    // 1. Vertices to camera space; the near plane scales with the scene's depth range.
    let cam_pos: Vec<Vec3> = scene
        .positions
        .par_iter()
        .map(|&p| cam.to_camera(p))
        .collect();
    let max_depth = cam_pos
        .par_iter()
        .map(|c| c[2].abs())
        .reduce(|| 0.0, f64::max);
    let near = (max_depth * 1e-7).max(1e-12);

    // 2. Near clipping, projection, orientation, bounding boxes.
    let setups: Vec<Setup> = scene
        .triangles
        .par_iter()
        .zip(scene.labels.par_iter())
        .flat_map_iter(|(tri, &label)| {
            let c = [
                cam_pos[tri[0] as usize],
                cam_pos[tri[1] as usize],
                cam_pos[tri[2] as usize],
            ];
            let mut out: [Option<Setup>; 2] = [None, None];
            if c.iter().all(|v| v[2] >= near) {
                out[0] = make_setup(cam, c, label);
            } else if c.iter().any(|v| v[2] >= near) {
                let poly = clip_near(&c, near);
                for k in 1..poly.len().saturating_sub(1).min(3) {
                    out[k - 1] = make_setup(cam, [poly[0], poly[k], poly[k + 1]], label);
                }
            }
            out.into_iter().flatten()
        })
        .collect();

    // 3. Bin by bands of rows (counting sort keeps each band's triangles in scene order, so
    //    ties in depth go to the earlier triangle whatever the thread schedule).
    let bands = h.div_ceil(BAND_ROWS) as usize;
    let mut counts = vec![0u32; bands + 1];
    for s in &setups {
        for b in (s.j0 / BAND_ROWS)..=(s.j1 / BAND_ROWS) {
            counts[b as usize + 1] += 1;
        }
    }
    for b in 0..bands {
        counts[b + 1] += counts[b];
    }
    let mut fill = counts.clone();
    let mut binned = vec![0u32; counts[bands] as usize];
    for (k, s) in setups.iter().enumerate() {
        for b in (s.j0 / BAND_ROWS)..=(s.j1 / BAND_ROWS) {
            let slot = &mut fill[b as usize];
            binned[*slot as usize] = k as u32;
            *slot += 1;
        }
    }

    // 4. Gouraud meshes for this camera.
    let meshes: Vec<PaneMesh> = match opts.cos {
        CosMode::Exact => Vec::new(),
        CosMode::Gouraud { mesh } => {
            let mut normals = vec![[0.0, 0.0, 1.0]; scene.panes.len()];
            for g in &scene.glass {
                if let Some(slot) = normals.get_mut(g.pane as usize) {
                    *slot = g.normal;
                }
            }
            scene
                .panes
                .par_iter()
                .zip(normals)
                .map(|(r, n)| PaneMesh::new(*r, n, mesh, cam, near))
                .collect()
        }
    };

    // 5. Rasterise and resolve each band.
    let (offsets, centre) = sample_offsets(opts.samples);
    let grid = (opts.samples * opts.samples) as usize;
    let ns = offsets.len();
    let npix = w as usize * h as usize;
    let mut id = vec![0u16; npix];
    let mut plane = vec![0u16; npix];
    let mut cos_theta = vec![0f32; npix];
    let mut coverage = if opts.samples >= 2 {
        Some(vec![0f32; npix])
    } else {
        None
    };
    let band_px = (BAND_ROWS * w) as usize;
    let cov_chunks: Vec<Option<&mut [f32]>> = match coverage.as_mut() {
        Some(c) => c.chunks_mut(band_px).map(Some).collect(),
        None => (0..bands).map(|_| None).collect(),
    };
    id.par_chunks_mut(band_px)
        .zip(plane.par_chunks_mut(band_px))
        .zip(cos_theta.par_chunks_mut(band_px))
        .zip(cov_chunks.into_par_iter())
        .enumerate()
        .for_each(|(band, (((id_b, plane_b), cos_b), cov_b))| {
            let row0 = band as u32 * BAND_ROWS;
            let rows = (h - row0).min(BAND_ROWS);
            let mut depth = vec![0f64; rows as usize * w as usize * ns];
            let mut winner = vec![0u32; rows as usize * w as usize * ns];
            for &k in &binned[counts[band] as usize..counts[band + 1] as usize] {
                let s = &setups[k as usize];
                let j0 = s.j0.max(row0);
                let j1 = s.j1.min(row0 + rows - 1);
                let [x0, x1, x2] = s.x;
                let [y0, y1, y2] = s.y;
                let edges = [
                    CanonicalEdge::new(x1, y1, x2, y2),
                    CanonicalEdge::new(x2, y2, x0, y0),
                    CanonicalEdge::new(x0, y0, x1, y1),
                ];
                for j in j0..=j1 {
                    let rowbase = (j - row0) as usize * w as usize;
                    for (si, off) in offsets.iter().enumerate() {
                        let py = j as f64 + off[1];
                        let rows_terms = [edges[0].row(py), edges[1].row(py), edges[2].row(py)];
                        // Conservative column span where all three edges can be ≥ 0.
                        let (mut lo, mut hi) = (s.i0 as f64, s.i1 as f64);
                        let mut empty = false;
                        for (e, &t) in edges.iter().zip(&rows_terms) {
                            if e.s_dy > 0.0 {
                                hi = hi.min((e.ax + t / e.s_dy - off[0]).floor() + 1.0);
                            } else if e.s_dy < 0.0 {
                                lo = lo.max((e.ax + t / e.s_dy - off[0]).ceil() - 1.0);
                            } else if t < 0.0 || (t == 0.0 && !e.owned) {
                                empty = true;
                            }
                        }
                        if empty || lo > hi || lo.is_nan() || hi.is_nan() {
                            continue;
                        }
                        for i in (lo as u32)..=(hi as u32) {
                            let px = i as f64 + off[0];
                            let e0 = edges[0].eval(rows_terms[0], px);
                            let e1 = edges[1].eval(rows_terms[1], px);
                            let e2 = edges[2].eval(rows_terms[2], px);
                            let inside = (e0 > 0.0 || (e0 == 0.0 && edges[0].owned))
                                && (e1 > 0.0 || (e1 == 0.0 && edges[1].owned))
                                && (e2 > 0.0 || (e2 == 0.0 && edges[2].owned));
                            if !inside {
                                continue;
                            }
                            let z = (e0 * s.w[0] + e1 * s.w[1] + e2 * s.w[2]) * s.inv_area2;
                            let slot = (rowbase + i as usize) * ns + si;
                            if z > depth[slot] {
                                depth[slot] = z;
                                winner[slot] = s.label;
                            }
                        }
                    }
                }
            }
            let mut cov_b = cov_b;
            for jr in 0..rows {
                let j = row0 + jr;
                for i in 0..w {
                    let p = (jr * w + i) as usize;
                    let samples = &winner[p * ns..(p + 1) * ns];
                    let key = |label: u32| -> Option<(u16, u16)> {
                        (label != 0)
                            .then(|| scene.glass[label as usize - 1])
                            .map(|g| (g.id, g.plane))
                    };
                    let mut chosen = samples[centre];
                    if chosen == 0 && ns > 1 {
                        // The centre misses glass: take the glass most of the grid samples show.
                        let mut best = (0usize, 0u32);
                        for a in 0..grid {
                            let l = samples[a];
                            if l == 0 {
                                continue;
                            }
                            let n = samples[..grid]
                                .iter()
                                .filter(|&&m| key(m) == key(l))
                                .count();
                            if n > best.0 {
                                best = (n, l);
                            }
                        }
                        chosen = best.1;
                    }
                    if chosen == 0 {
                        continue;
                    }
                    let g = scene.glass[chosen as usize - 1];
                    id_b[p] = g.id;
                    plane_b[p] = g.plane;
                    if let Some(cov) = cov_b.as_deref_mut() {
                        let n = samples[..grid]
                            .iter()
                            .filter(|&&m| key(m) == Some((g.id, g.plane)))
                            .count();
                        cov[p] = n as f32 / grid as f32;
                    }
                    let d = cam.pixel_ray(i, j);
                    let exact = math::dot(g.normal, d).abs();
                    let c = match opts.cos {
                        CosMode::Exact => exact,
                        CosMode::Gouraud { .. } => {
                            let denom = math::dot(g.normal, d);
                            if denom.abs() < 1e-15 {
                                0.0
                            } else {
                                let t = -(math::dot(g.normal, cam.origin) + g.d) / denom;
                                let hit = math::add(cam.origin, math::scale(d, t));
                                match meshes.get(g.pane as usize) {
                                    Some(m) => m.cos_at(hit, i as f64 + 0.5, j as f64 + 0.5),
                                    None => exact, // a scene built without panes
                                }
                            }
                        }
                    };
                    cos_b[p] = c.clamp(0.0, 1.0) as f32;
                }
            }
        });
    Ok(RasterOutput {
        width: w,
        height: h,
        id,
        plane,
        cos_theta,
        coverage,
        triangles_drawn: setups.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic pseudo-random numbers in [0, 1).
    fn lcg(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn shared_edges_get_exactly_opposite_values_and_one_owner() {
        let mut s = 12345u64;
        for k in 0..20_000 {
            let v: Vec<f64> = (0..7).map(|_| lcg(&mut s) * 2000.0 - 100.0).collect();
            let (ax, ay, bx, by) = (v[0], v[1], v[2], v[3]);
            // Half of the samples lie (up to rounding) on the edge itself.
            let t = (v[4] + 100.0) / 2000.0;
            let (px, py) = if k % 2 == 0 {
                (ax + t * (bx - ax), ay + t * (by - ay))
            } else {
                (v[5], v[6])
            };
            let e = CanonicalEdge::new(ax, ay, bx, by);
            let f = CanonicalEdge::new(bx, by, ax, ay);
            let (ve, vf) = (e.eval(e.row(py), px), f.eval(f.row(py), px));
            assert!(
                ve == -vf,
                "{ve} vs {vf}: edge ({ax}, {ay})→({bx}, {by}) at ({px}, {py})"
            );
            assert!(e.owned != f.owned);
            // Hence a sample is inside exactly one of the two half-planes (ties by ownership).
            let inside_e = ve > 0.0 || (ve == 0.0 && e.owned);
            let inside_f = vf > 0.0 || (vf == 0.0 && f.owned);
            assert!(inside_e != inside_f);
        }
        // Horizontal and vertical edges too.
        for (ax, ay, bx, by) in [(0.0, 1.0, 5.0, 1.0), (2.0, 0.0, 2.0, 9.0)] {
            let e = CanonicalEdge::new(ax, ay, bx, by);
            let f = CanonicalEdge::new(bx, by, ax, ay);
            assert!(e.owned != f.owned);
            let on = (ax + bx) / 2.0;
            assert_eq!(e.eval(e.row(1.0), on), 0.0);
        }
    }

    #[test]
    fn sample_grids_hold_the_centre() {
        for k in 1..=6 {
            let (offs, c) = sample_offsets(k);
            assert_eq!(offs[c], [0.5, 0.5]);
            assert_eq!(offs.len() as u32, k * k + (1 - k % 2));
        }
    }
}
