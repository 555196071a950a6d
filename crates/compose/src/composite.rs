//! The composite phase: a decoded frame's reflection passes placed with their planes' sides,
//! the kernel ([`crate::kernel`]) run in place on the transmission pass, and what the report
//! says of the frame.

use std::collections::BTreeMap;

use glassdb_image::{ImageWindows, PixelWindow};
use glassdb_mask::MaskImage;
use glassdb_side::Side;

use crate::colour::{ChosenTable, PassSpace};
use crate::decode::MaskOnce;
use crate::kernel::{self, KernelCounts, KernelInput, OutsidePass, PlacedGroupRefl, PlacedRefl};
use crate::lut::GlassLut;
use crate::memory::MemoryEstimate;
use crate::{ComposeError, ComposeSettings, DecodedFrame, OutsidePolicy};

/// The composite of a frame, ready to be written, and what the report says of it.
pub(crate) struct Composited {
    /// The transmission pass, composited in place, with what its output carries.
    pub(crate) image: ToWrite,
    pub(crate) facts: FrameFacts,
}

/// What is written: the composite in the transmission pass's frame, and the passes' space.
pub(crate) struct ToWrite {
    pub(crate) trans: glassdb_pass::Pass,
    pub(crate) frame: glassdb_pass::CarriedFrame,
    pub(crate) space: PassSpace,
    pub(crate) table: ChosenTable,
}

/// The report's facts of a composited frame.
pub(crate) struct FrameFacts {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) windows: ImageWindows,
    pub(crate) id_counts: BTreeMap<u16, u64>,
    pub(crate) cos_range: Option<(f64, f64)>,
    pub(crate) counts: KernelCounts,
    pub(crate) outside_pixels: u64,
    pub(crate) folded_pixels: u64,
    pub(crate) memory: MemoryEstimate,
}

/// The kernel over one frame: each reflection pass (its R, G, B planes and its window relative
/// to the frame) placed with its plane's side, composited in place on `trans`, glass outside a
/// cropped pass treated as `settings` says; a unit's pane groups from `groups` (none: each
/// plane's pass takes every group's share, as `--surfaces 1`). Files and arrays
/// (`compose_in_memory`) alike.
pub(crate) fn run_kernel<'a>(
    trans: [&mut [f32]; 3],
    refl: impl Iterator<Item = (&'a [Vec<f32>; 3], PixelWindow)>,
    groups: &[PlacedGroupRefl<'a>],
    mask: &MaskImage,
    lut: &GlassLut,
    settings: &ComposeSettings,
) -> Result<KernelCounts, ComposeError> {
    let placed: Vec<PlacedRefl<'_>> = refl
        .enumerate()
        .map(|(k, ([r, g, b], window))| PlacedRefl {
            rgb: [r.as_slice(), g.as_slice(), b.as_slice()],
            window,
            side: settings.plane_sides.get(&k).copied().unwrap_or(Side::Front),
        })
        .collect();
    let outside_mode = match settings.decode.outside {
        OutsidePolicy::Transmission => OutsidePass::Transmission,
        OutsidePolicy::Error | OutsidePolicy::NoReflection => OutsidePass::NoReflection,
    };
    let input = KernelInput::placed(trans, &placed, mask, lut, outside_mode)?
        .with_groups(groups, settings.decode.max_groups)?;
    Ok(kernel::compose_in_place(input))
}

/// The composite phase: every reflection pass placed in the frame with its plane's side, the
/// kernel run in place on the transmission pass, and the decoded passes freed beside the
/// encoder; the mask is handed back to `mask_once` where given (the next composite of the
/// frame takes it), else freed with them.
pub(crate) fn composite(
    mut frame: DecodedFrame<'_>,
    settings: &ComposeSettings,
    mask_once: Option<&MaskOnce>,
) -> Result<Composited, ComposeError> {
    let refl = frame
        .refl
        .iter()
        .map(|p| &p.image.rgb)
        .zip(frame.refl_windows.iter().copied());
    let groups: Vec<PlacedGroupRefl<'_>> = frame
        .groups
        .iter()
        .map(|g| {
            let [r, gr, b] = &g.pass.image.rgb;
            PlacedGroupRefl {
                plane: g.plane,
                group: g.group,
                rgb: [r.as_slice(), gr.as_slice(), b.as_slice()],
                window: g.window,
            }
        })
        .collect();
    let [r, g, b] = &mut frame.trans.image.rgb;
    let counts = run_kernel([r, g, b], refl, &groups, &frame.mask, frame.lut, settings)?;
    let cos_range = frame.mask.cos_theta_range();
    drop(groups);
    // Returning a frame's decoded passes to the system takes tens of milliseconds on one core;
    // another thread does it while the encoder keeps both cores busy.
    // Where no thread can be started, the closure, and so the passes, are dropped here.
    let (refl, groups) = (frame.refl, frame.groups);
    let mask = match mask_once {
        Some(once) => {
            once.give_back(frame.mask, frame.trans.windows);
            None
        }
        None => Some(frame.mask),
    };
    let _ = std::thread::Builder::new()
        .name("glassdb-free".into())
        .spawn(move || drop((refl, groups, mask)));
    let trans = frame.trans;
    let facts = FrameFacts {
        width: trans.image.width,
        height: trans.image.height,
        windows: trans.windows,
        id_counts: frame.id_counts,
        cos_range,
        counts,
        outside_pixels: frame.outside.values().map(|(n, _)| n).sum(),
        folded_pixels: frame.folded_pixels,
        memory: frame.memory,
    };
    Ok(Composited {
        image: ToWrite {
            trans,
            frame: frame.frame,
            space: frame.space,
            table: frame.table,
        },
        facts,
    })
}
