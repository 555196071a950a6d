//! Figures for glassdb users, who review fit quality by looking rather than by reading
//! coefficients: fitted angle curves with residuals, spectra with the colour-matching functions
//! beneath, a registry's curves per channel, a mask's reflectance as a heat map. The
//! speed-against-error report (`docs/accuracy.md`) draws its figures with them (glassdb-report).
//!
//! Everything renders with plotters and the embedded DejaVu Sans font (no system font
//! library); PNG or SVG by the output extension; files are written atomically.

#![warn(missing_docs)]

pub mod chart;
pub mod colormap;
mod error;
pub mod figure;
pub mod font;
pub mod heatmap;
pub mod inspect;
pub mod render;

pub use error::PlotError;
pub use render::{Figure, ImageFormat, render_for, save};
pub mod plots;

#[cfg(test)]
mod tests;
