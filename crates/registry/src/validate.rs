//! Registry validation: ids, finite numbers, normal values, curve shapes, and the physical range
//! of r and t on a dense angle grid per side and channel (`docs/registry.md`, "Validation").

use std::collections::BTreeMap;

use glassdb_fit::MAX_CURVE_TOLERANCE;

use crate::RegistryError;
use crate::hemispherical::{HEMISPHERICAL_TOLERANCE, HemisphericalRecord};
use crate::record::{AngleCurve, GlassRecord};
use crate::registry::{CHANNELS, Registry, RegistryTable};
use crate::unit_record::{UnitElement, UnitRecord};
use glassdb_side::Side;

/// Angle step of the validation grid (degrees): 0, 0.25, …, 90.
const VALIDATION_STEP_DEG: f64 = 0.25;

/// Slack added to every recorded tolerance so that rounding in the JSON round trip never flips
/// a check.
const VALIDATION_EPS: f64 = 1e-9;

impl Registry {
    /// Validates every table ([`RegistryTable::validate_named`]) and how they fit together:
    /// at least one table, one table per colour basis and light, the same glasses (ids and
    /// names, in order) in each, and the lights' rules (every table names its light or none
    /// does; one spectrum per light; every light in every basis).
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
                format!("{source_name} (table {}: {})", k + 1, t.label())
            } else {
                source_name.to_string()
            };
            t.validate_named(&name)?;
            if let Some(earlier) = tables[..k]
                .iter()
                .find(|e| e.basis() == t.basis() && e.light == t.light)
            {
                return Err(RegistryError::DuplicateTable {
                    source_name: source_name.to_string(),
                    basis: t.label(),
                    first: earlier.spectral.method.to_string(),
                    second: t.spectral.method.to_string(),
                });
            }
            if k > 0 && ids(t) != first_ids {
                return Err(RegistryError::TablesDiffer {
                    source_name: source_name.to_string(),
                    first: first.label(),
                    other: t.label(),
                    first_glasses: first_ids.iter().map(label).collect(),
                    other_glasses: ids(t).iter().map(label).collect(),
                });
            }
        }
        self.validate_lights(source_name)
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

/// An unphysical value of `glass` at (side, channel, angle).
fn unphysical(
    source_name: &str,
    glass: &str,
    (side, channel, angle_deg): (Side, usize, f64),
    what: String,
    tolerance: f64,
) -> RegistryError {
    RegistryError::Unphysical {
        source_name: source_name.to_string(),
        glass: glass.to_string(),
        side,
        channel: CHANNELS[channel],
        angle_deg,
        what,
        tolerance,
    }
}

/// The validation grid: `(angle_deg, cos θ)` at 0, 0.25, …, 90° (cos exactly 0 at 90°).
fn validation_grid() -> impl Iterator<Item = (f64, f64)> {
    let steps = (90.0 / VALIDATION_STEP_DEG).round() as usize;
    (0..=steps).map(move |i| {
        let angle_deg = i as f64 * VALIDATION_STEP_DEG;
        let cos = if i == steps {
            0.0
        } else {
            angle_deg.to_radians().cos()
        };
        (angle_deg, cos)
    })
}

/// The shape, finite numbers and tolerance of three channel curves named `field`.
fn check_curves(
    field: &str,
    curves: &[AngleCurve; 3],
    glass: &str,
    source_name: &str,
) -> Result<(), RegistryError> {
    let non_finite = |field: String| RegistryError::NonFinite {
        source_name: source_name.to_string(),
        glass: glass.to_string(),
        field,
    };
    for (c, curve) in curves.iter().enumerate() {
        let name = format!("{field}[{c}] ({})", CHANNELS[c]);
        curve
            .polynomial
            .check_shape()
            .map_err(|shape| RegistryError::CurveShape {
                source_name: source_name.to_string(),
                glass: glass.to_string(),
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
                glass: glass.to_string(),
                field: name.clone(),
                tolerance: curve.tolerance,
            });
        }
        if curve.tolerance > MAX_CURVE_TOLERANCE {
            return Err(RegistryError::ToleranceTooLarge {
                source_name: source_name.to_string(),
                glass: glass.to_string(),
                field: name.clone(),
                tolerance: curve.tolerance,
                max: MAX_CURVE_TOLERANCE,
            });
        }
    }
    Ok(())
}

/// A unit's record: finite per-layer values, well-formed share curves, pane groups covering
/// the layers in order, and on the validation grid per side and channel each share within
/// [0, 1] and their sum within the unit's r, each by the curves' recorded tolerances.
fn validate_unit(
    g: &GlassRecord,
    unit: &UnitRecord,
    source_name: &str,
) -> Result<(), RegistryError> {
    let glass = g.label();
    let bad = |what: String| RegistryError::NormalValue {
        source_name: source_name.to_string(),
        glass: glass.clone(),
        what,
    };
    let n_layers = unit
        .elements
        .iter()
        .filter(|e| matches!(e, UnitElement::Layer(_)))
        .count();
    for (i, e) in unit.elements.iter().enumerate() {
        let numbers: Vec<f64> = match e {
            UnitElement::Gap(gap) => vec![gap.thickness_mm],
            UnitElement::Layer(l) => {
                l.r0.iter()
                    .chain(&l.t0)
                    .chain(&l.r0_back)
                    .copied()
                    .chain(l.thickness_mm)
                    .collect()
            }
        };
        if numbers.iter().any(|v| !v.is_finite()) {
            return Err(RegistryError::NonFinite {
                source_name: source_name.to_string(),
                glass: glass.clone(),
                field: format!("unit.elements[{i}]"),
            });
        }
    }
    let covered: Vec<usize> = unit
        .groups
        .iter()
        .flat_map(|gr| gr.layers.clone())
        .collect();
    if n_layers == 0 || covered != (0..n_layers).collect::<Vec<_>>() {
        return Err(bad(format!(
            "unit.groups cover layers {covered:?} but the unit has {n_layers} layers in order"
        )));
    }
    for (k, gr) in unit.groups.iter().enumerate() {
        for (field, values) in [("r0", &gr.r0), ("r0_back", &gr.r0_back)] {
            if values
                .iter()
                .any(|v| !v.is_finite() || !(0.0..=1.0).contains(v))
            {
                return Err(bad(format!(
                    "unit.groups[{k}].{field} = {values:?} is outside [0, 1]"
                )));
            }
        }
        check_curves(
            &format!("unit.groups[{k}].c_r"),
            &gr.c_r,
            &glass,
            source_name,
        )?;
        check_curves(
            &format!("unit.groups[{k}].c_r_back"),
            &gr.c_r_back,
            &glass,
            source_name,
        )?;
    }
    for side in [Side::Front, Side::Back] {
        let (_, c_r) = g.r_parts(side);
        for (angle_deg, cos) in validation_grid() {
            let (r, _) = g.eval_raw(side, cos);
            let unphysical = |c: usize, what: String, tolerance: f64| {
                unphysical(source_name, &glass, (side, c, angle_deg), what, tolerance)
            };
            let mut sum = [0.0; 3];
            let mut slack = [c_r[0].tolerance, c_r[1].tolerance, c_r[2].tolerance];
            for (k, gr) in unit.groups.iter().enumerate() {
                let s = gr.eval_raw(side, cos);
                let curves = if side == Side::Front {
                    &gr.c_r
                } else {
                    &gr.c_r_back
                };
                for c in 0..3 {
                    let tol = curves[c].tolerance + VALIDATION_EPS;
                    if !s[c].is_finite() || s[c] < -tol || s[c] > 1.0 + tol {
                        let what =
                            format!("pane group {} reflects {:.6}, outside [0, 1]", k + 1, s[c]);
                        return Err(unphysical(c, what, tol));
                    }
                    sum[c] += s[c];
                    slack[c] += curves[c].tolerance;
                }
            }
            for c in 0..3 {
                let tol = slack[c] + VALIDATION_EPS;
                if (sum[c] - r[c]).abs() > tol {
                    let what = format!(
                        "the pane groups reflect {:.6} in all but the unit {:.6}",
                        sum[c], r[c]
                    );
                    return Err(unphysical(c, what, tol));
                }
            }
        }
    }
    Ok(())
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
    for (field, curves) in [("c_r", &g.c_r), ("c_t", &g.c_t), ("c_r_back", &g.c_r_back)] {
        check_curves(field, curves, &glass, source_name)?;
    }
    for side in [Side::Front, Side::Back] {
        let (_, c_r) = g.r_parts(side);
        for (angle_deg, cos) in validation_grid() {
            let (r, t) = g.eval_raw(side, cos);
            for c in 0..3 {
                let tol_r = c_r[c].tolerance + VALIDATION_EPS;
                let tol_t = g.c_t[c].tolerance + VALIDATION_EPS;
                let fail = |what: String, tolerance: f64| {
                    unphysical(source_name, &glass, (side, c, angle_deg), what, tolerance)
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
    if let Some(unit) = &g.unit {
        validate_unit(g, unit, source_name)?;
    }
    if let Some(stored) = &g.hemispherical {
        check_hemispherical(g, stored, source_name)?;
    }
    Ok(())
}

/// Stored hemispherical values must be the integral of the curves they sit beside (a registry
/// edited by hand, or curves changed without them, would otherwise light a room with one glass
/// and tint its panes with another).
fn check_hemispherical(
    g: &GlassRecord,
    stored: &HemisphericalRecord,
    source_name: &str,
) -> Result<(), RegistryError> {
    let computed = HemisphericalRecord::of(g);
    for ((field, values), (_, expected)) in stored.fields().into_iter().zip(computed.fields()) {
        for c in 0..3 {
            if !(values[c] - expected[c]).abs().le(&HEMISPHERICAL_TOLERANCE) {
                return Err(RegistryError::Hemispherical {
                    source_name: source_name.to_string(),
                    glass: g.label(),
                    field: format!("{field}[{c}] ({})", CHANNELS[c]),
                    stored: values[c],
                    computed: expected[c],
                });
            }
        }
    }
    Ok(())
}
