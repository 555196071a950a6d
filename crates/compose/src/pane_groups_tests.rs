//! Units' pane groups (issue 27): the kernel against the registry's shares computed here in
//! f64, the one-group frame unchanged, and the frame's checks of group passes.

use std::num::NonZeroUsize;
use std::path::Path;

use glassdb_mask::{CosCode, CosTheta, MaskImage};
use glassdb_registry::GlassRecord;

use super::*;
use crate::colour::RegistryLuts;
use crate::kernel::{KernelInput, PlacedGroupRefl, PlacedRefl, compose_in_place};
use crate::lut::GlassLut;
use crate::tests::write_float_pass;

/// The bundled double clear unit (two pane groups) and a monolithic glass.
fn records() -> (GlassRecord, GlassRecord) {
    let reg = glassdb_registry::default_registry().unwrap();
    let table = reg.default_table();
    let unit = table
        .glasses
        .iter()
        .find(|g| g.unit.as_ref().is_some_and(|u| u.groups.len() == 2))
        .unwrap()
        .clone();
    let mono = table
        .glasses
        .iter()
        .find(|g| g.unit.is_none())
        .unwrap()
        .clone();
    (unit, mono)
}

/// Pixels: the unit from the front on plane 0, the monolithic glass on plane 0, the unit from
/// the back on plane 1, no glass.
fn frame_mask() -> MaskImage {
    MaskImage {
        width: 4,
        height: 1,
        id: vec![11, 2, 11, 0],
        cos_theta: CosTheta::Quantized8(vec![200, 200, 128, 0]),
        plane: vec![0, 0, 1, 0],
        coverage: None,
    }
}

fn lut() -> GlassLut {
    let (unit, mono) = records();
    GlassLut::from_records(&[(11, &unit), (2, &mono)])
}

/// Runs the kernel on `frame_mask` with plane passes `planes` and group-1 passes `groups`
/// (constant images), plane 1 seen from the back.
fn run(planes: [f32; 2], groups: Option<[f32; 2]>, limit: Option<usize>) -> [Vec<f32>; 3] {
    let m = frame_mask();
    let lut = lut();
    let constant = |v: f32| [vec![v; 4], vec![v * 0.5; 4], vec![v * 0.25; 4]];
    let plane_passes = planes.map(constant);
    let group_passes = groups.map(|g| g.map(constant));
    let frame = glassdb_image::PixelWindow::at_origin(4, 1);
    let sides = [Side::Front, Side::Back];
    let placed: Vec<PlacedRefl<'_>> = plane_passes
        .iter()
        .zip(sides)
        .map(|(p, side)| PlacedRefl {
            rgb: [&p[0], &p[1], &p[2]],
            window: frame,
            side,
        })
        .collect();
    let placed_groups: Vec<PlacedGroupRefl<'_>> = group_passes
        .iter()
        .flatten()
        .enumerate()
        .map(|(plane, p)| PlacedGroupRefl {
            plane,
            group: 1,
            rgb: [&p[0], &p[1], &p[2]],
            window: frame,
        })
        .collect();
    let mut out = [vec![1.0f32; 4], vec![2.0; 4], vec![4.0; 4]];
    let [a, b, c] = &mut out;
    let input = KernelInput::placed([a, b, c], &placed, &m, &lut, Default::default())
        .unwrap()
        .with_groups(&placed_groups, limit.and_then(NonZeroUsize::new))
        .unwrap();
    compose_in_place(input);
    out
}

#[test]
fn a_units_reflection_is_the_sum_of_its_groups_passes_weighted_by_their_shares() {
    let (unit, _) = records();
    let groups = &unit.unit.as_ref().unwrap().groups;
    let out = run([8.0, 16.0], Some([3.0, 5.0]), None);
    // Pixel 0 (front): the outer pane's pass 8, the inner's 3; pixel 2 (back): the inner pane
    // is met first (pass 16), the outer second (pass 5).
    for (pixel, side, code, first, second, order) in [
        (0, Side::Front, 200u8, 8.0, 3.0, [0, 1]),
        (2, Side::Back, 128, 16.0, 5.0, [1, 0]),
    ] {
        let cos = CosCode::decode8(code);
        let (r, t) = unit.eval(side, cos);
        let raw = order.map(|k| groups[k].eval(side, cos));
        for c in 0..3 {
            let scale = [1.0, 0.5, 0.25][c];
            let sum = raw[0][c] + raw[1][c];
            let s = raw.map(|v| v[c] * r[c] / sum);
            let trans = [1.0, 2.0, 4.0][c];
            let want = trans * t[c] + first * scale * s[0] + second * scale * s[1];
            let got = f64::from(out[c][pixel]);
            assert!(
                (got - want).abs() < 1e-5 * want,
                "pixel {pixel} channel {c}: {got} vs {want}"
            );
            // The deeper group is a real part of it: the ghost is not negligible.
            assert!(s[1] > 0.3 * s[0], "{s:?}");
        }
    }
}

#[test]
fn monolithic_glass_and_one_pass_per_plane_composite_as_before() {
    let before = run([8.0, 16.0], None, None);
    // The monolithic pixel (1) and the empty one (3) ignore the group passes, bit for bit.
    let with = run([8.0, 16.0], Some([3.0, 5.0]), None);
    for c in 0..3 {
        for p in [1, 3] {
            assert_eq!(with[c][p].to_bits(), before[c][p].to_bits());
        }
    }
    // Every group seeing the same image: the one-group composite (shares sum to r).
    let same = run([8.0, 16.0], Some([8.0, 16.0]), None);
    for c in 0..3 {
        for p in 0..4 {
            assert!((same[c][p] - before[c][p]).abs() <= 2e-6 * before[c][p].abs());
        }
    }
    // One group composited (`--surfaces 1`): exactly the one-group frame.
    let folded = run([8.0, 16.0], Some([3.0, 5.0]), Some(1));
    assert_eq!(folded, before);
}

/// Writes a 4 × 1 frame (mask, trans, plane passes) into `dir`; returns its files.
fn frame_files(dir: &Path) -> FrameFiles {
    let pass = |name: &str, v: f32| {
        let path = dir.join(name);
        write_float_pass(&path, 4, 1, [vec![v; 4], vec![v; 4], vec![v; 4]]);
        path
    };
    let m_path = dir.join("m.png");
    glassdb_mask::write_mask(&m_path, &frame_mask(), glassdb_mask::MaskFormat::Png8).unwrap();
    FrameFiles::new(
        vec![pass("refl_0.exr", 8.0), pass("refl_1.exr", 16.0)],
        pass("t.exr", 1.0),
        m_path,
    )
}

fn group(dir: &Path, plane: usize, g: usize, v: f32) -> GroupPassFile {
    let path = dir.join(format!("refl_{plane}_{g}.exr"));
    write_float_pass(&path, 4, 1, [vec![v; 4], vec![v; 4], vec![v; 4]]);
    GroupPassFile {
        plane,
        group: g,
        path,
        layer: None,
    }
}

#[test]
fn a_frame_needs_every_units_group_pass_unless_limited() {
    let dir = tempfile::tempdir().unwrap();
    let files = frame_files(dir.path());
    let luts = RegistryLuts::single(
        glassdb_registry::ColourBasis::Space(glassdb_colour::RgbSpace::Srgb),
        lut(),
    );
    let mut settings = ComposeSettings::default();
    settings.plane_sides.insert(1, Side::Back);
    let job = |inputs: FrameFiles| ComposeJob {
        inputs,
        output: dir.path().join("o.exr"),
    };
    // No group pass: an error naming the plane, the group, the unit and the file to give.
    let e = compose_frame(&job(files.clone()), &settings, &luts).unwrap_err();
    let message = e.to_string();
    assert!(
        matches!(
            e,
            ComposeError::GroupWithoutPass {
                plane: 0,
                group: 1,
                id: 11,
                groups: 2,
                pixels: 1,
                ..
            }
        ),
        "{message}"
    );
    assert!(
        message.contains("refl_0_1") && message.contains("plane0.group1"),
        "{message}"
    );
    // Plane 0's given, plane 1's not.
    let mut some = files.clone();
    some.groups.push(group(dir.path(), 0, 1, 3.0));
    let e = compose_frame(&job(some.clone()), &settings, &luts).unwrap_err();
    assert!(
        matches!(
            e,
            ComposeError::GroupWithoutPass {
                plane: 1,
                group: 1,
                ..
            }
        ),
        "{e}"
    );
    // One group: composited, and the report counts the folded pixels (the unit's two).
    let mut one = settings.clone();
    one.decode.max_groups = NonZeroUsize::new(1);
    let r = compose_frame(&job(files.clone()), &one, &luts).unwrap();
    assert_eq!((r.folded_pixels, r.group_passes), (2, 0));
    // Every group: composited, the same as the kernel gives.
    let mut all = some.clone();
    all.groups.push(group(dir.path(), 1, 1, 5.0));
    let r = compose_frame(&job(all.clone()), &settings, &luts).unwrap();
    assert_eq!((r.folded_pixels, r.group_passes), (0, 2));
    let out = glassdb_pass::read_pass(&dir.path().join("o.exr"), &Default::default()).unwrap();
    let kernel = run([8.0, 16.0], Some([3.0, 5.0]), None);
    assert!((out.image.rgb[0][0] - kernel[0][0]).abs() < 1e-6);
    assert!((out.image.rgb[0][2] - kernel[0][2]).abs() < 1e-6);
    // A group pass twice, on a plane without a pass, or numbered 0.
    let mut twice = all.clone();
    twice.groups.push(group(dir.path(), 0, 1, 3.0));
    let e = compose_frame(&job(twice), &settings, &luts).unwrap_err();
    assert!(
        matches!(
            e,
            ComposeError::GroupPassTwice {
                plane: 0,
                group: 1,
                ..
            }
        ),
        "{e}"
    );
    for (plane, g) in [(2, 1), (0, 0)] {
        let mut bad = all.clone();
        bad.groups.push(group(dir.path(), plane, g, 3.0));
        let e = compose_frame(&job(bad), &settings, &luts).unwrap_err();
        assert!(
            matches!(e, ComposeError::GroupPassWithoutPlane { .. }),
            "{e}"
        );
        assert_eq!(e.kind(), glassdb_io::ErrorKind::Invalid);
    }
}
