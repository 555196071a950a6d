//! glassdb-spectral: read a glass's spectral transmittance τ(λ) and reflectances ρ(λ) and turn
//! them into the per-channel factors the compositor multiplies by (docs/method.md "Colour",
//! eqs. 15–20) and into the luminous values glass makers publish (ISO 9050 / EN 410).
//!
//! - [`read_spectral_file`] / [`read_spectral_bytes`]: our CSV and instrument exports, LBNL
//!   Optics/IGDB text files and IGSDB JSON (schema v1 and v2), always returned as nm and
//!   fractions, validated with file:line errors; shading products, BSDF XML, diffuse data and
//!   binary files are refused by name ([`UnsupportedKind`]).
//! - [`Integrator`]: built once from [`IntegrationSettings`], then cheap per spectrum
//!   ([`Integrator::channels`]).
//! - [`Illuminant`]: the light, a bundled [`CieIlluminant`] (D series, A, E, FL1–FL12, the
//!   CIE 15:2018 LED series) or an [`Spd`] read from a CSV file ([`read_spd_file`]), and
//!   [`WhiteBalance`], the white the camera is balanced to.
//! - [`luminous_iso9050`]: visible transmittance/reflectance, D65 × V(λ), 380–780 nm at 10 nm.
//! - [`WindowWeights`] / [`window_average`]: WINDOW's NFRC 300-2003 photopic and solar
//!   averages, computed as pywincalc 3.3.1 computes them (linear interpolation, trapezoids).
//! - [`check_spectrum_balance`] / [`check_channel_balance`]: T + R ≤ 1 per wavelength and per
//!   integrated channel, the checks every command applies to a glass's spectra.
//!
//! Interpolation and alignment follow colour-science 0.4.7 (Sprague for uniform spacing,
//! not-a-knot cubic spline otherwise, end values held constant outside the data), so the numbers
//! agree with it to 1e-9 relative; the differences where colour is wrong are in
//! `docs/spectral.md`.

#![warn(missing_docs)]

#[macro_use]
mod names;
mod balance;
mod error;
mod illuminant;
mod integrate;
mod interp;
mod open;
mod read;
mod read_csv;
mod read_igsdb;
mod sniff;
mod spline;
mod tables;
mod window;

pub use balance::{
    CHANNEL_BALANCE_SLACK, SPECTRUM_BALANCE_SLACK, check_channel_balance, check_spectrum_balance,
    largest_visible_gap,
};
pub use error::{SpectralError, UnsupportedKind};
pub use glassdb_colour::{CHROMATICITIES_TOLERANCE, RgbSpace, rgb_to_rgb, xyz_to_rgb};
pub use illuminant::{
    CieIlluminant, Illuminant, LIGHT_RANGE_NM, MAX_SPD_SAMPLES, Spd, WhiteBalance, read_spd_bytes,
    read_spd_file,
};
pub use integrate::{
    ColorimetricSettings, GridIntegrator, IntegrationSettings, Integrator, LuminousGrid, Method,
    MethodKind, Observer, RgbCmf, luminous, luminous_iso9050, rgb_matrix,
};
pub use interp::resample;
pub use open::{SPECTRAL_FILE, detect_format, read_spectral_bytes, read_spectral_file};
pub use read::{ProductInfo, ReadOptions, SpectralData, SpectralFormat, microns_to_nm};
pub use window::{WindowMethod, WindowWeights, window_average};
