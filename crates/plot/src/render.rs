//! Output of figures: PNG (plotters' bitmap backend, encoded by glassdb-image) or SVG, picked
//! by the output file's extension, always written atomically (`glassdb_io::write_bytes_atomic`).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::error::draw_err;
use crate::{PlotError, font};

/// Largest figure side accepted, in pixels (guards the bitmap allocation).
pub const MAX_FIGURE_SIDE_PX: u32 = 8192;

/// The file formats a figure can be written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// 8-bit RGB PNG.
    Png,
    /// Scalable vector graphics (text as `<text>` in the DejaVu Sans family, then sans-serif).
    Svg,
}

// Each format's name is its file extension.
glassdb_io::enum_names!(ImageFormat { Png => "png", Svg => "svg" });

impl ImageFormat {
    /// The format named by `path`'s extension (case-insensitive `png` or `svg`).
    pub fn from_path(path: &Path) -> Result<Self, PlotError> {
        glassdb_io::lowercase_extension(path)
            .and_then(|ext| Self::from_name(&ext))
            .ok_or_else(|| PlotError::UnknownFormat {
                path: path.to_path_buf(),
            })
    }
}

/// Something that can draw itself on a plotters drawing area of any backend.
pub trait Figure {
    /// Figure size in pixels (width, height).
    fn size(&self) -> (u32, u32);
    /// A short name for error messages ("fit plot of clear_6mm", …).
    fn describe(&self) -> String;
    /// Draws the figure onto `root` (already filled white); `format` lets a figure keep vector
    /// output small (e.g. fewer heat-map cells in SVG).
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        format: ImageFormat,
    ) -> Result<(), PlotError>;
}

fn check_size(width: u32, height: u32) -> Result<(), PlotError> {
    if width == 0 || height == 0 || width > MAX_FIGURE_SIDE_PX || height > MAX_FIGURE_SIDE_PX {
        return Err(PlotError::BadSize {
            width,
            height,
            max: MAX_FIGURE_SIDE_PX,
        });
    }
    Ok(())
}

/// Runs a drawing closure, turning a panic inside plotters into [`PlotError::DrawPanic`].
fn guarded<T>(what: &str, f: impl FnOnce() -> Result<T, PlotError>) -> Result<T, PlotError> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(_) => Err(PlotError::DrawPanic {
            what: what.to_string(),
        }),
    }
}

/// Fills `backend`'s area white and draws `fig` on it in `format`, a panic inside plotters
/// turned into [`PlotError::DrawPanic`].
fn draw_on<F: Figure, DB: DrawingBackend>(
    fig: &F,
    backend: DB,
    format: ImageFormat,
) -> Result<(), PlotError> {
    guarded(&fig.describe(), || {
        let root = backend.into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        fig.draw(&root, format)?;
        root.present().map_err(draw_err)
    })
}

/// Draws `fig` into an RGB8 buffer (row-major, `width * height * 3` bytes).
pub fn render_rgb<F: Figure>(fig: &F) -> Result<(Vec<u8>, u32, u32), PlotError> {
    font::ensure_registered()?;
    let (w, h) = fig.size();
    check_size(w, h)?;
    let mut buf = vec![255u8; w as usize * h as usize * 3];
    let backend = BitMapBackend::with_buffer(&mut buf, (w, h));
    draw_on(fig, backend, ImageFormat::Png)?;
    Ok((buf, w, h))
}

/// Draws `fig` as PNG bytes.
pub fn render_png<F: Figure>(fig: &F) -> Result<Vec<u8>, PlotError> {
    let (rgb, w, h) = render_rgb(fig)?;
    encode_png_rgb(&rgb, w, h)
}

/// Draws `fig` as an SVG document.
pub fn render_svg<F: Figure>(fig: &F) -> Result<String, PlotError> {
    font::ensure_registered()?;
    let (w, h) = fig.size();
    check_size(w, h)?;
    let mut svg = String::new();
    draw_on(
        fig,
        SVGBackend::with_string(&mut svg, (w, h)),
        ImageFormat::Svg,
    )?;
    Ok(svg)
}

/// Draws `fig` in the format the extension of `path` names; returns the file's bytes.
pub fn render_for<F: Figure>(fig: &F, path: &Path) -> Result<(Vec<u8>, ImageFormat), PlotError> {
    let format = ImageFormat::from_path(path)?;
    let bytes = match format {
        ImageFormat::Png => render_png(fig)?,
        ImageFormat::Svg => render_svg(fig)?.into_bytes(),
    };
    Ok((bytes, format))
}

/// Draws `fig` and writes it to `path` atomically, in the format its extension names.
pub fn save<F: Figure>(fig: &F, path: &Path) -> Result<ImageFormat, PlotError> {
    let (bytes, format) = render_for(fig, path)?;
    glassdb_io::write_bytes_atomic(path, &bytes)?;
    Ok(format)
}

/// Encodes an RGB8 buffer as a PNG. Plots are mostly flat colour, so the strongest
/// compression keeps figures small (docs/figures stay well under 200 KB).
pub fn encode_png_rgb(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, PlotError> {
    let options = glassdb_image::PngEncodeOptions {
        compression: glassdb_image::PngCompression::High,
        srgb_chunk: false,
    };
    glassdb_image::encode_png(
        width,
        height,
        glassdb_image::PngColor::Rgb,
        glassdb_image::PngSampleSlice::U8(rgb),
        options,
    )
    .map_err(PlotError::Encode)
}
