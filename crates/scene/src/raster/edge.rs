//! Edge functions with a tie rule: two triangles sharing an edge cover every sample on it
//! exactly once (no cracks in a pane made of several triangles, no sample drawn twice).

/// The edge function of edge a→b, `E(p) = (bx − ax)(py − ay) − (by − ay)(px − ax)`, set up
/// with the two endpoints in a canonical order (and the sign carried separately, which is
/// exact), so that the two triangles sharing an edge get bitwise opposite values at every
/// sample, plus the tie rule for samples exactly on the edge.
#[derive(Debug, Clone, Copy)]
pub(super) struct CanonicalEdge {
    pub(super) ax: f64,
    ay: f64,
    /// sign · (bx − ax) and sign · (by − ay) of the canonical endpoints.
    s_dx: f64,
    pub(super) s_dy: f64,
    /// Whether a sample with E = 0 belongs to this triangle: exactly one of the two
    /// triangles sharing the edge owns it.
    pub(super) owned: bool,
}

impl CanonicalEdge {
    #[inline(always)]
    pub(super) fn new(ax: f64, ay: f64, bx: f64, by: f64) -> CanonicalEdge {
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
    pub(super) fn row(&self, py: f64) -> f64 {
        self.s_dx * (py - self.ay)
    }

    /// `E(px, py)` from the row term.
    #[inline(always)]
    pub(super) fn eval(&self, row: f64, px: f64) -> f64 {
        row - self.s_dy * (px - self.ax)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::raster::tests::lcg;

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
}
