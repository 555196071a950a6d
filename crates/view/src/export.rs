//! The export: a folder that shows the same page without glassdb, from `file://` or any static
//! host. Browsers refuse `fetch()` of local files, so the data travels as scripts that the
//! page loads with `<script>` tags: `data.js` (the scene, every candidate product's lookup
//! table in base64, the chosen products and exposure) and one `frame-NNNN.js` per frame (its
//! passes and mask in base64), beside `index.html`, `viewer.js` and `viewer.css`. Every file
//! lands together or not at all (`glassdb_io::StagedOutput`).

use std::io::Write;
use std::path::Path;

use base64::display::Base64Display;
use base64::engine::general_purpose::STANDARD;
use glassdb_io::StagedOutput;
use serde_json::json;

use crate::{GlassChoice, ViewError, Viewer, assets};

/// Writes the export of `viewer` into `dir` (created if missing), starting with `choices`
/// and exposure `ev`.
pub fn write_export(
    viewer: &Viewer,
    dir: &Path,
    choices: &[GlassChoice],
    ev: f64,
) -> Result<(), ViewError> {
    let dir_error = |source| ViewError::ExportDir {
        path: dir.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(dir_error)?;
    if !std::fs::metadata(dir).map_err(dir_error)?.is_dir() {
        return Err(dir_error(std::io::Error::other("not a directory")));
    }
    let mut staged = StagedOutput::new();
    let frames = viewer.frame_count();
    let frame_file = |i: usize| format!("frame-{i:04}.js");
    let data_tags = format!(
        "<script>window.GLASSDB_EXPORT_FRAME_FILES = {};</script>\n<script src=\"data.js\"></script>",
        json!((0..frames).map(frame_file).collect::<Vec<_>>())
    );
    let html = assets::INDEX_HTML.replace(assets::EXPORT_DATA_MARK, &data_tags);
    staged.write_bytes(&dir.join("index.html"), html.as_bytes())?;
    staged.write_bytes(&dir.join("viewer.js"), assets::VIEWER_JS.as_bytes())?;
    staged.write_bytes(&dir.join("viewer.css"), assets::VIEWER_CSS.as_bytes())?;

    let mut scene = viewer.scene().clone();
    scene.initial_glass = Some(viewer.choices_param(choices));
    scene.initial_ev = Some(ev);
    scene.export_available = false;
    let scene = json!(scene);
    staged.write(&dir.join("data.js"), |w| {
        write!(
            w,
            "window.GLASSDB_EXPORT = {{\"scene\": {scene}, \"luts\": "
        )?;
        let luts = (0..viewer.products().len()).filter_map(|i| viewer.product_lut(i));
        write_base64_array(w, luts)?;
        w.write_all(b", \"views\": ")?;
        let views = (0..viewer.view_count()).filter_map(|i| viewer.view_data(i));
        write_base64_array(w, views.map(|v| &v[..]))?;
        w.write_all(b", \"frames\": {}};\n")
    })?;
    for i in 0..frames {
        let frame = viewer.frame(i)?;
        staged.write(&dir.join(frame_file(i)), |w| {
            writeln!(
                w,
                "window.GLASSDB_EXPORT.frames[{i}] = {{\"info\": {}, \"passes\": \"{}\", \"mask\": \"{}\"}};",
                json!(frame.info),
                Base64Display::new(&frame.passes, &STANDARD),
                Base64Display::new(&frame.mask, &STANDARD)
            )
        })?;
    }
    staged.commit()?;
    Ok(())
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
