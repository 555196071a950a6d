//! What an output carries over from the transmission pass's file besides the composite: its
//! windows always, an EXR's attributes, and (when asked) every other part and channel exactly
//! as stored. It is read with the transmission pass itself ([`read_transmission`]), from one
//! open file, and written by glassdb-encode.

use std::path::Path;

use glassdb_colour::RgbSpace;
use glassdb_image::{
    ExactExr, ExrImageAttributes, ExrLayerAttributes, ExrPart, ImageHeader, ImageWindows,
};

use crate::PassError;
use crate::read::{
    Pass, PassReadOptions, PassSource, channel_names, decode_err, layer_channels, open_seekable,
    read_err, read_exr_pass, read_layer, read_pass_bytes, rewind,
};

/// Which of the transmission file's channels an output carries over besides the composite.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Carry {
    /// Keep the file's other channels and parts (an EXR output with `--keep-channels all`).
    pub keep_channels: bool,
    /// The composite goes beside the original layer (as a new layer) instead of replacing it.
    pub beside: bool,
}

impl Carry {
    /// Nothing but the attributes (a PNG output, the viewer).
    pub const NONE: Carry = Carry {
        keep_channels: false,
        beside: false,
    };
}

/// What of the transmission pass's file an output carries besides the composite.
#[derive(Debug, Clone)]
pub struct CarriedFrame {
    /// The output's data and display windows: the transmission pass's.
    pub windows: ImageWindows,
    /// For an EXR transmission pass: its attributes, and its other channels when kept.
    pub exr: Option<ExrCarried>,
    /// The colour space to tag an EXR output with (`chromaticities`, and `colorInteropID` on
    /// the composite's part); `None` leaves the carried attributes as they are.
    pub tag_space: Option<RgbSpace>,
}

/// The parts of an EXR transmission file written into the output.
#[derive(Debug, Clone)]
pub enum ExrCarried {
    /// The file's shared attributes and the chosen part's own; no other channels. The
    /// composite keeps the layer's channel names (`names`: R, G, B, then A) when the file holds
    /// nothing else and channels are kept; `None`: bare `R`, `G`, `B`, `A`.
    Attributes {
        /// The file's shared attributes.
        image: Box<ExrImageAttributes>,
        /// The chosen part's own attributes.
        part: Box<ExrLayerAttributes>,
        /// The layer's channel names, kept for the composite (see above).
        names: Option<Vec<String>>,
    },
    /// Every part exactly as stored; the composite replaces (or goes beside) the chosen layer's
    /// channels `channel_names` (R, G, B, then A if any) of part `part`.
    Whole {
        /// Every part and channel, exactly as stored.
        file: ExactExr,
        /// The part holding the chosen layer.
        part: usize,
        /// The layer's channels as stored: R, G, B, then A if any.
        channel_names: Vec<String>,
    },
}

impl CarriedFrame {
    /// A whole frame of `width × height` at the origin, with nothing carried over.
    pub fn whole(width: u32, height: u32) -> CarriedFrame {
        CarriedFrame {
            windows: ImageWindows::full_frame(width as usize, height as usize),
            exr: None,
            tag_space: None,
        }
    }

    /// The frame of a transmission pass read from `bytes` (the file `path`): attributes always,
    /// every part and channel when `keep_channels` and the file holds more than the layer or
    /// the composite goes `beside` the original layer.
    fn of_transmission(
        pass: &Pass,
        bytes: &[u8],
        path: &Path,
        carry: Carry,
        max_pixels: u64,
    ) -> Result<CarriedFrame, PassError> {
        let PassSource::Exr {
            part,
            channel_names,
            ..
        } = &pass.source
        else {
            return Ok(CarriedFrame {
                windows: pass.windows,
                exr: None,
                tag_space: None,
            });
        };
        let parts = glassdb_image::read_exr_headers(bytes).map_err(|s| decode_err(path, s))?;
        if !carries_whole_file(&parts, channel_names, carry) {
            return Self::with_attributes(
                pass.windows,
                (*part, channel_names),
                &parts,
                bytes,
                path,
                carry.keep_channels,
            );
        }
        let file = glassdb_image::read_exr_exact(bytes, max_pixels).map_err(|source| {
            PassError::KeepChannels {
                path: path.to_path_buf(),
                source,
            }
        })?;
        Ok(CarriedFrame {
            windows: pass.windows,
            exr: Some(ExrCarried::Whole {
                file,
                part: *part,
                channel_names: channel_names.clone(),
            }),
            tag_space: None,
        })
    }

    /// The frame (`windows`) of an EXR transmission pass (`parts`, the file's headers; its
    /// layer in part `part`, channels `channel_names`) of which only the attributes are carried
    /// over, read from `header` (the file from its start: only its headers are read).
    fn with_attributes(
        windows: ImageWindows,
        (part, channel_names): (usize, &[String]),
        parts: &[ExrPart],
        header: impl std::io::Read,
        path: &Path,
        keep_channels: bool,
    ) -> Result<CarriedFrame, PassError> {
        let (image, part) =
            glassdb_image::read_exr_attributes(header, part).map_err(|s| decode_err(path, s))?;
        Ok(CarriedFrame {
            windows,
            exr: Some(ExrCarried::Attributes {
                image: Box::new(image),
                part: Box::new(part),
                names: (keep_channels && only_the_layer(parts, channel_names))
                    .then(|| channel_names.to_vec()),
            }),
            tag_space: None,
        })
    }
}

/// Reads the transmission pass and what the output carries over from it, from one open file
/// (a file replaced meanwhile cannot mix two versions): an EXR whose other channels are not
/// carried is decoded by seeking (its blocks are read as they are decoded, never the whole
/// file at once), then its headers again for the attributes; otherwise the whole file is read.
pub fn read_transmission(
    path: &Path,
    opts: &PassReadOptions,
    carry: Carry,
) -> Result<(Pass, CarriedFrame), PassError> {
    let (mut file, header, len) = open_seekable(path, opts.max_pixels)?;
    if let ImageHeader::Exr(headers) = &header {
        let (chosen, _) = read_layer(&headers.parts, opts, path)?;
        let names = headers
            .parts
            .get(chosen.part)
            .map_or_else(Vec::new, |p| channel_names(p, &layer_channels(&chosen)));
        if !carries_whole_file(&headers.parts, &names, carry) {
            let pass = read_exr_pass(&headers.parts, path, opts, |part, channels| {
                glassdb_image::read_exr_channel_rows_from(
                    &mut file,
                    &headers.parts,
                    part,
                    channels,
                    opts.max_pixels,
                    None,
                )
            })?;
            rewind(&mut file, path)?;
            let frame = match &pass.source {
                PassSource::Exr {
                    part,
                    channel_names,
                    ..
                } => CarriedFrame::with_attributes(
                    pass.windows,
                    (*part, channel_names),
                    &headers.parts,
                    file,
                    path,
                    carry.keep_channels,
                )?,
                PassSource::Png { .. } => CarriedFrame {
                    windows: pass.windows,
                    exr: None,
                    tag_space: None,
                },
            };
            return Ok((pass, frame));
        }
    }
    let bytes = glassdb_io::read_open_input(file, len, glassdb_image::IMAGE_FILE)
        .map_err(|cause| read_err(path, cause))?;
    let pass = read_pass_bytes(&bytes, path, opts)?;
    let frame = CarriedFrame::of_transmission(&pass, &bytes, path, carry, opts.max_pixels)?;
    Ok((pass, frame))
}

/// What an output carries over from the transmission file `path` whose pass (the layer
/// `opts` chooses) was read before: as [`read_transmission`] carries it with `carry`, less
/// the channels `leave_out` names (by their full names: a light-split frame's group layers,
/// which the output replaces by their sum), never held. The file is read by seeking, one block
/// per decoding thread at a time, not whole.
pub fn read_carried(
    path: &Path,
    opts: &PassReadOptions,
    carry: Carry,
    leave_out: &dyn Fn(&str) -> bool,
) -> Result<CarriedFrame, PassError> {
    let (mut file, header, _) = open_seekable(path, opts.max_pixels)?;
    let headers = match header {
        ImageHeader::Png(png) => return Ok(CarriedFrame::whole(png.width, png.height)),
        ImageHeader::Exr(headers) => headers,
    };
    let (chosen, _) = read_layer(&headers.parts, opts, path)?;
    let info = headers.parts.get(chosen.part).ok_or_else(|| {
        decode_err(
            path,
            glassdb_image::ImageError::Unsupported {
                feature: format!("part {}", chosen.part),
            },
        )
    })?;
    let names = channel_names(info, &layer_channels(&chosen));
    let windows = info.windows();
    if !carries_whole_file(&headers.parts, &names, carry) {
        return CarriedFrame::with_attributes(
            windows,
            (chosen.part, &names),
            &headers.parts,
            file,
            path,
            carry.keep_channels,
        );
    }
    let keep = |name: &str| !leave_out(name);
    let file =
        glassdb_image::read_exr_exact_keeping(&mut file, &headers.parts, opts.max_pixels, &keep)
            .map_err(|source| PassError::KeepChannels {
                path: path.to_path_buf(),
                source,
            })?;
    Ok(CarriedFrame {
        windows,
        exr: Some(ExrCarried::Whole {
            file,
            part: chosen.part,
            channel_names: names,
        }),
        tag_space: None,
    })
}

/// Whether the output carries every part and channel of the transmission file (`parts`, its
/// chosen layer's channels `channel_names`): when they are kept and the file holds more than
/// the layer, or the composite goes beside the original layer.
pub fn carries_whole_file(parts: &[ExrPart], channel_names: &[String], carry: Carry) -> bool {
    carry.keep_channels && (carry.beside || !only_the_layer(parts, channel_names))
}

/// Whether the file (`parts`) holds nothing but the chosen layer's channels `channel_names`.
fn only_the_layer(parts: &[ExrPart], channel_names: &[String]) -> bool {
    parts.len() == 1
        && parts
            .first()
            .is_some_and(|p| p.channels.len() == channel_names.len())
}
