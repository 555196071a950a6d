//! The `.cube` reader against hand-made tables.
use super::*;

fn parse(text: &str) -> Result<CubeLut, CubeError> {
    CubeLut::parse(text, Path::new("t.cube"))
}

/// An identity 3D table of edge `n`, red fastest.
fn identity3(n: usize) -> String {
    let mut s = format!("TITLE \"id\"\nLUT_3D_SIZE {n}\n");
    for b in 0..n {
        for g in 0..n {
            for r in 0..n {
                let f = |i: usize| i as f32 / (n - 1) as f32;
                s += &format!("{} {} {}\n", f(r), f(g), f(b));
            }
        }
    }
    s
}

#[test]
fn identity_cube_is_identity_inside_and_clamps_outside() {
    let lut = parse(&identity3(5)).unwrap();
    assert_eq!(lut.title.as_deref(), Some("id"));
    let v = lut.apply([0.1, 0.55, 0.9]);
    for (a, b) in v.iter().zip([0.1, 0.55, 0.9]) {
        assert!((a - b).abs() < 1e-6);
    }
    assert_eq!(lut.apply([-1.0, 2.0, f32::NAN]), [0.0, 1.0, 0.0]);
}

#[test]
fn red_varies_fastest() {
    // A 2³ table whose output is the row number: row 1 is (r=1, g=0, b=0).
    let mut s = "LUT_3D_SIZE 2\n".to_string();
    for i in 0..8 {
        s += &format!("{i} 0 0\n");
    }
    let lut = parse(&s).unwrap();
    assert_eq!(lut.apply([1.0, 0.0, 0.0])[0], 1.0);
    assert_eq!(lut.apply([0.0, 1.0, 0.0])[0], 2.0);
    assert_eq!(lut.apply([0.0, 0.0, 1.0])[0], 4.0);
    // Trilinear, not tetrahedral: the centre is the mean of the 8 corners.
    assert!((lut.apply([0.5, 0.5, 0.5])[0] - 3.5).abs() < 1e-6);
}

#[test]
fn shaper_then_cube_with_input_ranges() {
    // Shaper over [0, 4]: maps x to x/4 (then 3D identity).
    let mut s = "# comment\nLUT_1D_SIZE 3\nLUT_1D_INPUT_RANGE 0 4\nLUT_3D_SIZE 2\n".to_string();
    s += "0 0 0\n0.5 0.5 0.5\n1 1 1\n";
    for b in 0..2 {
        for g in 0..2 {
            for r in 0..2 {
                s += &format!("{r} {g} {b}\n");
            }
        }
    }
    let lut = parse(&s).unwrap();
    assert_eq!(lut.shaper_size(), Some(3));
    assert_eq!(lut.cube_size(), Some(2));
    let v = lut.apply([1.0, 3.0, 8.0]);
    assert!((v[0] - 0.25).abs() < 1e-6 && (v[1] - 0.75).abs() < 1e-6 && v[2] == 1.0);
}

#[test]
fn domain_min_max_scale_a_single_table() {
    let s = "DOMAIN_MIN -1 0 0\nDOMAIN_MAX 1 2 1\nLUT_1D_SIZE 2\n0 0 0\n1 1 1\n";
    let lut = parse(s).unwrap();
    let v = lut.apply([0.0, 1.0, 0.5]);
    assert!((v[0] - 0.5).abs() < 1e-6 && (v[1] - 0.5).abs() < 1e-6);
}

#[test]
fn errors_name_the_line() {
    let bad = [
        ("LUT_3D_SIZE 2\n0 0 0\n0 0 x\n", Some(3)),
        ("LUT_3D_SIZE 999\n", Some(1)),
        ("LUT_3D_SIZE 1\n", Some(1)),
        ("0 0 0\n", Some(1)),
        ("LUT_3D_SIZE 2\nLUT_3D_SIZE 2\n", Some(2)),
        ("FOO 1\n", Some(1)),
        ("LUT_2D_SIZE 4\n", Some(1)),
        ("LUT_1D_SIZE 2\n0 0 0\nLUT_3D_SIZE 2\n", Some(3)),
        ("LUT_1D_SIZE 2\n0 0 0\n1 1 1\n1 1 1\n", Some(4)),
        ("LUT_1D_SIZE 2\nLUT_1D_INPUT_RANGE 1 0\n", Some(2)),
        ("LUT_1D_SIZE 2\n0 0 0\n", None),
        ("TITLE \"x\"\n", None),
        ("", None),
        ("DOMAIN_MIN 0 0 0\nLUT_1D_SIZE 2\nLUT_3D_SIZE 2\n", None),
        ("LUT_1D_SIZE 2\n0 0 inf\n", Some(2)),
    ];
    for (text, line) in bad {
        let err = parse(text).unwrap_err();
        match (&err, line) {
            (CubeError::Syntax { line: l, path, .. }, Some(want)) => {
                assert_eq!(*l, want, "{text:?}: {err}");
                assert_eq!(path, Path::new("t.cube"));
            }
            (CubeError::Invalid { .. }, None) => {}
            _ => panic!("{text:?}: {err:?}"),
        }
        assert!(err.to_string().contains("t.cube"), "{err}");
    }
}
