//! The z-buffer of one band of rows: every triangle overlapping the band is drawn at every
//! sample, keeping the nearest (largest `1/z`, linear in screen space, so depth is
//! perspective-correct).

use super::edge::CanonicalEdge;
use super::setup::Setup;

/// The label of the nearest triangle at every sample of rows `row0..row0 + rows` (0 where
/// none is), `samples` per pixel, pixel-major. `triangles` index `setups`, in scene order.
pub(super) fn nearest_labels(
    setups: &[Setup],
    triangles: &[u32],
    row0: u32,
    rows: u32,
    width: u32,
    offsets: &[[f64; 2]],
) -> Vec<u32> {
    let ns = offsets.len();
    let mut depth = vec![0f64; rows as usize * width as usize * ns];
    let mut winner = vec![0u32; rows as usize * width as usize * ns];
    for &k in triangles {
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
            let rowbase = (j - row0) as usize * width as usize;
            for (si, off) in offsets.iter().enumerate() {
                let py = j as f64 + off[1];
                let rows_terms = [edges[0].row(py), edges[1].row(py), edges[2].row(py)];
                let Some((lo, hi)) = column_span(s, &edges, &rows_terms, off[0]) else {
                    continue;
                };
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
                    if z > depth[slot] {
                        depth[slot] = z;
                        winner[slot] = s.label;
                    }
                }
            }
        }
    }
    winner
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
    let (mut lo, mut hi) = (s.i0 as f64, s.i1 as f64);
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
