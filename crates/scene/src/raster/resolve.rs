//! From the nearest labels at each sample to the mask's pixels: which glass a pixel shows,
//! its coverage, and its cos θ (exact or Gouraud).

use super::gouraud::PaneMesh;
use super::samples::SampleGrid;
use super::{CosMode, GlassLabel, RasterScene};
use crate::camera::Camera;
use crate::math;

/// One band's share of the output planes, `rows × width` pixels each.
pub(super) struct BandPixels<'a> {
    pub(super) id: &'a mut [u16],
    pub(super) plane: &'a mut [u16],
    pub(super) cos_theta: &'a mut [f32],
    pub(super) coverage: Option<&'a mut [f32]>,
}

/// What resolving needs besides the labels: the glass of each label, the camera and the cos θ
/// mode with its meshes.
pub(super) struct Resolver<'a> {
    pub(super) scene: &'a RasterScene,
    pub(super) cam: &'a Camera,
    pub(super) cos: CosMode,
    pub(super) meshes: &'a [PaneMesh],
    pub(super) samples: &'a SampleGrid,
}

impl Resolver<'_> {
    /// Writes the pixels of rows `row0..row0 + rows` from their samples' labels.
    pub(super) fn resolve_band(&self, row0: u32, rows: u32, winner: &[u32], out: BandPixels<'_>) {
        let w = self.cam.width;
        let ns = self.samples.len();
        let BandPixels {
            id,
            plane,
            cos_theta,
            mut coverage,
        } = out;
        for jr in 0..rows {
            let j = row0 + jr;
            for i in 0..w {
                let p = (jr * w + i) as usize;
                let samples = &winner[p * ns..(p + 1) * ns];
                let chosen = self.chosen_label(samples);
                if chosen == 0 {
                    continue;
                }
                let g = self.scene.glass[chosen as usize - 1];
                id[p] = g.id;
                plane[p] = g.plane;
                if let Some(cov) = coverage.as_deref_mut() {
                    cov[p] = self.coverage(samples, &g);
                }
                cos_theta[p] = self.cos_theta(&g, i, j).clamp(0.0, 1.0) as f32;
            }
        }
    }

    /// The (id, plane) a label shows; `None` for opaque (label 0).
    fn key(&self, label: u32) -> Option<(u16, u16)> {
        (label != 0)
            .then(|| self.scene.glass[label as usize - 1])
            .map(|g| (g.id, g.plane))
    }

    /// The label of the pixel: the centre sample's, or when the centre misses glass, the glass
    /// most of the grid samples show (0: no glass).
    fn chosen_label(&self, samples: &[u32]) -> u32 {
        let grid = self.samples.grid;
        let chosen = samples[self.samples.centre];
        if chosen != 0 || samples.len() <= 1 {
            return chosen;
        }
        let mut best = (0usize, 0u32);
        for &l in &samples[..grid] {
            if l == 0 {
                continue;
            }
            let n = samples[..grid]
                .iter()
                .filter(|&&m| self.key(m) == self.key(l))
                .count();
            if n > best.0 {
                best = (n, l);
            }
        }
        best.1
    }

    /// Fraction of the grid samples showing glass `g` (same id and plane).
    fn coverage(&self, samples: &[u32], g: &GlassLabel) -> f32 {
        let grid = self.samples.grid;
        let n = samples[..grid]
            .iter()
            .filter(|&&m| self.key(m) == Some((g.id, g.plane)))
            .count();
        n as f32 / grid as f32
    }

    /// cos θ of pixel (i, j) on glass `g`: `|n · d̂|` of the pixel-centre ray, or Gouraud.
    fn cos_theta(&self, g: &GlassLabel, i: u32, j: u32) -> f64 {
        let cam = self.cam;
        let d = cam.pixel_ray(i, j);
        let exact = math::dot(g.normal, d).abs();
        match self.cos {
            CosMode::Exact => exact,
            CosMode::Gouraud { .. } => {
                let denom = math::dot(g.normal, d);
                if denom.abs() < 1e-15 {
                    0.0
                } else {
                    let t = -(math::dot(g.normal, cam.origin) + g.d) / denom;
                    let hit = math::add(cam.origin, math::scale(d, t));
                    match self.meshes.get(g.pane as usize) {
                        Some(m) => m.cos_at(hit, i as f64 + 0.5, j as f64 + 0.5),
                        None => exact, // a scene built without panes
                    }
                }
            }
        }
    }
}
