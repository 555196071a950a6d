//! The glass-swap viewer (docs/viewer.md): `glassdb view` serves a local page on which a
//! designer picks a product for every glass of a frame and sees the composite at once.
//!
//! The page composites on the GPU (WebGL2) with exactly what `compose` uses: the passes and the
//! mask decoded, placed and checked by [`glassdb_compose::decode_frame`] (for display: no
//! output file), and, per product, the
//! compositor's own lookup table ([`glassdb_compose::lut::GlassLut`]: r and t per channel at the
//! 256 8-bit cos θ codes, on the fine grid, and at normal incidence) built from that product's
//! registry record as if it were the mask id's record. A product swap for id k is that table
//! uploaded into k's slot.
//!
//! - [`scene`]: the frames, the candidate products and their tables, the binary data the page
//!   uploads ([`data`] says how it is laid out) and the typed, versioned data that describes
//!   them ([`page`]).
//! - [`server`]: the small HTTP server (tiny_http, [`server::WORKERS`] threads, 127.0.0.1 by
//!   default).
//! - [`export`]: the self-contained folder that works from `file://`.
//! - [`units`]: insulated units built on the page by the registry's stack engine.
//! - [`relight`]: a frame's light parts, so that a product change rescales the room's light.

#![warn(missing_docs)]

pub mod data;
pub mod error;
pub mod export;
pub mod page;
pub mod relight;
pub mod scene;
pub mod server;
pub mod units;

pub use error::ViewError;
pub use scene::{GlassChoice, Viewer, ViewerFrame, ViewerInputs};

/// The page: HTML, script and style, embedded in the binary.
pub mod assets {
    /// The page's HTML; the export puts its data scripts where `<!--EXPORT-DATA-->` stands.
    pub const INDEX_HTML: &str = include_str!("../assets/index.html");
    /// The page's script (WebGL2 composite, picker, A/B, probe, frames, automation hooks).
    pub const VIEWER_JS: &str = include_str!("../assets/viewer.js");
    /// The page's style.
    pub const VIEWER_CSS: &str = include_str!("../assets/viewer.css");
    /// Where the export inserts its data scripts in [`INDEX_HTML`].
    pub const EXPORT_DATA_MARK: &str = "<!--EXPORT-DATA-->";
}
