//! The id-indexed glass table a glazed scene uses (method.md, "Mask" and "Angle dependence";
//! the paper's section 5.2 and eqs. 11–14): per glass, per channel R, G, B, the normal-incidence
//! reflectance and transmittance `r0`, `t0`, `r0_back` and the angle curves `C_r`, `C_t`,
//! `C_r_back`, built from a catalog of real products (`catalog.toml`) and stored as a versioned
//! JSON file (`docs/registry.md`).
//!
//! - [`Registry`]: the JSON schema, loading with validation, and atomic writing.
//! - [`GlassRecord::eval`]: what the compositor tabulates.
//! - [`build_registry`] / [`default_registry`]: catalog → registry.

mod build;
mod bundled;
pub mod catalog;
mod error;
pub mod physics;
mod record;

pub use build::{Application, BuildOptions, build_registry, curve_record, default_registry};
pub use error::RegistryError;
pub use record::{
    AngleModelRecord, CHANNELS, CurveRecord, FileRef, GlassRecord, LuminousRecord, ProductRecord,
    Provenance, Registry, SCHEMA_VERSION, Side, SpectralMethodRecord,
};
