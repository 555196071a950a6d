//! A registry glass as the thin-pane shader of the Blender-side script: r (front and back) and
//! t per RGB channel tabulated at [`STOPS`] values of cos θ, for its Color Ramp nodes.

use glassdb_registry::{GlassRecord, Side};
use serde::Serialize;

/// Stops of a Blender Color Ramp (its maximum is 32).
pub const STOPS: usize = 32;

/// One glass material's tables, as the script reads them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThinPane {
    /// The Blender material.
    pub material: String,
    /// Its registry id.
    pub id: u16,
    /// cos θ of each stop, ascending from 0 to 1 (quadratic spacing: dense near grazing, where
    /// the curves bend most).
    pub cos: Vec<f64>,
    /// Front reflectance per channel at each stop.
    pub r_front: Vec<[f64; 3]>,
    /// Back reflectance per channel at each stop.
    pub r_back: Vec<[f64; 3]>,
    /// Transmittance per channel at each stop.
    pub t: Vec<[f64; 3]>,
}

/// The stops' cos θ.
pub fn stop_cosines() -> Vec<f64> {
    (0..STOPS)
        .map(|k| {
            let x = k as f64 / (STOPS - 1) as f64;
            x * x
        })
        .collect()
}

impl ThinPane {
    /// The tables of `glass` (r = r0·C_r(cos θ), t = t0·C_t(cos θ), as the compositor
    /// evaluates them: [`GlassRecord::eval_raw`]), each clamped to 0–1.
    pub fn of(material: &str, glass: &GlassRecord) -> ThinPane {
        let cos = stop_cosines();
        // `pick` takes r or t from eval_raw's (r, t).
        let table = |side: Side, pick: fn(RAndT) -> [f64; 3]| -> Vec<[f64; 3]> {
            cos.iter()
                .map(|&c| pick(glass.eval_raw(side, c)).map(unit))
                .collect()
        };
        ThinPane {
            material: material.to_string(),
            id: glass.id,
            r_front: table(Side::Front, |(r, _)| r),
            r_back: table(Side::Back, |(r, _)| r),
            t: table(Side::Front, |(_, t)| t),
            cos,
        }
    }
}

/// r and t per channel, as [`GlassRecord::eval_raw`] gives them.
type RAndT = ([f64; 3], [f64; 3]);

/// `v` clamped to 0–1.
fn unit(v: f64) -> f64 {
    v.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest difference, over `samples` cos θ in 0–1 and every channel, between the
    /// ramp's piecewise-linear r (front) or t and the curve itself (what the ramp costs).
    fn ramp_error(pane: &ThinPane, glass: &GlassRecord, samples: usize) -> f64 {
        let lerp = |tab: &[[f64; 3]], c: f64, ch: usize| {
            let k = pane.cos.partition_point(|&x| x <= c).clamp(1, STOPS - 1);
            let (c0, c1) = (pane.cos[k - 1], pane.cos[k]);
            let w = ((c - c0) / (c1 - c0)).clamp(0.0, 1.0);
            tab[k - 1][ch] * (1.0 - w) + tab[k][ch] * w
        };
        let mut worst: f64 = 0.0;
        for s in 0..=samples {
            let c = s as f64 / samples as f64;
            let (r, t) = glass.eval_raw(Side::Front, c);
            let (r, t) = (r.map(unit), t.map(unit));
            for ch in 0..3 {
                worst = worst
                    .max((lerp(&pane.r_front, c, ch) - r[ch]).abs())
                    .max((lerp(&pane.t, c, ch) - t[ch]).abs());
            }
        }
        worst
    }

    #[test]
    fn stops_span_zero_to_one_ascending() {
        let c = stop_cosines();
        assert_eq!(c.len(), STOPS);
        assert_eq!((c[0], c[STOPS - 1]), (0.0, 1.0));
        assert!(c.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn the_tables_are_r0_c_r_and_t0_c_t_clamped() {
        let registry = glassdb_registry::default_registry().unwrap();
        for glass in &registry.default_table().glasses {
            let pane = ThinPane::of("m", glass);
            for (k, &c) in pane.cos.iter().enumerate() {
                for ch in 0..3 {
                    let by_hand = |v0: &[f64; 3], curves: &[glassdb_registry::AngleCurve; 3]| {
                        (v0[ch] * curves[ch].eval(c)).clamp(0.0, 1.0)
                    };
                    assert_eq!(pane.r_front[k][ch], by_hand(&glass.r0, &glass.c_r));
                    assert_eq!(pane.r_back[k][ch], by_hand(&glass.r0_back, &glass.c_r_back));
                    assert_eq!(pane.t[k][ch], by_hand(&glass.t0, &glass.c_t));
                }
            }
        }
    }

    #[test]
    fn the_bundled_glasses_ramp_within_two_thousandths() {
        let registry = glassdb_registry::default_registry().unwrap();
        for glass in &registry.default_table().glasses {
            let pane = ThinPane::of("m", glass);
            // At normal incidence the ramp is the registry's value itself.
            assert_eq!(
                pane.t[STOPS - 1][1],
                (glass.t0[1] * glass.c_t[1].eval(1.0)).clamp(0.0, 1.0)
            );
            let err = ramp_error(&pane, glass, 2000);
            // Measured: 9.3e-4 (id 1), 8.9e-4 (id 5), absolute, in r or t.
            assert!(err < 0.002, "glass {}: ramp error {err}", glass.id);
        }
    }
}
