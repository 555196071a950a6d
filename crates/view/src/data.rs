//! The binary data the page uploads as textures, little-endian, rows top to bottom:
//!
//! - passes: half floats, RGBA per pixel: the transmission pass (its alpha, or 1), then each
//!   reflection pass placed in the frame (0 where it holds no pixels: the kernel's "no
//!   reflection" there), then each pane group's pass the frame composites apart
//!   ([`group_pass_bytes`], in the order of `PageFrame::groups`), placed the same way;
//! - a light part's passes ([`part_bytes`]): `u32` RGBA texels, each `u32` two halves (low bits
//!   first): per pixel the transmission's R, G, B and the reflection of the pixel's own plane
//!   (R, G, B), then the fourth `u32` 0; with pane-group passes a second layer of the plane's
//!   groups 1 and 2 (R, G, B each), so that the shader fetches one texel per part on a glass
//!   pixel, not one per pass;
//! - mask: `f32` RGBA per pixel: glass slot + 1 (0: no glass), plane, cos θ (the 8-bit code
//!   for an 8-bit mask; cos θ for 16-bit and float masks, NaN as 1 as the kernel reads it; 1
//!   for a binary mask), coverage (1 without);
//! - a product's table: `f32` RGBA texels (RGB, 0), [`LUT_ROWS_PER_CURVE`] rows of
//!   [`LUT_WIDTH`] per curve, curves in the order front r, front t, back r, back t; each curve
//!   holds the 256 8-bit entries, then the [`FINE_STEPS`] + 1 fine entries, then normal
//!   incidence. Then the pane groups' shares of r (issue 27, `glassdb_compose::shares`): front
//!   groups 0..[`PAGE_GROUPS`], then back groups, in the order the rays meet them, the shares
//!   of groups deeper than the last folded into it; zeros for a glass of one group. The front
//!   r curve's normal-incidence texel holds the glass's number of pane groups in its alpha
//!   (at most [`PAGE_GROUPS`]; 1 for a glass of one group).

use glassdb_colour::CubeLut;
use glassdb_compose::DecodedFrame;
use glassdb_compose::lut::{FINE_STEPS, GlassSideLut, RtTriple};
use glassdb_compose::shares::GroupShares;
use glassdb_mask::{CosCode, CosTheta};

/// Texels per row of the lookup-table texture (WebGL2 guarantees 2048).
pub const LUT_WIDTH: usize = 1024;
/// Texels of one curve: 256 8-bit entries, the fine table, normal incidence.
pub const LUT_TEXELS_PER_CURVE: usize = 256 + FINE_STEPS + 1 + 1;
/// Rows of one curve.
pub const LUT_ROWS_PER_CURVE: usize = LUT_TEXELS_PER_CURVE.div_ceil(LUT_WIDTH);
/// Most pane groups of a unit the page composites with a pass each: the shares of deeper
/// groups go to the last one's (a quadruple unit shows three reflections).
pub const PAGE_GROUPS: usize = 3;
/// Curves of one glass slot: front r, front t, back r, back t, then the groups' shares.
pub const LUT_CURVES_PER_SLOT: usize = 4 + 2 * PAGE_GROUPS;
/// Rows of one glass slot.
pub const LUT_ROWS_PER_SLOT: usize = LUT_CURVES_PER_SLOT * LUT_ROWS_PER_CURVE;
/// Offset of the fine table in a curve.
pub const LUT_FINE_OFFSET: usize = 256;
/// Offset of the normal-incidence entry in a curve.
pub const LUT_NORMAL_OFFSET: usize = 256 + FINE_STEPS + 1;
/// Bytes of one product's table ([`lut_bytes`]): its rows of `f32` RGBA texels.
pub const LUT_BYTES: usize = LUT_ROWS_PER_SLOT * LUT_WIDTH * 4 * 4;

/// How the mask's third channel holds cos θ, which the shader follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MaskMode {
    /// The 8-bit code: an exact entry of the 8-bit table.
    Code8,
    /// cos θ, linearly interpolated in the fine table.
    Cos,
    /// No angle: normal incidence.
    Normal,
}

impl MaskMode {
    /// The mode of a decoded mask.
    pub fn of(cos: &CosTheta) -> MaskMode {
        match cos {
            CosTheta::Quantized8(_) => MaskMode::Code8,
            CosTheta::Quantized16(_) | CosTheta::Float(_) => MaskMode::Cos,
            CosTheta::Normal => MaskMode::Normal,
        }
    }

    /// Its name in the scene JSON and in messages.
    pub fn name(self) -> &'static str {
        match self {
            MaskMode::Code8 => "code8",
            MaskMode::Cos => "cos",
            MaskMode::Normal => "normal",
        }
    }
}

/// A product's table for one glass: both sides (front, back), r and t, and its pane groups'
/// shares (`None` or empty: a glass of one group), in the texture layout ([`LUT_BYTES`]
/// bytes).
pub fn lut_bytes(sides: [&GlassSideLut; 2], shares: Option<&GroupShares>) -> Vec<u8> {
    let curve_len = LUT_ROWS_PER_CURVE * LUT_WIDTH * 4;
    let mut texels = vec![0f32; LUT_CURVES_PER_SLOT * curve_len];
    let picks: [fn(&RtTriple) -> [f32; 3]; 2] = [|e| e.r, |e| e.t];
    let mut k = 0;
    for side in sides {
        for pick in picks {
            let curve = &mut texels[k * curve_len..(k + 1) * curve_len];
            for (texel, e) in curve.chunks_exact_mut(4).zip(side.entries()) {
                texel[..3].copy_from_slice(&pick(e));
            }
            k += 1;
        }
    }
    let groups = shares.map_or(0, |s| s[0].len());
    if let Some(shares) = shares.filter(|_| groups > 1) {
        for (side, tables) in shares.iter().enumerate() {
            for (g, share) in tables.iter().enumerate() {
                let k = 4 + side * PAGE_GROUPS + g.min(PAGE_GROUPS - 1);
                let curve = &mut texels[k * curve_len..(k + 1) * curve_len];
                for (texel, e) in curve.chunks_exact_mut(4).zip(share.entries()) {
                    (0..3).for_each(|c| texel[c] += e[c]);
                }
            }
        }
    }
    texels[LUT_NORMAL_OFFSET * 4 + 3] = groups.clamp(1, PAGE_GROUPS) as f32;
    f32_bytes(&texels)
}

/// The pane groups' passes of a decoded frame, each placed in the frame as
/// [`pass_bytes`] places the planes' (see the module docs).
pub fn group_pass_bytes(frame: &DecodedFrame<'_>) -> Vec<u8> {
    let trans = &frame.trans.image;
    let (w, h) = (trans.width as usize, trans.height as usize);
    let mut out: Vec<u8> = Vec::with_capacity(w * h * 8 * frame.groups.len());
    for g in &frame.groups {
        placed_pass(
            &mut out,
            &g.pass.image.rgb,
            |x, y| g.window.index_of(x, y),
            w,
            h,
        );
    }
    out
}

/// `rgb` placed in a `w`×`h` frame (`index_of`: its sample of a frame pixel) as half-float
/// RGBA (0 where it has none, alpha 1).
fn placed_pass(
    out: &mut Vec<u8>,
    rgb: &[Vec<f32>; 3],
    index_of: impl Fn(i64, i64) -> Option<usize>,
    w: usize,
    h: usize,
) {
    let mut push = |v: f32| out.extend_from_slice(&half::f16::from_f32(v).to_le_bytes());
    for y in 0..h {
        for x in 0..w {
            match index_of(x as i64, y as i64) {
                Some(j) => (0..3).for_each(|c| push(rgb[c][j])),
                None => (0..3).for_each(|_| push(0.0)),
            }
            push(1.0);
        }
    }
}

/// Layers of one light part's passes ([`part_bytes`]): the transmission and the reflection of
/// each pixel's own plane, and with pane-group passes a second layer of its groups 1 and 2.
pub fn part_layers(groups: bool) -> usize {
    if groups { 2 } else { 1 }
}

/// One light part's passes as the page's shader reads them, packed so that a glass pixel costs
/// one texture fetch per part (see the module docs): per pixel, in `u32` RGBA texels of two
/// halves each (low bits first), the transmission's R, G, B and the reflection of the pixel's
/// plane (its mask plane's pass there; 0 off glass or outside the pass); with `groups`, a
/// second layer with the reflections of that plane's pane groups 1 and 2 (0 where the plane has
/// no such pass). The halves are [`pass_bytes`]' and [`group_pass_bytes`]' values.
pub fn part_bytes(frame: &DecodedFrame<'_>, groups: bool) -> Vec<u8> {
    let trans = &frame.trans.image;
    let (w, h) = (trans.width as usize, trans.height as usize);
    let n = w * h;
    let layers = part_layers(groups);
    let half = |v: f32| u32::from(half::f16::from_f32(v).to_bits());
    let pack = |lo: f32, hi: f32| half(lo) | (half(hi) << 16);
    // The pane-group passes of each plane, groups 1 and 2.
    let mut of_plane: Vec<[Option<&glassdb_compose::DecodedGroupPass>; 2]> =
        vec![[None; 2]; frame.refl.len()];
    for g in &frame.groups {
        if let Some(slots) = of_plane.get_mut(g.plane)
            && (1..=2).contains(&g.group)
        {
            slots[g.group - 1] = Some(g);
        }
    }
    let mut texels = vec![0u32; layers * n * 4];
    for i in 0..n {
        let (x, y) = ((i % w) as i64, (i / w) as i64);
        let mut v = [0f32; 12];
        for (c, out) in v[..3].iter_mut().enumerate() {
            *out = trans.rgb[c][i];
        }
        let plane = usize::from(frame.mask.plane[i]);
        if frame.mask.id[i] != 0 && plane < frame.refl.len() {
            if let Some(j) = frame.refl_windows[plane].index_of(x, y) {
                for c in 0..3 {
                    v[3 + c] = frame.refl[plane].image.rgb[c][j];
                }
            }
            for (k, g) in of_plane[plane].iter().enumerate() {
                if let Some(g) = g.filter(|_| groups)
                    && let Some(j) = g.window.index_of(x, y)
                {
                    for c in 0..3 {
                        v[6 + 3 * k + c] = g.pass.image.rgb[c][j];
                    }
                }
            }
        }
        for l in 0..layers {
            let at = (l * n + i) * 4;
            let v = &v[6 * l..6 * l + 6];
            texels[at] = pack(v[0], v[1]);
            texels[at + 1] = pack(v[2], v[3]);
            texels[at + 2] = pack(v[4], v[5]);
        }
    }
    texels.iter().flat_map(|t| t.to_le_bytes()).collect()
}

/// The passes of a decoded frame as half-float RGBA planes (see the module docs).
pub fn pass_bytes(frame: &DecodedFrame<'_>) -> Vec<u8> {
    let trans = &frame.trans.image;
    let (w, h) = (trans.width as usize, trans.height as usize);
    let n = w * h;
    let mut out: Vec<u8> = Vec::with_capacity(n * 8 * (1 + frame.refl.len()));
    let mut push = |v: f32| out.extend_from_slice(&half::f16::from_f32(v).to_le_bytes());
    for i in 0..n {
        for c in 0..3 {
            push(trans.rgb[c][i]);
        }
        push(trans.alpha.as_ref().map_or(1.0, |a| a[i]));
    }
    for (pass, window) in frame.refl.iter().zip(&frame.refl_windows) {
        placed_pass(
            &mut out,
            &pass.image.rgb,
            |x, y| window.index_of(x, y),
            w,
            h,
        );
    }
    out
}

/// The mask of a decoded frame as `f32` RGBA (see the module docs); `slot_of(id)` is the
/// glass slot of a mask id (every id of a checked frame has one).
pub fn mask_bytes(frame: &DecodedFrame<'_>, slot_of: impl Fn(u16) -> Option<usize>) -> Vec<u8> {
    let mask = &frame.mask;
    let n = mask.pixel_count();
    let mut texels = Vec::with_capacity(n * 4);
    for i in 0..n {
        let id = mask.id[i];
        let slot = if id == 0 {
            0.0
        } else {
            slot_of(id).map_or(0.0, |s| s as f32 + 1.0)
        };
        let cos = match &mask.cos_theta {
            CosTheta::Quantized8(c) => f32::from(c[i]),
            CosTheta::Quantized16(c) => CosCode::Bits16.decode_f32(c[i]),
            CosTheta::Float(c) if c[i].is_nan() => 1.0,
            CosTheta::Float(c) => c[i],
            CosTheta::Normal => 1.0,
        };
        let coverage = mask.coverage.as_ref().map_or(1.0, |c| c[i]);
        texels.extend_from_slice(&[slot, f32::from(mask.plane[i]), cos, coverage]);
    }
    f32_bytes(&texels)
}

/// A `.cube` view's tables as `f32` RGB texels: the 1D table (if any) in rows of
/// [`LUT_WIDTH`], the last row padded with zeros, then the 3D table (if any), red fastest.
pub fn view_bytes(lut: &CubeLut) -> Vec<u8> {
    let mut texels: Vec<f32> = Vec::new();
    if let Some(t) = lut.shaper_table() {
        texels.extend_from_slice(t.values);
        texels.resize(t.size.div_ceil(LUT_WIDTH) * LUT_WIDTH * 3, 0.0);
    }
    if let Some(t) = lut.cube_table() {
        texels.extend_from_slice(t.values);
    }
    f32_bytes(&texels)
}

fn f32_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glassdb_compose::lut::GlassLut;

    #[test]
    fn a_lut_holds_the_compositors_entries_where_the_layout_says() {
        let reg = glassdb_registry::default_registry().unwrap();
        let g = &reg.default_table().glasses[3];
        let lut = GlassLut::from_records(&[(1, g)]);
        let sides = [
            lut.side(1, glassdb_registry::Side::Front).unwrap(),
            lut.side(1, glassdb_registry::Side::Back).unwrap(),
        ];
        let bytes = lut_bytes(sides, lut.group_shares(1));
        let texel = |curve: usize, e: usize, c: usize| {
            let at = ((curve * LUT_ROWS_PER_CURVE * LUT_WIDTH) + e) * 4 + c;
            f32::from_le_bytes(bytes[at * 4..at * 4 + 4].try_into().unwrap())
        };
        // Back t at code 77, front r at fine entry 4000, back r at normal incidence.
        assert_eq!(texel(3, 77, 1), sides[1].q8[77].t[1]);
        assert_eq!(
            texel(0, LUT_FINE_OFFSET + 4000, 2),
            sides[0].fine[4000].r[2]
        );
        assert_eq!(texel(2, LUT_NORMAL_OFFSET, 0), g.r0_back[0] as f32);
        assert_eq!(bytes.len(), 10 * LUT_ROWS_PER_CURVE * LUT_WIDTH * 16);
        assert_eq!(bytes.len(), LUT_BYTES);
    }
}
