//! Registry validation: ids, finite numbers, normal values, curve shapes, and the physical range
//! of r and t on a dense angle grid per side and channel (`docs/registry.md`, "Validation").

use std::collections::BTreeMap;

use glassdb_fit::MAX_CURVE_TOLERANCE;

use crate::RegistryError;
use crate::Side;
use crate::record::{CHANNELS, GlassRecord, Registry, RegistryTable};

/// Angle step of the validation grid (degrees): 0, 0.25, …, 90.
const VALIDATION_STEP_DEG: f64 = 0.25;

/// Slack added to every recorded tolerance so that rounding in the JSON round trip never flips
/// a check.
const VALIDATION_EPS: f64 = 1e-9;

impl Registry {
    /// Validates every table ([`RegistryTable::validate_named`]) and how they fit together:
    /// at least one table, one table per colour basis, and the same glasses (ids and names,
    /// in order) in each.
    pub fn validate(&self) -> Result<(), RegistryError> {
        self.validate_named("registry")
    }

    /// [`Registry::validate`] with a name for the messages.
    pub fn validate_named(&self, source_name: &str) -> Result<(), RegistryError> {
        let tables = self.tables();
        let Some(first) = tables.first() else {
            return Err(RegistryError::NoTables {
                source_name: source_name.to_string(),
            });
        };
        let several = tables.len() > 1;
        let ids = |t: &RegistryTable| -> Vec<(u16, String)> {
            t.glasses.iter().map(|g| (g.id, g.name.clone())).collect()
        };
        let first_ids = ids(first);
        for (k, t) in tables.iter().enumerate() {
            let name = if several {
                format!("{source_name} (table {}: {})", k + 1, t.basis())
            } else {
                source_name.to_string()
            };
            t.validate_named(&name)?;
            if let Some(earlier) = tables[..k].iter().find(|e| e.basis() == t.basis()) {
                return Err(RegistryError::DuplicateTable {
                    source_name: source_name.to_string(),
                    basis: t.basis().to_string(),
                    first: earlier.spectral.method.to_string(),
                    second: t.spectral.method.to_string(),
                });
            }
            if k > 0 && ids(t) != first_ids {
                return Err(RegistryError::TablesDiffer {
                    source_name: source_name.to_string(),
                    first: first.basis().to_string(),
                    other: t.basis().to_string(),
                    first_glasses: first_ids.iter().map(label).collect(),
                    other_glasses: ids(t).iter().map(label).collect(),
                });
            }
        }
        Ok(())
    }
}

fn label((id, name): &(u16, String)) -> String {
    format!("{id} \"{name}\"")
}

impl RegistryTable {
    /// Validates one table: ids unique and non-zero, every number finite, normal values in
    /// [0, 1] with r0 + t0 ≤ 1, well-formed curves, and on a dense 0–90° grid per side and
    /// channel 0 ≤ r, t ≤ 1 and r + t ≤ 1, each within the tolerance recorded for the curve.
    /// A recorded tolerance is refused above [`MAX_CURVE_TOLERANCE`]: the slack of validation
    /// is not the file's to set.
    pub fn validate_named(&self, source_name: &str) -> Result<(), RegistryError> {
        let mut seen: BTreeMap<u16, &str> = BTreeMap::new();
        for g in &self.glasses {
            if g.id == 0 {
                return Err(RegistryError::IdZero {
                    source_name: source_name.to_string(),
                    name: g.name.clone(),
                });
            }
            if let Some(first) = seen.insert(g.id, &g.name) {
                return Err(RegistryError::DuplicateId {
                    source_name: source_name.to_string(),
                    id: g.id,
                    first: first.to_string(),
                    second: g.name.clone(),
                });
            }
            validate_glass(g, source_name)?;
        }
        Ok(())
    }
}

fn validate_glass(g: &GlassRecord, source_name: &str) -> Result<(), RegistryError> {
    let glass = g.label();
    let non_finite = |field: String| RegistryError::NonFinite {
        source_name: source_name.to_string(),
        glass: glass.clone(),
        field,
    };
    for (field, values) in [("r0", &g.r0), ("t0", &g.t0), ("r0_back", &g.r0_back)] {
        for (c, v) in values.iter().enumerate() {
            if !v.is_finite() {
                return Err(non_finite(format!("{field}[{c}] ({})", CHANNELS[c])));
            }
            if !(0.0..=1.0).contains(v) {
                return Err(RegistryError::NormalValue {
                    source_name: source_name.to_string(),
                    glass: glass.clone(),
                    what: format!("{field} channel {} = {v} is outside [0, 1]", CHANNELS[c]),
                });
            }
        }
    }
    if let Some(l) = &g.luminous {
        for (field, v) in [
            ("luminous.transmittance", l.transmittance),
            ("luminous.reflectance", l.reflectance),
            ("luminous.reflectance_back", l.reflectance_back),
        ] {
            if !v.is_finite() {
                return Err(non_finite(field.to_string()));
            }
        }
    }
    validate_curves(g, source_name)?;
    validate_physical(g, source_name)
}

/// Every curve of `g` well formed, with finite numbers and a tolerance in
/// [0, [`MAX_CURVE_TOLERANCE`]].
fn validate_curves(g: &GlassRecord, source_name: &str) -> Result<(), RegistryError> {
    let glass = g.label();
    let non_finite = |field: String| RegistryError::NonFinite {
        source_name: source_name.to_string(),
        glass: glass.clone(),
        field,
    };
    for (field, curves) in [("c_r", &g.c_r), ("c_t", &g.c_t), ("c_r_back", &g.c_r_back)] {
        for (c, curve) in curves.iter().enumerate() {
            let name = format!("{field}[{c}] ({})", CHANNELS[c]);
            curve
                .polynomial
                .check_shape()
                .map_err(|shape| RegistryError::CurveShape {
                    source_name: source_name.to_string(),
                    glass: glass.clone(),
                    field: name.clone(),
                    shape,
                })?;
            for (k, v) in curve.polynomial.coefficients.iter().enumerate() {
                if !v.is_finite() {
                    return Err(non_finite(format!("{name}.coefficients[{k}]")));
                }
            }
            for (key, v) in [
                ("rms_error", curve.fit.rms_error),
                ("max_abs_error", curve.fit.max_abs_error),
                ("max_error_angle_deg", curve.fit.max_error_angle_deg),
                ("tolerance", curve.tolerance),
            ] {
                if !v.is_finite() {
                    return Err(non_finite(format!("{name}.{key}")));
                }
            }
            if curve.tolerance < 0.0 {
                return Err(RegistryError::NegativeTolerance {
                    source_name: source_name.to_string(),
                    glass: glass.clone(),
                    field: name.clone(),
                    tolerance: curve.tolerance,
                });
            }
            if curve.tolerance > MAX_CURVE_TOLERANCE {
                return Err(RegistryError::ToleranceTooLarge {
                    source_name: source_name.to_string(),
                    glass: glass.clone(),
                    field: name.clone(),
                    tolerance: curve.tolerance,
                    max: MAX_CURVE_TOLERANCE,
                });
            }
        }
    }
    Ok(())
}

/// r, t and r + t of `g` within [0, 1] (each within its curves' tolerance) on both sides, at
/// every [`VALIDATION_STEP_DEG`] from 0° to 90°.
fn validate_physical(g: &GlassRecord, source_name: &str) -> Result<(), RegistryError> {
    let glass = g.label();
    let steps = (90.0 / VALIDATION_STEP_DEG).round() as usize;
    for side in [Side::Front, Side::Back] {
        let (_, c_r) = g.r_parts(side);
        for i in 0..=steps {
            let angle_deg = i as f64 * VALIDATION_STEP_DEG;
            let cos = if i == steps {
                0.0
            } else {
                angle_deg.to_radians().cos()
            };
            let (r, t) = g.eval_raw(side, cos);
            for c in 0..3 {
                let tol_r = c_r[c].tolerance + VALIDATION_EPS;
                let tol_t = g.c_t[c].tolerance + VALIDATION_EPS;
                let fail = |what: String, tolerance: f64| RegistryError::Unphysical {
                    source_name: source_name.to_string(),
                    glass: glass.clone(),
                    side,
                    channel: CHANNELS[c],
                    angle_deg,
                    what,
                    tolerance,
                };
                if !r[c].is_finite() || !t[c].is_finite() {
                    return Err(fail("r or t is not finite".into(), 0.0));
                }
                if r[c] < -tol_r || r[c] > 1.0 + tol_r {
                    return Err(fail(format!("r = {:.6} is outside [0, 1]", r[c]), tol_r));
                }
                if t[c] < -tol_t || t[c] > 1.0 + tol_t {
                    return Err(fail(format!("t = {:.6} is outside [0, 1]", t[c]), tol_t));
                }
                if r[c] + t[c] > 1.0 + tol_r + tol_t {
                    return Err(fail(
                        format!(
                            "r + t = {:.6} + {:.6} = {:.6} > 1 (energy is not conserved)",
                            r[c],
                            t[c],
                            r[c] + t[c]
                        ),
                        tol_r + tol_t,
                    ));
                }
            }
        }
    }
    Ok(())
}
