//! The two-flux interreflection of layers in series, sample by sample (a wavelength or a
//! colour channel): the system's T, Rf, Rb; each layer's absorptance for light from either
//! side; and each pane group's share of the system reflectance (docs/stack.md, eqs. 1–6;
//! ISO 15099 §6 / ISO 9050 §5.3 / EN 410 §5; Windows-CalcEngine `CEquivalentLayerSingleComponent`
//! and `CAbsorptancesMultiPane`).

use std::ops::Range;

use crate::layer::LayerValues;

/// A quantity for light from outdoors (`front`) and for light from indoors (`back`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FrontBack<T> {
    /// For light from outdoors.
    pub front: T,
    /// For light from indoors.
    pub back: T,
}

/// The optics of a unit at one angle for some quantity (`V`: a spectrum, a colour's three
/// channels, or one averaged value): system T, Rf, Rb, absorptance of each layer, and the
/// share of each pane group in the system reflectance.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Optics<V> {
    /// Transmittance (the same from both sides).
    pub t: V,
    /// Reflectance for light from outdoors.
    pub rf: V,
    /// Reflectance for light from indoors.
    pub rb: V,
    /// Per layer (outside first), the fraction absorbed of light from outdoors and from indoors.
    pub absorptance: FrontBack<Vec<V>>,
    /// Per pane group (outside first), its share of `rf` (front) and of `rb` (back): they sum
    /// to that reflectance.
    pub share: FrontBack<Vec<V>>,
}

impl<V> Optics<V> {
    /// The same optics with every value mapped by `f` (e.g. a spectrum integrated), called in
    /// the order t, rf, rb, each layer's absorptance (front, then back), each group's share
    /// (front, then back): the order in which messages name them.
    pub fn try_map<U, E>(&self, mut f: impl FnMut(&V) -> Result<U, E>) -> Result<Optics<U>, E> {
        let t = f(&self.t)?;
        let rf = f(&self.rf)?;
        let rb = f(&self.rb)?;
        let mut all = |vs: &[V]| vs.iter().map(&mut f).collect::<Result<Vec<U>, E>>();
        let mut both = |fb: &FrontBack<Vec<V>>| -> Result<FrontBack<Vec<U>>, E> {
            Ok(FrontBack {
                front: all(&fb.front)?,
                back: all(&fb.back)?,
            })
        };
        Ok(Optics {
            t,
            rf,
            rb,
            absorptance: both(&self.absorptance)?,
            share: both(&self.share)?,
        })
    }
}

/// `1/(1 − Rb·Rf)`: the light bouncing between two layers facing each other with
/// reflectances `rb` and `rf`. At grazing incidence both are 1 and no light reaches the gap (the
/// transmittances are 0); the factor is then 0 rather than infinite.
#[inline]
fn interreflection(rb: f64, rf: f64) -> f64 {
    let den = 1.0 - rb * rf;
    if den > 0.0 { 1.0 / den } else { 0.0 }
}

/// T, Rf, Rb of one sample of an equivalent layer.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Rt {
    t: f64,
    rf: f64,
    rb: f64,
}

impl Rt {
    /// `self` followed (on the inner side) by `next`: eqs. 1–3,
    /// `T = T1·T2/(1 − Rb1·Rf2)`, `Rf = Rf1 + T1²·Rf2/(1 − Rb1·Rf2)`,
    /// `Rb = Rb2 + T2²·Rb1/(1 − Rb1·Rf2)`.
    #[inline]
    fn then(self, next: Rt) -> Rt {
        let inter = interreflection(self.rb, next.rf);
        Rt {
            t: self.t * next.t * inter,
            rf: self.rf + self.t * self.t * next.rf * inter,
            rb: next.rb + next.t * next.t * self.rb * inter,
        }
    }

    /// The same layer seen from the other side.
    #[inline]
    fn reversed(self) -> Rt {
        Rt {
            t: self.t,
            rf: self.rb,
            rb: self.rf,
        }
    }
}

/// Combines `layers` (outside first, each on the same samples) whose pane groups are `groups`
/// (consecutive ranges of layer indices covering them all, outside first).
pub fn combine(layers: &[LayerValues], groups: &[Range<usize>]) -> Optics<Vec<f64>> {
    let n = layers.first().map_or(0, |l| l.t.len());
    let nl = layers.len();
    let ng = groups.len();
    let mut out = Optics {
        t: vec![0.0; n],
        rf: vec![0.0; n],
        rb: vec![0.0; n],
        absorptance: FrontBack {
            front: vec![vec![0.0; n]; nl],
            back: vec![vec![0.0; n]; nl],
        },
        share: FrontBack {
            front: vec![vec![0.0; n]; ng],
            back: vec![vec![0.0; n]; ng],
        },
    };
    let zero = Rt {
        t: 0.0,
        rf: 0.0,
        rb: 0.0,
    };
    let mut rt = vec![zero; nl];
    let mut reversed = vec![zero; nl];
    let mut group_rt = vec![zero; ng];
    let mut groups_reversed = vec![zero; ng];
    let mut abs = vec![0.0; nl];
    let mut shares = vec![0.0; ng];
    let mut r_behind = vec![0.0; nl.max(ng) + 1];
    for i in 0..n {
        for (r, l) in rt.iter_mut().zip(layers) {
            *r = Rt {
                t: l.t[i],
                rf: l.rf[i],
                rb: l.rb[i],
            };
        }
        let system = rt[1..].iter().fold(rt[0], |acc, &l| acc.then(l));
        out.t[i] = system.t;
        out.rf[i] = system.rf;
        out.rb[i] = system.rb;
        from_both_sides(
            &rt,
            &mut reversed,
            (&mut abs, &mut r_behind),
            absorptances,
            &mut out.absorptance,
            i,
        );
        for (g, range) in group_rt.iter_mut().zip(groups) {
            let members = &rt[range.clone()];
            *g = members[1..].iter().fold(members[0], |acc, &l| acc.then(l));
        }
        from_both_sides(
            &group_rt,
            &mut groups_reversed,
            (&mut shares, &mut r_behind),
            reflectance_shares,
            &mut out.share,
            i,
        );
    }
    out
}

/// `per_item` (absorptances, reflectance shares) of `items` lit from the front, then from the
/// back (`items` in reverse order, each turned round, in `reversed`), written at sample `i` of
/// `out`'s front and back, both indexed as `items` are. `per_item` is given the reflectance
/// behind each item ([`reflectance_behind`], computed into `r_behind`).
fn from_both_sides(
    items: &[Rt],
    reversed: &mut [Rt],
    (values, r_behind): (&mut [f64], &mut [f64]),
    per_item: fn(&[Rt], &[f64], &mut [f64]),
    out: &mut FrontBack<Vec<Vec<f64>>>,
    i: usize,
) {
    reflectance_behind(items, r_behind);
    per_item(items, r_behind, values);
    for (f, v) in out.front.iter_mut().zip(values.iter()) {
        f[i] = *v;
    }
    for (r, l) in reversed.iter_mut().zip(items.iter().rev()) {
        *r = l.reversed();
    }
    reflectance_behind(reversed, r_behind);
    per_item(reversed, r_behind, values);
    for (b, v) in out.back.iter_mut().rev().zip(values.iter()) {
        b[i] = *v;
    }
}

/// `r_behind[k]`: the front reflectance of `items[k..]` combined (0 at `k = items.len()`),
/// from the last forwards: `r_k = Rf_k + T_k²·r_{k+1}/(1 − Rb_k·r_{k+1})`.
fn reflectance_behind(items: &[Rt], r_behind: &mut [f64]) {
    let n = items.len();
    r_behind[n] = 0.0;
    for k in (0..n).rev() {
        let l = items[k];
        let r = r_behind[k + 1];
        r_behind[k] = l.rf + l.t * l.t * r * interreflection(l.rb, r);
    }
}

/// Absorptance of each layer for unit flux arriving at the first (eqs. 4–5): with
/// `r_k = Rf_k + T_k²·r_{k+1}/(1 − Rb_k·r_{k+1})` the reflectance of layers k… (`r_behind`,
/// [`reflectance_behind`]), `τ_k = T_k/(1 − Rb_k·r_{k+1})` is the flux layer k passes on per
/// unit arriving; then `I⁻_0 = 1`, `I⁻_{k+1} = τ_k·I⁻_k`, `I⁺_k = r_{k+1}·I⁻_{k+1}` and
/// `A_k = I⁻_k·(1 − T_k − Rf_k) + I⁺_k·(1 − T_k − Rb_k)`.
fn absorptances(layers: &[Rt], r_behind: &[f64], abs: &mut [f64]) {
    let n = layers.len();
    let mut down = 1.0;
    for k in 0..n {
        let l = layers[k];
        let r = r_behind[k + 1];
        let passed = l.t * interreflection(l.rb, r) * down;
        let up = r * passed;
        abs[k] = down * (1.0 - l.t - l.rf) + up * (1.0 - l.t - l.rb);
        down = passed;
    }
}

/// Each group's share of the reflectance of `groups` in series (eq. 6): with `B_k` the groups
/// k… combined, `s_1 = Rf(G_1)`, and `s_k = Π_{j<k} T_j²/(1 − Rb(G_j)·Rf(B_{j+1})) · Rf(G_k)`:
/// light first reflected by group k, with every interreflection in front of it; Σ s_k = Rf(B_1).
/// `r_behind[k]` is `Rf(B_k)` ([`reflectance_behind`]).
fn reflectance_shares(groups: &[Rt], r_behind: &[f64], shares: &mut [f64]) {
    let n = groups.len();
    let mut reach = 1.0;
    for k in 0..n {
        let g = groups[k];
        shares[k] = reach * g.rf;
        reach *= g.t * g.t * interreflection(g.rb, r_behind[k + 1]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn layer(t: f64, rf: f64, rb: f64) -> LayerValues {
        LayerValues {
            t: vec![t],
            rf: vec![rf],
            rb: vec![rb],
        }
    }

    /// The two-flux model by brute force: the flux arriving at each layer from either side is
    /// split into transmitted, reflected and absorbed parts, round after round, until what is
    /// still travelling is negligible; tallies what leaves each side and what each layer
    /// absorbs. Independent of the closed forms above.
    fn trace(layers: &[(f64, f64, f64)], from_front: bool) -> (f64, f64, Vec<f64>) {
        let n = layers.len();
        let mut abs = vec![0.0; n];
        let (mut out_front, mut out_back) = (0.0, 0.0);
        // down[k]: arriving at layer k travelling inwards; up[k]: travelling outwards
        let (mut down, mut up) = (vec![0.0; n], vec![0.0; n]);
        if from_front {
            down[0] = 1.0;
        } else {
            up[n - 1] = 1.0;
        }
        for _ in 0..1_000_000 {
            let (mut next_down, mut next_up) = (vec![0.0; n], vec![0.0; n]);
            for k in 0..n {
                let (t, rf, rb) = layers[k];
                abs[k] += down[k] * (1.0 - t - rf) + up[k] * (1.0 - t - rb);
                // inwards: transmitted goes on inwards, reflected turns outwards
                if k + 1 < n {
                    next_down[k + 1] += down[k] * t
                } else {
                    out_back += down[k] * t
                }
                if k > 0 {
                    next_up[k - 1] += down[k] * rf
                } else {
                    out_front += down[k] * rf
                }
                // outwards: transmitted goes on outwards, reflected turns inwards
                if k > 0 {
                    next_up[k - 1] += up[k] * t
                } else {
                    out_front += up[k] * t
                }
                if k + 1 < n {
                    next_down[k + 1] += up[k] * rb
                } else {
                    out_back += up[k] * rb
                }
            }
            down = next_down;
            up = next_up;
            if down.iter().chain(&up).sum::<f64>() < 1e-15 {
                break;
            }
        }
        if from_front {
            (out_back, out_front, abs)
        } else {
            (out_front, out_back, abs)
        }
    }

    proptest! {
        #[test]
        fn closed_forms_match_a_ray_trace(
            raw in proptest::collection::vec((0.0f64..0.9, 0.0f64..0.95, 0.0f64..0.95), 1..5),
            split in 0usize..4,
        ) {
            // T + R ≤ 1 on both sides
            let layers: Vec<(f64, f64, f64)> = raw
                .iter()
                .map(|&(t, a, b)| (t, a * (1.0 - t), b * (1.0 - t)))
                .collect();
            let values: Vec<LayerValues> = layers.iter().map(|&(t, rf, rb)| layer(t, rf, rb)).collect();
            let n = layers.len();
            let cut = split.min(n - 1);
            let groups: Vec<Range<usize>> = if cut == 0 {
                std::iter::once(0..n).collect()
            } else {
                vec![0..cut, cut..n]
            };
            let o = combine(&values, &groups);
            let (t, r, abs) = trace(&layers, true);
            prop_assert!((o.t[0] - t).abs() < 1e-9 && (o.rf[0] - r).abs() < 1e-9);
            for (ours, traced) in o.absorptance.front.iter().zip(&abs) {
                prop_assert!((ours[0] - traced).abs() < 1e-9);
            }
            let (tb, rb, absb) = trace(&layers, false);
            prop_assert!((o.t[0] - tb).abs() < 1e-9 && (o.rb[0] - rb).abs() < 1e-9);
            for (ours, traced) in o.absorptance.back.iter().zip(&absb) {
                prop_assert!((ours[0] - traced).abs() < 1e-9);
            }
            // energy: T + R + ΣA = 1 from each side; shares sum to R
            let sum_a: f64 = o.absorptance.front.iter().map(|a| a[0]).sum();
            prop_assert!((o.t[0] + o.rf[0] + sum_a - 1.0).abs() < 1e-12);
            let sf: f64 = o.share.front.iter().map(|s| s[0]).sum();
            let sb: f64 = o.share.back.iter().map(|s| s[0]).sum();
            prop_assert!((sf - o.rf[0]).abs() < 1e-12 && (sb - o.rb[0]).abs() < 1e-12);
        }
    }

    #[test]
    fn double_pane_shares_are_the_issue_formulas() {
        let (t1, rf1, rb1) = (0.8, 0.1, 0.12);
        let (t2, rf2, rb2) = (0.85, 0.08, 0.08);
        let o = combine(&[layer(t1, rf1, rb1), layer(t2, rf2, rb2)], &[0..1, 1..2]);
        assert_eq!(o.share.front[0][0], rf1);
        let inner = t1 * t1 * rf2 / (1.0 - rb1 * rf2);
        assert!((o.share.front[1][0] - inner).abs() < 1e-15);
        assert_eq!(o.share.back[1][0], rb2);
        let outer_from_inside = t2 * t2 * rb1 / (1.0 - rf2 * rb1);
        assert!((o.share.back[0][0] - outer_from_inside).abs() < 1e-15);
        assert!((o.t[0] - t1 * t2 / (1.0 - rb1 * rf2)).abs() < 1e-15);
    }
}
