//! The z-buffer of one band of rows: every triangle overlapping the band is drawn at every
//! sample, keeping the nearest (largest `1/z`, linear in screen space, so depth is
//! perspective-correct); ties in depth go to the triangle earlier in the scene.
//!
//! Every band draws its triangles nearest first ([`DrawOrder`], sorted once for the scene).
//! Under heavy overdraw (large triangles whose area covers the band several times over, e.g.
//! many large overlapping panes) it skips, per tile of columns, those that lie wholly behind
//! what the tile already holds: a triangle's largest
//! possible `1/z` ([`z_bound`], with the rounding of the edge functions accounted for)
//! below every sample of a tile cannot win a sample there. Skipping only what cannot win, with
//! the tie going to the earlier triangle whatever the drawing order, gives the same labels as
//! drawing every triangle in scene order.

use super::bins::{BandCover, BandTriangles};
use super::edge::CanonicalEdge;
use super::setup::{PixelBox, Setup};

/// Columns per tile of the occlusion test.
const TILE: usize = 32;

/// Overdraw (the triangles' area over the band's area) from which a band of large
/// triangles draws nearest first and skips hidden ones; below it sorting would cost more than
/// it saves.
const CULL_OVERDRAW: f64 = 3.0;

/// No triangle (in the per-sample winner buffer).
const NONE: u32 = u32::MAX;

/// The triangles of the scene as the bands see them: each triangle's box and area and the
/// largest `1/z` it can reach ([`z_bound`]), computed once (not once per band), in the order
/// the bands draw them: under heavy overdraw nearest first by that bound, scene order among
/// equals (otherwise scene order). A band reads
/// the entries of its triangles in that order, one after the other: no band sorts, and
/// skipping a hidden triangle never fetches its setup.
pub(super) struct DrawOrder {
    /// Entry `p` is the `p`-th triangle drawn.
    pub(super) entries: Vec<Candidate>,
}

/// A triangle as the skipping test sees it.
pub(super) struct Candidate {
    /// Its index in the setups.
    pub(super) k: u32,
    /// Its box.
    pub(super) bbox: PixelBox,
    /// Its area, pixels.
    pub(super) area: f64,
    /// Its largest possible `1/z` ([`z_bound`]).
    pub(super) z_bound: f64,
}

impl DrawOrder {
    /// The draw order of `setups` (computed in parallel) on an image of `pixels` pixels. A
    /// scene drawn less than [`CULL_OVERDRAW`] times over keeps its own order (sorting would
    /// cost more than it saves; any order gives the same labels).
    pub(super) fn new(setups: &[Setup], pixels: f64) -> DrawOrder {
        use rayon::prelude::*;
        let mut entries: Vec<Candidate> = setups
            .par_iter()
            .enumerate()
            .map(|(k, s)| Candidate {
                k: k as u32,
                bbox: s.bbox,
                area: 0.5 / s.inv_area2,
                z_bound: z_bound(s),
            })
            .collect();
        let area: f64 = entries.par_iter().map(|c| c.area).sum();
        if area > CULL_OVERDRAW * pixels {
            // Stable: scene order among equal bounds.
            entries.par_sort_by(|a, b| b.z_bound.total_cmp(&a.z_bound));
        }
        DrawOrder { entries }
    }
}

/// The label of the nearest triangle at every sample of rows `row0..row0 + rows` (0 where
/// none is), `samples` per pixel, pixel-major. `band` holds the band's triangles as positions
/// in `order`, increasing, and how much of the band they cover. Ties in depth go to the triangle earlier in the scene, whatever
/// the order they are drawn in.
pub(super) fn nearest_labels(
    setups: &[Setup],
    order: &DrawOrder,
    band: BandTriangles<'_>,
    row0: u32,
    rows: u32,
    width: u32,
    offsets: &[[f64; 2]],
) -> Vec<u32> {
    let ns = offsets.len();
    let w = width as usize;
    let band_px = rows as usize * w;
    let mut depth = vec![0f64; band_px * ns];
    // The setup index of the nearest triangle so far, per sample.
    let mut winner = vec![NONE; band_px * ns];
    let row1 = row0 + rows - 1;
    // How many times over the band is drawn (`cover.area`), and by how large boxes.
    let BandTriangles { drawn, cover } = band;
    let BandCover { area, boxes } = cover;
    // Skipping needs tiles' bounds, which only triangles whose box covers a good part of a
    // tile recompute (see `Tiles::open_columns`): small triangles alone would only pay for it.
    // Measured by their boxes, not their areas: a pane made of long thin triangles (a round
    // window as a fan) covers tiles as a large one does.
    let large = boxes * 4.0 >= drawn.len() as f64 * (TILE as f64 * f64::from(rows));
    let mut tiles =
        (large && area > CULL_OVERDRAW * band_px as f64).then(|| Tiles::new(w, rows as usize));
    for &p in drawn {
        let c = &order.entries[p as usize];
        let k = c.k;
        let (j0, j1) = (c.bbox.rows.0.max(row0), c.bbox.rows.1.min(row1));
        let (c0, c1) = match tiles.as_mut() {
            Some(t) => {
                match t.open_columns(
                    c.bbox.columns,
                    c.z_bound,
                    (j1 - j0 + 1) as usize,
                    &depth,
                    ns,
                ) {
                    Some(c) => c,
                    None => continue,
                }
            }
            None => c.bbox.columns,
        };
        let s = &setups[k as usize];
        let edges = s.edges();
        for j in j0..=j1 {
            let rowbase = (j - row0) as usize * w;
            for (si, off) in offsets.iter().enumerate() {
                let py = j as f64 + off[1];
                let rows_terms = [edges[0].row(py), edges[1].row(py), edges[2].row(py)];
                let Some((lo, hi)) = column_span(s, &edges, &rows_terms, off[0]) else {
                    continue;
                };
                let (lo, hi) = (lo.max(c0), hi.min(c1));
                for i in lo..=hi {
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
                    // Drawn nearest first, not in scene order: a tie goes to the earlier
                    // triangle by its index.
                    let nearer = z > depth[slot] || (z == depth[slot] && k < winner[slot]);
                    if nearer {
                        depth[slot] = z;
                        winner[slot] = k;
                    }
                }
            }
        }
    }
    winner
        .into_iter()
        .map(|k| setups.get(k as usize).map_or(0, |s| s.label))
        .collect()
}

/// Per tile of [`TILE`] columns of the band: a lower bound of the depth (`1/z`) of its
/// samples, exact when last computed and raised only by drawing (depths only grow).
struct Tiles {
    width: usize,
    rows: usize,
    /// The smallest `1/z` of the tile's samples when last computed (0: a sample without any
    /// triangle).
    lowest: Vec<f64>,
    /// Drawn into since `lowest` was computed (so it may be higher now).
    drawn: Vec<bool>,
}

impl Tiles {
    fn new(width: usize, rows: usize) -> Tiles {
        let n = width.div_ceil(TILE);
        Tiles {
            width,
            rows,
            lowest: vec![0.0; n],
            drawn: vec![false; n],
        }
    }

    /// The columns of a triangle's box (`columns`, `rows` of the band high) in tiles where it may win a sample
    /// (from the first such tile to the last), marked as drawn into; `None` when it is behind
    /// every sample of every tile it overlaps.
    fn open_columns(
        &mut self,
        (i0, i1): (u32, u32),
        z_bound: f64,
        rows: usize,
        depth: &[f64],
        ns: usize,
    ) -> Option<(u32, u32)> {
        let (t0, t1) = (i0 as usize / TILE, i1 as usize / TILE);
        let mut open = (t0..=t1).filter(|&t| {
            // Recomputing a tile's bound costs as much as drawing a quarter of it: only worth
            // it for a triangle that covers that much of the tile.
            let columns = (i1 as usize).min((t + 1) * TILE - 1) + 1 - (i0 as usize).max(t * TILE);
            let worth = 4 * columns * rows >= TILE * self.rows;
            !self.hides(t, z_bound, worth, depth, ns)
        });
        let first = open.next()?;
        let last = open.last().unwrap_or(first);
        for d in &mut self.drawn[first..=last] {
            *d = true;
        }
        let c0 = (first * TILE) as u32;
        let c1 = ((last + 1) * TILE).min(self.width) as u32 - 1;
        Some((i0.max(c0), i1.min(c1)))
    }

    /// Whether every sample of tile `t` is nearer than `z_bound` (strictly: a tie could win),
    /// by the bound as last computed, or recomputed first if `recompute` and it was drawn into
    /// since.
    fn hides(&mut self, t: usize, z_bound: f64, recompute: bool, depth: &[f64], ns: usize) -> bool {
        if self.lowest[t] > z_bound {
            return true;
        }
        if !(self.drawn[t] && recompute) {
            return false;
        }
        let (c0, c1) = (t * TILE, ((t + 1) * TILE).min(self.width));
        let mut lowest = f64::INFINITY;
        for r in 0..self.rows {
            let row = &depth[(r * self.width + c0) * ns..(r * self.width + c1) * ns];
            lowest = row.iter().copied().fold(lowest, f64::min);
        }
        self.lowest[t] = lowest;
        self.drawn[t] = false;
        lowest > z_bound
    }
}

/// A conservative span of columns where all three edges can be ≥ 0 on one sample row
/// (`None` when it is empty); the exact test is done per sample.
#[inline(always)]
fn column_span(
    s: &Setup,
    edges: &[CanonicalEdge; 3],
    rows_terms: &[f64; 3],
    off_x: f64,
) -> Option<(u32, u32)> {
    let (mut lo, mut hi) = (s.bbox.columns.0 as f64, s.bbox.columns.1 as f64);
    for (e, &t) in edges.iter().zip(rows_terms) {
        if e.s_dy > 0.0 {
            hi = hi.min((e.ax + t / e.s_dy - off_x).floor() + 1.0);
        } else if e.s_dy < 0.0 {
            lo = lo.max((e.ax + t / e.s_dy - off_x).ceil() - 1.0);
        } else if t < 0.0 || (t == 0.0 && !e.owned) {
            return None;
        }
    }
    if lo > hi || lo.is_nan() || hi.is_nan() {
        return None;
    }
    Some((lo as u32, hi as u32))
}

/// An upper bound of the 1/depth that the depth test computes at any sample inside `s`: the
/// largest corner 1/depth, times the factor by which rounding can make the three edge
/// functions' sum exceed twice the area at the samples it is evaluated at, the box
/// `[i0, i1 + 1) × [j0, j1 + 1)` (one pixel more either way, to be safe). Each edge function is
/// exact up to a few ulps of its terms' magnitudes; the constant is generous. Infinite when no
/// bound is finite.
fn z_bound(s: &Setup) -> f64 {
    let eps = 16.0 * f64::EPSILON;
    let (x, y) = (&s.x, &s.y);
    let PixelBox {
        columns: (i0, i1),
        rows: (j0, j1),
    } = s.bbox;
    let columns = (f64::from(i0) - 1.0, f64::from(i1) + 2.0);
    let rows = (f64::from(j0) - 1.0, f64::from(j1) + 2.0);
    let far = |v: f64, (lo, hi): (f64, f64)| (lo - v).abs().max((hi - v).abs());
    let mut terms = 0.0;
    for (a, b) in [(1, 2), (2, 0), (0, 1)] {
        let (dx, dy) = ((x[b] - x[a]).abs(), (y[b] - y[a]).abs());
        let far_x = far(x[a], columns).max(far(x[b], columns));
        let far_y = far(y[a], rows).max(far(y[b], rows));
        terms += dx * far_y + dy * far_x;
    }
    let corner =
        (x[1] - x[0]).abs() * (y[2] - y[0]).abs() + (x[2] - x[0]).abs() * (y[1] - y[0]).abs();
    let w_max = s.w[0].max(s.w[1]).max(s.w[2]);
    // inv_area2 is 1 / |twice the area| as the depth test uses it.
    let bound = w_max * (1.0 + eps * (terms + corner) * s.inv_area2) * (1.0 + eps);
    if bound.is_finite() {
        bound
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::raster::tests::lcg;

    /// A projected triangle as `setup` makes it (counter-clockwise, box clamped to the image).
    fn setup(mut x: [f64; 3], mut y: [f64; 3], mut w: [f64; 3], label: u32, size: u32) -> Setup {
        let area2 = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
        if area2 < 0.0 {
            x.swap(1, 2);
            y.swap(1, 2);
            w.swap(1, 2);
        }
        Setup {
            x,
            y,
            w,
            inv_area2: 1.0 / area2.abs(),
            label,
            bbox: PixelBox::of_triangle(&x, &y, size, size),
        }
    }

    /// The z-buffer as it was before skipping: every triangle at every sample, in scene order.
    fn reference(setups: &[Setup], rows: u32, width: u32, offsets: &[[f64; 2]]) -> Vec<u32> {
        let ns = offsets.len();
        let mut depth = vec![0f64; (rows * width) as usize * ns];
        let mut winner = vec![0u32; depth.len()];
        for s in setups {
            let edges = s.edges();
            let PixelBox {
                columns: (i0, i1),
                rows: (j0, j1),
            } = s.bbox;
            for j in j0..=j1.min(rows - 1) {
                for i in i0..=i1 {
                    for (si, off) in offsets.iter().enumerate() {
                        let (px, py) = (i as f64 + off[0], j as f64 + off[1]);
                        let e: Vec<f64> = edges.iter().map(|e| e.eval(e.row(py), px)).collect();
                        let inside = (0..3).all(|k| e[k] > 0.0 || (e[k] == 0.0 && edges[k].owned));
                        let z = (e[0] * s.w[0] + e[1] * s.w[1] + e[2] * s.w[2]) * s.inv_area2;
                        let slot = ((j * width + i) as usize) * ns + si;
                        if inside && z > depth[slot] {
                            depth[slot] = z;
                            winner[slot] = s.label;
                        }
                    }
                }
            }
        }
        winner
    }

    #[test]
    fn skipping_hidden_triangles_gives_the_labels_of_drawing_them_all_in_scene_order() {
        let (width, rows) = (96u32, 8u32);
        let mut state = 99u64;
        for (count, size, samples) in [(400, 60.0, 1), (300, 90.0, 1), (200, 40.0, 5)] {
            let offsets: Vec<[f64; 2]> = if samples == 1 {
                vec![[0.5, 0.5]]
            } else {
                (0..samples)
                    .map(|k| [(k as f64 + 0.5) / samples as f64, 1.0 / 3.0])
                    .collect()
            };
            let mut setups = Vec::new();
            for k in 0..count {
                let (cx, cy) = (lcg(&mut state) * 96.0, lcg(&mut state) * 8.0);
                let x = [0, 1, 2].map(|_| cx + (lcg(&mut state) - 0.5) * size);
                let y = [0, 1, 2].map(|_| cy + (lcg(&mut state) - 0.5) * size * 0.3);
                // Few depth levels, so that many samples tie; some triangles repeat exactly.
                let w = [0, 1, 2].map(|_| 0.1 + (lcg(&mut state) * 4.0).floor() * 0.1);
                let s = setup(x, y, w, k + 1, width);
                if s.bbox.rows.0 >= rows {
                    continue;
                }
                if k % 7 == 0 {
                    setups.push(Setup {
                        label: 10_000 + k,
                        ..s
                    });
                }
                setups.push(s);
            }
            let want = reference(&setups, rows, width, &offsets);
            // Drawn nearest first (heavy overdraw), and in scene order.
            for pixels in [0.0, f64::INFINITY] {
                let order = DrawOrder::new(&setups, pixels);
                let bands = width.div_ceil(rows) as usize;
                let bins = super::super::bins::BandBins::new(&order, bands, rows);
                let got = nearest_labels(&setups, &order, bins.band(0), 0, rows, width, &offsets);
                assert_eq!(got, want, "{count} triangles of size {size}, {pixels}");
            }
            // The heavy overdraw did take the skipping path.
            let area: f64 = setups.iter().map(|s| 0.5 / s.inv_area2).sum();
            assert!(area > CULL_OVERDRAW * f64::from(rows * width), "{area}");
        }
    }
}
