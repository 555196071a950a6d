//! A frame's further light groups (and a relit frame's further lights) composited in row bands
//! into the sum of the composites before them (docs/performance.md, "Light groups"): band by
//! band, the rows of the group's transmission layer are read (the blocks holding them, by
//! seeking), with the rows of each reflection pass that its plane's glass needs there,
//! composited by the kernel and added to the sum, so that no group's whole frame is held
//! beside the sum and a frame of G groups takes about the memory of one group's composite.
//! The kernel works pixel by pixel and every sample gets the same f32 additions as a
//! whole-frame composite would give it, so the sum is the same bit for bit.

use std::time::{Duration, Instant};

use glassdb_image::{ImageWindows, PixelWindow};
use glassdb_mask::MaskImage;
use glassdb_pass::Pass;

use crate::composite::{Composited, run_kernel};
use crate::decode::MaskOnce;
use crate::kernel::PlacedGroupRefl;
use crate::place::{check_frames, in_frame, relative_to};
use crate::plan::FramePlan;
use crate::{ComposeError, ComposeSettings, FrameFiles, StageTimings};

/// Rows of the frame composited at a time: a multiple of every EXR compression's block height
/// (1, 16, 32, 256 rows), so that a band of a transmission pass decodes whole blocks, each
/// once; at 4K, 12 MB of f32 R, G, B per pass read.
pub(crate) const BAND_ROWS: usize = 256;

/// A group's frame as the bands read it: its files, how each pass is read, the mask placed in
/// the frame and the rows of each plane's glass.
struct BandedFrame<'a> {
    files: &'a FrameFiles,
    settings: &'a ComposeSettings,
    plan: &'a FramePlan<'a>,
    mask: &'a MaskImage,
    /// The frame: the first group's transmission windows, which the sum holds.
    frame: ImageWindows,
    /// Per plane, the first and last row (absolute) of its glass; `None`: no glass.
    glass_rows: Vec<Option<(i64, i64)>>,
}

/// Composites the frame `plan` planned (one light group's layers, or one light's mix of a
/// relit frame's parts) band by band (`band_rows` rows each) and adds it to `sum`, the
/// composites of the groups before it. The checks of a whole-frame decode are made first on
/// the headers and the mask (ids, planes, pane-group passes, glass outside cropped passes);
/// the mask is `mask_once`'s, handed back for the next group. With `keep`, the group's own
/// composite is given back too.
pub(crate) fn add_in_bands(
    files: &FrameFiles,
    settings: &ComposeSettings,
    plan: FramePlan<'_>,
    mask_once: &MaskOnce,
    sum: &mut Composited,
    keep: bool,
    band_rows: usize,
) -> Result<BandedGroup, ComposeError> {
    let t0 = Instant::now();
    let frame = sum.image.trans.windows;
    check_frames(
        &files.trans,
        &frame,
        &[(files.trans.as_path(), plan.trans_windows)],
    )?;
    if plan.trans_windows.data != frame.data {
        return Err(window_mismatch(
            files,
            &plan,
            plan.trans_windows.data,
            &frame,
        ));
    }
    let mask = crate::decode::mask_in_frame(files, &settings.decode, mask_once, &frame)?;
    check_group(files, settings, &plan, &mask, &frame.data)?;
    let top = i64::from(frame.data.y);
    let bounds = mask.plane_bounds();
    let glass_rows = (0..files.refl.len())
        .map(|plane| {
            let b = u16::try_from(plane).ok().and_then(|p| bounds.get(&p))?;
            Some((top + i64::from(b.y_min), top + i64::from(b.y_max)))
        })
        .collect();
    let group = BandedFrame {
        files,
        settings,
        plan: &plan,
        mask: &mask,
        frame,
        glass_rows,
    };
    let (width, height) = (frame.data.width, frame.data.height);
    let mut kept = keep.then(|| [0, 1, 2].map(|_| vec![0f32; width * height]));
    let mut timings = StageTimings {
        decode: t0.elapsed(),
        ..StageTimings::default()
    };
    let band_rows = band_rows.max(1);
    for first in (0..height).step_by(band_rows) {
        let rows = band_rows.min(height - first);
        let (read, composite) = group.add_band(first, rows, sum, kept.as_mut())?;
        timings.decode += read;
        timings.compose += composite;
    }
    drop(group);
    mask_once.give_back(mask, frame);
    Ok(BandedGroup { own: kept, timings })
}

/// What [`add_in_bands`] gives back beside the sum.
pub(crate) struct BandedGroup {
    /// The group's own composite, where kept.
    pub(crate) own: Option<[Vec<f32>; 3]>,
    /// The time spent reading (`decode`) and compositing (`compose`).
    pub(crate) timings: StageTimings,
}

/// The error for a group whose transmission layer holds the pixels `window`, not the frame's.
fn window_mismatch(
    files: &FrameFiles,
    plan: &FramePlan<'_>,
    window: PixelWindow,
    frame: &ImageWindows,
) -> ComposeError {
    ComposeError::GroupWindowMismatch {
        path: files.trans.clone(),
        layer: plan.reads.trans.layer.clone().unwrap_or_default(),
        window,
        frame: frame.data,
    }
}

/// The checks a whole-frame decode makes of a frame (`decode_planned`), on the passes' header
/// windows and the mask placed in the frame `data`.
fn check_group(
    files: &FrameFiles,
    settings: &ComposeSettings,
    plan: &FramePlan<'_>,
    mask: &MaskImage,
    data: &PixelWindow,
) -> Result<(), ComposeError> {
    let planes = files.refl.len();
    let decode = &settings.decode;
    let id_counts = mask.id_pixel_counts();
    crate::decode::check_inputs(&files.mask, decode, plan.lut, planes, mask, &id_counts)?;
    let stored: Vec<PixelWindow> = plan.refl_windows.iter().map(|w| w.data).collect();
    let relative: Vec<PixelWindow> = stored.iter().map(|w| relative_to(w, data)).collect();
    let (own, groups) = relative.split_at(planes.min(relative.len()));
    let (own_stored, groups_stored) = stored.split_at(planes.min(stored.len()));
    crate::pane_groups::check_group_passes(
        files,
        decode,
        plan.lut,
        mask,
        groups,
        groups_stored,
        data,
    )?;
    crate::decode::refuse_glass_outside(files, decode, mask, plan.lut, own, own_stored, data)?;
    Ok(())
}

impl BandedFrame<'_> {
    /// Reads, composites and adds to `sum` (and copies into `kept`) the frame's rows
    /// `first..first + rows` (from the data window's top); the time spent reading and
    /// compositing.
    fn add_band(
        &self,
        first: usize,
        rows: usize,
        sum: &mut Composited,
        kept: Option<&mut [Vec<f32>; 3]>,
    ) -> Result<(Duration, Duration), ComposeError> {
        let t0 = Instant::now();
        let data = self.frame.data;
        let band = PixelWindow {
            y: data.y + first as i32,
            height: rows,
            ..data
        };
        let (y0, y1) = (i64::from(band.y), i64::from(band.y) + rows as i64 - 1);
        let rows_of = |plane: usize| {
            let (a, b) = self.glass_rows.get(plane).copied().flatten()?;
            let (a, b) = (a.max(y0), b.min(y1));
            (a <= b).then_some((a, b))
        };
        let reads = &self.plan.reads;
        let (trans, refl) = rayon::join(
            || glassdb_pass::read_pass_rows(&self.files.trans, &reads.trans, (y0, y1)),
            || crate::decode::read_reflection_rows(self.files, &reads.refl, &rows_of),
        );
        let (mut trans, refl) = (trans?, refl?);
        let start = self.band_start(&trans, &band)?;
        let refl_windows = self.placed_windows(&refl, &band)?;
        let read = t0.elapsed();

        let t1 = Instant::now();
        let mask = self.mask.placed(
            &PixelWindow::at_origin(data.width, data.height),
            &PixelWindow {
                x: 0,
                y: first as i32,
                width: data.width,
                height: rows,
            },
        );
        let n = data.width * rows;
        let [r, g, b] = &mut trans.image.rgb;
        let composite = [r, g, b].map(|p| &mut p[start..start + n]);
        let empty: [Vec<f32>; 3] = Default::default();
        let rgb = |k: usize| refl[k].as_ref().map_or(&empty, |p| &p.image.rgb);
        let planes = self.files.refl.len();
        let groups: Vec<PlacedGroupRefl<'_>> = self
            .files
            .groups
            .iter()
            .enumerate()
            .map(|(i, g)| {
                let [r, gr, b] = rgb(planes + i);
                PlacedGroupRefl {
                    plane: g.plane,
                    group: g.group,
                    rgb: [r.as_slice(), gr.as_slice(), b.as_slice()],
                    window: refl_windows[planes + i],
                }
            })
            .collect();
        let own = (0..planes).map(|k| (rgb(k), refl_windows[k]));
        let [r, g, b] = composite;
        run_kernel(
            [&mut *r, &mut *g, &mut *b],
            own,
            &groups,
            &mask,
            self.plan.lut,
            self.settings,
        )?;
        let at = first * data.width;
        let band_planes = [&*r, &*g, &*b];
        let [sr, sg, sb] = &mut sum.image.trans.image.rgb;
        crate::light_groups::add_planes(
            [
                &mut sr[at..at + n],
                &mut sg[at..at + n],
                &mut sb[at..at + n],
            ],
            band_planes,
        );
        if let Some(kept) = kept {
            for (k, plane) in kept.iter_mut().zip(band_planes) {
                k[at..at + n].copy_from_slice(plane);
            }
        }
        Ok((read, t1.elapsed()))
    }

    /// Where the band `band` starts in the decoded rows of the transmission pass `trans`,
    /// checked to hold the band's rows of the frame (a file replaced since its header was read
    /// is refused, not misplaced).
    fn band_start(&self, trans: &Pass, band: &PixelWindow) -> Result<usize, ComposeError> {
        let frame = &self.frame;
        check_frames(
            &self.files.trans,
            frame,
            &[(self.files.trans.as_path(), trans.windows)],
        )?;
        let data = trans.windows.data;
        let holds = data.x == band.x
            && data.width == band.width
            && data.y <= band.y
            && data.end_y() >= band.end_y();
        // The decoded planes must be the rows the window names, so that the band's slice of
        // them is in bounds.
        let sized = trans.image.width as usize == data.width
            && trans.image.height as usize == data.height
            && trans
                .image
                .rgb
                .iter()
                .all(|p| p.len() == data.width * data.height);
        if !holds || !sized {
            return Err(window_mismatch(self.files, self.plan, data, frame));
        }
        Ok((band.y - data.y) as usize * data.width)
    }

    /// Each reflection input's decoded rows relative to the band (an empty window where none
    /// were read), checked to frame the transmission pass's display window.
    fn placed_windows(
        &self,
        refl: &[Option<Pass>],
        band: &PixelWindow,
    ) -> Result<Vec<PixelWindow>, ComposeError> {
        let display = self.frame.display;
        let windows: Vec<Option<ImageWindows>> = refl
            .iter()
            .map(|p| {
                p.as_ref()
                    .map(|p| in_frame(p.windows, !p.source.has_coordinates(), &display))
            })
            .collect();
        let others: Vec<(&std::path::Path, ImageWindows)> = self
            .files
            .reflection_inputs()
            .into_iter()
            .zip(&windows)
            .filter_map(|((_, path), w)| Some((path, (*w)?)))
            .collect();
        check_frames(&self.files.trans, &self.frame, &others)?;
        Ok(windows
            .iter()
            .map(|w| w.map_or(PixelWindow::at_origin(0, 0), |w| relative_to(&w.data, band)))
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use glassdb_side::Side;

    use crate::colour::RegistryLuts;
    use crate::light_groups::{LightGroup, compose_groups_banded};
    use crate::lut::GlassLut;
    use crate::memory::MemoryBudget;
    use crate::{ComposeJob, ComposeSettings, FrameFiles};

    /// The light-group fixture's glass (ids 9 and 10) with r and t scaled by `k`, so that each
    /// group's table differs.
    fn group(name: &str, k: f64) -> LightGroup {
        let lut = GlassLut::from_fn(
            &[9, 10],
            |id, side, c| {
                let r = if side == Side::Front { 0.1 } else { 0.3 } * k * (2.0 - c);
                ([r, r * 0.5, r * 0.25], [k * c * f64::from(id) / 10.0; 3])
            },
            |_, _| ([0.1 * k; 3], [0.9 * k; 3]),
        );
        let basis = glassdb_registry::ColourBasis::Space(glassdb_colour::RgbSpace::Srgb);
        LightGroup {
            name: name.into(),
            luts: RegistryLuts::single(basis, lut),
        }
    }

    /// Bands of any height, aligned with the passes' blocks or not (the fixture's 6 rows are
    /// one ZIP block of 16), give the frame whole bands give, bit for bit, the beauty and each
    /// group's kept composite alike.
    #[test]
    fn any_band_height_gives_the_same_frame() {
        let fixture = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/light_groups");
        let dir = tempfile::tempdir().unwrap();
        let groups = [group("sun", 1.0), group("warm", 0.7)];
        let mut settings = ComposeSettings::default();
        settings.output.exr_data_type = Some(glassdb_encode::ExrDataType::Float);
        let frame = |rows: usize| {
            let job = ComposeJob {
                inputs: FrameFiles::new(
                    vec![fixture.join("refl.exr")],
                    fixture.join("trans.exr"),
                    fixture.join("mask.png"),
                ),
                output: dir.path().join(format!("bands_{rows}.exr")),
            };
            let budget = MemoryBudget::new(settings.decode.max_memory);
            let progress = glassdb_io::NoProgress;
            compose_groups_banded(&job, &settings, (&groups, rows), true, &budget, &progress)
                .unwrap();
            let bytes = std::fs::read(&job.output).unwrap();
            glassdb_image::read_exr_exact(&bytes, 1 << 20)
                .unwrap()
                .parts
        };
        let whole = frame(super::BAND_ROWS);
        let names: Vec<&str> = whole[0].channels.iter().map(|(n, _)| n.as_str()).collect();
        assert!(names.contains(&"ViewLayer.Combined_warm.G"), "{names:?}");
        for rows in [1, 2, 4, 5] {
            assert!(frame(rows) == whole, "bands of {rows} rows");
        }
    }
}
