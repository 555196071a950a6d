//! Header first: every input's header is read and the inputs are compared before any pixel is
//! decoded — display windows and sizes, layer choice, channel presence (the mask's channels,
//! a Cryptomatte layer and its manifest), the passes' colour space, planes in the mask when
//! several reflection passes are given — and the frame's memory is estimated from them
//! ([`crate::memory`]). A 1 MB PNG that claims 11000×11000 pixels beside 1920×1080 passes is
//! refused for its size, not decoded first.

use std::path::Path;

use glassdb_image::ImageWindows;
use glassdb_mask::MaskHeader;

use glassdb_encode::{Encoding, ExrDataType};
use glassdb_pass::{Carry, PassHeader, PassSource, PngBits};

use crate::colour::{self, PassSpace};
use crate::memory::{MemoryEstimate, MemoryItem, file_label};
use crate::place::{check_frames, in_frame};
use crate::{ComposeError, DecodeSettings, FrameFiles};

/// What a frame is decoded for, as far as reading it must know: the channels of the
/// transmission file an output carries over, and the encoding whose buffers the frame's memory
/// estimate counts (`name` says what is encoded, in the estimate's shares).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DecodeTarget {
    /// The transmission file's channels carried over.
    pub carry: Carry,
    /// The output's format and sample type or bit depth.
    pub encoding: Encoding,
    /// What is encoded, for the memory estimate's shares (an output's file name).
    pub name: String,
}

impl DecodeTarget {
    /// A frame decoded to be shown, not written (the viewer): nothing carried over, its memory
    /// counted as the 8-bit (or the passes' 16-bit) PNG a display shows.
    pub fn display() -> DecodeTarget {
        DecodeTarget {
            carry: Carry::NONE,
            encoding: Encoding::Png { bits: None },
            name: "the displayed image".into(),
        }
    }
}

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
    files: &FrameFiles,
    settings: &DecodeSettings,
    target: &DecodeTarget,
) -> Result<FramePlan, ComposeError> {
    let trans = glassdb_pass::read_pass_header(
        &files.trans,
        &settings.pass_options(Some(&settings.layers.trans)),
    )?;
    let mask = glassdb_mask::read_mask_header(&files.mask, &settings.mask)?;
    let refl = files
        .refl
        .iter()
        .enumerate()
        .map(|(k, p)| {
            glassdb_pass::read_refl_header(p, &settings.pass_options(settings.layers.refl.get(k)))
        })
        .collect::<Result<Vec<_>, _>>()?;

    let display = trans.windows.display;
    let mask_windows = in_frame(mask.windows, !mask.has_coordinates, &display);
    let mut others: Vec<(&Path, ImageWindows)> = vec![(files.mask.as_path(), mask_windows)];
    others.extend(files.refl.iter().zip(&refl).map(|(path, p)| {
        (
            path.as_path(),
            in_frame(p.windows, !p.source.has_coordinates(), &display),
        )
    }));
    check_frames(&files.trans, &trans.windows, &others)?;
    let refl_windows = others.iter().skip(1).map(|(_, w)| *w).collect();

    let declared = settings.input_space;
    let trans_space = colour::pass_space(&files.trans, &trans.colour, declared)?;
    let refl_spaces = files
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
    let space = colour::frame_space((&files.trans, trans_space), &refl_spaces)?;

    if refl.len() > 1 && !mask.stores_planes {
        return Err(ComposeError::MaskWithoutPlanes {
            mask: files.mask.clone(),
            passes: refl.len(),
        });
    }

    let memory = estimate(files, target, &trans, &refl, &mask, &mask_windows);
    Ok(FramePlan {
        space,
        display,
        refl_windows,
        memory,
    })
}

/// The frame's memory from the headers (module docs of [`crate::memory`]): the largest of its
/// three stages, decoding, compositing and encoding, with the program's overhead.
fn estimate(
    files: &FrameFiles,
    target: &DecodeTarget,
    trans: &PassHeader,
    refl: &[PassHeader],
    mask: &MaskHeader,
    mask_windows: &ImageWindows,
) -> MemoryEstimate {
    let pixels = trans.windows.data.pixel_count();
    let carried = carried_bytes(trans, target);
    let placed_mask = if mask_windows.data == trans.windows.data {
        0
    } else {
        pixels.saturating_mul(mask.bytes_per_pixel)
    };
    let output = encoding_bytes(trans, target, carried);
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
    let refl_share = |k: usize| {
        let m = &refl[k].memory;
        if by_transient.contains(&k) {
            m.peak()
        } else {
            m.kept
        }
    };
    let shares = Shares {
        trans: trans.memory.peak(),
        refl: (0..refl.len()).map(refl_share).collect(),
        mask: mask.memory.peak().saturating_add(placed_mask),
        carried,
        output,
        overhead: total - largest_stage,
    };
    MemoryEstimate {
        total,
        items: shares.items(files, target),
        carried,
    }
}

/// Bytes of the transmission file's other channels carried over into an EXR output.
fn carried_bytes(trans: &PassHeader, target: &DecodeTarget) -> u64 {
    match (&trans.source, target.encoding) {
        (PassSource::Exr { channel_names, .. }, Encoding::Exr { .. })
            if glassdb_pass::carries_whole_file(&trans.parts, channel_names, target.carry) =>
        {
            trans
                .parts
                .iter()
                .map(|p| p.stored_bytes())
                .fold(0, u64::saturating_add)
        }
        _ => 0,
    }
}

/// The encoder's own buffers for the output of `target`.
fn encoding_bytes(trans: &PassHeader, target: &DecodeTarget, carried: u64) -> u64 {
    let pixels = trans.windows.data.pixel_count();
    // Bytes per pixel of the composite (f32 R, G, B and maybe A) and of the carried channels.
    let composite_bpp = trans.memory.kept / pixels.max(1);
    let carried_bpp = carried / pixels.max(1);
    match target.encoding {
        Encoding::Exr { data_type } => {
            // A half copy of one plane at a time; the compressor's window of blocks (raw, split
            // and deflated: three copies of 16 rows of every channel, four blocks per thread).
            let half = match glassdb_encode::exr_data_type(&trans.source, data_type) {
                ExrDataType::Half => pixels.saturating_mul(2),
                ExrDataType::Float => 0,
            };
            let row_bytes = (trans.windows.data.width as u64)
                .saturating_mul(composite_bpp.saturating_add(carried_bpp));
            let rows = (16 * 4 * rayon::current_num_threads() as u64)
                .min(trans.windows.data.height as u64);
            half.saturating_add(row_bytes.saturating_mul(3 * rows))
        }
        Encoding::Png { bits } => {
            // The encoded samples and the file (at most their size); 16-bit: a big-endian copy.
            let channels = composite_bpp / 4;
            match glassdb_encode::png_bits(&trans.source, bits) {
                PngBits::Eight => pixels.saturating_mul(channels).saturating_mul(2),
                PngBits::Sixteen => pixels.saturating_mul(2 * channels).saturating_mul(3),
            }
        }
    }
}

/// The shares of a frame's estimate, in bytes, before they are named.
struct Shares {
    trans: u64,
    refl: Vec<u64>,
    mask: u64,
    carried: u64,
    output: u64,
    overhead: u64,
}

impl Shares {
    /// The shares named for messages, largest first.
    fn items(self, files: &FrameFiles, target: &DecodeTarget) -> Vec<MemoryItem> {
        let mut items = vec![MemoryItem {
            what: file_label(&files.trans),
            bytes: self.trans,
        }];
        items.extend(
            files
                .refl
                .iter()
                .zip(self.refl)
                .map(|(path, bytes)| MemoryItem {
                    what: file_label(path),
                    bytes,
                }),
        );
        items.push(MemoryItem {
            what: format!("{} (the mask)", file_label(&files.mask)),
            bytes: self.mask,
        });
        if self.carried > 0 {
            items.push(MemoryItem {
                what: format!("the channels of {} carried over", file_label(&files.trans)),
                bytes: self.carried,
            });
        }
        items.push(MemoryItem {
            what: format!("encoding {}", target.name),
            bytes: self.output,
        });
        items.push(MemoryItem {
            what: "the program and what the allocator keeps".into(),
            bytes: self.overhead,
        });
        items.sort_by(|a, b| b.bytes.cmp(&a.bytes).then_with(|| a.what.cmp(&b.what)));
        items
    }
}
