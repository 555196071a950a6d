//! Unit tests of the integrators: flat spectra, matrices, settings JSON, names.
use super::*;
use glassdb_colour::{ACES_XY, normalised_primary_matrix};

/// D65's white for `observer`.
fn d65(observer: Observer) -> [f64; 2] {
    CieIlluminant::D65.white_xy(observer).unwrap()
}

fn flat(v: f64) -> (Vec<f64>, Vec<f64>) {
    let wl: Vec<f64> = (0..=53).map(|i| 300.0 + 10.0 * i as f64).collect();
    (wl.clone(), vec![v; wl.len()])
}

#[test]
fn a_flat_spectrum_gives_its_value_in_every_method() {
    let (wl, v) = flat(0.37);
    let mut methods: Vec<Method> = RgbCmf::ALL.iter().map(|&c| Method::Paper(c)).collect();
    let spd = Arc::new(
        crate::read_spd_bytes(b"wavelength_nm,power\n300,1\n450,3\n830,0.5\n", "lamp.csv").unwrap(),
    );
    let lights = CieIlluminant::ALL
        .iter()
        .map(|&c| Illuminant::Cie(c))
        .chain([Illuminant::Spd(spd)]);
    for illuminant in lights {
        for &observer in Observer::ALL {
            for &space in RgbSpace::ALL {
                for white_balance in [WhiteBalance::Light, WhiteBalance::Fixed(CieIlluminant::D65)]
                {
                    methods.push(Method::Colorimetric(ColorimetricSettings {
                        observer,
                        illuminant: illuminant.clone(),
                        space,
                        white_balance,
                    }));
                }
            }
        }
    }
    methods.push(Method::Luminous);
    for method in methods {
        let it = Integrator::new(&IntegrationSettings {
            method: method.clone(),
            extrapolate: false,
        })
        .unwrap();
        let rgb = it.channels(&wl, &v).unwrap();
        for c in rgb {
            assert!((c - 0.37).abs() < 1e-13, "{method:?}: {rgb:?}");
        }
    }
    assert!((luminous_iso9050(&wl, &v).unwrap() - 0.37).abs() < 1e-13);
    assert!((luminous(&wl, &v, LuminousGrid::OneNm, false).unwrap() - 0.37).abs() < 1e-13);
}

#[test]
fn srgb_of_d65_white_is_neutral_and_acescg_matrix_matches_the_aces_spec() {
    // The sRGB matrix maps D65 (0.3127, 0.3290) to nearly equal RGB.
    let m = xyz_to_rgb(RgbSpace::Srgb);
    let w = m * Vector3::new(0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290);
    assert!((w[0] - 1.0).abs() < 1e-3 && (w[1] - 1.0).abs() < 1e-3 && (w[2] - 1.0).abs() < 1e-3);
    // ACEScg XYZ→AP1 from the ACES TB-2014-004 (S-2014-004) specification, 10 decimals.
    let aces = xyz_to_rgb(RgbSpace::AcesCg);
    let spec = Matrix3::new(
        1.6410233797,
        -0.3248032942,
        -0.2364246952,
        -0.6636628587,
        1.6153315917,
        0.0167563477,
        0.0117218943,
        -0.0082844420,
        0.9883948585,
    );
    assert!((aces - spec).abs().max() < 1e-9);
}

#[test]
fn adaptation_is_cat02_to_the_space_white_and_identity_where_the_whites_agree() {
    // D65 spaces under 1931 D65, and XYZ under anything: no adaptation at all (bit-exact).
    for space in [RgbSpace::Srgb, RgbSpace::Rec2020, RgbSpace::DisplayP3] {
        assert_eq!(rgb_matrix(d65(Observer::Cie1931), space), xyz_to_rgb(space));
    }
    for &o in Observer::ALL {
        for &i in CieIlluminant::ALL {
            let white = i.white_xy(o).unwrap();
            assert_eq!(rgb_matrix(white, RgbSpace::Xyz), Matrix3::identity());
        }
    }
    // colour 0.4.7: XYZ_to_RGB(np.identity(3), "ACEScg", illuminant=D65) (columns are the
    // images of X, Y, Z), i.e. AP1 · CAT02(D65 → ACES).
    let colour = Matrix3::new(
        1.658854308471041,
        -0.31185697539741886,
        -0.24315600712571486,
        -0.6622832871075869,
        1.6121995708713222,
        0.01585912660306284,
        0.01148056645747657,
        -0.00923632492424387,
        0.91668651344913,
    );
    let ours = rgb_matrix(d65(Observer::Cie1931), RgbSpace::AcesCg);
    assert!((ours - colour).abs().max() < 1e-12, "{ours}");
    // The adapted D65 white lands on the ACES white, i.e. on equal AP1 channels.
    let d65 = Vector3::new(0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290);
    let w = ours * d65;
    assert!((w[0] - 1.0).abs() < 1e-12 && (w[1] - 1.0).abs() < 1e-12 && (w[2] - 1.0).abs() < 1e-12);
    // The AP0 matrix is the published ST 2065-1 one; it nearly inverts the primaries' NPM.
    let npm = normalised_primary_matrix([0.7347, 0.2653, 0.0, 1.0, 0.0001, -0.077], ACES_XY);
    assert!(
        (xyz_to_rgb(RgbSpace::Aces2065_1) * npm - Matrix3::identity())
            .abs()
            .max()
            < 1e-9
    );
}

#[test]
fn rec709_is_an_input_alias_of_srgb() {
    assert_eq!("rec709".parse::<RgbSpace>().unwrap(), RgbSpace::Srgb);
    assert_eq!("Rec709".parse::<RgbSpace>().unwrap(), RgbSpace::Srgb);
    let json: RgbSpace = serde_json::from_str(r#""rec709""#).unwrap();
    assert_eq!(json, RgbSpace::Srgb);
    assert_eq!(serde_json::to_string(&json).unwrap(), r#""srgb""#);
    let names: Vec<&str> = RgbSpace::ALL.iter().map(|s| s.name()).collect();
    assert_eq!(
        names,
        [
            "srgb",
            "rec2020",
            "acescg",
            "aces2065-1",
            "display-p3",
            "xyz"
        ]
    );
    for &s in RgbSpace::ALL {
        assert_eq!(s.name().parse::<RgbSpace>().unwrap(), s);
    }
}

#[test]
fn the_same_spectrum_gives_the_same_bits_whatever_came_before() {
    // Irregular data: the first call builds the kernel, later ones reuse it; evicting it
    // (more arrays than cache slots) and coming back rebuilds the same kernel.
    let mut wl: Vec<f64> = (0..40).map(|i| 300.0 + 5.0 * f64::from(i)).collect();
    wl.extend((0..60).map(|i| 500.0 + 7.0 * f64::from(i)));
    let v: Vec<f64> = wl.iter().map(|w| 0.5 + 0.4 * (w / 29.0).sin()).collect();
    let it = Integrator::new(&IntegrationSettings::default()).unwrap();
    let first = it.channels(&wl, &v).unwrap();
    assert_eq!(it.channels(&wl, &v).unwrap(), first);
    for k in 0..2 * KERNEL_CACHE_SLOTS {
        let other: Vec<f64> = wl.iter().map(|w| w + 0.1 * (k + 1) as f64).collect();
        it.channels(&other, &v).unwrap();
    }
    assert_eq!(it.channels(&wl, &v).unwrap(), first);
    // and the kernel is the direct spline evaluation to rounding
    let mut direct = [0.0f64; 3];
    for_each_on_grid(&wl, &v, false, it.grid_nm(), |j, x| {
        for (d, w) in direct.iter_mut().zip(&it.weights()[j]) {
            *d += x * w;
        }
    });
    for c in 0..3 {
        assert!((direct[c] - first[c]).abs() < 1e-13, "{direct:?} {first:?}");
    }
}

#[test]
fn settings_json_is_flat_and_round_trips() {
    let default = IntegrationSettings::default();
    let text = serde_json::to_string(&default).unwrap();
    assert_eq!(
        text,
        r#"{"method":"colorimetric","observer":"cie1931","illuminant":"D65","space":"srgb","extrapolate":false}"#
    );
    assert_eq!(
        serde_json::from_str::<IntegrationSettings>(&text).unwrap(),
        default
    );
    let paper = IntegrationSettings {
        method: Method::Paper(RgbCmf::StilesBurch1955),
        extrapolate: true,
    };
    let text = serde_json::to_string(&paper).unwrap();
    assert_eq!(
        text,
        r#"{"method":"paper","cmf":"stiles-burch-1955","extrapolate":true}"#
    );
    assert_eq!(
        serde_json::from_str::<IntegrationSettings>(&text).unwrap(),
        paper
    );
    // Absent options take their defaults; options of another method are refused.
    let lum: IntegrationSettings = serde_json::from_str(r#"{"method":"luminous"}"#).unwrap();
    assert_eq!(lum.method, Method::Luminous);
    assert!(!lum.extrapolate);
    let col: IntegrationSettings =
        serde_json::from_str(r#"{"method":"colorimetric","space":"acescg"}"#).unwrap();
    assert_eq!(
        col.method,
        Method::Colorimetric(ColorimetricSettings {
            observer: Observer::Cie1931,
            illuminant: Illuminant::default(),
            space: RgbSpace::AcesCg,
            white_balance: WhiteBalance::Light,
        })
    );
    for bad in [
        r#"{"method":"paper","space":"srgb"}"#,
        r#"{"method":"colorimetric","cmf":"stiles-burch-1955"}"#,
        r#"{"method":"luminous","observer":"cie1931"}"#,
        r#"{"method":"explicit"}"#,
    ] {
        assert!(
            serde_json::from_str::<IntegrationSettings>(bad).is_err(),
            "{bad}"
        );
    }
    for &k in MethodKind::ALL {
        assert_eq!(k.name().parse::<MethodKind>().unwrap(), k);
        assert_eq!(serde_json::to_string(&k).unwrap(), format!("\"{k}\""));
    }
}

/// Each value serialises to its name as a JSON string.
fn assert_json_names<T: Serialize>(values: &[T], name: impl Fn(&T) -> &'static str) {
    for value in values {
        assert_eq!(
            serde_json::to_string(value).unwrap(),
            format!("\"{}\"", name(value))
        );
    }
}

#[test]
fn names_round_trip() {
    for &c in RgbCmf::ALL {
        assert_eq!(c.name().parse::<RgbCmf>().unwrap(), c);
    }
    assert_json_names(RgbCmf::ALL, |c| c.name());
    assert_json_names(RgbSpace::ALL, |s| s.name());
    assert_json_names(Observer::ALL, |o| o.name());
    assert_json_names(CieIlluminant::ALL, |i| i.name());
    for &i in CieIlluminant::ALL {
        assert_eq!(i.name().parse::<CieIlluminant>().unwrap(), i);
    }
    assert_eq!("f2".parse::<CieIlluminant>().unwrap(), CieIlluminant::Fl2);
    assert_eq!(
        "led-b3".parse::<CieIlluminant>().unwrap(),
        CieIlluminant::LedB3
    );
    assert!("bogus".parse::<RgbSpace>().is_err());
}

/// A method's own JSON form (as opposed to [`IntegrationSettings`]' flat one) keeps the
/// colorimetric options as the fields of one `colorimetric` object.
#[test]
fn a_colorimetric_method_serialises_as_one_object_of_its_options() {
    let method = Method::Colorimetric(ColorimetricSettings {
        observer: Observer::Cie1964,
        illuminant: Illuminant::default(),
        space: RgbSpace::AcesCg,
        white_balance: WhiteBalance::Light,
    });
    let json = serde_json::to_value(&method).unwrap();
    let expected = serde_json::json!({"colorimetric": {
        "observer": "cie1964",
        "illuminant": Illuminant::default().name(),
        "space": "acescg",
        "white_balance": "light",
    }});
    assert_eq!(json, expected);
    assert_eq!(serde_json::from_value::<Method>(expected).unwrap(), method);
}
