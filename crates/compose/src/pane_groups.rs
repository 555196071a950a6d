//! The pane groups' reflection passes of a frame (issue 27): which a frame's units need, and
//! that each is given once, on a plane with a pass, and holds its glass.

use std::collections::BTreeMap;
use std::path::Path;

use glassdb_image::PixelWindow;
use glassdb_mask::MaskImage;

use crate::lut::GlassLut;
use crate::place::absolute_from;
use crate::{ComposeError, DecodeSettings, FrameFiles, OutsidePolicy};

/// Refuses group passes on a plane without a pass of its own, numbered 0, or given twice
/// (before any header is read).
pub(crate) fn check_group_files(files: &FrameFiles) -> Result<(), ComposeError> {
    let mut seen = BTreeMap::new();
    for g in &files.groups {
        if g.plane >= files.refl.len() || g.group == 0 {
            return Err(ComposeError::GroupPassWithoutPlane {
                pass: g.path.clone(),
                plane: g.plane,
                group: g.group,
                planes: files.refl.len(),
            });
        }
        if let Some(first) = seen.insert((g.plane, g.group), &g.path) {
            return Err(ComposeError::GroupPassTwice {
                plane: g.plane,
                group: g.group,
                first: first.clone(),
                second: g.path.clone(),
            });
        }
    }
    Ok(())
}

/// Checks that every unit of the frame has a pass for each of its pane groups (within
/// `settings.max_groups`) and that each group pass holds its glass (unless
/// `settings.outside` lets it go); returns the glass pixels whose deeper groups are folded into
/// a nearer group's pass. `windows[i]` and `stored[i]` are group pass i's windows, relative to
/// the frame and as stored; `data` the frame's data window.
pub(crate) fn check_group_passes(
    files: &FrameFiles,
    settings: &DecodeSettings,
    lut: &GlassLut,
    mask: &MaskImage,
    windows: &[PixelWindow],
    stored: &[PixelWindow],
    data: &PixelWindow,
) -> Result<u64, ComposeError> {
    if !lut.has_units() {
        return Ok(0);
    }
    let limit = settings.max_groups.map_or(usize::MAX, |l| l.get());
    let mut per_plane_id: BTreeMap<(u16, u16), u64> = BTreeMap::new();
    for (&id, &plane) in mask.id.iter().zip(&mask.plane) {
        if id != 0 && lut.group_count(id) > 1 {
            *per_plane_id.entry((plane, id)).or_default() += 1;
        }
    }
    let mut folded = 0;
    for (&(plane, id), &pixels) in &per_plane_id {
        let groups = lut.group_count(id);
        if groups > limit {
            folded += pixels;
        }
        let given = |g: usize| {
            files
                .groups
                .iter()
                .any(|p| p.plane == usize::from(plane) && p.group == g)
        };
        if let Some(group) = (1..groups.min(limit)).find(|&g| !given(g)) {
            return Err(ComposeError::GroupWithoutPass {
                mask: files.mask.clone(),
                plane,
                group,
                id,
                groups,
                pixels,
                plane_pass: files
                    .refl
                    .get(usize::from(plane))
                    .map_or_else(|| Path::new("").to_path_buf(), |p| p.clone()),
            });
        }
    }
    if settings.outside == OutsidePolicy::Error {
        for ((g, window), stored) in files.groups.iter().zip(windows).zip(stored) {
            if g.group >= limit {
                continue;
            }
            let outside = mask.plane_bounds_of(|x, y, id, plane| {
                usize::from(plane) == g.plane
                    && lut.group_count(id) > g.group
                    && !window.contains(i64::from(x), i64::from(y))
            });
            if let Some(b) = outside.values().next() {
                return Err(ComposeError::GlassOutsidePass {
                    plane: g.plane,
                    pass: g.path.clone(),
                    pixels: b.glass_pixels,
                    pass_window: *stored,
                    bounds: absolute_from(&b.window(), data),
                });
            }
        }
    }
    Ok(folded)
}
