//! The paper's cos θ (method.md section 6): at the nodes of an N×N mesh over each pane's
//! rectangle, Gouraud-interpolated in screen space.

use rayon::prelude::*;

use super::{CosMode, PaneRect, RasterScene};
use crate::camera::Camera;
use crate::math::{self, Vec3};

/// The Gouraud meshes of every pane for this camera (none for exact cos θ).
pub(super) fn pane_meshes(
    scene: &RasterScene,
    cam: &Camera,
    near: f64,
    cos: CosMode,
) -> Vec<PaneMesh> {
    match cos {
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
    }
}

/// Gouraud data of one pane for the current camera.
pub(super) struct PaneMesh {
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
    pub(super) fn cos_at(&self, hit: Vec3, px: f64, py: f64) -> f64 {
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
