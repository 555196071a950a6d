//! The id-indexed glass table a glazed scene uses (method.md, "Mask" and "Angle dependence";
//! the paper's section 5.2 and eqs. 11–14): per glass, per channel R, G, B, the normal-incidence
//! reflectance and transmittance `r0`, `t0`, `r0_back` and the angle curves `C_r`, `C_t`,
//! `C_r_back`, built from a catalog of real products (`catalog.toml`) and stored as a versioned
//! JSON file (`docs/registry.md`).
//!
//! - [`Registry`]: the JSON schema, loading with validation, and atomic writing.
//! - [`GlassRecord::eval`]: what the compositor tabulates.
//! - Lights ([`NamedLight`], [`Registry::lights`], [`Registry::table_under`]): one table per
//!   (colour basis, light), so that each light group of a render is composited with its own
//!   light's table.
//! - [`build_registry`]: catalog → registry; [`default_registry`]: the bundled, prebuilt
//!   `data/registry.json`.
//! - Units: a catalog entry with `layers` is built by the stack engine (`glassdb-stack`) into
//!   system curves plus a [`UnitRecord`] (build-up, per-layer values, pane groups' depths and
//!   reflectance shares); [`UnitBuilder`] builds one from a catalog's glasses on demand.

#![warn(missing_docs)]

mod angle_model;
mod build;
mod bundled;
pub mod catalog;
mod catalog_files;
mod curves;
mod error;
mod hemispherical;
mod lights;
mod normal;
mod record;
mod registry;
mod unit;
mod unit_builder;
mod unit_record;
mod validate;

/// The single-layer angle models (they live in the stack engine, which both the registry's
/// glasses and its units use).
pub use glassdb_stack::physics;

/// The largest catalog (`catalog.toml`) read.
pub const CATALOG_FILE: glassdb_io::InputLimit = glassdb_io::InputLimit::mib(16, "a catalog");

pub use build::{Application, BuildOptions, MaskIds, build_registry, catalog_inputs};
pub use bundled::{DEFAULT_REGISTRY_JSON, DEFAULT_REGISTRY_NAME, default_registry};
pub use error::RegistryError;
/// The cap on every curve's recorded validation tolerance (shared with fit files).
pub use glassdb_fit::MAX_CURVE_TOLERANCE;
/// The face of a pane a record's values are for (the `glassdb-side` crate's type).
pub use glassdb_side::{Side, UnknownSide};
pub use hemispherical::HemisphericalRecord;
pub use lights::{MAX_LIGHT_NAME, NamedLight, RegistryLight, check_light_name};
pub use record::{
    AngleCurve, AngleModelRecord, FileRef, GlassRecord, LuminousRecord, ProductRecord, Provenance,
};
pub use registry::{
    CHANNELS, ColourBasis, Registry, RegistryTable, SCHEMA_VERSION, SCHEMA_VERSION_BEFORE_LIGHTS,
    SCHEMA_VERSION_BEFORE_UNITS, SCHEMA_VERSION_ONE_TABLE,
};
pub use unit_builder::{ChosenElement, UnitBuilder, UnitChoice};
pub use unit_record::{
    Absorptance, GapRecord, PaneGroupRecord, SystemValues, UnitElement, UnitLayerRecord, UnitRecord,
};
