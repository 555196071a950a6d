//! The sub-pixel samples of one pixel: a K×K grid for coverage, plus the pixel centre, which
//! decides the pixel's glass when it shows one.

/// Sample offsets within a pixel and which of them is the centre.
pub(super) struct SampleGrid {
    /// The K×K grid `((a + ½)/K, (b + ½)/K)`, then the pixel centre if the grid lacks it
    /// (even K).
    pub(super) offsets: Vec<[f64; 2]>,
    /// Index of the pixel-centre sample in `offsets`.
    pub(super) centre: usize,
    /// K², the number of grid samples (the first entries of `offsets`).
    pub(super) grid: usize,
}

impl SampleGrid {
    pub(super) fn new(k: u32) -> SampleGrid {
        let mut offsets = Vec::with_capacity((k * k + 1) as usize);
        for b in 0..k {
            for a in 0..k {
                offsets.push([(a as f64 + 0.5) / k as f64, (b as f64 + 0.5) / k as f64]);
            }
        }
        let centre = if k % 2 == 1 {
            let h = (k / 2) as usize;
            h * k as usize + h
        } else {
            offsets.push([0.5, 0.5]);
            offsets.len() - 1
        };
        SampleGrid {
            offsets,
            centre,
            grid: (k * k) as usize,
        }
    }

    /// Samples per pixel (K², plus one for even K).
    pub(super) fn len(&self) -> usize {
        self.offsets.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_grids_hold_the_centre() {
        for k in 1..=6 {
            let g = SampleGrid::new(k);
            assert_eq!(g.offsets[g.centre], [0.5, 0.5]);
            assert_eq!(g.offsets.len() as u32, k * k + (1 - k % 2));
            assert_eq!(g.grid as u32, k * k);
        }
    }
}
