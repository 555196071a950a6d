//! What a file handed to the angle-table or fit-file reader is when it is not what that reader
//! reads: binary data (an EXR, a PNG), a fit file given to `glassdb fit`, an angle table given
//! to `glassdb eval`, a registry or a planes file. Named from the bytes alone, before any parse
//! error could echo them.

use glassdb_io::sniff::BinaryKind;

/// What a file is, as far as the fit crate's readers tell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileContent {
    /// Binary data: an image, an archive, a database (named when its signature is known).
    Binary(BinaryKind),
    /// A glassdb fit file (`{"glasses": [...]}`), which `glassdb eval` reads.
    FitFile,
    /// An angle table (CSV with an `angle_deg` or `theta_deg` column), which `glassdb fit`
    /// reads.
    AngleTable,
    /// A glassdb glass registry (`{"schema": …, "tables" or "glasses": …}`).
    Registry,
    /// A glassdb planes file (`{"format": "glassdb-planes/…"}`).
    Planes,
    /// Some other JSON document.
    Json,
}

impl FileContent {
    /// What `bytes` are when they are not an angle table: binary data or JSON (a fit file, a
    /// registry, a planes file, other JSON). `None` for text the CSV reader should try.
    pub fn not_an_angle_table(bytes: &[u8]) -> Option<FileContent> {
        if let Some(kind) = glassdb_io::sniff::binary_kind(bytes) {
            return Some(FileContent::Binary(kind));
        }
        FileContent::of_json(bytes)
    }

    /// What `bytes` are when they are not a fit file: binary data, an angle table, a registry
    /// or a planes file. `None` for anything else (the JSON reader's error says what is wrong).
    pub fn not_a_fit_file(bytes: &[u8]) -> Option<FileContent> {
        if let Some(kind) = glassdb_io::sniff::binary_kind(bytes) {
            return Some(FileContent::Binary(kind));
        }
        match FileContent::of_json(bytes) {
            Some(kind @ (FileContent::Registry | FileContent::Planes)) => Some(kind),
            Some(_) => None,
            None => looks_like_angle_table(bytes).then_some(FileContent::AngleTable),
        }
    }

    /// The kind of a JSON document from its top-level keys (`None`: not JSON).
    fn of_json(bytes: &[u8]) -> Option<FileContent> {
        #[derive(serde::Deserialize)]
        struct TopLevel {
            #[serde(default)]
            schema: Option<serde::de::IgnoredAny>,
            #[serde(default)]
            format: Option<serde_json::Value>,
            #[serde(default)]
            glasses: Option<serde::de::IgnoredAny>,
        }
        let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        let value: serde_json::Value = serde_json::from_slice(bytes).ok()?;
        if !value.is_object() {
            return Some(FileContent::Json);
        }
        let Ok(top) = serde_json::from_value::<TopLevel>(value) else {
            return Some(FileContent::Json);
        };
        let planes = top
            .format
            .as_ref()
            .and_then(|f| f.as_str())
            .is_some_and(|f| f.starts_with("glassdb-planes"));
        Some(if top.schema.is_some() {
            FileContent::Registry
        } else if planes {
            FileContent::Planes
        } else if top.glasses.is_some() {
            FileContent::FitFile
        } else {
            FileContent::Json
        })
    }
}

/// True when the first line that is not blank or a `#` comment is a CSV header with an
/// `angle_deg` or `theta_deg` column.
fn looks_like_angle_table(bytes: &[u8]) -> bool {
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(64 * 1024)]);
    let Some(header) = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))
    else {
        return false;
    };
    header.split(',').any(|cell| {
        let cell = cell.trim().trim_start_matches('\u{feff}');
        cell.eq_ignore_ascii_case("angle_deg") || cell.eq_ignore_ascii_case("theta_deg")
    })
}

/// What a reader of the fit crate reads: the file it was handed should have been one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExpectedFile {
    /// An angle table (`glassdb fit`).
    AngleTable,
    /// A fit file (`glassdb eval`).
    FitFile,
}

impl std::fmt::Display for ExpectedFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ExpectedFile::AngleTable => "an angle table",
            ExpectedFile::FitFile => "a fit file",
        })
    }
}

impl std::fmt::Display for FileContent {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FileContent::Binary(kind) => write!(f, "{kind}"),
            FileContent::FitFile => f.write_str("a glassdb fit file"),
            FileContent::AngleTable => f.write_str("an angle table (CSV)"),
            FileContent::Registry => f.write_str("a glassdb glass registry"),
            FileContent::Planes => f.write_str("a glassdb planes file"),
            FileContent::Json => f.write_str("a JSON document"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_kind_is_named_by_the_reader_it_is_not_for() {
        let exr = b"\x76\x2F\x31\x01\x02\x00\x00\x00channels\x00";
        for bytes in [&exr[..], b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR"] {
            assert!(matches!(
                FileContent::not_an_angle_table(bytes),
                Some(FileContent::Binary(_))
            ));
            assert!(matches!(
                FileContent::not_a_fit_file(bytes),
                Some(FileContent::Binary(_))
            ));
        }
        let fit = br#"{"glasses": [{"name": "a"}]}"#;
        assert_eq!(
            FileContent::not_an_angle_table(fit),
            Some(FileContent::FitFile)
        );
        assert_eq!(FileContent::not_a_fit_file(fit), None);
        let table = b"# clear glass\nangle_deg,R,T\n0,0.08,0.88\n";
        assert_eq!(FileContent::not_an_angle_table(table), None);
        assert_eq!(
            FileContent::not_a_fit_file(table),
            Some(FileContent::AngleTable)
        );
        let registry = br#"{"schema": "glassdb-registry/3", "tables": []}"#;
        assert_eq!(
            FileContent::not_a_fit_file(registry),
            Some(FileContent::Registry)
        );
        let planes = br#"{"format": "glassdb-planes/1", "planes": []}"#;
        assert_eq!(
            FileContent::not_an_angle_table(planes),
            Some(FileContent::Planes)
        );
        assert_eq!(
            FileContent::not_an_angle_table(b"[1, 2]"),
            Some(FileContent::Json)
        );
        // a table whose header is not an angle table's is left to the CSV reader
        assert_eq!(
            FileContent::not_a_fit_file(b"wavelength,T\n300,0.1\n"),
            None
        );
    }
}
