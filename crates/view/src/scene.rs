//! What the viewer shows: the frames (decoded on request, the last one kept), the candidate
//! products (every record of the registry's table in the passes' space) and their lookup
//! tables, and the choice of a product per glass id.

use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use glassdb_colour::{CubeLut, RgbSpace};
use glassdb_compose::colour::RegistryLuts;
use glassdb_compose::lut::GlassLut;
use glassdb_compose::memory::MemoryBudget;
use glassdb_compose::{DecodeSettings, DecodeTarget, DecodedFrame, FrameFiles, decode_frame};
use glassdb_registry::{GlassRecord, Registry};
use glassdb_side::Side;
use glassdb_stack::Gas;

use crate::ViewError;
use crate::data::{self, MaskMode};
use crate::page::{
    LutLayout, PAGE_FORMAT, PageDisplayView, PageFrame, PageGroupPass, PageProduct, PageScene,
};
use crate::units::{BuiltUnit, UnitWorkshop};

/// The viewer's inputs: the frames' files and sides, how to read them, and the registry whose
/// records are the candidate products.
pub struct ViewerInputs {
    /// The frames, in order (at least one).
    pub frames: Vec<ViewerFrame>,
    /// How the inputs are read and checked, as `compose` reads them.
    pub settings: DecodeSettings,
    /// The registry whose records are the candidate products.
    pub registry: Registry,
    /// `.cube` display views the page offers beside `standard`.
    pub display_views: Vec<CubeLut>,
    /// The catalog whose single glasses the page builds units from (none: the page builds
    /// no units).
    pub unit_catalog: Option<PathBuf>,
}

/// One frame the viewer shows: its label on the page, its files and the side of each plane
/// the camera sees in it (a camera that moves may see a plane from the other side later).
#[derive(Debug, Clone, PartialEq)]
pub struct ViewerFrame {
    /// The frame's number, or its transmission pass for a single frame.
    pub label: String,
    /// The passes and the mask.
    pub files: FrameFiles,
    /// Side of each plane that faces the camera; planes not listed show the front.
    pub plane_sides: BTreeMap<usize, Side>,
    /// The frame's light parts, when its passes keep the light's path apart (a product change
    /// then rescales the room's light too, [`crate::relight`]).
    pub light_parts: Option<glassdb_compose::light_parts::LightParts>,
}

impl ViewerFrame {
    /// The frames of a sequence: `files` with their `#` runs expanded for each of `numbers`,
    /// every frame with the same sides; no numbers: `files` as one frame.
    pub fn sequence(
        files: &FrameFiles,
        numbers: &[u32],
        plane_sides: &BTreeMap<usize, Side>,
    ) -> Result<Vec<ViewerFrame>, ViewError> {
        if numbers.is_empty() {
            return Ok(vec![ViewerFrame {
                label: files.trans.display().to_string(),
                files: files.clone(),
                plane_sides: plane_sides.clone(),
                light_parts: None,
            }]);
        }
        numbers
            .iter()
            .map(|&n| {
                Ok(ViewerFrame {
                    label: n.to_string(),
                    files: files.for_frame(n)?,
                    plane_sides: plane_sides.clone(),
                    light_parts: None,
                })
            })
            .collect()
    }
}

/// One decoded frame as the page uploads it.
#[derive(Debug)]
pub struct FrameData {
    /// Glass pixels per id and the frame's transmission pass: the frame's JSON.
    pub info: PageFrame,
    /// Half-float passes ([`data::pass_bytes`]).
    pub passes: Vec<u8>,
    /// The mask ([`data::mask_bytes`]).
    pub mask: Vec<u8>,
    /// The light parts' passes, part after part, each packed by [`data::part_bytes`] (empty
    /// without light parts; [`crate::relight`]).
    pub parts: Vec<u8>,
}

/// A product chosen for a glass id: (id, index of the product in [`Viewer::products`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GlassChoice {
    /// The glass id.
    pub id: u16,
    /// The product's index in [`Viewer::products`].
    pub product: usize,
}

/// The loaded viewer: scene description, candidate products, frames on request.
pub struct Viewer {
    inputs: ViewerInputs,
    luts: RegistryLuts,
    budget: MemoryBudget,
    /// The candidate products: the records of the table the frames composite with.
    products: Vec<GlassRecord>,
    /// The glass slot of each product id: its first product's index.
    slots: HashMap<u16, usize>,
    /// Every product's table in the page's layout, one after the other, [`data::LUT_BYTES`]
    /// each ([`product_tables`]).
    product_luts: Arc<[u8]>,
    /// Each `.cube` view's tables as the page uploads them ([`data::view_bytes`]).
    view_tables: Vec<Arc<[u8]>>,
    scene: PageScene,
    mask_mode: MaskMode,
    /// Where units asked for on the page are built.
    units: Option<UnitWorkshop>,
    /// The last frame decoded.
    cache: Mutex<Option<(usize, Arc<FrameData>)>>,
}

impl Viewer {
    /// Decodes the first frame (checking it as `compose` does) to learn the size, the colour
    /// space and its registry table, and the mask kind.
    pub fn open(inputs: ViewerInputs) -> Result<Viewer, ViewError> {
        let luts = RegistryLuts::new(&inputs.registry);
        let budget = MemoryBudget::new(inputs.settings.max_memory);
        let first_frame = inputs.frames.first().ok_or(ViewError::NoFrames)?;
        let first_files = &first_frame.files;
        let first = decode_frame(
            first_files,
            &frame_settings(&inputs.settings, first_frame),
            &luts,
            &budget,
            &DecodeTarget::display(),
        )?;
        let (width, height, planes) = (
            first.trans.image.width,
            first.trans.image.height,
            first.refl.len(),
        );
        let (space, table) = (first.space.clone(), first.table);
        let mask_mode = MaskMode::of(&first.mask.cos_theta);
        let products = inputs
            .registry
            .table(table.basis)
            .map(|t| t.glasses.clone())
            .unwrap_or_default();
        let slots = slot_map(&products);
        let units = match &inputs.unit_catalog {
            Some(catalog) => {
                let table = inputs
                    .registry
                    .table(table.basis)
                    .unwrap_or_else(|| inputs.registry.default_table());
                Some(UnitWorkshop::new(catalog, table)?)
            }
            None => None,
        };
        let product_luts = product_tables(&products, &slots, first.lut);
        // Kept for the page's first request.
        let first_data = frame_data(&first, first_frame, &slots, &inputs.settings);
        drop(first);
        let first_data = Arc::new(crate::relight::with_parts(
            first_data,
            first_frame,
            &frame_settings(&inputs.settings, first_frame),
            &luts,
            &budget,
        )?);
        let display_matrix = (space.space != RgbSpace::Srgb).then(|| {
            let m = glassdb_colour::rgb_to_rgb(space.space, RgbSpace::Srgb);
            (0..3)
                .flat_map(|r| (0..3).map(move |c| (r, c)))
                .map(|(r, c)| m[(r, c)])
                .collect::<Vec<f64>>()
        });
        let frames: Vec<String> = inputs.frames.iter().map(|f| f.label.clone()).collect();
        let scene = PageScene {
            format: PAGE_FORMAT,
            width,
            height,
            planes,
            frames,
            space: space.to_string(),
            table: table.basis.to_string(),
            approximate_table: table.approximate,
            display_matrix,
            registry: inputs.settings.registry_label.clone(),
            mask_mode: mask_mode.name(),
            trans: first_files.trans.display().to_string(),
            lut: LutLayout::TEXTURE,
            slots: products.iter().map(|g| g.id).collect(),
            products: products
                .iter()
                .enumerate()
                .map(|(i, g)| PageProduct::of(i, g))
                .collect(),
            views: inputs
                .display_views
                .iter()
                .map(PageDisplayView::of)
                .collect(),
            unit_layers: units
                .as_ref()
                .map_or_else(Vec::new, |u| u.layers().to_vec()),
            gases: Gas::ALL.iter().map(|g| g.name()).collect(),
            export_available: false,
            initial_glass: None,
            initial_ev: None,
        };
        let view_tables = inputs
            .display_views
            .iter()
            .map(|v| data::view_bytes(v).into())
            .collect();
        Ok(Viewer {
            inputs,
            luts,
            budget,
            products,
            slots,
            product_luts,
            view_tables,
            scene,
            mask_mode,
            units,
            cache: Mutex::new(Some((0, first_data))),
        })
    }

    /// The scene the page starts from (no export button, no initial choices).
    pub fn scene(&self) -> &PageScene {
        &self.scene
    }

    /// The candidate products.
    pub fn products(&self) -> &[GlassRecord] {
        &self.products
    }

    /// Where the page's units are built, if it builds any.
    pub fn units(&self) -> Option<&UnitWorkshop> {
        self.units.as_ref()
    }

    /// How many frames there are.
    pub fn frame_count(&self) -> usize {
        self.inputs.frames.len()
    }

    /// Where product `index`'s lookup table lies in [`Viewer::all_product_luts`]: the table
    /// the compositor builds for a mask id whose record is this product's, in the page's
    /// layout ([`data::lut_bytes`]).
    pub fn product_lut_range(&self, index: usize) -> Option<Range<usize>> {
        (index < self.products.len())
            .then(|| index * data::LUT_BYTES..(index + 1) * data::LUT_BYTES)
    }

    /// Product `index`'s lookup table (see [`Viewer::product_lut_range`]).
    pub fn product_lut(&self, index: usize) -> Option<&[u8]> {
        self.product_luts.get(self.product_lut_range(index)?)
    }

    /// Every product's table, one after the other (the page loads them in one request, so a
    /// later swap needs none).
    pub fn all_product_luts(&self) -> &Arc<[u8]> {
        &self.product_luts
    }

    /// View `index`'s tables as the page uploads them ([`data::view_bytes`]).
    pub fn view_data(&self, index: usize) -> Option<&Arc<[u8]>> {
        self.view_tables.get(index)
    }

    /// How many `.cube` views there are.
    pub fn view_count(&self) -> usize {
        self.view_tables.len()
    }

    /// Frame `index` (0-based), decoded and checked as `compose` does; the last one is kept.
    pub fn frame(&self, index: usize) -> Result<Arc<FrameData>, ViewError> {
        let mut cache = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((i, data)) = cache.as_ref()
            && *i == index
        {
            return Ok(data.clone());
        }
        // Free the old frame first: two frames need not fit in memory together.
        *cache = None;
        let Some(viewer_frame) = self.inputs.frames.get(index) else {
            return Err(ViewError::NoSuchFrame {
                index,
                frames: self.inputs.frames.len(),
            });
        };
        let files = &viewer_frame.files;
        let frame = decode_frame(
            files,
            &frame_settings(&self.inputs.settings, viewer_frame),
            &self.luts,
            &self.budget,
            &DecodeTarget::display(),
        )?;
        let mode = MaskMode::of(&frame.mask.cos_theta);
        if mode != self.mask_mode {
            return Err(ViewError::MaskKindChanges {
                frame: viewer_frame.label.clone(),
                mask: files.mask.clone(),
                found: mode.name(),
                first: self.mask_mode.name(),
            });
        }
        let data = frame_data(&frame, viewer_frame, &self.slots, &self.inputs.settings);
        drop(frame);
        let data = Arc::new(crate::relight::with_parts(
            data,
            viewer_frame,
            &frame_settings(&self.inputs.settings, viewer_frame),
            &self.luts,
            &self.budget,
        )?);
        *cache = Some((index, data.clone()));
        Ok(data)
    }

    /// Parses `ID:PRODUCT,ID:PRODUCT` (PRODUCT: a product's full name, any case; its registry
    /// id; or a part of its name matching one product only). Names may hold commas: a comma
    /// starts a new choice only when `ID:` follows it.
    pub fn parse_choices(&self, spec: &str) -> Result<Vec<GlassChoice>, ViewError> {
        self.parse_choices_among(spec, &[])
    }

    /// [`Viewer::parse_choices`] among the products and `units` built on the page (numbered
    /// after the products, in their order).
    pub fn parse_choices_among(
        &self,
        spec: &str,
        units: &[BuiltUnit],
    ) -> Result<Vec<GlassChoice>, ViewError> {
        let candidates: Vec<&GlassRecord> = self
            .products
            .iter()
            .chain(units.iter().map(|u| &u.record))
            .collect();
        split_choices(spec)
            .into_iter()
            .map(|part| {
                let bad = |why: &str| ViewError::GlassSpec {
                    spec: part.to_string(),
                    why: why.to_string(),
                };
                let (id, name) = part
                    .split_once(':')
                    .ok_or_else(|| bad("expected ID:PRODUCT, e.g. 1:Clear"))?;
                let id: u16 = id
                    .trim()
                    .parse()
                    .map_err(|_| bad("the glass id must be a number 1–65535"))?;
                if !self.products.iter().any(|g| g.id == id) {
                    return Err(ViewError::UnknownGlassId { id });
                }
                Ok(GlassChoice {
                    id,
                    product: find_product_in(&candidates, name.trim())?,
                })
            })
            .collect()
    }

    /// The product a name means (see [`Viewer::parse_choices`]).
    pub fn find_product(&self, name: &str) -> Result<usize, ViewError> {
        find_product_in(&self.products.iter().collect::<Vec<_>>(), name)
    }

    /// Glass choices as the page's `glass` parameter (product names), among the products and
    /// `units` (as [`Viewer::parse_choices_among`] numbers them).
    pub fn choices_param(&self, choices: &[GlassChoice], units: &[BuiltUnit]) -> String {
        let name = |i: usize| match self.products.get(i) {
            Some(g) => &g.name,
            None => &units[i - self.products.len()].record.name,
        };
        choices
            .iter()
            .map(|c| format!("{}:{}", c.id, name(c.product)))
            .collect::<Vec<_>>()
            .join(",")
    }
}

/// The candidate a name means: its full name (any case), its registry id, or a part of its
/// name that only it has.
fn find_product_in(candidates: &[&GlassRecord], name: &str) -> Result<usize, ViewError> {
    let lower = name.to_lowercase();
    if let Some(i) = candidates
        .iter()
        .position(|g| g.name.to_lowercase() == lower)
    {
        return Ok(i);
    }
    if let Ok(id) = name.parse::<u16>()
        && let Some(i) = candidates.iter().position(|g| g.id == id)
    {
        return Ok(i);
    }
    let matches: Vec<usize> = (0..candidates.len())
        .filter(|&i| candidates[i].name.to_lowercase().contains(&lower))
        .collect();
    match matches.as_slice() {
        [i] => Ok(*i),
        [] => Err(ViewError::UnknownProduct {
            name: name.to_string(),
            candidates: candidates
                .iter()
                .map(|g| format!("{} ({})", g.name, g.id))
                .collect::<Vec<_>>()
                .join("; "),
        }),
        many => Err(ViewError::AmbiguousProduct {
            name: name.to_string(),
            matches: many
                .iter()
                .map(|&i| candidates[i].name.clone())
                .collect::<Vec<_>>()
                .join("; "),
        }),
    }
}

/// How `frame` is decoded: as `settings` say, with its units' deeper pane groups folded onto
/// their plane's pass (`compose --surfaces 1`) where it has no pane-group passes (a render
/// with `--surfaces 1`).
pub(crate) fn frame_settings(settings: &DecodeSettings, frame: &ViewerFrame) -> DecodeSettings {
    DecodeSettings {
        max_groups: if frame.files.groups.is_empty() {
            std::num::NonZeroUsize::new(1)
        } else {
            settings.max_groups
        },
        ..settings.clone()
    }
}

/// A decoded frame as the page uploads it; `slots` gives each mask id's glass slot.
fn frame_data(
    frame: &DecodedFrame<'_>,
    source: &ViewerFrame,
    slots: &HashMap<u16, usize>,
    settings: &DecodeSettings,
) -> FrameData {
    let folded = (settings.max_groups == std::num::NonZeroUsize::new(1)
        && !source.files.groups.is_empty())
    .then_some(
        "one surface per plane: the units' deeper pane groups reflect on their plane's pass",
    );
    let mut passes = data::pass_bytes(frame);
    if folded.is_none() {
        passes.extend(data::group_pass_bytes(frame));
    }
    FrameData {
        info: PageFrame {
            ids: frame.id_counts.clone(),
            trans: source.files.trans.display().to_string(),
            plane_sides: (0..frame.refl.len())
                .map(|k| source.plane_sides.get(&k).copied().unwrap_or(Side::Front))
                .collect(),
            parts: Vec::new(),
            groups: match folded {
                Some(_) => Vec::new(),
                None => frame
                    .groups
                    .iter()
                    .map(|g| PageGroupPass {
                        plane: g.plane,
                        group: g.group,
                    })
                    .collect(),
            },
            groups_folded: folded,
        },
        passes,
        mask: data::mask_bytes(frame, |id| slots.get(&id).copied()),
        parts: Vec::new(),
    }
}

/// The glass slot of each product id: the index of the first product with that id (a
/// validated registry has one product per id).
fn slot_map(products: &[GlassRecord]) -> HashMap<u16, usize> {
    let mut slots = HashMap::with_capacity(products.len());
    for (i, g) in products.iter().enumerate() {
        slots.entry(g.id).or_insert(i);
    }
    slots
}

/// Every product's table in the page's layout ([`data::lut_bytes`]), one after the other:
/// each product's entries in `lut`, the table the frames composite with, built from these
/// very records under their own ids. A product whose id does not stand for it there (id 0, or
/// an id an earlier product has: a registry that was not validated) gets a table of its own,
/// as [`GlassLut::from_records`] builds it for any id.
fn product_tables(
    products: &[GlassRecord],
    slots: &HashMap<u16, usize>,
    lut: &GlassLut,
) -> Arc<[u8]> {
    let table_of = |lut: &GlassLut, id: u16| {
        Some(data::lut_bytes(
            [lut.side(id, Side::Front)?, lut.side(id, Side::Back)?],
            lut.group_shares(id),
        ))
    };
    let mut bytes = Vec::with_capacity(products.len() * data::LUT_BYTES);
    for (i, g) in products.iter().enumerate() {
        let table = (slots.get(&g.id) == Some(&i))
            .then(|| table_of(lut, g.id))
            .flatten()
            .or_else(|| table_of(&GlassLut::from_records(&[(1, g)]), 1))
            .unwrap_or_else(|| vec![0; data::LUT_BYTES]);
        bytes.extend_from_slice(&table);
    }
    bytes.into()
}

/// `a:b,c:d` split at the commas that an `ID:` follows.
fn split_choices(spec: &str) -> Vec<&str> {
    let mut parts = Vec::new();
    let mut start = 0;
    for (i, _) in spec.match_indices(',') {
        let rest = &spec[i + 1..];
        let digits = rest
            .trim_start()
            .bytes()
            .take_while(u8::is_ascii_digit)
            .count();
        if digits > 0 && rest.trim_start()[digits..].starts_with(':') {
            parts.push(&spec[start..i]);
            start = i + 1;
        }
    }
    parts.push(&spec[start..]);
    parts.into_iter().filter(|p| !p.trim().is_empty()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A product's table, built on its own as the viewer built them before it took them
    /// from the compositor's table.
    fn own_table(g: &GlassRecord) -> Vec<u8> {
        let lut = GlassLut::from_records(&[(g.id, g)]);
        data::lut_bytes(
            [
                lut.side(g.id, Side::Front).unwrap(),
                lut.side(g.id, Side::Back).unwrap(),
            ],
            lut.group_shares(g.id),
        )
    }

    #[test]
    fn product_tables_are_each_products_own_table() {
        let reg = glassdb_registry::default_registry().unwrap();
        for table in reg.tables() {
            let products = &table.glasses;
            let slots = slot_map(products);
            let bytes = product_tables(products, &slots, &GlassLut::from_table(table));
            assert_eq!(bytes.len(), products.len() * data::LUT_BYTES);
            for (g, got) in products.iter().zip(bytes.chunks_exact(data::LUT_BYTES)) {
                assert!(got == own_table(g), "{} ({})", g.name, table.basis());
            }
        }
        // An id given twice, and id 0 (a registry not validated): each product still gets
        // its own record's table.
        let mut products = reg.default_table().glasses[..3].to_vec();
        products[1].id = products[0].id;
        products[2].id = 0;
        let slots = slot_map(&products);
        let lut = GlassLut::from_records(&[(products[0].id, &products[0])]);
        let bytes = product_tables(&products, &slots, &lut);
        for (g, got) in products.iter().zip(bytes.chunks_exact(data::LUT_BYTES)) {
            let mut own = g.clone();
            own.id = 1;
            assert!(got == own_table(&own), "{}", g.name);
        }
        assert_eq!(slots[&products[0].id], 0);
    }

    #[test]
    fn choices_split_only_where_an_id_follows_the_comma() {
        assert_eq!(
            split_choices("1:Clear float 3 mm (Generic Clear Glass, NFRC 102),5: Stopray"),
            [
                "1:Clear float 3 mm (Generic Clear Glass, NFRC 102)",
                "5: Stopray"
            ]
        );
        // A comma not followed by `ID:` belongs to the name.
        assert_eq!(split_choices("1:a, 20:b,"), ["1:a", " 20:b,"]);
        assert_eq!(split_choices("1:a,b:c"), ["1:a,b:c"]);
        assert!(split_choices("").is_empty());
    }
}
