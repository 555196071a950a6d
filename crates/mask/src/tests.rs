use std::path::Path;

use glassdb_image::{ImageErrorKind, PngColor, PngCompression, PngEncodeOptions, PngSampleSlice};
use proptest::prelude::*;

use super::*;

fn opts() -> MaskReadOptions {
    MaskReadOptions::default()
}

/// The mask in `bytes`, read as file `name` with the default options.
fn read(bytes: &[u8], name: &str) -> MaskImage {
    read_mask_bytes(bytes, Path::new(name), &opts()).unwrap()
}

/// The message of reading `bytes` as file `name` with the default options, which must fail.
/// Writing `m` as `name` in `format` fails with a message that contains each of `needles`.
#[track_caller]
fn assert_write_error(m: &MaskImage, name: &str, format: MaskFormat, needles: &[&str]) {
    let err = write_mask_bytes(Path::new(name), m, format)
        .unwrap_err()
        .to_string();
    for needle in needles {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }
}

/// Reading `bytes` as the mask `name` fails with a message that contains each of `needles`.
#[track_caller]
fn assert_read_error(bytes: &[u8], name: &str, needles: &[&str]) {
    let err = read_mask_bytes(bytes, Path::new(name), &opts())
        .unwrap_err()
        .to_string();
    for needle in needles {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }
}

/// A 3×2 mask with hand-chosen values: ids 0, 7, 200 / 7, 0, 3; planes; cos codes.
fn packed8() -> MaskImage {
    MaskImage {
        width: 3,
        height: 2,
        id: vec![0, 7, 200, 7, 0, 3],
        cos_theta: CosTheta::Quantized8(vec![0, 255, 128, 1, 0, 51]),
        plane: vec![0, 0, 2, 1, 0, 0],
        coverage: None,
    }
}

/// Test PNG depth: 8-bit samples as given, or 16-bit samples from big-endian byte pairs.
#[derive(Clone, Copy)]
enum Depth {
    Eight,
    Sixteen,
}

fn encode_png(width: u32, height: u32, color: PngColor, depth: Depth, data: &[u8]) -> Vec<u8> {
    let options = PngEncodeOptions {
        compression: PngCompression::Fast,
        srgb_chunk: false,
    };
    match depth {
        Depth::Eight => {
            glassdb_image::encode_png(width, height, color, PngSampleSlice::U8(data), options)
        }
        Depth::Sixteen => {
            let wide: Vec<u16> = data
                .chunks_exact(2)
                .map(|b| u16::from_be_bytes([b[0], b[1]]))
                .collect();
            glassdb_image::encode_png(width, height, color, PngSampleSlice::U16(&wide), options)
        }
    }
    .unwrap()
}

fn exr_bytes(width: usize, height: usize, channels: Vec<(&str, Vec<f32>)>) -> Vec<u8> {
    glassdb_image::encode_exr_f32(width, height, channels).unwrap()
}

/// The whole error chain, as the command line prints it.
fn chain(err: &dyn std::error::Error) -> String {
    let mut text = err.to_string();
    let mut source = err.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    text
}

#[test]
fn packed_8bit_png_reads_green_as_id_blue_as_cos_red_as_plane() {
    // Pixel (1, 0): R = 4 (plane), G = 9 (id), B = 255 (cos 1).
    let data = [0, 0, 0, 4, 9, 255];
    let bytes = encode_png(2, 1, PngColor::Rgb, Depth::Eight, &data);
    let m = read(&bytes, "m.png");
    assert_eq!((m.width, m.height), (2, 1));
    assert_eq!(m.id, vec![0, 9]);
    assert_eq!(m.plane, vec![0, 4]);
    assert_eq!(m.cos_theta, CosTheta::Quantized8(vec![0, 255]));
    assert_eq!(m.cos_theta_at(1), 1.0);
    assert_eq!(
        m.id_pixel_counts().into_iter().collect::<Vec<_>>(),
        vec![(9, 1)]
    );
}

#[test]
fn packed_16bit_png_reads_big_endian_samples() {
    // One pixel: R = 1, G = 300, B = 32768 (cos = 32768/65535).
    let data = [0, 1, 0x01, 0x2c, 0x80, 0x00];
    let bytes = encode_png(1, 1, PngColor::Rgb, Depth::Sixteen, &data);
    let m = read(&bytes, "m.png");
    assert_eq!(m.id, vec![300]);
    assert_eq!(m.plane, vec![1]);
    assert_eq!(m.cos_theta, CosTheta::Quantized16(vec![32768]));
    assert!((m.cos_theta_at(0) - 32768.0 / 65535.0).abs() < 1e-15);
}

#[test]
fn rgba_png_alpha_is_ignored() {
    let data = [1, 2, 3, 0];
    let bytes = encode_png(1, 1, PngColor::Rgba, Depth::Eight, &data);
    let m = read(&bytes, "m.png");
    assert_eq!((m.id[0], m.plane[0]), (2, 1));
}

#[test]
fn png8_round_trip_is_exact() {
    let m = packed8();
    let bytes = write_mask_bytes(Path::new("x.png"), &m, MaskFormat::Png8).unwrap();
    assert_eq!(read(&bytes, "x.png"), m);
}

#[test]
fn png16_from_8bit_codes_is_exact_scaling_by_257() {
    let m = packed8();
    let bytes = write_mask_bytes(Path::new("x.png"), &m, MaskFormat::Png16).unwrap();
    let back = read(&bytes, "x.png");
    assert_eq!(back.id, m.id);
    assert_eq!(
        back.cos_theta,
        CosTheta::Quantized16(vec![0, 65535, 128 * 257, 257, 0, 51 * 257])
    );
    for i in 0..6 {
        assert_eq!(back.cos_theta_at(i), m.cos_theta_at(i));
    }
}

#[test]
fn exr_round_trip_keeps_float_cos_plane_and_coverage() {
    let m = MaskImage {
        width: 2,
        height: 2,
        id: vec![0, 1, 65535, 2],
        cos_theta: CosTheta::Float(vec![0.0, 0.123_456_7, 1.0, 0.5]),
        plane: vec![0, 3, 0, 1],
        coverage: Some(vec![0.0, 0.25, 1.0, 0.5]),
    };
    let bytes = write_mask_bytes(Path::new("x.exr"), &m, MaskFormat::Exr).unwrap();
    assert_eq!(read(&bytes, "x.exr"), m);
}

#[test]
fn exr_channel_names_are_selectable() {
    let bytes = exr_bytes(
        2,
        1,
        vec![
            ("ViewLayer.IndexMA", vec![0.0, 4.0]),
            ("ViewLayer.Facing", vec![0.3, 0.75]),
            ("R", vec![1.0, 1.0]),
        ],
    );
    let mut o = opts();
    o.exr_channels.id = "ViewLayer.IndexMA".into();
    o.exr_channels.cos_theta = "ViewLayer.Facing".into();
    let m = read_mask_bytes(&bytes, Path::new("aov.exr"), &o).unwrap();
    assert_eq!(m.id, vec![0, 4]);
    assert_eq!(m.cos_theta, CosTheta::Float(vec![0.3, 0.75]));
    assert_eq!(m.plane, vec![0, 0]);
    assert_eq!(m.coverage, None);

    assert_read_error(
        &bytes,
        "aov.exr",
        &["aov.exr", "\"id\"", "ViewLayer.IndexMA"],
    );
}

#[test]
fn exr_fractional_id_names_the_pixel() {
    let bytes = exr_bytes(
        3,
        2,
        vec![
            ("id", vec![0.0, 1.0, 2.0, 3.0, 4.5, 0.0]),
            ("cos_theta", vec![0.5; 6]),
        ],
    );
    assert_read_error(&bytes, "bad.exr", &["bad.exr", "x 1, y 1", "4.5"]);
}

#[test]
fn exr_cos_outside_unit_interval_on_glass_is_an_error_but_ignored_off_glass() {
    let ok = exr_bytes(
        2,
        1,
        vec![("id", vec![0.0, 1.0]), ("cos_theta", vec![7.0, 1.0000001])],
    );
    let m = read(&ok, "m.exr");
    assert_eq!(m.cos_theta_at(1), 1.0);
    let bad = exr_bytes(
        2,
        1,
        vec![("id", vec![0.0, 1.0]), ("cos_theta", vec![0.0, f32::NAN])],
    );
    assert_read_error(&bad, "m.exr", &["x 1, y 0", "NaN"]);
}

#[test]
fn binary_mask_white_is_the_given_glass_at_normal_incidence() {
    let data = [0, 255, 0, 255];
    let bytes = encode_png(4, 1, PngColor::Grey, Depth::Eight, &data);
    let mut o = opts();
    o.binary_glass_id = Some(12);
    let m = read_mask_bytes(&bytes, Path::new("b.png"), &o).unwrap();
    assert_eq!(m.id, vec![0, 12, 0, 12]);
    assert_eq!(m.cos_theta, CosTheta::Normal);
    assert_eq!(m.cos_theta_at(1), 1.0);
    assert_eq!(m.coverage, None);
    // Grey (antialiased) edges become coverage.
    let data = [0, 0, 0, 51, 51, 51, 255, 255, 255];
    let bytes = encode_png(3, 1, PngColor::Rgb, Depth::Eight, &data);
    let m = read_mask_bytes(&bytes, Path::new("b.png"), &o).unwrap();
    assert_eq!(m.id, vec![0, 12, 12]);
    assert_eq!(m.coverage, Some(vec![0.0, 0.2, 1.0]));
}

#[test]
fn grey_png_without_glass_id_is_explained() {
    let bytes = encode_png(1, 1, PngColor::Grey, Depth::Eight, &[255]);
    let err = read_mask_bytes(&bytes, Path::new("g.png"), &opts()).unwrap_err();
    assert!(
        matches!(err, MaskError::GreyPngWithoutGlassId { .. }),
        "{err:?}"
    );
    // The library says what is missing; the command line adds the flag that gives it.
    let err = err.to_string();
    assert!(
        err.contains("g.png") && err.contains("give the glass id"),
        "{err}"
    );
    assert!(!err.contains("--"), "{err}");
}

#[test]
fn writers_refuse_what_the_format_cannot_hold() {
    let mut m = packed8();
    m.id[4] = 256;
    assert_write_error(&m, "o.png", MaskFormat::Png8, &["x 1, y 1", "256"]);
    assert!(write_mask_bytes(Path::new("o.png"), &m, MaskFormat::Png16).is_ok());
    let mut m = packed8();
    m.coverage = Some(vec![1.0; 6]);
    assert!(write_mask_bytes(Path::new("o.png"), &m, MaskFormat::Png8).is_err());
    let mut m = packed8();
    m.plane.pop();
    assert!(matches!(
        write_mask_bytes(Path::new("o.exr"), &m, MaskFormat::Exr),
        Err(MaskError::Inconsistent(_))
    ));
}

#[test]
fn binary_round_trip_keeps_the_glass_and_its_coverage_and_refuses_two_glasses() {
    let m = MaskImage {
        width: 4,
        height: 1,
        id: vec![0, 7, 7, 7],
        cos_theta: CosTheta::Float(vec![0.0, 0.3, 0.6, 0.9]),
        plane: vec![0; 4],
        coverage: Some(vec![0.0, 1.0, 0.5, 0.001]),
    };
    let bytes = write_mask_bytes(Path::new("b.png"), &m, MaskFormat::Binary).unwrap();
    let read_opts = MaskReadOptions {
        binary_glass_id: Some(7),
        ..opts()
    };
    let back = read_mask_bytes(&bytes, Path::new("b.png"), &read_opts).unwrap();
    assert_eq!(back.id, vec![0, 7, 7, 7]);
    assert_eq!(back.cos_theta, CosTheta::Normal);
    // Coverage survives to 1/255; a sliver of glass stays glass (never rounds to black).
    let cov = back.coverage.expect("partial coverage is kept as grey");
    assert_eq!(cov, vec![0.0, 1.0, 128.0 / 255.0, 1.0 / 255.0]);
    let mut two = m.clone();
    two.id[3] = 8;
    assert_write_error(
        &two,
        "b.png",
        MaskFormat::Binary,
        &["x 3, y 0", "one glass"],
    );
    let mut planes = m.clone();
    planes.plane[2] = 1;
    assert_write_error(
        &planes,
        "b.png",
        MaskFormat::Binary,
        &["x 2, y 0", "one plane"],
    );
}

#[test]
fn float_cos_rounds_to_nearest_code() {
    let m = MaskImage {
        width: 3,
        height: 1,
        id: vec![1, 1, 1],
        cos_theta: CosTheta::Float(vec![0.5, 1.0 / 255.0 * 0.49, 0.999]),
        plane: vec![0; 3],
        coverage: None,
    };
    let bytes = write_mask_bytes(Path::new("o.png"), &m, MaskFormat::Png8).unwrap();
    let back = read(&bytes, "o.png");
    assert_eq!(back.cos_theta, CosTheta::Quantized8(vec![128, 0, 255]));
}

#[test]
fn write_mask_is_atomic_and_read_mask_names_missing_files() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("m.png");
    write_mask(&p, &packed8(), MaskFormat::Png8).unwrap();
    assert_eq!(read_mask(&p, &opts()).unwrap(), packed8());
    let missing = dir.path().join("nope.png");
    let err = read_mask(&missing, &opts()).unwrap_err().to_string();
    assert!(err.contains("nope.png"), "{err}");
    let err = write_mask(
        &dir.path().join("no/dir/m.png"),
        &packed8(),
        MaskFormat::Png8,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("no/dir/m.png"), "{err}");
}

#[test]
fn size_limit_is_checked_before_decoding() {
    let bytes = write_mask_bytes(Path::new("x.png"), &packed8(), MaskFormat::Png8).unwrap();
    let mut o = opts();
    o.max_pixels = 5;
    let err = read_mask_bytes(&bytes, Path::new("x.png"), &o).unwrap_err();
    assert_eq!(err.image_error_kind(), Some(ImageErrorKind::Limits));
    let err = chain(&err);
    assert!(err.contains("3×2") && err.contains("limit"), "{err}");
    let bytes = write_mask_bytes(Path::new("x.exr"), &packed8(), MaskFormat::Exr).unwrap();
    let err = read_mask_bytes(&bytes, Path::new("x.exr"), &o).unwrap_err();
    let err = chain(&err);
    assert!(err.contains("3×2") && err.contains("limit"), "{err}");
}

#[test]
fn unknown_format_shows_the_first_bytes() {
    let err = read_mask_bytes(b"GIF89a....", Path::new("m.gif"), &opts()).unwrap_err();
    let err = chain(&err);
    assert!(err.contains("m.gif") && err.contains("47"), "{err}");
}

#[test]
fn truncated_files_are_errors() {
    for format in [MaskFormat::Png8, MaskFormat::Exr] {
        let bytes = write_mask_bytes(Path::new("x"), &packed8(), format).unwrap();
        // (A PNG cut inside its final IEND chunk still holds every pixel, so it may decode.)
        for cut in [8, bytes.len() / 2, bytes.len() - 20] {
            assert!(
                read_mask_bytes(&bytes[..cut], Path::new("x"), &opts()).is_err(),
                "{format:?} cut at {cut}"
            );
        }
        for cut in 0..bytes.len() - 20 {
            let err = read_mask_bytes(&bytes[..cut], Path::new("x"), &opts()).unwrap_err();
            assert!(
                matches!(
                    err.image_error_kind(),
                    Some(ImageErrorKind::Invalid | ImageErrorKind::Unsupported)
                ),
                "{format:?} cut at {cut}: {err:?}"
            );
        }
    }
}

fn corrupt(bytes: &[u8], flips: &[(usize, u8)], cut: usize) -> Vec<u8> {
    let mut b = bytes.to_vec();
    for &(pos, v) in flips {
        if !b.is_empty() {
            let i = pos % b.len();
            b[i] ^= v;
        }
    }
    b.truncate(cut.max(1).min(b.len()));
    b
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, rng_seed: proptest::test_runner::RngSeed::Fixed(0x6c61_7373), failure_persistence: None, ..ProptestConfig::default() })]

    /// Corrupt PNG and EXR masks never panic: each read returns a mask or an error.
    #[test]
    fn corrupt_masks_never_panic(
        flips in proptest::collection::vec((any::<usize>(), 1u8..=255), 0..6),
        cut in 0usize..4000,
        exr in any::<bool>(),
        binary in any::<bool>(),
    ) {
        let m = MaskImage {
            width: 20,
            height: 17,
            id: (0..340).map(|i| (i % 5) as u16).collect(),
            cos_theta: CosTheta::Float((0..340).map(|i| (i % 11) as f32 / 10.0).collect()),
            plane: (0..340).map(|i| (i % 3) as u16).collect(),
            coverage: None,
        };
        let format = if exr { MaskFormat::Exr } else { MaskFormat::Png16 };
        let bytes = write_mask_bytes(Path::new("p"), &m, format).unwrap();
        let bad = corrupt(&bytes, &flips, if flips.is_empty() { cut } else { bytes.len() });
        let mut o = opts();
        o.max_pixels = 1 << 16;
        if binary && !exr {
            o.binary_glass_id = Some(1);
        }
        let _ = read_mask_bytes(&bad, Path::new("p"), &o);
    }
}

/// A frame that sees one plane of several (every glass pixel on plane 0) still says which
/// plane its pixels are on: once its EXR mask had no plane channel, and compose refused it
/// beside the scene's other planes' passes.
#[test]
fn an_exr_mask_on_plane_0_alone_still_stores_its_planes() {
    let dir = tempfile::tempdir().unwrap();
    let mut m = packed8();
    m.plane = vec![0; m.pixel_count()];
    let p = dir.path().join("m.exr");
    write_mask(&p, &m, MaskFormat::Exr).unwrap();
    assert!(read_mask_header(&p, &opts()).unwrap().stores_planes);
    let placed = read_placed_mask(&p, &opts()).unwrap();
    assert!(placed.stores_planes);
    assert_eq!(placed.image.plane, m.plane);
}

#[test]
fn the_header_says_where_the_mask_lies_and_what_reading_it_costs_without_decoding() {
    let dir = tempfile::tempdir().unwrap();
    for (format, stores_planes, has_coordinates, per_pixel) in [
        (MaskFormat::Png8, true, false, 5),
        (MaskFormat::Png16, true, false, 6),
        (MaskFormat::Exr, true, true, 8),
    ] {
        let p = dir.path().join(format!("m{format:?}"));
        write_mask(&p, &packed8(), format).unwrap();
        let h = read_mask_header(&p, &opts()).unwrap();
        let placed = read_placed_mask(&p, &opts()).unwrap();
        assert_eq!(h.windows, placed.windows, "{format:?}");
        assert_eq!(
            (h.stores_planes, h.has_coordinates),
            (stores_planes, has_coordinates)
        );
        assert_eq!(
            (placed.stores_planes, placed.has_coordinates),
            (stores_planes, has_coordinates)
        );
        assert_eq!(h.bytes_per_pixel, per_pixel, "{format:?}");
        assert_eq!(h.memory.kept, 6 * per_pixel, "{format:?}");
        // The file is held while reading.
        let len = std::fs::metadata(&p).unwrap().len();
        assert!(h.memory.transient >= len, "{format:?}");
    }
    // Only the header is read: cut after it, the file passes the header and fails decoding.
    let bytes = write_mask_bytes(Path::new("x.png"), &packed8(), MaskFormat::Png8).unwrap();
    let idat = bytes.windows(4).position(|w| w == b"IDAT").unwrap();
    let cut = dir.path().join("cut.png");
    std::fs::write(&cut, &bytes[..idat + 8]).unwrap();
    let h = read_mask_header(&cut, &opts()).unwrap();
    assert_eq!((h.windows.display.width, h.windows.display.height), (3, 2));
    assert!(read_mask(&cut, &opts()).is_err());
    // The header's checks are the reader's: a grey PNG is no packed mask, a binary mask must
    // be a PNG, glass id 0 is no glass, channels must exist.
    let grey = dir.path().join("grey.png");
    std::fs::write(
        &grey,
        encode_png(2, 1, PngColor::Grey, Depth::Eight, &[0, 255]),
    )
    .unwrap();
    assert!(matches!(
        read_mask_header(&grey, &opts()),
        Err(MaskError::GreyPngWithoutGlassId { .. })
    ));
    let binary = MaskReadOptions {
        binary_glass_id: Some(4),
        ..opts()
    };
    let h = read_mask_header(&grey, &binary).unwrap();
    assert!(!h.stores_planes && h.bytes_per_pixel == 8);
    let zero = MaskReadOptions {
        binary_glass_id: Some(0),
        ..opts()
    };
    assert!(matches!(
        read_mask_header(&grey, &zero),
        Err(MaskError::Layout { .. })
    ));
    let exr = dir.path().join("m.exr");
    std::fs::write(&exr, exr_bytes(2, 1, vec![("id", vec![1.0, 0.0])])).unwrap();
    assert!(matches!(
        read_mask_header(&exr, &binary),
        Err(MaskError::BinaryMaskNotPng { .. })
    ));
    let err = chain(&read_mask_header(&exr, &opts()).unwrap_err());
    assert!(err.contains("cos_theta") && err.contains("id"), "{err}");
}

#[test]
fn plane_bounds_are_the_glass_rectangles_per_plane() {
    // packed8: glass at (1,0) id 7 plane 0, (2,0) id 200 plane 2, (0,1) id 7 plane 1,
    // (2,1) id 3 plane 0.
    let b = packed8().plane_bounds();
    assert_eq!(b.keys().copied().collect::<Vec<_>>(), vec![0, 1, 2]);
    let p0 = b[&0];
    assert_eq!((p0.x_min, p0.y_min, p0.x_max, p0.y_max), (1, 0, 2, 1));
    assert_eq!(p0.glass_pixels, 2);
    assert_eq!(
        p0.window(),
        PixelWindow {
            x: 1,
            y: 0,
            width: 2,
            height: 2
        }
    );
    assert_eq!((b[&1].x_min, b[&1].y_min, b[&1].glass_pixels), (0, 1, 1));
    assert_eq!((b[&2].x_max, b[&2].y_max), (2, 0));
}

#[test]
fn group_bounds_hold_the_glass_of_units_with_that_group() {
    // packed8 with id 7 a unit of three pane groups, id 3 of two, id 200 monolithic.
    let groups = |id: u16| match id {
        7 => 3,
        3 => 2,
        _ => 1,
    };
    let b = packed8().group_bounds(groups);
    let keys: Vec<_> = b.keys().copied().collect();
    // Plane 0 holds ids 7 (1,0) and 3 (2,1); plane 1 id 7 (0,1); plane 2 only the monolith.
    assert_eq!(keys, vec![(0, 1), (0, 2), (1, 1), (1, 2)]);
    let g = |k| {
        let p: PlaneBounds = b[&k];
        (p.x_min, p.y_min, p.x_max, p.y_max, p.glass_pixels)
    };
    assert_eq!(g((0, 1)), (1, 0, 2, 1, 2));
    assert_eq!(g((0, 2)), (1, 0, 1, 0, 1), "only id 7 has a third group");
    assert_eq!(g((1, 2)), (0, 1, 0, 1, 1));
    assert!(packed8().group_bounds(|_| 1).is_empty());
}

/// Blender's own edge rule, `int(fraction · size)` with the fraction stored as float32
/// (DNA's `rctf border`) and multiplied in float32 (render_init_from_main).
fn blender_edge(fraction: f64, size: u32) -> i64 {
    ((fraction as f32) * size as f32) as i64
}

/// The edges Blender takes from a border: `[x_min, y_min, x_max, y_max]` inclusive, row 0 at
/// the top, as the rectangle states them.
fn blender_rectangle(border: [f64; 4], width: u32, height: u32) -> [i64; 4] {
    let [x0, x1, y0, y1] = border;
    let h = i64::from(height);
    [
        blender_edge(x0, width),
        h - blender_edge(y1, height),
        blender_edge(x1, width) - 1,
        h - blender_edge(y0, height) - 1,
    ]
}

#[test]
fn blender_borders_truncate_to_the_rectangle() {
    // 13/22 in float32 times 22 is 12.999999: an exact edge would lose a pixel there.
    assert_eq!(blender_edge(13.0 / 22.0, 22), 12);
    for (w, h) in [
        (1u32, 1u32),
        (22, 22),
        (22, 7),
        (7, 5),
        (64, 48),
        (99, 101),
        (320, 240),
        (1920, 1080),
        (4097, 2161),
        (16383, 9),
    ] {
        // Every edge of the frame, as a one-pixel rectangle's left and right, top and bottom.
        for e in 0..w.max(h) as i32 {
            let (x, y) = (e.min(w as i32 - 1), e.min(h as i32 - 1));
            let b = PlaneBounds {
                x_min: x,
                y_min: y,
                x_max: x,
                y_max: y,
                glass_pixels: 1,
            };
            let want = [x, y, x, y].map(i64::from);
            assert_eq!(
                blender_rectangle(b.blender_border(w, h), w, h),
                want,
                "{w}x{h}"
            );
        }
        let whole = PlaneBounds {
            x_min: 0,
            y_min: 0,
            x_max: w as i32 - 1,
            y_max: h as i32 - 1,
            glass_pixels: 0,
        };
        let b = whole.blender_border(w, h);
        assert_eq!(
            blender_rectangle(b, w, h),
            [0, 0, w as i64 - 1, h as i64 - 1]
        );
        assert!(b.iter().all(|f| (0.0..=1.0).contains(f)), "{b:?}");
    }
}

proptest! {
    /// Blender's truncation of the border gives back the rectangle, in any frame.
    #[test]
    fn blender_borders_truncate_to_any_rectangle(
        (w, h, x0, x1, y0, y1) in (1u32..5000, 1u32..5000).prop_flat_map(|(w, h)| {
            (Just(w), Just(h), 0..w, 0..w, 0..h, 0..h)
        })
    ) {
        let (x0, x1) = (x0.min(x1) as i32, x0.max(x1) as i32);
        let (y0, y1) = (y0.min(y1) as i32, y0.max(y1) as i32);
        let b = PlaneBounds { x_min: x0, y_min: y0, x_max: x1, y_max: y1, glass_pixels: 1 };
        prop_assert_eq!(
            blender_rectangle(b.blender_border(w, h), w, h),
            [x0, y0, x1, y1].map(i64::from)
        );
    }

    /// Every glass pixel lies in its plane's rectangle, and every side of the rectangle touches
    /// a glass pixel of that plane (brute force over the pixels).
    #[test]
    fn plane_bounds_are_tight(
        (w, h, cells) in (1u32..9, 1u32..9).prop_flat_map(|(w, h)| {
            (Just(w), Just(h), proptest::collection::vec((0u16..3, 0u16..3), (w * h) as usize))
        })
    ) {
        let mask = MaskImage {
            width: w,
            height: h,
            id: cells.iter().map(|c| c.0).collect(),
            cos_theta: CosTheta::Normal,
            plane: cells.iter().map(|c| c.1).collect(),
            coverage: None,
        };
        let bounds = mask.plane_bounds();
        for plane in 0u16..3 {
            let pixels: Vec<(i32, i32)> = (0..(w * h) as usize)
                .filter(|&i| mask.id[i] != 0 && mask.plane[i] == plane)
                .map(|i| ((i % w as usize) as i32, (i / w as usize) as i32))
                .collect();
            match bounds.get(&plane) {
                None => prop_assert!(pixels.is_empty()),
                Some(b) => {
                    prop_assert_eq!(b.glass_pixels, pixels.len() as u64);
                    prop_assert_eq!(b.x_min, pixels.iter().map(|p| p.0).min().unwrap());
                    prop_assert_eq!(b.x_max, pixels.iter().map(|p| p.0).max().unwrap());
                    prop_assert_eq!(b.y_min, pixels.iter().map(|p| p.1).min().unwrap());
                    prop_assert_eq!(b.y_max, pixels.iter().map(|p| p.1).max().unwrap());
                }
            }
        }
    }
}

/// The whole-mask scans run in parallel over many tasks (a 301 × 700 mask is four or more);
/// their merged results equal one pass over the pixels in order.
#[test]
fn parallel_scans_equal_a_serial_pass() {
    let (w, h) = (301usize, 700usize);
    let hash = |i: usize| (i as u32).wrapping_mul(0x9e37_79b9).rotate_left(11);
    let id: Vec<u16> = (0..w * h)
        .map(|i| {
            if hash(i) % 5 < 2 {
                0
            } else {
                (hash(i) >> 8) as u16 % 4
            }
        })
        .collect();
    // Planes in vertical and horizontal bands, so that runs along a row change plane.
    let plane: Vec<u16> = (0..w * h)
        .map(|i| ((i % w) / 70 + (i / w) / 150) as u16 % 6)
        .collect();
    let codes: Vec<u8> = (0..w * h).map(|i| (hash(i) >> 16) as u8).collect();
    for cos_theta in [
        CosTheta::Quantized8(codes.clone()),
        CosTheta::Float(codes.iter().map(|&c| f32::from(c) / 300.0).collect()),
    ] {
        let mask = MaskImage {
            width: w as u32,
            height: h as u32,
            id: id.clone(),
            cos_theta,
            plane: plane.clone(),
            coverage: None,
        };
        // Pixel by pixel, in order: the bounds of the glass pixels `keep` selects.
        let serial_bounds = |keep: &dyn Fn(usize) -> bool| {
            let mut bounds: BTreeMap<u16, PlaneBounds> = BTreeMap::new();
            for i in (0..w * h).filter(|&i| id[i] != 0 && keep(i)) {
                let (x, y) = ((i % w) as i32, (i / w) as i32);
                let b = bounds.entry(plane[i]).or_insert(PlaneBounds {
                    x_min: x,
                    y_min: y,
                    x_max: x,
                    y_max: y,
                    glass_pixels: 0,
                });
                (b.x_min, b.y_min) = (b.x_min.min(x), b.y_min.min(y));
                (b.x_max, b.y_max) = (b.x_max.max(x), b.y_max.max(y));
                b.glass_pixels += 1;
            }
            bounds
        };
        let mut counts = BTreeMap::new();
        let mut range: Option<(f64, f64)> = None;
        for i in (0..w * h).filter(|&i| id[i] != 0) {
            *counts.entry(id[i]).or_insert(0u64) += 1;
            let c = mask.cos_theta_at(i);
            range = Some(range.map_or((c, c), |(lo, hi)| (lo.min(c), hi.max(c))));
        }
        let bounds = serial_bounds(&|_| true);
        assert_eq!(mask.id_pixel_counts(), counts);
        assert_eq!(mask.plane_bounds(), bounds);
        // A selection of the glass pixels (odd columns of ids 1 and 2) against the same pass.
        let select = |x: i32, id: u16| x % 2 == 1 && id < 3;
        let selected = serial_bounds(&|i| select((i % w) as i32, id[i]));
        assert_eq!(mask.plane_bounds_of(|x, _, id, _| select(x, id)), selected);
        assert_eq!(mask.cos_theta_range(), range);
        assert!(
            bounds.len() == 6 && counts.len() == 3,
            "{bounds:?} {counts:?}"
        );
    }
}
