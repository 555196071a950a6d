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

use std::ops::Range;

use glassdb_image::PixelWindow;
use glassdb_mask::{CosCode, CosTheta, MaskImage};
use glassdb_side::Side;
use rayon::prelude::*;

use crate::lut::{GlassLut, GlassSideLut, Lerp, RtTriple, SideLut};

mod pane_groups;

pub use pane_groups::PlacedGroupRefl;
use pane_groups::{PaneGroupPasses, UnitPixel};

/// Rows per parallel task.
const BAND_ROWS: usize = 16;

/// One reflection pass (R, G, B planes) and which face of the glass its plane shows (0: front,
/// 1: back, the index into [`GlassLut`]'s sides).
#[derive(Clone, Copy)]
struct PlanePass<'a> {
    refl: [&'a [f32]; 3],
    side: usize,
    /// The pixels the pass holds, relative to the frame's top-left pixel; `None` when it holds
    /// exactly the frame.
    window: Option<PixelWindow>,
}

impl PlanePass<'_> {
    /// Index into the pass of frame pixel `i` (frame `width` pixels wide), if the pass holds it.
    #[inline(always)]
    fn index(&self, i: usize, width: usize) -> Option<usize> {
        match &self.window {
            None => Some(i),
            Some(w) => w.index_of((i % width) as i64, (i / width) as i64),
        }
    }
}

/// A reflection pass placed in the frame: its R, G, B planes hold the pixels of `window`
/// (coordinates relative to the frame's top-left pixel; it may cover only part of the frame,
/// e.g. its pane's screen rectangle, or reach beyond it).
#[derive(Clone, Copy)]
pub struct PlacedRefl<'a> {
    /// Its R, G, B planes.
    pub rgb: [&'a [f32]; 3],
    /// The pixels it holds, relative to the frame's top-left pixel.
    pub window: PixelWindow,
    /// The face of the glass its plane shows.
    pub side: Side,
}

/// What the kernel does with a glass pixel whose plane's reflection pass does not hold it
/// (the caller refuses such pixels first unless the user chose one of these).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OutsidePass {
    /// Composite with no reflection there (black): `out = trans·t`.
    #[default]
    NoReflection,
    /// Leave the pixel as the transmission pass (counted as passed through).
    Transmission,
}

/// Everything the kernel reads and the transmission pass it overwrites, checked once by
/// [`KernelInput::new`]: every plane of every pass has one sample per mask pixel and every
/// reflection pass has its side, so the kernel indexes plainly and cannot fail. Glass ids
/// without a table and planes without a reflection pass are not errors: those pixels are
/// left as the transmission pass and counted ([`KernelCounts::passthrough_pixels`]).
pub struct KernelInput<'a> {
    trans: [&'a mut [f32]; 3],
    planes: Vec<PlanePass<'a>>,
    mask: &'a MaskImage,
    lut: &'a GlassLut,
    outside: OutsidePass,
    groups: PaneGroupPasses<'a>,
}

/// The kernel's inputs do not fit together (the caller checks files first; this guards the
/// library API).
#[derive(Debug, thiserror::Error)]
pub enum KernelShapeError {
    /// The mask's per-pixel vectors disagree with its size.
    #[error("kernel input sizes disagree: the mask is inconsistent: {0}")]
    Mask(String),
    /// A plane of the transmission pass has the wrong number of samples.
    #[error(
        "kernel input sizes disagree: transmission pass channel {channel} has {samples} samples for {pixels} mask pixels"
    )]
    Transmission {
        /// The channel (0 R, 1 G, 2 B).
        channel: usize,
        /// Its samples.
        samples: usize,
        /// The pixels it should hold.
        pixels: usize,
    },
    /// A plane of a reflection pass has the wrong number of samples.
    #[error(
        "kernel input sizes disagree: reflection pass {pass} channel {channel} has {samples} samples for the {pixels} pixels of its window"
    )]
    Reflection {
        /// The reflection pass.
        pass: usize,
        /// The channel (0 R, 1 G, 2 B).
        channel: usize,
        /// Its samples.
        samples: usize,
        /// The pixels it should hold.
        pixels: usize,
    },
    /// A pane group's reflection pass is on a plane without a reflection pass.
    #[error(
        "kernel input sizes disagree: the pass of pane group {group} of plane {plane} has no plane pass ({planes} planes)"
    )]
    GroupPlane {
        /// The plane.
        plane: usize,
        /// The pane group.
        group: usize,
        /// Planes with a pass.
        planes: usize,
    },
    /// A plane of a pane group's reflection pass has the wrong number of samples.
    #[error(
        "kernel input sizes disagree: the pass of pane group {group} of plane {plane}, channel {channel}, has {samples} samples for the {pixels} pixels of its window"
    )]
    GroupSamples {
        /// The plane.
        plane: usize,
        /// The pane group.
        group: usize,
        /// The channel (0 R, 1 G, 2 B).
        channel: usize,
        /// Its samples.
        samples: usize,
        /// The pixels it should hold.
        pixels: usize,
    },
    /// A pane group's pass given twice, or as group 0 (the plane's own pass).
    #[error(
        "kernel input sizes disagree: pane group {group} of plane {plane} is given twice (group 0 is the plane's own pass)"
    )]
    GroupRepeated {
        /// The plane.
        plane: usize,
        /// The pane group.
        group: usize,
    },
    /// The reflection passes and the sides of their planes are not one to one.
    #[error("kernel input sizes disagree: {passes} reflection passes but {sides} plane sides")]
    SidesPerPass {
        /// Reflection passes.
        passes: usize,
        /// Plane sides.
        sides: usize,
    },
}

impl<'a> KernelInput<'a> {
    /// Checks the inputs against the mask: `trans` and every plane of `refl` hold one sample per
    /// pixel, `plane_sides` one side per reflection pass (plane k shows `plane_sides[k]`).
    pub fn new(
        trans: [&'a mut [f32]; 3],
        refl: &[[&'a [f32]; 3]],
        plane_sides: &[Side],
        mask: &'a MaskImage,
        lut: &'a GlassLut,
    ) -> Result<KernelInput<'a>, KernelShapeError> {
        if refl.len() != plane_sides.len() {
            return Err(KernelShapeError::SidesPerPass {
                passes: refl.len(),
                sides: plane_sides.len(),
            });
        }
        let frame = PixelWindow::at_origin(mask.width as usize, mask.height as usize);
        let placed: Vec<PlacedRefl<'a>> = refl
            .iter()
            .zip(plane_sides)
            .map(|(&rgb, &side)| PlacedRefl {
                rgb,
                window: frame,
                side,
            })
            .collect();
        KernelInput::placed(trans, &placed, mask, lut, OutsidePass::default())
    }

    /// Checks the inputs against the mask: `trans` holds one sample per mask pixel, every
    /// reflection pass one per pixel of its window.
    pub fn placed(
        trans: [&'a mut [f32]; 3],
        refl: &[PlacedRefl<'a>],
        mask: &'a MaskImage,
        lut: &'a GlassLut,
        outside: OutsidePass,
    ) -> Result<KernelInput<'a>, KernelShapeError> {
        mask.check_consistent().map_err(KernelShapeError::Mask)?;
        let pixels = mask.pixel_count();
        if let Some((channel, p)) = trans.iter().enumerate().find(|(_, p)| p.len() != pixels) {
            return Err(KernelShapeError::Transmission {
                channel,
                samples: p.len(),
                pixels,
            });
        }
        let frame = PixelWindow::at_origin(mask.width as usize, mask.height as usize);
        for (pass, placed) in refl.iter().enumerate() {
            if let Some((channel, samples, pixels)) = wrong_channel(&placed.rgb, &placed.window) {
                return Err(KernelShapeError::Reflection {
                    pass,
                    channel,
                    samples,
                    pixels,
                });
            }
        }
        let planes = refl
            .iter()
            .map(|p| PlanePass {
                refl: p.rgb,
                side: match p.side {
                    Side::Front => 0,
                    Side::Back => 1,
                },
                window: (p.window != frame).then_some(p.window),
            })
            .collect();
        Ok(KernelInput {
            trans,
            planes,
            mask,
            lut,
            outside,
            groups: PaneGroupPasses::default(),
        })
    }
}

/// The first channel of `rgb` without one sample per pixel of `window`: (channel, samples,
/// pixels).
fn wrong_channel(rgb: &[&[f32]; 3], window: &PixelWindow) -> Option<(usize, usize, usize)> {
    let pixels = window.width * window.height;
    rgb.iter()
        .enumerate()
        .find(|(_, p)| p.len() != pixels)
        .map(|(c, p)| (c, p.len(), pixels))
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

/// cos θ source over one band of pixels, monomorphised per mask kind.
trait CosLookup: Sync {
    /// The same source restricted to the pixels `range`.
    fn band(&self, range: Range<usize>) -> Self;
    /// The entry of a side's table (r and t, or a pane group's share of r) at pixel `j` of the
    /// band.
    fn at<E: Lerp>(&self, lut: &SideLut<E>, j: usize) -> E;
}

/// A mask's cos θ sample, looked up in a side's table as its kind is.
trait CosSample: Copy + Sync {
    /// The entry of `lut` at this sample.
    fn at<E: Lerp>(self, lut: &SideLut<E>) -> E;
}

impl CosSample for u8 {
    #[inline(always)]
    fn at<E: Lerp>(self, lut: &SideLut<E>) -> E {
        lut.at_code8(self)
    }
}
impl CosSample for u16 {
    #[inline(always)]
    fn at<E: Lerp>(self, lut: &SideLut<E>) -> E {
        lut.at_cos(CosCode::Bits16.decode_f32(self))
    }
}
impl CosSample for f32 {
    #[inline(always)]
    fn at<E: Lerp>(self, lut: &SideLut<E>) -> E {
        lut.at_cos(self)
    }
}

/// A mask's cos θ plane: 8-bit codes, 16-bit codes or floats.
#[derive(Clone, Copy)]
struct Samples<'a, T>(&'a [T]);
/// A binary mask's: normal incidence everywhere.
#[derive(Clone, Copy)]
struct Normal;

impl<T: CosSample> CosLookup for Samples<'_, T> {
    fn band(&self, range: Range<usize>) -> Self {
        Samples(&self.0[range])
    }
    #[inline(always)]
    fn at<E: Lerp>(&self, lut: &SideLut<E>, j: usize) -> E {
        self.0[j].at(lut)
    }
}
impl CosLookup for Normal {
    fn band(&self, _range: Range<usize>) -> Self {
        Normal
    }
    #[inline(always)]
    fn at<E: Lerp>(&self, lut: &SideLut<E>, _j: usize) -> E {
        lut.normal
    }
}

/// Composites in place: the transmission pass of `input` becomes the output.
pub fn compose_in_place(input: KernelInput<'_>) -> KernelCounts {
    let KernelInput {
        trans,
        planes,
        mask,
        lut,
        outside,
        groups,
    } = input;
    if mask.pixel_count() == 0 {
        return KernelCounts::default();
    }
    let sweep = Sweep {
        planes: &planes,
        mask,
        lut,
        outside,
        // Units' deeper pane groups only where their passes are given and some glass has
        // them: the one-group frame keeps its own sweeps.
        with_groups: groups.active(lut),
        groups: &groups,
    };
    match &mask.cos_theta {
        CosTheta::Quantized8(c) => sweep.run(trans, &Samples(c)),
        CosTheta::Quantized16(c) => sweep.run(trans, &Samples(c)),
        CosTheta::Float(c) => sweep.run(trans, &Samples(c)),
        CosTheta::Normal => sweep.run(trans, &Normal),
    }
}

/// The read-only part of a checked [`KernelInput`], shared by the bands.
struct Sweep<'a> {
    planes: &'a [PlanePass<'a>],
    mask: &'a MaskImage,
    lut: &'a GlassLut,
    outside: OutsidePass,
    with_groups: bool,
    groups: &'a PaneGroupPasses<'a>,
}

impl Sweep<'_> {
    /// One parallel sweep over bands of rows.
    fn run<C: CosLookup>(&self, trans: [&mut [f32]; 3], cos: &C) -> KernelCounts {
        let band = self.mask.width as usize * BAND_ROWS;
        let [tr, tg, tb] = trans;
        let simple = self.planes.len() == 1
            && self.mask.coverage.is_none()
            && self.planes[0].window.is_none()
            && !self.with_groups;
        tr.par_chunks_mut(band)
            .zip(tg.par_chunks_mut(band))
            .zip(tb.par_chunks_mut(band))
            .enumerate()
            .map(|(k, ((r, g), b))| {
                let pixels = k * band..k * band + r.len();
                let cos = cos.band(pixels.clone());
                if simple {
                    self.band_one_plane(pixels, [r, g, b], &cos)
                } else {
                    self.band_any_planes(pixels, [r, g, b], &cos)
                }
            })
            .reduce(KernelCounts::default, KernelCounts::add)
    }

    /// The common case: one plane, no coverage. Ids are spatially coherent, so the table of
    /// the previous glass pixel is reused while the id stays the same.
    fn band_one_plane<C: CosLookup>(
        &self,
        pixels: Range<usize>,
        out: [&mut [f32]; 3],
        cos: &C,
    ) -> KernelCounts {
        let mut counts = KernelCounts::default();
        let pass = &self.planes[0];
        let ids = &self.mask.id[pixels.clone()];
        let rr = &pass.refl[0][pixels.clone()];
        let rg = &pass.refl[1][pixels.clone()];
        let rb = &pass.refl[2][pixels];
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
                last = self.lut.sides(id).map(|s| &s[pass.side]);
            }
            let Some(lut) = last else {
                counts.passthrough_pixels += 1;
                continue;
            };
            let rt = cos.at(lut, j);
            composite_pixel(&mut counts, [r_out, g_out, b_out], &rt, [fr, fg, fb]);
        }
        counts
    }

    /// Any number of planes and pane groups, with or without coverage.
    fn band_any_planes<C: CosLookup>(
        &self,
        pixels: Range<usize>,
        out: [&mut [f32]; 3],
        cos: &C,
    ) -> KernelCounts {
        let mask = self.mask;
        let base = pixels.start;
        let ids = &mask.id[pixels.clone()];
        let planes = &mask.plane[pixels.clone()];
        let coverage = mask.coverage.as_deref().map(|c| &c[pixels]);
        let width = mask.width as usize;
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
            // An id without a table, or a plane without a reflection pass: left as is.
            let (Some(sides), Some(pass)) =
                (self.lut.sides(id), self.planes.get(usize::from(plane)))
            else {
                counts.passthrough_pixels += 1;
                continue;
            };
            let mut rt = cos.at(&sides[pass.side], j);
            if let Some(coverage) = coverage {
                let k = coverage[j];
                for c in 0..3 {
                    rt.t[c] = 1.0 - k + k * rt.t[c];
                    rt.r[c] *= k;
                }
            }
            if let Some(shares) = self.unit_shares(id, pass.side) {
                let at = UnitPixel {
                    pass,
                    plane: usize::from(plane),
                    frame_index: base + j,
                    band_index: j,
                    width,
                    coverage: coverage.map_or(1.0, |c| c[j]),
                };
                let out = [r_out, g_out, b_out];
                if !self.composite_unit(&mut counts, out, rt.t, shares, &at, cos) {
                    counts.passthrough_pixels += 1;
                }
                continue;
            }
            let rf = match pass.index(base + j, width) {
                Some(i) => [pass.refl[0][i], pass.refl[1][i], pass.refl[2][i]],
                None if self.outside == OutsidePass::Transmission => {
                    counts.passthrough_pixels += 1;
                    continue;
                }
                None => {
                    rt.r = [0.0; 3];
                    [0.0; 3]
                }
            };
            composite_pixel(&mut counts, [r_out, g_out, b_out], &rt, rf);
        }
        counts
    }
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
/// Eq. 8 on one glass pixel in place: `out = trans·t + refl·r` per channel, counting
/// non-finite results by their source.
#[inline(always)]
fn composite_pixel(counts: &mut KernelCounts, out: [&mut f32; 3], rt: &RtTriple, rf: [f32; 3]) {
    let tr = [*out[0], *out[1], *out[2]];
    let o: [f32; 3] = std::array::from_fn(|c| weighted(tr[c], rt.t[c], rf[c], rt.r[c]));
    for (slot, v) in out.into_iter().zip(o) {
        *slot = v;
    }
    count_composited(counts, o, tr, rf);
}

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
