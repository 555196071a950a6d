//! The angle model of one layer: which physical model ([`LayerModel`]) turns its normal values
//! into values at any angle, chosen from the catalog's `model` key ([`ModelChoice`]), the data
//! file's product type or the data themselves ([`choose_model`]); and the model evaluated for
//! one wavelength or channel ([`model_at`]). Equations in `docs/registry.md`.

use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::physics::{
    CoatedCurve, UncoatedSlab, fresnel_single_surface, ior_from_reflectance, opaque_reflectance,
};

/// Front and back reflectance of a glass are "equal" (uncoated) when they differ by less than
/// this everywhere (the rule of the Modelica Buildings library, `glassProperty`, tol = 0.005).
pub const UNCOATED_RF_RB_TOL: f64 = 0.005;

/// The `model` key of a catalog entry or layer, and `model=` of a command-line layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModelChoice {
    /// From the data file's product type (see [`choose_model`]).
    #[default]
    Auto,
    /// WINDOW/EnergyPlus Fresnel slab model for uncoated glass.
    Uncoated,
    /// WINDOW-4 coated curves, clear or bronze chosen per wavelength (T0(λ) > 0.645 → clear).
    Coated,
    /// WINDOW-4 clear curve everywhere.
    CoatedClear,
    /// WINDOW-4 bronze curve everywhere (what pywincalc 3.3.1 applies to every coated layer).
    CoatedBronze,
    /// WINDOW-4 bronze curve everywhere as WINDOW applies it, not renormalised to the
    /// measured 0° values (pywincalc 3.3.1's numbers exactly; T(θ → 0°) = 1.01175·T0).
    CoatedBronzePublished,
    /// An opaque specular surface: t0 = 0, single-surface Fresnel reflectance.
    Opaque,
}

impl ModelChoice {
    /// Every choice, in the order help texts list them.
    pub const ALL: [ModelChoice; 7] = [
        ModelChoice::Auto,
        ModelChoice::Uncoated,
        ModelChoice::Coated,
        ModelChoice::CoatedClear,
        ModelChoice::CoatedBronze,
        ModelChoice::CoatedBronzePublished,
        ModelChoice::Opaque,
    ];
}

// The name used in catalogs and in the registry's `angle_model.kind`.
glassdb_io::enum_names!(ModelChoice {
    Auto => "auto",
    Uncoated => "uncoated",
    Coated => "coated",
    CoatedClear => "coated-clear",
    CoatedBronze => "coated-bronze",
    CoatedBronzePublished => "coated-bronze-published",
    Opaque => "opaque",
});

impl FromStr for ModelChoice {
    type Err = String;

    /// A model's name as [`ModelChoice::name`] writes it, any case.
    fn from_str(s: &str) -> Result<ModelChoice, String> {
        ModelChoice::from_name(s.trim()).ok_or_else(|| {
            let names: Vec<&str> = ModelChoice::ALL.iter().map(|m| m.name()).collect();
            format!("unknown model `{s}`; expected one of {}", names.join(", "))
        })
    }
}

/// The physical model of a layer once chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LayerModel {
    /// The Fresnel slab of WINDOW / EnergyPlus ([`UncoatedSlab`]).
    Uncoated,
    /// WINDOW-4's clear/bronze curve chosen per wavelength (or channel) by T0 > 0.645.
    Coated,
    /// One WINDOW-4 curve everywhere.
    CoatedFixed(CoatedCurve),
    /// One WINDOW-4 curve everywhere, as published (not renormalised).
    CoatedPublished(CoatedCurve),
    /// An opaque specular surface (single-surface Fresnel, T = 0).
    Opaque,
}

impl LayerModel {
    /// The model's name (as [`ModelChoice::name`] writes the choice that fixes it).
    pub fn name(self) -> &'static str {
        match self {
            LayerModel::Uncoated => "uncoated",
            LayerModel::Coated => "coated",
            LayerModel::CoatedFixed(CoatedCurve::Clear) => "coated-clear",
            LayerModel::CoatedFixed(CoatedCurve::Bronze) => "coated-bronze",
            LayerModel::CoatedPublished(CoatedCurve::Clear) => "coated-clear-published",
            LayerModel::CoatedPublished(CoatedCurve::Bronze) => "coated-bronze-published",
            LayerModel::Opaque => "opaque",
        }
    }

    /// The model a choice fixes (`None` for `auto`).
    pub fn fixed_by(choice: ModelChoice) -> Option<LayerModel> {
        match choice {
            ModelChoice::Uncoated => Some(LayerModel::Uncoated),
            ModelChoice::Coated => Some(LayerModel::Coated),
            ModelChoice::CoatedClear => Some(LayerModel::CoatedFixed(CoatedCurve::Clear)),
            ModelChoice::CoatedBronze => Some(LayerModel::CoatedFixed(CoatedCurve::Bronze)),
            ModelChoice::CoatedBronzePublished => {
                Some(LayerModel::CoatedPublished(CoatedCurve::Bronze))
            }
            ModelChoice::Opaque => Some(LayerModel::Opaque),
            ModelChoice::Auto => None,
        }
    }
}

/// A layer's model prepared for one sample (a wavelength or a channel): what depends only on
/// its normal values is computed once ([`ModelSample::new`]), then [`ModelSample::at`] gives
/// the values at any angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModelSample {
    /// The uncoated slabs of the two sides (the front one gives T).
    Uncoated {
        /// Solved from (T0, Rf0).
        front: UncoatedSlab,
        /// Solved from (T0, Rb0).
        back: UncoatedSlab,
    },
    /// A coated curve and the normal values it scales.
    Coated(CoatedSample),
    /// An opaque surface.
    Opaque {
        /// Normal front reflectance.
        rf0: f64,
        /// Normal back reflectance.
        rb0: f64,
        /// `(n, k)` when given.
        ior: Option<(f64, f64)>,
    },
}

/// A coated layer's curve and the normal values it scales, for one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoatedSample {
    /// The curve.
    pub curve: CoatedCurve,
    /// As published (not renormalised).
    pub published: bool,
    /// Normal transmittance.
    pub t0: f64,
    /// Normal front reflectance.
    pub rf0: f64,
    /// Normal back reflectance.
    pub rb0: f64,
}

impl CoatedSample {
    /// `(Rf, T, Rb)` at `cos θ`: the curve applied to each side's normal reflectance.
    #[inline]
    pub fn at(&self, cos_theta: f64) -> (f64, f64, f64) {
        let at = |r0| {
            if self.published {
                self.curve.at_published(self.t0, r0, cos_theta)
            } else {
                self.curve.at(self.t0, r0, cos_theta)
            }
        };
        let (rf, t) = at(self.rf0);
        let (rb, _) = at(self.rb0);
        (rf, t, rb)
    }
}

impl ModelSample {
    /// The model `model` for a sample with normal values `t0`, `rf0`, `rb0` (and the `(n, k)`
    /// of an opaque surface, when given).
    pub fn new(model: LayerModel, t0: f64, rf0: f64, rb0: f64, ior: Option<(f64, f64)>) -> Self {
        match model {
            LayerModel::Uncoated => ModelSample::Uncoated {
                front: UncoatedSlab::from_normal(t0, rf0),
                back: UncoatedSlab::from_normal(t0, rb0),
            },
            LayerModel::Coated | LayerModel::CoatedFixed(_) | LayerModel::CoatedPublished(_) => {
                let (curve, published) = match model {
                    LayerModel::CoatedFixed(c) => (c, false),
                    LayerModel::CoatedPublished(c) => (c, true),
                    _ => (CoatedCurve::for_t0(t0), false),
                };
                ModelSample::Coated(CoatedSample {
                    curve,
                    published,
                    t0,
                    rf0,
                    rb0,
                })
            }
            LayerModel::Opaque => ModelSample::Opaque { rf0, rb0, ior },
        }
    }

    /// `(Rf, T, Rb)` at `cos θ`.
    #[inline]
    pub fn at(&self, cos_theta: f64) -> (f64, f64, f64) {
        match *self {
            ModelSample::Uncoated { front, back } => {
                let (rf, t) = front.at(cos_theta);
                let (rb, _) = back.at(cos_theta);
                (rf, t, rb)
            }
            ModelSample::Coated(coated) => coated.at(cos_theta),
            ModelSample::Opaque { rf0, rb0, ior } => {
                let f = |r0: f64| match ior {
                    Some(nk) => opaque_reflectance(r0, nk, cos_theta),
                    None => fresnel_single_surface(ior_from_reflectance(r0), 0.0, cos_theta),
                };
                (f(rf0), 0.0, f(rb0))
            }
        }
    }
}

/// `(Rf, T, Rb)` of one wavelength (or channel) at `cos θ` from its normal values `t0`, `rf0`,
/// `rb0`; `ior` is the `(n, k)` of an opaque surface when given.
pub fn model_at(
    model: LayerModel,
    t0: f64,
    rf0: f64,
    rb0: f64,
    ior: Option<(f64, f64)>,
    cos_theta: f64,
) -> (f64, f64, f64) {
    ModelSample::new(model, t0, rf0, rb0, ior).at(cos_theta)
}

/// Picks the physical model: the one `choice` fixes; else `opaque` with an index of
/// refraction or zero transmittance; else from the data file's product type (`Monolithic` →
/// uncoated; coated, laminate, film, interlayer → coated: WINDOW's rule); else uncoated when
/// `rf` and `rb` agree within [`UNCOATED_RF_RB_TOL`], coated otherwise. Returns the model and
/// why it was chosen.
pub fn choose_model(
    choice: ModelChoice,
    has_ior: bool,
    product_type: Option<&str>,
    t: &[f64],
    rf: &[f64],
    rb: &[f64],
) -> (LayerModel, String) {
    if let Some(m) = LayerModel::fixed_by(choice) {
        return (m, "catalog `model`".into());
    }
    if has_ior {
        return (LayerModel::Opaque, "catalog `ior`".into());
    }
    if t.iter().all(|&v| v <= 0.0) {
        return (LayerModel::Opaque, "zero transmittance".into());
    }
    if let Some(pt) = product_type {
        let p = pt.to_ascii_lowercase();
        if p.contains("monolithic") {
            return (LayerModel::Uncoated, format!("product type \"{pt}\""));
        }
        let coated = ["coat", "laminate", "film", "interlayer"];
        if coated.iter().any(|k| p.contains(k)) {
            return (LayerModel::Coated, format!("product type \"{pt}\""));
        }
    }
    let max_diff = rf
        .iter()
        .zip(rb)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    if max_diff < UNCOATED_RF_RB_TOL {
        let why = format!("Rf = Rb within {UNCOATED_RF_RB_TOL} (max difference {max_diff:.4})");
        (LayerModel::Uncoated, why)
    } else {
        (
            LayerModel::Coated,
            format!("Rf differs from Rb by up to {max_diff:.4}"),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_model_from_product_type_and_from_rf_rb() {
        let t = [0.8, 0.8];
        let auto =
            |pt, rf: &[f64], rb: &[f64]| choose_model(ModelChoice::Auto, false, pt, &t, rf, rb);
        let (m, _) = auto(Some("Monolithic"), &[0.1, 0.1], &[0.3, 0.3]);
        assert_eq!(m, LayerModel::Uncoated);
        let (m, _) = auto(Some("applied-film"), &[0.1, 0.1], &[0.1, 0.1]);
        assert_eq!(m, LayerModel::Coated);
        let (m, why) = auto(None, &[0.1, 0.1], &[0.104, 0.1]);
        assert_eq!(m, LayerModel::Uncoated, "{why}");
        let (m, _) = auto(None, &[0.1, 0.1], &[0.106, 0.1]);
        assert_eq!(m, LayerModel::Coated);
        let (m, _) = choose_model(ModelChoice::Auto, false, None, &[0.0, 0.0], &[0.9], &[0.9]);
        assert_eq!(m, LayerModel::Opaque);
        let (m, why) = choose_model(
            ModelChoice::CoatedBronze,
            false,
            Some("Monolithic"),
            &t,
            &[0.1],
            &[0.1],
        );
        assert_eq!(
            (m.name(), why.as_str()),
            ("coated-bronze", "catalog `model`")
        );
    }

    #[test]
    fn model_names_parse_back() {
        for m in ModelChoice::ALL {
            assert_eq!(m.name().parse::<ModelChoice>().unwrap(), m);
        }
        assert!(
            "shiny"
                .parse::<ModelChoice>()
                .unwrap_err()
                .contains("coated-bronze")
        );
    }
}
