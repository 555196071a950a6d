//! Glass masks: which pixels show glass, which glass (registration id), at what cos θ, on which
//! plane. Read by `glassdb registry build --mask` and by the compositor; written by
//! `glassdb mask`. The on-disk formats are documented in `docs/mask.md`:
//!
//! | format | id | cos θ | plane | coverage |
//! |---|---|---|---|---|
//! | 8-bit RGB PNG (the paper's packed mask, method.md "Mask") | G, 1–255 | B / 255 | R | – |
//! | 16-bit RGB PNG | G, 1–65535 | B / 65535 | R | – |
//! | EXR, float channels (names selectable) | `id` | `cos_theta` | `plane` (optional) | `coverage` (optional) |
//! | binary PNG (method.md, binary form), with [`MaskReadOptions::binary_glass_id`] | the given id where not black | 1 (normal incidence) | 0 | grey level |
//!
//! Id 0 means "no glass" everywhere. Decoding and encoding the files is glassdb-image's job;
//! this crate maps the formats' layouts to and from [`MaskImage`].

#![warn(missing_docs)]

mod aov;
mod channels;
mod cos_code;
mod cryptomatte;
mod error;
mod glass_names;
mod read;
mod write;

use std::collections::BTreeMap;

use rayon::prelude::*;

/// The largest Cryptomatte manifest side file (JSON) read.
pub const MANIFEST_FILE: glassdb_io::InputLimit =
    glassdb_io::InputLimit::mib(64, "a Cryptomatte manifest");

pub use channels::MaskHeader;
pub use cos_code::CosCode;
pub use cryptomatte::{
    AovWeighting, CosSource, CryptomatteLayer, CryptomatteOptions, PlaneSource, cryptomatte_layers,
    float_encoded, murmur3_32,
};
pub use error::MaskError;
pub use glass_names::{GlassMapping, GlassNames};
pub use glassdb_image::DEFAULT_MAX_PIXELS;
use glassdb_image::PixelWindow;
pub use read::{
    FloatMaskChannels, mask_from_floats, read_mask, read_mask_bytes, read_mask_header,
    read_placed_mask, read_placed_mask_bytes,
};
pub use write::{MaskFormat, write_mask, write_mask_bytes};

/// A decoded mask, row-major, row 0 at the top. All per-pixel vectors have `width * height`
/// entries.
#[derive(Debug, Clone, PartialEq)]
pub struct MaskImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Glass registration id per pixel; 0 means "no glass".
    pub id: Vec<u16>,
    /// cos θ per pixel (angle of incidence of the view ray on the glass), as stored.
    pub cos_theta: CosTheta,
    /// Glass plane index per pixel (selects the reflection pass); all 0 with one plane.
    pub plane: Vec<u16>,
    /// Fraction of the pixel covered by glass, when the mask carries it (antialiased edges).
    pub coverage: Option<Vec<f32>>,
}

/// A mask as read from a file: its pixels, where they lie in the frame, and whether the file
/// stores a plane per pixel (a mask without planes has every glass pixel on plane 0).
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedMask {
    /// The mask's pixels.
    pub image: MaskImage,
    /// Where they lie: the file's data and display windows.
    pub windows: glassdb_image::ImageWindows,
    /// Whether the file stores a plane per pixel.
    pub stores_planes: bool,
    /// Whether the file states its pixels' coordinates (EXR); a PNG holds a whole frame at
    /// (0, 0), wherever the frame of the passes lies.
    pub has_coordinates: bool,
}

/// Pixels per parallel task of the whole-mask scans.
const SCAN_CHUNK: usize = 1 << 16;

/// Smallest and largest of `value(v)` over the glass pixels (id ≠ 0), scanned in parallel;
/// NaN values are passed over, as `f64::min` and `f64::max` do.
fn glass_range<T: Sync>(
    ids: &[u16],
    values: &[T],
    value: impl Fn(&T) -> f64 + Sync,
) -> Option<(f64, f64)> {
    ids.par_chunks(SCAN_CHUNK)
        .zip(values.par_chunks(SCAN_CHUNK))
        .filter_map(|(ids, values)| {
            ids.iter()
                .zip(values)
                .filter(|(id, _)| **id != 0)
                .map(|(_, v)| value(v))
                .fold(None, |range, c| {
                    Some(range.map_or((c, c), |(lo, hi): (f64, f64)| (lo.min(c), hi.max(c))))
                })
        })
        .reduce_with(|(a_lo, a_hi), (b_lo, b_hi)| (a_lo.min(b_lo), a_hi.max(b_hi)))
}

impl MaskImage {
    /// The packed 8-bit mask (docs/mask.md): per pixel R = plane, G = id, B = the cos θ code
    /// ([`CosCode::encode8`]), `channels` samples per pixel (3, or 4 with an ignored alpha),
    /// row-major. The caller checks that `samples` holds `width × height` pixels.
    pub fn from_packed8(width: u32, height: u32, channels: usize, samples: &[u8]) -> MaskImage {
        let n = width as usize * height as usize;
        let mut id = Vec::with_capacity(n);
        let mut plane = Vec::with_capacity(n);
        let mut cos = Vec::with_capacity(n);
        for px in samples.chunks_exact(channels).take(n) {
            plane.push(u16::from(px[0]));
            id.push(u16::from(px[1]));
            cos.push(px[2]);
        }
        MaskImage {
            width,
            height,
            id,
            cos_theta: CosTheta::Quantized8(cos),
            plane,
            coverage: None,
        }
    }

    /// The mask over window `to` of the frame, from a mask holding window `from`: pixels of
    /// `to` outside `from` have no glass (id 0).
    pub fn placed(&self, from: &PixelWindow, to: &PixelWindow) -> MaskImage {
        use glassdb_image::place_plane;
        let (width, height) = (to.width as u32, to.height as u32);
        MaskImage {
            width,
            height,
            id: place_plane(&self.id, from, to, 0),
            cos_theta: match &self.cos_theta {
                CosTheta::Quantized8(c) => CosTheta::Quantized8(place_plane(c, from, to, 0)),
                CosTheta::Quantized16(c) => CosTheta::Quantized16(place_plane(c, from, to, 0)),
                CosTheta::Float(c) => CosTheta::Float(place_plane(c, from, to, 0.0)),
                CosTheta::Normal => CosTheta::Normal,
            },
            plane: place_plane(&self.plane, from, to, 0),
            coverage: self
                .coverage
                .as_ref()
                .map(|c| place_plane(c, from, to, 0.0)),
        }
    }
}

/// One plane's screen rectangle in a mask: inclusive pixel bounds as in an OpenEXR data window
/// (`x_min..=x_max`, `y_min..=y_max`, row 0 at the top) and the glass pixels inside.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlaneBounds {
    /// Leftmost glass column.
    pub x_min: i32,
    /// Topmost glass row.
    pub y_min: i32,
    /// Rightmost glass column.
    pub x_max: i32,
    /// Bottom glass row.
    pub y_max: i32,
    /// Glass pixels of the plane.
    pub glass_pixels: u64,
}

impl PlaneBounds {
    /// Grows the rectangle to hold `other` too, and adds its glass pixels.
    fn include(&mut self, other: &PlaneBounds) {
        self.x_min = self.x_min.min(other.x_min);
        self.y_min = self.y_min.min(other.y_min);
        self.x_max = self.x_max.max(other.x_max);
        self.y_max = self.y_max.max(other.y_max);
        self.glass_pixels += other.glass_pixels;
    }

    /// The rectangle as a [`PixelWindow`] (top-left pixel and size).
    pub fn window(&self) -> PixelWindow {
        PixelWindow {
            x: self.x_min,
            y: self.y_min,
            width: (self.x_max - self.x_min) as usize + 1,
            height: (self.y_max - self.y_min) as usize + 1,
        }
    }

    /// The rectangle as Blender's render border in a `width × height` frame:
    /// `[min_x, max_x, min_y, max_y]` (`render.border_min_x` …), fractions of the frame with y
    /// **up**. Blender takes `int(fraction · size)` for each edge, in float32
    /// (`render_init_from_main`), and an exact edge such as 13/22 can truncate one pixel short;
    /// so each edge is given half a pixel on, at the centre of the pixel that starts there,
    /// `(edge + 0.5) / size` (at most 1), which truncates to the edge whatever the rounding:
    /// columns `x_min..=x_max`, rows `y_min..=y_max` counted from the top, exactly.
    pub fn blender_border(&self, width: u32, height: u32) -> [f64; 4] {
        let frac = |edge: i64, size: u32| ((edge as f64 + 0.5) / f64::from(size)).clamp(0.0, 1.0);
        let (x_min, x_max) = (i64::from(self.x_min), i64::from(self.x_max));
        let (y_min, y_max) = (i64::from(self.y_min), i64::from(self.y_max));
        let h = i64::from(height);
        [
            frac(x_min, width),
            frac(x_max + 1, width),
            frac(h - 1 - y_max, height),
            frac(h - y_min, height),
        ]
    }
}

/// cos θ as the mask stores it: quantised codes ([`CosCode`]) are kept as codes so that
/// lookups into 256-entry tables stay exact.
#[derive(Debug, Clone, PartialEq)]
pub enum CosTheta {
    /// 8-bit: cos θ = code / 255 (the paper's packed mask).
    Quantized8(Vec<u8>),
    /// 16-bit: cos θ = code / 65535.
    Quantized16(Vec<u16>),
    /// Float: cos θ as given (EXR masks).
    Float(Vec<f32>),
    /// A binary mask carries no angle: every glass pixel is seen at normal incidence.
    Normal,
}

impl MaskImage {
    /// Number of pixels (`width * height`).
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Glass pixels per id (id 0, "no glass", is not counted). Used to list unknown ids with
    /// their pixel counts and by `glassdb registry build --mask`.
    pub fn id_pixel_counts(&self) -> BTreeMap<u16, u64> {
        let counts = self
            .id
            .par_chunks(SCAN_CHUNK)
            .fold(
                || vec![0u64; 1 << 16],
                |mut counts, ids| {
                    for &id in ids {
                        counts[usize::from(id)] += 1;
                    }
                    counts
                },
            )
            .reduce_with(|mut a, b| {
                a.iter_mut().zip(&b).for_each(|(a, b)| *a += b);
                a
            })
            .unwrap_or_default();
        counts
            .iter()
            .enumerate()
            .skip(1)
            .filter(|(_, n)| **n > 0)
            .map(|(id, n)| (id as u16, *n))
            .collect()
    }

    /// cos θ of pixel `index` as a number in [0, 1]: code/255, code/65535, the float value,
    /// or 1 for a binary mask. Returns NaN for an index outside the image.
    pub fn cos_theta_at(&self, index: usize) -> f64 {
        let v = match &self.cos_theta {
            CosTheta::Quantized8(c) => c.get(index).map(|&c| CosCode::decode8(c)),
            CosTheta::Quantized16(c) => c.get(index).map(|&c| CosCode::Bits16.decode(c)),
            CosTheta::Float(c) => c.get(index).map(|&c| f64::from(c)),
            CosTheta::Normal => (index < self.pixel_count()).then_some(1.0),
        };
        v.unwrap_or(f64::NAN)
    }

    /// Smallest and largest cos θ over glass pixels (id ≠ 0); `None` without glass.
    pub fn cos_theta_range(&self) -> Option<(f64, f64)> {
        match &self.cos_theta {
            CosTheta::Quantized8(c) => glass_range(&self.id, c, |&c| CosCode::decode8(c)),
            CosTheta::Quantized16(c) => glass_range(&self.id, c, |&c| CosCode::Bits16.decode(c)),
            CosTheta::Float(c) => glass_range(&self.id, c, |&c| f64::from(c)),
            CosTheta::Normal => self.id.iter().any(|&id| id != 0).then_some((1.0, 1.0)),
        }
    }

    /// Each plane's screen rectangle: the smallest window holding every glass pixel (id ≠ 0)
    /// of that plane, in the mask's pixel coordinates (row 0 at the top), with its glass pixel
    /// count. Planes without glass in view are absent. What a renderer's border (crop) region
    /// must cover for that plane's reflection pass (docs/scene.md, "Plane bounds").
    pub fn plane_bounds(&self) -> BTreeMap<u16, PlaneBounds> {
        self.plane_bounds_of(|_, _, _, _| true)
    }

    /// Each deeper pane group's screen rectangle, by `(plane, group)` for groups 1 and on
    /// (issue 27): the smallest window holding the glass pixels of that plane whose glass has
    /// more than `group` pane groups (`groups_of(id)`: 1 for a monolithic glass), i.e. where
    /// that group's reflection pass is composited. Group 0's rectangle is the plane's own
    /// ([`MaskImage::plane_bounds`]).
    pub fn group_bounds(
        &self,
        groups_of: impl Fn(u16) -> usize + Sync,
    ) -> BTreeMap<(u16, usize), PlaneBounds> {
        let most = self
            .id_pixel_counts()
            .keys()
            .map(|&id| groups_of(id))
            .max()
            .unwrap_or(1);
        let mut out = BTreeMap::new();
        for group in 1..most {
            let bounds = self.plane_bounds_of(|_, _, id, _| groups_of(id) > group);
            out.extend(bounds.into_iter().map(|(plane, b)| ((plane, group), b)));
        }
        out
    }

    /// [`MaskImage::plane_bounds`] of the glass pixels `(x, y, id, plane)` that `select` keeps
    /// (e.g. those outside their plane's pass). Rows are scanned in parallel.
    pub fn plane_bounds_of(
        &self,
        select: impl Fn(i32, i32, u16, u16) -> bool + Sync,
    ) -> BTreeMap<u16, PlaneBounds> {
        let width = self.width as usize;
        if width == 0 {
            return BTreeMap::new();
        }
        let rows_per_task = (SCAN_CHUNK / width).max(1);
        self.id
            .par_chunks(width * rows_per_task)
            .zip(self.plane.par_chunks(width * rows_per_task))
            .enumerate()
            .map(|(task, (ids, planes))| {
                let mut bounds: BTreeMap<u16, PlaneBounds> = BTreeMap::new();
                let rows = ids.chunks_exact(width).zip(planes.chunks_exact(width));
                for (row, (ids, planes)) in rows.enumerate() {
                    let y = (task * rows_per_task + row) as i32;
                    let kept =
                        |col: usize| ids[col] != 0 && select(col as i32, y, ids[col], planes[col]);
                    // Runs of one plane along the row: one map lookup per run.
                    let mut col = 0;
                    while col < width {
                        if !kept(col) {
                            col += 1;
                            continue;
                        }
                        let plane = planes[col];
                        let (start, mut last, mut glass) = (col, col, 0u64);
                        while col < width {
                            if kept(col) {
                                if planes[col] != plane {
                                    break;
                                }
                                glass += 1;
                                last = col;
                            }
                            col += 1;
                        }
                        let run = PlaneBounds {
                            x_min: start as i32,
                            y_min: y,
                            x_max: last as i32,
                            y_max: y,
                            glass_pixels: glass,
                        };
                        bounds
                            .entry(plane)
                            .and_modify(|b| b.include(&run))
                            .or_insert(run);
                    }
                }
                bounds
            })
            .reduce(BTreeMap::new, |mut a, b| {
                for (plane, run) in b {
                    a.entry(plane)
                        .and_modify(|b| b.include(&run))
                        .or_insert(run);
                }
                a
            })
    }

    /// Largest plane index over glass pixels (0 without glass).
    pub fn max_plane(&self) -> u16 {
        self.id
            .iter()
            .zip(&self.plane)
            .filter(|(id, _)| **id != 0)
            .map(|(_, p)| *p)
            .max()
            .unwrap_or(0)
    }

    /// Checks that every per-pixel vector has `width * height` entries.
    pub fn check_consistent(&self) -> Result<(), String> {
        let n = self.pixel_count();
        let len_cos = match &self.cos_theta {
            CosTheta::Quantized8(c) => Some(c.len()),
            CosTheta::Quantized16(c) => Some(c.len()),
            CosTheta::Float(c) => Some(c.len()),
            CosTheta::Normal => None,
        };
        let bad = |what: &str, len: usize| format!("{what} has {len} entries for {n} pixels");
        if self.id.len() != n {
            return Err(bad("id", self.id.len()));
        }
        if self.plane.len() != n {
            return Err(bad("plane", self.plane.len()));
        }
        if let Some(l) = len_cos.filter(|&l| l != n) {
            return Err(bad("cos_theta", l));
        }
        if let Some(c) = self.coverage.as_ref().filter(|c| c.len() != n) {
            return Err(bad("coverage", c.len()));
        }
        Ok(())
    }
}

/// Names of the EXR channels a mask is read from. Full channel names as stored in the file
/// (`ViewLayer.IndexMA`), or `layer.channel` for a named part of a multi-part file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExrMaskChannels {
    /// Glass id (float or uint, integral values 0–65535). Default `id`.
    pub id: String,
    /// cos θ in [0, 1]. Default `cos_theta`.
    pub cos_theta: String,
    /// Plane index (optional in the file; all 0 when absent). Default `plane`.
    pub plane: String,
    /// Pixel coverage in [0, 1] (optional in the file). Default `coverage`.
    pub coverage: String,
}

impl Default for ExrMaskChannels {
    fn default() -> Self {
        ExrMaskChannels {
            id: "id".into(),
            cos_theta: "cos_theta".into(),
            plane: "plane".into(),
            coverage: "coverage".into(),
        }
    }
}

/// How to read a mask file. The format (PNG or EXR) is detected from the file's bytes.
#[derive(Debug, Clone, PartialEq)]
pub struct MaskReadOptions {
    /// EXR channel names.
    pub exr_channels: ExrMaskChannels,
    /// Read a PNG as the paper's binary mask (section 5.1: white = glass, black = not), every
    /// glass pixel getting this id at normal incidence. `None`: the packed RGB formats.
    pub binary_glass_id: Option<u16>,
    /// Refuse images with more pixels than this (checked from the header before allocating).
    pub max_pixels: u64,
    /// Build the mask from the render's Cryptomatte instead of id and cos θ channels.
    pub cryptomatte: Option<CryptomatteOptions>,
    /// EXR layer the channel names are relative to (`ViewLayer`: `IndexMA` is then
    /// `ViewLayer.IndexMA`); `None`: names as given, or found by their last components.
    pub layer: Option<String>,
}

impl Default for MaskReadOptions {
    fn default() -> Self {
        MaskReadOptions {
            cryptomatte: None,
            layer: None,
            exr_channels: ExrMaskChannels::default(),
            binary_glass_id: None,
            max_pixels: DEFAULT_MAX_PIXELS,
        }
    }
}

#[cfg(test)]
mod tests;
