//! The composite written as a file, atomically: an EXR in the transmission pass's windows with
//! its attributes, the channels carried over ([`glassdb_pass::CarriedFrame`]), glassdb's
//! provenance and the passes' colour tags (half or float, any compression `exr` writes, ZIP
//! deflated in parallel); or a PNG of 8 or 16 bits through a display view
//! ([`glassdb_colour::DisplayView`]), un-premultiplied.
//!
//! An output is described once, where it is written ([`OutputOptions`] and its path); what
//! the work before writing must know of it is [`Encoding`] (the compositor's memory estimate)
//! and the checks of [`check_output`] (refusals before any pixel is read).

#![warn(missing_docs)]

mod error;
mod exr_file;
mod png_file;

use std::path::{Path, PathBuf};

use glassdb_colour::DisplayView;
use glassdb_image::ExrSampleType;
use glassdb_pass::{CarriedFrame, LinearImage, PassSource, PngBits};

pub use error::EncodeError;
pub use exr_file::{
    DEFAULT_EXR_COMPRESSION, EXR_COMPRESSIONS, exr_compression_name, parse_exr_compression,
};

/// EXR sample type of the output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExrDataType {
    /// 16-bit half float.
    Half,
    /// 32-bit float.
    Float,
}

/// Output file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// OpenEXR, scene-linear.
    Exr,
    /// PNG, display-encoded through a [`DisplayView`].
    Png,
}

// Each format's name is its file extension.
glassdb_io::enum_names!(OutputFormat { Exr => "exr", Png => "png" });

/// The output format from the extension (`.exr`, `.png`, any case).
pub fn output_format(path: &Path) -> Result<OutputFormat, EncodeError> {
    glassdb_io::lowercase_extension(path)
        .and_then(|ext| OutputFormat::from_name(&ext))
        .ok_or_else(|| EncodeError::OutputExtension {
            path: path.to_path_buf(),
        })
}

/// Output encoding settings; `None` fields take defaults from the transmission pass.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputOptions {
    /// EXR sample type (`None`: the transmission pass's).
    pub exr_data_type: Option<ExrDataType>,
    /// EXR compression (`None`: [`DEFAULT_EXR_COMPRESSION`]).
    pub exr_compression: Option<exr::compression::Compression>,
    /// zlib level (0–9) of ZIP/ZIPS output; `None`: OpenEXR's default, 4.
    pub exr_zip_level: Option<u32>,
    /// PNG bits per sample (`None`: the transmission pass's, 8 for EXR input).
    pub png_bits: Option<PngBits>,
    /// Ordered dither for 8-bit PNG output.
    pub dither: bool,
    /// View transform of PNG output (`None`: [`DisplayView::Standard`]). Given for an EXR
    /// output, which stays scene-linear, it is an error ([`EncodeError::ViewOnExr`]).
    pub view: Option<DisplayView>,
    /// EXR output keeps the transmission file's other channels and parts (Z, AOVs, other
    /// views), unchanged.
    pub keep_channels: bool,
    /// EXR output writes the composite as this new layer (`NAME.R`, …) beside the original
    /// channels instead of replacing the transmission pass's RGB.
    pub output_layer: Option<String>,
    /// Attributes glassdb adds to EXR output (name, text): its version, the registry's hash.
    /// Names start with `glassdb/`; those the transmission file carries are replaced.
    pub provenance: Vec<(String, String)>,
}

impl Default for OutputOptions {
    fn default() -> Self {
        OutputOptions {
            exr_data_type: None,
            exr_compression: None,
            exr_zip_level: None,
            png_bits: None,
            dither: true,
            view: None,
            keep_channels: true,
            output_layer: None,
            provenance: Vec::new(),
        }
    }
}

/// What a frame will be encoded as, as far as the work before writing must know: the format,
/// and the sample type or bit depth asked for (`None`: the transmission pass's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// An EXR of this sample type.
    Exr {
        /// As asked, else the transmission pass's ([`exr_data_type`]).
        data_type: Option<ExrDataType>,
    },
    /// A PNG of these bits per sample.
    Png {
        /// As asked, else the transmission pass's ([`png_bits`]).
        bits: Option<PngBits>,
    },
}

impl Encoding {
    /// The encoding of an output at `path` (format from its extension) written with `opts`.
    pub fn of(path: &Path, opts: &OutputOptions) -> Result<Encoding, EncodeError> {
        Ok(match output_format(path)? {
            OutputFormat::Exr => Encoding::Exr {
                data_type: opts.exr_data_type,
            },
            OutputFormat::Png => Encoding::Png {
                bits: opts.png_bits,
            },
        })
    }

    /// Its file format.
    pub fn format(&self) -> OutputFormat {
        match self {
            Encoding::Exr { .. } => OutputFormat::Exr,
            Encoding::Png { .. } => OutputFormat::Png,
        }
    }
}

/// What was written.
#[derive(Debug, Clone, PartialEq)]
pub struct WrittenOutput {
    /// The file.
    pub path: PathBuf,
    /// Its format.
    pub format: OutputFormat,
    /// e.g. "half, zip" or "8-bit, dithered".
    pub encoding: String,
    /// Its size.
    pub bytes: u64,
    /// Finite samples too large for half float, written as ±65504, the largest finite half
    /// (half output only).
    pub half_overflow: u64,
    /// The first of them: its channel, pixel and value.
    pub first_half_overflow: Option<glassdb_image::ClampedSample>,
    /// Channels and parts carried over from the transmission file besides the composite.
    pub kept_channels: usize,
}

/// Refuses, before any work is done, an output that could not be written as asked: a name
/// without a `.exr` or `.png` extension, a display view for an EXR (scene-linear), a new
/// layer name EXR cannot hold. Returns its format.
pub fn check_output(path: &Path, opts: &OutputOptions) -> Result<OutputFormat, EncodeError> {
    let format = output_format(path)?;
    if opts.view.is_some() && format == OutputFormat::Exr {
        return Err(EncodeError::ViewOnExr {
            path: path.to_path_buf(),
        });
    }
    if let Some(name) = &opts.output_layer {
        exr_file::check_layer_name(name)?;
    }
    Ok(format)
}

/// Writes `image` to `path` (format from the extension), atomically, in `frame`: the
/// transmission pass's windows, and for an EXR output its attributes and the channels carried
/// over. `source` (the transmission pass's storage) gives the defaults: its EXR sample type
/// (half for 8-bit PNG input, float for 16-bit), its PNG bit depth (8 for EXR input).
pub fn write_output(
    path: &Path,
    image: LinearImage,
    frame: CarriedFrame,
    source: &PassSource,
    opts: &OutputOptions,
) -> Result<WrittenOutput, EncodeError> {
    let format = output_format(path)?;
    if opts.view.is_some() && format == OutputFormat::Exr {
        return Err(EncodeError::ViewOnExr {
            path: path.to_path_buf(),
        });
    }
    let data_type = exr_data_type(source, opts.exr_data_type);
    let bits = png_bits(source, opts.png_bits);
    let written = match format {
        OutputFormat::Exr => exr_file::write_exr_output(path, image, frame, data_type, opts)?,
        OutputFormat::Png => png_file::write_png_output(path, image, bits, opts)?,
    };
    Ok(WrittenOutput {
        path: path.to_path_buf(),
        format,
        encoding: written.encoding,
        bytes: written.bytes,
        half_overflow: written.half_overflow,
        first_half_overflow: written.first_half_overflow,
        kept_channels: written.kept_channels,
    })
}

/// What one format's writer reports.
pub(crate) struct Written {
    pub(crate) bytes: u64,
    pub(crate) encoding: String,
    pub(crate) half_overflow: u64,
    pub(crate) first_half_overflow: Option<glassdb_image::ClampedSample>,
    pub(crate) kept_channels: usize,
}

/// The EXR output's sample type: `asked`, else the transmission pass's (half for 8-bit PNG
/// input, float for 16-bit).
pub fn exr_data_type(source: &PassSource, asked: Option<ExrDataType>) -> ExrDataType {
    asked.unwrap_or(match source {
        PassSource::Exr {
            sample_type: ExrSampleType::Half,
            ..
        } => ExrDataType::Half,
        PassSource::Exr { .. } => ExrDataType::Float,
        PassSource::Png {
            bits: PngBits::Eight,
        } => ExrDataType::Half,
        PassSource::Png {
            bits: PngBits::Sixteen,
        } => ExrDataType::Float,
    })
}

/// The PNG output's bits per sample: `asked`, else the transmission pass's (8 for EXR input).
pub fn png_bits(source: &PassSource, asked: Option<PngBits>) -> PngBits {
    asked.unwrap_or(match source {
        PassSource::Png { bits } => *bits,
        PassSource::Exr { .. } => PngBits::Eight,
    })
}
