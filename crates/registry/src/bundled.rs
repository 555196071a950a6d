//! The bundled default registry: `data/registry.json`, built from `data/catalog.toml` with the
//! default options (`glassdb registry build data/catalog.toml -o data/registry.json`) and
//! compiled in, so `compose` without a registry file needs neither the catalog nor a fit.

use crate::{Registry, RegistryError};

/// The bundled registry JSON text.
pub const DEFAULT_REGISTRY_JSON: &str = include_str!("../../../data/registry.json");

/// The name the bundled registry goes by in messages.
pub const DEFAULT_REGISTRY_NAME: &str = "data/registry.json (bundled)";

/// The bundled default registry, parsed and validated once per process and cloned afterwards.
pub fn default_registry() -> Result<Registry, RegistryError> {
    static DEFAULT: std::sync::OnceLock<Registry> = std::sync::OnceLock::new();
    if let Some(registry) = DEFAULT.get() {
        return Ok(registry.clone());
    }
    let registry = Registry::from_json_str(DEFAULT_REGISTRY_JSON, DEFAULT_REGISTRY_NAME)?;
    Ok(DEFAULT.get_or_init(|| registry).clone())
}
