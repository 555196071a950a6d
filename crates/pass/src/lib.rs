//! Render passes in linear light, as the compositor and the viewer read them.
//!
//! - [`pixels`]: linear and encoded pixels as different types ([`LinearImage`],
//!   [`EncodedImage`]), and the conversions between them.
//! - [`read`]: a pass's header first ([`read_pass_header`]: windows, layer, colour tags,
//!   memory), then the pixels of its RGB layer ([`read_pass`], [`read_pass_rows`]).
//! - [`carry`]: what an output carries from the transmission pass's file ([`CarriedFrame`]:
//!   windows, attributes, other channels as [`Carry`] asks), read with the pass itself
//!   ([`read_transmission`]).
//! - [`groups`]: the light-group layers of a pass ([`light_group_layers_of`]).

#![warn(missing_docs)]

pub mod carry;
mod error;
pub mod groups;
pub mod pixels;
pub mod read;

pub use carry::{
    CarriedFrame, Carry, ExrCarried, carries_whole_file, read_carried, read_transmission,
};
pub use error::PassError;
pub use groups::{GroupLayer, GroupNaming, light_group_layers_of, light_group_of_layer};
pub use pixels::{EncodedImage, EncodedSamples, InputTransfer, LinearImage, PngBits};
pub use read::{
    LightMix, Pass, PassHeader, PassReadOptions, PassSource, plane_group_layers_of,
    plane_layers_of, read_pass, read_pass_bytes, read_pass_header, read_pass_rows,
    read_refl_header,
};
