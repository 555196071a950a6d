//! glassdb-colour: linear RGB working spaces: their primaries and whites, the XYZ→RGB matrices colour-science
//! holds for them, how files name them (OpenEXR `chromaticities`, the Color Interop Forum ids
//! Blender 5 writes as `colorInteropID`), and RGB→RGB conversion between them; and
//! [`display`]: the display views (the sRGB transfer, `.cube` LUTs) that turn scene-linear RGB
//! into a PNG's display-encoded values.

#![warn(missing_docs)]

pub mod display;

use std::str::FromStr;

pub use display::{CubeError, CubeLut, DisplayView};
pub use nalgebra::Matrix3;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Linear RGB working space of the renderer (colorimetric method). Each space's XYZ→RGB matrix
/// is colour-science 0.4.7's `RGB_COLOURSPACES[...].matrix_XYZ_to_RGB`; XYZ integrated under an
/// illuminant whose white differs from the space's white is first adapted with CAT02, as
/// colour's `XYZ_to_RGB` does by default (see glassdb-spectral's `rgb_matrix` and docs/spectral.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum RgbSpace {
    /// Linear ITU-R BT.709 / sRGB primaries, D65 white (IEC 61966-2-1 matrix, as colour's
    /// `sRGB` holds it). `rec709` is accepted as an alias on input; it is written `srgb`.
    #[serde(rename = "srgb", alias = "rec709")]
    Srgb,
    /// ITU-R BT.2020 primaries, D65 white.
    #[serde(rename = "rec2020")]
    Rec2020,
    /// ACEScg (AP1 primaries, ACES white ≈ D60).
    #[serde(rename = "acescg")]
    AcesCg,
    /// ACES2065-1 (AP0 primaries, ACES white ≈ D60; the SMPTE ST 2065-1 matrix).
    #[serde(rename = "aces2065-1")]
    Aces2065_1,
    /// Display P3 (P3 primaries, D65 white).
    #[serde(rename = "display-p3")]
    DisplayP3,
    /// CIE XYZ itself (the identity; no white point, no adaptation).
    #[serde(rename = "xyz")]
    Xyz,
}

/// XYZ → linear RGB matrix of a working space, as colour-science 0.4.7 holds it
/// (`RGB_COLOURSPACES[...].matrix_XYZ_to_RGB`; the identity for [`RgbSpace::Xyz`]).
/// It expects XYZ relative to the space's own white ([`RgbSpace::whitepoint_xy`]).
pub fn xyz_to_rgb(space: RgbSpace) -> Matrix3<f64> {
    match space {
        // colour uses the IEC 61966-2-1 published (rounded) matrix for sRGB.
        RgbSpace::Srgb => Matrix3::new(
            3.2406, -1.5372, -0.4986, -0.9689, 1.8758, 0.0415, 0.0557, -0.2040, 1.0570,
        ),
        RgbSpace::Rec2020 => invert(normalised_primary_matrix(REC2020_PRIMARIES, D65_XY)),
        RgbSpace::AcesCg => invert(normalised_primary_matrix(AP1_PRIMARIES, ACES_XY)),
        // colour uses the published (10-decimal) XYZ→AP0 matrix of SMPTE ST 2065-1 / ACES
        // TB-2014-004, not the one derived from the primaries (they differ by 4e-11).
        RgbSpace::Aces2065_1 => Matrix3::new(
            1.0498110175,
            0.0,
            -0.0000974845,
            -0.4959030231,
            1.3733130458,
            0.0982400361,
            0.0,
            0.0,
            0.9912520182,
        ),
        RgbSpace::DisplayP3 => invert(normalised_primary_matrix(P3_PRIMARIES, D65_XY)),
        RgbSpace::Xyz => Matrix3::identity(),
    }
}

const REC2020_PRIMARIES: [f64; 6] = [0.708, 0.292, 0.170, 0.797, 0.131, 0.046];
const AP1_PRIMARIES: [f64; 6] = [0.713, 0.293, 0.165, 0.830, 0.128, 0.044];
const P3_PRIMARIES: [f64; 6] = [0.680, 0.320, 0.265, 0.690, 0.150, 0.060];
/// CIE 1931 xy of D65 as colour holds it (the white of sRGB, BT.2020 and Display P3).
pub const D65_XY: [f64; 2] = [0.3127, 0.3290];
/// CIE 1931 xy of the ACES white (≈ D60; ACES TB-2014-004).
pub const ACES_XY: [f64; 2] = [0.32168, 0.33767];

impl RgbSpace {
    /// The space's white point as CIE xy, as colour holds it; `None` for [`RgbSpace::Xyz`].
    pub fn whitepoint_xy(self) -> Option<[f64; 2]> {
        match self {
            RgbSpace::Srgb | RgbSpace::Rec2020 | RgbSpace::DisplayP3 => Some(D65_XY),
            RgbSpace::AcesCg | RgbSpace::Aces2065_1 => Some(ACES_XY),
            RgbSpace::Xyz => None,
        }
    }
}

/// Von Kries adaptation matrix in the CAT02 space from white `from_xy` to white `to_xy` (colour's
/// `matrix_chromatic_adaptation_VonKries(..., transform="CAT02")`, whites at Y = 1).
pub fn cat02(from_xy: [f64; 2], to_xy: [f64; 2]) -> Matrix3<f64> {
    let m = Matrix3::new(
        0.7328, 0.4296, -0.1624, -0.7036, 1.6975, 0.0061, 0.0030, 0.0136, 0.9834,
    );
    let xyz = |xy: [f64; 2]| Vector3::new(xy[0] / xy[1], 1.0, (1.0 - xy[0] - xy[1]) / xy[1]);
    let (from, to) = (m * xyz(from_xy), m * xyz(to_xy));
    invert(m) * Matrix3::from_diagonal(&to.component_div(&from)) * m
}

fn invert(m: Matrix3<f64>) -> Matrix3<f64> {
    // The primaries are constants with a well-conditioned matrix; identity is unreachable.
    m.try_inverse().unwrap_or_else(Matrix3::identity)
}

/// RGB → XYZ matrix from primaries' and white's chromaticities (colour's
/// `normalised_primary_matrix`, SMPTE RP 177).
pub fn normalised_primary_matrix(xy: [f64; 6], white: [f64; 2]) -> Matrix3<f64> {
    let p = Matrix3::new(
        xy[0],
        xy[2],
        xy[4],
        xy[1],
        xy[3],
        xy[5],
        1.0 - xy[0] - xy[1],
        1.0 - xy[2] - xy[3],
        1.0 - xy[4] - xy[5],
    );
    let w = Vector3::new(
        white[0] / white[1],
        1.0,
        (1.0 - white[0] - white[1]) / white[1],
    );
    let c = invert(p) * w;
    p * Matrix3::from_diagonal(&c)
}

impl RgbSpace {
    /// Every space, for help texts.
    pub const ALL: &'static [RgbSpace] = &[
        RgbSpace::Srgb,
        RgbSpace::Rec2020,
        RgbSpace::AcesCg,
        RgbSpace::Aces2065_1,
        RgbSpace::DisplayP3,
        RgbSpace::Xyz,
    ];
}

glassdb_io::enum_names!(RgbSpace {
    Srgb => "srgb" | "rec709", Rec2020 => "rec2020", AcesCg => "acescg", Aces2065_1 => "aces2065-1",
    DisplayP3 => "display-p3", Xyz => "xyz",
});

impl FromStr for RgbSpace {
    type Err = String;
    /// A [`RgbSpace::name`] or `rec709` (= `srgb`), any case.
    fn from_str(s: &str) -> Result<Self, String> {
        RgbSpace::from_name(s).ok_or_else(|| {
            let names: Vec<&str> = RgbSpace::ALL.iter().map(|r| r.name()).collect();
            format!("unknown value `{s}`; expected one of: {}", names.join(", "))
        })
    }
}

/// OpenEXR's `chromaticities` for CIE XYZ data (its ImfStandardAttributes convention).
const XYZ_CHROMATICITIES: [f64; 8] = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0 / 3.0, 1.0 / 3.0];

/// How far (in CIE xy) a file's `chromaticities` may lie from a space's and still name it:
/// writers round to 3–5 decimals, and the closest two spaces here (BT.2020 and AP1) differ
/// by 0.005 in red x.
pub const CHROMATICITIES_TOLERANCE: f64 = 1e-3;

impl RgbSpace {
    /// The primaries' CIE 1931 xy (red, green, blue), as the space's standard gives them;
    /// `None` for [`RgbSpace::Xyz`].
    pub fn primaries_xy(self) -> Option<[f64; 6]> {
        match self {
            RgbSpace::Srgb => Some([0.64, 0.33, 0.30, 0.60, 0.15, 0.06]),
            RgbSpace::Rec2020 => Some(REC2020_PRIMARIES),
            RgbSpace::AcesCg => Some(AP1_PRIMARIES),
            RgbSpace::Aces2065_1 => Some([0.7347, 0.2653, 0.0, 1.0, 0.0001, -0.0770]),
            RgbSpace::DisplayP3 => Some(P3_PRIMARIES),
            RgbSpace::Xyz => None,
        }
    }

    /// The space as OpenEXR's `chromaticities` attribute holds it: red, green, blue and white
    /// xy. CIE XYZ is written as OpenEXR specifies for XYZ data (primaries at the corners of
    /// the xy triangle, equal-energy white).
    pub fn chromaticities(self) -> [f64; 8] {
        match (self.primaries_xy(), self.whitepoint_xy()) {
            (Some(p), Some(w)) => [p[0], p[1], p[2], p[3], p[4], p[5], w[0], w[1]],
            _ => XYZ_CHROMATICITIES,
        }
    }

    /// The space whose [`RgbSpace::chromaticities`] lie within [`CHROMATICITIES_TOLERANCE`] of
    /// `c` in every coordinate; `None` when no space here matches.
    pub fn from_chromaticities(c: [f64; 8]) -> Option<RgbSpace> {
        RgbSpace::ALL.iter().copied().find(|s| {
            s.chromaticities()
                .iter()
                .zip(&c)
                .all(|(a, b)| (a - b).abs() <= CHROMATICITIES_TOLERANCE)
        })
    }

    /// The Color Interop Forum id of the space's scene-linear encoding, as Blender 5 writes it
    /// in an EXR part's `colorInteropID` (`lin_rec709_scene`, `lin_ap1_scene`, …).
    pub fn interop_id(self) -> &'static str {
        match self {
            RgbSpace::Srgb => "lin_rec709_scene",
            RgbSpace::Rec2020 => "lin_rec2020_scene",
            RgbSpace::AcesCg => "lin_ap1_scene",
            RgbSpace::Aces2065_1 => "lin_ap0_scene",
            RgbSpace::DisplayP3 => "lin_p3d65_scene",
            RgbSpace::Xyz => "lin_ciexyzd65_scene",
        }
    }

    /// The space a scene-linear Color Interop Forum id names ([`RgbSpace::interop_id`]);
    /// `None` for any other id (encoded, display-referred, `data`, or unknown).
    pub fn from_interop_id(id: &str) -> Option<RgbSpace> {
        RgbSpace::ALL
            .iter()
            .copied()
            .find(|s| s.interop_id().eq_ignore_ascii_case(id.trim()))
    }
}

/// Linear RGB of `from` → linear RGB of `to`: `xyz_to_rgb(to) · CAT02(white_from → white_to)
/// · xyz_to_rgb(from)⁻¹`, what colour-science 0.4.7's `RGB_to_RGB` does with its default
/// `chromatic_adaptation_transform="CAT02"`. No adaptation when the whites are equal or either
/// side is [`RgbSpace::Xyz`]; the identity when `from == to`.
pub fn rgb_to_rgb(from: RgbSpace, to: RgbSpace) -> Matrix3<f64> {
    if from == to {
        return Matrix3::identity();
    }
    let to_xyz = invert(xyz_to_rgb(from));
    let adapt = match (from.whitepoint_xy(), to.whitepoint_xy()) {
        (Some(a), Some(b)) if a != b => cat02(a, b),
        _ => Matrix3::identity(),
    };
    xyz_to_rgb(to) * adapt * to_xyz
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_space_is_found_from_its_own_tags_and_only_from_them() {
        for &s in RgbSpace::ALL {
            assert_eq!(RgbSpace::from_chromaticities(s.chromaticities()), Some(s));
            assert_eq!(RgbSpace::from_interop_id(s.interop_id()), Some(s));
            // Rounded to f32, as an EXR stores them.
            let c = s.chromaticities().map(|v| f64::from(v as f32));
            assert_eq!(RgbSpace::from_chromaticities(c), Some(s));
        }
        // BT.2020 red moved towards AP1's by 0.002: no longer BT.2020, not yet AP1.
        let mut c = RgbSpace::Rec2020.chromaticities();
        c[0] += 0.002;
        assert_eq!(RgbSpace::from_chromaticities(c), None);
        for id in [
            "data",
            "srgb_rec709_scene",
            "lin_rec709_display",
            "",
            "ACEScg",
        ] {
            assert_eq!(RgbSpace::from_interop_id(id), None, "{id}");
        }
    }

    #[test]
    fn rgb_to_rgb_round_trips_and_keeps_white_white() {
        for &a in RgbSpace::ALL {
            for &b in RgbSpace::ALL {
                let there_and_back = rgb_to_rgb(b, a) * rgb_to_rgb(a, b);
                assert!(
                    (there_and_back - Matrix3::identity()).abs().max() < 1e-12,
                    "{a} {b}"
                );
                if a != RgbSpace::Xyz && b != RgbSpace::Xyz {
                    // Chromatic adaptation maps one white to the other: (1, 1, 1) stays grey.
                    let w = rgb_to_rgb(a, b) * Vector3::new(1.0, 1.0, 1.0);
                    assert!(
                        (w - Vector3::new(1.0, 1.0, 1.0)).abs().max() < 2e-4,
                        "{a} {b} {w}"
                    );
                }
            }
        }
        assert_eq!(
            rgb_to_rgb(RgbSpace::AcesCg, RgbSpace::AcesCg),
            Matrix3::identity()
        );
    }
}
