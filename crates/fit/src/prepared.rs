//! The samples a fit works on: validated, sorted by angle, repeated angles averaged, with
//! cos θ and the measured 0° value.

use crate::error::FitError;
use crate::model::{AngleSamples, cos_deg};

/// Validated samples, sorted by angle, repeated angles averaged.
#[derive(Clone, Debug)]
pub(crate) struct Prepared {
    pub angle_deg: Vec<f64>,
    pub cos: Vec<f64>,
    pub value: Vec<f64>,
    /// The 0° value when the samples include 0°.
    pub measured_normal: Option<f64>,
}

/// The samples checked (angles within 0–90°, finite values), sorted, repeated angles averaged.
pub(crate) fn prepare(samples: &AngleSamples) -> Result<Prepared, FitError> {
    if samples.angle_deg.len() != samples.value.len() {
        return Err(FitError::InvalidSamples(format!(
            "{} angles but {} values",
            samples.angle_deg.len(),
            samples.value.len()
        )));
    }
    if samples.angle_deg.is_empty() {
        return Err(FitError::InvalidSamples("no samples".into()));
    }
    let mut pairs: Vec<(f64, f64)> = Vec::with_capacity(samples.value.len());
    for (&a, &v) in samples.angle_deg.iter().zip(&samples.value) {
        if !a.is_finite() || !(0.0..=90.0).contains(&a) {
            return Err(FitError::InvalidSamples(format!(
                "angle {a}° is not within 0–90°"
            )));
        }
        if !v.is_finite() {
            return Err(FitError::InvalidSamples(format!(
                "value {v} at {a}° is not finite"
            )));
        }
        pairs.push((a, v));
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut angle_deg = Vec::with_capacity(pairs.len());
    let mut value = Vec::with_capacity(pairs.len());
    let mut i = 0;
    while i < pairs.len() {
        let mut j = i + 1;
        let mut sum = pairs[i].1;
        while j < pairs.len() && pairs[j].0 == pairs[i].0 {
            sum += pairs[j].1;
            j += 1;
        }
        angle_deg.push(pairs[i].0);
        value.push(sum / (j - i) as f64);
        i = j;
    }
    let cos = angle_deg.iter().map(|&a| cos_deg(a)).collect();
    let measured_normal = (angle_deg[0] == 0.0).then(|| value[0]);
    Ok(Prepared {
        angle_deg,
        cos,
        value,
        measured_normal,
    })
}
