//! The encoders and the reader agree: what is written reads back exactly, and each refusal has
//! the class a user can act on.

use std::io::Cursor;

use glassdb_image::{
    ExrPlane, ExrSampleType, ExrStorage, ExrWriteOptions, ImageError, ImageErrorKind, ImageFile,
    PngColor, PngCompression, PngEncodeOptions, PngSampleSlice, PngSamples, decode_png,
    encode_exr_f32, encode_png, open_image, write_exr_planes,
};

const FAST: PngEncodeOptions = PngEncodeOptions {
    compression: PngCompression::Fast,
    srgb_chunk: false,
};

#[test]
fn png_round_trips_every_layout_and_depth() {
    for color in [PngColor::Grey, PngColor::Rgb, PngColor::Rgba] {
        let n = 3 * 2 * color.channels();
        let eight: Vec<u8> = (0..n).map(|i| (i * 37 % 256) as u8).collect();
        let sixteen: Vec<u16> = (0..n).map(|i| (i * 4099 % 65536) as u16).collect();
        for compression in [
            PngCompression::Fast,
            PngCompression::Balanced,
            PngCompression::High,
        ] {
            let options = PngEncodeOptions {
                compression,
                srgb_chunk: true,
            };
            let bytes = encode_png(3, 2, color, PngSampleSlice::U8(&eight), options).unwrap();
            let back = decode_png(&bytes, 6).unwrap();
            assert_eq!((back.width, back.height), (3, 2));
            assert_eq!(back.channels, color.channels());
            assert_eq!(back.samples, PngSamples::U8(eight.clone()));
            let bytes = encode_png(3, 2, color, PngSampleSlice::U16(&sixteen), options).unwrap();
            let back = decode_png(&bytes, 6).unwrap();
            assert_eq!(back.samples, PngSamples::U16(sixteen.clone()));
            assert_eq!(back.max_value(), 65535);
        }
    }
}

#[test]
fn png_encoder_refuses_a_wrong_sample_count_as_invalid() {
    let err = encode_png(2, 2, PngColor::Rgb, PngSampleSlice::U8(&[0; 11]), FAST).unwrap_err();
    assert!(
        matches!(err, ImageError::SampleCount { samples: 11, .. }),
        "{err:?}"
    );
    assert_eq!(err.kind(), ImageErrorKind::Invalid);
}

#[test]
fn pixel_limit_is_class_limits_for_png_and_exr() {
    let png = encode_png(3, 2, PngColor::Grey, PngSampleSlice::U8(&[9; 6]), FAST).unwrap();
    let err = decode_png(&png, 5).unwrap_err();
    assert_eq!(err.kind(), ImageErrorKind::Limits);
    assert!(err.to_string().contains("3×2"), "{err}");
    let exr = encode_exr_f32(3, 2, vec![("Y", vec![0.5; 6])]).unwrap();
    let ImageFile::Exr(file) = open_image(&exr, 5).unwrap() else {
        panic!("an EXR opens as an EXR");
    };
    let err = file.read_channels(0, &[0]).unwrap_err();
    assert_eq!(err.kind(), ImageErrorKind::Limits);
}

#[test]
fn exr_planes_round_trip_as_half_and_float() {
    let r: Vec<f32> = (0..12).map(|i| i as f32 * 0.25).collect();
    let a: Vec<f32> = (0..12).map(|i| 1.0 - i as f32 / 16.0).collect();
    for (storage, sample_type) in [
        (ExrStorage::Float, ExrSampleType::Float),
        (ExrStorage::Half, ExrSampleType::Half),
    ] {
        for (compression, zip_level) in [
            (exr::compression::Compression::ZIP16, None),
            (exr::compression::Compression::ZIP16, Some(9)),
            (exr::compression::Compression::ZIP1, Some(1)),
            (exr::compression::Compression::PIZ, None),
        ] {
            let planes = vec![
                ExrPlane::new("R", r.clone()),
                ExrPlane {
                    linear: true,
                    ..ExrPlane::new("A", a.clone())
                },
            ];
            let options = ExrWriteOptions {
                storage,
                compression,
                zip_level,
            };
            let mut out = Cursor::new(Vec::new());
            write_exr_planes(&mut out, 4, 3, planes, options).unwrap();
            let bytes = out.into_inner();
            let ImageFile::Exr(file) = open_image(&bytes, 100).unwrap() else {
                panic!("an EXR opens as an EXR");
            };
            let part = &file.parts()[0];
            // Channels are stored sorted by name: A, R.
            let names: Vec<&str> = part.channels.iter().map(|c| c.name.as_str()).collect();
            assert_eq!(names, ["A", "R"]);
            assert!(part.channels.iter().all(|c| c.sample_type == sample_type));
            let (info, planes) = file.read_channels(0, &[1, 0]).unwrap();
            assert_eq!((info.width, info.height), (4, 3));
            // Every sample here is exact in half precision.
            assert_eq!(
                planes,
                vec![r.clone(), a.clone()],
                "{storage:?} {compression:?}"
            );
            // A channel asked for twice comes back twice.
            let (_, planes) = file.read_channels(0, &[1, 0, 1]).unwrap();
            assert_eq!(planes, vec![r.clone(), a.clone(), r.clone()]);
        }
    }
}

#[test]
fn exr_writer_refuses_bad_input_with_its_class() {
    let write = |planes: Vec<ExrPlane>, zip_level| {
        let options = ExrWriteOptions {
            storage: ExrStorage::Float,
            compression: exr::compression::Compression::ZIP16,
            zip_level,
        };
        write_exr_planes(Cursor::new(Vec::new()), 2, 2, planes, options).unwrap_err()
    };
    let err = write(vec![ExrPlane::new("R", vec![0.0; 3])], None);
    assert_eq!(err.kind(), ImageErrorKind::Invalid, "{err:?}");
    let err = write(vec![ExrPlane::new("R", vec![0.0; 4])], Some(10));
    assert_eq!(err.kind(), ImageErrorKind::Unsupported, "{err:?}");
}

#[test]
fn unknown_bytes_are_unsupported_and_show_their_start() {
    let err = open_image(b"GIF89a....", 100).unwrap_err();
    assert_eq!(err.kind(), ImageErrorKind::Unsupported);
    assert!(err.to_string().contains("47, 49, 46"), "{err}");
}

/// Two parts of half, float and uint channels, one in scan lines (ZIP) at an offset data
/// window, one in tiles (PIZ) smaller than its part: `read_exr_exact_keeping` returns what
/// `read_exr_exact` returns less the channels it leaves out, in the stored types.
#[test]
fn exr_exact_read_of_some_channels_is_the_whole_read_without_the_others() {
    use exr::prelude::{
        AnyChannel, AnyChannels, Blocks, Compression, Encoding, FlatSamples, Image,
        ImageAttributes, IntegerBounds, Layer, LayerAttributes, LineOrder, SmallVec, Vec2,
        WritableImage,
    };
    let ramp =
        |n: usize, k: usize| -> Vec<f32> { (0..n).map(|i| (i * 7 + k) as f32 / 64.0).collect() };
    let half = |v: Vec<f32>| FlatSamples::F16(v.into_iter().map(half::f16::from_f32).collect());
    let channels = |n: usize| -> AnyChannels<FlatSamples> {
        let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = [
            AnyChannel::new("ViewLayer.Combined.R", half(ramp(n, 1))),
            AnyChannel::new("ViewLayer.Combined.G", FlatSamples::F32(ramp(n, 2))),
            AnyChannel::new("ViewLayer.Combined_sun.R", half(ramp(n, 3))),
            AnyChannel::new("ViewLayer.Combined_sun.G", FlatSamples::F32(ramp(n, 4))),
            AnyChannel::new("ViewLayer.Depth.Z", FlatSamples::F32(ramp(n, 5))),
            AnyChannel::new("id", FlatSamples::U32((0..n as u32).collect())),
        ]
        .into_iter()
        .collect();
        AnyChannels::sort(list)
    };
    let layer = |name: &str, (w, h): (usize, usize), at: (i32, i32), blocks, compression| {
        let mut attributes = LayerAttributes::named(name);
        attributes.layer_position = Vec2(at.0, at.1);
        let encoding = Encoding {
            compression,
            blocks,
            line_order: LineOrder::Increasing,
        };
        Layer::new((w, h), attributes, encoding, channels(w * h))
    };
    let layers: SmallVec<[_; 2]> = [
        layer(
            "lines",
            (37, 45),
            (3, -2),
            Blocks::ScanLines,
            Compression::ZIP16,
        ),
        layer(
            "tiles",
            (21, 13),
            (0, 0),
            Blocks::Tiles(Vec2(8, 8)),
            Compression::PIZ,
        ),
    ]
    .into_iter()
    .collect();
    let image = Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions((40, 44))),
        layers,
    );
    let mut bytes = Vec::new();
    image.write().to_buffered(Cursor::new(&mut bytes)).unwrap();

    let whole = glassdb_image::read_exr_exact(&bytes, u64::MAX).unwrap();
    let parts = glassdb_image::read_exr_headers(&bytes).unwrap();
    let keeps: [&dyn Fn(&str) -> bool; 4] = [
        &|_| true,
        &|n| !n.starts_with("ViewLayer.Combined_sun."),
        &|n| n == "id",
        &|_| false,
    ];
    for (k, keep) in keeps.iter().enumerate() {
        let got =
            glassdb_image::read_exr_exact_keeping(Cursor::new(&bytes), &parts, u64::MAX, keep)
                .unwrap();
        let mut want = whole.clone();
        for part in &mut want.parts {
            part.channels.retain(|(name, _)| keep(name));
        }
        assert_eq!(got, want, "filter {k}");
    }
    // The limits are read_exr_exact's, from the headers.
    let small = glassdb_image::read_exr_exact_keeping(Cursor::new(&bytes), &parts, 100, &|_| true);
    assert!(
        matches!(small, Err(ImageError::TooLarge { .. })),
        "{small:?}"
    );
}
