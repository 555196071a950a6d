//! Which reader reads a spectral file, and reading it: the format from the extension, then
//! from the content; data glassdb does not read refused by name first.

use std::path::Path;

use crate::error::SpectralError;
use crate::read::{ReadOptions, SpectralData, SpectralFormat, decode_cp1252, read_optics};
use crate::read_csv::{looks_like_csv, read_csv};
use crate::read_igsdb::read_igsdb_json;
use crate::sniff::{unsupported_kind, utf16_to_utf8};

/// The largest spectral data file read (CSV, LBNL Optics text or IGSDB JSON).
pub const SPECTRAL_FILE: glassdb_io::InputLimit =
    glassdb_io::InputLimit::mib(64, "a spectral data file");

/// Reads a spectral file; the format comes from the extension, then from the content.
pub fn read_spectral_file(path: &Path, opts: &ReadOptions) -> Result<SpectralData, SpectralError> {
    let bytes =
        glassdb_io::read_input(path, SPECTRAL_FILE).map_err(|source| SpectralError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    read_spectral_bytes(&bytes, &path.display().to_string(), opts)
}

/// Reads spectral data from memory. `source_name` is used for messages and, by its extension
/// (`.csv`, `.json`, anything else), to choose the format; when the extension says nothing
/// the content decides (`{"` starts JSON, a wavelength header starts CSV, else Optics).
///
/// UTF-16 text with a byte-order mark is read as text. Binary data and markup (BSDF XML, HTML)
/// are refused as [`SpectralError::Unsupported`] whatever the extension says.
pub fn read_spectral_bytes(
    bytes: &[u8],
    source_name: &str,
    opts: &ReadOptions,
) -> Result<SpectralData, SpectralError> {
    let transcoded = utf16_to_utf8(bytes);
    let bytes = transcoded.as_deref().unwrap_or(bytes);
    if let Some(kind) = unsupported_kind(bytes) {
        return Err(SpectralError::Unsupported {
            source_name: source_name.to_owned(),
            kind,
        });
    }
    match detect_format(bytes, source_name) {
        SpectralFormat::Csv => read_csv(bytes, source_name, opts),
        SpectralFormat::Optics => read_optics(bytes, source_name),
        SpectralFormat::IgsdbJson => read_igsdb_json(bytes, source_name),
    }
}

/// Chooses the reader: by extension, then by the first non-blank bytes.
pub fn detect_format(bytes: &[u8], source_name: &str) -> SpectralFormat {
    match glassdb_io::lowercase_extension(Path::new(source_name)).as_deref() {
        Some("csv" | "tsv") => return SpectralFormat::Csv,
        Some("json") => return SpectralFormat::IgsdbJson,
        Some(
            "dat" | "lof" | "afg" | "oag" | "ipe" | "vta" | "gvb" | "hct" | "ppg" | "sgg" | "gdt",
        ) => {
            return SpectralFormat::Optics;
        }
        _ => {}
    }
    let text_start: Vec<u8> = bytes
        .iter()
        .copied()
        .skip_while(|b| b.is_ascii_whitespace() || *b == 0xEF || *b == 0xBB || *b == 0xBF)
        .take(4096)
        .collect();
    let after_first = || text_start[1..].iter().find(|b| !b.is_ascii_whitespace());
    match text_start.first() {
        Some(b'{') if matches!(after_first(), Some(b'"') | Some(b'}')) => {
            return SpectralFormat::IgsdbJson;
        }
        Some(b'{') => return SpectralFormat::Optics,
        // A list of products (the API's search results).
        Some(b'[') if matches!(after_first(), Some(b'{')) => return SpectralFormat::IgsdbJson,
        _ => {}
    }
    let lower: Vec<u8> = text_start.iter().map(|b| b.to_ascii_lowercase()).collect();
    if lower.windows(11).any(|w| w == b"wavelength_") {
        return SpectralFormat::Csv;
    }
    // A header with a wavelength column (`Wavelength (nm)`, `nm`, …), perhaps below a title.
    // Whole lines only, so that a multi-byte UTF-8 character is never cut in two.
    let complete_lines = match text_start.iter().rposition(|&b| b == b'\n') {
        Some(end) => &text_start[..end],
        None => &text_start[..],
    };
    if looks_like_csv(&decode_cp1252(complete_lines)) {
        return SpectralFormat::Csv;
    }
    SpectralFormat::Optics
}
