//! Pane-group reflectance shares of a unit (docs/stack.md eq. 6, issue 27): per glass id and
//! side, the share `r_k(θ)` of each pane group in the order the camera's rays meet them (from
//! the front: outside first; from the back: inside first), tabulated like [`crate::lut`]'s r
//! and t. The shares are scaled to sum exactly to the table's system r at every entry, so a
//! frame whose group passes are all the same image composites as the one-group frame.

use glassdb_mask::CosCode;
use glassdb_registry::GlassRecord;
use glassdb_side::Side;

use crate::lut::{FINE_STEPS, SideLut};

/// One pane group's share of the reflectance, seen from one side, per channel, tabulated as
/// [`crate::lut::GlassSideLut`] is (at normal incidence: the group's `r0`, scaled to the
/// system's).
pub type ShareSideLut = SideLut<[f32; 3]>;

/// The pane groups of one glass, per side (0 front, 1 back), in the order the rays meet them;
/// empty for a glass of one group (a monolithic glass or a unit of one pane group).
pub type GroupShares = [Box<[ShareSideLut]>; 2];

/// The group shares of `record`: empty unless it is a unit of two or more pane groups.
pub fn group_shares(record: &GlassRecord) -> GroupShares {
    let groups = match &record.unit {
        Some(u) if u.groups.len() > 1 => &u.groups,
        _ => return [Box::new([]), Box::new([])],
    };
    let side_tables = |side: Side| -> Box<[ShareSideLut]> {
        // The order the rays meet the groups: outside first from the front, inside first from
        // the back.
        let order: Vec<usize> = match side {
            Side::Front => (0..groups.len()).collect(),
            Side::Back => (0..groups.len()).rev().collect(),
        };
        // Every group's share at one cos θ, scaled so that they sum to the system's r.
        let at = |cos: f64| -> Vec<[f32; 3]> {
            let system = record.eval(side, cos).0;
            let raw: Vec<[f64; 3]> = order.iter().map(|&k| groups[k].eval(side, cos)).collect();
            scaled(&raw, system)
        };
        let normal = {
            let system = match side {
                Side::Front => record.r0,
                Side::Back => record.r0_back,
            };
            let raw: Vec<[f64; 3]> = order
                .iter()
                .map(|&k| match side {
                    Side::Front => groups[k].r0,
                    Side::Back => groups[k].r0_back,
                })
                .collect();
            scaled(&raw, system)
        };
        let q8: Vec<Vec<[f32; 3]>> = (0..256)
            .map(|code| at(CosCode::decode8(code as u8)))
            .collect();
        let fine: Vec<Vec<[f32; 3]>> = (0..=FINE_STEPS)
            .map(|i| at(i as f64 / FINE_STEPS as f64))
            .collect();
        (0..order.len())
            .map(|g| ShareSideLut {
                q8: Box::new(std::array::from_fn(|i| q8[i][g])),
                fine: Box::new(std::array::from_fn(|i| fine[i][g])),
                normal: normal[g],
            })
            .collect()
    };
    [side_tables(Side::Front), side_tables(Side::Back)]
}

/// `raw` shares scaled per channel to sum to `system` (all of it on the first group where the
/// shares sum to 0).
fn scaled(raw: &[[f64; 3]], system: [f64; 3]) -> Vec<[f32; 3]> {
    let mut out = vec![[0.0f32; 3]; raw.len()];
    for c in 0..3 {
        let sum: f64 = raw.iter().map(|s| s[c]).sum();
        if sum > 0.0 {
            for (o, s) in out.iter_mut().zip(raw) {
                o[c] = (s[c] * system[c] / sum) as f32;
            }
        } else if let Some(first) = out.first_mut() {
            first[c] = system[c] as f32;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn double_clear() -> GlassRecord {
        let reg = glassdb_registry::default_registry().unwrap();
        reg.default_table()
            .glasses
            .iter()
            .find(|g| g.unit.as_ref().is_some_and(|u| u.groups.len() == 2))
            .expect("the bundled catalog has a double unit")
            .clone()
    }

    #[test]
    fn shares_follow_the_registry_and_sum_to_the_system_r() {
        let g = double_clear();
        let unit = g.unit.as_ref().unwrap();
        let shares = group_shares(&g);
        for (s, side) in [(0, Side::Front), (1, Side::Back)] {
            assert_eq!(shares[s].len(), 2);
            for code in [0u8, 40, 128, 200, 255] {
                let cos = CosCode::decode8(code);
                let system = g.eval(side, cos).0;
                // The first group the rays meet: the outer pane from the front, the inner from
                // the back.
                let first = match side {
                    Side::Front => &unit.groups[0],
                    Side::Back => &unit.groups[1],
                };
                let reg_first = first.eval(side, cos);
                for c in 0..3 {
                    let sum = shares[s][0].at_code8(code)[c] + shares[s][1].at_code8(code)[c];
                    assert!(
                        (f64::from(sum) - system[c]).abs() < 1e-6,
                        "{sum} vs {system:?}"
                    );
                    // Scaling to the system r moves a share by at most the curves' tolerance.
                    let got = f64::from(shares[s][0].at_code8(code)[c]);
                    assert!((got - reg_first[c]).abs() < 2e-3, "{got} vs {reg_first:?}");
                }
            }
        }
        // The inner pane of a clear double unit gives a good part of the reflection (docs/stack.md:
        // 44 % at 0°).
        let inner = shares[0][1].at_code8(255)[1]
            / (shares[0][0].at_code8(255)[1] + shares[0][1].at_code8(255)[1]);
        assert!((0.3..0.5).contains(&inner), "{inner}");
    }

    #[test]
    fn a_monolithic_glass_has_no_group_tables() {
        let reg = glassdb_registry::default_registry().unwrap();
        let g = reg
            .default_table()
            .glasses
            .iter()
            .find(|g| g.unit.is_none())
            .unwrap();
        let s = group_shares(g);
        assert!(s[0].is_empty() && s[1].is_empty());
    }
}
