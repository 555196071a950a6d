//! Per-channel and luminous values of a spectrum (method.md "Colour", eqs. 15–20; ISO 9050 /
//! EN 410 for the luminous values).
//!
//! Every method is a weighted sum over a fixed reference grid: the spectrum is resampled onto
//! the grid (Sprague or not-a-knot spline, as colour-science does; see [`crate::interp`]) and
//! dotted with weights precomputed once in [`Integrator::new`]. A call to
//! [`Integrator::channels`] therefore costs one pass over the grid (uniform data) or one dot
//! product with the wavelength array's cached spline kernel (irregular data), and does not
//! allocate once its thread has warmed up.

use std::cell::RefCell;
use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::SpectralError;
use crate::illuminant::{CieIlluminant, Illuminant, WhiteBalance, xy_of};
use crate::interp::{check_coverage, for_each_on_grid, sprague_kernel, validate};
use crate::spline::spline_kernel;
use crate::tables::{Table, tables};
use glassdb_colour::{RgbSpace, cat02, xyz_to_rgb};

/// The RGB colour-matching functions of the paper's method (eqs. 15–20).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum RgbCmf {
    /// Wright & Guild 1931 2°, 380–780 nm at 5 nm (the CIE 1931 RGB CMFs).
    #[serde(rename = "wright-guild-1931")]
    WrightGuild1931,
    /// Stiles & Burch 1955 2°, 390–730 nm at 5 nm.
    #[serde(rename = "stiles-burch-1955")]
    StilesBurch1955,
    /// Stiles & Burch 1959 10°, 390–830 nm at 5 nm.
    #[serde(rename = "stiles-burch-1959")]
    StilesBurch1959,
}

/// CIE standard colorimetric observer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Observer {
    /// CIE 1931 2°.
    #[serde(rename = "cie1931")]
    Cie1931,
    /// CIE 1964 10°.
    #[serde(rename = "cie1964")]
    Cie1964,
}

/// How a spectrum becomes three numbers.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// The paper's eqs. 15–20: `∫ρ·c̄ dλ / ∫c̄ dλ` per RGB CMF channel, on the CMF's own grid.
    /// The CMFs have negative lobes, so a channel may exceed the largest input value or fall
    /// below the smallest: that is the formula, not a defect.
    Paper(RgbCmf),
    /// `RGB(value × illuminant) / RGB(illuminant)` per channel, XYZ through the observer over
    /// 360–780 nm at 1 nm, then CAT02 from the white the camera is balanced to (by default the
    /// illuminant's own) to the space's white (identity when they are equal, and for
    /// [`RgbSpace::Xyz`]) and the space's XYZ→RGB matrix ([`rgb_matrix`]).
    Colorimetric(ColorimetricSettings),
    /// ISO 9050 / EN 410 luminous value (D65 × V(λ), 380–780 nm at 10 nm) in all three channels.
    Luminous,
}

/// The options of the colorimetric method ([`Method::Colorimetric`]).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct ColorimetricSettings {
    /// The CIE standard observer.
    pub observer: Observer,
    /// The light the glass is seen under.
    pub illuminant: Illuminant,
    /// The linear RGB space of the channels.
    pub space: RgbSpace,
    /// The white the camera is balanced to: where the adaptation starts.
    pub white_balance: WhiteBalance,
}

/// The readable description, as [`Method`]'s `Display` gives it.
impl fmt::Display for ColorimetricSettings {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "colorimetric, {} observer, illuminant {}, {} (linear)",
            self.observer, self.illuminant, self.space
        )?;
        match &self.white_balance {
            WhiteBalance::Light => Ok(()),
            WhiteBalance::Fixed(w) => write!(f, ", camera balanced to {w}"),
        }
    }
}

impl ColorimetricSettings {
    /// The method's grid (360–780 nm at 1 nm), each grid point's RGB weights and the
    /// integrator's label: XYZ through the observer under the illuminant, CAT02 from the white
    /// the camera is balanced to, then the space's matrix, normalised so that the light's own
    /// spectrum gives its white.
    fn weights(&self) -> Result<MethodWeights, SpectralError> {
        let grid: Vec<f64> = (360..=780).map(f64::from).collect();
        let xyz_weights = xyz_weights_of(self.observer, &self.illuminant, &grid)?;
        let white_xyz = xyz_weights
            .iter()
            .fold(Vector3::zeros(), |acc, w| acc + Vector3::from(*w));
        // The adaptation starts from the white the camera is balanced to: the light's
        // own (tabulated for a CIE illuminant, integrated above for an SPD) or a fixed one.
        let from_white = match (&self.white_balance, &self.illuminant) {
            (WhiteBalance::Light, Illuminant::Spd(_)) => {
                xy_of([white_xyz[0], white_xyz[1], white_xyz[2]])
            }
            _ => self
                .white_balance
                .white_xy(&self.illuminant, self.observer)?,
        };
        let m = rgb_matrix(from_white, self.space);
        let white_rgb = m * white_xyz;
        for (c, name) in ["red", "green", "blue"].iter().enumerate() {
            if white_rgb[c].is_nan() || white_rgb[c] <= 1e-12 * white_xyz[1].abs() {
                return Err(SpectralError::DegenerateWhite {
                    illuminant: self.illuminant.name().to_owned(),
                    channel: name,
                    value: white_rgb[c],
                });
            }
        }
        let weights = xyz_weights
            .iter()
            .map(|w| {
                let rgb = m * Vector3::from(*w);
                [
                    rgb[0] / white_rgb[0],
                    rgb[1] / white_rgb[1],
                    rgb[2] / white_rgb[2],
                ]
            })
            .collect();
        let label = format!(
            "the colorimetric method ({}, {}, {})",
            self.observer.name(),
            self.illuminant.name(),
            self.space.name()
        );
        Ok(MethodWeights {
            grid_nm: grid,
            weights,
            label,
        })
    }
}

/// What an [`Integrator`] is built from: a method's grid, each grid point's channel weights
/// and the integrator's label.
struct MethodWeights {
    grid_nm: Vec<f64>,
    weights: Vec<[f64; 3]>,
    label: String,
}

/// Which of the three methods, by name: what `--method` and the JSON `method` key hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MethodKind {
    /// [`Method::Colorimetric`].
    Colorimetric,
    /// [`Method::Paper`].
    Paper,
    /// [`Method::Luminous`].
    Luminous,
}

impl Method {
    /// The method's kind (its name without options).
    pub fn kind(&self) -> MethodKind {
        match self {
            Method::Paper(_) => MethodKind::Paper,
            Method::Colorimetric(_) => MethodKind::Colorimetric,
            Method::Luminous => MethodKind::Luminous,
        }
    }
}

/// The readable description of a method with its options, as `glassdb spectral` prints it
/// and figures caption it.
impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Method::Paper(cmf) => write!(f, "paper method (eqs. 15–20), {cmf} RGB CMFs"),
            Method::Colorimetric(c) => c.fmt(f),
            Method::Luminous => f.write_str("luminous (ISO 9050: D65 × V(λ), 380–780 nm at 10 nm)"),
        }
    }
}

/// Everything an [`Integrator`] needs. Its JSON form is one flat object: `method` (a
/// [`MethodKind`]), that method's options (`cmf`; `observer`, `illuminant`, `space`,
/// `white_balance`; absent ones take their defaults, and `white_balance` is written only when it
/// is not `light`) and `extrapolate` (default false).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(into = "SettingsJson", try_from = "SettingsJson")]
pub struct IntegrationSettings {
    /// The method.
    pub method: Method,
    /// Hold the spectrum's end values constant where it does not cover the method's grid
    /// (colour-science's behaviour); without it partial coverage is an error.
    pub extrapolate: bool,
}

impl Default for IntegrationSettings {
    /// The colorimetric method in sRGB under the default illuminant.
    fn default() -> Self {
        IntegrationSettings::colorimetric(RgbSpace::Srgb, Illuminant::default())
    }
}

impl IntegrationSettings {
    /// The colorimetric method in `space` under `illuminant` (CIE 1931 observer, camera
    /// balanced to the light, no extrapolation).
    pub fn colorimetric(space: RgbSpace, illuminant: Illuminant) -> IntegrationSettings {
        IntegrationSettings {
            method: Method::Colorimetric(ColorimetricSettings {
                observer: Observer::Cie1931,
                illuminant,
                space,
                white_balance: WhiteBalance::Light,
            }),
            extrapolate: false,
        }
    }
}

/// The flat JSON form of [`IntegrationSettings`].
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SettingsJson {
    method: MethodKind,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cmf: Option<RgbCmf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    observer: Option<Observer>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    illuminant: Option<Illuminant>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    space: Option<RgbSpace>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    white_balance: Option<WhiteBalance>,
    #[serde(default)]
    extrapolate: bool,
}

impl From<IntegrationSettings> for SettingsJson {
    fn from(s: IntegrationSettings) -> SettingsJson {
        let mut json = SettingsJson {
            method: s.method.kind(),
            cmf: None,
            observer: None,
            illuminant: None,
            space: None,
            white_balance: None,
            extrapolate: s.extrapolate,
        };
        match s.method {
            Method::Paper(cmf) => json.cmf = Some(cmf),
            Method::Colorimetric(c) => {
                json.observer = Some(c.observer);
                json.illuminant = Some(c.illuminant);
                json.space = Some(c.space);
                json.white_balance =
                    (c.white_balance != WhiteBalance::Light).then_some(c.white_balance);
            }
            Method::Luminous => {}
        }
        json
    }
}

impl TryFrom<SettingsJson> for IntegrationSettings {
    type Error = String;

    /// Refuses options of another method (e.g. `cmf` with `colorimetric`).
    fn try_from(j: SettingsJson) -> Result<IntegrationSettings, String> {
        let colorimetric = j.observer.is_some()
            || j.illuminant.is_some()
            || j.space.is_some()
            || j.white_balance.is_some();
        let method = match j.method {
            MethodKind::Paper if colorimetric => {
                return Err(
                    "observer, illuminant, space and white_balance apply to method colorimetric, not paper".into(),
                );
            }
            MethodKind::Paper => Method::Paper(j.cmf.unwrap_or(RgbCmf::WrightGuild1931)),
            MethodKind::Colorimetric if j.cmf.is_some() => {
                return Err("cmf applies to method paper, not colorimetric".into());
            }
            MethodKind::Colorimetric => Method::Colorimetric(ColorimetricSettings {
                observer: j.observer.unwrap_or(Observer::Cie1931),
                illuminant: j.illuminant.unwrap_or_default(),
                space: j.space.unwrap_or(RgbSpace::Srgb),
                white_balance: j.white_balance.unwrap_or_default(),
            }),
            MethodKind::Luminous if colorimetric || j.cmf.is_some() => {
                return Err(
                    "cmf, observer, illuminant, space and white_balance do not apply to method luminous".into(),
                );
            }
            MethodKind::Luminous => Method::Luminous,
        };
        Ok(IntegrationSettings {
            method,
            extrapolate: j.extrapolate,
        })
    }
}

/// Grid for the luminous (visible) value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LuminousGrid {
    /// ISO 9050 / EN 410 table: 380–780 nm at 10 nm.
    Iso9050,
    /// 380–780 nm at 1 nm (D65 linearly interpolated, as colour-science does).
    OneNm,
}

/// Precomputed weights for one method: cheap to apply to many spectra.
#[derive(Debug, Clone)]
pub struct Integrator {
    /// Identifies the weights in the per-thread kernel cache (clones share it: same weights).
    id: u64,
    settings: IntegrationSettings,
    grid_nm: Vec<f64>,
    /// Per grid point, the weight of each channel (each channel's weights sum to 1 for a
    /// flat spectrum to give that value back).
    weights: Vec<[f64; 3]>,
    label: String,
}

impl Integrator {
    /// Builds the integrator: loads the embedded tables and precomputes the weights.
    pub fn new(settings: &IntegrationSettings) -> Result<Self, SpectralError> {
        let t = tables()?;
        let MethodWeights {
            grid_nm,
            weights,
            label,
        } = match &settings.method {
            Method::Paper(cmf) => {
                let table = match *cmf {
                    RgbCmf::WrightGuild1931 => &t.wright_guild_1931,
                    RgbCmf::StilesBurch1955 => &t.stiles_burch_1955,
                    RgbCmf::StilesBurch1959 => &t.stiles_burch_1959,
                };
                let sums: Vec<f64> = table.columns.iter().map(|c| c.iter().sum()).collect();
                let weights = (0..table.wavelength_nm.len())
                    .map(|j| [0, 1, 2].map(|c| table.columns[c][j] / sums[c]))
                    .collect();
                MethodWeights {
                    grid_nm: table.wavelength_nm.clone(),
                    weights,
                    label: format!("the paper method ({})", cmf.name()),
                }
            }
            Method::Colorimetric(c) => c.weights()?,
            Method::Luminous => {
                let (grid_nm, weights) = luminous_weights(LuminousGrid::Iso9050)?;
                MethodWeights {
                    grid_nm,
                    weights: weights.iter().map(|&w| [w; 3]).collect(),
                    label: "the ISO 9050 luminous value".to_owned(),
                }
            }
        };
        Ok(Integrator {
            id: NEXT_INTEGRATOR_ID.fetch_add(1, Ordering::Relaxed),
            settings: settings.clone(),
            grid_nm,
            weights,
            label,
        })
    }

    /// The luminous value on either grid, as an integrator (all three channels equal).
    fn luminous_on(grid: LuminousGrid) -> Result<Self, SpectralError> {
        let (grid_nm, weights) = luminous_weights(grid)?;
        let label = match grid {
            LuminousGrid::Iso9050 => "the ISO 9050 luminous value",
            LuminousGrid::OneNm => "the 1 nm luminous value",
        };
        Ok(Integrator {
            id: NEXT_INTEGRATOR_ID.fetch_add(1, Ordering::Relaxed),
            settings: IntegrationSettings {
                method: Method::Luminous,
                extrapolate: false,
            },
            grid_nm,
            weights: weights.iter().map(|&w| [w; 3]).collect(),
            label: label.to_owned(),
        })
    }

    /// Validates, checks coverage and applies the weights. Uniform data go through Sprague
    /// directly; irregular data through the cached spline kernel of their wavelength array.
    fn apply(
        &self,
        wavelength_nm: &[f64],
        values: &[f64],
        extrapolate: bool,
    ) -> Result<[f64; 3], SpectralError> {
        let check_coverage = || {
            check_coverage(
                wavelength_nm,
                &self.grid_nm,
                extrapolate,
                &self.description(),
            )
        };
        // Fast path: a wavelength array this thread has already validated (equality with the
        // cached copy implies it is valid and irregular): one dot product with its kernel.
        if wavelength_nm.len() == values.len() && values.iter().all(|v| v.is_finite()) {
            let hit = KERNELS.with(|cell| {
                let cache = cell.borrow();
                let entry = cache
                    .entries
                    .iter()
                    .find(|e| e.id == self.id && e.wavelength_nm.as_slice() == wavelength_nm)?;
                Some(dot_kernel(&entry.kernel, values))
            });
            if let Some(acc) = hit {
                check_coverage()?;
                return Ok(acc);
            }
        }
        let uniform = validate(wavelength_nm, values)?;
        check_coverage()?;
        if uniform {
            // Sprague on the grid directly: no solve, nothing to cache.
            let mut acc = [0.0f64; 3];
            let weights = &self.weights;
            for_each_on_grid(wavelength_nm, values, true, &self.grid_nm, |j, v| {
                if let Some(w) = weights.get(j) {
                    acc[0] += v * w[0];
                    acc[1] += v * w[1];
                    acc[2] += v * w[2];
                }
            });
            return Ok(acc);
        }
        // First sight of this irregular wavelength array: build its spline kernel now and
        // remember it, so that every spectrum on these wavelengths is integrated by the same
        // arithmetic (the same spectrum gives the same bits whatever was integrated before).
        let kernel = spline_kernel(wavelength_nm, &self.grid_nm, &self.weights);
        let acc = dot_kernel(&kernel, values);
        KERNELS.with(|cell| {
            let mut cache = cell.borrow_mut();
            let entry = KernelEntry {
                id: self.id,
                wavelength_nm: wavelength_nm.to_vec(),
                kernel,
            };
            if cache.entries.len() < KERNEL_CACHE_SLOTS {
                cache.entries.push(entry);
            } else {
                let slot = cache.next_slot % KERNEL_CACHE_SLOTS;
                cache.next_slot = slot + 1;
                cache.entries[slot] = entry;
            }
        });
        Ok(acc)
    }

    /// The three channel values of a spectrum (`wavelength_nm` strictly increasing, values as
    /// fractions). For [`Method::Luminous`] all three are the luminous value.
    ///
    /// Cost: uniform spacing evaluates Sprague on the grid directly. Irregular spacing builds
    /// the spline's linear kernel the first time a thread sees a wavelength array (kept for the
    /// 8 most recent arrays); from then on a spectrum on the same wavelengths is one dot
    /// product. Either way the result depends only on the spectrum, not on what the thread
    /// integrated before.
    pub fn channels(
        &self,
        wavelength_nm: &[f64],
        values: &[f64],
    ) -> Result<[f64; 3], SpectralError> {
        self.apply(wavelength_nm, values, self.settings.extrapolate)
    }

    /// This integrator fixed to one wavelength array, for integrating many spectra sampled on
    /// it: one dot product with the array's kernel per spectrum, the same numbers as
    /// [`Integrator::channels`] (bit for bit on irregular wavelengths, to rounding on uniform
    /// ones, where `channels` evaluates Sprague directly). Errors as `channels` for the array
    /// (validity, coverage).
    pub fn on_grid(&self, wavelength_nm: &[f64]) -> Result<GridIntegrator, SpectralError> {
        let probe = vec![0.0; wavelength_nm.len()];
        let uniform = validate(wavelength_nm, &probe)?;
        check_coverage(
            wavelength_nm,
            &self.grid_nm,
            self.settings.extrapolate,
            &self.description(),
        )?;
        let kernel = if uniform {
            sprague_kernel(wavelength_nm, &self.grid_nm, &self.weights)
        } else {
            spline_kernel(wavelength_nm, &self.grid_nm, &self.weights)
        };
        Ok(GridIntegrator {
            wavelength_nm: wavelength_nm.to_vec(),
            kernel,
        })
    }

    /// The settings this integrator was built from.
    pub fn settings(&self) -> &IntegrationSettings {
        &self.settings
    }

    /// The reference grid (nm) the spectrum is resampled onto.
    pub fn grid_nm(&self) -> &[f64] {
        &self.grid_nm
    }

    /// The grid's per-channel weights (each channel sums to 1).
    pub fn weights(&self) -> &[[f64; 3]] {
        &self.weights
    }

    fn description(&self) -> String {
        let (first, last) = (
            self.grid_nm.first().copied().unwrap_or(0.0),
            self.grid_nm.last().copied().unwrap_or(0.0),
        );
        let step = self.grid_nm.get(1).map(|s| s - first).unwrap_or(0.0);
        format!("{} on {first}–{last} nm at {step} nm", self.label)
    }
}

/// An [`Integrator`] fixed to one wavelength array ([`Integrator::on_grid`]).
#[derive(Debug, Clone)]
pub struct GridIntegrator {
    wavelength_nm: Vec<f64>,
    /// Per sample of the array, its weight in each channel (Sprague's or the spline's).
    kernel: Vec<[f64; 3]>,
}

impl GridIntegrator {
    /// The channels of a spectrum on the array (as many finite values as wavelengths).
    pub fn channels(&self, values: &[f64]) -> Result<[f64; 3], SpectralError> {
        crate::interp::validate_values(&self.wavelength_nm, values)?;
        Ok(dot_kernel(&self.kernel, values))
    }
}

/// `S(λ)·x̄(λ), S(λ)·ȳ(λ), S(λ)·z̄(λ)` of the light `illuminant` and the CMFs of `observer` on
/// `grid` (every grid point a row of the CMF table).
pub(crate) fn xyz_weights_of(
    observer: Observer,
    illuminant: &Illuminant,
    grid: &[f64],
) -> Result<Vec<[f64; 3]>, SpectralError> {
    let t = tables()?;
    let cmfs = match observer {
        Observer::Cie1931 => &t.cie_1931,
        Observer::Cie1964 => &t.cie_1964,
    };
    xyz_weights(cmfs, illuminant.power_on(grid)?, grid)
}

/// `S(λ)·x̄(λ), S(λ)·ȳ(λ), S(λ)·z̄(λ)` on `grid` (every grid point must be a table row).
fn xyz_weights(cmfs: &Table, spd: Vec<f64>, grid: &[f64]) -> Result<Vec<[f64; 3]>, SpectralError> {
    grid.iter()
        .zip(spd)
        .map(|(&w, s)| {
            let j = cmfs
                .index_of(w)
                .ok_or_else(|| SpectralError::EmbeddedTable {
                    table: "CIE CMFs",
                    message: format!("no row at {w} nm"),
                })?;
            Ok([0, 1, 2].map(|c| s * cmfs.columns[c][j]))
        })
        .collect()
}

/// Normalised `D65(λ)·V(λ)` weights of the luminous value on the chosen grid.
fn luminous_weights(grid: LuminousGrid) -> Result<(Vec<f64>, Vec<f64>), SpectralError> {
    let t = tables()?;
    let step = match grid {
        LuminousGrid::Iso9050 => 10,
        LuminousGrid::OneNm => 1,
    };
    let grid: Vec<f64> = (380..=780).step_by(step).map(f64::from).collect();
    let xyz = xyz_weights(&t.cie_1931, CieIlluminant::D65.power_on(&grid)?, &grid)?;
    let total: f64 = xyz.iter().map(|w| w[1]).sum();
    Ok((grid, xyz.iter().map(|w| w[1] / total).collect()))
}

/// XYZ → linear RGB of `space` for a camera balanced to the white `from_white_xy`: what
/// colour-science 0.4.7's `XYZ_to_RGB(XYZ, space, illuminant=from_white_xy)` does with its
/// default `chromatic_adaptation_transform="CAT02"`, i.e. `xyz_to_rgb(space) · M_CAT02(from
/// white → space white)` (method.md eqs. 15–20 for the integration; von Kries in the CAT02
/// sharpened space). The adaptation is left out (exactly the identity) when the two whites are
/// equal and for [`RgbSpace::Xyz`].
pub fn rgb_matrix(from_white_xy: [f64; 2], space: RgbSpace) -> Matrix3<f64> {
    let m = xyz_to_rgb(space);
    match space.whitepoint_xy() {
        Some(white) if white != from_white_xy => m * cat02(from_white_xy, white),
        _ => m,
    }
}

/// Visible (luminous) transmittance or reflectance per ISO 9050 / EN 410: `Σ v·D65·V / Σ D65·V`
/// over 380–780 nm at 10 nm. The spectrum must cover 380–780 nm.
pub fn luminous_iso9050(wavelength_nm: &[f64], values: &[f64]) -> Result<f64, SpectralError> {
    luminous(wavelength_nm, values, LuminousGrid::Iso9050, false)
}

/// Luminous value on either grid, optionally holding end values outside the data.
pub fn luminous(
    wavelength_nm: &[f64],
    values: &[f64],
    grid: LuminousGrid,
    extrapolate: bool,
) -> Result<f64, SpectralError> {
    static ISO: OnceLock<Result<Integrator, Arc<SpectralError>>> = OnceLock::new();
    static ONE: OnceLock<Result<Integrator, Arc<SpectralError>>> = OnceLock::new();
    let cell = match grid {
        LuminousGrid::Iso9050 => &ISO,
        LuminousGrid::OneNm => &ONE,
    };
    let integrator = cell
        .get_or_init(|| Integrator::luminous_on(grid).map_err(Arc::new))
        .as_ref()
        .map_err(|source| SpectralError::EmbeddedData {
            what: "luminous weights",
            source: Arc::clone(source),
        })?;
    Ok(integrator.apply(wavelength_nm, values, extrapolate)?[1])
}

/// `Σ_i kernel[i] · values[i]` per channel.
fn dot_kernel(kernel: &[[f64; 3]], values: &[f64]) -> [f64; 3] {
    let mut acc = [0.0f64; 3];
    for (k, v) in kernel.iter().zip(values) {
        acc[0] += k[0] * v;
        acc[1] += k[1] * v;
        acc[2] += k[2] * v;
    }
    acc
}

static NEXT_INTEGRATOR_ID: AtomicU64 = AtomicU64::new(0);

/// Kernels kept per thread (one per integrator × wavelength array in recent use).
const KERNEL_CACHE_SLOTS: usize = 8;

struct KernelEntry {
    id: u64,
    wavelength_nm: Vec<f64>,
    /// The spline's linear map from the values to the channels.
    kernel: Vec<[f64; 3]>,
}

#[derive(Default)]
struct KernelCache {
    entries: Vec<KernelEntry>,
    next_slot: usize,
}

thread_local! {
    static KERNELS: RefCell<KernelCache> = RefCell::new(KernelCache::default());
}

names!(RgbCmf { WrightGuild1931 => "wright-guild-1931", StilesBurch1955 => "stiles-burch-1955", StilesBurch1959 => "stiles-burch-1959" });
names!(Observer { Cie1931 => "cie1931", Cie1964 => "cie1964" });
names!(MethodKind { Colorimetric => "colorimetric", Paper => "paper", Luminous => "luminous" });

#[cfg(test)]
mod tests;
