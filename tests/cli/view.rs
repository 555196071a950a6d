//! `compose --view`: PNG output through a `.cube` LUT (a 1D shaper then a 3D table, in the
//! layout `ociobakelut --format resolve_cube --shapersize` writes), checked pixel by pixel
//! against OpenColorIO applying the same file (python_oracle/cube_oracle.py).

use glassdb_colour::CubeLut;
use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};

use crate::util::{compose, fails_naming, ok, read_png_planes, run_oracle, write_rgb};

const W: u32 = 16;
const H: u32 = 8;

/// A cube file as ociobakelut writes one with a shaper: comments, `LUT_1D_SIZE`,
/// `LUT_1D_INPUT_RANGE`, `LUT_3D_SIZE`, then the shaper rows, then the 3D rows (red fastest),
/// at 6 decimals. The shaper is a log-like curve over [-0.125, 12]; the 3D table mixes the
/// channels and tone-maps, so that trilinear interpolation, clamping and the domain mapping
/// all show.
fn lut_text() -> String {
    let (lo, hi) = (-0.125f64, 12.0f64);
    let shaper = 257;
    let n = 17;
    let mut s = String::from("# glassdb test view\n# shaper then cube\n\n");
    s += &format!("LUT_1D_SIZE {shaper}\nLUT_1D_INPUT_RANGE {lo:.6} {hi:.6}\nLUT_3D_SIZE {n}\n");
    for i in 0..shaper {
        let x = lo + (hi - lo) * i as f64 / (shaper - 1) as f64;
        let y = ((x - lo) * 4.0 + 1.0).ln() / ((hi - lo) * 4.0 + 1.0).ln();
        // Slightly different per channel.
        s += &format!("{:.6} {:.6} {:.6}\n", y, y.powf(1.05), y.powf(0.95));
    }
    for b in 0..n {
        for g in 0..n {
            for r in 0..n {
                let f = |i: usize| i as f64 / (n - 1) as f64;
                let (r, g, b) = (f(r), f(g), f(b));
                let mix = [
                    0.8 * r + 0.15 * g + 0.05 * b,
                    0.1 * r + 0.8 * g + 0.1 * b,
                    0.05 * r + 0.2 * g + 0.75 * b,
                ];
                let t = mix.map(|v| (v * v * (3.0 - 2.0 * v)).clamp(0.0, 1.0));
                s += &format!("{:.6} {:.6} {:.6}\n", t[0], t[1], t[2]);
            }
        }
    }
    s
}

/// Scene-linear values spanning 0–10, with a few outside the shaper's domain.
fn pixels() -> Vec<[f32; 3]> {
    let mut state = 0x2545_f491_u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        f64::from(state) / f64::from(u32::MAX)
    };
    (0..W * H)
        .map(|i| match i {
            0 => [0.0, 0.0, 0.0],
            1 => [10.0, 10.0, 10.0],
            2 => [-0.5, 13.0, 0.18],
            _ => [0; 3].map(|_| (10.0 * next().powi(3)) as f32),
        })
        .collect()
}

#[test]
fn cube_view_matches_opencolorio() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let lut_path = d.join("view.cube");
    std::fs::write(&lut_path, lut_text()).unwrap();
    let px = pixels();
    let trans = d.join("t.exr");
    let refl = d.join("r.exr");
    write_rgb(&trans, W, H, &px);
    write_rgb(&refl, W, H, &vec![[0.0; 3]; px.len()]);
    // No glass anywhere: the composite is the transmission pass.
    let mask = d.join("m.png");
    let n = (W * H) as usize;
    let m = MaskImage {
        width: W,
        height: H,
        id: vec![0; n],
        cos_theta: CosTheta::Quantized8(vec![255; n]),
        plane: vec![0; n],
        coverage: None,
    };
    write_mask(&mask, &m, MaskFormat::Png8).unwrap();
    let out = d.join("o.png");
    let mut c = compose();
    c.arg("--refl").arg(&refl).arg("--trans").arg(&trans);
    c.arg("--mask").arg(&mask).arg("-o").arg(&out);
    c.args(["--png-bits", "16", "--view"]).arg(&lut_path);
    ok(&mut c);

    let input = d.join("in.txt");
    let text: String = px
        .iter()
        .map(|p| format!("{:?} {:?} {:?}\n", p[0], p[1], p[2]))
        .collect();
    std::fs::write(&input, text).unwrap();
    let oracle = run_oracle("cube_oracle.py", &[lut_path.as_os_str(), input.as_os_str()]);
    let want: Vec<[f64; 3]> = oracle
        .lines()
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|w| w.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    assert_eq!(want.len(), n);

    // Before quantisation: the library's own evaluation against OCIO.
    let lut = CubeLut::read(&lut_path).unwrap();
    let mut max_float = 0f64;
    for (p, w) in px.iter().zip(&want) {
        let got = lut.apply(*p);
        for c in 0..3 {
            max_float = max_float.max((f64::from(got[c]) - w[c]).abs());
        }
    }
    // The PNG: every sample within 1e-4 of OCIO's value (clamped to [0, 1]) plus half a code.
    let planes = read_png_planes(&out);
    assert_eq!(planes.names, ["R", "G", "B"]);
    let tol = 1e-4 + 0.5 / 65535.0;
    let mut max_png = 0f64;
    for (i, w) in want.iter().enumerate() {
        for (c, &want_c) in w.iter().enumerate() {
            let got = planes.channels[c][i] / 65535.0;
            let diff = (got - want_c.clamp(0.0, 1.0)).abs();
            assert!(
                diff <= tol,
                "pixel {i} channel {c}: input {:?}, compose {got}, OCIO {}",
                px[i],
                want_c
            );
            max_png = max_png.max(diff);
        }
    }
    eprintln!("cube view vs OCIO: max |Δ| {max_float:.3e} in f32, {max_png:.3e} in the 16-bit PNG");
    assert!(max_float <= 1e-4, "{max_float}");

    // EXR output stays scene-linear: --view is refused with a hint.
    let mut c = compose();
    c.arg("--refl").arg(&refl).arg("--trans").arg(&trans);
    c.arg("--mask").arg(&mask).arg("-o").arg(d.join("o.exr"));
    c.arg("--view").arg(&lut_path);
    fails_naming(&mut c, &["--view", "o.exr", "scene-linear", ".png"]);

    // A broken LUT names its file and line.
    let bad = d.join("bad.cube");
    std::fs::write(&bad, "LUT_3D_SIZE 2\n0 0 0\n0 0\n").unwrap();
    let mut c = compose();
    c.arg("--refl").arg(&refl).arg("--trans").arg(&trans);
    c.arg("--mask").arg(&mask).arg("-o").arg(&out);
    c.arg("--view").arg(&bad);
    fails_naming(&mut c, &["bad.cube", "line 3"]);
}
