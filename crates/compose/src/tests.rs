//! Golden images small enough to compute by hand, and the r = 0, t = 1 identity.

use std::path::Path;

use glassdb_encode::OutputOptions;
use glassdb_mask::{CosTheta, MaskImage};
use glassdb_pass::{CarriedFrame, LinearImage, PassReadOptions, PassSource};
use proptest::prelude::*;

use super::*;
use crate::colour::RegistryLuts;
use crate::kernel::{KernelInput, KernelShapeError, compose_in_place};
use crate::lut::GlassLut;

/// Glass 1: r = (0.1, 0.2, 0.3), t = (0.5, 0.6, 0.7) at every angle, back r = (0.4, 0.4, 0.4).
/// Glass 2: r = 0.5·(1 − cos), t = cos (grey); normal values r0 = 0, t0 = 1.
fn test_lut() -> GlassLut {
    GlassLut::from_fn(
        &[1, 2],
        |id, side, c| match (id, side) {
            (1, Side::Front) => ([0.1, 0.2, 0.3], [0.5, 0.6, 0.7]),
            (1, Side::Back) => ([0.4; 3], [0.5, 0.6, 0.7]),
            _ => ([0.5 * (1.0 - c); 3], [c; 3]),
        },
        |id, side| match (id, side) {
            (1, Side::Front) => ([0.1, 0.2, 0.3], [0.5, 0.6, 0.7]),
            (1, Side::Back) => ([0.4; 3], [0.5, 0.6, 0.7]),
            _ => ([0.0; 3], [1.0; 3]),
        },
    )
}

fn mask(id: Vec<u16>, cos: CosTheta, plane: Vec<u16>, coverage: Option<Vec<f32>>) -> MaskImage {
    let n = id.len() as u32;
    MaskImage {
        width: n,
        height: 1,
        id,
        cos_theta: cos,
        plane,
        coverage,
    }
}

/// A mask with 8-bit cos θ codes and no coverage.
fn mask8(id: Vec<u16>, codes: Vec<u8>, plane: Vec<u16>) -> MaskImage {
    mask(id, CosTheta::Quantized8(codes), plane, None)
}

/// One pixel of the same value in every channel.
fn grey(v: f32) -> [Vec<f32>; 3] {
    [vec![v], vec![v], vec![v]]
}

fn run(
    trans: [Vec<f32>; 3],
    refl: &[[Vec<f32>; 3]],
    m: &MaskImage,
    sides: &[Side],
) -> ([Vec<f32>; 3], KernelCounts) {
    let lut = test_lut();
    let refl_planes: Vec<[&[f32]; 3]> = refl
        .iter()
        .map(|p| [p[0].as_slice(), p[1].as_slice(), p[2].as_slice()])
        .collect();
    let mut out = trans;
    let [a, b, c] = &mut out;
    let counts =
        compose_in_place(KernelInput::new([a, b, c], &refl_planes, sides, m, &lut).unwrap());
    (out, counts)
}

#[test]
fn golden_constant_glass_8bit_mask() {
    // Pixel 0: no glass → trans. Pixel 1: glass 1 → trans·t + refl·r per channel.
    let m = mask8(vec![0, 1], vec![0, 200], vec![0, 0]);
    let trans = [vec![1.0, 1.0], vec![2.0, 2.0], vec![4.0, 4.0]];
    let refl = [[vec![8.0, 10.0], vec![8.0, 10.0], vec![8.0, 10.0]]];
    let (out, counts) = run(trans, &refl, &m, &[Side::Front]);
    // R: 1·0.5 + 10·0.1 = 1.5; G: 2·0.6 + 10·0.2 = 3.2; B: 4·0.7 + 10·0.3 = 5.8.
    assert_eq!([out[0][0], out[1][0], out[2][0]], [1.0, 2.0, 4.0]);
    assert!((out[0][1] - 1.5).abs() < 1e-6);
    assert!((out[1][1] - 3.2).abs() < 1e-6);
    assert!((out[2][1] - 5.8).abs() < 1e-6);
    assert_eq!(counts, KernelCounts::default());
}

#[test]
fn golden_angle_dependent_glass_each_cos_kind() {
    // Glass 2 at cos = 0.2: t = 0.2, r = 0.4; trans 1, refl 2 → 0.2 + 0.8 = 1.0.
    // At cos = 51/255 = 0.2 exactly (8-bit), 13107/65535 = 0.2 (16-bit), 0.2 (float).
    for cos in [
        CosTheta::Quantized8(vec![51]),
        CosTheta::Quantized16(vec![13107]),
        CosTheta::Float(vec![0.2]),
    ] {
        let m = mask(vec![2], cos.clone(), vec![0], None);
        let (out, _) = run(grey(1.0), &[grey(2.0)], &m, &[Side::Front]);
        assert!((out[0][0] - 1.0).abs() < 2e-6, "{cos:?}: {}", out[0][0]);
    }
    // Binary mask: normal-incidence values r0 = 0, t0 = 1 → the transmission pass.
    let m = mask(vec![2], CosTheta::Normal, vec![0], None);
    let (out, _) = run(grey(3.0), &[grey(9.0)], &m, &[Side::Front]);
    assert_eq!(out[0][0], 3.0);
}

#[test]
fn golden_two_planes_and_back_side() {
    // Pixel 0 on plane 0 (front, r_R = 0.1), pixel 1 on plane 1 (back, r = 0.4).
    let m = mask8(vec![1, 1], vec![255, 255], vec![0, 1]);
    let trans = [vec![0.0, 0.0], vec![0.0, 0.0], vec![0.0, 0.0]];
    let refl = [
        [vec![10.0, 99.0], vec![10.0, 99.0], vec![10.0, 99.0]],
        [vec![99.0, 5.0], vec![99.0, 5.0], vec![99.0, 5.0]],
    ];
    let (out, _) = run(trans, &refl, &m, &[Side::Front, Side::Back]);
    assert!((out[0][0] - 1.0).abs() < 1e-6); // 10 · 0.1
    assert!((out[0][1] - 2.0).abs() < 1e-6); // 5 · 0.4
}

#[test]
fn golden_coverage() {
    // Coverage 0.25 on glass 1, R: (1 − 0.25)·2 + 0.25·(2·0.5 + 4·0.1) = 1.5 + 0.35 = 1.85.
    let m = mask(
        vec![1],
        CosTheta::Float(vec![1.0]),
        vec![0],
        Some(vec![0.25]),
    );
    let (out, _) = run(grey(2.0), &[grey(4.0)], &m, &[Side::Front]);
    assert!((out[0][0] - 1.85).abs() < 1e-6, "{}", out[0][0]);
}

#[test]
fn nan_propagates_and_is_counted() {
    let m = mask8(vec![1, 0, 1], vec![9; 3], vec![0; 3]);
    let trans = [
        vec![f32::NAN, f32::INFINITY, 1.0],
        vec![1.0; 3],
        vec![1.0; 3],
    ];
    let refl = [[vec![1.0, 1.0, f32::NAN], vec![1.0; 3], vec![1.0; 3]]];
    let (out, counts) = run(trans, &refl, &m, &[Side::Front]);
    assert!(out[0][0].is_nan() && out[0][1].is_infinite() && out[0][2].is_nan());
    assert_eq!(counts.nonfinite_output, 3);
    assert_eq!(counts.nonfinite_trans, 2);
    assert_eq!(counts.nonfinite_refl, 1);
}

#[test]
fn unknown_ids_pass_through_when_allowed() {
    let m = mask8(vec![9], vec![9], vec![0]);
    let (out, counts) = run(grey(1.5), &[grey(7.0)], &m, &[Side::Front]);
    assert_eq!(out[0][0], 1.5);
    assert_eq!(counts.passthrough_pixels, 1);
}

#[test]
fn kernel_input_of_the_wrong_shape_is_refused_once() {
    let lut = test_lut();
    let m = mask(vec![1, 0], CosTheta::Normal, vec![0, 0], None);
    let two = [1.0f32; 2];
    let three = [1.0f32; 3];
    let good = [[two.as_slice(), two.as_slice(), two.as_slice()]];
    let (mut a, mut b, mut c) = (vec![1.0f32; 2], vec![1.0f32; 2], vec![1.0f32; 3]);
    let e = KernelInput::new([&mut a, &mut b, &mut c], &good, &[Side::Front], &m, &lut);
    assert!(matches!(
        e,
        Err(KernelShapeError::Transmission {
            channel: 2,
            samples: 3,
            pixels: 2
        })
    ));
    let bad = [[two.as_slice(), three.as_slice(), two.as_slice()]];
    let mut c = vec![1.0f32; 2];
    let e = KernelInput::new([&mut a, &mut b, &mut c], &bad, &[Side::Front], &m, &lut);
    assert!(matches!(
        e,
        Err(KernelShapeError::Reflection {
            pass: 0,
            channel: 1,
            ..
        })
    ));
    let e = KernelInput::new([&mut a, &mut b, &mut c], &good, &[], &m, &lut);
    assert!(matches!(
        e,
        Err(KernelShapeError::SidesPerPass {
            passes: 1,
            sides: 0
        })
    ));
    let inconsistent = mask(vec![1, 0], CosTheta::Quantized8(vec![3]), vec![0, 0], None);
    let e = KernelInput::new(
        [&mut a, &mut b, &mut c],
        &good,
        &[Side::Front],
        &inconsistent,
        &lut,
    );
    assert!(matches!(e, Err(KernelShapeError::Mask(_))));
    let ok = KernelInput::new([&mut a, &mut b, &mut c], &good, &[Side::Front], &m, &lut);
    assert_eq!(compose_in_place(ok.unwrap()).passthrough_pixels, 0);
}

/// Writes `planes` (R, G, B of `width × height` pixels) as a float EXR pass.
pub(crate) fn write_float_pass(path: &Path, width: u32, height: u32, planes: [Vec<f32>; 3]) {
    let img = LinearImage {
        width,
        height,
        rgb: planes,
        alpha: None,
    };
    let src = PassSource::Exr {
        sample_type: glassdb_image::ExrSampleType::Float,
        compression: glassdb_encode::DEFAULT_EXR_COMPRESSION,
        layer: String::new(),
        part: 0,
        channel_names: vec!["R".into(), "G".into(), "B".into()],
    };
    let frame = CarriedFrame::whole(width, height);
    glassdb_encode::write_output(path, img, frame, &src, &OutputOptions::default()).unwrap();
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(5), failure_persistence: None, ..ProptestConfig::default() })]

    /// r = 0, t = 1 returns the transmission pass bit for bit (every finite f32 including −0,
    /// subnormals and huge values; any mask), through a float EXR file and back.
    #[test]
    fn r0_t1_is_identity_bit_exact(
        bits in proptest::collection::vec(any::<u32>(), 3 * 12),
        refl in proptest::collection::vec(-1e30f32..1e30, 3 * 12),
        ids in proptest::collection::vec(0u16..3, 12),
        codes in proptest::collection::vec(any::<u8>(), 12),
    ) {
        let lut = GlassLut::from_fn(&[1, 2], |_, _, _| ([0.0; 3], [1.0; 3]), |_, _| ([0.0; 3], [1.0; 3]));
        let trans: Vec<f32> = bits.iter().map(|&b| { let v = f32::from_bits(b); if v.is_finite() { v } else { 0.5 } }).collect();
        let planes = |v: &[f32]| [v[..12].to_vec(), v[12..24].to_vec(), v[24..].to_vec()];
        let m = MaskImage { width: 4, height: 3, id: ids, cos_theta: CosTheta::Quantized8(codes), plane: vec![0; 12], coverage: None };
        let dir = tempfile::tempdir().unwrap();
        let t_path = dir.path().join("t.exr");
        let r_path = dir.path().join("r.exr");
        let m_path = dir.path().join("m.png");
        let write = |p: &Path, v: &[f32]| write_float_pass(p, 4, 3, planes(v));
        write(&t_path, &trans);
        write(&r_path, &refl);
        glassdb_mask::write_mask(&m_path, &m, glassdb_mask::MaskFormat::Png8).unwrap();
        let job = ComposeJob { inputs: FrameFiles::new(vec![r_path], t_path, m_path), output: dir.path().join("o.exr") };
        let luts = RegistryLuts::single(glassdb_registry::ColourBasis::Space(glassdb_colour::RgbSpace::Srgb), lut);
        compose_frame(&job, &ComposeSettings::default(), &luts).unwrap();
        let out = glassdb_pass::read_pass(&job.output, &PassReadOptions::default()).unwrap();
        let got: Vec<u32> = out.image.rgb.iter().flatten().map(|v| v.to_bits()).collect();
        let want: Vec<u32> = trans.iter().map(|v| v.to_bits()).collect();
        prop_assert_eq!(got, want);
        let is_float = matches!(out.source, PassSource::Exr { sample_type: glassdb_image::ExrSampleType::Float, .. });
        prop_assert!(is_float);
    }
}

#[test]
fn unknown_ids_are_listed_up_to_ten_then_counted() {
    let ids: Vec<(u16, u64)> = (1..=12).map(|id| (id, 100 + u64::from(id))).collect();
    let err = ComposeError::UnknownIds {
        mask: "m.png".into(),
        registry: "r.json".into(),
        ids,
        none_known: false,
    };
    let message = err.to_string();
    assert!(message.contains("id 10 (110 pixels)"), "{message}");
    assert!(!message.contains("id 11 ("), "{message}");
    // Ids 11 and 12: 111 + 112 pixels.
    assert!(
        message.contains("and 2 more id(s) (223 pixels)"),
        "{message}"
    );
    assert!(!message.contains("colour transform"), "{message}");
    let err = ComposeError::UnknownIds {
        mask: "m.png".into(),
        registry: "r.json".into(),
        ids: vec![(187, 5)],
        none_known: true,
    };
    assert!(err.to_string().contains("colour transform"), "{err}");
}

#[test]
fn a_frame_reports_its_stages_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, v: f32| {
        let path = dir.path().join(name);
        write_float_pass(&path, 2, 1, [vec![v; 2], vec![v; 2], vec![v; 2]]);
        path
    };
    let m = mask(
        vec![1, 0],
        CosTheta::Quantized8(vec![255, 0]),
        vec![0; 2],
        None,
    );
    let m_path = dir.path().join("m.png");
    glassdb_mask::write_mask(&m_path, &m, glassdb_mask::MaskFormat::Png8).unwrap();
    let job = ComposeJob {
        inputs: FrameFiles::new(vec![write("r.exr", 0.25)], write("t.exr", 0.5), m_path),
        output: dir.path().join("o.exr"),
    };
    let basis = glassdb_registry::ColourBasis::Space(glassdb_colour::RgbSpace::Srgb);
    let luts = RegistryLuts::single(basis, test_lut());
    let log = glassdb_io::StageLog::default();
    compose_frame_with_progress(&job, &ComposeSettings::default(), &luts, &log).unwrap();
    assert_eq!(log.stages(), FRAME_STAGES);
    // a frame that fails before decoding reports no stage
    let log = glassdb_io::StageLog::default();
    let no_refl = ComposeJob {
        inputs: FrameFiles {
            refl: Vec::new(),
            ..job.inputs
        },
        ..job
    };
    assert!(
        compose_frame_with_progress(&no_refl, &ComposeSettings::default(), &luts, &log).is_err()
    );
    assert!(log.stages().is_empty());
}

/// Three pixels on two planes: glass 1 front (plane 0), glass 2 back (plane 1, cos 0.6), no
/// glass; trans 0.5 and refl 0.25 (plane 0), 0.75 (plane 1), per channel c + 0.01·c.
fn in_memory_frame() -> (MemoryFrame, ComposeSettings) {
    let ch = |v: f32| -> [Vec<f32>; 3] { std::array::from_fn(|c| vec![v + 0.01 * c as f32; 3]) };
    let frame = MemoryFrame {
        trans: ch(0.5),
        refl: vec![ch(0.25), ch(0.75)],
        mask: mask8(vec![1, 2, 0], vec![255, 153, 0], vec![0, 1, 0]),
        space: None,
    };
    let mut settings = ComposeSettings::default();
    settings.plane_sides.insert(1, Side::Back);
    (frame, settings)
}

fn labels() -> MemoryLabels {
    MemoryLabels {
        trans: "trans".into(),
        mask: "mask".into(),
    }
}

#[test]
fn a_frame_in_memory_is_the_frame_compose_writes() {
    let (frame, settings) = in_memory_frame();
    let basis = glassdb_registry::ColourBasis::Space(glassdb_colour::RgbSpace::Srgb);
    let luts = RegistryLuts::single(basis, test_lut());
    let got = compose_in_memory(frame.clone(), &settings, &luts, &labels()).unwrap();
    // Glass 1 front: trans·t + refl·r; glass 2 at cos 0.6 (code 153): r = 0.2, t = 0.6.
    let c = 153.0f32 / 255.0;
    assert_eq!(got.rgb[0][0], 0.5 * 0.5 + 0.25 * 0.1);
    assert!((got.rgb[0][1] - (0.5 * c + 0.75 * 0.5 * (1.0 - c))).abs() < 1e-6);
    assert_eq!(got.rgb[2][2], 0.52);
    assert_eq!(got.id_counts, BTreeMap::from([(1, 1), (2, 1)]));

    // The same frame through files and compose_frame, read back: the same samples.
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, planes: &[Vec<f32>; 3]| {
        let path = dir.path().join(name);
        write_float_pass(&path, 3, 1, planes.clone());
        path
    };
    let m_path = dir.path().join("m.png");
    glassdb_mask::write_mask(&m_path, &frame.mask, glassdb_mask::MaskFormat::Png8).unwrap();
    let job = ComposeJob {
        inputs: FrameFiles {
            refl: vec![
                write("r0.exr", &frame.refl[0]),
                write("r1.exr", &frame.refl[1]),
            ],
            groups: Vec::new(),
            trans: write("t.exr", &frame.trans),
            mask: m_path,
        },
        output: dir.path().join("o.exr"),
    };
    compose_frame(&job, &settings, &luts).unwrap();
    let written = glassdb_pass::read_pass(&job.output, &PassReadOptions::default()).unwrap();
    assert_eq!(written.image.rgb, got.rgb);
}

#[test]
fn a_frame_in_memory_is_checked_as_files_are() {
    let basis = glassdb_registry::ColourBasis::Space(glassdb_colour::RgbSpace::Srgb);
    let luts = RegistryLuts::single(basis, test_lut());
    let (mut frame, settings) = in_memory_frame();
    frame.mask.id[2] = 9;
    let err = compose_in_memory(frame, &settings, &luts, &labels()).unwrap_err();
    assert!(matches!(err, ComposeError::UnknownIds { ref mask, .. } if mask == Path::new("mask")));
    let (mut frame, settings) = in_memory_frame();
    frame.refl.pop();
    let err = compose_in_memory(frame, &settings, &luts, &labels()).unwrap_err();
    assert!(
        matches!(err, ComposeError::PlaneWithoutPass { plane: 1, .. }),
        "{err}"
    );
    let (mut frame, settings) = in_memory_frame();
    frame.trans[1].pop();
    let err = compose_in_memory(frame, &settings, &luts, &labels()).unwrap_err();
    assert_eq!(err.kind(), glassdb_io::ErrorKind::Internal, "{err}");
}

#[test]
fn interleaved_samples_round_trip_through_planes() {
    let samples: Vec<f32> = (0..4 * 40_000).map(|i| i as f32).collect();
    let (rgb, alpha) = planes_from_interleaved(&samples, 4);
    assert_eq!(rgb[1][2], 9.0);
    assert_eq!(alpha.as_ref().unwrap()[2], 11.0);
    assert_eq!(interleave(&rgb, alpha.as_deref()), samples);
    let (rgb, alpha) = planes_from_interleaved(&samples[..3 * 40_000], 3);
    assert!(alpha.is_none());
    assert_eq!(interleave(&rgb, None), samples[..3 * 40_000]);
}
