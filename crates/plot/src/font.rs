//! The embedded font: DejaVu Sans (free licence, `data/fonts/LICENSE-DejaVu.txt`), registered
//! with plotters' ab_glyph backend so that text renders without any system font library.

use std::sync::OnceLock;

use plotters::style::FontStyle;

use crate::PlotError;

/// The family name figures use for all text.
pub const FAMILY: &str = "sans-serif";

static DEJAVU_SANS: &[u8] = include_bytes!("../../../data/fonts/DejaVuSans.ttf");
static REGISTERED: OnceLock<bool> = OnceLock::new();

/// Registers DejaVu Sans as [`FAMILY`] (once per process); every figure calls this first.
pub fn ensure_registered() -> Result<(), PlotError> {
    let ok = *REGISTERED.get_or_init(|| {
        [
            FontStyle::Normal,
            FontStyle::Bold,
            FontStyle::Italic,
            FontStyle::Oblique,
        ]
        .into_iter()
        .all(|style| plotters::style::register_font(FAMILY, style, DEJAVU_SANS).is_ok())
    });
    if ok { Ok(()) } else { Err(PlotError::Font) }
}
