//! The files a catalog names, read relative to it and hashed for the registry's provenance:
//! what the normal values, the angle models, the units and the build share.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use crate::RegistryError;
use crate::catalog::resolve;

/// Reads the files a catalog names, relative to the catalog.
pub(crate) struct CatalogFiles<'a> {
    pub(crate) catalog_path: &'a Path,
}

impl CatalogFiles<'_> {
    /// The full path and bytes of the file `rel` that `glass` names, of at most `limit`.
    pub(crate) fn read(
        &self,
        rel: &str,
        glass: &str,
        limit: glassdb_io::InputLimit,
    ) -> Result<(PathBuf, Vec<u8>), RegistryError> {
        let path = resolve(self.catalog_path, rel);
        match glassdb_io::read_input(&path, limit) {
            Ok(bytes) => Ok((path, bytes)),
            Err(source) => Err(RegistryError::InputFile {
                glass: glass.to_string(),
                path,
                source,
            }),
        }
    }
}

/// The SHA-256 of `bytes` in lowercase hex (a catalog's and its files' provenance).
pub(crate) fn sha256_hex(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    digest.iter().map(|b| format!("{b:02x}")).collect()
}
