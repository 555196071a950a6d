//! Hemispherical (diffuse-diffuse) values of a glass: what it passes and reflects of light that
//! arrives from a whole hemisphere of uniform radiance, such as the sky seen through a window
//! (docs/registry.md, "Hemispherical values"). `x_dif = 2∫₀^{π/2} x(θ) cos θ sin θ dθ
//! = 2∫₀¹ x(μ) μ dμ` with μ = cos θ, per channel, integrated on the curves as the compositor
//! evaluates them ([`GlassRecord::eval`]: clamped to the physical range).

use glassdb_side::Side;
use serde::{Deserialize, Serialize};

use crate::record::GlassRecord;

/// Hemispherical (diffuse-diffuse) values per channel R, G, B (see the module).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HemisphericalRecord {
    /// `t_dif`: transmittance of uniform hemispherical light, the same from both sides (as
    /// `t(θ)` is).
    pub transmittance: [f64; 3],
    /// `r_dif` of the front (viewer-side) face.
    pub reflectance: [f64; 3],
    /// `r_dif` of the back face.
    pub reflectance_back: [f64; 3],
}

/// Intervals of the composite Simpson rule over μ ∈ [0, 1] (even). The curves are polynomials
/// (Simpson's error ~h⁴), and a kink where the physical clamp starts near grazing costs
/// O(h²) ≈ 6e-8: far below the 1e-6 that validation allows between stored and recomputed values.
const SIMPSON_INTERVALS: usize = 4096;

/// How far a stored value may be from the one recomputed from the curves (absolute): the JSON
/// round trip and a different summation order change the last digits only.
pub(crate) const HEMISPHERICAL_TOLERANCE: f64 = 1e-6;

impl HemisphericalRecord {
    /// The values of `glass` integrated from its curves.
    pub fn of(glass: &GlassRecord) -> HemisphericalRecord {
        let n = SIMPSON_INTERVALS;
        let h = 1.0 / n as f64;
        let mut out = HemisphericalRecord {
            transmittance: [0.0; 3],
            reflectance: [0.0; 3],
            reflectance_back: [0.0; 3],
        };
        for i in 0..=n {
            let mu = i as f64 * h;
            let weight = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            // 2∫ x(μ) μ dμ ≈ 2 · h/3 · Σ w_i x(μ_i) μ_i.
            let w = 2.0 * weight * mu * h / 3.0;
            let (r_front, t) = glass.eval(Side::Front, mu);
            let (r_back, _) = glass.eval(Side::Back, mu);
            for c in 0..3 {
                out.transmittance[c] += w * t[c];
                out.reflectance[c] += w * r_front[c];
                out.reflectance_back[c] += w * r_back[c];
            }
        }
        out
    }

    /// The values with the front and back faces swapped (a glass turned round).
    pub(crate) fn turned_round(self) -> HemisphericalRecord {
        HemisphericalRecord {
            reflectance: self.reflectance_back,
            reflectance_back: self.reflectance,
            ..self
        }
    }

    /// The values as `(field, per-channel values)`, for validation and messages.
    pub(crate) fn fields(&self) -> [(&'static str, &[f64; 3]); 3] {
        [
            ("hemispherical.transmittance", &self.transmittance),
            ("hemispherical.reflectance", &self.reflectance),
            ("hemispherical.reflectance_back", &self.reflectance_back),
        ]
    }
}

impl GlassRecord {
    /// The glass's hemispherical values: the stored ones, or, for a record without them (a
    /// registry of schema 2 to 4 written before they were stored, a hand-made glass), integrated
    /// from its curves.
    pub fn hemispherical(&self) -> HemisphericalRecord {
        self.hemispherical
            .unwrap_or_else(|| HemisphericalRecord::of(self))
    }

    /// `t_dif` per channel (the same from both sides): [`GlassRecord::hemispherical`]'s
    /// transmittance.
    pub fn t_dif(&self) -> [f64; 3] {
        self.hemispherical().transmittance
    }
}

#[cfg(test)]
mod tests {
    use glassdb_fit::{Basis, CosPolynomial, FitSummary};

    use super::*;
    use crate::record::AngleCurve;

    fn curve(basis: Basis, powers: Vec<u32>, coefficients: Vec<f64>) -> AngleCurve {
        AngleCurve {
            fit: FitSummary::exact(*powers.iter().max().unwrap_or(&0)),
            polynomial: CosPolynomial {
                basis,
                powers,
                coefficients,
            },
            tolerance: 0.002,
        }
    }

    /// Closed forms: a constant x gives x (2∫μ dμ = 1); x = x0·μ gives 2·x0/3; x = x0·μ² gives
    /// x0/2.
    #[test]
    fn polynomial_curves_integrate_to_their_closed_forms() {
        let flat = curve(Basis::Full, vec![0], vec![1.0]);
        let linear = curve(Basis::Paper, vec![1], vec![1.0]);
        let square = curve(Basis::Paper, vec![2], vec![1.0]);
        let g = GlassRecord::with_shared_curves(
            1,
            "closed forms",
            "uncoated",
            [[0.1, 0.2, 0.3], [0.6, 0.5, 0.4], [0.05, 0.04, 0.03]],
            [&flat, &linear, &square],
        );
        let h = HemisphericalRecord::of(&g);
        for c in 0..3 {
            assert!((h.reflectance[c] - g.r0[c]).abs() < 1e-12, "{h:?}");
            assert!(
                (h.transmittance[c] - 2.0 * g.t0[c] / 3.0).abs() < 1e-12,
                "{h:?}"
            );
            assert!(
                (h.reflectance_back[c] - g.r0_back[c] / 2.0).abs() < 1e-12,
                "{h:?}"
            );
        }
        assert_eq!(g.hemispherical(), h);
        assert_eq!(g.t_dif(), h.transmittance);
        let turned = h.turned_round();
        assert_eq!(
            (turned.reflectance, turned.reflectance_back),
            (h.reflectance_back, h.reflectance)
        );
    }

    /// The integral is of the clamped curves the compositor uses: r = 0.9·(2 − μ) reaches 1 at
    /// μ = 8/9 and is held there, so r_dif = 2∫₀^{8/9} μ dμ + 2∫_{8/9}^1 0.9(2 − μ)μ dμ.
    #[test]
    fn the_integral_follows_the_physical_clamp() {
        let steep = curve(Basis::Full, vec![0, 1], vec![2.0, -1.0]);
        let t = curve(Basis::Paper, vec![1], vec![1.0]);
        let g = GlassRecord::with_shared_curves(
            2,
            "clamped",
            "uncoated",
            [[0.9; 3], [0.0; 3], [0.9; 3]],
            [&steep, &t, &steep],
        );
        let a: f64 = 8.0 / 9.0;
        let upper = |m: f64| 0.9 * (m * m - m * m * m / 3.0);
        let exact = a * a + 2.0 * (upper(1.0) - upper(a));
        let h = HemisphericalRecord::of(&g);
        assert!(
            (h.reflectance[0] - exact).abs() < 1e-6,
            "{} {exact}",
            h.reflectance[0]
        );
        assert_eq!(h.transmittance, [0.0; 3]);
    }
}

#[cfg(test)]
mod stored {
    use glassdb_fit::{Basis, CosPolynomial, FitSummary};
    use glassdb_spectral::IntegrationSettings;

    use super::*;
    use crate::record::AngleCurve;
    use crate::{Registry, RegistryError, RegistryTable};

    fn registry(hemispherical: bool) -> Registry {
        let c = |basis, powers: Vec<u32>, coefficients| AngleCurve {
            fit: FitSummary::exact(2),
            polynomial: CosPolynomial {
                basis,
                powers,
                coefficients,
            },
            tolerance: 0.002,
        };
        let cr = c(Basis::Full, vec![0, 1, 2], vec![10.0, -18.0, 9.0]);
        let ct = c(Basis::Paper, vec![1, 2], vec![1.5, -0.5]);
        let mut g = GlassRecord::with_shared_curves(
            4,
            "hand-made",
            "uncoated",
            [[0.1; 3], [0.8, 0.7, 0.6], [0.05; 3]],
            [&cr, &ct, &cr],
        );
        if hemispherical {
            g.hemispherical = Some(HemisphericalRecord::of(&g));
        }
        Registry::single(RegistryTable {
            spectral: IntegrationSettings::default(),
            light: None,
            glasses: vec![g],
        })
    }

    /// A registry written before the values were stored reads as it is and integrates them;
    /// stored values survive the JSON round trip and agree with the integral; a value edited
    /// away from the curves is refused, naming glass, field and channel.
    #[test]
    fn stored_values_round_trip_and_must_match_the_curves() {
        let old = registry(false);
        let text = old.to_json_string().unwrap();
        assert!(!text.contains("hemispherical"), "{text}");
        let read = Registry::from_json_str(&text, "old.json").unwrap();
        let new = registry(true);
        let g = &read.default_table().glasses[0];
        assert_eq!(g.hemispherical, None);
        assert_eq!(
            Some(g.hemispherical()),
            new.default_table().glasses[0].hemispherical
        );

        let text = new.to_json_string().unwrap();
        assert!(text.contains("\"hemispherical\""), "{text}");
        assert_eq!(Registry::from_json_str(&text, "new.json").unwrap(), new);

        let mut edited = new.clone();
        let h = edited.tables_mut()[0].glasses[0]
            .hemispherical
            .as_mut()
            .unwrap();
        h.transmittance[1] += 0.01;
        let text = edited.to_json_string().unwrap();
        let err = Registry::from_json_str(&text, "edited.json").unwrap_err();
        assert!(matches!(err, RegistryError::Hemispherical { .. }), "{err}");
        let e = err.to_string();
        assert!(
            e.starts_with(
                "edited.json: glass id 4 (\"hand-made\"): hemispherical.transmittance[1] (G)"
            ),
            "{e}"
        );
        let mut nan = new;
        nan.tables_mut()[0].glasses[0]
            .hemispherical
            .as_mut()
            .unwrap()
            .reflectance_back[2] = f64::NAN;
        assert!(matches!(
            nan.validate(),
            Err(RegistryError::Hemispherical { .. })
        ));
    }

    /// Turning a glass round swaps its reflectances and keeps the stored values equal to the
    /// integral of the turned curves.
    #[test]
    fn a_turned_glass_keeps_its_values_consistent() {
        let mut reg = registry(true);
        let g = &mut reg.tables_mut()[0].glasses[0];
        g.turn_round();
        assert_eq!(g.hemispherical, Some(HemisphericalRecord::of(g)));
        reg.validate().unwrap();
    }
}
