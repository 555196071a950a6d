//! What a file's bytes are when a text reader is handed binary data (an image, an archive, a
//! database): named from its signature, so that the reader's message says what the file is
//! instead of echoing its bytes as a bad header or cell.

/// How many leading bytes the sniffers look at ([`binary_kind`], and the spectral readers' look
/// for markup).
pub const SNIFF_BYTES: usize = 8192;

/// Known binary signatures and what they usually are.
const SIGNATURES: &[(&[u8], &str)] = &[
    (b"\x89PNG\r\n\x1a\n", "a PNG image"),
    (b"\xFF\xD8\xFF", "a JPEG image"),
    (b"\x76\x2F\x31\x01", "an OpenEXR image"),
    (b"II*\x00", "a TIFF image"),
    (b"MM\x00*", "a TIFF image"),
    (b"BLENDER", "a Blender file (.blend)"),
    (b"%PDF-", "a PDF document"),
    (
        b"PK\x03\x04",
        "a ZIP archive, e.g. an .xlsx workbook or a THERM .thmz",
    ),
    (
        b"\xD0\xCF\x11\xE0\xA1\xB1\x1A\xE1",
        "an OLE2 compound file, e.g. a legacy .xls workbook",
    ),
    (
        b"\x00\x01\x00\x00Standard Jet DB",
        "a Microsoft Access database, e.g. the IGDB's .mdb",
    ),
    (
        b"\x00\x01\x00\x00Standard ACE DB",
        "a Microsoft Access database (.accdb)",
    ),
    (b"SQLite format 3\x00", "an SQLite database"),
    (b"\x1F\x8B", "gzip-compressed data"),
    (b"\x7FELF", "an executable (ELF)"),
];

/// Binary data, named when its signature is known.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BinaryKind {
    /// What the signature says the file is (`"an OpenEXR image"`), if it is a known one.
    pub what: Option<&'static str>,
}

impl std::fmt::Display for BinaryKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.what.unwrap_or("binary data"))
    }
}

/// The kind of binary data `bytes` start with, or `None` for what may be text: a known
/// signature, else a NUL byte or more than 5 % control bytes (other than whitespace and the DOS
/// end-of-file mark) in the first 8 KiB. Bytes ≥ 0x80 count as text (UTF-8, Windows-1252).
pub fn binary_kind(bytes: &[u8]) -> Option<BinaryKind> {
    if let Some((_, what)) = SIGNATURES.iter().find(|(sig, _)| bytes.starts_with(sig)) {
        return Some(BinaryKind { what: Some(what) });
    }
    let head = &bytes[..bytes.len().min(SNIFF_BYTES)];
    let control = head
        .iter()
        .filter(|&&b| (b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r' | 0x0C | 0x1A)) || b == 0x7F)
        .count();
    (head.contains(&0) || control * 20 > head.len()).then_some(BinaryKind { what: None })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signatures_and_control_bytes() {
        let exr = b"\x76\x2F\x31\x01\x02\x00\x00\x00channels\x00chlist\x00";
        assert_eq!(binary_kind(exr).unwrap().to_string(), "an OpenEXR image");
        let png = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR";
        assert_eq!(binary_kind(png).unwrap().to_string(), "a PNG image");
        assert_eq!(
            binary_kind(b"0.3 0.1\x00 0.2 0.3").unwrap().to_string(),
            "binary data"
        );
        // text: CSV, UTF-8 and Windows-1252 (™ = 0x99), nothing at all
        assert_eq!(binary_kind(b"angle_deg,R,T\n0,0.08,0.88\n"), None);
        assert_eq!(binary_kind("Wavelength (µm)\tT\n".as_bytes()), None);
        assert_eq!(binary_kind(b"{ Product Name: Optifloat\x99 }\n"), None);
        assert_eq!(binary_kind(b""), None);
    }
}
