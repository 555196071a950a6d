//! Angle models of a glass: the physical model (uncoated slab, coated clear/bronze, opaque)
//! sampled at 0–90° per wavelength or per channel, and a measured angle table replacing it up
//! to its last angle, continued by the model to grazing incidence (`docs/registry.md`).

use glassdb_fit::AngleSamples;
use glassdb_spectral::Integrator;

use crate::catalog::{GlassSpec, ModelChoice};
use crate::catalog_files::{Application, CatalogFiles, sha256_hex};
use crate::normal::{NormalValues, Spectra, integrate};
use crate::physics::{
    CoatedCurve, UncoatedSlab, fresnel_single_surface, ior_from_reflectance, opaque_reflectance,
};
use crate::{FileRef, RegistryError};

/// Angles (degrees) at which a physical model is sampled for fitting: 0–90° in 1° steps.
pub(crate) const MODEL_STEP_DEG: f64 = 1.0;

/// Front and back reflectance of a glass are "equal" (uncoated) when they differ by less than
/// this everywhere (the rule of the Modelica Buildings library, `glassProperty`, tol = 0.005).
const UNCOATED_RF_RB_TOL: f64 = 0.005;

/// The physical model chosen for a glass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Physical {
    Uncoated,
    /// Clear/bronze chosen per wavelength (or per channel) by T0 > 0.645.
    Coated,
    CoatedFixed(CoatedCurve),
    Opaque,
}

impl Physical {
    pub(crate) fn name(self) -> &'static str {
        match self {
            Physical::Uncoated => "uncoated",
            Physical::Coated => "coated",
            Physical::CoatedFixed(CoatedCurve::Clear) => "coated-clear",
            Physical::CoatedFixed(CoatedCurve::Bronze) => "coated-bronze",
            Physical::Opaque => "opaque",
        }
    }
}

/// `(Rf, T, Rb)` of one wavelength (or channel) at `cos θ`.
fn model_at(
    model: Physical,
    t0: f64,
    rf0: f64,
    rb0: f64,
    ior: Option<(f64, f64)>,
    cos_theta: f64,
) -> (f64, f64, f64) {
    match model {
        Physical::Uncoated => {
            let (rf, t) = UncoatedSlab::from_normal(t0, rf0).at(cos_theta);
            let (rb, _) = UncoatedSlab::from_normal(t0, rb0).at(cos_theta);
            (rf, t, rb)
        }
        Physical::Coated | Physical::CoatedFixed(_) => {
            let curve = match model {
                Physical::CoatedFixed(c) => c,
                _ => CoatedCurve::for_t0(t0),
            };
            let (rf, t) = curve.at(t0, rf0, cos_theta);
            let (rb, _) = curve.at(t0, rb0, cos_theta);
            (rf, t, rb)
        }
        Physical::Opaque => {
            let f = |r0: f64| match ior {
                Some(nk) => opaque_reflectance(r0, nk, cos_theta),
                None => fresnel_single_surface(ior_from_reflectance(r0), 0.0, cos_theta),
            };
            (f(rf0), 0.0, f(rb0))
        }
    }
}

/// Picks the physical model for `auto` from the product type, or from the data.
pub(crate) fn choose_model(
    spec: &GlassSpec,
    product_type: Option<&str>,
    t: &[f64],
    rf: &[f64],
    rb: &[f64],
) -> (Physical, String) {
    let fixed = match spec.model {
        ModelChoice::Uncoated => Some(Physical::Uncoated),
        ModelChoice::Coated => Some(Physical::Coated),
        ModelChoice::CoatedClear => Some(Physical::CoatedFixed(CoatedCurve::Clear)),
        ModelChoice::CoatedBronze => Some(Physical::CoatedFixed(CoatedCurve::Bronze)),
        ModelChoice::Opaque => Some(Physical::Opaque),
        ModelChoice::Auto => None,
    };
    if let Some(m) = fixed {
        return (m, "catalog `model`".into());
    }
    if spec.ior.is_some() {
        return (Physical::Opaque, "catalog `ior`".into());
    }
    if t.iter().all(|&v| v <= 0.0) {
        return (Physical::Opaque, "zero transmittance".into());
    }
    if let Some(pt) = product_type {
        let p = pt.to_ascii_lowercase();
        if p.contains("monolithic") {
            return (Physical::Uncoated, format!("product type \"{pt}\""));
        }
        let coated = ["coat", "laminate", "film", "interlayer"];
        if coated.iter().any(|k| p.contains(k)) {
            return (Physical::Coated, format!("product type \"{pt}\""));
        }
    }
    let max_diff = rf
        .iter()
        .zip(rb)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    if max_diff < UNCOATED_RF_RB_TOL {
        let why = format!("Rf = Rb within {UNCOATED_RF_RB_TOL} (max difference {max_diff:.4})");
        (Physical::Uncoated, why)
    } else {
        (
            Physical::Coated,
            format!("Rf differs from Rb by up to {max_diff:.4}"),
        )
    }
}

/// The physical model sampled every [`MODEL_STEP_DEG`] from 0° to 90°: per angle, per
/// channel, front reflectance, transmittance and back reflectance (row 0: the normal values).
pub(crate) struct ModelTables {
    pub angles: Vec<f64>,
    pub rf: Vec<[f64; 3]>,
    pub t: Vec<[f64; 3]>,
    pub rb: Vec<[f64; 3]>,
}

impl ModelTables {
    /// Samples `model` per wavelength of `spectra` (then integrated) when `application` says so
    /// and a spectrum exists, else per channel from the normal values.
    pub(crate) fn sample(
        model: Physical,
        spec: &GlassSpec,
        normal: &NormalValues,
        spectra: Option<&Spectra>,
        application: Application,
        integrator: &Integrator,
        glass: &str,
    ) -> Result<ModelTables, RegistryError> {
        let ior_per_channel = spec.ior;
        let ior_single = ior_per_channel.map(|v| v[1]);
        let steps = (90.0 / MODEL_STEP_DEG).round() as usize;
        let angles: Vec<f64> = (0..=steps).map(|i| i as f64 * MODEL_STEP_DEG).collect();
        let cos_of = |deg: f64| {
            if deg >= 90.0 {
                0.0
            } else {
                deg.to_radians().cos()
            }
        };
        let NormalValues { r0, t0, r0_back } = *normal;
        let mut tables = ModelTables {
            rf: vec![[0.0; 3]; angles.len()],
            t: vec![[0.0; 3]; angles.len()],
            rb: vec![[0.0; 3]; angles.len()],
            angles,
        };
        for i in 0..tables.angles.len() {
            let deg = tables.angles[i];
            let c = cos_of(deg);
            if i == 0 {
                tables.rf[i] = r0;
                tables.t[i] = t0;
                tables.rb[i] = r0_back;
                continue;
            }
            match (application, spectra) {
                (Application::PerWavelength, Some(s)) => {
                    let n = s.wavelength_nm.len();
                    let (mut rf, mut t, mut rb) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
                    for k in 0..n {
                        (rf[k], t[k], rb[k]) =
                            model_at(model, s.t[k], s.rf[k], s.rb[k], ior_single, c);
                    }
                    let channels = |v: &[f64], what: &str| {
                        integrate(integrator, s, v, glass, format!("{what} at {deg}°"))
                    };
                    tables.rf[i] = channels(&rf, "front reflectance")?;
                    tables.t[i] = if model == Physical::Opaque {
                        [0.0; 3]
                    } else {
                        channels(&t, "transmittance")?
                    };
                    tables.rb[i] = channels(&rb, "back reflectance")?;
                }
                _ => {
                    for ch in 0..3 {
                        let nk = ior_per_channel.map(|v| v[ch]);
                        (tables.rf[i][ch], tables.t[i][ch], tables.rb[i][ch]) =
                            model_at(model, t0[ch], r0[ch], r0_back[ch], nk, c);
                    }
                }
            }
        }
        Ok(tables)
    }

    /// One channel of one table as fit samples.
    pub(crate) fn samples(&self, table: &[[f64; 3]], channel: usize) -> AngleSamples {
        AngleSamples {
            angle_deg: self.angles.clone(),
            value: table.iter().map(|v| v[channel]).collect(),
        }
    }
}

/// A measured angle table of a glass: its front R and T samples (either may be absent).
pub(crate) struct MeasuredTable {
    pub reflectance: Option<AngleSamples>,
    pub transmittance: Option<AngleSamples>,
    /// The largest measured angle.
    pub max_angle_deg: f64,
    pub file: FileRef,
}

/// Reads the catalog's angle table for a glass (none when the catalog names none): the file's
/// only glass, or the one of the glass's name.
pub(crate) fn read_measured_table(
    spec: &GlassSpec,
    files: &CatalogFiles<'_>,
    glass: &str,
) -> Result<Option<MeasuredTable>, RegistryError> {
    let Some((rel, percent)) = &spec.angles else {
        return Ok(None);
    };
    let (full, bytes) = files.read(rel, glass, glassdb_fit::ANGLE_TABLE_FILE)?;
    let stem = full
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "glass".into());
    let tables =
        glassdb_fit::parse_angle_table(&bytes, &full, &stem, *percent).map_err(|source| {
            RegistryError::AngleTable {
                glass: glass.to_string(),
                path: full.clone(),
                source: Box::new(source),
            }
        })?;
    let names: Vec<String> = tables.iter().map(|t| t.name.clone()).collect();
    let table = if tables.len() == 1 {
        tables.into_iter().next()
    } else {
        tables.into_iter().find(|t| t.name == spec.name)
    };
    let table = table.ok_or_else(|| RegistryError::AngleTableGlass {
        glass: glass.to_string(),
        path: full.clone(),
        detail: if names.is_empty() {
            "holds no glass".to_string()
        } else {
            format!(
                "holds several glasses ({}) and none is named \"{}\"",
                names.join(", "),
                spec.name
            )
        },
    })?;
    let mut max_angle_deg: f64 = 0.0;
    for s in [&table.reflectance, &table.transmittance]
        .into_iter()
        .flatten()
    {
        max_angle_deg = max_angle_deg.max(s.angle_deg.iter().copied().fold(0.0, f64::max));
    }
    Ok(Some(MeasuredTable {
        reflectance: table.reflectance,
        transmittance: table.transmittance,
        max_angle_deg,
        file: FileRef {
            path: rel.clone(),
            sha256: sha256_hex(&bytes),
        },
    }))
}

/// A measured table continued by the physical model beyond its last angle so that R → 1 and
/// T → 0 at 90°: for θ > θmax, `R(θ) = Rm + (Rp(θ) − Rp(θmax))·(1 − Rm)/(1 − Rp(θmax))` and
/// `T(θ) = Tm·Tp(θ)/Tp(θmax)`, with Rm, Tm the measured values at θmax and Rp, Tp the model's
/// (channel G).
pub(crate) fn continue_measured(
    m: &AngleSamples,
    angles: &[f64],
    tab: &[[f64; 3]],
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
    if theta_max >= 90.0 - 1e-9 {
        return out;
    }
    let measured_at_max = m.value[last_i];
    // The model's absolute value (channel G) at an angle, interpolated in the 1° model table.
    let g = 1;
    let model = |deg: f64| -> f64 {
        let x = deg.clamp(0.0, 90.0) / MODEL_STEP_DEG;
        let i = (x.floor() as usize).min(angles.len().saturating_sub(2));
        let f = x - i as f64;
        tab[i][g] * (1.0 - f) + tab[i + 1][g] * f
    };
    let at_max = model(theta_max);
    for &deg in angles.iter().filter(|&&d| d > theta_max + 0.5) {
        let v = if reflect {
            if at_max < 1.0 {
                measured_at_max + (model(deg) - at_max) * (1.0 - measured_at_max) / (1.0 - at_max)
            } else {
                1.0
            }
        } else if at_max > 0.0 {
            measured_at_max * model(deg) / at_max
        } else {
            0.0
        };
        out.angle_deg.push(deg);
        out.value.push(v.clamp(0.0, 1.0));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalog::NormalSource;

    #[test]
    fn auto_model_from_product_type_and_from_rf_rb() {
        let spec = GlassSpec {
            id: 1,
            name: "x".into(),
            normal: NormalSource::Explicit {
                r0: [0.1; 3],
                t0: [0.8; 3],
                r0_back: [0.1; 3],
            },
            angles: None,
            model: ModelChoice::Auto,
            ior: None,
        };
        let t = [0.8, 0.8];
        let (m, _) = choose_model(&spec, Some("Monolithic"), &t, &[0.1, 0.1], &[0.3, 0.3]);
        assert_eq!(m, Physical::Uncoated);
        let (m, _) = choose_model(&spec, Some("applied-film"), &t, &[0.1, 0.1], &[0.1, 0.1]);
        assert_eq!(m, Physical::Coated);
        let (m, why) = choose_model(&spec, None, &t, &[0.1, 0.1], &[0.104, 0.1]);
        assert_eq!(m, Physical::Uncoated, "{why}");
        let (m, _) = choose_model(&spec, None, &t, &[0.1, 0.1], &[0.106, 0.1]);
        assert_eq!(m, Physical::Coated);
        let (m, _) = choose_model(&spec, None, &[0.0, 0.0], &[0.9, 0.9], &[0.9, 0.9]);
        assert_eq!(m, Physical::Opaque);
    }
}
