//! The page's data: what `GET /api/scene` and `GET /api/frame/N` answer, and what an export's
//! `data.js` and `frame-NNNN.js` hold. Typed and versioned ([`PAGE_FORMAT`]) so that
//! `viewer.js` reads it in one place (`readScene`, `readFrame`), whichever way it came; the
//! binary data it describes is laid out as [`crate::data`] says.

use std::collections::BTreeMap;

use glassdb_colour::CubeLut;
use glassdb_registry::{GlassRecord, LuminousRecord};
use glassdb_side::Side;
use serde::Serialize;

use crate::data;

/// Value of [`PageScene::format`]; `viewer.js` refuses anything else.
pub const PAGE_FORMAT: &str = "glassdb-viewer-page/1";

/// The scene the page starts from: the frames, their colour, the candidate products and the
/// layout of their tables.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PageScene {
    /// [`PAGE_FORMAT`].
    pub format: &'static str,
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Number of reflection passes (glass planes).
    pub planes: usize,
    /// The side each plane shows the camera.
    pub plane_sides: Vec<Side>,
    /// The frames' labels: frame numbers, or the transmission pass of a single frame.
    pub frames: Vec<String>,
    /// The passes' colour space and how it was known.
    pub space: String,
    /// The registry table composited with.
    pub table: String,
    /// Whether that table is not in the passes' own space.
    pub approximate_table: bool,
    /// Row-major 3×3 matrix from the passes' space to linear Rec.709 (for the standard view),
    /// when they are in another space.
    pub display_matrix: Option<Vec<f64>>,
    /// The registry's name.
    pub registry: String,
    /// How the mask holds cos θ: `code8`, `cos` or `normal` ([`data::MaskMode`]).
    pub mask_mode: &'static str,
    /// The first frame's transmission pass.
    pub trans: String,
    /// The layout of a product's table texture.
    pub lut: LutLayout,
    /// The registry id of each glass slot (slot i starts with product i).
    pub slots: Vec<u16>,
    /// The candidate products.
    pub products: Vec<PageProduct>,
    /// The `.cube` views offered beside `standard`.
    pub views: Vec<PageDisplayView>,
    /// Whether the page's export button can write (a served page started with an export
    /// folder).
    pub export_available: bool,
    /// The products chosen first (an export's), as the `glass` parameter.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_glass: Option<String>,
    /// The exposure first shown, in stops (an export's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_ev: Option<f64>,
}

/// Where a curve's entries lie in a product's table texture ([`data::lut_bytes`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct LutLayout {
    /// Texels per row.
    pub width: usize,
    /// Rows of one curve.
    pub rows_per_curve: usize,
    /// Rows of one glass slot (four curves).
    pub rows_per_slot: usize,
    /// Offset of the fine table in a curve.
    pub fine_offset: usize,
    /// Steps of the fine table.
    pub fine_steps: usize,
    /// Offset of the normal-incidence entry in a curve.
    pub normal_offset: usize,
}

impl LutLayout {
    /// The layout [`data::lut_bytes`] writes.
    pub const TEXTURE: LutLayout = LutLayout {
        width: data::LUT_WIDTH,
        rows_per_curve: data::LUT_ROWS_PER_CURVE,
        rows_per_slot: data::LUT_ROWS_PER_SLOT,
        fine_offset: data::LUT_FINE_OFFSET,
        fine_steps: glassdb_compose::lut::FINE_STEPS,
        normal_offset: data::LUT_NORMAL_OFFSET,
    };
}

/// A candidate product, as the picker lists it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PageProduct {
    /// Its index among the products (and its table's in `/api/luts`).
    pub index: usize,
    /// Its registry id.
    pub id: u16,
    /// Its name.
    pub name: String,
    /// Normal-incidence reflectance, front, per channel.
    pub r0: [f64; 3],
    /// Normal-incidence transmittance per channel.
    pub t0: [f64; 3],
    /// Normal-incidence reflectance, back, per channel.
    pub r0_back: [f64; 3],
    /// Luminous values, when the registry has them.
    pub luminous: Option<LuminousRecord>,
    /// The angle model behind its curves.
    pub angle_model: String,
}

impl PageProduct {
    /// Product `index`, from its registry record.
    pub fn of(index: usize, g: &GlassRecord) -> PageProduct {
        PageProduct {
            index,
            id: g.id,
            name: g.name.clone(),
            r0: g.r0,
            t0: g.t0,
            r0_back: g.r0_back,
            luminous: g.luminous,
            angle_model: g.angle_model.kind.clone(),
        }
    }
}

/// A `.cube` display view as the page lists it (its `views`): its name and its tables' sizes and domains.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PageDisplayView {
    /// The file's stem.
    pub name: String,
    /// Its `TITLE`.
    pub title: Option<String>,
    /// Its 1D table, if any.
    pub shaper: Option<PageShaper>,
    /// Its 3D table, if any.
    pub cube: Option<PageCube>,
}

/// A view's 1D table, as uploaded ([`data::view_bytes`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PageShaper {
    /// Entries.
    pub len: usize,
    /// Texture rows.
    pub rows: usize,
    /// Per channel, `x·scale + offset` maps the domain to [0, 1].
    pub scale: [f32; 3],
    /// Per channel, the offset of that map.
    pub offset: [f32; 3],
}

/// A view's 3D table, as uploaded ([`data::view_bytes`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PageCube {
    /// Edge.
    pub n: usize,
    /// Per channel, `x·scale + offset` maps the domain to [0, 1].
    pub scale: [f32; 3],
    /// Per channel, the offset of that map.
    pub offset: [f32; 3],
}

impl PageDisplayView {
    /// The view of `lut`.
    pub fn of(lut: &CubeLut) -> PageDisplayView {
        let name = lut.path.file_stem().map_or_else(
            || lut.path.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        PageDisplayView {
            name,
            title: lut.title.clone(),
            shaper: lut.shaper_table().map(|t| PageShaper {
                len: t.size,
                rows: t.size.div_ceil(data::LUT_WIDTH),
                scale: t.scale,
                offset: t.offset,
            }),
            cube: lut.cube_table().map(|t| PageCube {
                n: t.size,
                scale: t.scale,
                offset: t.offset,
            }),
        }
    }
}

/// One frame, besides its binary passes and mask.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PageFrame {
    /// Glass pixels per id.
    pub ids: BTreeMap<u16, u64>,
    /// The frame's transmission pass.
    pub trans: String,
}
