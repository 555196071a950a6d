//! Binning of triangles into bands of rows, the unit of parallel rasterisation.

use super::setup::Setup;

/// The triangles overlapping each band of `rows_per_band` rows, by index into the setups.
/// A counting sort keeps each band's triangles in scene order, so ties in depth go to the
/// earlier triangle whatever the thread schedule.
pub(super) struct BandBins {
    /// Band `b`'s triangles are `binned[start[b]..start[b + 1]]`.
    start: Vec<u32>,
    binned: Vec<u32>,
}

impl BandBins {
    pub(super) fn new(setups: &[Setup], bands: usize, rows_per_band: u32) -> BandBins {
        let mut counts = vec![0u32; bands + 1];
        for s in setups {
            for b in (s.j0 / rows_per_band)..=(s.j1 / rows_per_band) {
                counts[b as usize + 1] += 1;
            }
        }
        for b in 0..bands {
            counts[b + 1] += counts[b];
        }
        let mut fill = counts.clone();
        let mut binned = vec![0u32; counts[bands] as usize];
        for (k, s) in setups.iter().enumerate() {
            for b in (s.j0 / rows_per_band)..=(s.j1 / rows_per_band) {
                let slot = &mut fill[b as usize];
                binned[*slot as usize] = k as u32;
                *slot += 1;
            }
        }
        BandBins {
            start: counts,
            binned,
        }
    }

    /// Indices of the triangles overlapping band `band`, in scene order.
    pub(super) fn band(&self, band: usize) -> &[u32] {
        &self.binned[self.start[band] as usize..self.start[band + 1] as usize]
    }
}
