//! The page's data: what `GET /api/scene` and `GET /api/frame/N` answer, and what an export's
//! `data.js` and `frame-NNNN.js` hold. Typed and versioned ([`PAGE_FORMAT`]) so that
//! `viewer.js` reads it in one place (`readScene`, `readFrame`), whichever way it came; the
//! binary data it describes is laid out as [`crate::data`] says.

use std::collections::BTreeMap;

use glassdb_colour::CubeLut;
use glassdb_registry::{GlassRecord, LuminousRecord, SystemValues, UnitElement, UnitRecord};
use glassdb_side::Side;
use serde::Serialize;

use crate::data;

/// Value of [`PageScene::format`]; `viewer.js` refuses anything else.
pub const PAGE_FORMAT: &str = "glassdb-viewer-page/4";

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
    /// The single glasses a unit can be built from on the page (empty: the page builds no
    /// units), in the catalog's order.
    pub unit_layers: Vec<PageUnitLayer>,
    /// The gases a gap may hold.
    pub gases: Vec<&'static str>,
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
    /// Rows of one glass slot (four curves, then the pane groups' shares).
    pub rows_per_slot: usize,
    /// Pane groups per side whose shares a slot holds (curves 4.. front, then back).
    pub groups: usize,
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
        groups: data::PAGE_GROUPS,
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
    /// Its build-up, when it is an insulated unit.
    pub unit: Option<PageUnit>,
    /// Hemispherical transmittance per channel: the factor of sky light through it (the
    /// relit swap, docs/compose.md "Relit swap").
    pub t_dif: [f64; 3],
    /// Its pane groups (1: a monolithic glass; a unit's reflection is one per group: its
    /// ghosts).
    pub pane_groups: usize,
}

/// A unit's build-up as the picker shows it: its layers and gaps, outside first, and the
/// system's WINDOW photopic values (the registry's; the page computes nothing itself).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PageUnit {
    /// Layers and gaps, outside first.
    pub elements: Vec<PageUnitElement>,
    /// The unit's thickness (mm), when every layer's is known.
    pub thickness_mm: Option<f64>,
    /// Visible transmittance and reflectance from outdoors and indoors at normal incidence
    /// (WINDOW's NFRC photopic method), when every layer has a spectrum.
    pub photopic: Option<SystemValues>,
}

/// One element of a unit's build-up.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum PageUnitElement {
    /// A pane (or a laminate).
    Layer {
        /// The product its file names, else its file.
        name: String,
        /// Its thickness (mm).
        thickness_mm: Option<f64>,
        /// Turned round in the unit.
        flipped: bool,
        /// Its angle model (`uncoated`, `coated`, `measured`, …).
        model: String,
        /// The unit's surfaces that carry its coating, numbered from outdoors (#1 the outer
        /// face of the outer pane); empty when uncoated or the file does not say which side.
        coated_surfaces: Vec<u32>,
    },
    /// A gap between panes.
    Gap {
        /// Its width (mm).
        thickness_mm: f64,
        /// Its gas.
        gas: &'static str,
    },
}

impl PageUnit {
    /// The build-up of a registry unit record.
    pub fn of(unit: &UnitRecord) -> PageUnit {
        let mut layer_index = 0u32;
        let elements = unit
            .elements
            .iter()
            .map(|e| match e {
                UnitElement::Gap(g) => PageUnitElement::Gap {
                    thickness_mm: g.thickness_mm,
                    gas: g.gas.name(),
                },
                UnitElement::Layer(l) => {
                    let product = l.provenance.product.as_ref();
                    let name = product
                        .and_then(|p| p.name.clone())
                        .or_else(|| l.provenance.spectral.as_ref().map(|f| f.path.clone()))
                        .unwrap_or_else(|| format!("layer {}", layer_index + 1));
                    let coated_side = product.and_then(|p| p.coated_side.as_deref());
                    let surfaces =
                        coated_surfaces(layer_index, coated_side.unwrap_or(""), l.flipped);
                    layer_index += 1;
                    PageUnitElement::Layer {
                        name: name.trim().to_string(),
                        thickness_mm: l.thickness_mm,
                        flipped: l.flipped,
                        model: l.model.clone(),
                        coated_surfaces: surfaces,
                    }
                }
            })
            .collect();
        PageUnit {
            elements,
            thickness_mm: unit.thickness_mm,
            photopic: unit.photopic,
        }
    }
}

/// The unit surfaces (numbered from outdoors, #1 and #2 the outer pane's) that carry the
/// coating of layer `layer` (0: outermost) whose file says its coating is on `side` (`Front`,
/// `Back`, `Both`; anything else: none), turned round or not.
fn coated_surfaces(layer: u32, side: &str, flipped: bool) -> Vec<u32> {
    let (front, back) = (2 * layer + 1, 2 * layer + 2);
    let (file_front, file_back) = if flipped {
        (back, front)
    } else {
        (front, back)
    };
    let mut out = match side.to_ascii_lowercase().as_str() {
        "front" => vec![file_front],
        "back" => vec![file_back],
        "both" => vec![file_front, file_back],
        _ => Vec::new(),
    };
    out.sort_unstable();
    out
}

/// A single glass of the catalog that the page can put in a unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PageUnitLayer {
    /// Its catalog id.
    pub id: u16,
    /// Its name.
    pub name: String,
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
            unit: g.unit.as_ref().map(PageUnit::of),
            t_dif: g.t_dif(),
            pane_groups: g.unit.as_ref().map_or(1, |u| u.groups.len().max(1)),
        }
    }
}

/// What `POST /api/unit` answers: the unit built, as a product of the picker, and the
/// compositor's lookup table of it in the page's layout ([`data::lut_bytes`]) in base64.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PageBuiltUnit {
    /// [`PAGE_FORMAT`].
    pub format: &'static str,
    /// The unit as a product (its `index` is 0: the page numbers the units it holds).
    pub product: PageProduct,
    /// Its lookup table, base64.
    pub lut: String,
    /// Milliseconds the server took to build it (stack engine, fit, table).
    pub build_ms: f64,
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
    /// The side each plane shows the camera in this frame.
    pub plane_sides: Vec<Side>,
    /// The frame's light parts, in the order of its `parts` data (none: passes without a
    /// light-path split).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub parts: Vec<crate::relight::PagePart>,
    /// The pane groups' passes composited apart, in the order of their layers after the
    /// planes' (issue 27: a unit's ghosts).
    pub groups: Vec<PageGroupPass>,
    /// Why the frame's pane-group passes are not composited apart (the units' deeper groups
    /// then reflect on their plane's pass, as `compose --surfaces 1`), if they are not.
    pub groups_folded: Option<&'static str>,
}

/// A pane group's pass in a frame's data: its plane and group (1 or more, in the order the
/// rays meet the groups from the plane's side).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct PageGroupPass {
    /// The plane.
    pub plane: usize,
    /// The pane group.
    pub group: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coated_surfaces_count_from_outdoors_and_turn_with_the_pane() {
        assert_eq!(coated_surfaces(0, "Back", false), [2]);
        assert_eq!(coated_surfaces(0, "Front", true), [2]);
        assert_eq!(coated_surfaces(2, "Front", false), [5]);
        assert_eq!(coated_surfaces(1, "both", true), [3, 4]);
        assert!(coated_surfaces(0, "Neither", false).is_empty());
        assert!(coated_surfaces(0, "NA", true).is_empty());
    }

    #[test]
    fn the_bundled_units_show_their_build_up() {
        let reg = glassdb_registry::default_registry().unwrap();
        let table = reg.default_table();
        let triple = PageProduct::of(0, table.glass(13).unwrap());
        let unit = triple.unit.expect("13 is a unit");
        let surfaces: Vec<Vec<u32>> = unit
            .elements
            .iter()
            .filter_map(|e| match e {
                PageUnitElement::Layer {
                    coated_surfaces, ..
                } => Some(coated_surfaces.clone()),
                PageUnitElement::Gap { .. } => None,
            })
            .collect();
        // Energy Advantage on #2 and #5, as the catalog's name says.
        assert_eq!(surfaces, [vec![2], vec![], vec![5]]);
        assert!(matches!(
            unit.elements[1],
            PageUnitElement::Gap { gas: "argon", thickness_mm } if thickness_mm == 12.0
        ));
        assert!(unit.photopic.is_some());
        let r67 = PageProduct::of(0, table.glass(12).unwrap()).unit.unwrap();
        assert!(matches!(
            &r67.elements[0],
            PageUnitElement::Layer { coated_surfaces, .. } if coated_surfaces == &[2]
        ));
        assert!(PageProduct::of(0, table.glass(1).unwrap()).unit.is_none());
    }
}
