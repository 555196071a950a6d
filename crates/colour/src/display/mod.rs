//! Display views: how a scene-linear image becomes the display-encoded values of a PNG
//! (docs/colour.md, "What a person sees"). (`view` alone names the viewer, `glassdb view`.)
//!
//! - [`DisplayView::Standard`]: the sRGB transfer with clipping (IEC 61966-2-1), the default.
//! - [`DisplayView::Lut`]: a `.cube` file ([`CubeLut`]), e.g. an AgX, Filmic or ACES view
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

mod error;
mod parse;

pub use error::CubeError;

/// Largest 3D table edge (OCIO's own limit, so that every file read here OCIO reads too).
pub const MAX_CUBE_3D_SIZE: usize = 129;
/// Largest 1D table (OCIO's own limit).
pub const MAX_CUBE_1D_SIZE: usize = 300_000;
/// The largest `.cube` file read (a 129³ table at 6 decimals is about 60 MB).
pub const CUBE_FILE: glassdb_io::InputLimit = glassdb_io::InputLimit::mib(256, "a .cube LUT");
/// Largest `.cube` file read, in bytes ([`CUBE_FILE`]).
pub const MAX_CUBE_FILE_BYTES: u64 = CUBE_FILE.bytes;

/// How a scene-linear image becomes the display-encoded values of a PNG.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum DisplayView {
    /// sRGB transfer (IEC 61966-2-1), values outside [0, 1] clipped.
    #[default]
    Standard,
    /// A `.cube` look-up table (1D, 3D, or a 1D shaper then 3D); its output is display-encoded.
    Lut(Arc<CubeLut>),
}

impl DisplayView {
    /// `standard` or the path of a `.cube` file.
    pub fn from_arg(arg: &str) -> Result<DisplayView, CubeError> {
        if arg == "standard" {
            Ok(DisplayView::Standard)
        } else {
            Ok(DisplayView::Lut(Arc::new(CubeLut::read(Path::new(arg))?)))
        }
    }

    /// A name for reports: `standard` or the LUT's file.
    pub fn describe(&self) -> String {
        match self {
            DisplayView::Standard => "standard view: sRGB transfer, clipped".to_string(),
            DisplayView::Lut(lut) => format!("view {}", lut.path.display()),
        }
    }
}

/// One table's input domain, per channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Domain {
    pub(crate) min: [f32; 3],
    pub(crate) max: [f32; 3],
}

impl Domain {
    pub(crate) const UNIT: Domain = Domain {
        min: [0.0; 3],
        max: [1.0; 3],
    };

    /// `(scale, offset)` per channel mapping the domain to [0, 1], computed in f64 and rounded
    /// to f32 as OCIO's min/max matrix op is.
    pub(crate) fn scale_offset(&self) -> ([f32; 3], [f32; 3]) {
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

/// One table of a `.cube` file over its domain: a per-channel 1D table of `size` entries,
/// or a 3D table of `size³` RGB entries, red index fastest.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct DomainTable {
    pub(crate) size: usize,
    pub(crate) scale: [f32; 3],
    pub(crate) offset: [f32; 3],
    /// Interleaved R, G, B (at `r + n·g + n²·b` in a 3D table of edge n).
    pub(crate) values: Vec<f32>,
}

impl DomainTable {
    /// The table of `values` with `size` entries (1D) or edge `size` (3D) over `domain`.
    pub(crate) fn new(size: usize, domain: Domain, values: Vec<f32>) -> DomainTable {
        let (scale, offset) = domain.scale_offset();
        DomainTable {
            size,
            scale,
            offset,
            values,
        }
    }

    /// The table as [`CubeLut::apply`] and the viewer's shader read it.
    fn as_cube_table(&self) -> CubeTable<'_> {
        CubeTable {
            size: self.size,
            scale: self.scale,
            offset: self.offset,
            values: &self.values,
        }
    }
}

/// One table of a `.cube` file as [`CubeLut::apply`] reads it.
#[derive(Debug, Clone, Copy)]
pub struct CubeTable<'a> {
    /// Entries of a 1D table; edge of a 3D table.
    pub size: usize,
    /// Per channel, `x·scale + offset` maps the table's domain to [0, 1].
    pub scale: [f32; 3],
    /// Per channel, the offset of that map.
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
    pub(crate) shaper: Option<DomainTable>,
    pub(crate) cube: Option<DomainTable>,
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
    pub fn read(path: &Path) -> Result<CubeLut, CubeError> {
        let text = glassdb_io::read_input_string(path, CUBE_FILE).map_err(|cause| match cause {
            glassdb_io::InputError::TooLarge { size, .. } => CubeError::TooLarge {
                path: path.to_path_buf(),
                bytes: size.unwrap_or(MAX_CUBE_FILE_BYTES + 1),
                max: MAX_CUBE_FILE_BYTES,
            },
            cause => CubeError::Read {
                path: path.to_path_buf(),
                cause,
            },
        })?;
        CubeLut::parse(&text, path)
    }

    /// Parses the text of a `.cube` file; `path` names it in errors. Its phases: the keyword
    /// lines (sizes, domains, title), the table rows, then the tables built and checked
    /// against what the keywords declared.
    pub fn parse(text: &str, path: &Path) -> Result<CubeLut, CubeError> {
        parse::parse_cube(text, path)
    }

    /// The 1D table, if any (the viewer's shader evaluates it as [`CubeLut::apply`]).
    pub fn shaper_table(&self) -> Option<CubeTable<'_>> {
        self.shaper.as_ref().map(DomainTable::as_cube_table)
    }

    /// The 3D table, if any: `size` is its edge n, `values` its n³ entries, red index fastest.
    pub fn cube_table(&self) -> Option<CubeTable<'_>> {
        self.cube.as_ref().map(DomainTable::as_cube_table)
    }

    /// Edge of the 3D table, if there is one.
    pub fn cube_size(&self) -> Option<usize> {
        self.cube.as_ref().map(|c| c.size)
    }

    /// Length of the 1D table (the shaper when there is a 3D table too), if there is one.
    pub fn shaper_size(&self) -> Option<usize> {
        self.shaper.as_ref().map(|s| s.size)
    }

    /// Applies the 1D table (if any) then the 3D table (if any) to one RGB triple.
    pub fn apply(&self, rgb: [f32; 3]) -> [f32; 3] {
        let mut v = rgb;
        if let Some(t) = &self.shaper {
            let len = t.size;
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
            let n = t.size;
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

#[cfg(test)]
mod tests;
