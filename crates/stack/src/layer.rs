//! One solid layer of a unit: its normal-incidence data (spectra on its own wavelengths, or
//! values per colour channel), its angle model, whether it is flipped, its thickness, and a
//! measured angle table if it has one; and its front/back R and T at any angle
//! ([`Layer::values_at`]).

use glassdb_spectral::{ProductInfo, SpectralData};

use crate::StackError;
use crate::measured::MeasuredRatio;
use std::ops::Range;

use crate::model::{LayerModel, ModelChoice, ModelSample, choose_model};

/// A layer's normal-incidence data, as given (before any flip).
#[derive(Debug, Clone, PartialEq)]
pub enum LayerData {
    /// Spectra on the layer's own wavelengths (nm, strictly increasing), as fractions.
    Spectral {
        /// The wavelengths (nm).
        wavelength_nm: Vec<f64>,
        /// T(λ), the same from both sides.
        t: Vec<f64>,
        /// Front reflectance Rf(λ).
        rf: Vec<f64>,
        /// Back reflectance Rb(λ).
        rb: Vec<f64>,
    },
    /// Values per colour channel only (explicit r0/t0 of a catalog): used as they are in
    /// whichever colour basis the stack is evaluated, so a stack with such a layer is combined
    /// per channel.
    Channels {
        /// t0 per channel R, G, B.
        t: [f64; 3],
        /// r0 (front) per channel.
        rf: [f64; 3],
        /// r0_back per channel.
        rb: [f64; 3],
    },
}

impl LayerData {
    /// The wavelength range of spectral data (`None` for channel values).
    pub fn range_nm(&self) -> Option<(f64, f64)> {
        match self {
            LayerData::Spectral { wavelength_nm, .. } => {
                Some((*wavelength_nm.first()?, *wavelength_nm.last()?))
            }
            LayerData::Channels { .. } => None,
        }
    }

    /// The normal transmittance values (per wavelength or per channel).
    pub fn t(&self) -> &[f64] {
        match self {
            LayerData::Spectral { t, .. } => t,
            LayerData::Channels { t, .. } => t,
        }
    }

    fn parts(&self) -> (&[f64], &[f64], &[f64]) {
        match self {
            LayerData::Spectral { t, rf, rb, .. } => (t, rf, rb),
            LayerData::Channels { t, rf, rb } => (t, rf, rb),
        }
    }
}

/// How a layer is used: the catalog's or command line's choices besides its data.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LayerOptions {
    /// The angle model (`auto` decides from the file's product type or the data).
    pub model: ModelChoice,
    /// `(n, k)` per channel of an opaque surface (its R, G, B; wavelengths use G).
    pub ior: Option<[(f64, f64); 3]>,
    /// The layer faces the other way: its back faces outdoors (Rf and Rb swap).
    pub flipped: bool,
    /// Thickness (mm) overriding the file's.
    pub thickness_mm: Option<f64>,
}

/// A layer's R and T at one angle, on its own samples (wavelengths or channels), after any
/// flip: `t` the same from both sides, `rf` seen from the outer side, `rb` from the inner.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LayerValues {
    /// Transmittance.
    pub t: Vec<f64>,
    /// Reflectance of the side facing outdoors.
    pub rf: Vec<f64>,
    /// Reflectance of the side facing indoors.
    pub rb: Vec<f64>,
}

/// One solid layer (a pane, a laminate, a film on glass) of a unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    /// How messages name the layer (its file, or "r0/t0 values").
    pub label: String,
    /// Normal-incidence data as given.
    pub data: LayerData,
    /// The physical angle model.
    pub model: LayerModel,
    /// Why this model (the `model` key, the file's product type, or Rf vs Rb).
    pub model_reason: String,
    /// `(n, k)` per channel of an opaque surface.
    pub ior: Option<[(f64, f64); 3]>,
    /// Faces the other way (Rf and Rb swap).
    pub flipped: bool,
    /// Thickness in mm (from the file, or the override), when known.
    pub thickness_mm: Option<f64>,
    /// A measured angle table (its curves replacing the model for Rf and T).
    pub measured: Option<MeasuredRatio>,
    /// The product as its file describes it.
    pub product: Option<ProductInfo>,
}

/// T + R ≤ 1 at one sample, as Windows-CalcEngine's `checkRange` enforces it: where the sum
/// exceeds 1, the larger of the two gives way.
#[inline]
fn check_range(t: f64, r: f64) -> (f64, f64) {
    if t + r > 1.0 {
        if r >= t { (t, 1.0 - t) } else { (1.0 - r, r) }
    } else {
        (t, r)
    }
}

impl Layer {
    /// A layer from spectra (wavelengths in nm, strictly increasing; fractions), checked:
    /// equal lengths, finite values in [0, 1], T + R ≤ 1 at every wavelength (within
    /// [`glassdb_spectral::SPECTRUM_BALANCE_SLACK`]); its model from `opts.model`, else
    /// `product_type`, else the data.
    pub fn from_spectra(
        label: &str,
        wavelength_nm: Vec<f64>,
        t: Vec<f64>,
        rf: Vec<f64>,
        rb: Vec<f64>,
        product_type: Option<&str>,
        opts: &LayerOptions,
    ) -> Result<Layer, StackError> {
        let err = |message: String| StackError::Layer {
            label: label.to_string(),
            message,
        };
        let n = wavelength_nm.len();
        if n < 2 || t.len() != n || rf.len() != n || rb.len() != n {
            return Err(err(format!(
                "{n} wavelengths but {}, {} and {} values of T, Rf and Rb (at least two of each)",
                t.len(),
                rf.len(),
                rb.len()
            )));
        }
        if let Some(k) = (1..n).find(|&k| {
            wavelength_nm[k].partial_cmp(&wavelength_nm[k - 1]) != Some(std::cmp::Ordering::Greater)
        }) {
            return Err(err(format!(
                "wavelengths not strictly increasing at {} nm",
                wavelength_nm[k]
            )));
        }
        for (name, v) in [("T", &t), ("Rf", &rf), ("Rb", &rb)] {
            if let Some(k) = v.iter().position(|x| !(0.0..=1.0).contains(x)) {
                return Err(err(format!(
                    "{name} = {} at {} nm is not a fraction in [0, 1]",
                    v[k], wavelength_nm[k]
                )));
            }
        }
        glassdb_spectral::check_spectrum_balance(&wavelength_nm, Some(&t), &[Some(&rf), Some(&rb)])
            .map_err(|source| StackError::LayerSpectrum {
                label: label.to_string(),
                source: Box::new(source),
            })?;
        Ok(Layer::new(
            label,
            LayerData::Spectral {
                wavelength_nm,
                t,
                rf,
                rb,
            },
            product_type,
            opts,
        ))
    }

    /// A layer of checked data, its model chosen by `opts.model`, else `product_type`, else
    /// the data.
    fn new(label: &str, data: LayerData, product_type: Option<&str>, opts: &LayerOptions) -> Layer {
        let (t, rf, rb) = data.parts();
        let (model, model_reason) =
            choose_model(opts.model, opts.ior.is_some(), product_type, t, rf, rb);
        Layer {
            label: label.to_string(),
            data,
            model,
            model_reason,
            ior: opts.ior,
            flipped: opts.flipped,
            thickness_mm: opts.thickness_mm,
            measured: None,
            product: None,
        }
    }

    /// A layer from a spectral file's data: T (zero for an opaque model), Rf, Rb (Rf where
    /// the file has none); its product type picks the model under `auto`; its thickness
    /// unless `opts.thickness_mm` overrides it.
    pub fn from_spectral_data(
        data: SpectralData,
        opts: &LayerOptions,
        label: &str,
    ) -> Result<Layer, StackError> {
        let err = |message: &str| StackError::Layer {
            label: label.to_string(),
            message: message.to_string(),
        };
        let n = data.wavelength_nm.len();
        let opaque = opts.model == ModelChoice::Opaque || opts.ior.is_some();
        let t = match data.transmittance {
            Some(t) if opaque && t.iter().any(|&v| v > 0.0) => {
                return Err(err(
                    "model `opaque` means T = 0, but the file has a non-zero transmittance",
                ));
            }
            Some(t) => t,
            None if opaque => vec![0.0; n],
            None => return Err(err("has no transmittance column (T)")),
        };
        let rf = data
            .reflectance_front
            .ok_or_else(|| err("has no front reflectance column (R or Rf)"))?;
        let rb = data.reflectance_back.unwrap_or_else(|| rf.clone());
        let mut layer = Layer::from_spectra(
            label,
            data.wavelength_nm,
            t,
            rf,
            rb,
            data.product.product_type.as_deref(),
            opts,
        )?;
        layer.thickness_mm = opts.thickness_mm.or(data.product.thickness_mm);
        layer.product = Some(data.product);
        Ok(layer)
    }

    /// A layer known per colour channel only (a catalog's explicit r0, t0, r0_back).
    pub fn from_channels(
        label: &str,
        t: [f64; 3],
        rf: [f64; 3],
        rb: [f64; 3],
        opts: &LayerOptions,
    ) -> Layer {
        Layer::new(label, LayerData::Channels { t, rf, rb }, None, opts)
    }

    /// Whether the layer transmits nothing at any wavelength (or channel).
    pub fn is_opaque(&self) -> bool {
        self.model == LayerModel::Opaque || self.data.t().iter().all(|&t| t <= 0.0)
    }

    /// Whether the layer has spectra (rather than channel values only).
    pub fn is_spectral(&self) -> bool {
        matches!(self.data, LayerData::Spectral { .. })
    }

    /// The normal values after any flip: `(t, rf, rb)` with `rf` facing outdoors.
    pub fn normal(&self) -> LayerValues {
        let (t, rf, rb) = self.data.parts();
        let (rf, rb) = if self.flipped { (rb, rf) } else { (rf, rb) };
        LayerValues {
            t: t.to_vec(),
            rf: rf.to_vec(),
            rb: rb.to_vec(),
        }
    }

    /// R and T at `cos θ` on the layer's own samples (after any flip): the normal values at
    /// normal incidence (as WINDOW uses the measured data at 0°), else the model per sample
    /// (with a measured table's ratio curves for Rf and T), then T + R ≤ 1 per side as WINDOW
    /// enforces it.
    pub fn values_at(&self, cos_theta: f64) -> LayerValues {
        let prepared = self.prepare();
        self.values_prepared(&prepared, 0..prepared.len(), cos_theta)
    }

    /// The layer's model prepared for each of its own samples (the `ior` of G for spectra, each
    /// channel's for channel values): computed once, used at every angle.
    pub fn prepare(&self) -> Vec<ModelSample> {
        let (t0, rf0, rb0) = self.data.parts();
        let per_channel = !self.is_spectral();
        self.prepare_samples(t0, rf0, rb0, per_channel)
    }

    fn prepare_samples(
        &self,
        t0: &[f64],
        rf0: &[f64],
        rb0: &[f64],
        per_channel: bool,
    ) -> Vec<ModelSample> {
        (0..t0.len())
            .map(|k| {
                let ior = self.ior.map(|v| v[if per_channel { k.min(2) } else { 1 }]);
                ModelSample::new(self.model, t0[k], rf0[k], rb0[k], ior)
            })
            .collect()
    }

    /// [`Layer::values_at`] applied to given normal values instead of the layer's own: its
    /// spectra reduced to three channels (each with its channel's `ior`) or to one value (with
    /// the `ior` of G), when the model is applied per channel.
    pub fn values_at_samples(
        &self,
        t0: &[f64],
        rf0: &[f64],
        rb0: &[f64],
        cos_theta: f64,
    ) -> LayerValues {
        let prepared = self.prepare_samples(t0, rf0, rb0, t0.len() == 3);
        self.values_from(&prepared, t0, rf0, rb0, 0..t0.len(), cos_theta)
    }

    /// Per channel, [`Layer::values_at`] of channel data with each channel's own `ior`.
    pub(crate) fn channel_values_at(&self, cos_theta: f64) -> Option<LayerValues> {
        match &self.data {
            LayerData::Channels { t, rf, rb } => Some(self.values_at_samples(t, rf, rb, cos_theta)),
            LayerData::Spectral { .. } => None,
        }
    }

    /// [`Layer::values_at`] on the samples `range` only, with the model prepared by
    /// [`Layer::prepare`].
    pub fn values_prepared(
        &self,
        prepared: &[ModelSample],
        range: Range<usize>,
        cos_theta: f64,
    ) -> LayerValues {
        let (t0, rf0, rb0) = self.data.parts();
        self.values_from(prepared, t0, rf0, rb0, range, cos_theta)
    }

    fn values_from(
        &self,
        prepared: &[ModelSample],
        t0: &[f64],
        rf0: &[f64],
        rb0: &[f64],
        range: Range<usize>,
        cos_theta: f64,
    ) -> LayerValues {
        let n = range.len();
        let mut v = LayerValues {
            t: Vec::with_capacity(n),
            rf: Vec::with_capacity(n),
            rb: Vec::with_capacity(n),
        };
        let normal = cos_theta >= 1.0;
        let measured = if normal { None } else { self.measured.as_ref() };
        for k in range {
            let (mut rf, mut t, rb) = if normal {
                (rf0[k], t0[k], rb0[k])
            } else {
                prepared[k].at(cos_theta)
            };
            if let Some(m) = measured {
                rf = m.reflectance_at(rf0[k], cos_theta).unwrap_or(rf);
                t = m.transmittance_at(t0[k], cos_theta).unwrap_or(t);
            }
            let (t, rf) = check_range(t, rf);
            let (t, rb) = check_range(t, rb);
            v.t.push(t);
            v.rf.push(rf);
            v.rb.push(rb);
        }
        if self.flipped {
            std::mem::swap(&mut v.rf, &mut v.rb);
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clear() -> Layer {
        let wl = vec![300.0, 500.0, 700.0, 2500.0];
        Layer::from_spectra(
            "clear",
            wl,
            vec![0.0, 0.9, 0.88, 0.8],
            vec![0.05, 0.08, 0.08, 0.07],
            vec![0.05, 0.08, 0.081, 0.07],
            Some("Monolithic"),
            &LayerOptions::default(),
        )
        .unwrap()
    }

    #[test]
    fn normal_incidence_gives_the_data_and_grazing_reflects_everything() {
        let l = clear();
        assert_eq!(l.values_at(1.0), l.normal());
        let g = l.values_at(0.0);
        assert!(g.t.iter().all(|&t| t == 0.0) && g.rf.iter().all(|&r| r == 1.0));
    }

    #[test]
    fn flip_swaps_the_reflectances_at_every_angle() {
        let mut coated = clear();
        coated.data = LayerData::Spectral {
            wavelength_nm: vec![300.0, 500.0, 700.0, 2500.0],
            t: vec![0.1, 0.6, 0.5, 0.2],
            rf: vec![0.3, 0.05, 0.1, 0.6],
            rb: vec![0.1, 0.2, 0.3, 0.4],
        };
        coated.model = LayerModel::Coated;
        let mut flipped = coated.clone();
        flipped.flipped = true;
        for c in [1.0, 0.7, 0.2] {
            let (a, b) = (coated.values_at(c), flipped.values_at(c));
            assert_eq!((a.t, a.rf, a.rb), (b.t, b.rb, b.rf));
        }
    }

    #[test]
    fn bad_spectra_name_the_layer_and_wavelength() {
        let e = Layer::from_spectra(
            "x.csv",
            vec![400.0, 500.0],
            vec![0.9, 0.95],
            vec![0.05, 0.1],
            vec![0.05, 0.05],
            None,
            &LayerOptions::default(),
        )
        .unwrap_err();
        let msg = format!("{e}: {}", std::error::Error::source(&e).unwrap());
        assert!(msg.contains("x.csv") && msg.contains("500"), "{msg}");
    }
}
