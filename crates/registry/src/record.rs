//! One glass's record in a registry table: normal-incidence values per channel, angle curves,
//! how they were made, and the evaluation the compositor uses (method.md eqs. 11–14:
//! `r(θ) = r0·C_r(θ)`, `t(θ) = t0·C_t(θ)`, per channel).

use glassdb_fit::{CosPolynomial, FitSummary};
use glassdb_side::Side;
use serde::{Deserialize, Serialize};

/// One glass product: normal-incidence values per channel and its angle curves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GlassRecord {
    /// Registration id as stored in masks (1–65535; 0 means "no glass").
    pub id: u16,
    /// Product name.
    pub name: String,
    /// Front (viewer-side) reflectance at normal incidence, per channel R, G, B.
    pub r0: [f64; 3],
    /// Transmittance at normal incidence, per channel (the same from both sides).
    pub t0: [f64; 3],
    /// Back reflectance at normal incidence, per channel (coated glass differs from the front).
    pub r0_back: [f64; 3],
    /// Front reflectance curves C_r per channel: `r(θ) = r0·C_r(cos θ)`.
    pub c_r: [AngleCurve; 3],
    /// Transmittance curves C_t per channel: `t(θ) = t0·C_t(cos θ)`.
    pub c_t: [AngleCurve; 3],
    /// Back reflectance curves per channel: `r_back(θ) = r0_back·C_r_back(cos θ)`.
    pub c_r_back: [AngleCurve; 3],
    /// Luminous (ISO 9050: D65 × V(λ)) values at normal incidence, when a spectrum was given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub luminous: Option<LuminousRecord>,
    /// Where the angle dependence came from.
    pub angle_model: AngleModelRecord,
    /// Input files and their sha256, and the product as the data file describes it.
    pub provenance: Provenance,
    /// A unit's build-up, per-layer values and per-pane-group reflectances (none for a single
    /// glass: one pane group whose reflectance is `r`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<crate::unit_record::UnitRecord>,
    /// Hemispherical (diffuse-diffuse) values integrated from the curves (stored by every build
    /// since they were added; [`GlassRecord::hemispherical`] integrates them for a record
    /// without).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hemispherical: Option<crate::hemispherical::HemisphericalRecord>,
}

/// One angle curve: the fitted polynomial `C(cos θ)` with the summary of its fit, under the
/// keys of `glassdb fit` (`basis`, `powers`, `coefficients`, `degree`, `rms_error`, …).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AngleCurve {
    /// C(θ) in the fit crate's form.
    #[serde(flatten)]
    pub polynomial: CosPolynomial,
    /// How well it fits its data.
    #[serde(flatten)]
    pub fit: FitSummary,
    /// Absolute tolerance on r (or t) that validation allows beyond the physical range (the
    /// larger of the fit tolerance and the fit's own max residual). Validation refuses a value
    /// above [`glassdb_fit::MAX_CURVE_TOLERANCE`].
    pub tolerance: f64,
}

/// Luminous values at normal incidence (ISO 9050 / EN 410, D65 × V(λ), 380–780 nm / 10 nm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LuminousRecord {
    /// τv.
    pub transmittance: f64,
    /// ρv, front.
    pub reflectance: f64,
    /// ρv, back.
    pub reflectance_back: f64,
}

/// The physical or measured model behind the curves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AngleModelRecord {
    /// `measured`, `uncoated`, `coated` (clear/bronze chosen per wavelength), `coated-clear`,
    /// `coated-bronze` or `opaque`.
    pub kind: String,
    /// `per-wavelength` (model applied to the spectrum before integration) or `per-channel`.
    pub applied: String,
    /// Complex refractive index `[n, k]` used by the `opaque` model, when given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ior: Option<[f64; 2]>,
    /// For measured tables: the largest measured angle; beyond it the physical model continues.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measured_max_angle_deg: Option<f64>,
    /// The physical model that continues a measured table (or `null`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub continued_by: Option<String>,
    /// Why this model: the catalog's `model` key, the file's product type, or Rf vs Rb.
    #[serde(default)]
    pub chosen_by: String,
}

/// Input files and the product description.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Provenance {
    /// The catalog the glass came from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub catalog: Option<FileRef>,
    /// The spectral data file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spectral: Option<FileRef>,
    /// The measured angle table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angles: Option<FileRef>,
    /// The product as the spectral file names it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub product: Option<ProductRecord>,
}

/// A file and the sha256 of its bytes (hex).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileRef {
    /// The file, relative to the catalog.
    pub path: String,
    /// Its SHA-256 (hex).
    pub sha256: String,
}

/// The product as its data file describes it.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ProductRecord {
    /// The product's name in the file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Its maker.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub manufacturer: Option<String>,
    /// `Monolithic`, `Coated`, `coated-glass`, `laminate`, … as in the file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub product_type: Option<String>,
    /// Which face is coated, as the file says.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coated_side: Option<String>,
    /// Its thickness.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness_mm: Option<f64>,
    /// The parts an IGSDB product lists (a laminate's plies and interlayer), when it lists them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub composition: Vec<String>,
}

impl AngleCurve {
    /// `C(cos θ)`, unclamped.
    #[inline]
    pub fn eval(&self, cos_theta: f64) -> f64 {
        self.polynomial.eval(cos_theta)
    }

    /// A curve equal to `cos θ` (used where t0 = 0, so C_t never matters): C(0°) = 1, C(90°) = 0.
    pub fn nominal_transmittance() -> AngleCurve {
        AngleCurve {
            polynomial: CosPolynomial {
                basis: glassdb_fit::Basis::Paper,
                powers: vec![1],
                coefficients: vec![1.0],
            },
            fit: FitSummary::exact(1),
            tolerance: 0.0,
        }
    }
}

/// Clamps a pair to the physical range: `0 ≤ r ≤ 1`, then `0 ≤ t ≤ 1 − r` (reflectance is the
/// better-determined quantity near grazing, where both curves are steep).
#[inline]
fn clamp_physical(r: f64, t: f64) -> (f64, f64) {
    let r = if r.is_finite() {
        r.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0 - r)
    } else {
        0.0
    };
    (r, t)
}

impl GlassRecord {
    /// A hand-made glass (tests, examples): normal-incidence values `[r0, t0, r0_back]` and one
    /// curve each `[c_r, c_t, c_r_back]` shared by all three channels, under the per-channel
    /// angle model `kind`, with no luminous values and no provenance.
    pub fn with_shared_curves(
        id: u16,
        name: &str,
        kind: &str,
        [r0, t0, r0_back]: [[f64; 3]; 3],
        [c_r, c_t, c_r_back]: [&AngleCurve; 3],
    ) -> GlassRecord {
        GlassRecord {
            id,
            name: name.to_string(),
            r0,
            t0,
            r0_back,
            c_r: std::array::from_fn(|_| c_r.clone()),
            c_t: std::array::from_fn(|_| c_t.clone()),
            c_r_back: std::array::from_fn(|_| c_r_back.clone()),
            luminous: None,
            angle_model: AngleModelRecord {
                kind: kind.to_string(),
                applied: "per-channel".into(),
                ior: None,
                measured_max_angle_deg: None,
                continued_by: None,
                chosen_by: String::new(),
            },
            provenance: Provenance::default(),
            unit: None,
            hemispherical: None,
        }
    }

    /// The glass turned round: front and back reflectance (values, curves, luminous)
    /// swapped, as a layer flipped in a unit.
    pub fn turn_round(&mut self) {
        std::mem::swap(&mut self.r0, &mut self.r0_back);
        std::mem::swap(&mut self.c_r, &mut self.c_r_back);
        if let Some(l) = &mut self.luminous {
            std::mem::swap(&mut l.reflectance, &mut l.reflectance_back);
        }
        self.hemispherical = self.hemispherical.map(|h| h.turned_round());
    }

    /// "id 3 (\"Clear 6 mm\")", for messages.
    pub fn label(&self) -> String {
        format!("id {} (\"{}\")", self.id, self.name)
    }

    pub(crate) fn r_parts(&self, side: Side) -> (&[f64; 3], &[AngleCurve; 3]) {
        match side {
            Side::Front => (&self.r0, &self.c_r),
            Side::Back => (&self.r0_back, &self.c_r_back),
        }
    }

    /// Unclamped `(r, t)` per channel at `cos θ` (for validation and diagnostics).
    pub fn eval_raw(&self, side: Side, cos_theta: f64) -> ([f64; 3], [f64; 3]) {
        let (r0, c_r) = self.r_parts(side);
        let r = std::array::from_fn(|c| r0[c] * c_r[c].eval(cos_theta));
        let t = std::array::from_fn(|c| self.t0[c] * self.c_t[c].eval(cos_theta));
        (r, t)
    }

    /// `(r, t)` per channel at `cos θ` (clamped to [0, 1]), clamped to the physical range
    /// `0 ≤ r ≤ 1`, `0 ≤ t ≤ 1 − r`. Transmittance is the same from both sides.
    pub fn eval(&self, side: Side, cos_theta: f64) -> ([f64; 3], [f64; 3]) {
        let cos_theta = if cos_theta.is_finite() {
            cos_theta.clamp(0.0, 1.0)
        } else {
            1.0
        };
        let (r, t) = self.eval_raw(side, cos_theta);
        let mut out_r = [0.0; 3];
        let mut out_t = [0.0; 3];
        for c in 0..3 {
            (out_r[c], out_t[c]) = clamp_physical(r[c], t[c]);
        }
        (out_r, out_t)
    }
}
