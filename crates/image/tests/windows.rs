//! EXR data and display windows, read from OpenEXR's own samples (`fixtures/exr_windows/`):
//! the windows are reported as the file states them, and a file whose data window is not its
//! display window is refused as unsupported, never read index by index (which shifts it).

use glassdb_image::{ImageErrorKind, ImageFile, PixelWindow, open_image};

fn sample(name: &str) -> Vec<u8> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/exr_windows")
        .join(name);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn window(x: i32, y: i32, width: usize, height: usize) -> PixelWindow {
    PixelWindow {
        x,
        y,
        width,
        height,
    }
}

#[test]
fn full_frame_sample_reports_equal_windows_and_is_accepted() {
    let bytes = sample("t01.exr");
    let ImageFile::Exr(exr) = open_image(&bytes, 1 << 24).unwrap() else {
        panic!("t01.exr is an EXR");
    };
    let part = &exr.parts()[0];
    assert_eq!(part.data_window, window(0, 0, 400, 300));
    assert_eq!(part.display_window, part.data_window);
    exr.require_full_frame().unwrap();
}

#[test]
fn cropped_sample_reports_its_windows_and_is_refused_as_unsupported() {
    let bytes = sample("t08.exr");
    let ImageFile::Exr(exr) = open_image(&bytes, 1 << 24).unwrap() else {
        panic!("t08.exr is an EXR");
    };
    let part = &exr.parts()[0];
    // DisplayWindow/README.rst: the same 400 × 300 pixels, data window (30, 40)–(429, 339)
    // inside the display window (0, 0)–(500, 400).
    assert_eq!(part.data_window, window(30, 40, 400, 300));
    assert_eq!(part.display_window, window(0, 0, 501, 401));
    let err = exr.require_full_frame().unwrap_err();
    assert_eq!(err.kind(), ImageErrorKind::Unsupported);
    let message = err.to_string();
    for part in ["(30, 40)–(429, 339)", "(0, 0)–(500, 400)"] {
        assert!(message.contains(part), "{message}");
    }
}
