//! Units built on the page: a designer puts the catalog's single glasses and gaps together
//! (outer pane, gap, inner pane, each pane turned round or not) and the server builds the
//! unit with the registry's stack engine ([`glassdb_registry::UnitBuilder`]: per wavelength
//! and angle, then the curves fitted) in the table the frames composite with, and sends its
//! record and the compositor's lookup table of it. The page computes nothing physical itself.
//! The server keeps nothing of a unit it built: the page holds the units it asked for.

use std::panic::AssertUnwindSafe;
use std::path::Path;

use glassdb_compose::lut::GlassLut;
use glassdb_registry::{
    BuildOptions, ChosenElement, GlassRecord, RegistryTable, UnitBuilder, UnitChoice,
};
use glassdb_side::Side;
use glassdb_stack::Gas;
use serde_json::Value;

use crate::ViewError;
use crate::data;
use crate::page::PageUnitLayer;

/// Most elements (layers and gaps) a unit built on the page may have: a quintuple unit.
pub const MAX_ELEMENTS: usize = 9;

/// The registry id a built unit's record carries (it is swapped into a glass's slot, so the
/// id only names it).
pub const BUILT_UNIT_ID: u16 = u16::MAX;

/// The catalog the page builds units from, loaded once, and the table they are built in.
#[derive(Debug)]
pub struct UnitWorkshop {
    builder: UnitBuilder,
    layers: Vec<PageUnitLayer>,
}

/// A unit built for the page: its record in the frames' table and that record's lookup table
/// in the page's layout ([`data::lut_bytes`]).
#[derive(Debug)]
pub struct BuiltUnit {
    /// The unit's record.
    pub record: GlassRecord,
    /// Its lookup table, [`data::LUT_BYTES`] bytes.
    pub lut: Vec<u8>,
}

impl UnitWorkshop {
    /// Loads `catalog`; units are built with the spectral method of `table` (the registry
    /// table the frames composite with).
    pub fn new(catalog: &Path, table: &RegistryTable) -> Result<UnitWorkshop, ViewError> {
        let opts = BuildOptions {
            tables: vec![table.spectral.clone()],
            ..BuildOptions::default()
        };
        let builder = UnitBuilder::new(catalog, opts).map_err(ViewError::UnitCatalog)?;
        let layers = builder
            .glasses()
            .into_iter()
            .map(|(id, name)| PageUnitLayer {
                id,
                name: name.to_string(),
            })
            .collect();
        Ok(UnitWorkshop { builder, layers })
    }

    /// The glasses a unit can be built from.
    pub fn layers(&self) -> &[PageUnitLayer] {
        &self.layers
    }

    /// Builds the unit the page asks for: `{"elements": [{"glass": ID, "flip": false},
    /// {"gap_mm": 12.7, "gas": "argon"}, …]}`, outside first ([`parse_request`]).
    pub fn build(&self, request: &Value) -> Result<BuiltUnit, ViewError> {
        let elements = parse_request(request)?;
        let name = self.name_of(&elements);
        let choice = UnitChoice {
            id: BUILT_UNIT_ID,
            name,
            elements,
        };
        // A failure of the engine on some input is an answer to the page, not the end of the
        // server.
        let built = std::panic::catch_unwind(AssertUnwindSafe(|| self.builder.build(&choice)))
            .map_err(|_| ViewError::UnitPanicked)?;
        let registry = built.map_err(ViewError::Unit)?;
        let record = registry.default_table().glasses[0].clone();
        let lut = GlassLut::from_records(&[(1, &record)]);
        let table = match (lut.side(1, Side::Front), lut.side(1, Side::Back)) {
            (Some(front), Some(back)) => data::lut_bytes([front, back], lut.group_shares(1)),
            _ => unreachable!("the table of id 1 holds id 1"),
        };
        Ok(BuiltUnit { record, lut: table })
    }

    /// A built unit's name: its layers' names (turned round: "flipped") and its gaps, outside
    /// first.
    fn name_of(&self, elements: &[ChosenElement]) -> String {
        elements
            .iter()
            .map(|e| match e {
                ChosenElement::Glass { id, flip } => {
                    let name = self
                        .layers
                        .iter()
                        .find(|l| l.id == *id)
                        .map_or_else(|| format!("glass {id}"), |l| l.name.clone());
                    if *flip {
                        format!("{name} (flipped)")
                    } else {
                        name
                    }
                }
                ChosenElement::Gap { thickness_mm, gas } => {
                    format!("{thickness_mm} mm {}", gas.name())
                }
            })
            .collect::<Vec<_>>()
            .join(" | ")
    }
}

/// The elements of a unit request, each checked: a layer is `{"glass": ID, "flip": BOOL}`
/// (flip optional), a gap `{"gap_mm": MM, "gas": GAS}` (gas optional: air) with a finite
/// width; at most [`MAX_ELEMENTS`]. The order (no two gaps in a row, a pane at each end, …) is
/// the stack engine's to check.
pub fn parse_request(request: &Value) -> Result<Vec<ChosenElement>, ViewError> {
    let bad = |element: usize, why: String| ViewError::UnitRequest { element, why };
    let Some(elements) = request.get("elements").and_then(Value::as_array) else {
        return Err(bad(
            0,
            "the request must be a JSON object with an array \"elements\"".into(),
        ));
    };
    if elements.is_empty() {
        return Err(bad(0, "a unit needs at least one pane".into()));
    }
    if elements.len() > MAX_ELEMENTS {
        return Err(bad(
            0,
            format!(
                "{} elements; a unit built on the page has at most {MAX_ELEMENTS}",
                elements.len()
            ),
        ));
    }
    elements
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let k = i + 1;
            if let Some(glass) = e.get("glass") {
                let id = glass
                    .as_u64()
                    .and_then(|v| u16::try_from(v).ok())
                    .filter(|&v| v > 0)
                    .ok_or_else(|| {
                        bad(
                            k,
                            format!("the pane's glass must be a catalog id 1–65535, not {glass}"),
                        )
                    })?;
                let flip = match e.get("flip") {
                    None | Some(Value::Null) => false,
                    Some(Value::Bool(b)) => *b,
                    Some(other) => {
                        return Err(bad(k, format!("flip must be true or false, not {other}")));
                    }
                };
                Ok(ChosenElement::Glass { id, flip })
            } else if let Some(width) = e.get("gap_mm") {
                let thickness_mm = width.as_f64().filter(|w| w.is_finite()).ok_or_else(|| {
                    bad(
                        k,
                        format!(
                            "the gap's width must be a finite number of millimetres, not {width}"
                        ),
                    )
                })?;
                let gas = match e.get("gas") {
                    None | Some(Value::Null) => Gas::Air,
                    Some(g) => Gas::ALL
                        .into_iter()
                        .find(|gas| g.as_str() == Some(gas.name()))
                        .ok_or_else(|| {
                            bad(
                                k,
                                format!(
                                    "unknown gas {g}; a gap holds {}",
                                    Gas::ALL.map(Gas::name).join(", ")
                                ),
                            )
                        })?,
                };
                Ok(ChosenElement::Gap { thickness_mm, gas })
            } else {
                Err(bad(
                    k,
                    format!(
                        "expected a pane {{\"glass\": ID}} or a gap {{\"gap_mm\": MM}}, not {e}"
                    ),
                ))
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn workshop() -> UnitWorkshop {
        let catalog = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/catalog.toml");
        let reg = glassdb_registry::default_registry().unwrap();
        UnitWorkshop::new(&catalog, reg.default_table()).unwrap()
    }

    fn said(e: ViewError) -> String {
        glassdb_io::ErrorChain(&e).to_string()
    }

    #[test]
    fn a_unit_built_on_the_page_is_the_catalogs_unit() {
        let w = workshop();
        assert!(w.layers().iter().any(|l| l.id == 6));
        assert!(
            w.layers().iter().all(|l| l.id != 12),
            "units are not layers"
        );
        let built = w
            .build(&json!({"elements": [
                {"glass": 6}, {"gap_mm": 12.7, "gas": "argon"}, {"glass": 2, "flip": false}
            ]}))
            .unwrap();
        // The bundled catalog's id 12 is the same build-up.
        let reg = glassdb_registry::default_registry().unwrap();
        let twelve = reg.default_table().glass(12).unwrap();
        let g = &built.record;
        assert_eq!(
            (g.r0, g.t0, g.r0_back),
            (twelve.r0, twelve.t0, twelve.r0_back)
        );
        assert!(
            g.name.contains("R67") && g.name.contains("12.7 mm argon"),
            "{}",
            g.name
        );
        assert_eq!(built.lut.len(), data::LUT_BYTES);
        let lut = GlassLut::from_records(&[(1, twelve)]);
        let want = data::lut_bytes(
            [
                lut.side(1, Side::Front).unwrap(),
                lut.side(1, Side::Back).unwrap(),
            ],
            lut.group_shares(1),
        );
        assert!(
            built.lut == want,
            "the table differs from the catalog unit's"
        );
    }

    #[test]
    fn bad_unit_requests_say_what_is_wrong() {
        let w = workshop();
        let build = |v: Value| said(w.build(&v).unwrap_err());
        let gap = json!({"gap_mm": 12, "gas": "argon"});
        let e = build(json!({"elements": [{"glass": 2}, gap, gap, {"glass": 2}]}));
        assert!(e.contains("two gaps in a row"), "{e}");
        let e = build(json!({"elements": [{"glass": 99}]}));
        assert!(e.contains("no glass with id 99"), "{e}");
        let e = build(json!({"elements": [{"glass": 2}, {"gap_mm": null}, {"glass": 2}]}));
        assert!(
            e.contains("element 2") && e.contains("finite number"),
            "{e}"
        );
        let e = build(json!({"elements": [{"glass": 2}, {"gap_mm": "NaN"}, {"glass": 2}]}));
        assert!(e.contains("finite number"), "{e}");
        let e = build(json!({"elements": [{"glass": 2}, {"gap_mm": -3}, {"glass": 2}]}));
        assert!(e.contains("-3"), "{e}");
        let e = build(json!({"elements": [{"glass": 2}, {"gap_mm": 9, "gas": "neon"}]}));
        assert!(e.contains("unknown gas") && e.contains("argon"), "{e}");
        let e = build(json!({"elements": [{"glass": 0}]}));
        assert!(e.contains("catalog id"), "{e}");
        let e = build(json!({"elements": []}));
        assert!(e.contains("at least one pane"), "{e}");
        let e = build(json!({"elements": vec![json!({"glass": 2}); 10]}));
        assert!(e.contains("at most 9"), "{e}");
        let e = build(json!([1, 2]));
        assert!(e.contains("\"elements\""), "{e}");
        let e = build(json!({"elements": [{"pane": 2}]}));
        assert!(e.contains("expected a pane"), "{e}");
    }
}
