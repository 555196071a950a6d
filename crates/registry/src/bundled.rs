//! The bundled default catalog (`data/catalog.toml`) and the spectral files it names, compiled
//! into the binary so that `compose` without `--registry` needs no file lookups.

/// The catalog text.
pub const CATALOG: &str = include_str!("../../../data/catalog.toml");

/// The name the catalog goes by in messages and provenance.
pub const CATALOG_NAME: &str = "data/catalog.toml (bundled)";

/// The bundled files, by their path relative to the catalog.
const FILES: &[(&str, &[u8])] = &[
    (
        "glazing/CLEAR_3.DAT",
        include_bytes!("../../../data/glazing/CLEAR_3.DAT"),
    ),
    (
        "glazing/CLEAR_6.DAT",
        include_bytes!("../../../data/glazing/CLEAR_6.DAT"),
    ),
    (
        "glazing/CLEAR5.LOF",
        include_bytes!("../../../data/glazing/CLEAR5.LOF"),
    ),
    (
        "glazing/LOW-E_5.LOF",
        include_bytes!("../../../data/glazing/LOW-E_5.LOF"),
    ),
    (
        "glazing/913.json",
        include_bytes!("../../../data/glazing/913.json"),
    ),
    (
        "glazing/igsdb_product_10693.json",
        include_bytes!("../../../data/glazing/igsdb_product_10693.json"),
    ),
    (
        "glazing/CSR42_3.afg",
        include_bytes!("../../../data/glazing/CSR42_3.afg"),
    ),
    (
        "glazing/nfrc_20748.oag",
        include_bytes!("../../../data/glazing/nfrc_20748.oag"),
    ),
    (
        "glazing/nfrc_9962.json",
        include_bytes!("../../../data/glazing/nfrc_9962.json"),
    ),
    (
        "glazing/nfrc_9223.json",
        include_bytes!("../../../data/glazing/nfrc_9223.json"),
    ),
];

/// The bytes of a bundled file.
pub fn file(rel: &str) -> Option<&'static [u8]> {
    FILES
        .iter()
        .find(|(name, _)| *name == rel)
        .map(|(_, bytes)| *bytes)
}
