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
use glassdb_pass::{Carry, PassHeader, PassReadOptions, PassSource, PngBits};

use crate::colour::{self, ChosenTable, PassSpace, RegistryLuts};
use crate::lut::GlassLut;
use crate::memory::{MemoryBudget, MemoryEstimate, MemoryItem, Reservation, file_label};
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

/// How each input is read: the pass options with each pass's own layer, decided once.
pub(crate) struct InputReads {
    /// The transmission pass's.
    pub(crate) trans: PassReadOptions,
    /// Reflection pass k's at k, then the pane groups' passes' in order.
    pub(crate) refl: Vec<PassReadOptions>,
}

impl InputReads {
    /// The read options of every pass of `files`: `settings.pass`, each with its own layer
    /// where `settings.layers` names one.
    fn of(files: &FrameFiles, settings: &DecodeSettings) -> InputReads {
        let with_layer = |layer: Option<&Option<String>>| {
            let mut opts = settings.pass.clone();
            if let Some(Some(l)) = layer {
                opts.layer = Some(l.clone());
            }
            opts
        };
        InputReads {
            trans: with_layer(Some(&settings.layers.trans)),
            refl: (0..files.refl.len())
                .map(|k| with_layer(settings.layers.refl.get(k)))
                .chain(files.groups.iter().map(|g| with_layer(Some(&g.layer))))
                .collect(),
        }
    }
}

/// What the headers decided for one frame: how it is read, its colour, where its inputs lie
/// and the memory held for it.
pub(crate) struct FramePlan<'a> {
    /// How each pass is read.
    pub(crate) reads: InputReads,
    /// The passes' one colour space.
    pub(crate) space: PassSpace,
    /// The registry table chosen for that space.
    pub(crate) table: ChosenTable,
    /// The lookup table of that registry table.
    pub(crate) lut: &'a GlassLut,
    /// The frame's display window (the transmission pass's), where a PNG mask is placed.
    pub(crate) display: glassdb_image::PixelWindow,
    /// The transmission pass's windows as its header states them (the frame).
    pub(crate) trans_windows: ImageWindows,
    /// Each reflection pass's windows in the frame as its file stores them (decoding may keep
    /// only the rows its plane's glass needs).
    pub(crate) refl_windows: Vec<ImageWindows>,
    /// The frame's memory estimate.
    pub(crate) memory: MemoryEstimate,
    /// The estimate held from the budget until the frame is dropped.
    pub(crate) reservation: Reservation<'a>,
}

/// The header phase: reads every input's header and checks the frame from them (see the
/// module docs), chooses the registry table for the passes' space and holds the frame's
/// memory from `budget` (refused over its limit).
pub(crate) fn plan_frame<'a>(
    files: &FrameFiles,
    settings: &DecodeSettings,
    luts: &'a RegistryLuts,
    budget: &'a MemoryBudget,
    target: &DecodeTarget,
) -> Result<FramePlan<'a>, ComposeError> {
    if files.refl.is_empty() {
        return Err(ComposeError::NoReflectionPass);
    }
    crate::pane_groups::check_group_files(files)?;
    let reads = InputReads::of(files, settings);
    let trans = glassdb_pass::read_pass_header(&files.trans, &reads.trans)?;
    let mask = glassdb_mask::read_mask_header(&files.mask, &settings.mask)?;
    let refl_files = files.reflection_inputs();
    let refl = refl_files
        .iter()
        .zip(&reads.refl)
        .map(|((_, p), opts)| glassdb_pass::read_refl_header(p, opts))
        .collect::<Result<Vec<_>, _>>()?;

    let display = trans.windows.display;
    let mask_windows = in_frame(mask.windows, !mask.has_coordinates, &display);
    let mut others: Vec<(&Path, ImageWindows)> = vec![(files.mask.as_path(), mask_windows)];
    others.extend(refl_files.iter().zip(&refl).map(|((_, path), p)| {
        (
            *path,
            in_frame(p.windows, !p.source.has_coordinates(), &display),
        )
    }));
    check_frames(&files.trans, &trans.windows, &others)?;
    let refl_windows = others.iter().skip(1).map(|(_, w)| *w).collect();

    let space = frame_space(files, settings, &trans, &refl)?;
    if files.refl.len() > 1 && !mask.stores_planes {
        return Err(ComposeError::MaskWithoutPlanes {
            mask: files.mask.clone(),
            passes: files.refl.len(),
        });
    }
    let (table, lut) = luts.for_space(&space, &files.trans, &settings.registry_label)?;

    let memory = estimate(files, target, &trans, &refl, &mask, &mask_windows);
    if memory.total > budget.limit() {
        return Err(ComposeError::MemoryLimit {
            trans: files.trans.clone(),
            estimate: memory.total,
            limit: budget.limit(),
            items: memory.items,
            carried: memory.carried,
        });
    }
    let reservation = budget.reserve(memory.total);
    Ok(FramePlan {
        reads,
        space,
        table,
        lut,
        display,
        trans_windows: trans.windows,
        refl_windows,
        memory,
        reservation,
    })
}

/// The passes' one colour space: each pass's from its header, or as declared; they must
/// agree.
fn frame_space(
    files: &FrameFiles,
    settings: &DecodeSettings,
    trans: &PassHeader,
    refl: &[PassHeader],
) -> Result<PassSpace, ComposeError> {
    let declared = settings.input_space;
    let trans_space = colour::pass_space(&files.trans, &trans.colour, declared)?;
    let refl_spaces = files
        .reflection_inputs()
        .into_iter()
        .zip(refl)
        .map(|((_, path), pass)| {
            Ok((
                path.to_path_buf(),
                colour::pass_space(path, &pass.colour, declared)?,
            ))
        })
        .collect::<Result<Vec<_>, ComposeError>>()?;
    colour::frame_space((&files.trans, trans_space), &refl_spaces)
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
        items.extend(files.reflection_inputs().into_iter().zip(self.refl).map(
            |((_, path), bytes)| MemoryItem {
                what: file_label(path),
                bytes,
            },
        ));
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
