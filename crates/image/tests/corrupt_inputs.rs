//! Corrupt input never panics and never reaches the `Internal` class: every committed fixture
//! image cut at a sweep of prefix lengths, and OpenEXR's own damaged-file corpus
//! (`fixtures/exr_damaged/`, see its README), each fail as invalid or unsupported data.

use std::path::{Path, PathBuf};

use glassdb_image::{ImageError, ImageErrorKind, ImageFile, open_image};

/// Pixel limit for the sweeps: well above every fixture, far below what a forged header asks.
const MAX_PIXELS: u64 = 1 << 24;

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Decodes everything in the file: a PNG whole, every channel of every part of an EXR.
fn decode_all(bytes: &[u8]) -> Result<(), ImageError> {
    match open_image(bytes, MAX_PIXELS)? {
        ImageFile::Png(_) => Ok(()),
        ImageFile::Exr(exr) => {
            for (p, part) in exr.parts().iter().enumerate() {
                let channels: Vec<usize> = (0..part.channels.len()).collect();
                exr.read_channels(p, &channels)?;
            }
            Ok(())
        }
    }
}

/// Every `*.exr` and `*.png` under `dir`, recursively, sorted.
fn images_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            images_under(&path, out);
        } else if matches!(
            path.extension().and_then(|e| e.to_str()),
            Some("exr" | "png")
        ) {
            out.push(path);
        }
    }
}

fn committed_fixture_images() -> Vec<PathBuf> {
    let mut files = Vec::new();
    for dir in ["fixtures", "data"] {
        images_under(&repo_root().join(dir), &mut files);
    }
    files.sort();
    files
}

/// Where a PNG's pixel data is complete: the end of its last IDAT chunk's data. A prefix that
/// keeps every IDAT byte (cut in the last CRC or in IEND) legitimately still decodes.
fn png_pixel_data_end(bytes: &[u8]) -> usize {
    let mut pos = 8;
    let mut end = bytes.len();
    while pos + 8 <= bytes.len() {
        let len = u32::from_be_bytes([bytes[pos], bytes[pos + 1], bytes[pos + 2], bytes[pos + 3]])
            as usize;
        if &bytes[pos + 4..pos + 8] == b"IDAT" {
            end = pos + 8 + len;
        }
        pos += 12 + len;
    }
    end
}

/// Prefix lengths to try: every length up to 2 KiB (headers, offset tables), then about 200
/// evenly spread ones, and the last few bytes.
fn prefix_lengths(len: usize) -> Vec<usize> {
    let mut cuts: Vec<usize> = (0..len.min(2048)).collect();
    if len > 2048 {
        let step = ((len - 2048) / 200).max(1);
        cuts.extend((2048..len).step_by(step));
        cuts.extend(len.saturating_sub(16)..len);
    }
    cuts.sort_unstable();
    cuts.dedup();
    cuts
}

fn is_data_class(kind: ImageErrorKind) -> bool {
    matches!(kind, ImageErrorKind::Invalid | ImageErrorKind::Unsupported)
}

#[test]
fn every_fixture_prefix_is_invalid_or_unsupported() {
    let files = committed_fixture_images();
    assert!(
        files.len() >= 10,
        "expected the committed fixtures, found {files:?}"
    );
    let mut failures = Vec::new();
    for path in &files {
        let bytes = std::fs::read(path).unwrap();
        let name = path.strip_prefix(repo_root()).unwrap_or(path).display();
        if let Err(e) = decode_all(&bytes) {
            failures.push(format!("{name}: the whole file fails: {e:?}"));
            continue;
        }
        let is_png = bytes.starts_with(b"\x89PNG");
        let ok_from = if is_png {
            png_pixel_data_end(&bytes)
        } else {
            bytes.len()
        };
        for cut in prefix_lengths(bytes.len()) {
            match decode_all(&bytes[..cut]) {
                Ok(()) if cut >= ok_from => {}
                Ok(()) => failures.push(format!("{name} cut at {cut}: decoded")),
                Err(e) if is_data_class(e.kind()) => {}
                Err(e) => failures.push(format!("{name} cut at {cut}: {:?}: {e:?}", e.kind())),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The class each damaged file must get, from `fixtures/exr_damaged/expected.tsv`.
fn expected_classes() -> Vec<(String, String)> {
    let text =
        std::fs::read_to_string(repo_root().join("fixtures/exr_damaged/expected.tsv")).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let (name, class) = l.split_once('\t').expect("name<TAB>class");
            (name.to_string(), class.to_string())
        })
        .collect()
}

fn class_name(result: &Result<(), ImageError>) -> &'static str {
    match result {
        Ok(()) => "ok",
        Err(e) => match e.kind() {
            ImageErrorKind::Invalid => "invalid",
            ImageErrorKind::Unsupported => "unsupported",
            ImageErrorKind::Limits => "limits",
            ImageErrorKind::Io => "io",
            ImageErrorKind::Internal => "internal",
        },
    }
}

#[test]
fn openexr_damaged_corpus_gets_its_recorded_class() {
    let dir = repo_root().join("fixtures/exr_damaged");
    let expected = expected_classes();
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !matches!(n.as_str(), "LICENSE" | "README.md" | "expected.tsv"))
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = expected.iter().map(|(n, _)| n.clone()).collect();
    listed.sort();
    assert_eq!(on_disk, listed, "expected.tsv must list every damaged file");
    let mut failures = Vec::new();
    for (name, class) in &expected {
        assert!(
            matches!(class.as_str(), "invalid" | "unsupported" | "limits" | "ok"),
            "{name}: class {class:?} is not one a damaged file may have"
        );
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let result = decode_all(&bytes);
        let got = class_name(&result);
        if got != class {
            failures.push(format!("{name}: expected {class}, got {got}: {result:?}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
