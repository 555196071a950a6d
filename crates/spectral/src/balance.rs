//! Energy checks of a glass's spectra, shared by every command that turns spectra into values
//! (`glassdb spectral` and the registry build): no more light out than in, T + R ≤ 1, at every
//! wavelength of the data and for the integrated channel values.

use crate::SpectralError;

/// Slack on T + R ≤ 1 at one wavelength of the data: a millionth, the rounding of the data's
/// last digit and below (a published spectrum sums to at most 1 as printed).
pub const SPECTRUM_BALANCE_SLACK: f64 = 1e-6;

/// Slack on t + r ≤ 1 for integrated channel values: 0.002, the default fit tolerance of the
/// angle curves (`glassdb_fit::DEFAULT_TOL`) and far above the few 1e-5 that Sprague or spline
/// interpolation adds to a well-sampled spectrum. More than that is the interpolation
/// overshooting across sparse samples (a gap in the data), not physics.
pub const CHANNEL_BALANCE_SLACK: f64 = 2e-3;

/// The channel names, in order.
const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// The range whose sampling decides the visible channels (the ISO 9050 luminous range).
const VISIBLE_NM: (f64, f64) = (380.0, 780.0);

/// Checks T + R ≤ 1 (within [`SPECTRUM_BALANCE_SLACK`]) at every wavelength, for each given
/// reflectance (front and back). Without a transmittance, or without a reflectance, there is
/// nothing to check (each value is already within [0, 1]).
pub fn check_spectrum_balance(
    wavelength_nm: &[f64],
    transmittance: Option<&[f64]>,
    reflectances: &[Option<&[f64]>],
) -> Result<(), SpectralError> {
    let Some(t) = transmittance else {
        return Ok(());
    };
    for (k, &wl) in wavelength_nm.iter().enumerate() {
        let r = reflectances
            .iter()
            .flatten()
            .filter_map(|r| r.get(k).copied())
            .fold(f64::NEG_INFINITY, f64::max);
        let Some(&tk) = t.get(k) else { break };
        if r.is_finite() && tk + r > 1.0 + SPECTRUM_BALANCE_SLACK {
            return Err(SpectralError::SpectrumEnergy {
                wavelength_nm: wl,
                sum: tk + r,
            });
        }
    }
    Ok(())
}

/// Checks the integrated values of one side of a glass: per channel, `t + r ≤ 1` within
/// [`CHANNEL_BALANCE_SLACK`], each value clamped to [0, 1] first (as a registry stores them: a
/// channel outside [0, 1] is a colour outside the working space's gamut, not light created).
/// `side` names the reflectance ("front", "back"); `wavelength_nm` are the data's samples, whose
/// largest gap in the visible range the error reports (sparse data are the usual cause).
pub fn check_channel_balance(
    transmittance: [f64; 3],
    reflectance: [f64; 3],
    side: &'static str,
    wavelength_nm: &[f64],
) -> Result<(), SpectralError> {
    for c in 0..3 {
        let t = transmittance[c].clamp(0.0, 1.0);
        let r = reflectance[c].clamp(0.0, 1.0);
        // a NaN (never from a validated spectrum) fails the check rather than passing it
        if t.is_nan() || r.is_nan() || t + r > 1.0 + CHANNEL_BALANCE_SLACK {
            return Err(SpectralError::ChannelEnergy {
                side,
                channel: CHANNELS[c],
                transmittance: t,
                reflectance: r,
                largest_gap_nm: largest_visible_gap(wavelength_nm),
            });
        }
    }
    Ok(())
}

/// The interval between consecutive samples with the widest part inside the visible range,
/// as `(from, to)` in nm (none without two samples around or inside that range).
pub fn largest_visible_gap(wavelength_nm: &[f64]) -> Option<(f64, f64)> {
    let inside = |w: &[f64]| w[1].min(VISIBLE_NM.1) - w[0].max(VISIBLE_NM.0);
    wavelength_nm
        .windows(2)
        .filter(|w| inside(w) > 0.0)
        .max_by(|a, b| inside(a).total_cmp(&inside(b)))
        .map(|w| (w[0], w[1]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectrum_balance_names_the_first_wavelength_over_one() {
        let wl = [400.0, 500.0, 600.0];
        let t = [0.8, 0.85, 0.9];
        let rf = [0.1, 0.1, 0.1];
        let rb = [0.1, 0.2, 0.1];
        assert!(check_spectrum_balance(&wl, Some(&t), &[Some(&rf)]).is_ok());
        let e = check_spectrum_balance(&wl, Some(&t), &[Some(&rf), Some(&rb)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "at 500 nm, T + R = 1.0500 > 1: more light out than in"
        );
        assert!(check_spectrum_balance(&wl, None, &[Some(&rb)]).is_ok());
    }

    #[test]
    fn channel_balance_clamps_then_allows_the_slack() {
        let wl = [300.0, 380.0, 450.0, 600.0, 700.0, 780.0, 900.0];
        // out of gamut: clamped to 0 and 1, not energy
        assert!(check_channel_balance([1.2, 0.5, -0.3], [0.0, 0.4, 0.2], "front", &wl).is_ok());
        assert!(check_channel_balance([0.9, 0.9, 0.9], [0.1015, 0.1, 0.1], "front", &wl).is_ok());
        let e = check_channel_balance([0.9, 0.95, 0.9], [0.1, 0.1, 0.1], "back", &wl).unwrap_err();
        assert_eq!(
            e.to_string(),
            "channel G: integrated transmittance + back reflectance = 0.950000 + 0.100000 = \
             1.050000 > 1 (energy is not conserved; largest gap between samples in 380–780 nm: \
             150 nm, 450–600 nm)"
        );
        assert!(check_channel_balance([f64::NAN; 3], [0.1; 3], "front", &wl).is_err());
        assert_eq!(largest_visible_gap(&[300.0, 400.0]), Some((300.0, 400.0)));
        assert_eq!(
            largest_visible_gap(&[300.0, 350.0, 790.0]),
            Some((350.0, 790.0))
        );
        assert_eq!(largest_visible_gap(&[800.0, 900.0]), None);
    }
}
