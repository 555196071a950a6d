//! Units' pane groups in the kernel (issue 27): on a pixel of a unit of several pane groups,
//!
//! ```text
//! out_c = trans_c · t_c(id, θ) + Σ_k refl_{plane,k,c} · r_{k,c}(id, θ)
//! ```
//!
//! with `refl_{plane,k}` the scene mirrored about group k's mid-plane and `r_k` its share of
//! the unit's reflectance ([`crate::shares`], in the order the rays meet the groups; Σ r_k = r).
//! Group 0's pass is the plane's own reflection pass. A group without a pass of its own, or
//! beyond the limit on the groups, has its share added to the deepest nearer group that has
//! one (so with one group, `--surfaces 1`, the frame is the one-group composite). Glasses of
//! one group composite exactly as in the other sweeps.

use std::num::NonZeroUsize;

use glassdb_image::PixelWindow;

use super::{
    CosLookup, KernelCounts, KernelInput, KernelShapeError, OutsidePass, PlanePass, Sweep,
    count_composited, wrong_channel,
};
use crate::shares::ShareSideLut;

/// The reflection pass of pane group `group` (1 or more: the second group the rays meet, …)
/// behind plane `plane`, placed in the frame like a [`super::PlacedRefl`] (the plane's side is
/// its pass's).
#[derive(Clone, Copy)]
pub struct PlacedGroupRefl<'a> {
    /// The plane.
    pub plane: usize,
    /// The pane group, counted from 0 (the plane's own pass) in the order the rays meet them.
    pub group: usize,
    /// Its R, G, B planes.
    pub rgb: [&'a [f32]; 3],
    /// The pixels it holds, relative to the frame's top-left pixel.
    pub window: PixelWindow,
}

/// The checked group passes: `by_plane[p][g - 1]` is plane p's group g, and how many groups
/// are composited (deeper ones folded into the last).
#[derive(Default)]
pub(super) struct PaneGroupPasses<'a> {
    by_plane: Vec<Vec<Option<PlanePass<'a>>>>,
    limit: Option<NonZeroUsize>,
}

impl PaneGroupPasses<'_> {
    /// Whether the group sweep is needed: some group pass is given, more than one group is
    /// composited and some glass of the table has several groups.
    pub(super) fn active(&self, lut: &crate::lut::GlassLut) -> bool {
        self.by_plane.iter().any(|g| g.iter().any(Option::is_some))
            && self.limit.is_none_or(|l| l.get() > 1)
            && lut.has_units()
    }

    /// The pass that takes group `g`'s share on `plane` (whose own pass is `first`): its own,
    /// or the deepest nearer one given, within the limit.
    #[inline(always)]
    fn pass_for<'p>(
        &'p self,
        first: &'p PlanePass<'p>,
        plane: usize,
        g: usize,
    ) -> &'p PlanePass<'p> {
        let g = self.limit.map_or(g, |l| g.min(l.get() - 1));
        let Some(groups) = self.by_plane.get(plane) else {
            return first;
        };
        (1..=g.min(groups.len()))
            .rev()
            .find_map(|k| groups[k - 1].as_ref())
            .unwrap_or(first)
    }
}

impl<'a> KernelInput<'a> {
    /// Adds the pane groups' reflection passes (checked: each on a plane that has a pass,
    /// group 1 or more, given once, one sample per pixel of its window) and the number of
    /// groups composited (`None`: all; deeper groups' shares go to the last one's pass).
    pub fn with_groups(
        mut self,
        groups: &[PlacedGroupRefl<'a>],
        limit: Option<NonZeroUsize>,
    ) -> Result<KernelInput<'a>, KernelShapeError> {
        let frame = PixelWindow::at_origin(self.mask.width as usize, self.mask.height as usize);
        let mut by_plane: Vec<Vec<Option<PlanePass<'a>>>> = vec![Vec::new(); self.planes.len()];
        for placed in groups {
            let (plane, group) = (placed.plane, placed.group);
            let Some(first) = self.planes.get(plane) else {
                return Err(KernelShapeError::GroupPlane {
                    plane,
                    group,
                    planes: self.planes.len(),
                });
            };
            if let Some((channel, samples, pixels)) = wrong_channel(&placed.rgb, &placed.window) {
                return Err(KernelShapeError::GroupSamples {
                    plane,
                    group,
                    channel,
                    samples,
                    pixels,
                });
            }
            let slots = &mut by_plane[plane];
            if group == 0 || slots.get(group - 1).is_some_and(Option::is_some) {
                return Err(KernelShapeError::GroupRepeated { plane, group });
            }
            if slots.len() < group {
                slots.resize(group, None);
            }
            slots[group - 1] = Some(PlanePass {
                refl: placed.rgb,
                side: first.side,
                window: (placed.window != frame).then_some(placed.window),
            });
        }
        self.groups = PaneGroupPasses { by_plane, limit };
        Ok(self)
    }
}

/// Where a glass pixel of a unit is composited: its plane's pass, the plane, the pixel's index
/// in the frame and in its band, the frame's width and the pixel's coverage.
pub(super) struct UnitPixel<'p> {
    pub(super) pass: &'p PlanePass<'p>,
    pub(super) plane: usize,
    pub(super) frame_index: usize,
    pub(super) band_index: usize,
    pub(super) width: usize,
    pub(super) coverage: f32,
}

impl Sweep<'_> {
    /// The share tables of `id` seen from `side` when the frame composites pane groups and the
    /// glass has several (`None`: composite it as a glass of one group).
    #[inline(always)]
    pub(super) fn unit_shares(&self, id: u16, side: usize) -> Option<&[ShareSideLut]> {
        if !self.with_groups {
            return None;
        }
        let shares = &self.lut.group_shares(id)?[side];
        (!shares.is_empty()).then_some(&shares[..])
    }

    /// Eq. 8 with one pass per pane group on one pixel of a unit, in place; `false` when a
    /// group's pass does not hold the pixel and the pixel is to stay the transmission pass.
    #[inline(always)]
    pub(super) fn composite_unit<C: CosLookup>(
        &self,
        counts: &mut KernelCounts,
        out: [&mut f32; 3],
        t: [f32; 3],
        shares: &[ShareSideLut],
        at: &UnitPixel<'_>,
        cos: &C,
    ) -> bool {
        let tr = [*out[0], *out[1], *out[2]];
        let mut sum = [0.0f32; 3];
        let mut bad = [false; 3];
        let mut outside = false;
        for (g, share) in shares.iter().enumerate() {
            let target = self.groups.pass_for(at.pass, at.plane, g);
            let Some(p) = target.index(at.frame_index, at.width) else {
                outside = true;
                continue;
            };
            let s = cos.at(share, at.band_index);
            for c in 0..3 {
                let w = s[c] * at.coverage;
                if w != 0.0 {
                    let v = target.refl[c][p];
                    bad[c] |= !v.is_finite();
                    sum[c] += v * w;
                }
            }
        }
        if outside && self.outside == OutsidePass::Transmission {
            return false;
        }
        let o: [f32; 3] = std::array::from_fn(|c| {
            if t[c] == 0.0 {
                sum[c]
            } else {
                tr[c] * t[c] + sum[c]
            }
        });
        for (slot, v) in out.into_iter().zip(o) {
            *slot = v;
        }
        let rf = bad.map(|b| if b { f32::NAN } else { 0.0 });
        count_composited(counts, o, tr, rf);
        true
    }
}
