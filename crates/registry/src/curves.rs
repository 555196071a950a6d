//! The angle curves of a glass: C_r, C_t, C_r_back per channel fitted to the model tables, or
//! one measured curve (continued to grazing) shared by the three channels.

use glassdb_fit::{AngleSamples, FitOptions, Quantity};

use glassdb_stack::measured::continue_measured;

use crate::angle_model::{MeasuredTable, ModelTables};
use crate::normal::NormalValues;
use crate::{AngleCurve, BuildOptions, CHANNELS, RegistryError};

/// Normal values at or below this are zero: the curve never matters and is the nominal one.
const ZERO_NORMAL: f64 = 1e-9;

/// The three curves of each kind, per channel.
pub(crate) struct GlassCurves {
    pub c_r: [AngleCurve; 3],
    pub c_t: [AngleCurve; 3],
    pub c_r_back: [AngleCurve; 3],
}

/// Fits one curve; the validation tolerance recorded with it is the larger of the fit
/// tolerance and the fit's own largest residual, at most [`glassdb_fit::MAX_CURVE_TOLERANCE`]
/// (a worse fit is still validated with that slack, on the curve itself).
fn fit_curve(
    samples: &AngleSamples,
    quantity: Quantity,
    opts: &BuildOptions,
    glass: &str,
    curve: String,
) -> Result<AngleCurve, RegistryError> {
    let mut fo = FitOptions::new(quantity);
    fo.tol = opts.fit_tol;
    fo.max_degree = opts.max_degree;
    let fit = glassdb_fit::fit_curve(samples, &fo).map_err(|source| RegistryError::Fit {
        glass: glass.to_string(),
        curve,
        source: Box::new(source),
    })?;
    let summary = fit.diagnostics.summary;
    Ok(AngleCurve {
        polynomial: fit.polynomial,
        fit: summary,
        tolerance: opts
            .fit_tol
            .max(summary.max_abs_error)
            .min(glassdb_fit::MAX_CURVE_TOLERANCE),
    })
}

/// Fits the three channel curves of one reflectance share (a pane group's, one side): the
/// nominal curve where its normal value is zero.
pub(crate) fn fit_share_curves(
    r0: [f64; 3],
    tables: &ModelTables,
    table: &[[f64; 3]],
    quantity: Quantity,
    opts: &BuildOptions,
    glass: &str,
    name: &str,
) -> Result<[AngleCurve; 3], RegistryError> {
    let curve = |ch: usize| {
        if r0[ch] <= ZERO_NORMAL {
            Ok(AngleCurve::nominal_transmittance())
        } else {
            fit_curve(
                &tables.samples(table, ch),
                quantity,
                opts,
                glass,
                format!("{name} channel {}", CHANNELS[ch]),
            )
        }
    };
    Ok([curve(0)?, curve(1)?, curve(2)?])
}

/// Fits every curve of a glass. A measured table's R and T curves (the ratio C(θ) of the table,
/// continued by the model's channel G beyond its last angle) are shared by the three channels;
/// otherwise each channel fits its model table. Zero normal values get the nominal curve.
pub(crate) fn fit_glass_curves(
    normal: &NormalValues,
    tables: &ModelTables,
    measured: Option<&MeasuredTable>,
    opts: &BuildOptions,
    glass: &str,
) -> Result<GlassCurves, RegistryError> {
    let fit = |samples: &AngleSamples, quantity: Quantity, curve: String| {
        fit_curve(samples, quantity, opts, glass, curve)
    };
    // A measured curve continued by the model `table` beyond its last angle.
    let shared = |measured: Option<&AngleSamples>, table: &[[f64; 3]], quantity, curve: &str| {
        let reflect = quantity == Quantity::Reflectance;
        // the model's channel G continues the table
        let model: Vec<f64> = table.iter().map(|v| v[1]).collect();
        measured
            .map(|m| {
                let continued = continue_measured(m, &tables.angles, &model, reflect);
                fit(&continued, quantity, curve.into())
            })
            .transpose()
    };
    let measured_r = measured.and_then(|m| m.reflectance.as_ref());
    let measured_t = measured.and_then(|m| m.transmittance.as_ref());
    let shared_r = shared(measured_r, &tables.rf, Quantity::Reflectance, "measured R")?;
    let shared_t = shared(measured_t, &tables.t, Quantity::Transmittance, "measured T")?;
    // Front reflectance, transmittance, back reflectance: the shared curve if any, else the
    // nominal one for a zero normal value, else a fit of the channel's model table.
    let kinds = [
        (
            shared_r.as_ref(),
            normal.r0,
            &tables.rf,
            Quantity::Reflectance,
            "C_r",
        ),
        (
            shared_t.as_ref(),
            normal.t0,
            &tables.t,
            Quantity::Transmittance,
            "C_t",
        ),
        (
            None,
            normal.r0_back,
            &tables.rb,
            Quantity::Reflectance,
            "C_r_back",
        ),
    ];
    // Per channel in the order R, G, B.
    let channel = |ch: usize| -> Result<[AngleCurve; 3], RegistryError> {
        let [c_r, c_t, c_r_back] =
            kinds.map(|(shared, normal, table, quantity, kind)| match shared {
                Some(c) => Ok(c.clone()),
                None if normal[ch] <= ZERO_NORMAL => Ok(AngleCurve::nominal_transmittance()),
                None => fit(
                    &tables.samples(table, ch),
                    quantity,
                    format!("{kind} channel {}", CHANNELS[ch]),
                ),
            });
        Ok([c_r?, c_t?, c_r_back?])
    };
    let [[r_r, t_r, rb_r], [r_g, t_g, rb_g], [r_b, t_b, rb_b]] =
        [channel(0)?, channel(1)?, channel(2)?];
    Ok(GlassCurves {
        c_r: [r_r, r_g, r_b],
        c_t: [t_r, t_g, t_b],
        c_r_back: [rb_r, rb_g, rb_b],
    })
}
