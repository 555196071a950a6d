//! What a file is before any reader tries it: UTF-16 text (transcoded), binary data and markup
//! (XML/HTML, BSDF XML), which no spectral reader reads and which otherwise get a misleading
//! "expected 4 numbers" or "invalid JSON" message.

use glassdb_io::sniff::SNIFF_BYTES;

use crate::error::UnsupportedKind;

/// UTF-16 text with a byte-order mark (Excel's "Unicode Text" export, some instrument software),
/// as UTF-8. `None` when there is no UTF-16 BOM. Unpaired surrogates become U+FFFD.
pub(crate) fn utf16_to_utf8(bytes: &[u8]) -> Option<Vec<u8>> {
    let little_endian = match bytes {
        [0xFF, 0xFE, ..] => true,
        [0xFE, 0xFF, ..] => false,
        _ => return None,
    };
    let units = bytes[2..].chunks_exact(2).map(|pair| {
        let pair = [pair[0], pair[1]];
        if little_endian {
            u16::from_le_bytes(pair)
        } else {
            u16::from_be_bytes(pair)
        }
    });
    let text: String = char::decode_utf16(units)
        .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
        .collect();
    Some(text.into_bytes())
}

/// The kind of file `bytes` is when it is one the spectral readers cannot read: binary data or
/// markup. `None` for anything that may be text spectral data.
pub(crate) fn unsupported_kind(bytes: &[u8]) -> Option<UnsupportedKind> {
    binary_kind(bytes).or_else(|| markup_kind(bytes))
}

/// Binary data, named from its signature by the one list of them (`glassdb_io::sniff`).
fn binary_kind(bytes: &[u8]) -> Option<UnsupportedKind> {
    glassdb_io::sniff::binary_kind(bytes).map(|b| UnsupportedKind::Binary { what: b.what })
}

fn markup_kind(bytes: &[u8]) -> Option<UnsupportedKind> {
    let head = &bytes[..bytes.len().min(SNIFF_BYTES)];
    let head = head.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(head);
    let start = head.iter().position(|b| !b.is_ascii_whitespace())?;
    let mut rest = &head[start..];
    if rest.first() != Some(&b'<') {
        return None;
    }
    if contains(head, b"<WindowElement") {
        return Some(UnsupportedKind::BsdfXml);
    }
    // Skip the declaration, processing instructions, comments and the DOCTYPE to the first
    // element's name.
    loop {
        let skip_to = if rest.starts_with(b"<?") {
            find(rest, b"?>").map(|i| i + 2)
        } else if rest.starts_with(b"<!--") {
            find(rest, b"-->").map(|i| i + 3)
        } else if rest.starts_with(b"<!") {
            find(rest, b">").map(|i| i + 1)
        } else {
            break;
        };
        let Some(skip_to) = skip_to else { break };
        rest = &rest[skip_to..];
        let next = rest.iter().position(|b| !b.is_ascii_whitespace())?;
        rest = &rest[next..];
    }
    let name: String = rest
        .strip_prefix(b"<")?
        .iter()
        .take_while(|b| b.is_ascii_alphanumeric() || matches!(b, b':' | b'_' | b'-' | b'.'))
        .take(64)
        .map(|&b| b as char)
        .collect();
    if name.is_empty() {
        return None;
    }
    Some(UnsupportedKind::Markup { root: name })
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

fn contains(haystack: &[u8], needle: &[u8]) -> bool {
    find(haystack, needle).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binary_signatures_and_control_bytes() {
        let png = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR";
        assert_eq!(
            unsupported_kind(png),
            Some(UnsupportedKind::Binary {
                what: Some("a PNG image")
            })
        );
        let zip = b"PK\x03\x04\x14\x00\x06\x00";
        assert!(matches!(
            unsupported_kind(zip),
            Some(UnsupportedKind::Binary { what: Some(w) }) if w.contains("xlsx")
        ));
        assert_eq!(
            unsupported_kind(b"0.3 0.1\x00 0.2 0.3"),
            Some(UnsupportedKind::Binary { what: None })
        );
        // Windows-1252 text (™ = 0x99) and UTF-8 text are text.
        assert_eq!(unsupported_kind(b"{ Product Name: Optifloat\x99 }\n"), None);
        assert_eq!(unsupported_kind("Wavelength (µm)\tT\n".as_bytes()), None);
        assert_eq!(unsupported_kind(b""), None);
    }

    #[test]
    fn markup_is_named_by_its_first_element() {
        let bsdf = b"<?xml version=\"1.0\"?>\n<WindowElement xmlns=\"http://windows.lbl.gov\">";
        assert_eq!(unsupported_kind(bsdf), Some(UnsupportedKind::BsdfXml));
        let html = b"\n<!DOCTYPE html>\n<!-- saved -->\n<html lang=\"en\"><head>";
        assert_eq!(
            unsupported_kind(html),
            Some(UnsupportedKind::Markup {
                root: "html".into()
            })
        );
        assert_eq!(unsupported_kind(b"<"), None);
        assert_eq!(unsupported_kind(b"{\"a\": 1}"), None);
    }

    #[test]
    fn utf16_with_bom_becomes_utf8() {
        let mut le = vec![0xFF, 0xFE];
        for u in "nm\t%T\n300\t0,5\n".encode_utf16() {
            le.extend(u.to_le_bytes());
        }
        assert_eq!(utf16_to_utf8(&le).unwrap(), b"nm\t%T\n300\t0,5\n");
        let be: Vec<u8> = [0xFE, 0xFF, 0x00, b'a', 0xD8, 0x00].into_iter().collect();
        assert_eq!(utf16_to_utf8(&be).unwrap(), "a\u{FFFD}".as_bytes());
        assert_eq!(utf16_to_utf8(b"abc"), None);
    }
}
