//! The export: a folder that shows the same page without glassdb, from `file://` or any static
//! host. Browsers refuse `fetch()` of local files, so the data travels as scripts that the
//! page loads with `<script>` tags: `data.js` (the scene, every candidate product's lookup
//! table, the chosen products and exposure) and one `frame-NNNN.js` per frame (its passes and
//! mask), beside `index.html`, `viewer.js` and `viewer.css`. Every file lands together or not
//! at all (`glassdb_io::StagedOutput`).
//!
//! The binary data is stored compactly ([`packed_base64`]): the passes as half floats, the
//! tables and the mask as `f32` (RGBA texels), each element replaced by its difference from
//! the same channel of the texel before (the integer difference of their bits, wrapping: a
//! smooth curve's neighbours differ in their low bits only), the elements' bytes gathered by
//! position (byte 0 of every element, then byte 1, …), then gzip (libdeflate), then base64;
//! the page undoes it, inflating with the browser's own `DecompressionStream`. The values are
//! the page's exactly.
//!
//! What an export does to a folder that exists (docs/reliability.md): it writes into an empty
//! folder, or one that holds a previous export (recognised by its [`MARKER`] file), replacing
//! that export's files; any other folder with something in it is refused unless the user says
//! `--force` ([`ExportFolder::force`]). A symbolic link in the folder is never followed: an
//! export file whose name is a link replaces the link itself, so a link planted there cannot
//! send a file elsewhere. A previous export's frame files that this one does not write are
//! removed.

use std::io::Write;
use std::path::{Path, PathBuf};

use base64::Engine;
use base64::display::Base64Display;
use base64::engine::general_purpose::STANDARD;
use glassdb_io::StagedOutput;
use serde_json::json;

use crate::page::PageProduct;
use crate::units::BuiltUnit;
use crate::{GlassChoice, ViewError, Viewer, assets};

/// What an export wrote: its files and their size on disk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExportSummary {
    /// Files written.
    pub files: usize,
    /// Their bytes in all.
    pub bytes: u64,
}

/// Elements per texel: the differences are taken channel by channel.
const TEXEL_ELEMENTS: usize = 4;

/// `bytes`, little-endian elements of `element_bytes` (2 or 4) each, in RGBA texels, as the
/// export stores them: differences from the texel before, bytes gathered by position, gzip,
/// base64 (see the module docs).
pub fn packed_base64(bytes: &[u8], element_bytes: usize) -> std::io::Result<String> {
    let k = element_bytes.clamp(1, 4);
    let n = bytes.len() / k;
    let value = |i: usize| {
        bytes[i * k..(i + 1) * k]
            .iter()
            .rev()
            .fold(0u32, |v, &b| (v << 8) | u32::from(b))
    };
    let mut planes = vec![0u8; n * k];
    for i in 0..n {
        let prev = if i >= TEXEL_ELEMENTS {
            value(i - TEXEL_ELEMENTS)
        } else {
            0
        };
        let delta = value(i).wrapping_sub(prev);
        for b in 0..k {
            planes[b * n + i] = (delta >> (8 * b)) as u8;
        }
    }
    let level = libdeflater::CompressionLvl::new(9).unwrap_or_default();
    let mut compressor = libdeflater::Compressor::new(level);
    let mut gz = vec![0u8; compressor.gzip_compress_bound(planes.len())];
    let len = compressor
        .gzip_compress(&planes, &mut gz)
        .map_err(|e| std::io::Error::other(format!("gzip of the export's data: {e:?}")))?;
    gz.truncate(len);
    Ok(STANDARD.encode(&gz))
}

/// The file that marks a folder as an export (JSON: what wrote it and the files it wrote), so
/// that a later export recognises the folder as its own to replace.
pub const MARKER: &str = "glassdb-export.json";

/// What the marker's `format` says.
const MARKER_FORMAT: &str = "glassdb view export";

/// Where an export goes and whether it may write into a folder that holds other things.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExportFolder {
    /// The folder (created if missing; a link to a folder is taken as that folder).
    pub dir: PathBuf,
    /// Write into the folder even when it holds things that are not a previous export
    /// (`--force`): the export's own file names are replaced, links among them as links.
    pub force: bool,
}

/// How many of a refused folder's entries its message names.
const NAMED_ENTRIES: usize = 5;

impl ExportFolder {
    /// Checks that an export may write into the folder, without writing anything: it is
    /// missing, empty, a previous export, or [`ExportFolder::force`] is set; and it is a folder
    /// (or a link to one). Returns the files the previous export wrote (none otherwise).
    pub fn check(&self) -> Result<Vec<String>, ViewError> {
        let dir = &self.dir;
        let meta = match std::fs::metadata(dir) {
            Ok(meta) => meta,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
            Err(source) => {
                return Err(ViewError::ExportDir {
                    path: dir.clone(),
                    source,
                });
            }
        };
        if !meta.is_dir() {
            return Err(ViewError::ExportNotAFolder {
                path: dir.clone(),
                kind: glassdb_io::FileKind::of(&meta.file_type()),
            });
        }
        if let Some(files) = previous_export(dir) {
            return Ok(files);
        }
        let entries = std::fs::read_dir(dir).map_err(|source| ViewError::ExportDir {
            path: dir.clone(),
            source,
        })?;
        let mut names: Vec<String> = entries
            .filter_map(Result::ok)
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .take(NAMED_ENTRIES + 1)
            .collect();
        if names.is_empty() || self.force {
            return Ok(Vec::new());
        }
        names.sort();
        let more = names.len() > NAMED_ENTRIES;
        names.truncate(NAMED_ENTRIES);
        Err(ViewError::ExportFolderInUse {
            path: dir.clone(),
            entries: format!("{}{}", names.join(", "), if more { ", …" } else { "" }),
        })
    }
}

/// The files a previous export in `dir` wrote, from its [`MARKER`] (a regular file, not a link,
/// of bounded size); `None` when `dir` holds no export.
fn previous_export(dir: &Path) -> Option<Vec<String>> {
    let marker = dir.join(MARKER);
    if !std::fs::symlink_metadata(&marker).ok()?.is_file() {
        return None;
    }
    // Not recorded as an input: the export replaces it.
    let bytes = glassdb_io::read_previous_output(&marker, glassdb_io::limits::JSON).ok()?;
    let value: serde_json::Value = serde_json::from_slice(&bytes).ok()?;
    if value.get("format")?.as_str()? != MARKER_FORMAT {
        return None;
    }
    let files = value.get("files")?.as_array()?;
    Some(
        files
            .iter()
            .filter_map(|f| f.as_str())
            .filter(|f| is_export_file_name(f))
            .map(str::to_string)
            .collect(),
    )
}

/// Whether `name` is one an export writes (a plain name in the folder, never a path).
fn is_export_file_name(name: &str) -> bool {
    let frame = name
        .strip_prefix("frame-")
        .and_then(|n| n.strip_suffix(".js"))
        .is_some_and(|n| n.len() >= 4 && n.bytes().all(|b| b.is_ascii_digit()));
    frame || STATIC_FILES.contains(&name) || name == MARKER
}

/// The files every export writes, besides its frames and [`MARKER`].
const STATIC_FILES: [&str; 4] = ["index.html", "viewer.js", "viewer.css", "data.js"];

/// Writes the export of `viewer` into `folder` (created if missing; see [`ExportFolder::check`]
/// for which existing folders are refused), with the `units` built on the page among the
/// candidates (after the products), starting with `choices` (numbered as
/// [`Viewer::parse_choices_among`] numbers them) and exposure `ev`.
pub fn write_export(
    viewer: &Viewer,
    folder: &ExportFolder,
    choices: &[GlassChoice],
    ev: f64,
    units: &[BuiltUnit],
) -> Result<ExportSummary, ViewError> {
    let dir = folder.dir.as_path();
    let previous = folder.check()?;
    std::fs::create_dir_all(dir).map_err(|source| ViewError::ExportDir {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut staged = StagedOutput::new();
    let frames = viewer.frame_count();
    let frame_file = |i: usize| format!("frame-{i:04}.js");
    let mut written: Vec<String> = STATIC_FILES.iter().map(|f| f.to_string()).collect();
    written.extend((0..frames).map(frame_file));
    let data_tags = format!(
        "<script>window.GLASSDB_EXPORT_FRAME_FILES = {};</script>\n<script src=\"data.js\"></script>",
        json!((0..frames).map(frame_file).collect::<Vec<_>>())
    );
    let html = assets::INDEX_HTML.replace(assets::EXPORT_DATA_MARK, &data_tags);
    staged.write_bytes_replacing_link(&dir.join("index.html"), html.as_bytes())?;
    staged.write_bytes_replacing_link(&dir.join("viewer.js"), assets::VIEWER_JS.as_bytes())?;
    staged.write_bytes_replacing_link(&dir.join("viewer.css"), assets::VIEWER_CSS.as_bytes())?;

    let mut scene = viewer.scene().clone();
    scene.initial_glass = Some(viewer.choices_param(choices, units));
    scene.initial_ev = Some(ev);
    scene.export_available = false;
    let first = scene.products.len();
    scene.products.extend(
        units
            .iter()
            .enumerate()
            .map(|(k, u)| PageProduct::of(first + k, &u.record)),
    );
    let scene = json!(scene);
    staged.write_replacing_link(&dir.join("data.js"), |w| {
        write!(
            w,
            "window.GLASSDB_EXPORT = {{\"scene\": {scene}, \"luts\": ["
        )?;
        let luts = (0..viewer.products().len())
            .filter_map(|i| viewer.product_lut(i))
            .chain(units.iter().map(|u| u.lut.as_slice()));
        for (k, lut) in luts.enumerate() {
            let sep = if k > 0 { "," } else { "" };
            write!(w, "{sep}\"{}\"", packed_base64(lut, 4)?)?;
        }
        w.write_all(b"], \"views\": ")?;
        let views = (0..viewer.view_count()).filter_map(|i| viewer.view_data(i));
        write_base64_array(w, views.map(|v| &v[..]))?;
        w.write_all(b", \"frames\": {}};\n")
    })?;
    for i in 0..frames {
        let frame = viewer.frame(i)?;
        staged.write_replacing_link(&dir.join(frame_file(i)), |w| {
            writeln!(
                w,
                "window.GLASSDB_EXPORT.frames[{i}] = {{\"info\": {}, \"passes\": \"{}\", \"mask\": \"{}\", \"parts\": \"{}\"}};",
                json!(frame.info),
                packed_base64(&frame.passes, 2)?,
                packed_base64(&frame.mask, 4)?,
                packed_base64(&frame.parts, 4)?
            )
        })?;
    }
    let marker = json!({
        "format": MARKER_FORMAT,
        "written_by": concat!("glassdb ", env!("CARGO_PKG_VERSION")),
        "files": written,
    });
    staged.write_bytes_replacing_link(&dir.join(MARKER), format!("{marker:#}\n").as_bytes())?;
    staged.commit()?;
    // The previous export's frames beyond this one's: its own files (a link among them is
    // removed as a link), named by its marker.
    for stale in previous
        .iter()
        .filter(|f| !written.contains(f) && *f != MARKER)
    {
        let _ = std::fs::remove_file(dir.join(stale));
    }
    let bytes = written
        .iter()
        .chain(std::iter::once(&MARKER.to_string()))
        .filter_map(|f| std::fs::symlink_metadata(dir.join(f)).ok())
        .map(|m| m.len())
        .sum();
    Ok(ExportSummary {
        files: written.len() + 1,
        bytes,
    })
}

/// A JSON array of base64 strings, one per item, as `serde_json` writes it.
fn write_base64_array<'a>(
    w: &mut impl Write,
    items: impl Iterator<Item = &'a [u8]>,
) -> std::io::Result<()> {
    w.write_all(b"[")?;
    for (k, bytes) in items.enumerate() {
        if k > 0 {
            w.write_all(b",")?;
        }
        write!(w, "\"{}\"", Base64Display::new(bytes, &STANDARD))?;
    }
    w.write_all(b"]")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The page's unpacking (viewer.js `packedBytes`), here: gunzip, each element's bytes
    /// taken back from their planes, the differences summed.
    fn unpacked(text: &str, element_bytes: usize) -> Vec<u8> {
        let gz = STANDARD.decode(text).unwrap();
        let mut planes = vec![0u8; 1 << 20];
        let n = libdeflater::Decompressor::new()
            .gzip_decompress(&gz, &mut planes)
            .unwrap();
        planes.truncate(n);
        let count = n / element_bytes;
        let mask = if element_bytes == 4 {
            u32::MAX
        } else {
            (1 << (8 * element_bytes)) - 1
        };
        let mut values: Vec<u32> = (0..count)
            .map(|i| {
                (0..element_bytes).fold(0, |v, b| v | u32::from(planes[b * count + i]) << (8 * b))
            })
            .collect();
        for i in TEXEL_ELEMENTS..count {
            values[i] = values[i].wrapping_add(values[i - TEXEL_ELEMENTS]) & mask;
        }
        values
            .iter()
            .flat_map(|v| v.to_le_bytes().into_iter().take(element_bytes))
            .collect()
    }

    #[test]
    fn packed_data_unpacks_to_the_same_bytes_and_is_smaller() {
        let floats: Vec<u8> = (0..4096)
            .flat_map(|i| ((0.9 - 0.3 * (f64::from(i) / 4096.0).powi(3)) as f32).to_le_bytes())
            .collect();
        let packed = packed_base64(&floats, 4).unwrap();
        assert_eq!(unpacked(&packed, 4), floats);
        assert!(
            packed.len() * 2 < floats.len(),
            "{} of {}",
            packed.len(),
            floats.len()
        );
        let halves: Vec<u8> = (0..1000u16)
            .flat_map(|h| (h.wrapping_mul(40_503)).to_le_bytes())
            .collect();
        assert_eq!(unpacked(&packed_base64(&halves, 2).unwrap(), 2), halves);
        assert_eq!(
            unpacked(&packed_base64(&[], 4).unwrap(), 4),
            Vec::<u8>::new()
        );
    }
}
