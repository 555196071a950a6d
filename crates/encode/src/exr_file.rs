//! The EXR output: the composite in the transmission pass's windows, with its file's
//! attributes, the channels carried over, glassdb's provenance and the passes' colour tags,
//! written by glassdb-image's one EXR writer.

use std::io::{Seek, SeekFrom};
use std::path::Path;

use exr::meta::attribute::{AttributeValue, Text};
use glassdb_colour::RgbSpace;
use glassdb_image::{
    ExactPart, ExrImageAttributes, ExrImageOut, ExrLayerAttributes, ExrPartOut, ExrPlane,
    ExrStorage, ExrWriteOptions, ExrWriteReport, PlaneSamples,
};
use glassdb_pass::{CarriedFrame, ExrCarried, LinearImage};

use crate::{EncodeError, ExrDataType, OutputOptions, Written};

/// EXR compressions the writer offers (names as in OpenEXR / oiiotool).
pub const EXR_COMPRESSIONS: &[(&str, exr::compression::Compression)] = &[
    ("none", exr::compression::Compression::Uncompressed),
    ("rle", exr::compression::Compression::RLE),
    ("zips", exr::compression::Compression::ZIP1),
    ("zip", exr::compression::Compression::ZIP16),
    ("piz", exr::compression::Compression::PIZ),
    ("pxr24", exr::compression::Compression::PXR24),
    ("b44", exr::compression::Compression::B44),
    ("b44a", exr::compression::Compression::B44A),
    ("dwaa", exr::compression::Compression::DWAA(None)),
    ("dwab", exr::compression::Compression::DWAB(None)),
];

/// Parses an EXR compression name (`none`, `rle`, `zips`, `zip`, `piz`, `pxr24`, `b44`, `b44a`,
/// `dwaa`, `dwab`).
pub fn parse_exr_compression(name: &str) -> Result<exr::compression::Compression, EncodeError> {
    EXR_COMPRESSIONS
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, c)| *c)
        .ok_or_else(|| EncodeError::UnknownCompression {
            name: name.to_string(),
            known: EXR_COMPRESSIONS.iter().map(|(n, _)| *n).collect(),
        })
}

/// The name of a compression in [`EXR_COMPRESSIONS`].
pub fn exr_compression_name(c: exr::compression::Compression) -> &'static str {
    EXR_COMPRESSIONS
        .iter()
        .find(|(_, k)| *k == c)
        .map_or("other", |(n, _)| n)
}

/// The default output compression: ZIP (16-line blocks), compressed in parallel by libdeflate
/// (glassdb-image's `exr_zip`) and read by every EXR reader; docs/performance.md has the measured alternatives.
pub const DEFAULT_EXR_COMPRESSION: exr::compression::Compression =
    exr::compression::Compression::ZIP16;

/// The R, G, B (and A) planes of the composite, named `prefix` + channel.
fn composite_planes(image: LinearImage, names: &[String]) -> Vec<ExrPlane> {
    let LinearImage {
        rgb: [r, g, b],
        alpha,
        ..
    } = image;
    let mut planes: Vec<ExrPlane> = [r, g, b]
        .into_iter()
        .zip(names)
        .map(|(v, n)| ExrPlane::new(n, v))
        .collect();
    if let (Some(a), Some(name)) = (alpha, names.get(3)) {
        // Alpha is linear data: quantise it linearly in lossy compressions.
        planes.push(ExrPlane {
            linear: true,
            ..ExrPlane::new(name, a)
        });
    }
    planes
}

/// `R`, `G`, `B`, `A` under `layer` (`layer.R`, …), or bare.
fn layer_channel_names(layer: Option<&str>) -> Vec<String> {
    ["R", "G", "B", "A"]
        .iter()
        .map(|c| match layer {
            Some(l) => format!("{l}.{c}"),
            None => c.to_string(),
        })
        .collect()
}

/// The EXR file to write: the composite in the transmission pass's windows, with its file's
/// attributes, its other channels and parts when carried, and glassdb's provenance. Returns
/// the file and the number of channels carried over.
pub(crate) fn exr_output(
    image: LinearImage,
    frame: CarriedFrame,
    opts: &OutputOptions,
) -> (ExrImageOut, usize) {
    let CarriedFrame {
        windows,
        exr,
        tag_space,
    } = frame;
    let new_layer = opts.output_layer.as_deref();
    let (mut attributes, parts, kept) = match exr {
        None => (
            ExrImageAttributes::new(to_bounds(&windows.display)),
            vec![ExrPartOut {
                data_window: windows.data,
                attributes: ExrLayerAttributes::default(),
                planes: composite_planes(image, &layer_channel_names(new_layer)),
            }],
            0,
        ),
        Some(ExrCarried::Attributes {
            image: shared,
            part,
            names,
        }) => {
            let names = match (names, new_layer) {
                (Some(names), None) => names,
                _ => layer_channel_names(new_layer),
            };
            (
                *shared,
                vec![ExrPartOut {
                    data_window: windows.data,
                    attributes: *part,
                    planes: composite_planes(image, &names),
                }],
                0,
            )
        }
        Some(ExrCarried::Whole {
            file,
            part,
            channel_names,
        }) => {
            let (parts, kept) = carried_parts(image, file.parts, part, &channel_names, new_layer);
            (file.attributes, parts, kept)
        }
    };
    let mut parts = parts;
    replace_provenance(&mut attributes, &mut parts, &opts.provenance);
    if let Some(space) = tag_space {
        tag_colour(&mut attributes, &mut parts, space);
    }
    (
        ExrImageOut {
            display_window: windows.display,
            attributes,
            parts,
        },
        kept,
    )
}

/// The prefix of glassdb's own attributes ([`OutputOptions::provenance`]).
const PROVENANCE_PREFIX: &str = "glassdb/";

/// Sets glassdb's provenance on the output's shared attributes. The carried file's own
/// `glassdb/*` attributes (a previous composite's, in any part) describe the run that wrote it,
/// not this one: they are removed, so the provenance appears once and is this run's (the exr
/// crate refuses a name both shared and a part's own).
fn replace_provenance(
    attributes: &mut ExrImageAttributes,
    parts: &mut [ExrPartOut],
    provenance: &[(String, String)],
) {
    let ours = |name: &Text| name.to_string().starts_with(PROVENANCE_PREFIX);
    attributes.other.retain(|name, _| !ours(name));
    for part in parts.iter_mut() {
        part.attributes.other.retain(|name, _| !ours(name));
    }
    for (name, value) in provenance {
        if let (Some(name), Some(value)) = (exr_text(name), exr_text(value)) {
            attributes.other.insert(name, AttributeValue::Text(value));
        }
    }
}

/// Tags the output with `space`: `chromaticities` (shared by every part), and
/// `colorInteropID` on each part holding the composite's R, G, B (other parts, e.g. Blender's
/// `data` passes, keep theirs).
fn tag_colour(attributes: &mut ExrImageAttributes, parts: &mut [ExrPartOut], space: RgbSpace) {
    let c = space.chromaticities().map(|v| v as f32);
    attributes.chromaticities = Some(exr::meta::attribute::Chromaticities {
        red: exr::math::Vec2(c[0], c[1]),
        green: exr::math::Vec2(c[2], c[3]),
        blue: exr::math::Vec2(c[4], c[5]),
        white: exr::math::Vec2(c[6], c[7]),
    });
    let id = Text::from(space.interop_id());
    for part in parts {
        let holds_composite = part
            .planes
            .iter()
            .any(|p| matches!(p.samples, PlaneSamples::Converted(_)) && !p.linear);
        if holds_composite {
            part.attributes.other.insert(
                Text::from("colorInteropID"),
                AttributeValue::Text(id.clone()),
            );
        }
    }
}

/// Every part of the transmission file with the composite in part `part`: replacing the
/// layer's R, G, B (its alpha is the composite's alpha, unchanged), or as the new layer
/// `new_layer` (a new part of that name in a multi-part file).
fn carried_parts(
    image: LinearImage,
    parts: Vec<ExactPart>,
    part: usize,
    channel_names: &[String],
    new_layer: Option<&str>,
) -> (Vec<ExrPartOut>, usize) {
    let multi_part = parts.len() > 1;
    let mut kept = 0;
    let mut out: Vec<ExrPartOut> = Vec::with_capacity(parts.len() + 1);
    let mut composite = Some(image);
    for (k, p) in parts.into_iter().enumerate() {
        let mut planes: Vec<ExrPlane> = Vec::with_capacity(p.channels.len() + 4);
        let replacing = k == part && new_layer.is_none();
        for (name, samples) in p.channels {
            // The layer's R, G, B are replaced; its A is kept exactly (it is the output's).
            if replacing && channel_names.iter().take(3).any(|n| *n == name) {
                continue;
            }
            kept += 1;
            planes.push(ExrPlane {
                name,
                samples: PlaneSamples::Exact(samples),
                linear: false,
            });
        }
        if k == part
            && let Some(mut image) = composite.take()
        {
            let names = match new_layer {
                None => channel_names.to_vec(),
                Some(l) => layer_channel_names(Some(l)),
            };
            if new_layer.is_none() {
                image.alpha = None;
            }
            if multi_part && new_layer.is_some() {
                let mut attributes = p.attributes.clone();
                attributes.layer_name = new_layer.and_then(exr_text);
                out.push(ExrPartOut {
                    data_window: p.data_window,
                    attributes: p.attributes,
                    planes,
                });
                out.push(ExrPartOut {
                    data_window: p.data_window,
                    attributes,
                    planes: composite_planes(image, &names),
                });
                continue;
            }
            planes.extend(composite_planes(image, &names));
        }
        out.push(ExrPartOut {
            data_window: p.data_window,
            attributes: p.attributes,
            planes,
        });
    }
    (out, kept)
}

/// Writes the EXR output (module docs) of `data_type` with the compression and zip level of
/// `opts`.
pub(crate) fn write_exr_output(
    path: &Path,
    image: LinearImage,
    frame: CarriedFrame,
    data_type: ExrDataType,
    opts: &OutputOptions,
) -> Result<Written, EncodeError> {
    let compression = opts.exr_compression.unwrap_or(DEFAULT_EXR_COMPRESSION);
    let zip_level = match (
        glassdb_image::zip_block_lines(compression),
        opts.exr_zip_level,
    ) {
        (Some(_), level) => Some(level.unwrap_or(glassdb_image::DEFAULT_ZIP_LEVEL)),
        (None, None) => None,
        (None, Some(_)) => {
            return Err(EncodeError::ZipLevelNotApplicable {
                compression: exr_compression_name(compression),
            });
        }
    };
    if let Some(level) = zip_level.filter(|&l| l > 9) {
        return Err(EncodeError::ZipLevelOutOfRange { level });
    }
    let (out, kept_channels) = exr_output(image, frame, opts);
    let options = ExrWriteOptions {
        storage: match data_type {
            ExrDataType::Half => ExrStorage::Half,
            ExrDataType::Float => ExrStorage::Float,
        },
        compression,
        zip_level,
    };
    let (bytes, report) = write_exr(path, out, options)?;
    let ty = if data_type == ExrDataType::Half {
        "half"
    } else {
        "float"
    };
    let name = exr_compression_name(compression);
    let encoding = match zip_level {
        Some(level) => format!("{ty}, {name} level {level}"),
        None => format!("{ty}, {name}"),
    };
    Ok(Written {
        bytes,
        encoding,
        half_overflow: report.half_overflow,
        first_half_overflow: report.first_half_overflow,
        kept_channels,
    })
}

/// EXR text (Latin-1 bytes); `None` for text it cannot hold.
fn exr_text(s: &str) -> Option<Text> {
    Text::new_or_none(s)
}

fn to_bounds(w: &glassdb_image::PixelWindow) -> exr::meta::attribute::IntegerBounds {
    exr::meta::attribute::IntegerBounds::new(
        exr::math::Vec2(w.x, w.y),
        exr::math::Vec2(w.width, w.height),
    )
}

fn write_exr(
    path: &Path,
    image: ExrImageOut,
    options: ExrWriteOptions,
) -> Result<(u64, ExrWriteReport), EncodeError> {
    let mut size = 0u64;
    let mut report = ExrWriteReport::default();
    glassdb_io::write_atomic(path, |out| {
        let mut counting = CountingWriter {
            inner: out,
            pos: 0,
            len: 0,
        };
        report = glassdb_image::write_exr_image(&mut counting, image, options)
            .map_err(std::io::Error::other)?;
        size = counting.len;
        Ok(())
    })?;
    Ok((size, report))
}

/// Tracks the file length through seeks (exr seeks back to fill its offset table).
struct CountingWriter<W> {
    inner: W,
    pos: u64,
    len: u64,
}

impl<W: std::io::Write> std::io::Write for CountingWriter<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.pos += n as u64;
        self.len = self.len.max(self.pos);
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

impl<W: Seek> Seek for CountingWriter<W> {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.pos = self.inner.seek(pos)?;
        Ok(self.pos)
    }
}

/// Checks that `name` can be an EXR layer name (Latin-1, not empty, no dot at either end).
pub fn check_layer_name(name: &str) -> Result<(), EncodeError> {
    if exr_text(name).is_none() || name.is_empty() || name.starts_with('.') || name.ends_with('.') {
        return Err(EncodeError::BadLayerName {
            name: name.to_string(),
        });
    }
    Ok(())
}
