//! A truncated pass, at every prefix length, is a decoding error of class invalid or
//! unsupported that names the file; never a panic, never a pass.

use std::path::Path;

use glassdb_image::ImageErrorKind;
use glassdb_pass::{PassError, PassReadOptions, read_pass_bytes};

fn sweep(fixture: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/example")
        .join(fixture);
    let bytes = std::fs::read(&path).unwrap();
    let opts = PassReadOptions::default();
    read_pass_bytes(&bytes, &path, &opts).expect("the whole fixture reads");
    // A PNG still decodes when only its IEND chunk (the last 12 bytes) is cut.
    let strict = if fixture.ends_with(".png") {
        bytes.len() - 12
    } else {
        bytes.len()
    };
    for cut in 0..strict {
        let err = match read_pass_bytes(&bytes[..cut], &path, &opts) {
            Ok(_) => panic!("{fixture} cut at {cut} decoded"),
            Err(e) => e,
        };
        assert!(
            matches!(err, PassError::Decode { .. })
                && matches!(
                    err.image_error_kind(),
                    Some(ImageErrorKind::Invalid | ImageErrorKind::Unsupported)
                ),
            "{fixture} cut at {cut}: {err:?}"
        );
        assert!(err.to_string().contains(fixture), "{err}");
    }
}

#[test]
fn truncated_exr_passes_are_invalid_or_unsupported() {
    sweep("trans.exr");
    sweep("refl.exr");
}

#[test]
fn truncated_png_passes_are_invalid_or_unsupported() {
    sweep("mask.png");
}
