//! Binning of triangles into bands of rows, the unit of parallel rasterisation.

use super::depth::DrawOrder;

/// The triangles overlapping each band of `rows_per_band` rows, by position in the draw order
/// ([`DrawOrder`]): a counting sort keeps each band's triangles in that order.
pub(super) struct BandBins {
    /// Band `b`'s triangles are `binned[start[b]..start[b + 1]]`.
    start: Vec<u32>,
    binned: Vec<u32>,
    /// Per band: its triangles' area in it (each triangle's area times the share of its rows
    /// in the band), and their boxes' area in it, pixels.
    cover: Vec<BandCover>,
}

/// The triangles of one band.
#[derive(Debug, Clone, Copy)]
pub(super) struct BandTriangles<'a> {
    /// Their positions in the draw order, increasing.
    pub(super) drawn: &'a [u32],
    /// How much of the band they cover.
    pub(super) cover: BandCover,
}

/// How much of a band its triangles cover: their area in it, and their boxes' area in it.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct BandCover {
    pub(super) area: f64,
    pub(super) boxes: f64,
}

impl BandBins {
    pub(super) fn new(order: &DrawOrder, bands: usize, rows_per_band: u32) -> BandBins {
        let mut counts = vec![0u32; bands + 1];
        for c in &order.entries {
            for b in (c.bbox.rows.0 / rows_per_band)..=(c.bbox.rows.1 / rows_per_band) {
                counts[b as usize + 1] += 1;
            }
        }
        for b in 0..bands {
            counts[b + 1] += counts[b];
        }
        let mut fill = counts.clone();
        let mut binned = vec![0u32; counts[bands] as usize];
        let mut cover = vec![BandCover::default(); bands];
        for (p, c) in order.entries.iter().enumerate() {
            let (j0, j1) = c.bbox.rows;
            for b in (j0 / rows_per_band)..=(j1 / rows_per_band) {
                let slot = &mut fill[b as usize];
                binned[*slot as usize] = p as u32;
                *slot += 1;
                let row0 = b * rows_per_band;
                let row1 = row0 + rows_per_band - 1;
                let in_band = f64::from(j1.min(row1) + 1 - j0.max(row0));
                let band = &mut cover[b as usize];
                band.area += c.area * in_band / f64::from(j1 + 1 - j0);
                band.boxes += f64::from(c.bbox.columns.1 + 1 - c.bbox.columns.0) * in_band;
            }
        }
        BandBins {
            start: counts,
            binned,
            cover,
        }
    }

    /// The triangles overlapping band `band` and how much of it they cover.
    pub(super) fn band(&self, band: usize) -> BandTriangles<'_> {
        BandTriangles {
            drawn: &self.binned[self.start[band] as usize..self.start[band + 1] as usize],
            cover: self.cover[band],
        }
    }
}
