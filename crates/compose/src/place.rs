//! OpenEXR's coordinate model applied to one frame: the frame is the transmission pass's
//! display and data windows; every input must frame the same display window (a PNG of that
//! size is that frame), and each keeps its own data window, relative to the frame's.

use std::path::Path;

use glassdb_image::{ImageWindows, PixelWindow};

use crate::ComposeError;

/// Every input must frame the same display window as the transmission pass `trans` (the file
/// `trans_path`); sizes are named when both are whole frames at the origin (PNGs, full
/// renders).
pub(crate) fn check_frames(
    trans_path: &Path,
    trans: &ImageWindows,
    others: &[(&Path, ImageWindows)],
) -> Result<(), ComposeError> {
    for (path, w) in others {
        if w.display == trans.display {
            continue;
        }
        let whole = |w: &ImageWindows| w.data == w.display && w.display.x == 0 && w.display.y == 0;
        let size = |w: &PixelWindow| (w.width as u32, w.height as u32);
        return Err(if whole(trans) && whole(w) {
            ComposeError::SizeMismatch {
                a: trans_path.to_path_buf(),
                a_size: size(&trans.display),
                b: path.to_path_buf(),
                b_size: size(&w.display),
            }
        } else {
            ComposeError::DisplayWindowMismatch {
                a: trans_path.to_path_buf(),
                a_window: trans.display,
                b: path.to_path_buf(),
                b_window: w.display,
            }
        });
    }
    Ok(())
}

/// The windows of an input in the frame `display`: an image without coordinates (a PNG) of the
/// frame's size is that frame, wherever it lies; anything else keeps its own windows.
pub(crate) fn in_frame(
    windows: ImageWindows,
    without_coordinates: bool,
    display: &PixelWindow,
) -> ImageWindows {
    let same_size =
        windows.display.width == display.width && windows.display.height == display.height;
    if without_coordinates && same_size {
        ImageWindows {
            data: *display,
            display: *display,
        }
    } else {
        windows
    }
}

/// `w` in coordinates relative to `origin`'s top-left pixel.
pub(crate) fn relative_to(w: &PixelWindow, origin: &PixelWindow) -> PixelWindow {
    PixelWindow {
        x: w.x - origin.x,
        y: w.y - origin.y,
        ..*w
    }
}

/// `w` (relative to `origin`'s top-left pixel) in absolute coordinates.
pub(crate) fn absolute_from(w: &PixelWindow, origin: &PixelWindow) -> PixelWindow {
    PixelWindow {
        x: w.x + origin.x,
        y: w.y + origin.y,
        ..*w
    }
}
