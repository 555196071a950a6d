//! glassdb-stack: the glass as it is built. An insulated glazing unit is layers (panes,
//! laminates, coated glass, films) and gaps; per wavelength and angle of incidence each layer's
//! front and back R and T come from its single-layer angle model (uncoated Fresnel slab,
//! WINDOW-4 coated clear/bronze curves, opaque Fresnel, or a measured angle table), and the
//! two-flux interreflection recursion combines any number of them, from both sides, with each
//! layer's absorptance and each pane group's share of the reflectance. Equations and sources in
//! `docs/stack.md` (WINDOW / Windows-CalcEngine, ISO 15099 §6, ISO 9050, EN 410).
//!
//! - [`Layer`]: one layer's data and model; [`Layer::values_at`] its R, T at an angle.
//! - [`Stack`]: a validated build-up ([`Element`]s: layers and [`Gap`]s), its [`PaneGroup`]s
//!   with their depths, and the wavelengths its layers share.
//! - [`Stack::evaluate`]: the unit at a list of angles, integrated with the spectral crate's
//!   integrators (every registry colour basis) and to WINDOW's photopic and solar values
//!   ([`glassdb_spectral::WindowMethod`]); [`Stack::spectra_at`] the spectra themselves.
//! - [`physics`] and [`model`]: the single-layer angle models, which the registry's plain
//!   glasses use too (a glass is a unit of one layer).
//!
//! The crate knows nothing of catalogs, files or registries: the registry builds units from
//! its catalog with it, and `glassdb stack` from the command line.

#![warn(missing_docs)]

mod combine;
mod error;
mod evaluate;
mod layer;
pub mod measured;
pub mod model;
pub mod physics;
mod stack;

pub use combine::{FrontBack, Optics, combine};
pub use error::StackError;
pub use evaluate::{Application, Combination, EvalOptions, Evaluation, Spectra};
pub use layer::{Layer, LayerData, LayerOptions, LayerValues};
pub use measured::{MeasuredRatio, RatioFit};
pub use model::{LayerModel, ModelChoice};
pub use stack::{Element, Gap, Gas, Grid, PaneGroup, Stack};
