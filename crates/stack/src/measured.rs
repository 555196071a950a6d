//! Measured angle tables of a layer: the table's R and T continued beyond its last angle by the
//! layer's physical model ([`continue_measured`], `docs/registry.md` "Measured angle table"),
//! and, for a layer inside a unit, the continued table fitted once to curves `R_t(θ)`, `T_t(θ)`
//! that carry its angle dependence to every wavelength ([`MeasuredRatio`]: T as the paper's
//! ratio, `T(λ, θ) = T0(λ)·T_t(θ)/T_t(0)`; R as the affine map that keeps R(90°) = 1 at every
//! wavelength, `R(λ, θ) = R0(λ) + (R_t(θ) − R_t(0))·(1 − R0(λ))/(1 − R_t(0))`).

use glassdb_fit::{AngleSamples, CosPolynomial, FitOptions, Quantity};

use crate::StackError;

/// Step (degrees) of the angle grid on which models are sampled for fitting: 0–90° in 1°.
pub const MODEL_STEP_DEG: f64 = 1.0;

/// The model angle grid: 0, 1, …, 90°.
pub fn model_angles_deg() -> Vec<f64> {
    let steps = (90.0 / MODEL_STEP_DEG).round() as usize;
    (0..=steps).map(|i| i as f64 * MODEL_STEP_DEG).collect()
}

/// `cos θ` of an angle in degrees, exactly 0 at 90° (so that grazing gets R = 1, T = 0).
pub fn cos_deg(deg: f64) -> f64 {
    if deg >= 90.0 {
        0.0
    } else {
        deg.to_radians().cos()
    }
}

/// A measured table continued by the physical model beyond its last angle so that R → 1 and
/// T → 0 at 90°: for θ > θmax, `R(θ) = Rm + (Rp(θ) − Rp(θmax))·(1 − Rm)/(1 − Rp(θmax))` and
/// `T(θ) = Tm·Tp(θ)/Tp(θmax)`, with Rm, Tm the measured values at θmax and Rp, Tp the model's
/// values `model` on the grid `angles` (0, [`MODEL_STEP_DEG`], …, 90°), interpolated linearly.
pub fn continue_measured(
    m: &AngleSamples,
    angles: &[f64],
    model: &[f64],
    reflect: bool,
) -> AngleSamples {
    let mut out = m.clone();
    let Some((last_i, &theta_max)) = m
        .angle_deg
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
    else {
        return out;
    };
    if theta_max >= 90.0 - 1e-9 || model.len() < 2 {
        return out;
    }
    let measured_at_max = m.value[last_i];
    let model_at = |deg: f64| -> f64 {
        let x = deg.clamp(0.0, 90.0) / MODEL_STEP_DEG;
        let i = (x.floor() as usize).min(model.len() - 2);
        let f = x - i as f64;
        model[i] * (1.0 - f) + model[i + 1] * f
    };
    let at_max = model_at(theta_max);
    for &deg in angles.iter().filter(|&&d| d > theta_max + 0.5) {
        let v = if reflect {
            if at_max < 1.0 {
                measured_at_max
                    + (model_at(deg) - at_max) * (1.0 - measured_at_max) / (1.0 - at_max)
            } else {
                1.0
            }
        } else if at_max > 0.0 {
            measured_at_max * model_at(deg) / at_max
        } else {
            0.0
        };
        out.angle_deg.push(deg);
        out.value.push(v.clamp(0.0, 1.0));
    }
    out
}

/// A layer's measured angle table, fitted: the front reflectance and the transmittance as
/// `normal·C(cos θ)` (either may be absent: the model then gives that quantity).
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredRatio {
    /// R_t(0) and `C_r(cos θ)` of the front reflectance.
    pub reflectance: Option<(f64, CosPolynomial)>,
    /// T_t(0) and `C_t(cos θ)` of the transmittance.
    pub transmittance: Option<(f64, CosPolynomial)>,
    /// The largest measured angle.
    pub max_angle_deg: f64,
}

impl MeasuredRatio {
    /// The front reflectance at `cos θ` of a wavelength whose normal value is `r0`: the table's
    /// rise from its 0° value mapped onto `[r0, 1]` (none without a reflectance table).
    pub fn reflectance_at(&self, r0: f64, cos_theta: f64) -> Option<f64> {
        let (rt0, c) = self.reflectance.as_ref()?;
        let rise = rt0 * c.eval(cos_theta) - rt0;
        let r = if *rt0 < 1.0 {
            r0 + rise * (1.0 - r0) / (1.0 - rt0)
        } else {
            r0
        };
        Some(r.clamp(0.0, 1.0))
    }

    /// The transmittance at `cos θ` of a wavelength whose normal value is `t0`: `t0·C_t(cos θ)`
    /// (none without a transmittance table).
    pub fn transmittance_at(&self, t0: f64, cos_theta: f64) -> Option<f64> {
        let (_, c) = self.transmittance.as_ref()?;
        Some((t0 * c.eval(cos_theta)).clamp(0.0, 1.0))
    }
}

/// How tightly the continued tables are fitted (the registry's defaults).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RatioFit {
    /// Absolute tolerance on R or T.
    pub tol: f64,
    /// Highest degree tried.
    pub max_degree: u32,
}

impl Default for RatioFit {
    fn default() -> RatioFit {
        RatioFit {
            tol: glassdb_fit::DEFAULT_TOL,
            max_degree: 12,
        }
    }
}

impl MeasuredRatio {
    /// Fits the measured R and T samples, each continued beyond its last angle by the model
    /// values `model_r`, `model_t` on [`model_angles_deg`] (a broadband value of the layer:
    /// its luminous value, or the table's own for a grey layer).
    pub fn fit(
        reflectance: Option<&AngleSamples>,
        transmittance: Option<&AngleSamples>,
        model_r: &[f64],
        model_t: &[f64],
        opts: RatioFit,
        label: &str,
    ) -> Result<MeasuredRatio, StackError> {
        let angles = model_angles_deg();
        let mut max_angle_deg: f64 = 0.0;
        let mut fit = |samples: Option<&AngleSamples>, model: &[f64], quantity, curve| {
            samples
                .map(|m| {
                    max_angle_deg = m.angle_deg.iter().copied().fold(max_angle_deg, f64::max);
                    let continued =
                        continue_measured(m, &angles, model, quantity == Quantity::Reflectance);
                    let mut fo = FitOptions::new(quantity);
                    fo.tol = opts.tol;
                    fo.max_degree = opts.max_degree;
                    glassdb_fit::fit_curve(&continued, &fo)
                        .map(|f| (f.normal, f.polynomial))
                        .map_err(|source| StackError::Fit {
                            label: label.to_string(),
                            curve,
                            source: Box::new(source),
                        })
                })
                .transpose()
        };
        let reflectance = fit(reflectance, model_r, Quantity::Reflectance, "R")?;
        let transmittance = fit(transmittance, model_t, Quantity::Transmittance, "T")?;
        Ok(MeasuredRatio {
            reflectance,
            transmittance,
            max_angle_deg,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn continuation_is_continuous_and_reaches_grazing_limits() {
        let angles = model_angles_deg();
        let model_r: Vec<f64> = angles
            .iter()
            .map(|a| 0.08 + 0.92 * (a / 90.0f64).powi(6))
            .collect();
        let model_t: Vec<f64> = angles.iter().map(|&a| 0.9 * cos_deg(a).powf(0.3)).collect();
        let m = AngleSamples {
            angle_deg: vec![0.0, 20.0, 40.0, 60.0],
            value: vec![0.1, 0.1, 0.11, 0.16],
        };
        let r = continue_measured(&m, &angles, &model_r, true);
        assert_eq!(r.angle_deg[4], 61.0);
        assert!((r.value[r.value.len() - 1] - 1.0).abs() < 1e-12);
        assert!((r.value[4] - 0.16).abs() < 0.01, "{}", r.value[4]);
        let t = continue_measured(&m, &angles, &model_t, false);
        assert_eq!(*t.value.last().unwrap(), 0.0);
    }
}
