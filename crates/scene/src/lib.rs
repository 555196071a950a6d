//! The scene side of the glassdb method (docs/method.md, "Passes"): from a plain OBJ scene,
//! the glass planes, the mirrored *virtual scene* of each plane for the reflection pass
//! (section 3, eqs. 4–7), and the id + cos θ mask (sections 5–6) by z-buffer rasterisation.
//! Conventions and formats: docs/scene.md.

#![warn(missing_docs)]

pub mod bounds_file;
pub mod camera;
pub mod error;
pub mod mask;
pub mod mask_frames;
pub mod math;
pub mod mirror;
pub mod obj;
pub mod pane_groups;
pub mod planes;
pub mod planes_file;
pub mod raster;
pub mod triangulate;
pub mod virtual_scene;
pub mod warning;

pub use bounds_file::{
    BlenderBorder, GroupBoundsEntry, PLANE_BOUNDS_FORMAT, PlaneBoundsEntry, PlaneBoundsFile,
};
pub use camera::{CAMERA_FILE, Camera, CameraSource, CameraSpec, SensorFit, ViewPlane};
pub use error::SceneError;
pub use mask::{
    CosEncoding, GlassMapping, MaskScene, PlaneSource, build_mask_scene, to_mask_image,
};
pub use mask_frames::{
    FrameMask, MASK_STAGES, MaskJob, MaskPlanes, label_scene, mask_frame, mask_frames,
};
pub use mirror::{MirrorStats, mirror_scene};
pub use obj::{MTL_FILE, Mesh, OBJ_FILE, Scene, load_obj, stage_obj};
pub use pane_groups::{GroupEntry, group_scene_name};
pub use planes::{GlassPlane, MaterialMatcher, Plane, PlaneTolerance, detect_planes};
pub use planes_file::{PlanesFile, sides_from_planes_json};
pub use raster::{CosMode, RasterOptions, RasterOutput, RasterScene, rasterize};
pub use virtual_scene::{MirrorReport, MirrorRequest, write_virtual_scenes};
pub use warning::{FanReason, SceneWarning};
