//! The figures of `glassdb plot`: each function reads its inputs through the owning crate
//! and returns a [`Figure`](crate::Figure) to [`save`](crate::save).

pub mod fit;
pub mod mask;
pub mod registry;
pub mod spectral;
pub mod stack;

use glassdb_fit::cos_deg;

/// Angles from 0 to 90° in `steps` equal steps (endpoints included).
pub(crate) fn angle_grid(steps: usize) -> Vec<f64> {
    (0..=steps)
        .map(|k| 90.0 * k as f64 / steps as f64)
        .collect()
}

/// (angle, f(cos θ)) over 0–90°.
pub(crate) fn curve_points(f: impl Fn(f64) -> f64) -> Vec<(f64, f64)> {
    angle_grid(360)
        .into_iter()
        .map(|a| (a, f(cos_deg(a))))
        .collect()
}

/// Axis title of incidence angle.
pub const ANGLE_AXIS: &str = "angle of incidence θ (°)";
