//! The relit swap's factors against the registry evaluated by hand, and its composite against
//! the sum of each part's own composite (linearity).

use std::path::{Path, PathBuf};

use glassdb_image::{ExrPlane, ExrStorage, ExrWriteOptions};
use glassdb_mask::{CosTheta, MaskImage};
use glassdb_pass::PassReadOptions;
use proptest::prelude::*;

use super::*;
use crate::light_parts::{Aperture, LIGHT_PARTS_FORMAT};

/// The bundled registry and the id of its first glass.
fn registry() -> (Registry, u16) {
    let reg = glassdb_registry::default_registry().unwrap();
    let id = reg.default_table().glasses[0].id;
    (reg, id)
}

fn part(group: &str, source: LightSource, through: Option<(usize, [f64; 3], u16)>) -> LightPart {
    LightPart {
        group: group.into(),
        source,
        through: through.map(|(plane, normal, id)| Aperture {
            plane,
            normal,
            id: u32::from(id),
        }),
        light: None,
    }
}

/// `2∫₀¹ t(μ) μ dμ` by the midpoint rule on the registry's own evaluation.
fn t_dif_by_hand(g: &glassdb_registry::GlassRecord) -> [f64; 3] {
    let n = 20_000;
    let mut out = [0.0; 3];
    for i in 0..n {
        let mu = (i as f64 + 0.5) / n as f64;
        let (_, t) = g.eval(Side::Front, mu);
        for c in 0..3 {
            out[c] += 2.0 * t[c] * mu / n as f64;
        }
    }
    out
}

#[test]
fn factors_are_the_registry_at_the_suns_angle_and_its_hemispherical_value() {
    let (reg, id) = registry();
    let table = reg.default_table();
    let g = table.glass(id).unwrap();
    let lut = GlassLut::from_table(table);
    let glass = ApertureGlass {
        lut: &lut,
        table: Some(table),
        registry: "bundled",
    };
    let wall = [0.0, -1.0, 0.0];
    let parts = [
        part("interior", LightSource::Other, None),
        part(
            "sun_p0",
            LightSource::Sun {
                direction_to_sun: [0.3, -1.0, 0.8],
            },
            Some((0, wall, id)),
        ),
        // the sun behind the plane: seen from the back, straight on
        part(
            "sun_p1",
            LightSource::Sun {
                direction_to_sun: [0.0, 2.0, 0.0],
            },
            Some((1, wall, id)),
        ),
        part("sky_p0", LightSource::Sky, Some((0, wall, id))),
    ];
    let refs: Vec<&LightPart> = parts.iter().collect();
    let f = part_factors(&refs, 2, Path::new("m.exr"), &glass).unwrap();
    assert_eq!(f[0].factor, [1.0; 3]);
    assert_eq!(f[0].kind, FactorKind::Unglazed);
    // n·d = 1 / |(0.3, −1, 0.8)| = 1/√1.73, the front
    let cos = 1.0 / 1.73f64.sqrt();
    let (_, t) = g.eval(Side::Front, cos);
    let (_, t_back) = g.eval(Side::Back, 1.0);
    let t_hemi = t_dif_by_hand(g);
    for c in 0..3 {
        assert!(
            (f64::from(f[1].factor[c]) - t[c]).abs() < 2e-6,
            "{f:?} {t:?}"
        );
        assert!((f64::from(f[2].factor[c]) - t_back[c]).abs() < 2e-6);
        assert!((f64::from(f[3].factor[c]) - t_hemi[c]).abs() < 2e-6);
        assert!(f[3].factor[c] < f[1].factor[c] + 0.2 && f[3].factor[c] > 0.0);
    }
    match f[1].kind {
        FactorKind::Sun {
            cos_theta, side, ..
        } => {
            assert!((cos_theta - cos).abs() < 1e-12);
            assert_eq!(side, Side::Front);
        }
        ref k => panic!("{k:?}"),
    }
    assert!(matches!(
        f[2].kind,
        FactorKind::Sun {
            side: Side::Back,
            ..
        }
    ));

    // an aperture on a plane the mask has not, a glass the registry has not
    let far = part("sky_p5", LightSource::Sky, Some((5, wall, id)));
    let e = part_factors(&[&far], 2, Path::new("m.exr"), &glass).unwrap_err();
    assert!(
        matches!(
            e,
            ComposeError::AperturePlaneNotInMask {
                plane: 5,
                planes: 2,
                ..
            }
        ),
        "{e}"
    );
    let unknown = part("sky_p0", LightSource::Sky, Some((0, wall, 60_000)));
    let e = part_factors(&[&unknown], 2, Path::new("m.exr"), &glass).unwrap_err();
    assert!(e.to_string().contains("glass id 60000"), "{e}");
    let huge = LightPart {
        through: Some(Aperture {
            plane: 0,
            normal: wall,
            id: 70_000,
        }),
        ..unknown
    };
    assert!(part_factors(&[&huge], 2, Path::new("m.exr"), &glass).is_err());
}

#[test]
fn a_table_without_records_integrates_its_lookup_table() {
    // t = 0.8·μ: t_dif = 2∫ 0.8 μ² dμ = 0.8·2/3
    let lut = GlassLut::from_fn(
        &[4],
        |_, _, c| ([0.0; 3], [0.8 * c; 3]),
        |_, _| ([0.0; 3], [0.8; 3]),
    );
    let glass = ApertureGlass {
        lut: &lut,
        table: None,
        registry: "test",
    };
    let sky = part("sky", LightSource::Sky, Some((0, [0.0, 0.0, 1.0], 4)));
    let f = part_factors(&[&sky], 1, Path::new("m"), &glass).unwrap();
    assert!(
        (f64::from(f[0].factor[0]) - 0.8 * 2.0 / 3.0).abs() < 1e-6,
        "{f:?}"
    );
}

/// The groups of the synthetic frame: an interior lamp, the sun and the sky through glass.
const GROUPS: [&str; 3] = ["interior", "sun_p0_id", "sky_p0_id"];

fn parts_of(id: u16) -> LightParts {
    let wall = [0.0, 0.0, 1.0];
    LightParts {
        format: LIGHT_PARTS_FORMAT.into(),
        parts: vec![
            part(GROUPS[0], LightSource::Other, None),
            part(
                GROUPS[1],
                LightSource::Sun {
                    direction_to_sun: [0.5, 0.2, 0.7],
                },
                Some((0, wall, id)),
            ),
            part(GROUPS[2], LightSource::Sky, Some((0, wall, id))),
        ],
    }
}

/// Writes a float EXR of `w × h` with one `ViewLayer.Combined_<group>` layer per group, plane
/// values from `values[g][c]`.
fn write_groups(path: &Path, w: usize, h: usize, groups: &[&str], values: &[[Vec<f32>; 3]]) {
    let mut planes = Vec::new();
    for (g, rgb) in groups.iter().zip(values) {
        for (c, name) in ["R", "G", "B"].iter().enumerate() {
            planes.push(ExrPlane::new(
                &format!("ViewLayer.Combined_{g}.{name}"),
                rgb[c].clone(),
            ));
        }
    }
    let options = ExrWriteOptions {
        storage: ExrStorage::Float,
        compression: glassdb_encode::DEFAULT_EXR_COMPRESSION,
        zip_level: None,
    };
    let file = std::fs::File::create(path).unwrap();
    glassdb_image::write_exr_planes(file, w, h, planes, options).unwrap();
}

struct Frame {
    _dir: tempfile::TempDir,
    job: ComposeJob,
    dir: PathBuf,
}

/// A 4×3 frame: transmission and reflection passes split into [`GROUPS`], and a mask with
/// glass `id` on half its pixels at the given 8-bit cos θ codes.
fn frame(id: u16, trans: &[f32], refl: &[f32], codes: &[u8]) -> Frame {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().to_path_buf();
    let split = |v: &[f32]| -> Vec<[Vec<f32>; 3]> {
        (0..3)
            .map(|g| std::array::from_fn(|c| v[(g * 3 + c) * 12..(g * 3 + c + 1) * 12].to_vec()))
            .collect()
    };
    write_groups(&p.join("t.exr"), 4, 3, &GROUPS, &split(trans));
    write_groups(&p.join("r.exr"), 4, 3, &GROUPS, &split(refl));
    let m = MaskImage {
        width: 4,
        height: 3,
        id: (0..12).map(|i| if i % 2 == 0 { id } else { 0 }).collect(),
        cos_theta: CosTheta::Quantized8(codes.to_vec()),
        plane: vec![0; 12],
        coverage: None,
    };
    glassdb_mask::write_mask(&p.join("m.png"), &m, glassdb_mask::MaskFormat::Png8).unwrap();
    let job = ComposeJob {
        inputs: FrameFiles::new(vec![p.join("r.exr")], p.join("t.exr"), p.join("m.png")),
        output: p.join("relit.exr"),
    };
    Frame {
        _dir: dir,
        job,
        dir: p,
    }
}

fn read_rgb(path: &Path, layer: Option<String>) -> [Vec<f32>; 3] {
    let opts = PassReadOptions {
        layer,
        ..PassReadOptions::default()
    };
    glassdb_pass::read_pass(path, &opts).unwrap().image.rgb
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, rng_seed: proptest::test_runner::RngSeed::Fixed(28), failure_persistence: None, ..ProptestConfig::default() })]

    /// The relit frame is `Σ_p f_p · (composite of part p alone)`, each part composited from
    /// its own layer by the plain compositor.
    #[test]
    fn the_relit_frame_is_the_factor_weighted_sum_of_each_parts_composite(
        trans in proptest::collection::vec(0f32..4.0, 9 * 12),
        refl in proptest::collection::vec(0f32..4.0, 9 * 12),
        codes in proptest::collection::vec(1u8..=255, 12),
    ) {
        let (reg, id) = registry();
        let f = frame(id, &trans, &refl, &codes);
        let tables = PartTables::new(&reg, "bundled");
        let parts = parts_of(id);
        let settings = ComposeSettings::default();
        let report = compose_light_parts(&f.job, &settings, &tables, &parts, "test", &glassdb_io::NoProgress).unwrap();
        prop_assert_eq!(report.factors.len(), 3);
        let relit = read_rgb(&f.job.output, None);
        let luts = RegistryLuts::new(&reg);
        let mut want = [vec![0f64; 12], vec![0f64; 12], vec![0f64; 12]];
        for (g, factor) in GROUPS.iter().zip(&report.factors) {
            prop_assert_eq!(&factor.group, g);
            let mut one = settings.clone();
            let layer = Some(format!("ViewLayer.Combined_{g}"));
            one.decode.layers = InputLayers { trans: layer.clone(), refl: vec![layer.clone()] };
            let job = ComposeJob { output: f.dir.join(format!("{g}.exr")), ..f.job.clone() };
            crate::compose_frame(&job, &one, &luts).unwrap();
            let part = read_rgb(&job.output, layer);
            for c in 0..3 {
                for i in 0..12 {
                    want[c][i] += f64::from(factor.factor[c]) * f64::from(part[c][i]);
                }
            }
        }
        for c in 0..3 {
            for i in 0..12 {
                let (got, w) = (f64::from(relit[c][i]), want[c][i]);
                prop_assert!((got - w).abs() <= 1e-5 * (1.0 + w.abs()), "channel {c} pixel {i}: {got} vs {w}");
            }
        }
    }
}

#[test]
fn layers_and_parts_must_match() {
    let (reg, id) = registry();
    let values = vec![0.5f32; 9 * 12];
    let f = frame(id, &values, &values, &[200; 12]);
    let tables = PartTables::new(&reg, "bundled");
    let settings = ComposeSettings::default();
    let run = |parts: &LightParts| {
        compose_light_parts(
            &f.job,
            &settings,
            &tables,
            parts,
            "lp.json",
            &glassdb_io::NoProgress,
        )
    };
    // a part the passes do not have
    let mut more = parts_of(id);
    more.parts.push(part("lamp", LightSource::Other, None));
    let e = run(&more).unwrap_err();
    assert!(
        matches!(&e, ComposeError::PartWithoutLayer { group, .. } if group == "lamp"),
        "{e}"
    );
    // a layer no part names
    let mut fewer = parts_of(id);
    fewer.parts.remove(0);
    let e = run(&fewer).unwrap_err();
    assert!(
        matches!(&e, ComposeError::LayerWithoutPart { groups, .. } if groups == &["interior".to_string()]),
        "{e}"
    );
    // an aperture on a plane the mask has not
    let mut far = parts_of(id);
    far.parts[2].through.as_mut().unwrap().plane = 3;
    let e = run(&far).unwrap_err();
    assert!(
        matches!(e, ComposeError::AperturePlaneNotInMask { plane: 3, .. }),
        "{e}"
    );
    // a bad record
    let mut bad = parts_of(id);
    bad.format = "other".into();
    let e = run(&bad).unwrap_err();
    assert!(
        e.to_string().starts_with("light parts lp.json: format"),
        "{e}"
    );
    // a light the registry has no table for
    let mut lit = parts_of(id);
    lit.parts[0].light = Some("warm".into());
    let e = run(&lit).unwrap_err();
    assert!(matches!(e, ComposeError::NoTableForGroup { .. }), "{e}");
}
