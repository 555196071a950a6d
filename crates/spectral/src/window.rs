//! The spectral averages of LBNL WINDOW (NFRC 300-2003, the `W5_NFRC_2003` standard that
//! pywincalc and Windows-CalcEngine load): the photopic value (D65 × CIE 1931 ȳ of ASTM E308,
//! 380–780 nm on the 5 nm "Color" wavelength set) and the solar value (ASTM E891 direct AM1.5,
//! 300–2500 nm on the source's own wavelengths). Used where glassdb reports what WINDOW
//! reports (`glassdb stack`, docs/stack.md); the colour and ISO 9050 values stay in
//! [`crate::Integrator`] and [`crate::luminous_iso9050`].
//!
//! The computation is Windows-CalcEngine's (`CSeries::interpolate`, `CIntegratorTrapezoidal`,
//! `CSeries::sum`, `CalculationProperties::scaledSolarRadiation`): the spectrum is linearly
//! interpolated onto the method's wavelength set (end values held outside the data), multiplied
//! by the source × detector weight interpolated the same way, integrated by the trapezoidal rule
//! over the intervals that start in `[min, max)`, and divided by the weight's own integral. The
//! average is linear in the spectrum, so [`WindowWeights`] folds it into one weight per input
//! wavelength, computed once per wavelength array.

use std::sync::OnceLock;

use crate::error::SpectralError;
use crate::interp::validate_grid;
use crate::read::microns_to_nm;

const D65_1NM: &str = include_str!("../../../data/window/cie_illuminant_d65_1nm.ssp");
const E308_1931_Y: &str = include_str!("../../../data/window/astm_e308_1931_y.dsp");
const COLOR_5NM: &str = include_str!("../../../data/window/color_5nm.wvl");
const E891_DIRECT: &str = include_str!("../../../data/window/astm_e891_direct_am1_5.ssp");

/// Windows-CalcEngine's tolerance on the ends of the summed range (1e-6 µm).
const RANGE_TOLERANCE_NM: f64 = 1e-3;

/// One of WINDOW's NFRC 300-2003 spectral averages.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WindowMethod {
    /// `PHOTOPIC`: source CIE D65 (1 nm), detector ASTM E308 CIE 1931 ȳ (5 nm), wavelength set
    /// 380–780 nm at 5 nm, trapezoidal, 380–780 nm.
    Photopic,
    /// `SOLAR`: source ASTM E891 Table 1 direct normal AM1.5, no detector, the source's
    /// wavelengths, trapezoidal, 300–2500 nm.
    Solar,
}

impl WindowMethod {
    /// Both methods, photopic first.
    pub const ALL: [WindowMethod; 2] = [WindowMethod::Photopic, WindowMethod::Solar];

    /// The method's name in WINDOW's standard file (`PHOTOPIC`, `SOLAR`).
    pub fn name(self) -> &'static str {
        match self {
            WindowMethod::Photopic => "PHOTOPIC",
            WindowMethod::Solar => "SOLAR",
        }
    }

    /// The wavelength range the average covers (nm): 380–780 or 300–2500.
    pub fn range_nm(self) -> (f64, f64) {
        match self {
            WindowMethod::Photopic => (380.0, 780.0),
            WindowMethod::Solar => (300.0, 2500.0),
        }
    }

    /// The method's wavelength set and the source × detector weight on it (nm, relative).
    fn weighting(self) -> Result<&'static Weighting, SpectralError> {
        static PHOTOPIC: OnceLock<Result<Weighting, String>> = OnceLock::new();
        static SOLAR: OnceLock<Result<Weighting, String>> = OnceLock::new();
        let cell = match self {
            WindowMethod::Photopic => &PHOTOPIC,
            WindowMethod::Solar => &SOLAR,
        };
        cell.get_or_init(|| Weighting::build(self))
            .as_ref()
            .map_err(|message| SpectralError::EmbeddedTable {
                table: match self {
                    WindowMethod::Photopic => "WINDOW photopic weighting",
                    WindowMethod::Solar => "WINDOW solar weighting",
                },
                message: message.clone(),
            })
    }
}

impl std::fmt::Display for WindowMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WindowMethod::Photopic => {
                f.write_str("WINDOW photopic (NFRC 300-2003: D65 × CIE 1931 ȳ)")
            }
            WindowMethod::Solar => {
                f.write_str("WINDOW solar (NFRC 300-2003: ASTM E891 AM1.5 direct)")
            }
        }
    }
}

/// A method's wavelength set with the trapezoid weight of each point, normalised to sum 1.
#[derive(Debug)]
struct Weighting {
    wavelength_nm: Vec<f64>,
    weight: Vec<f64>,
}

/// A WINDOW data file (`.ssp`, `.dsp`, `.wvl`): header lines, then rows of one or two numbers;
/// `Wavelength Units: micron(s)` or `nanometers` (any case). Returns (nm, value) rows (value 0
/// for a one-column wavelength set).
fn parse_window_table(text: &str) -> Result<Vec<(f64, f64)>, String> {
    let mut microns = None;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if let Some(units) = line
            .to_ascii_lowercase()
            .strip_prefix("wavelength units:")
            .map(str::trim)
            .map(str::to_owned)
        {
            microns = Some(units.starts_with("micron"));
            continue;
        }
        let fields: Vec<&str> = line.split_whitespace().collect();
        let numbers: Option<Vec<f64>> = fields.iter().map(|f| f.parse::<f64>().ok()).collect();
        match numbers {
            Some(n) if !n.is_empty() && n.len() <= 2 => {
                let um = microns.ok_or_else(|| format!("line {}: data before units", i + 1))?;
                let nm = if um { microns_to_nm(n[0]) } else { n[0] };
                rows.push((nm, n.get(1).copied().unwrap_or(0.0)));
            }
            _ => {}
        }
    }
    if rows.len() < 2 || rows.windows(2).any(|p| p[1].0 <= p[0].0) {
        return Err("wavelengths missing or not ascending".into());
    }
    Ok(rows)
}

/// Windows-CalcEngine's linear interpolation: the value at `x`, end values held outside.
fn interpolate(rows: &[(f64, f64)], x: f64) -> f64 {
    let (lower, upper) = bracket(rows.iter().map(|r| r.0), x);
    let (x1, y1) = rows[lower];
    let (x2, y2) = rows[upper];
    if x2 == x1 {
        y1
    } else {
        y1 + (x - x1) * (y2 - y1) / (x2 - x1)
    }
}

/// The indices of the last point at or below `x` and of the first above it (the same index
/// twice outside the data), as `CSeries::findLower` / `findUpper` choose them.
fn bracket(xs: impl ExactSizeIterator<Item = f64>, x: f64) -> (usize, usize) {
    let n = xs.len();
    let above = xs.take_while(|&w| w <= x).count();
    match above {
        0 => (0, 0),
        k if k == n => (n - 1, n - 1),
        k => (k - 1, k),
    }
}

impl Weighting {
    fn build(method: WindowMethod) -> Result<Weighting, String> {
        let (grid, source): (Vec<f64>, Vec<f64>) = match method {
            WindowMethod::Photopic => {
                let d65 = parse_window_table(D65_1NM)?;
                let ybar = parse_window_table(E308_1931_Y)?;
                let set = parse_window_table(COLOR_5NM)?;
                let grid: Vec<f64> = set.iter().map(|r| r.0).collect();
                let source = grid
                    .iter()
                    .map(|&w| interpolate(&d65, w) * interpolate(&ybar, w))
                    .collect();
                (grid, source)
            }
            WindowMethod::Solar => parse_window_table(E891_DIRECT)?.into_iter().unzip(),
        };
        let (lo, hi) = method.range_nm();
        let mut weight = vec![0.0; grid.len()];
        for j in 1..grid.len() {
            let start = grid[j - 1];
            if start >= lo - RANGE_TOLERANCE_NM && start < hi - RANGE_TOLERANCE_NM {
                let half = 0.5 * (grid[j] - start);
                weight[j - 1] += half * source[j - 1];
                weight[j] += half * source[j];
            }
        }
        let total: f64 = weight.iter().sum();
        if total.is_nan() || total <= 0.0 {
            return Err("the weighting integrates to zero".into());
        }
        weight.iter_mut().for_each(|w| *w /= total);
        Ok(Weighting {
            wavelength_nm: grid,
            weight,
        })
    }
}

/// A WINDOW average folded into one weight per wavelength of a spectrum's grid: build it once
/// per wavelength array ([`WindowWeights::new`]), then [`WindowWeights::average`] is one dot
/// product per spectrum.
#[derive(Debug, Clone, PartialEq)]
pub struct WindowWeights {
    method: WindowMethod,
    weights: Vec<f64>,
}

impl WindowWeights {
    /// The weights of `method` for spectra sampled at `wavelength_nm` (strictly increasing,
    /// finite; an empty or one-point grid covers nothing). The data must cover the method's range (as WINDOW refuses a layer that does not:
    /// "Product without measured data for entire wavelength range").
    pub fn new(
        method: WindowMethod,
        wavelength_nm: &[f64],
    ) -> Result<WindowWeights, SpectralError> {
        validate_grid(wavelength_nm)?;
        let (lo, hi) = method.range_nm();
        let (first, last) = match wavelength_nm {
            [first, .., last] => (*first, *last),
            [only] => (*only, *only),
            [] => (f64::NAN, f64::NAN),
        };
        let covers = first <= lo + RANGE_TOLERANCE_NM && last >= hi - RANGE_TOLERANCE_NM;
        if !covers {
            return Err(SpectralError::WindowCoverage {
                method: method.name(),
                have_start_nm: first,
                have_end_nm: last,
                need_start_nm: lo,
                need_end_nm: hi,
            });
        }
        let weighting = method.weighting()?;
        let mut weights = vec![0.0; wavelength_nm.len()];
        for (&x, &w) in weighting.wavelength_nm.iter().zip(&weighting.weight) {
            if w == 0.0 {
                continue;
            }
            let (lower, upper) = bracket(wavelength_nm.iter().copied(), x);
            let (x1, x2) = (wavelength_nm[lower], wavelength_nm[upper]);
            if x2 == x1 {
                weights[lower] += w;
            } else {
                let f = (x - x1) / (x2 - x1);
                weights[lower] += w * (1.0 - f);
                weights[upper] += w * f;
            }
        }
        Ok(WindowWeights { method, weights })
    }

    /// The method these weights apply.
    pub fn method(&self) -> WindowMethod {
        self.method
    }

    /// The average of one spectrum sampled on the grid the weights were built for; an error
    /// when its length differs.
    pub fn average(&self, values: &[f64]) -> Result<f64, SpectralError> {
        if values.len() != self.weights.len() {
            return Err(SpectralError::LengthMismatch {
                wavelengths: self.weights.len(),
                values: values.len(),
            });
        }
        Ok(self.weights.iter().zip(values).map(|(w, v)| w * v).sum())
    }
}

/// WINDOW's `method` average of one spectrum ([`WindowWeights`] for one use).
pub fn window_average(
    method: WindowMethod,
    wavelength_nm: &[f64],
    values: &[f64],
) -> Result<f64, SpectralError> {
    crate::interp::validate_values(wavelength_nm, values)?;
    WindowWeights::new(method, wavelength_nm)?.average(values)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same average computed the long way, as Windows-CalcEngine does: interpolate the
    /// spectrum and the weight onto the wavelength set, trapezoids, sum over the range.
    fn long_way(method: WindowMethod, wl: &[f64], v: &[f64]) -> f64 {
        let rows: Vec<(f64, f64)> = wl.iter().copied().zip(v.iter().copied()).collect();
        let (grid, source): (Vec<f64>, Vec<f64>) = match method {
            WindowMethod::Photopic => {
                let d65 = parse_window_table(D65_1NM).unwrap();
                let y = parse_window_table(E308_1931_Y).unwrap();
                let set = parse_window_table(COLOR_5NM).unwrap();
                set.iter()
                    .map(|r| (r.0, interpolate(&d65, r.0) * interpolate(&y, r.0)))
                    .unzip()
            }
            WindowMethod::Solar => parse_window_table(E891_DIRECT).unwrap().into_iter().unzip(),
        };
        let (lo, hi) = method.range_nm();
        let (mut num, mut den) = (0.0, 0.0);
        for j in 1..grid.len() {
            if grid[j - 1] >= lo - 1e-3 && grid[j - 1] < hi - 1e-3 {
                let d = grid[j] - grid[j - 1];
                let m0 = interpolate(&rows, grid[j - 1]) * source[j - 1];
                let m1 = interpolate(&rows, grid[j]) * source[j];
                num += 0.5 * (m0 + m1) * d;
                den += 0.5 * (source[j - 1] + source[j]) * d;
            }
        }
        num / den
    }

    #[test]
    fn tables_parse_with_their_units() {
        let d65 = parse_window_table(D65_1NM).unwrap();
        assert_eq!((d65[0].0, d65[d65.len() - 1].0), (300.0, 830.0));
        let y = parse_window_table(E308_1931_Y).unwrap();
        assert_eq!((y[0].0, y[y.len() - 1].0, y.len()), (380.0, 780.0, 81));
        let s = parse_window_table(E891_DIRECT).unwrap();
        assert_eq!((s[0].0, s[s.len() - 1].0), (300.0, 4045.0));
        // D65 is 100 at 560 nm; ȳ is 0.995 at 560 nm in ASTM E308's 4-decimal table.
        assert!((interpolate(&d65, 560.0) - 100.0).abs() < 1e-9);
        assert!((interpolate(&y, 560.0) - 0.995).abs() < 1e-12);
    }

    #[test]
    fn folded_weights_equal_the_long_way_and_keep_a_flat_spectrum() {
        let wl: Vec<f64> = (0..=440)
            .map(|i| 300.0 + 5.0 * i as f64 + (i % 3) as f64)
            .collect();
        let v: Vec<f64> = wl.iter().map(|w| 0.5 + 0.4 * (w / 97.0).sin()).collect();
        for method in WindowMethod::ALL {
            let fast = window_average(method, &wl, &v).unwrap();
            let slow = long_way(method, &wl, &v);
            assert!((fast - slow).abs() < 1e-14, "{method}: {fast} vs {slow}");
            let flat = window_average(method, &wl, &vec![0.37; wl.len()]).unwrap();
            assert!((flat - 0.37).abs() < 1e-14, "{method}: {flat}");
        }
    }

    #[test]
    fn partial_coverage_is_refused() {
        let wl: Vec<f64> = (0..=100).map(|i| 380.0 + 4.0 * i as f64).collect();
        let v = vec![0.5; wl.len()];
        assert!(window_average(WindowMethod::Photopic, &wl, &v).is_ok());
        let e = window_average(WindowMethod::Solar, &wl, &v).unwrap_err();
        assert!(
            e.to_string().contains("SOLAR") && e.to_string().contains("300"),
            "{e}"
        );
    }
}
