//! What every mask layout read from an EXR shares, the EXR channels and Cryptomatte alike: the
//! header a mask reader returns, finding a channel by the names users type, checking from the
//! headers that channels can be decoded together, decoding them, and naming a bad pixel.

use std::path::Path;

use glassdb_image::{ChannelMatch, ExrFile, ExrPart, ImageWindows, ReadMemory};

use crate::MaskError;

/// What a mask file's header says, checked as the reader checks it before decoding any pixel:
/// where its pixels lie, whether it stores planes, and what reading it costs in memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MaskHeader {
    /// Where its pixels lie.
    pub windows: ImageWindows,
    /// Whether it stores a plane per pixel.
    pub stores_planes: bool,
    /// Whether the file states its pixels' coordinates (EXR); see [`crate::PlacedMask`].
    pub has_coordinates: bool,
    /// Bytes per pixel of the decoded [`crate::MaskImage`] (id, plane, cos θ, coverage).
    pub bytes_per_pixel: u64,
    /// Reading it: the file and the decoder's buffers while reading, the mask after.
    pub memory: ReadMemory,
}

pub(crate) fn decode_err(path: &Path, source: glassdb_image::ImageError) -> MaskError {
    MaskError::Decode {
        path: path.to_path_buf(),
        source,
    }
}

/// Checks, from the headers, that channels `wanted` (part, channel) can be decoded (within
/// `max_pixels`, not deep, not subsampled) and that their parts share one data window, which
/// is returned with the display window.
pub(crate) fn plan_channels(
    parts: &[ExrPart],
    wanted: &[(usize, usize)],
    path: &Path,
    max_pixels: u64,
) -> Result<ImageWindows, MaskError> {
    let mut windows: Option<ImageWindows> = None;
    let mut part_ids: Vec<usize> = wanted.iter().map(|w| w.0).collect();
    part_ids.sort_unstable();
    part_ids.dedup();
    for p in part_ids {
        let channels: Vec<usize> = wanted.iter().filter(|w| w.0 == p).map(|w| w.1).collect();
        let info = parts.get(p).ok_or_else(|| MaskError::Layout {
            path: path.to_path_buf(),
            detail: format!("no part {p}"),
        })?;
        glassdb_image::check_exr_readable(info, &channels, max_pixels)
            .map_err(|source| decode_err(path, source))?;
        match windows {
            None => windows = Some(info.windows()),
            Some(w) if w.data != info.data_window => {
                return Err(different_windows(path, &w, info));
            }
            Some(_) => {}
        }
    }
    windows.ok_or_else(|| MaskError::Layout {
        path: path.to_path_buf(),
        detail: "no mask channels".into(),
    })
}

fn different_windows(path: &Path, w: &ImageWindows, info: &ExrPart) -> MaskError {
    MaskError::Layout {
        path: path.to_path_buf(),
        detail: format!(
            "the mask channels lie in parts with different data windows ({} and {})",
            w.data, info.data_window
        ),
    }
}

/// Finds the (part, channel) named `name` (in `layer`, when given); a required channel that is
/// missing is an error listing the channels the file has.
pub(crate) fn locate_channel(
    parts: &[ExrPart],
    name: &str,
    layer: Option<&str>,
    required: bool,
    path: &Path,
) -> Result<Option<(usize, usize)>, MaskError> {
    match glassdb_image::find_channel(parts, name, layer) {
        ChannelMatch::Found(p, c) => Ok(Some((p, c))),
        ChannelMatch::Ambiguous(candidates) => Err(MaskError::AmbiguousChannel {
            path: path.to_path_buf(),
            channel: name.to_string(),
            candidates,
        }),
        ChannelMatch::Missing if required => Err(MaskError::MissingChannel {
            path: path.to_path_buf(),
            channel: match layer {
                Some(l) => format!("{l}.{name}"),
                None => name.to_string(),
            },
            available: glassdb_image::all_channel_names(parts),
        }),
        ChannelMatch::Missing => Ok(None),
    }
}

/// Decodes channels `wanted` (part, channel) of the file, each part once with all its wanted
/// channels, in the order asked; every part must have the same data window.
pub(crate) fn decode_channels(
    exr: &ExrFile<'_>,
    wanted: &[(usize, usize)],
    path: &Path,
) -> Result<(ImageWindows, Vec<Vec<f32>>), MaskError> {
    let mut out: Vec<Vec<f32>> = vec![Vec::new(); wanted.len()];
    let mut windows: Option<ImageWindows> = None;
    let mut parts: Vec<usize> = wanted.iter().map(|w| w.0).collect();
    parts.sort_unstable();
    parts.dedup();
    for p in parts {
        let slots: Vec<usize> = (0..wanted.len()).filter(|&k| wanted[k].0 == p).collect();
        let channels: Vec<usize> = slots.iter().map(|&k| wanted[k].1).collect();
        let (info, buffers) =
            exr.read_channels(p, &channels)
                .map_err(|source| MaskError::Decode {
                    path: path.to_path_buf(),
                    source,
                })?;
        match windows {
            None => windows = Some(info.windows()),
            Some(w) if w.data != info.data_window => {
                return Err(different_windows(path, &w, &info));
            }
            Some(_) => {}
        }
        for (k, b) in slots.into_iter().zip(buffers) {
            out[k] = b;
        }
    }
    let windows = windows.ok_or_else(|| MaskError::Layout {
        path: path.to_path_buf(),
        detail: "no mask channels".into(),
    })?;
    Ok((windows, out))
}

/// Builds [`MaskError::BadPixel`] for a pixel index of a mask file.
pub(crate) struct PixelError<'a> {
    pub(crate) path: &'a Path,
    pub(crate) width: usize,
}

impl PixelError<'_> {
    pub(crate) fn at(&self, i: usize, detail: String) -> MaskError {
        MaskError::BadPixel {
            path: self.path.to_path_buf(),
            x: (i % self.width) as u32,
            y: (i / self.width) as u32,
            detail,
        }
    }
}
