//! View transforms: how the scene-linear composite becomes the display-encoded values of a PNG
//! (docs/colour.md, "What a person sees").
//!
//! - [`ViewTransform::Standard`]: the sRGB transfer with clipping (IEC 61966-2-1), the default.
//! - [`ViewTransform::Lut`]: a `.cube` file ([`CubeLut`]), e.g. an AgX, Filmic or ACES view
//!   baked from an OCIO config with `ociobakelut --format resolve_cube`. Its output is taken as
//!   display-encoded values in 0–1 (no further transfer).
//!
//! The reader takes both `.cube` dialects OpenColorIO reads:
//! - Resolve: `LUT_1D_SIZE`, `LUT_3D_SIZE` (both: the 1D table, a per-channel "shaper", comes
//!   first in the file and is applied first), `LUT_1D_INPUT_RANGE min max`,
//!   `LUT_3D_INPUT_RANGE min max`;
//! - Adobe/Iridas: `TITLE "…"`, `DOMAIN_MIN r g b`, `DOMAIN_MAX r g b` (one table only);
//!
//! with `#` comment lines, keywords in any case, and the 3D table's rows with red varying
//! fastest. Evaluation follows what OCIO does with a `FileTransform` of such a file at its
//! default interpolation (`INTERP_DEFAULT`, FileFormatResolveCube.cpp / FileFormatIridasCube.cpp,
//! Lut1DOpData / Lut3DOpData `GetConcreteInterpolation`): each table's domain is first mapped
//! to [0, 1] (`x·s + o`, `s = 1/(max − min)`, `o = −min·s`), clamped to [0, 1], then the 1D
//! table is interpolated linearly per channel and the 3D table trilinearly (OCIO takes
//! tetrahedral only for `INTERP_TETRAHEDRAL`/`INTERP_BEST`). Arithmetic is `f32`, as OCIO's
//! CPU path is.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::ComposeError;

/// Largest 3D table edge (OCIO's own limit, so that every file read here OCIO reads too).
pub const MAX_CUBE_3D_SIZE: usize = 129;
/// Largest 1D table (OCIO's own limit).
pub const MAX_CUBE_1D_SIZE: usize = 300_000;
/// Largest `.cube` file read (a 129³ table at 6 decimals is about 60 MB).
pub const MAX_CUBE_FILE_BYTES: u64 = glassdb_io::limits::CUBE_LUT.bytes;

/// How the composite becomes the display-encoded values of a PNG.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum ViewTransform {
    /// sRGB transfer (IEC 61966-2-1), values outside [0, 1] clipped.
    #[default]
    Standard,
    /// A `.cube` look-up table (1D, 3D, or a 1D shaper then 3D); its output is display-encoded.
    Lut(Arc<CubeLut>),
}

impl ViewTransform {
    /// `standard` or the path of a `.cube` file.
    pub fn from_arg(arg: &str) -> Result<ViewTransform, ComposeError> {
        if arg == "standard" {
            Ok(ViewTransform::Standard)
        } else {
            Ok(ViewTransform::Lut(Arc::new(CubeLut::read(Path::new(arg))?)))
        }
    }

    /// A name for reports: `standard` or the LUT's file.
    pub fn describe(&self) -> String {
        match self {
            ViewTransform::Standard => "standard view: sRGB transfer, clipped".to_string(),
            ViewTransform::Lut(lut) => format!("view {}", lut.path.display()),
        }
    }
}

/// One table's input domain, per channel.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Domain {
    min: [f32; 3],
    max: [f32; 3],
}

impl Domain {
    const UNIT: Domain = Domain {
        min: [0.0; 3],
        max: [1.0; 3],
    };

    /// `(scale, offset)` per channel mapping the domain to [0, 1], computed in f64 and rounded
    /// to f32 as OCIO's min/max matrix op is.
    fn scale_offset(&self) -> ([f32; 3], [f32; 3]) {
        let mut s = [1.0f32; 3];
        let mut o = [0.0f32; 3];
        for c in 0..3 {
            let scale = 1.0 / (f64::from(self.max[c]) - f64::from(self.min[c]));
            s[c] = scale as f32;
            o[c] = (-f64::from(self.min[c]) * scale) as f32;
        }
        (s, o)
    }
}

/// A per-channel 1D table of `len` entries over its domain.
#[derive(Debug, Clone, PartialEq)]
struct Table1d {
    scale: [f32; 3],
    offset: [f32; 3],
    /// Interleaved R, G, B.
    values: Vec<f32>,
}

/// A 3D table of `n³` RGB entries, red index fastest.
#[derive(Debug, Clone, PartialEq)]
struct Table3d {
    n: usize,
    scale: [f32; 3],
    offset: [f32; 3],
    /// Interleaved R, G, B at `r + n·g + n²·b`.
    values: Vec<f32>,
}

/// One table of a `.cube` file as [`CubeLut::apply`] reads it.
#[derive(Debug, Clone, Copy)]
pub struct CubeTable<'a> {
    /// Entries of a 1D table; edge of a 3D table.
    pub size: usize,
    /// Per channel, `x·scale + offset` maps the table's domain to [0, 1].
    pub scale: [f32; 3],
    pub offset: [f32; 3],
    /// The entries, interleaved R, G, B.
    pub values: &'a [f32],
}

/// A parsed `.cube` file.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeLut {
    /// The file it was read from (reports).
    pub path: PathBuf,
    /// Its `TITLE`, if any.
    pub title: Option<String>,
    shaper: Option<Table1d>,
    cube: Option<Table3d>,
}

/// Maps `x` (already scaled to the table's unit domain) to a fractional index in `[0, last]`;
/// NaN maps to 0.
#[inline]
fn index(x: f32, last: f32) -> f32 {
    let v = x * last;
    if v.is_nan() { 0.0 } else { v.clamp(0.0, last) }
}

impl CubeLut {
    /// Reads and parses a `.cube` file, refusing one over [`MAX_CUBE_FILE_BYTES`] before
    /// reading it.
    pub fn read(path: &Path) -> Result<CubeLut, ComposeError> {
        let read_err = |cause| ComposeError::Read {
            path: path.to_path_buf(),
            cause,
        };
        let text =
            glassdb_io::read_input_string(path, glassdb_io::limits::CUBE_LUT).map_err(|cause| {
                match cause {
                    glassdb_io::InputError::TooLarge { size, .. } => ComposeError::CubeTooLarge {
                        path: path.to_path_buf(),
                        bytes: size.unwrap_or(MAX_CUBE_FILE_BYTES + 1),
                        max: MAX_CUBE_FILE_BYTES,
                    },
                    cause => read_err(cause),
                }
            })?;
        CubeLut::parse(&text, path)
    }

    /// Parses the text of a `.cube` file; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<CubeLut, ComposeError> {
        let syntax = |line: usize, text: &str, problem: String| ComposeError::CubeSyntax {
            path: path.to_path_buf(),
            line,
            text: text.chars().take(80).collect(),
            problem,
        };
        let mut title = None;
        let mut size1: Option<usize> = None;
        let mut size3: Option<usize> = None;
        let mut range1: Option<(f32, f32)> = None;
        let mut range3: Option<(f32, f32)> = None;
        let mut dmin: Option<[f32; 3]> = None;
        let mut dmax: Option<[f32; 3]> = None;
        let mut rows1: Vec<f32> = Vec::new();
        let mut rows3: Vec<f32> = Vec::new();
        let mut data_started = false;
        let mut last_line = 0;
        for (k, raw) in text.lines().enumerate() {
            let line_no = k + 1;
            last_line = line_no;
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let mut words = line.split_whitespace();
            let first = words.next().unwrap_or("");
            let keyword = first.to_ascii_uppercase();
            let starts_number = first
                .chars()
                .next()
                .is_some_and(|c| c.is_ascii_digit() || matches!(c, '-' | '+' | '.'));
            if !starts_number {
                if data_started {
                    return Err(syntax(
                        line_no,
                        line,
                        format!("{keyword} after the table's first row: keywords come first"),
                    ));
                }
                let args: Vec<&str> = words.collect();
                let numbers = |n: usize| -> Result<Vec<f32>, ComposeError> {
                    let parsed: Option<Vec<f32>> = args
                        .iter()
                        .map(|a| a.parse::<f32>().ok().filter(|v| v.is_finite()))
                        .collect();
                    match parsed {
                        Some(v) if v.len() == n => Ok(v),
                        _ => Err(syntax(
                            line_no,
                            line,
                            format!("{keyword} takes {n} finite number(s)"),
                        )),
                    }
                };
                let size = |max: usize| -> Result<usize, ComposeError> {
                    match args.as_slice() {
                        [n] => match n.parse::<usize>() {
                            Ok(n) if (2..=max).contains(&n) => Ok(n),
                            _ => Err(syntax(
                                line_no,
                                line,
                                format!("{keyword} must be a whole number from 2 to {max}"),
                            )),
                        },
                        _ => Err(syntax(
                            line_no,
                            line,
                            format!("{keyword} takes one whole number"),
                        )),
                    }
                };
                let twice = || syntax(line_no, line, format!("{keyword} given twice"));
                match keyword.as_str() {
                    "TITLE" => {
                        if title.is_some() {
                            return Err(twice());
                        }
                        let rest = line[first.len()..].trim();
                        title = Some(rest.trim_matches('"').to_string());
                    }
                    "LUT_1D_SIZE" => {
                        if size1.is_some() {
                            return Err(twice());
                        }
                        size1 = Some(size(MAX_CUBE_1D_SIZE)?);
                    }
                    "LUT_3D_SIZE" => {
                        if size3.is_some() {
                            return Err(twice());
                        }
                        size3 = Some(size(MAX_CUBE_3D_SIZE)?);
                    }
                    "LUT_1D_INPUT_RANGE" | "LUT_3D_INPUT_RANGE" => {
                        let v = numbers(2)?;
                        if v[1] <= v[0] {
                            return Err(syntax(
                                line_no,
                                line,
                                format!("{keyword}: the maximum must exceed the minimum"),
                            ));
                        }
                        let slot = if keyword == "LUT_1D_INPUT_RANGE" {
                            &mut range1
                        } else {
                            &mut range3
                        };
                        if slot.is_some() {
                            return Err(twice());
                        }
                        *slot = Some((v[0], v[1]));
                    }
                    "DOMAIN_MIN" | "DOMAIN_MAX" => {
                        let v = numbers(3)?;
                        let slot = if keyword == "DOMAIN_MIN" {
                            &mut dmin
                        } else {
                            &mut dmax
                        };
                        if slot.is_some() {
                            return Err(twice());
                        }
                        *slot = Some([v[0], v[1], v[2]]);
                    }
                    "LUT_2D_SIZE" => {
                        return Err(syntax(
                            line_no,
                            line,
                            "2D tables are not supported".to_string(),
                        ));
                    }
                    _ => {
                        return Err(syntax(
                            line_no,
                            line,
                            format!(
                                "unknown keyword {keyword} (known: TITLE, LUT_1D_SIZE, LUT_3D_SIZE, LUT_1D_INPUT_RANGE, LUT_3D_INPUT_RANGE, DOMAIN_MIN, DOMAIN_MAX)"
                            ),
                        ));
                    }
                }
                continue;
            }
            // A row of the tables.
            if !data_started {
                data_started = true;
                if size1.is_none() && size3.is_none() {
                    return Err(syntax(
                        line_no,
                        line,
                        "table rows before LUT_1D_SIZE or LUT_3D_SIZE".to_string(),
                    ));
                }
                // Sizes are bounded above, so these reservations are too.
                rows1.reserve_exact(size1.unwrap_or(0) * 3);
                rows3.reserve_exact(size3.map_or(0, |n| n * n * n * 3));
            }
            let values: Option<Vec<f32>> = line
                .split_whitespace()
                .map(|w| w.parse::<f32>().ok().filter(|v| v.is_finite()))
                .collect();
            let Some(values) = values.filter(|v| v.len() == 3) else {
                return Err(syntax(
                    line_no,
                    line,
                    "a table row is three finite numbers (R G B)".to_string(),
                ));
            };
            let want1 = size1.unwrap_or(0) * 3;
            let want3 = size3.map_or(0, |n| n * n * n * 3);
            if rows1.len() < want1 {
                rows1.extend_from_slice(&values);
            } else if rows3.len() < want3 {
                rows3.extend_from_slice(&values);
            } else {
                return Err(syntax(
                    line_no,
                    line,
                    format!(
                        "more rows than the header declares ({})",
                        declared(size1, size3)
                    ),
                ));
            }
        }
        let want1 = size1.unwrap_or(0) * 3;
        let want3 = size3.map_or(0, |n| n * n * n * 3);
        if size1.is_none() && size3.is_none() {
            return Err(ComposeError::CubeInvalid {
                path: path.to_path_buf(),
                problem: "no LUT_1D_SIZE or LUT_3D_SIZE: not a .cube file".to_string(),
            });
        }
        if rows1.len() < want1 || rows3.len() < want3 {
            return Err(ComposeError::CubeInvalid {
                path: path.to_path_buf(),
                problem: format!(
                    "ends at line {last_line} after {} rows, but the header declares {}",
                    (rows1.len() + rows3.len()) / 3,
                    declared(size1, size3)
                ),
            });
        }
        let domain_tags = dmin.is_some() || dmax.is_some();
        if domain_tags && size1.is_some() && size3.is_some() {
            return Err(ComposeError::CubeInvalid {
                path: path.to_path_buf(),
                problem: "DOMAIN_MIN/DOMAIN_MAX with both a 1D and a 3D table: give each table's domain with LUT_1D_INPUT_RANGE and LUT_3D_INPUT_RANGE".to_string(),
            });
        }
        if domain_tags && (range1.is_some() || range3.is_some()) {
            return Err(ComposeError::CubeInvalid {
                path: path.to_path_buf(),
                problem: "both DOMAIN_MIN/DOMAIN_MAX and LUT_*_INPUT_RANGE: give the domain once"
                    .to_string(),
            });
        }
        let domain_from = |range: Option<(f32, f32)>| -> Result<Domain, ComposeError> {
            if domain_tags {
                let d = Domain {
                    min: dmin.unwrap_or(Domain::UNIT.min),
                    max: dmax.unwrap_or(Domain::UNIT.max),
                };
                if (0..3).any(|c| d.max[c] <= d.min[c]) {
                    return Err(ComposeError::CubeInvalid {
                        path: path.to_path_buf(),
                        problem: "DOMAIN_MAX must exceed DOMAIN_MIN in every channel".to_string(),
                    });
                }
                Ok(d)
            } else {
                Ok(range.map_or(Domain::UNIT, |(lo, hi)| Domain {
                    min: [lo; 3],
                    max: [hi; 3],
                }))
            }
        };
        let shaper = match size1 {
            Some(_) => {
                let (scale, offset) = domain_from(range1)?.scale_offset();
                Some(Table1d {
                    scale,
                    offset,
                    values: rows1,
                })
            }
            None => None,
        };
        let cube = match size3 {
            Some(n) => {
                let (scale, offset) = domain_from(range3)?.scale_offset();
                Some(Table3d {
                    n,
                    scale,
                    offset,
                    values: rows3,
                })
            }
            None => None,
        };
        Ok(CubeLut {
            path: path.to_path_buf(),
            title,
            shaper,
            cube,
        })
    }

    /// The 1D table, if any (the viewer's shader evaluates it as [`CubeLut::apply`]).
    pub fn shaper_table(&self) -> Option<CubeTable<'_>> {
        self.shaper.as_ref().map(|t| CubeTable {
            size: t.values.len() / 3,
            scale: t.scale,
            offset: t.offset,
            values: &t.values,
        })
    }

    /// The 3D table, if any: `size` is its edge n, `values` its n³ entries, red index fastest.
    pub fn cube_table(&self) -> Option<CubeTable<'_>> {
        self.cube.as_ref().map(|t| CubeTable {
            size: t.n,
            scale: t.scale,
            offset: t.offset,
            values: &t.values,
        })
    }

    /// Edge of the 3D table, if there is one.
    pub fn cube_size(&self) -> Option<usize> {
        self.cube.as_ref().map(|c| c.n)
    }

    /// Length of the 1D table (the shaper when there is a 3D table too), if there is one.
    pub fn shaper_size(&self) -> Option<usize> {
        self.shaper.as_ref().map(|s| s.values.len() / 3)
    }

    /// Applies the 1D table (if any) then the 3D table (if any) to one RGB triple.
    pub fn apply(&self, rgb: [f32; 3]) -> [f32; 3] {
        let mut v = rgb;
        if let Some(t) = &self.shaper {
            let len = t.values.len() / 3;
            let last = (len - 1) as f32;
            for (c, x) in v.iter_mut().enumerate() {
                let f = index(*x * t.scale[c] + t.offset[c], last);
                let lo = (f.floor() as usize).min(len - 1);
                let hi = (lo + 1).min(len - 1);
                let d = f - lo as f32;
                let a = t.values[lo * 3 + c];
                let b = t.values[hi * 3 + c];
                *x = a + d * (b - a);
            }
        }
        if let Some(t) = &self.cube {
            let n = t.n;
            let last = (n - 1) as f32;
            let mut lo = [0usize; 3];
            let mut hi = [0usize; 3];
            let mut d = [0f32; 3];
            for c in 0..3 {
                let f = index(v[c] * t.scale[c] + t.offset[c], last);
                lo[c] = (f.floor() as usize).min(n - 1);
                hi[c] = (lo[c] + 1).min(n - 1);
                d[c] = f - lo[c] as f32;
            }
            let at = |r: usize, g: usize, b: usize| (r + n * (g + n * b)) * 3;
            let mut out = [0f32; 3];
            for (c, o) in out.iter_mut().enumerate() {
                let p = |r, g, b| t.values[at(r, g, b) + c];
                let lerp = |a: f32, b: f32, f: f32| a + f * (b - a);
                let c00 = lerp(p(lo[0], lo[1], lo[2]), p(hi[0], lo[1], lo[2]), d[0]);
                let c10 = lerp(p(lo[0], hi[1], lo[2]), p(hi[0], hi[1], lo[2]), d[0]);
                let c01 = lerp(p(lo[0], lo[1], hi[2]), p(hi[0], lo[1], hi[2]), d[0]);
                let c11 = lerp(p(lo[0], hi[1], hi[2]), p(hi[0], hi[1], hi[2]), d[0]);
                let c0 = lerp(c00, c10, d[1]);
                let c1 = lerp(c01, c11, d[1]);
                *o = lerp(c0, c1, d[2]);
            }
            v = out;
        }
        v
    }
}

fn declared(size1: Option<usize>, size3: Option<usize>) -> String {
    match (size1, size3) {
        (Some(a), Some(n)) => format!("{a} 1D rows then {n}³ = {} 3D rows", n * n * n),
        (Some(a), None) => format!("{a} 1D rows"),
        (None, Some(n)) => format!("{n}³ = {} 3D rows", n * n * n),
        (None, None) => "no table".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<CubeLut, ComposeError> {
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
                (ComposeError::CubeSyntax { line: l, path, .. }, Some(want)) => {
                    assert_eq!(*l, want, "{text:?}: {err}");
                    assert_eq!(path, Path::new("t.cube"));
                }
                (ComposeError::CubeInvalid { .. }, None) => {}
                _ => panic!("{text:?}: {err:?}"),
            }
            assert!(err.to_string().contains("t.cube"), "{err}");
        }
    }
}
