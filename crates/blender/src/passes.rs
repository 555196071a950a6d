//! The passes Blender rendered, moved into the output folder: each cropped reflection pass
//! placed at its plane's pixel rectangle in the frame, and a one-pixel pass for a plane with no
//! glass in a frame.

use std::path::Path;

use glassdb_image::{
    ExrImageOut, ExrPartOut, ExrPlane, ExrStorage, ExrWriteOptions, PixelWindow, PlaneSamples,
};

use crate::BlenderError;

/// Refuses a pass that Blender did not write.
fn check_written(pass: &Path) -> Result<(), BlenderError> {
    if pass.is_file() {
        Ok(())
    } else {
        Err(BlenderError::BadRender {
            path: pass.to_path_buf(),
            message: "Blender did not write this pass".into(),
        })
    }
}

pub(crate) fn rename(from: &Path, to: &Path) -> Result<(), BlenderError> {
    check_written(from)?;
    std::fs::rename(from, to).map_err(BlenderError::io("move", from))
}

/// The passes are written as compose writes by default: half float, ZIP.
const EXR_OPTIONS: ExrWriteOptions = ExrWriteOptions {
    storage: ExrStorage::Half,
    compression: glassdb_encode::DEFAULT_EXR_COMPRESSION,
    zip_level: None,
};

/// Writes Blender's cropped render `from` (its window reset to the origin, docs/compose.md)
/// to `to` with its data window at `window` in the `width × height` frame, samples unchanged.
pub(crate) fn place_crop(
    from: &Path,
    to: &Path,
    window: PixelWindow,
    width: u32,
    height: u32,
) -> Result<(), BlenderError> {
    let bad = |message: String| BlenderError::BadRender {
        path: from.to_path_buf(),
        message,
    };
    check_written(from)?;
    let bytes = glassdb_io::read_input(from, glassdb_image::IMAGE_FILE)?;
    let exact = glassdb_image::read_exr_exact(&bytes, glassdb_image::DEFAULT_MAX_PIXELS)?;
    let parts = exact.parts.len();
    let Ok([part]) = <[_; 1]>::try_from(exact.parts) else {
        return Err(bad(format!("{parts} parts, expected one")));
    };
    let got = (part.data_window.width, part.data_window.height);
    if got != (window.width, window.height) {
        return Err(bad(format!(
            "the render is {}x{}, but the border asked for {}x{}",
            got.0, got.1, window.width, window.height
        )));
    }
    let image = ExrImageOut {
        display_window: PixelWindow::at_origin(width as usize, height as usize),
        attributes: exact.attributes,
        parts: vec![ExrPartOut {
            data_window: window,
            attributes: part.attributes,
            planes: part
                .channels
                .into_iter()
                .map(|(name, samples)| ExrPlane {
                    name,
                    samples: PlaneSamples::Exact(samples),
                    linear: false,
                })
                .collect(),
        }],
    };
    write_exr(to, image)
}

pub(crate) fn write_exr(to: &Path, image: ExrImageOut) -> Result<(), BlenderError> {
    glassdb_io::write_atomic(to, |w| {
        glassdb_image::write_exr_image(w, image, EXR_OPTIONS)
            .map(|_| ())
            .map_err(std::io::Error::other)
    })?;
    Ok(())
}

/// The pass of a plane without glass in a frame (the compositor wants one per plane and never
/// reads its pixels): one black pixel at the frame's corner, with a layer per light group of
/// `groups` (the passes of a scene with light groups, [`crate::scene_lights`]).
pub(crate) fn write_unused_pass(
    to: &Path,
    width: u32,
    height: u32,
    groups: &[String],
) -> Result<(), BlenderError> {
    // Blender's multilayer names when the passes have group layers.
    let beauty = if groups.is_empty() {
        ""
    } else {
        "ViewLayer.Combined."
    };
    let mut planes: Vec<ExrPlane> = ["A", "B", "G", "R"]
        .iter()
        .map(|c| ExrPlane::new(&format!("{beauty}{c}"), vec![0.0]))
        .collect();
    for g in groups {
        for c in ["R", "G", "B"] {
            let layer = crate::light_split::group_layer(g);
            planes.push(ExrPlane::new(&format!("{layer}.{c}"), vec![0.0]));
        }
    }
    let display = PixelWindow::at_origin(width as usize, height as usize);
    write_exr(
        to,
        ExrImageOut {
            display_window: display,
            attributes: glassdb_image::ExrImageAttributes::with_size((
                width as usize,
                height as usize,
            )),
            parts: vec![ExrPartOut {
                data_window: PixelWindow::at_origin(1, 1),
                attributes: Default::default(),
                planes,
            }],
        },
    )
}
