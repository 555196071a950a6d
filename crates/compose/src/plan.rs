//! Header first: every input's header is read and the inputs are compared before any pixel is
//! decoded — display windows and sizes, layer choice, channel presence (the mask's channels,
//! a Cryptomatte layer and its manifest), the passes' colour space, planes in the mask when
//! several reflection passes are given — and the frame's memory is estimated from them
//! ([`crate::memory`]). A 1 MB PNG that claims 11000×11000 pixels beside 1920×1080 passes is
//! refused for its size, not decoded first.

use std::path::Path;

use glassdb_image::ImageWindows;
use glassdb_mask::MaskHeader;

use crate::colour::{self, PassSpace};
use crate::io::{self, ExrDataType, OutputFormat, PassHeader, PassSource};
use crate::memory::{MemoryEstimate, MemoryItem, file_label};
use crate::pixels::PngBits;
use crate::{ComposeError, ComposeJob, ComposeSettings, check_frames, in_frame};

/// What the headers decided for one frame.
pub(crate) struct FramePlan {
    /// The passes' one colour space.
    pub(crate) space: PassSpace,
    /// The frame's display window (the transmission pass's), where a PNG mask is placed.
    pub(crate) display: glassdb_image::PixelWindow,
    /// Each reflection pass's windows in the frame as its file stores them (decoding may keep
    /// only the rows its plane's glass needs).
    pub(crate) refl_windows: Vec<ImageWindows>,
    pub(crate) memory: MemoryEstimate,
}

/// Reads every input's header and checks the frame from them (see the module docs).
pub(crate) fn plan_frame(
    job: &ComposeJob,
    settings: &ComposeSettings,
) -> Result<FramePlan, ComposeError> {
    let trans = io::read_pass_header(
        &job.trans,
        &settings.pass_options(Some(&settings.layers.trans)),
    )?;
    let mask = glassdb_mask::read_mask_header(&job.mask, &settings.mask)?;
    let refl = job
        .refl
        .iter()
        .enumerate()
        .map(|(k, p)| io::read_refl_header(p, &settings.pass_options(settings.layers.refl.get(k))))
        .collect::<Result<Vec<_>, _>>()?;

    let display = trans.windows.display;
    let mask_windows = in_frame(mask.windows, !mask.has_coordinates, &display);
    let mut others: Vec<(&Path, ImageWindows)> = vec![(job.mask.as_path(), mask_windows)];
    others.extend(job.refl.iter().zip(&refl).map(|(path, p)| {
        (
            path.as_path(),
            in_frame(p.windows, !p.source.has_coordinates(), &display),
        )
    }));
    check_frames(job, &trans.windows, &others)?;
    let refl_windows = others.iter().skip(1).map(|(_, w)| *w).collect();

    let declared = settings.input_space;
    let trans_space = colour::pass_space(&job.trans, &trans.colour, declared)?;
    let refl_spaces = job
        .refl
        .iter()
        .zip(&refl)
        .map(|(path, pass)| {
            Ok((
                path.clone(),
                colour::pass_space(path, &pass.colour, declared)?,
            ))
        })
        .collect::<Result<Vec<_>, ComposeError>>()?;
    let space = colour::frame_space((&job.trans, trans_space), &refl_spaces)?;

    if refl.len() > 1 && !mask.stores_planes {
        return Err(ComposeError::MaskWithoutPlanes {
            mask: job.mask.clone(),
            passes: refl.len(),
        });
    }

    let memory = estimate(job, settings, &trans, &refl, &mask, &mask_windows)?;
    Ok(FramePlan {
        space,
        display,
        refl_windows,
        memory,
    })
}

/// The frame's memory from the headers (module docs of [`crate::memory`]).
fn estimate(
    job: &ComposeJob,
    settings: &ComposeSettings,
    trans: &PassHeader,
    refl: &[PassHeader],
    mask: &MaskHeader,
    mask_windows: &ImageWindows,
) -> Result<MemoryEstimate, ComposeError> {
    let format = io::output_format(&job.output)?;
    let pixels = trans.windows.data.pixel_count();
    let carried = match (&trans.source, format) {
        (PassSource::Exr { channel_names, .. }, OutputFormat::Exr)
            if io::carries_whole_file(
                &trans.parts,
                channel_names,
                (
                    settings.output.keep_channels,
                    settings.output.output_layer.is_some(),
                ),
            ) =>
        {
            trans
                .parts
                .iter()
                .map(|p| p.stored_bytes())
                .fold(0, u64::saturating_add)
        }
        _ => 0,
    };
    let placed_mask = if mask_windows.data == trans.windows.data {
        0
    } else {
        pixels.saturating_mul(mask.bytes_per_pixel)
    };
    // Bytes per pixel of the composite (f32 R, G, B and maybe A) and of the carried channels.
    let composite_bpp = trans.memory.kept / pixels.max(1);
    let carried_bpp = carried / pixels.max(1);
    let output = match format {
        OutputFormat::Exr => {
            // A half copy of one plane at a time; the compressor's window of blocks (raw, split
            // and deflated: three copies of 16 rows of every channel, four blocks per thread).
            let half = match io::output_data_type(&trans.source, &settings.output) {
                ExrDataType::Half => pixels.saturating_mul(2),
                ExrDataType::Float => 0,
            };
            let row_bytes = (trans.windows.data.width as u64)
                .saturating_mul(composite_bpp.saturating_add(carried_bpp));
            let rows = (16 * 4 * rayon::current_num_threads() as u64)
                .min(trans.windows.data.height as u64);
            half.saturating_add(row_bytes.saturating_mul(3 * rows))
        }
        OutputFormat::Png => {
            // The encoded samples and the file (at most their size); 16-bit: a big-endian copy.
            let channels = composite_bpp / 4;
            match io::output_png_bits(&trans.source, &settings.output) {
                PngBits::Eight => pixels.saturating_mul(channels).saturating_mul(2),
                PngBits::Sixteen => pixels.saturating_mul(2 * channels).saturating_mul(3),
            }
        }
    };

    let kept = std::iter::once(&trans.memory)
        .chain(refl.iter().map(|p| &p.memory))
        .chain(std::iter::once(&mask.memory))
        .map(|m| m.kept)
        .fold(0, u64::saturating_add);
    // The reflection passes are decoded a few at a time (`decode_inputs`): the largest few
    // transients at once (those passes' shares count them), beside the transmission pass's
    // and the mask's.
    let mut by_transient: Vec<usize> = (0..refl.len()).collect();
    by_transient.sort_by_key(|&k| std::cmp::Reverse(refl[k].memory.transient));
    by_transient.truncate(crate::memory::decoding_at_once());
    let refl_share = |k: usize| {
        let m = &refl[k].memory;
        if by_transient.contains(&k) {
            m.peak()
        } else {
            m.kept
        }
    };
    let transient = by_transient
        .iter()
        .map(|&k| refl[k].memory.transient)
        .fold(0u64, u64::saturating_add)
        .saturating_add(trans.memory.transient)
        .saturating_add(mask.memory.transient);
    let decoding = kept.saturating_add(transient).saturating_add(carried);
    let compositing = kept.saturating_add(carried).saturating_add(placed_mask);
    let encoding = trans
        .memory
        .kept
        .saturating_add(carried)
        .saturating_add(output);
    let largest_stage = decoding.max(compositing).max(encoding);
    let total = crate::memory::with_overhead(largest_stage);

    let mut items = vec![MemoryItem {
        what: file_label(&job.trans),
        bytes: trans.memory.peak(),
    }];
    items.extend(job.refl.iter().enumerate().map(|(k, path)| MemoryItem {
        what: file_label(path),
        bytes: refl_share(k),
    }));
    items.push(MemoryItem {
        what: format!("{} (the mask)", file_label(&job.mask)),
        bytes: mask.memory.peak().saturating_add(placed_mask),
    });
    if carried > 0 {
        items.push(MemoryItem {
            what: format!("the channels of {} carried over", file_label(&job.trans)),
            bytes: carried,
        });
    }
    items.push(MemoryItem {
        what: format!("encoding {}", file_label(&job.output)),
        bytes: output,
    });
    items.push(MemoryItem {
        what: "the program and what the allocator keeps".into(),
        bytes: total - largest_stage,
    });
    items.sort_by(|a, b| b.bytes.cmp(&a.bytes).then_with(|| a.what.cmp(&b.what)));
    Ok(MemoryEstimate {
        total,
        items,
        carried,
    })
}
