//! Encoding flat `f32` channels as a single-part OpenEXR file (the EXR mask format).

use std::io::Cursor;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, SmallVec,
    WritableImage,
};

use crate::ImageError;

/// Encodes `channels` (name, `width * height` row-major samples) as a ZIP-compressed scan-line
/// EXR of 32-bit float channels, in memory. Channels are stored sorted by name, as EXR requires.
pub fn encode_exr_f32(
    width: usize,
    height: usize,
    channels: Vec<(&str, Vec<f32>)>,
) -> Result<Vec<u8>, ImageError> {
    if let Some((_, bad)) = channels.iter().find(|(_, v)| v.len() != width * height) {
        return Err(ImageError::SampleCount {
            samples: bad.len(),
            width: u32::try_from(width).unwrap_or(u32::MAX),
            height: u32::try_from(height).unwrap_or(u32::MAX),
            channels: 1,
        });
    }
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .into_iter()
        .map(|(name, samples)| AnyChannel::new(name, FlatSamples::F32(samples)))
        .collect();
    let layer = Layer::new(
        (width, height),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    let mut out = Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut out)
        .map_err(ImageError::ExrEncode)?;
    Ok(out.into_inner())
}
