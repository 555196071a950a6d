//! A stack at a list of angles: each layer's values from its model, the layers combined per
//! wavelength (or per colour channel), and the result integrated to every colour basis asked
//! for and to WINDOW's photopic and solar values.

use glassdb_spectral::{Integrator, WindowMethod, WindowWeights};

use crate::StackError;
use crate::combine::{Optics, combine};
use crate::layer::{Layer, LayerData, LayerValues};
use crate::measured::cos_deg;
use crate::model::ModelSample;
use crate::stack::{Grid, Stack};

/// Where each layer's angle model is applied.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Application {
    /// To the spectrum, wavelength by wavelength, before integration (what WINDOW does).
    #[default]
    PerWavelength,
    /// To the layer's integrated per-channel values (the cheaper approximation; for comparison).
    PerChannel,
}

impl Application {
    /// `per-wavelength` or `per-channel`.
    pub fn name(self) -> &'static str {
        match self {
            Application::PerWavelength => "per-wavelength",
            Application::PerChannel => "per-channel",
        }
    }
}

/// Where the layers are combined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Combination {
    /// Wavelength by wavelength on the layers' common wavelengths, then integrated (WINDOW,
    /// ISO 9050 §5.3, EN 410 §5).
    #[default]
    PerWavelength,
    /// Each layer first integrated to the output's channels (or averaged to one value), then
    /// the channels combined: the "RGB shortcut". Forced when a layer has no spectrum or the
    /// models are applied per channel.
    PerBand,
}

impl Combination {
    /// `per-wavelength` or `per-band`.
    pub fn name(self) -> &'static str {
        match self {
            Combination::PerWavelength => "per-wavelength",
            Combination::PerBand => "per-band",
        }
    }
}

/// How to evaluate a stack.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EvalOptions {
    /// Where the layer models are applied.
    pub application: Application,
    /// Where the layers are combined (the effective choice is in [`Evaluation::combination`]).
    pub combination: Combination,
}

/// A stack's optics at each angle asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// The angles (degrees).
    pub angles_deg: Vec<f64>,
    /// Where the layers were combined.
    pub combination: Combination,
    /// Per integrator asked for (in order), per angle, the optics per channel.
    pub colour: Vec<Vec<Optics<[f64; 3]>>>,
    /// Per angle, WINDOW's photopic values (none when a layer has no spectrum).
    pub photopic: Option<Vec<Optics<f64>>>,
    /// Per angle, WINDOW's solar values (none when a layer has no spectrum).
    pub solar: Option<Vec<Optics<f64>>>,
}

/// The stack's spectra at one angle on its common wavelengths.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectra {
    /// The wavelengths (nm).
    pub wavelength_nm: Vec<f64>,
    /// The optics per wavelength.
    pub optics: Optics<Vec<f64>>,
}

/// Linear interpolation of one layer's samples onto the common wavelengths (end values held),
/// as Windows-CalcEngine's `CSeries::interpolate` does it.
#[derive(Debug, Clone)]
struct Resampling {
    /// The layer's samples the common grid needs (the others are not evaluated).
    range: std::ops::Range<usize>,
    /// Per grid point, the samples around it, relative to `range.start`.
    lower: Vec<usize>,
    upper: Vec<usize>,
    frac: Vec<f64>,
}

impl Resampling {
    fn new(from: &[f64], to: &[f64]) -> Resampling {
        let n = from.len();
        let mut r = Resampling {
            range: 0..0,
            lower: Vec::with_capacity(to.len()),
            upper: Vec::with_capacity(to.len()),
            frac: Vec::with_capacity(to.len()),
        };
        let mut k = 0; // points of `from` at or below x
        for &x in to {
            while k < n && from[k] <= x {
                k += 1;
            }
            let (lo, hi) = match k {
                0 => (0, 0),
                k if k == n => (n - 1, n - 1),
                k => (k - 1, k),
            };
            let f = if hi == lo {
                0.0
            } else {
                (x - from[lo]) / (from[hi] - from[lo])
            };
            r.lower.push(lo);
            r.upper.push(hi);
            r.frac.push(f);
        }
        let start = r.lower.iter().copied().min().unwrap_or(0);
        let end = r.upper.iter().copied().max().map_or(0, |m| m + 1);
        r.range = start..end;
        r.lower.iter_mut().for_each(|i| *i -= start);
        r.upper.iter_mut().for_each(|i| *i -= start);
        r
    }

    fn apply(&self, v: &[f64]) -> Vec<f64> {
        (0..self.frac.len())
            .map(|j| {
                let (a, b) = (v[self.lower[j]], v[self.upper[j]]);
                if self.lower[j] == self.upper[j] {
                    a
                } else {
                    a + self.frac[j] * (b - a)
                }
            })
            .collect()
    }
}

/// A WINDOW method and its values per angle.
type Averaged = (WindowMethod, Vec<Optics<f64>>);

/// WINDOW's `method` weights on `wavelength_nm`, or none where the data do not cover the
/// method's range (WINDOW refuses such a layer for that method; the other outputs stay).
fn window_weights(
    method: WindowMethod,
    wavelength_nm: &[f64],
    what: impl FnOnce() -> String,
) -> Result<Option<WindowWeights>, StackError> {
    match WindowWeights::new(method, wavelength_nm) {
        Ok(w) => Ok(Some(w)),
        Err(glassdb_spectral::SpectralError::WindowCoverage { .. }) => Ok(None),
        Err(source) => Err(StackError::Integration {
            what: what(),
            source: Box::new(source),
        }),
    }
}

/// How one output of a per-band evaluation reduces a spectrum: an integrator, or a WINDOW
/// method's weights on each layer's wavelengths (a method only when every layer covers it).
enum BandReduction<'a> {
    Colour(&'a Integrator),
    Window(Vec<WindowWeights>),
}

impl BandReduction<'_> {
    /// Layer `k`'s spectrum `v` on its wavelengths `wl`, reduced to this output's bands.
    fn reduce(
        &self,
        k: usize,
        wl: &[f64],
        v: &[f64],
    ) -> Result<Vec<f64>, glassdb_spectral::SpectralError> {
        match self {
            BandReduction::Colour(i) => i.channels(wl, v).map(|c| c.to_vec()),
            BandReduction::Window(w) => w[k].average(v).map(|a| vec![a]),
        }
    }
}

/// A layer's quantity in messages: `what of layer L at deg°`.
fn layer_label(l: &Layer, what: &str, deg: f64) -> String {
    format!("{what} of layer {} at {deg}°", l.label)
}

/// An integration failure about `what`, as the stack's error.
fn integration(what: String) -> impl FnOnce(glassdb_spectral::SpectralError) -> StackError {
    move |source| StackError::Integration {
        what,
        source: Box::new(source),
    }
}

/// The weights of WINDOW `method` on each layer's wavelengths; none when a layer has no
/// spectrum or its spectrum does not cover the method's.
fn layers_window_weights(
    layers: &[&Layer],
    method: WindowMethod,
) -> Result<Option<Vec<WindowWeights>>, StackError> {
    let mut per_layer = Vec::with_capacity(layers.len());
    for l in layers {
        let LayerData::Spectral { wavelength_nm, .. } = &l.data else {
            return Ok(None);
        };
        let what = || format!("{} average of layer {}", method.name(), l.label);
        match window_weights(method, wavelength_nm, what)? {
            Some(w) => per_layer.push(w),
            None => return Ok(None),
        }
    }
    Ok(Some(per_layer))
}

/// Per layer and output, the normal values reduced to the output's bands and clamped to
/// [0, 1] as a registry stores them (for models applied per channel; none otherwise).
#[allow(clippy::type_complexity)]
fn reduced_normals(
    layers: &[&Layer],
    outputs: &[BandReduction<'_>],
    application: Application,
) -> Result<Vec<Vec<Option<[Vec<f64>; 3]>>>, StackError> {
    let mut normals = Vec::with_capacity(layers.len());
    for (k, l) in layers.iter().enumerate() {
        let mut per = Vec::with_capacity(outputs.len());
        for r in outputs {
            per.push(match (&l.data, application) {
                (
                    LayerData::Spectral {
                        wavelength_nm,
                        t,
                        rf,
                        rb,
                    },
                    Application::PerChannel,
                ) => {
                    let red = |v: &[f64], what: &str| {
                        r.reduce(k, wavelength_nm, v)
                            .map(|x| x.into_iter().map(|c| c.clamp(0.0, 1.0)).collect())
                            .map_err(integration(layer_label(l, what, 0.0)))
                    };
                    Some([
                        red(t, "transmittance")?,
                        red(rf, "front reflectance")?,
                        red(rb, "back reflectance")?,
                    ])
                }
                _ => None,
            });
        }
        normals.push(per);
    }
    Ok(normals)
}

/// The name of one spectrum of [`Optics`] at an angle, for messages.
fn quantity_names(o: &Optics<Vec<f64>>) -> Vec<String> {
    let mut names = vec![
        "transmittance".to_string(),
        "front reflectance".into(),
        "back reflectance".into(),
    ];
    for (what, per) in [
        ("absorptance of layer", &o.absorptance),
        ("reflectance share of group", &o.share),
    ] {
        for (side, values) in [("front", &per.front), ("back", &per.back)] {
            names.extend((1..=values.len()).map(|k| format!("{what} {k} ({side})")));
        }
    }
    names
}

/// `f` applied to every spectrum of `o` in the order of [`quantity_names`], with the name for
/// messages.
fn integrate_optics<U>(
    o: &Optics<Vec<f64>>,
    angle_deg: f64,
    mut f: impl FnMut(&[f64]) -> Result<U, glassdb_spectral::SpectralError>,
) -> Result<Optics<U>, StackError> {
    let names = quantity_names(o);
    let mut k = 0;
    o.try_map(|v| {
        let r = f(v).map_err(|source| StackError::Integration {
            what: format!("{} at {angle_deg}°", names[k]),
            source: Box::new(source),
        });
        k += 1;
        r
    })
}

impl Stack {
    fn check_angles(angles_deg: &[f64]) -> Result<(), StackError> {
        match angles_deg.iter().find(|a| !(0.0..=90.0).contains(*a)) {
            Some(&a) => Err(StackError::Angle(a)),
            None => Ok(()),
        }
    }

    /// The per-wavelength optics at one angle (none when some layer has no spectrum).
    pub fn spectra_at(&self, angle_deg: f64) -> Result<Option<Spectra>, StackError> {
        Self::check_angles(&[angle_deg])?;
        let Grid::Wavelengths(grid) = self.grid() else {
            return Ok(None);
        };
        let resampling = self.resamplings(grid);
        let prepared: Vec<Vec<ModelSample>> = self.layers().map(Layer::prepare).collect();
        Ok(Some(Spectra {
            wavelength_nm: grid.clone(),
            optics: self.combined_spectra(&prepared, &resampling, cos_deg(angle_deg)),
        }))
    }

    fn resamplings(&self, grid: &[f64]) -> Vec<Resampling> {
        self.layers()
            .map(|l| match &l.data {
                LayerData::Spectral { wavelength_nm, .. } => Resampling::new(wavelength_nm, grid),
                LayerData::Channels { .. } => unreachable!("a wavelength grid has spectral layers"),
            })
            .collect()
    }

    fn combined_spectra(
        &self,
        prepared: &[Vec<ModelSample>],
        resampling: &[Resampling],
        cos_theta: f64,
    ) -> Optics<Vec<f64>> {
        let values: Vec<LayerValues> = self
            .layers()
            .zip(prepared)
            .zip(resampling)
            .map(|((l, p), r)| {
                let v = l.values_prepared(p, r.range.clone(), cos_theta);
                LayerValues {
                    t: r.apply(&v.t),
                    rf: r.apply(&v.rf),
                    rb: r.apply(&v.rb),
                }
            })
            .collect();
        combine(&values, &self.group_ranges())
    }

    fn group_ranges(&self) -> Vec<std::ops::Range<usize>> {
        self.groups().iter().map(|g| g.layers.clone()).collect()
    }

    /// The stack at `angles_deg` (each in 0–90°), integrated with each of `integrators` and,
    /// with `window`, averaged to WINDOW's photopic and solar values (each only where every
    /// layer has a spectrum covering the method's range, as WINDOW requires).
    pub fn evaluate(
        &self,
        angles_deg: &[f64],
        integrators: &[Integrator],
        window: bool,
        opts: EvalOptions,
    ) -> Result<Evaluation, StackError> {
        Self::check_angles(angles_deg)?;
        let all_spectral = self.layers().all(Layer::is_spectral);
        let combination = match (self.grid(), opts.application) {
            (Grid::Wavelengths(_), Application::PerWavelength) => opts.combination,
            _ => Combination::PerBand,
        };
        let methods: Vec<WindowMethod> = if window && all_spectral {
            WindowMethod::ALL.to_vec()
        } else {
            Vec::new()
        };
        let mut eval = Evaluation {
            angles_deg: angles_deg.to_vec(),
            combination,
            colour: vec![Vec::with_capacity(angles_deg.len()); integrators.len()],
            photopic: None,
            solar: None,
        };
        // per WINDOW method evaluated: its per-angle values
        let mut averaged: Vec<Averaged> = Vec::new();
        match (combination, self.grid()) {
            (Combination::PerWavelength, Grid::Wavelengths(grid)) => {
                let resampling = self.resamplings(grid);
                let prepared: Vec<Vec<ModelSample>> = self.layers().map(Layer::prepare).collect();
                let mut weights = Vec::new();
                for &m in &methods {
                    let what = || format!("{} average of the layers' common wavelengths", m.name());
                    if let Some(w) = window_weights(m, grid, what)? {
                        weights.push(w);
                        averaged.push((m, Vec::with_capacity(angles_deg.len())));
                    }
                }
                let on_grid: Vec<_> = integrators
                    .iter()
                    .map(|i| {
                        i.on_grid(grid).map_err(|source| StackError::Integration {
                            what: "the layers' common wavelengths".into(),
                            source: Box::new(source),
                        })
                    })
                    .collect::<Result<_, _>>()?;
                for &deg in angles_deg {
                    let spectra = self.combined_spectra(&prepared, &resampling, cos_deg(deg));
                    for (out, integrator) in eval.colour.iter_mut().zip(&on_grid) {
                        out.push(integrate_optics(&spectra, deg, |v| integrator.channels(v))?);
                    }
                    for (w, (_, out)) in weights.iter().zip(&mut averaged) {
                        out.push(integrate_optics(&spectra, deg, |v| w.average(v))?);
                    }
                }
            }
            _ => {
                averaged =
                    self.evaluate_per_band(&mut eval, integrators, &methods, opts.application)?;
            }
        }
        for (m, values) in averaged {
            match m {
                WindowMethod::Photopic => eval.photopic = Some(values),
                WindowMethod::Solar => eval.solar = Some(values),
            }
        }
        Ok(eval)
    }

    /// Each layer reduced to the output's bands (3 channels, or one averaged value) at each
    /// angle, then the bands combined; returns the WINDOW methods every layer covers, with
    /// their values.
    fn evaluate_per_band(
        &self,
        eval: &mut Evaluation,
        integrators: &[Integrator],
        methods: &[WindowMethod],
        application: Application,
    ) -> Result<Vec<Averaged>, StackError> {
        let groups = self.group_ranges();
        let layers: Vec<&Layer> = self.layers().collect();
        let mut outputs: Vec<BandReduction<'_>> =
            integrators.iter().map(BandReduction::Colour).collect();
        let mut averaged = Vec::new();
        for &m in methods {
            if let Some(per_layer) = layers_window_weights(&layers, m)? {
                outputs.push(BandReduction::Window(per_layer));
                averaged.push((m, Vec::with_capacity(eval.angles_deg.len())));
            }
        }
        let normals = reduced_normals(&layers, &outputs, application)?;
        let prepared: Vec<Vec<ModelSample>> = layers.iter().map(|l| l.prepare()).collect();
        for &deg in &eval.angles_deg.clone() {
            let c = cos_deg(deg);
            // per layer: its own-sample values at this angle (spectral layers under a
            // per-wavelength model)
            let own: Vec<Option<LayerValues>> = layers
                .iter()
                .zip(&prepared)
                .map(|(l, p)| match (&l.data, application) {
                    (LayerData::Spectral { .. }, Application::PerWavelength) => {
                        Some(l.values_prepared(p, 0..p.len(), c))
                    }
                    _ => None,
                })
                .collect();
            for (o, r) in outputs.iter().enumerate() {
                let mut values = Vec::with_capacity(layers.len());
                for (k, l) in layers.iter().enumerate() {
                    let v = match (&l.data, &own[k], &normals[k][o]) {
                        (LayerData::Spectral { wavelength_nm, .. }, Some(v), _) => {
                            let red = |x: &[f64], what: &str| {
                                r.reduce(k, wavelength_nm, x)
                                    .map_err(integration(layer_label(l, what, deg)))
                            };
                            LayerValues {
                                t: red(&v.t, "transmittance")?,
                                rf: red(&v.rf, "front reflectance")?,
                                rb: red(&v.rb, "back reflectance")?,
                            }
                        }
                        (_, _, Some([t, rf, rb])) => l.values_at_samples(t, rf, rb, c),
                        _ => l.channel_values_at(c).expect("channel layer"),
                    };
                    values.push(v);
                }
                let o_optics = combine(&values, &groups);
                if o < integrators.len() {
                    eval.colour[o]
                        .push(o_optics.try_map(|v| Ok::<_, StackError>([v[0], v[1], v[2]]))?);
                } else {
                    let scalar = o_optics.try_map(|v| Ok::<_, StackError>(v[0]))?;
                    averaged[o - integrators.len()].1.push(scalar);
                }
            }
        }
        Ok(averaged)
    }

    /// Each layer alone (flipped as in the unit) at `angles_deg`: its WINDOW `method` average
    /// of `(T, Rf, Rb)` per angle (none for a layer without spectrum).
    pub fn layer_averages(
        &self,
        angles_deg: &[f64],
        method: WindowMethod,
    ) -> Result<Vec<Option<Vec<[f64; 3]>>>, StackError> {
        Self::check_angles(angles_deg)?;
        self.layers()
            .map(|l| {
                let LayerData::Spectral { wavelength_nm, .. } = &l.data else {
                    return Ok(None);
                };
                let w = WindowWeights::new(method, wavelength_nm).map_err(|source| {
                    StackError::Integration {
                        what: format!("{} average of layer {}", method.name(), l.label),
                        source: Box::new(source),
                    }
                })?;
                let avg = |v: &[f64]| w.average(v).expect("same grid");
                let prepared = l.prepare();
                Ok(Some(
                    angles_deg
                        .iter()
                        .map(|&a| {
                            let v = l.values_prepared(&prepared, 0..prepared.len(), cos_deg(a));
                            [avg(&v.t), avg(&v.rf), avg(&v.rb)]
                        })
                        .collect(),
                ))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::combine::FrontBack;
    use glassdb_spectral::SpectralError;

    /// A unit of two layers and two pane groups whose spectra are all 1 but one, NaN, at `bad`
    /// in the order of [`quantity_names`].
    fn optics_with_nan_at(bad: usize) -> Optics<Vec<f64>> {
        let mut k = 0;
        let mut next = || {
            k += 1;
            vec![if k - 1 == bad { f64::NAN } else { 1.0 }]
        };
        let (t, rf, rb) = (next(), next(), next());
        let absorptance = FrontBack {
            front: vec![next(), next()],
            back: vec![next(), next()],
        };
        let share = FrontBack {
            front: vec![next(), next()],
            back: vec![next(), next()],
        };
        Optics {
            t,
            rf,
            rb,
            absorptance,
            share,
        }
    }

    #[test]
    fn an_integration_error_names_the_spectrum_that_failed() {
        let names = quantity_names(&optics_with_nan_at(usize::MAX));
        assert_eq!(names.len(), 11);
        for (bad, name) in names.iter().enumerate() {
            let err = integrate_optics(&optics_with_nan_at(bad), 30.0, |v| {
                if v[0].is_finite() {
                    Ok(v[0])
                } else {
                    Err(SpectralError::NonFinite {
                        what: "value",
                        index: 0,
                    })
                }
            })
            .unwrap_err();
            match err {
                StackError::Integration { what, .. } => assert_eq!(what, format!("{name} at 30°")),
                other => panic!("{other:?}"),
            }
        }
    }
}
