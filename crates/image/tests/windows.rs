//! EXR data and display windows, read from OpenEXR's own samples (`fixtures/exr_windows/`):
//! the windows are reported as the file states them, the pixels decoded are those of the data
//! window, and a file written from an exact read keeps windows, attributes and samples.

use std::io::Cursor;

use glassdb_image::{
    ExrImageOut, ExrPartOut, ExrPlane, ExrStorage, ExrWriteOptions, ImageFile, PixelWindow,
    PlaneSamples, open_image, read_exr_channel_rows, read_exr_exact, read_exr_headers,
    write_exr_image,
};

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

fn rgb(bytes: &[u8]) -> Vec<Vec<f32>> {
    let ImageFile::Exr(exr) = open_image(bytes, 1 << 24).unwrap() else {
        panic!("not an EXR");
    };
    let part = &exr.parts()[0];
    let channels: Vec<usize> = ["R", "G", "B"]
        .iter()
        .map(|n| part.channels.iter().position(|c| c.name == *n).unwrap())
        .collect();
    exr.read_channels(0, &channels).unwrap().1
}

#[test]
fn windows_are_reported_as_stored_and_the_data_window_is_decoded() {
    let full = read_exr_headers(&sample("t01.exr")).unwrap();
    assert_eq!(full[0].data_window, window(0, 0, 400, 300));
    assert_eq!(full[0].display_window, full[0].data_window);
    // DisplayWindow/README.rst: the same 400 × 300 pixels, data window (30, 40)–(429, 339)
    // inside the display window (0, 0)–(500, 400).
    let cropped = read_exr_headers(&sample("t08.exr")).unwrap();
    assert_eq!(cropped[0].data_window, window(30, 40, 400, 300));
    assert_eq!(cropped[0].display_window, window(0, 0, 501, 401));
    assert_eq!(cropped[0].windows().data.to_string(), "(30, 40)–(429, 339)");
    assert_eq!(rgb(&sample("t01.exr")), rgb(&sample("t08.exr")));
}

#[test]
fn an_exact_copy_keeps_windows_attributes_and_samples() {
    let bytes = sample("t08.exr");
    let exact = read_exr_exact(&bytes, 1 << 24).unwrap();
    let display = read_exr_headers(&bytes).unwrap()[0].display_window;
    let image = ExrImageOut {
        display_window: display,
        attributes: exact.attributes.clone(),
        parts: exact
            .parts
            .iter()
            .map(|p| ExrPartOut {
                data_window: p.data_window,
                attributes: p.attributes.clone(),
                planes: p
                    .channels
                    .iter()
                    .map(|(name, s)| ExrPlane {
                        name: name.clone(),
                        samples: PlaneSamples::Exact(s.clone()),
                        linear: false,
                    })
                    .collect(),
            })
            .collect(),
    };
    let mut out = Cursor::new(Vec::new());
    let options = ExrWriteOptions {
        storage: ExrStorage::Float,
        compression: exr::compression::Compression::ZIP16,
        zip_level: Some(4),
    };
    write_exr_image(&mut out, image, options).unwrap();
    let copy = out.into_inner();
    let headers = read_exr_headers(&copy).unwrap();
    assert_eq!(headers[0].data_window, window(30, 40, 400, 300));
    assert_eq!(headers[0].display_window, display);
    let again = read_exr_exact(&copy, 1 << 24).unwrap();
    assert_eq!(again.parts[0].channels, exact.parts[0].channels);
    assert_eq!(
        again.attributes.chromaticities,
        exact.attributes.chromaticities
    );
    assert_eq!(again.attributes.pixel_aspect, exact.attributes.pixel_aspect);
}

#[test]
fn reading_some_rows_decodes_the_blocks_holding_them_and_places_them() {
    // OpenEXR's t08.exr: data window (30, 40)–(429, 339), read whole and by rows.
    let bytes = sample("t08.exr");
    let ImageFile::Exr(exr) = open_image(&bytes, 1 << 24).unwrap() else {
        panic!("not an EXR");
    };
    let full = rgb(&bytes);
    let part = &exr.parts()[0];
    let lines = part.compression.scan_lines_per_block();
    let channels: Vec<usize> = ["R", "G", "B"]
        .iter()
        .map(|n| part.channels.iter().position(|c| c.name == *n).unwrap())
        .collect();
    for (first, last) in [(100, 100), (40, 60), (200, 500), (-10, 45), (339, 339)] {
        let (info, planes) =
            read_exr_channel_rows(&bytes, 0, &channels, 1 << 24, Some((first, last))).unwrap();
        let w = info.data_window;
        // Whole blocks of `lines` rows from the data window's top, covering the rows asked for.
        assert_eq!((w.x, w.width), (30, 400));
        assert_eq!((w.y - 40) % lines as i32, 0, "{first}-{last}: {w}");
        assert!(
            i64::from(w.y) <= first.max(40) && w.end_y() > last.min(339),
            "{w}"
        );
        assert!(w.height <= (last.min(339) - first.max(40)) as usize + 2 * lines);
        // The same samples as the whole read, where they are.
        let rows = (w.y - 40) as usize..(w.y - 40) as usize + w.height;
        for (got, all) in planes.iter().zip(&full) {
            assert!(
                got[..] == all[rows.start * 400..rows.end * 400],
                "{first}-{last}: samples differ"
            );
        }
    }
    // Rows outside the data window decode the first block only.
    let (info, _) = read_exr_channel_rows(exr.bytes(), 0, &[0], 1 << 24, Some((0, 10))).unwrap();
    assert_eq!((info.data_window.y, info.data_window.height), (40, lines));
}
