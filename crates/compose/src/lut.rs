//! The compositor's own compact lookup structure, built once from the registry: per glass id,
//! per side, r and t for the three channels (method.md eqs. 11–14, `r = r0·C_r(θ)`,
//! `t = t0·C_t(θ)`, clamped to the physical range as the registry does) at
//!
//! - the 256 cos θ codes of an 8-bit mask ([`CosCode::Bits8`], cos θ = i/255): exact, the
//!   registry's own values;
//! - a fine table of [`FINE_STEPS`] + 1 points for 16-bit and float masks, linearly
//!   interpolated; its largest error (measured when it is built, at every interval midpoint)
//!   is [`GlassLut::fine_table_error`];
//! - normal incidence from `r0`, `t0` (`r0_back` for the back side) for binary masks.

use glassdb_mask::CosCode;
use glassdb_registry::{GlassRecord, RegistryTable};
use glassdb_side::Side;
use rayon::prelude::*;

use crate::shares::{GroupShares, group_shares};

/// The share tables of a glass of one group.
fn no_groups() -> GroupShares {
    [Box::new([]), Box::new([])]
}

/// Intervals of the fine table over cos θ ∈ [0, 1].
pub const FINE_STEPS: usize = 4096;

/// r and t of the three channels at one cos θ.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RtTriple {
    /// Reflectance per channel.
    pub r: [f32; 3],
    /// Transmittance per channel.
    pub t: [f32; 3],
}

/// An entry of a side's table, which the fine table interpolates linearly.
pub trait Lerp: Copy {
    /// `a + (b − a)·f`, value by value.
    fn lerp(a: &Self, b: &Self, f: f32) -> Self;
}

impl Lerp for RtTriple {
    #[inline]
    fn lerp(a: &RtTriple, b: &RtTriple, f: f32) -> RtTriple {
        let mut out = RtTriple::default();
        for c in 0..3 {
            out.r[c] = a.r[c] + (b.r[c] - a.r[c]) * f;
            out.t[c] = a.t[c] + (b.t[c] - a.t[c]) * f;
        }
        out
    }
}

impl Lerp for [f32; 3] {
    #[inline]
    fn lerp(a: &[f32; 3], b: &[f32; 3], f: f32) -> [f32; 3] {
        std::array::from_fn(|c| a[c] + (b[c] - a[c]) * f)
    }
}

/// Where cos θ lies in a fine table: the interval's start and the fraction into it (cos θ
/// clamped to [0, 1]; NaN → normal incidence).
#[inline(always)]
pub(crate) fn fine_position(cos_theta: f32) -> (usize, f32) {
    let x = if cos_theta.is_nan() {
        1.0
    } else {
        cos_theta.clamp(0.0, 1.0)
    } * FINE_STEPS as f32;
    let i = (x as usize).min(FINE_STEPS - 1);
    (i, x - i as f32)
}

/// A table of one glass seen from one side, at every cos θ the kernel looks up.
#[derive(Debug, Clone, PartialEq)]
pub struct SideLut<E> {
    /// At the cos θ of each 8-bit code, `CosCode::decode8(i)`.
    pub q8: Box<[E; 256]>,
    /// At cos θ = i/FINE_STEPS, i = 0…FINE_STEPS.
    pub fine: Box<[E; FINE_STEPS + 1]>,
    /// At normal incidence.
    pub normal: E,
}

impl<E: Lerp> SideLut<E> {
    /// The entry at an arbitrary cos θ (clamped to [0, 1]; NaN → normal incidence) by linear
    /// interpolation in the fine table.
    #[inline]
    pub fn at_cos(&self, cos_theta: f32) -> E {
        let (i, f) = fine_position(cos_theta);
        E::lerp(&self.fine[i], &self.fine[i + 1], f)
    }

    /// At an 8-bit cos θ code: an exact table entry.
    #[inline]
    pub fn at_code8(&self, code: u8) -> E {
        self.q8[usize::from(code)]
    }

    /// Every entry: the 8-bit codes', then the fine table's, then normal incidence's.
    pub fn entries(&self) -> impl Iterator<Item = &E> {
        self.q8
            .iter()
            .chain(self.fine.iter())
            .chain(std::iter::once(&self.normal))
    }
}

/// One glass seen from one side: r and t (at normal incidence r0 and t0).
pub type GlassSideLut = SideLut<RtTriple>;

/// Per-id lookup for the kernel. Ids not in the table are "unknown".
#[derive(Debug, Clone)]
pub struct GlassLut {
    /// Slot of each id (index into `slots`), or `NONE`.
    index: Vec<u32>,
    /// Front and back per glass.
    slots: Vec<[GlassSideLut; 2]>,
    /// Per slot, the pane groups' shares of r (empty for a glass of one group).
    groups: Vec<GroupShares>,
    /// Largest |interpolated − exact| of the fine table over all glasses, sides, channels, r
    /// and t, at every interval midpoint.
    pub fine_table_error: f64,
}

const NONE: u32 = u32::MAX;

fn side_index(side: Side) -> usize {
    match side {
        Side::Front => 0,
        Side::Back => 1,
    }
}

impl GlassLut {
    /// Builds the tables from any evaluator: `eval(id, side, cos θ)` returns per-channel (r, t)
    /// and `normal(id, side)` the normal-incidence values.
    pub fn from_fn(
        ids: &[u16],
        eval: impl Fn(u16, Side, f64) -> ([f64; 3], [f64; 3]) + Sync,
        normal: impl Fn(u16, Side) -> ([f64; 3], [f64; 3]) + Sync,
    ) -> GlassLut {
        let to_triple = |(r, t): ([f64; 3], [f64; 3])| RtTriple {
            r: r.map(|v| v as f32),
            t: t.map(|v| v as f32),
        };
        let mut index = vec![NONE; 65536];
        // Each id once, in the order given (the first wins); slot k is unique[k]'s.
        let mut unique = Vec::new();
        for &id in ids {
            if id != 0 && index[id as usize] == NONE {
                index[id as usize] = unique.len() as u32;
                unique.push(id);
            }
        }
        let make = |id: u16, side: Side| -> (GlassSideLut, f64) {
            let q8 = Box::new(std::array::from_fn(|code| {
                to_triple(eval(id, side, CosCode::decode8(code as u8)))
            }));
            let fine = Box::new(std::array::from_fn(|i| {
                to_triple(eval(id, side, i as f64 / FINE_STEPS as f64))
            }));
            let lut = GlassSideLut {
                q8,
                fine,
                normal: to_triple(normal(id, side)),
            };
            let mut err: f64 = 0.0;
            for i in 0..FINE_STEPS {
                let cos = (i as f64 + 0.5) / FINE_STEPS as f64;
                let (r, t) = eval(id, side, cos);
                let got = lut.at_cos(cos as f32);
                for c in 0..3 {
                    err = err
                        .max((f64::from(got.r[c]) - r[c]).abs())
                        .max((f64::from(got.t[c]) - t[c]).abs());
                }
            }
            (lut, err)
        };
        // The glasses' tables in parallel: a catalog's hundreds of glasses would otherwise
        // hold up every frame's start on one core.
        let built: Vec<([GlassSideLut; 2], f64)> = unique
            .par_iter()
            .map(|&id| {
                let (front, e1) = make(id, Side::Front);
                let (back, e2) = make(id, Side::Back);
                ([front, back], e1.max(e2))
            })
            .collect();
        let worst = built.iter().map(|b| b.1).fold(0.0, f64::max);
        let groups = built.iter().map(|_| no_groups()).collect();
        GlassLut {
            index,
            slots: built.into_iter().map(|b| b.0).collect(),
            groups,
            fine_table_error: worst,
        }
    }

    /// Builds the tables for every glass of a registry table (its `eval` and normal values).
    pub fn from_table(registry: &RegistryTable) -> GlassLut {
        let records: Vec<(u16, &GlassRecord)> =
            registry.glasses.iter().map(|g| (g.id, g)).collect();
        GlassLut::from_records(&records)
    }

    /// Builds the tables of the given records, each under the id it is paired with (the
    /// viewer's product swap: another product's record under a mask id). The first record of
    /// an id wins.
    pub fn from_records(records: &[(u16, &GlassRecord)]) -> GlassLut {
        let ids: Vec<u16> = records.iter().map(|(id, _)| *id).collect();
        let record = |id: u16| records.iter().find(|(i, _)| *i == id).map(|(_, g)| *g);
        let mut lut = GlassLut::from_fn(
            &ids,
            |id, side, cos| record(id).map_or(([0.0; 3], [0.0; 3]), |g| g.eval(side, cos)),
            |id, side| {
                record(id).map_or(([0.0; 3], [0.0; 3]), |g| {
                    let r = match side {
                        Side::Front => g.r0,
                        Side::Back => g.r0_back,
                    };
                    (r, g.t0)
                })
            },
        );
        lut.add_group_shares(&record);
        lut
    }

    /// Adds the pane-group share tables of every unit of two or more groups among the
    /// glasses of `lut` (`record` finds an id's record).
    fn add_group_shares<'r>(&mut self, record: &(impl Fn(u16) -> Option<&'r GlassRecord> + Sync)) {
        let ids: Vec<Option<u16>> = {
            let mut by_slot = vec![None; self.slots.len()];
            for (id, &slot) in self.index.iter().enumerate() {
                if slot != NONE {
                    by_slot[slot as usize] = Some(id as u16);
                }
            }
            by_slot
        };
        self.groups = ids
            .par_iter()
            .map(|id| id.and_then(record).map_or_else(no_groups, group_shares))
            .collect();
    }

    /// How many pane groups `id` reflects from (1 for a monolithic glass or an unknown id).
    pub fn group_count(&self, id: u16) -> usize {
        self.group_shares(id).map_or(1, |g| g[0].len().max(1))
    }

    /// Whether some glass of the table has two or more pane groups.
    pub fn has_units(&self) -> bool {
        self.groups.iter().any(|g| !g[0].is_empty())
    }

    /// The pane groups' share tables of `id`, front and back, in the order the rays meet them
    /// (empty for a glass of one group).
    #[inline]
    pub fn group_shares(&self, id: u16) -> Option<&GroupShares> {
        let slot = *self.index.get(id as usize)?;
        self.groups.get(slot as usize)
    }

    /// Whether `id` has an entry.
    pub fn contains(&self, id: u16) -> bool {
        self.index.get(id as usize).is_some_and(|&s| s != NONE)
    }

    /// The tables of `id` seen from `side`.
    #[inline]
    pub fn side(&self, id: u16, side: Side) -> Option<&GlassSideLut> {
        let slot = *self.index.get(id as usize)?;
        self.slots.get(slot as usize).map(|s| &s[side_index(side)])
    }

    /// Slot lookup for the kernel: both sides of `id`.
    #[inline]
    pub(crate) fn sides(&self, id: u16) -> Option<&[GlassSideLut; 2]> {
        let slot = *self.index.get(id as usize)?;
        self.slots.get(slot as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fine_table_error_is_small_for_a_smooth_curve() {
        // r = 0.04 + 0.96 (1 − cos)^5 (Schlick), t = 0.9 cos: interpolation error ≤ h²/8 max|f''|.
        let lut = GlassLut::from_fn(
            &[3],
            |_, _, c| ([0.04 + 0.96 * (1.0 - c).powi(5); 3], [0.9 * c; 3]),
            |_, _| ([0.04; 3], [0.9; 3]),
        );
        let h = 1.0 / FINE_STEPS as f64;
        let bound = h * h / 8.0 * 0.96 * 20.0 + 1e-7; // f'' ≤ 20·0.96, plus f32 rounding
        assert!(
            lut.fine_table_error <= bound,
            "{} > {bound}",
            lut.fine_table_error
        );
        let s = lut.side(3, Side::Front).unwrap();
        assert_eq!(s.at_code8(255).r[0], 0.04);
        assert_eq!(s.at_code8(0).r[0], 1.0);
        assert!((s.at_cos(0.5).t[1] - 0.45).abs() < 1e-6);
        assert!(lut.contains(3) && !lut.contains(4) && !lut.contains(0));
    }

    #[test]
    fn code8_entries_are_the_registry_at_the_codes_cos_theta() {
        // The 8-bit entries equal the registry's eval at the code's cos θ, in f32, bit for bit.
        let reg = glassdb_registry::default_registry().unwrap();
        let table = reg.default_table();
        let lut = GlassLut::from_table(table);
        let g = &table.glasses[0];
        for side in [Side::Front, Side::Back] {
            let s = lut.side(g.id, side).unwrap();
            for code in [0u8, 1, 77, 128, 254, 255] {
                let (r, t) = g.eval(side, CosCode::decode8(code));
                let e = s.at_code8(code);
                for c in 0..3 {
                    assert_eq!(e.r[c], r[c] as f32);
                    assert_eq!(e.t[c], t[c] as f32);
                }
            }
        }
    }
}
