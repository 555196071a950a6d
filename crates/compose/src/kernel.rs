//! The per-pixel composite (method.md eqs. 8–10), in linear light, per channel c:
//!
//! ```text
//! out_c = trans_c · t_c(id, θ) + refl_{plane,c} · r_c(id, θ)     where the mask has a glass id
//! out_c = trans_c                                                  where the mask is 0
//! ```
//!
//! with coverage `k` (antialiased edges) `out = (1−k)·trans + k·(trans·t + refl·r)`, i.e. the
//! weights `t' = 1 − k + k·t` and `r' = k·r`. A term whose weight is exactly 0 is dropped
//! (so r = 0, t = 1 returns the transmission pass bit for bit, and a NaN in a pass reaches the
//! output only where that pass is weighted); NaN and ±Inf otherwise propagate and are counted.
//!
//! The kernel works in place on the transmission pass (no output allocation), one sweep over
//! the pixels for all planes, rayon over bands of rows.

use glassdb_mask::{CosTheta, MaskImage};
use glassdb_registry::Side;
use rayon::prelude::*;

use crate::lut::{GlassLut, GlassSideLut, RtTriple};

/// Rows per parallel task.
const BAND_ROWS: usize = 16;

/// What the kernel needs besides the transmission pass it overwrites.
pub struct KernelInput<'a> {
    /// One reflection pass per plane (R, G, B planes), each `width * height` samples.
    pub refl: &'a [[&'a [f32]; 3]],
    /// Which face each plane shows (same length as `refl`).
    pub plane_sides: &'a [Side],
    pub mask: &'a MaskImage,
    pub lut: &'a GlassLut,
}

/// Counts the kernel gathers in its sweep.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct KernelCounts {
    /// Output samples that are NaN or ±Inf.
    pub nonfinite_output: u64,
    /// Of those, samples whose transmission input was non-finite.
    pub nonfinite_trans: u64,
    /// Of those, samples whose reflection input was non-finite.
    pub nonfinite_refl: u64,
    /// Glass pixels left unchanged because their id has no table (`--unknown passthrough`) or
    /// their plane has no reflection pass.
    pub passthrough_pixels: u64,
}

impl KernelCounts {
    fn add(self, o: KernelCounts) -> KernelCounts {
        KernelCounts {
            nonfinite_output: self.nonfinite_output + o.nonfinite_output,
            nonfinite_trans: self.nonfinite_trans + o.nonfinite_trans,
            nonfinite_refl: self.nonfinite_refl + o.nonfinite_refl,
            passthrough_pixels: self.passthrough_pixels + o.passthrough_pixels,
        }
    }
}

/// The sizes do not agree (the caller checks files first; this guards the library API).
#[derive(Debug, thiserror::Error)]
#[error("kernel input sizes disagree: {0}")]
pub struct KernelShapeError(pub String);

/// cos θ source over one band of pixels, monomorphised per mask kind.
trait CosLookup: Sync {
    /// The same source restricted to pixels `start..start + len`.
    fn band(&self, start: usize, len: usize) -> Self;
    fn rt(&self, lut: &GlassSideLut, j: usize) -> RtTriple;
}

#[derive(Clone, Copy)]
struct Code8<'a>(&'a [u8]);
#[derive(Clone, Copy)]
struct Code16<'a>(&'a [u16]);
#[derive(Clone, Copy)]
struct FloatCos<'a>(&'a [f32]);
#[derive(Clone, Copy)]
struct Normal;

impl CosLookup for Code8<'_> {
    fn band(&self, start: usize, len: usize) -> Self {
        Code8(self.0.get(start..start + len).unwrap_or(&[]))
    }
    #[inline(always)]
    fn rt(&self, lut: &GlassSideLut, j: usize) -> RtTriple {
        lut.at_code8(self.0.get(j).copied().unwrap_or(255))
    }
}
impl CosLookup for Code16<'_> {
    fn band(&self, start: usize, len: usize) -> Self {
        Code16(self.0.get(start..start + len).unwrap_or(&[]))
    }
    #[inline(always)]
    fn rt(&self, lut: &GlassSideLut, j: usize) -> RtTriple {
        lut.at_cos(f32::from(self.0.get(j).copied().unwrap_or(65535)) * (1.0 / 65535.0))
    }
}
impl CosLookup for FloatCos<'_> {
    fn band(&self, start: usize, len: usize) -> Self {
        FloatCos(self.0.get(start..start + len).unwrap_or(&[]))
    }
    #[inline(always)]
    fn rt(&self, lut: &GlassSideLut, j: usize) -> RtTriple {
        lut.at_cos(self.0.get(j).copied().unwrap_or(1.0))
    }
}
impl CosLookup for Normal {
    fn band(&self, _start: usize, _len: usize) -> Self {
        Normal
    }
    #[inline(always)]
    fn rt(&self, lut: &GlassSideLut, _j: usize) -> RtTriple {
        lut.normal
    }
}

/// Composites in place: `trans` (R, G, B planes of the transmission pass) becomes the output.
pub fn compose_in_place(
    trans: [&mut [f32]; 3],
    input: &KernelInput,
) -> Result<KernelCounts, KernelShapeError> {
    let mask = input.mask;
    let n = mask.pixel_count();
    let w = mask.width as usize;
    mask.check_consistent().map_err(KernelShapeError)?;
    if trans.iter().any(|p| p.len() != n) {
        return Err(KernelShapeError(format!(
            "transmission pass planes are not {n} samples"
        )));
    }
    if input.refl.iter().flatten().any(|p| p.len() != n) {
        return Err(KernelShapeError(format!(
            "reflection pass planes are not {n} samples"
        )));
    }
    if input.refl.len() != input.plane_sides.len() {
        return Err(KernelShapeError(
            "one side per reflection pass is needed".into(),
        ));
    }
    if n == 0 {
        return Ok(KernelCounts::default());
    }
    match &mask.cos_theta {
        CosTheta::Quantized8(c) => Ok(run(trans, input, &Code8(c), w)),
        CosTheta::Quantized16(c) => Ok(run(trans, input, &Code16(c), w)),
        CosTheta::Float(c) => Ok(run(trans, input, &FloatCos(c), w)),
        CosTheta::Normal => Ok(run(trans, input, &Normal, w)),
    }
}

fn run<C: CosLookup>(
    trans: [&mut [f32]; 3],
    input: &KernelInput,
    cos: &C,
    w: usize,
) -> KernelCounts {
    let band = w * BAND_ROWS;
    let [tr, tg, tb] = trans;
    let simple = input.refl.len() == 1 && input.mask.coverage.is_none();
    tr.par_chunks_mut(band)
        .zip(tg.par_chunks_mut(band))
        .zip(tb.par_chunks_mut(band))
        .enumerate()
        .map(|(k, ((r, g), b))| {
            let base = k * band;
            let cos = cos.band(base, r.len());
            if simple {
                sweep_band_one_plane(base, [r, g, b], input, &cos)
            } else {
                sweep_band(base, [r, g, b], input, &cos)
            }
        })
        .reduce(KernelCounts::default, KernelCounts::add)
}

/// Counts the non-finite samples of a pixel the kernel leaves as the transmission pass.
#[inline(always)]
fn count_untouched(counts: &mut KernelCounts, px: [f32; 3]) {
    if !(px[0] + px[1] + px[2]).is_finite() {
        let bad = px.iter().filter(|v| !v.is_finite()).count() as u64;
        counts.nonfinite_output += bad;
        counts.nonfinite_trans += bad;
    }
}

/// Counts the non-finite samples of a composited pixel (the slow path runs only when one is).
#[inline(always)]
fn count_composited(counts: &mut KernelCounts, o: [f32; 3], tr: [f32; 3], rf: [f32; 3]) {
    if !(o[0] + o[1] + o[2]).is_finite() {
        for c in 0..3 {
            if !o[c].is_finite() {
                counts.nonfinite_output += 1;
                counts.nonfinite_trans += u64::from(!tr[c].is_finite());
                counts.nonfinite_refl += u64::from(!rf[c].is_finite());
            }
        }
    }
}

/// The common case: one plane, no coverage. Ids are spatially coherent, so the table of the
/// previous glass pixel is reused while the id stays the same.
fn sweep_band_one_plane<C: CosLookup>(
    base: usize,
    out: [&mut [f32]; 3],
    input: &KernelInput,
    cos: &C,
) -> KernelCounts {
    let mut counts = KernelCounts::default();
    let len = out[0].len();
    let (Some(ids), Some(refl), Some(&side)) = (
        input.mask.id.get(base..base + len),
        input.refl.first(),
        input.plane_sides.first(),
    ) else {
        return counts;
    };
    let (Some(rr), Some(rg), Some(rb)) = (
        refl[0].get(base..base + len),
        refl[1].get(base..base + len),
        refl[2].get(base..base + len),
    ) else {
        return counts;
    };
    let side = match side {
        Side::Front => 0,
        Side::Back => 1,
    };
    let [or, og, ob] = out;
    let mut last_id = 0u16;
    let mut last: Option<&GlassSideLut> = None;
    for (j, ((((&id, r_out), g_out), b_out), ((&fr, &fg), &fb))) in ids
        .iter()
        .zip(or.iter_mut())
        .zip(og.iter_mut())
        .zip(ob.iter_mut())
        .zip(rr.iter().zip(rg).zip(rb))
        .enumerate()
    {
        let tr = [*r_out, *g_out, *b_out];
        if id == 0 {
            count_untouched(&mut counts, tr);
            continue;
        }
        if id != last_id {
            last_id = id;
            last = input.lut.sides(id).map(|s| &s[side]);
        }
        let Some(lut) = last else {
            counts.passthrough_pixels += 1;
            continue;
        };
        let rt = cos.rt(lut, j);
        let rf = [fr, fg, fb];
        let o = [
            weighted(tr[0], rt.t[0], rf[0], rt.r[0]),
            weighted(tr[1], rt.t[1], rf[1], rt.r[1]),
            weighted(tr[2], rt.t[2], rf[2], rt.r[2]),
        ];
        *r_out = o[0];
        *g_out = o[1];
        *b_out = o[2];
        count_composited(&mut counts, o, tr, rf);
    }
    counts
}

#[inline(always)]
fn weighted(tr: f32, t: f32, rf: f32, r: f32) -> f32 {
    // A term whose weight is exactly 0 is dropped (branches predict well: r and t are per glass).
    let a = tr * t;
    if r == 0.0 {
        a
    } else if t == 0.0 {
        rf * r
    } else {
        a + rf * r
    }
}

fn sweep_band<C: CosLookup>(
    base: usize,
    out: [&mut [f32]; 3],
    input: &KernelInput,
    cos: &C,
) -> KernelCounts {
    let mask = input.mask;
    let len = out[0].len();
    let ids = mask.id.get(base..base + len).unwrap_or(&[]);
    let planes = mask.plane.get(base..base + len).unwrap_or(&[]);
    let coverage = mask.coverage.as_ref().and_then(|c| c.get(base..base + len));
    let mut counts = KernelCounts::default();
    let [or, og, ob] = out;
    for (j, (((&id, &plane), r_out), (g_out, b_out))) in ids
        .iter()
        .zip(planes)
        .zip(or.iter_mut())
        .zip(og.iter_mut().zip(ob.iter_mut()))
        .enumerate()
    {
        if id == 0 {
            count_untouched(&mut counts, [*r_out, *g_out, *b_out]);
            continue;
        }
        let i = base + j;
        let p = plane as usize;
        let (Some(sides), Some(refl), Some(&side)) = (
            input.lut.sides(id),
            input.refl.get(p),
            input.plane_sides.get(p),
        ) else {
            counts.passthrough_pixels += 1;
            continue;
        };
        let lut = match side {
            Side::Front => &sides[0],
            Side::Back => &sides[1],
        };
        let mut rt = cos.rt(lut, j);
        if let Some(k) = coverage.and_then(|c| c.get(j)).copied() {
            for c in 0..3 {
                rt.t[c] = 1.0 - k + k * rt.t[c];
                rt.r[c] *= k;
            }
        }
        let rf = [
            refl[0].get(i).copied().unwrap_or(0.0),
            refl[1].get(i).copied().unwrap_or(0.0),
            refl[2].get(i).copied().unwrap_or(0.0),
        ];
        let tr_in = [*r_out, *g_out, *b_out];
        let o = [
            weighted(tr_in[0], rt.t[0], rf[0], rt.r[0]),
            weighted(tr_in[1], rt.t[1], rf[1], rt.r[1]),
            weighted(tr_in[2], rt.t[2], rf[2], rt.r[2]),
        ];
        *r_out = o[0];
        *g_out = o[1];
        *b_out = o[2];
        count_composited(&mut counts, o, tr_in, rf);
    }
    counts
}
