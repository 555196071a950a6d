//! The decode phase: a frame's inputs decoded in parallel as its header phase
//! ([`crate::plan`]) planned them, placed in the transmission pass's frame and checked, ready
//! for the kernel (`composite`) or for the viewer's GPU textures. Nothing here knows of an
//! output file: what the transmission file carries over is a [`Carry`].

use std::collections::BTreeMap;
use std::path::Path;

use glassdb_image::{ImageWindows, PixelWindow};
use glassdb_mask::{MaskImage, PlacedMask};
use glassdb_pass::{CarriedFrame, Carry, Pass, PassReadOptions};
use rayon::prelude::*;

use crate::colour::{ChosenTable, PassSpace};
use crate::lut::GlassLut;
use crate::memory::{self, MemoryEstimate};
use crate::place::{absolute_from, check_frames, in_frame, relative_to};
use crate::plan::{FramePlan, InputReads};
use crate::{ComposeError, DecodeSettings, FrameFiles, OutsidePolicy, UnknownIds};

/// One frame's inputs decoded, placed in the transmission pass's frame and checked, ready for
/// the kernel (compose) or for the viewer's GPU textures.
pub struct DecodedFrame<'a> {
    /// The transmission pass: its image is the frame (its data window).
    pub trans: Pass,
    /// What an output would carry from the transmission pass's file.
    pub frame: CarriedFrame,
    /// The reflection passes, plane k at k.
    pub refl: Vec<Pass>,
    /// Each reflection pass's data window relative to the frame's top-left pixel.
    pub refl_windows: Vec<PixelWindow>,
    /// The pane groups' reflection passes, as `FrameFiles::groups` lists them.
    pub groups: Vec<DecodedGroupPass>,
    /// Glass pixels of units whose deeper pane groups are composited on a nearer group's pass
    /// (`DecodeSettings::max_groups`).
    pub folded_pixels: u64,
    /// The mask, moved into the frame's data window.
    pub mask: MaskImage,
    /// The passes' colour space.
    pub space: PassSpace,
    /// The registry table chosen for that space.
    pub table: ChosenTable,
    /// The lookup table of that registry table.
    pub lut: &'a GlassLut,
    /// Glass pixels per id.
    pub id_counts: BTreeMap<u16, u64>,
    /// Per plane: glass pixels outside its reflection pass and their bounding box (frame-relative).
    pub outside: BTreeMap<usize, (u64, PixelWindow)>,
    /// The frame's memory estimate.
    pub memory: MemoryEstimate,
    /// The estimate held from the budget until this is dropped.
    pub reservation: memory::Reservation<'a>,
}

/// A pane group's reflection pass, decoded and placed in the frame.
pub struct DecodedGroupPass {
    /// Its plane.
    pub plane: usize,
    /// Its pane group (1 or more).
    pub group: usize,
    /// The pass.
    pub pass: Pass,
    /// Its data window relative to the frame's top-left pixel.
    pub window: PixelWindow,
}

/// A frame's mask decoded once for several composites of the frame (its light groups, each
/// group's passes decoded in turn): the first composite reads it from its file, and each hands
/// it back, placed in the frame, for the next (decoding a 4K mask costs more than keeping it,
/// and keeping a copy beside the one in use would hold it twice).
#[derive(Default)]
pub(crate) struct MaskOnce {
    /// The mask between two composites.
    mask: std::sync::Mutex<Option<PlacedMask>>,
    /// Whether its file stores a plane per pixel, as read the first time.
    stores_planes: std::sync::OnceLock<bool>,
}

impl MaskOnce {
    /// Hands `mask` back, placed in the frame `windows` (the transmission pass's), for the
    /// next composite of the frame.
    pub(crate) fn give_back(&self, mask: MaskImage, windows: ImageWindows) {
        let placed = PlacedMask {
            image: mask,
            windows,
            stores_planes: self.stores_planes.get().copied().unwrap_or(true),
            has_coordinates: true,
        };
        if let Ok(mut slot) = self.mask.lock() {
            *slot = Some(placed);
        }
    }

    /// The mask handed back, if any.
    fn take(&self) -> Option<PlacedMask> {
        self.mask.lock().ok().and_then(|mut slot| slot.take())
    }
}

/// The frame's mask: the one `once` holds (handed back by the previous composite of the
/// frame), else read from its file.
fn read_mask(
    files: &FrameFiles,
    settings: &DecodeSettings,
    once: Option<&MaskOnce>,
) -> Result<PlacedMask, ComposeError> {
    if let Some(mask) = once.and_then(MaskOnce::take) {
        return Ok(mask);
    }
    let mask = glassdb_mask::read_placed_mask(&files.mask, &settings.mask)?;
    if let Some(once) = once {
        let _ = once.stores_planes.set(mask.stores_planes);
    }
    Ok(mask)
}

/// The frame's mask placed in the frame `frame` (a transmission pass's windows): the one `once`
/// holds (handed back by the previous composite of the frame), else read from its file and
/// checked to frame the same display window.
pub(crate) fn mask_in_frame(
    files: &FrameFiles,
    settings: &DecodeSettings,
    once: &MaskOnce,
    frame: &ImageWindows,
) -> Result<MaskImage, ComposeError> {
    let mask = read_mask(files, settings, Some(once))?;
    let windows = in_frame(mask.windows, !mask.has_coordinates, &frame.display);
    check_frames(&files.trans, frame, &[(files.mask.as_path(), windows)])?;
    Ok(if windows.data == frame.data {
        mask.image
    } else {
        mask.image.placed(&windows.data, &frame.data)
    })
}

/// The decoded inputs of one image, as read.
struct DecodedInputs {
    trans: Pass,
    frame: CarriedFrame,
    refl: Vec<Pass>,
    mask: PlacedMask,
}

/// The decode phase of a frame its header phase planned: decodes the inputs, places them in
/// the transmission pass's frame and checks ids, planes and glass outside cropped passes (as
/// `settings` says). `carry` says what the transmission file carries over; with `mask_once`
/// the mask is decoded by the first frame that asks and copied for the others (the light
/// groups of one frame, composited in turn).
pub(crate) fn decode_planned<'a>(
    files: &FrameFiles,
    settings: &DecodeSettings,
    plan: FramePlan<'a>,
    carry: Carry,
    mask_once: Option<&MaskOnce>,
) -> Result<DecodedFrame<'a>, ComposeError> {
    let FramePlan {
        reads,
        space,
        table,
        lut,
        display,
        refl_windows: stored_refl_windows,
        memory,
        reservation,
        ..
    } = plan;
    let inputs = decode_inputs(files, settings, &reads, &display, carry, mask_once)?;
    let mut placed = place_inputs(files, inputs)?;
    let id_counts = placed.mask.id_pixel_counts();
    let planes = files.refl.len();
    check_inputs(&files.mask, settings, lut, planes, &placed.mask, &id_counts)?;
    let folded_pixels = crate::pane_groups::check_group_passes(
        files,
        settings,
        lut,
        &placed.mask,
        &placed.refl_windows[planes..],
        &placed.stored_windows[planes..],
        &placed.trans.windows.data,
    )?;
    let groups = files
        .groups
        .iter()
        .zip(placed.refl.drain(planes..))
        .zip(&placed.refl_windows[planes..])
        .map(|((g, pass), &window)| DecodedGroupPass {
            plane: g.plane,
            group: g.group,
            pass,
            window,
        })
        .collect();
    placed.refl_windows.truncate(planes);
    placed.stored_windows.truncate(planes);
    let pass_windows: Vec<PixelWindow> = (0..planes)
        .map(|k| {
            stored_refl_windows
                .get(k)
                .map_or(placed.stored_windows[k], |w| w.data)
        })
        .collect();
    let outside = refuse_glass_outside(
        files,
        settings,
        &placed.mask,
        lut,
        &placed.refl_windows,
        &pass_windows,
        &placed.trans.windows.data,
    )?;
    Ok(DecodedFrame {
        trans: placed.trans,
        frame: placed.frame,
        refl: placed.refl,
        refl_windows: placed.refl_windows,
        groups,
        folded_pixels,
        mask: placed.mask,
        space,
        table,
        lut,
        id_counts,
        outside,
        memory,
        reservation,
    })
}

/// Reads the inputs of one image in parallel; the transmission file's attributes (and other
/// channels, as `carry` says) come with it.
fn decode_inputs(
    files: &FrameFiles,
    settings: &DecodeSettings,
    reads: &InputReads,
    display: &PixelWindow,
    carry: Carry,
    mask_once: Option<&MaskOnce>,
) -> Result<DecodedInputs, ComposeError> {
    let read_trans = || -> Result<(Pass, CarriedFrame), ComposeError> {
        Ok(glassdb_pass::read_transmission(
            &files.trans,
            &reads.trans,
            carry,
        )?)
    };
    let mask_then_refl = || -> Result<(PlacedMask, Vec<Pass>), ComposeError> {
        let mask = read_mask(files, settings, mask_once)?;
        let at = in_frame(mask.windows, !mask.has_coordinates, display).data;
        let rows = mask
            .image
            .plane_bounds()
            .into_iter()
            .map(|(plane, b)| {
                let y = i64::from(at.y);
                (plane, (y + i64::from(b.y_min), y + i64::from(b.y_max)))
            })
            .collect();
        let refl = read_reflections(files, &reads.refl, &rows)?;
        Ok((mask, refl))
    };
    let (trans, mask_refl) = rayon::join(read_trans, mask_then_refl);
    let (trans, frame) = trans?;
    let (mask, refl) = mask_refl?;
    Ok(DecodedInputs {
        trans,
        frame,
        refl,
        mask,
    })
}

/// The reflection passes a few at a time (as many as there are threads): each holds its
/// compressed blocks (read from its file by seeking) only while it is decoded, so that many
/// planes do not hold every file at once (`memory` counts it so). Of each, only the rows of
/// its plane's glass in the mask are decoded (`rows`, frame coordinates; a plane without glass
/// decodes one block).
fn read_reflections(
    files: &FrameFiles,
    reads: &[PassReadOptions],
    rows: &BTreeMap<u16, (i64, i64)>,
) -> Result<Vec<Pass>, ComposeError> {
    let rows_of = |plane: usize| {
        Some(
            u16::try_from(plane)
                .ok()
                .and_then(|plane| rows.get(&plane))
                .copied()
                .unwrap_or((i64::MIN, i64::MIN)),
        )
    };
    Ok(read_reflection_rows(files, reads, &rows_of)?
        .into_iter()
        .flatten()
        .collect())
}

/// Every reflection input's rows `rows_of(plane)` (frame coordinates, inclusive; `None`: the
/// input is not read), a few inputs at a time, as [`read_reflections`] reads them.
pub(crate) fn read_reflection_rows(
    files: &FrameFiles,
    reads: &[PassReadOptions],
    rows_of: &(dyn Fn(usize) -> Option<(i64, i64)> + Sync),
) -> Result<Vec<Option<Pass>>, ComposeError> {
    let at_once = memory::decoding_at_once();
    let inputs = files.reflection_inputs();
    let mut passes = Vec::with_capacity(inputs.len());
    for (c, chunk) in inputs.chunks(at_once).enumerate() {
        let decoded = chunk
            .par_iter()
            .enumerate()
            .map(|(i, &(plane, p))| {
                let k = c * at_once + i;
                rows_of(plane)
                    .map(|rows| glassdb_pass::read_pass_rows(p, &reads[k], rows))
                    .transpose()
            })
            .collect::<Result<Vec<_>, _>>()?;
        passes.extend(decoded);
    }
    Ok(passes)
}

/// The decoded inputs placed in the transmission pass's frame.
struct PlacedInputs {
    trans: Pass,
    frame: CarriedFrame,
    refl: Vec<Pass>,
    /// Each reflection pass's data window relative to the frame.
    refl_windows: Vec<PixelWindow>,
    /// Each reflection pass's data window as decoded (absolute).
    stored_windows: Vec<PixelWindow>,
    /// The mask moved into the frame's data window.
    mask: MaskImage,
}

/// Places what was decoded in the transmission pass's frame, checked again on what was
/// decoded: the header phase checked the headers, and a file replaced between the two reads
/// (a pass re-rendered while a farm composites) must not give a silently misplaced image.
fn place_inputs(files: &FrameFiles, inputs: DecodedInputs) -> Result<PlacedInputs, ComposeError> {
    let DecodedInputs {
        trans,
        frame,
        refl,
        mask,
    } = inputs;
    let data = trans.windows.data;
    let display = trans.windows.display;
    let mask_windows = in_frame(mask.windows, !mask.has_coordinates, &display);
    let refl_windows: Vec<ImageWindows> = refl
        .iter()
        .map(|p| in_frame(p.windows, !p.source.has_coordinates(), &display))
        .collect();
    let mut others: Vec<(&Path, ImageWindows)> = vec![(files.mask.as_path(), mask_windows)];
    others.extend(
        files
            .reflection_inputs()
            .into_iter()
            .map(|(_, p)| p)
            .zip(refl_windows.iter().copied()),
    );
    check_frames(&files.trans, &trans.windows, &others)?;
    let PlacedMask { image: mask, .. } = mask;
    let mask = if mask_windows.data == data {
        mask
    } else {
        let placed = mask.placed(&mask_windows.data, &data);
        drop(mask);
        placed
    };
    Ok(PlacedInputs {
        refl_windows: refl_windows
            .iter()
            .map(|w| relative_to(&w.data, &data))
            .collect(),
        stored_windows: refl_windows.iter().map(|w| w.data).collect(),
        trans,
        frame,
        refl,
        mask,
    })
}

/// Checks ids and planes of the mask (placed in the frame) before compositing (that a mask
/// without planes is not given several passes is checked from its header, `plan`).
pub(crate) fn check_inputs(
    mask_path: &Path,
    settings: &DecodeSettings,
    lut: &GlassLut,
    refl_count: usize,
    mask: &MaskImage,
    id_counts: &BTreeMap<u16, u64>,
) -> Result<(), ComposeError> {
    let unknown: Vec<(u16, u64)> = id_counts
        .iter()
        .filter(|(id, _)| !lut.contains(**id))
        .map(|(a, b)| (*a, *b))
        .collect();
    if !unknown.is_empty() && settings.unknown == UnknownIds::Error {
        return Err(ComposeError::UnknownIds {
            mask: mask_path.to_path_buf(),
            registry: settings.registry_label.clone(),
            none_known: unknown.len() == id_counts.len(),
            ids: unknown,
        });
    }
    if mask.max_plane() as usize >= refl_count {
        let mut per_plane: BTreeMap<u16, u64> = BTreeMap::new();
        for (&id, &p) in mask.id.iter().zip(&mask.plane) {
            if id != 0 && p as usize >= refl_count {
                *per_plane.entry(p).or_default() += 1;
            }
        }
        if let Some((&plane, &pixels)) = per_plane.iter().next() {
            return Err(ComposeError::PlaneWithoutPass {
                mask: mask_path.to_path_buf(),
                plane,
                pixels,
                passes: refl_count,
            });
        }
    }
    Ok(())
}

/// Glass pixels (with a table) outside their plane's reflection pass (`windows[k]`, plane k's,
/// relative to the frame `data`), refused where `settings` says so ([`OutsidePolicy::Error`],
/// naming the plane's pass and its data window as stored, `stored[k]`); else per plane, the
/// count and bounding box.
pub(crate) fn refuse_glass_outside(
    files: &FrameFiles,
    settings: &DecodeSettings,
    mask: &MaskImage,
    lut: &GlassLut,
    windows: &[PixelWindow],
    stored: &[PixelWindow],
    data: &PixelWindow,
) -> Result<BTreeMap<usize, (u64, PixelWindow)>, ComposeError> {
    let outside = glass_outside_passes(mask, lut, windows);
    if let (OutsidePolicy::Error, Some((&plane, &(pixels, bounds)))) =
        (settings.outside, outside.iter().next())
    {
        return Err(ComposeError::GlassOutsidePass {
            plane,
            pass: files.refl[plane].clone(),
            pixels,
            pass_window: stored[plane],
            bounds: absolute_from(&bounds, data),
        });
    }
    Ok(outside)
}

/// Glass pixels (with a table) outside their plane's reflection pass: per plane, the count and
/// bounding box in frame-relative coordinates. `windows[k]` is pass k's window relative to the
/// frame.
fn glass_outside_passes(
    mask: &MaskImage,
    lut: &GlassLut,
    windows: &[PixelWindow],
) -> BTreeMap<usize, (u64, PixelWindow)> {
    let frame = PixelWindow::at_origin(mask.width as usize, mask.height as usize);
    if windows.iter().all(|w| w.contains_window(&frame)) {
        return BTreeMap::new();
    }
    mask.plane_bounds_of(|x, y, id, plane| {
        lut.contains(id)
            && windows
                .get(usize::from(plane))
                .is_some_and(|w| !w.contains(i64::from(x), i64::from(y)))
    })
    .into_iter()
    .map(|(plane, b)| (usize::from(plane), (b.glass_pixels, b.window())))
    .collect()
}
