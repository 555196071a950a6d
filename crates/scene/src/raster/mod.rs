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
//! One step per file: `setup` (camera space, clipping, projection), `bins` (bands of rows),
//! `gouraud` (the paper's mesh), `depth` (the z-buffer of a band), `resolve` (labels to pixels).

mod bins;
mod depth;
mod edge;
mod gouraud;
mod resolve;
mod samples;
mod setup;

use rayon::prelude::*;

use crate::camera::Camera;
use crate::error::SceneError;
use crate::math::Vec3;
use bins::BandBins;
use resolve::{BandPixels, Resolver};
use samples::SampleGrid;

/// How cos θ is computed for a glass pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CosMode {
    /// `|n · d̂|` for the pixel-centre ray d̂: exact per pixel.
    Exact,
    /// The paper's way: cos θ at the nodes of an N×N mesh over each pane's bounding
    /// rectangle, linearly interpolated over the mesh triangles in screen space (Gouraud).
    Gouraud {
        /// N, the cells per side of each pane.
        mesh: u32,
    },
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
    /// The second in-plane axis.
    pub v: Vec3,
    /// The pane's smallest u.
    pub u_min: f64,
    /// The pane's smallest v.
    pub v_min: f64,
    /// Its extent along u.
    pub u_len: f64,
    /// Its extent along v.
    pub v_len: f64,
}

/// The geometry the rasteriser draws: one triangle soup with a label per triangle
/// (0: opaque, k ≥ 1: `glass[k − 1]`).
#[derive(Debug, Clone, Default)]
pub struct RasterScene {
    /// Every vertex.
    pub positions: Vec<Vec3>,
    /// Every triangle (indices into `positions`).
    pub triangles: Vec<[u32; 3]>,
    /// Each triangle's label: 0 opaque, k the glass `glass[k - 1]`.
    pub labels: Vec<u32>,
    /// The glass labels.
    pub glass: Vec<GlassLabel>,
    /// The panes (Gouraud mode).
    pub panes: Vec<PaneRect>,
}

/// Options of one rasterisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RasterOptions {
    /// How cos θ is computed.
    pub cos: CosMode,
    /// K: coverage from K×K sub-pixel samples when K ≥ 2; 1 = pixel centres only.
    pub samples: u32,
}

/// The mask in memory, row-major with row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct RasterOutput {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Glass id per pixel (0: none).
    pub id: Vec<u16>,
    /// Plane per pixel.
    pub plane: Vec<u16>,
    /// cos θ in [0, 1]; 0 where there is no glass.
    pub cos_theta: Vec<f32>,
    /// Fraction of the K×K samples showing the pixel's glass (K ≥ 2 only).
    pub coverage: Option<Vec<f32>>,
    /// Triangles that reached the binning stage (in front of the camera and on screen).
    pub triangles_drawn: usize,
}

/// Largest K of K×K coverage samples accepted.
pub const MAX_SAMPLES: u32 = 16;
/// Largest Gouraud mesh N accepted.
pub const MAX_MESH: u32 = 4096;

/// Checks the rasteriser options.
pub fn check_options(opts: &RasterOptions) -> Result<(), SceneError> {
    if opts.samples == 0 || opts.samples > MAX_SAMPLES {
        return Err(SceneError::SamplesOutOfRange {
            samples: opts.samples,
            max: MAX_SAMPLES,
        });
    }
    if let CosMode::Gouraud { mesh } = opts.cos
        && (mesh == 0 || mesh > MAX_MESH)
    {
        return Err(SceneError::MeshOutOfRange {
            mesh,
            max: MAX_MESH,
        });
    }
    Ok(())
}

/// Rows per band (the unit of parallel work).
const BAND_ROWS: u32 = 32;

/// Rasterises the labelled scene from `cam`: vertices to camera space, triangle setup, binning
/// into bands, Gouraud meshes, then per band (in parallel) the z-buffer and the pixels.
pub fn rasterize(
    scene: &RasterScene,
    cam: &Camera,
    opts: &RasterOptions,
) -> Result<RasterOutput, SceneError> {
    check_options(opts)?;
    crate::camera::check_image_size(cam.width, cam.height)?;
    let (w, h) = (cam.width, cam.height);
    let (cam_pos, near) = setup::camera_space(scene, cam);
    let setups = setup::triangle_setups(scene, cam, &cam_pos, near);
    let bands = h.div_ceil(BAND_ROWS) as usize;
    let order = depth::DrawOrder::new(&setups, f64::from(w) * f64::from(h));
    let bins = BandBins::new(&order, bands, BAND_ROWS);
    let meshes = gouraud::pane_meshes(scene, cam, near, opts.cos);
    let samples = SampleGrid::new(opts.samples);
    let resolver = Resolver {
        scene,
        cam,
        cos: opts.cos,
        meshes: &meshes,
        samples: &samples,
    };

    let npix = w as usize * h as usize;
    let mut id = vec![0u16; npix];
    let mut plane = vec![0u16; npix];
    let mut cos_theta = vec![0f32; npix];
    let mut coverage = (opts.samples >= 2).then(|| vec![0f32; npix]);
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
        .for_each(|(band, (((id, plane), cos_theta), coverage))| {
            let row0 = band as u32 * BAND_ROWS;
            let rows = (h - row0).min(BAND_ROWS);
            let winner = depth::nearest_labels(
                &setups,
                &order,
                bins.band(band),
                row0,
                rows,
                w,
                &samples.offsets,
            );
            let out = BandPixels {
                id,
                plane,
                cos_theta,
                coverage,
            };
            resolver.resolve_band(row0, rows, &winner, out);
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
pub(crate) mod tests {
    /// Deterministic pseudo-random numbers in [0, 1).
    pub(crate) fn lcg(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }
}
