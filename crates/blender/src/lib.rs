//! `glassdb blender`: a Blender scene to composited glazing in one command (docs/blender.md).
//! Blender (found and version-checked in [`program`]) runs the embedded script
//! `integrations/blender/glassdb_blender.py` headless: it exports the scene and the camera of
//! every frame; glassdb finds the glass planes, rasterises each frame's mask and each plane's
//! pixel rectangle; Blender renders the transmission pass and one cropped reflection pass per
//! plane ([`job`]); glassdb places the crops and composites every frame ([`pipeline`]).

#![warn(missing_docs)]

pub mod error;
pub mod geometry;
pub mod job;
pub mod light_split;
mod passes;
pub mod pipeline;
pub mod program;
mod reference_lights;
pub mod relit;
pub mod scene_lights;
pub mod swap;
pub mod thin_pane;

pub use error::BlenderError;
pub use job::{PixelBounds, RunRecord};
pub use pipeline::{
    BlenderTime, ComposeReport, DEFAULT_MASK_SAMPLES, RegistryChoice, RenderReport, RenderRequest,
    compose_dir, render,
};
pub use program::{Blender, Launcher};
pub use swap::{PassGlass, SwapWarning, swap_warnings};
pub use thin_pane::ThinPane;
