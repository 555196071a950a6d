//! Triangle setup: vertices to camera space, clipping at the near plane, projection,
//! orientation and pixel bounding boxes.

use rayon::prelude::*;

use super::RasterScene;
use super::edge::CanonicalEdge;
use crate::camera::Camera;
use crate::math::{self, Vec3};

/// The scene's vertices in camera space and the near-plane depth, which scales with the
/// scene's depth range.
pub(super) fn camera_space(scene: &RasterScene, cam: &Camera) -> (Vec<Vec3>, f64) {
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
    (cam_pos, near)
}

/// Every triangle clipped at `near` (into up to two), projected and oriented, in scene order.
pub(super) fn triangle_setups(
    scene: &RasterScene,
    cam: &Camera,
    cam_pos: &[Vec3],
    near: f64,
) -> Vec<Setup> {
    scene
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
        .collect()
}

/// A triangle after clipping and projection, oriented counter-clockwise in image space.
#[derive(Debug, Clone, Copy)]
pub(super) struct Setup {
    pub(super) x: [f64; 3],
    pub(super) y: [f64; 3],
    /// 1/depth at the corners.
    pub(super) w: [f64; 3],
    pub(super) inv_area2: f64,
    pub(super) label: u32,
    /// Pixel bounding box.
    pub(super) bbox: PixelBox,
}

/// A box of whole pixels, inclusive: columns `columns.0..=columns.1`, rows `rows.0..=rows.1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct PixelBox {
    pub(super) columns: (u32, u32),
    pub(super) rows: (u32, u32),
}

impl PixelBox {
    /// The pixels of a `width` × `height` image that the box of a triangle with corners
    /// (`x`, `y`) touches (clamped to the image): for tests that build a [`Setup`] by hand.
    #[cfg(test)]
    pub(super) fn of_triangle(x: &[f64; 3], y: &[f64; 3], width: u32, height: u32) -> PixelBox {
        PixelBox::of_bounds(
            (x[0].min(x[1]).min(x[2]), x[0].max(x[1]).max(x[2])),
            (y[0].min(y[1]).min(y[2]), y[0].max(y[1]).max(y[2])),
            width,
            height,
        )
    }

    /// The pixels of a `width` × `height` image that the box from `x.0` to `x.1` across and
    /// `y.0` to `y.1` down (pixel coordinates) touches, clamped to the image.
    fn of_bounds(x: (f64, f64), y: (f64, f64), width: u32, height: u32) -> PixelBox {
        let clampi = |v: f64, hi: u32| -> u32 { v.floor().clamp(0.0, (hi - 1) as f64) as u32 };
        PixelBox {
            columns: (clampi(x.0, width), clampi(x.1, width)),
            rows: (clampi(y.0, height), clampi(y.1, height)),
        }
    }
}

impl Setup {
    /// The triangle's three edges, each opposite its corner (edge k from corner k + 1 to
    /// k + 2), as the sample test evaluates them.
    #[inline(always)]
    pub(super) fn edges(&self) -> [CanonicalEdge; 3] {
        let [x0, x1, x2] = self.x;
        let [y0, y1, y2] = self.y;
        [
            CanonicalEdge::new(x1, y1, x2, y2),
            CanonicalEdge::new(x2, y2, x0, y0),
            CanonicalEdge::new(x0, y0, x1, y1),
        ]
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

/// Projects a camera-space triangle; `None` when it is degenerate or off screen.
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
    Some(Setup {
        x,
        y,
        w,
        inv_area2: 1.0 / area2.abs(),
        label,
        bbox: PixelBox::of_bounds((xmin, xmax), (ymin, ymax), cam.width, cam.height),
    })
}
