//! IGSDB JSON, both generations of the schema igsdb.lbl.gov serves:
//!
//! - v1: `spectral_data.spectral_data[]` of `{wavelength (µm), T, Rf, Rb}`, metadata at the top
//!   (`name`, `manufacturer_name`, `type`/`subtype`, `coated_side`) and `measured_data.thickness`;
//! - v2: `physical_properties.optical_properties.optical_data.angle_blocks[]`, one block per
//!   incidence angle, each with `wavelength_data[]` of `{w (µm), specular: {tf, tb, rf, rb},
//!   diffuse: {…}}` (numbers, or decimal strings); `physical_properties.thickness`.
//!
//! The 0° block is the normal-incidence spectrum; the other angles are listed in
//! [`ProductInfo::other_incidence_angles_deg`]. Shading layers, shade materials and products
//! with diffuse data are refused by name ([`UnsupportedKind`]).

use serde_json::Value;

use crate::error::{SpectralError, UnsupportedKind};
use crate::read::{Collected, Place, ProductInfo, SpectralData, SpectralFormat, microns_to_nm};

/// IGSDB subtypes (v1 kebab-case and v2 enum names, lower-cased) of shading layers.
const SHADING_SUBTYPES: &[&str] = &[
    "venetian",
    "venetian-blind",
    "venetian_blind",
    "vertical-louver",
    "vertical_louver",
    "perforated-screen",
    "perforated_screen",
    "woven",
    "woven-shade",
    "woven_shade",
    "roller-shade",
    "roller_shade",
    "cellular-shade",
    "cellular_shade",
    "pleated-shade",
    "pleated_shade",
    "roman-shade",
    "roman_shade",
    "diffusing-shade",
    "diffusing_shade",
    "solar-screen",
    "solar_screen",
];

pub(crate) fn read_igsdb_json(bytes: &[u8], source: &str) -> Result<SpectralData, SpectralError> {
    let value: Value = serde_json::from_slice(bytes).map_err(|e| SpectralError::Parse {
        source_name: source.to_owned(),
        line: e.line(),
        column: Some(e.column()),
        message: format!("invalid JSON: {e}"),
    })?;
    // A product list (the API's search results) of exactly one product is that product.
    let product = match &value {
        Value::Array(items) if items.len() == 1 => &items[0],
        Value::Array(items) => {
            return Err(SpectralError::format(
                source,
                format!(
                    "a JSON list of {} products; glassdb reads one product per file",
                    items.len()
                ),
            ));
        }
        other => other,
    };
    refuse_unsupported(product, source)?;
    let v2_blocks = product
        .pointer("/physical_properties/optical_properties/optical_data/angle_blocks")
        .filter(|b| !b.is_null());
    if let Some(blocks) = v2_blocks {
        return read_v2(product, blocks, bytes, source);
    }
    let rows = product
        .get("spectral_data")
        .and_then(|s| s.get("spectral_data").or(Some(s)))
        .and_then(Value::as_array)
        .ok_or_else(|| {
            SpectralError::format(
                source,
                "neither `spectral_data.spectral_data` (IGSDB v1) nor `physical_properties.optical_properties.optical_data.angle_blocks` (IGSDB v2): not an IGSDB glazing product",
            )
        })?;
    read_v1(product, rows, bytes, source)
}

/// Text of a metadata field: a non-blank string, or the `name` of an object.
fn text(v: Option<&Value>) -> Option<String> {
    v.and_then(|v| match v {
        Value::String(s) if !s.trim().is_empty() => Some(s.trim().to_owned()),
        Value::Object(o) => o
            .get("name")
            .and_then(Value::as_str)
            .filter(|s| !s.trim().is_empty())
            .map(|s| s.trim().to_owned()),
        _ => None,
    })
}

/// A number written as a JSON number or as a decimal string (v2 writes strings).
fn number_of(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        Value::String(s) => s.trim().parse::<f64>().ok(),
        _ => None,
    }
}

fn product_name(product: &Value) -> Option<String> {
    text(product.get("name"))
        .or_else(|| text(product.pointer("/product_description/name")))
        .or_else(|| text(product.get("product_name")))
}

/// The parts a product lists in `composition` (v1: `{child_product: {...}}` items; v2: the
/// product objects themselves), each "name (subtype, thickness mm)".
fn composition(product: &Value) -> Vec<String> {
    let Some(items) = product.get("composition").and_then(Value::as_array) else {
        return Vec::new();
    };
    items
        .iter()
        .map(|item| {
            let child = item.get("child_product").unwrap_or(item);
            let name = product_name(child).unwrap_or_else(|| "unnamed part".to_owned());
            let thickness = child
                .pointer("/measured_data/thickness")
                .or_else(|| child.pointer("/physical_properties/thickness"))
                .and_then(number_of);
            let details: Vec<String> = [
                text(child.get("subtype")),
                thickness.map(|t| format!("{t} mm")),
            ]
            .into_iter()
            .flatten()
            .collect();
            if details.is_empty() {
                name
            } else {
                format!("{name} ({})", details.join(", "))
            }
        })
        .collect()
}

/// Refuses shading layers, shade materials and non-specular products by name.
fn refuse_unsupported(product: &Value, source: &str) -> Result<(), SpectralError> {
    let name = product_name(product);
    let kind_of = |key: &str| {
        product
            .get(key)
            .and_then(Value::as_str)
            .map(|s| s.trim().to_ascii_lowercase())
    };
    let (ty, subtype) = (kind_of("type"), kind_of("subtype"));
    let written_subtype = text(product.get("subtype"));
    let shading_subtype = subtype
        .as_deref()
        .is_some_and(|s| SHADING_SUBTYPES.contains(&s));
    let kind = if ty.as_deref() == Some("shading") || shading_subtype {
        Some(UnsupportedKind::ShadingProduct {
            subtype: written_subtype,
            name,
        })
    } else if ty.as_deref() == Some("material") {
        Some(UnsupportedKind::ShadeMaterial { name })
    } else {
        let is_specular = product
            .pointer("/physical_properties/is_specular")
            .or_else(|| product.pointer("/measured_data/is_specular"))
            .and_then(Value::as_bool);
        (is_specular == Some(false) || has_diffuse_values(product))
            .then_some(UnsupportedKind::DiffuseIgsdb { name })
    };
    match kind {
        Some(kind) => Err(SpectralError::Unsupported {
            source_name: source.to_owned(),
            kind,
        }),
        None => Ok(()),
    }
}

/// Whether any v2 wavelength row carries a non-zero `diffuse` value.
fn has_diffuse_values(product: &Value) -> bool {
    let Some(blocks) = product
        .pointer("/physical_properties/optical_properties/optical_data/angle_blocks")
        .and_then(Value::as_array)
    else {
        return false;
    };
    blocks
        .iter()
        .filter_map(|b| b.get("wavelength_data").and_then(Value::as_array))
        .flatten()
        .filter_map(|row| row.get("diffuse").and_then(Value::as_object))
        .flat_map(|d| d.values())
        .any(|v| number_of(v).is_some_and(|x| x != 0.0))
}

fn read_v1(
    product: &Value,
    rows: &[Value],
    bytes: &[u8],
    source: &str,
) -> Result<SpectralData, SpectralError> {
    let info = ProductInfo {
        name: text(product.get("name")).or_else(|| text(product.get("product_name"))),
        manufacturer: text(product.get("manufacturer_name"))
            .or_else(|| text(product.get("manufacturer"))),
        product_type: text(product.get("subtype")).or_else(|| text(product.get("type"))),
        coated_side: text(product.get("coated_side")),
        thickness_mm: product
            .get("measured_data")
            .and_then(|m| m.get("thickness"))
            .and_then(Value::as_f64),
        composition: composition(product),
        ..ProductInfo::empty(SpectralFormat::IgsdbJson)
    };
    let lines = json_array_element_lines(bytes, "spectral_data", 0);
    let table = Table {
        source,
        what: "spectral_data",
        keys: ["T", "Rf", "Rb"],
        wavelength_key: "wavelength",
        group: None,
        strings: false,
    };
    table.collect(rows, &lines)?.finish([false; 3], false, info)
}

fn read_v2(
    product: &Value,
    blocks: &Value,
    bytes: &[u8],
    source: &str,
) -> Result<SpectralData, SpectralError> {
    let blocks_path = "physical_properties.optical_properties.optical_data.angle_blocks";
    let blocks = blocks
        .as_array()
        .ok_or_else(|| SpectralError::format(source, format!("`{blocks_path}` is not a list")))?;
    let mut angles = Vec::with_capacity(blocks.len());
    for (k, block) in blocks.iter().enumerate() {
        let angle = block
            .get("incidence_angle")
            .and_then(number_of)
            .filter(|a| a.is_finite())
            .ok_or_else(|| {
                SpectralError::format(
                    source,
                    format!("{blocks_path}[{k}] has no numeric `incidence_angle`"),
                )
            })?;
        angles.push(angle);
    }
    let Some(normal) = angles.iter().position(|&a| a == 0.0) else {
        let listed: Vec<String> = angles.iter().map(|a| format!("{a}°")).collect();
        return Err(SpectralError::format(
            source,
            format!(
                "no normal-incidence angle block (`incidence_angle` 0) in `{blocks_path}`; the file has {}",
                if listed.is_empty() {
                    "none".to_owned()
                } else {
                    listed.join(", ")
                }
            ),
        ));
    };
    let rows = blocks[normal]
        .get("wavelength_data")
        .and_then(Value::as_array)
        .ok_or_else(|| {
            SpectralError::format(
                source,
                format!("{blocks_path}[{normal}] has no `wavelength_data` list"),
            )
        })?;
    let physical = product.get("physical_properties");
    let info = ProductInfo {
        name: product_name(product),
        manufacturer: text(product.get("manufacturer")),
        product_type: text(product.get("subtype")).or_else(|| text(product.get("type"))),
        coated_side: text(product.get("coated_side")),
        thickness_mm: physical
            .and_then(|p| p.get("thickness"))
            .and_then(number_of),
        other_incidence_angles_deg: angles.iter().copied().filter(|&a| a != 0.0).collect(),
        composition: composition(product),
        format: SpectralFormat::IgsdbJson,
    };
    let lines = json_array_element_lines(bytes, "wavelength_data", normal);
    let table = Table {
        source,
        what: "wavelength_data",
        keys: ["tf", "rf", "rb"],
        wavelength_key: "w",
        group: Some("specular"),
        strings: true,
    };
    table.collect(rows, &lines)?.finish([false; 3], false, info)
}

/// Where the values of one JSON spectral table are.
struct Table<'a> {
    source: &'a str,
    /// The array's name, for messages.
    what: &'static str,
    /// T, Rf, Rb keys.
    keys: [&'static str; 3],
    wavelength_key: &'static str,
    /// The object inside each row that holds the values (`specular` in v2).
    group: Option<&'static str>,
    /// Decimal strings are accepted as numbers (v2).
    strings: bool,
}

impl<'a> Table<'a> {
    fn collect<'r>(
        &self,
        rows: &'r [Value],
        lines: &[usize],
    ) -> Result<Collected<'a>, SpectralError> {
        let source = self.source;
        let values_of = |row: &'r Value| -> Option<&'r Value> {
            match self.group {
                Some(g) => row.get(g),
                None => Some(row),
            }
        };
        let present: Vec<bool> = self
            .keys
            .iter()
            .map(|k| {
                rows.iter().any(|r| {
                    values_of(r)
                        .and_then(|g| g.get(*k))
                        .is_some_and(|v| !v.is_null())
                })
            })
            .collect();
        let mut collected = Collected {
            source,
            wavelength_nm: Vec::with_capacity(rows.len()),
            wavelength_places: Vec::with_capacity(rows.len()),
            quantities: [0, 1, 2].map(|k| present[k].then(|| (Vec::new(), Vec::new()))),
        };
        for (i, row) in rows.iter().enumerate() {
            let place = Place {
                line: lines.get(i).copied().unwrap_or(0),
                column: None,
            };
            let number = |obj: Option<&Value>, prefix: String, key: &str| {
                let found = obj.and_then(|o| o.get(key));
                let err = |msg: String| SpectralError::parse(source, place.line, None, msg);
                match found {
                    Some(Value::Number(n)) => n
                        .as_f64()
                        .ok_or_else(|| err(format!("{prefix}.{key} is out of range"))),
                    Some(Value::String(s)) if self.strings => {
                        let t = s.trim();
                        match t.parse::<f64>() {
                            Ok(v) if v.is_finite() => Ok(v),
                            _ => Err(err(format!(
                                "{prefix}.{key} {} is not a number",
                                glassdb_io::backticked(t)
                            ))),
                        }
                    }
                    Some(other) => Err(err(format!("{prefix}.{key} is {other}, not a number"))),
                    None => Err(err(format!("{prefix} has no `{key}`"))),
                }
            };
            let row_name = format!("{}[{i}]", self.what);
            let wl = number(Some(row), row_name.clone(), self.wavelength_key)?;
            collected.wavelength_nm.push(microns_to_nm(wl));
            collected.wavelength_places.push(place);
            let group_name = match self.group {
                Some(g) => format!("{row_name}.{g}"),
                None => row_name.clone(),
            };
            let group = values_of(row);
            if self.group.is_some() && group.is_none_or(|g| !g.is_object()) {
                return Err(SpectralError::parse(
                    source,
                    place.line,
                    None,
                    format!("{group_name} is missing or not an object"),
                ));
            }
            for (k, key) in self.keys.iter().enumerate() {
                if let Some((values, places)) = collected.quantities[k].as_mut() {
                    values.push(number(group, group_name.clone(), key)?);
                    places.push(place);
                }
            }
        }
        Ok(collected)
    }
}

/// 1-based line of each element of the `nth` (0-based) array named `key` (best effort: used only
/// to point messages at the right place in an already valid JSON text).
fn json_array_element_lines(bytes: &[u8], key: &str, nth: usize) -> Vec<usize> {
    let key = format!("\"{key}\"");
    let key = key.as_bytes();
    let mut search_from = 0;
    let mut seen = 0;
    while let Some(rel) = bytes
        .get(search_from..)
        .and_then(|b| b.windows(key.len()).position(|w| w == key))
    {
        let mut i = search_from + rel + key.len();
        search_from = i;
        while bytes.get(i).is_some_and(|b| b.is_ascii_whitespace()) {
            i += 1;
        }
        if bytes.get(i) != Some(&b':') {
            continue;
        }
        i += 1;
        while bytes.get(i).is_some_and(|b| b.is_ascii_whitespace()) {
            i += 1;
        }
        if bytes.get(i) != Some(&b'[') {
            continue;
        }
        if seen < nth {
            seen += 1;
            continue;
        }
        return element_lines(bytes, i);
    }
    Vec::new()
}

/// Lines of the objects directly inside the array that starts at `bytes[open]`.
fn element_lines(bytes: &[u8], open: usize) -> Vec<usize> {
    let mut line = 1 + bytes[..open].iter().filter(|&&b| b == b'\n').count();
    let mut depth = 0usize;
    let mut in_string = false;
    let mut escaped = false;
    let mut out = Vec::new();
    for &b in &bytes[open..] {
        if b == b'\n' {
            line += 1;
        }
        if in_string {
            if escaped {
                escaped = false;
            } else if b == b'\\' {
                escaped = true;
            } else if b == b'"' {
                in_string = false;
            }
            continue;
        }
        match b {
            b'"' => in_string = true,
            b'[' | b'{' => {
                if depth == 1 && b == b'{' {
                    out.push(line);
                }
                depth += 1;
            }
            b']' | b'}' => {
                depth = depth.saturating_sub(1);
                if depth == 0 {
                    return out;
                }
            }
            _ => {}
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v2(blocks: &str, extra: &str) -> String {
        format!(
            r#"{{"type": "GLAZING", "subtype": "MONOLITHIC", "name": "G", "manufacturer": "M",
 "coated_side": "NA"{extra},
 "physical_properties": {{"is_specular": true, "thickness": "4.0",
  "optical_properties": {{"optical_data": {{"angle_blocks": [{blocks}]}}}}}}}}"#
        )
    }

    fn block(angle: &str, t: &str) -> String {
        format!(
            r#"{{"incidence_angle": {angle}, "num_wavelengths": 9,
 "wavelength_data": [
  {{"w": "0.38", "specular": {{"tf": "{t}", "tb": "{t}", "rf": "0.08", "rb": "0.09"}}}},
  {{"w": 0.78, "specular": {{"tf": {t}, "tb": {t}, "rf": 0.07, "rb": 0.06}}}}
 ]}}"#
        )
    }

    fn read(text: &str) -> Result<SpectralData, SpectralError> {
        read_igsdb_json(text.as_bytes(), "p.json")
    }

    #[test]
    fn v2_reads_the_normal_block_and_lists_the_other_angles() {
        let text = v2(
            &[
                block("60", "0.5"),
                block("0", "0.9"),
                block("\"30\"", "0.8"),
            ]
            .join(","),
            "",
        );
        let d = read(&text).unwrap();
        assert_eq!(d.wavelength_nm, vec![380.0, 780.0]);
        assert_eq!(d.transmittance, Some(vec![0.9, 0.9]));
        assert_eq!(d.reflectance_front, Some(vec![0.08, 0.07]));
        assert_eq!(d.reflectance_back, Some(vec![0.09, 0.06]));
        let p = &d.product;
        assert_eq!(p.other_incidence_angles_deg, vec![60.0, 30.0]);
        assert_eq!(
            (p.name.as_deref(), p.manufacturer.as_deref()),
            (Some("G"), Some("M"))
        );
        assert_eq!(p.product_type.as_deref(), Some("MONOLITHIC"));
        assert_eq!(p.coated_side.as_deref(), Some("NA"));
        assert_eq!(p.thickness_mm, Some(4.0));
        // One-product lists (API search results) are that product.
        assert_eq!(read(&format!("[{text}]")).unwrap(), d);
    }

    #[test]
    fn a_laminates_composition_names_its_parts() {
        // the real laminate's file, with the composition the IGSDB lists for laminates whose
        // parts it holds (the test data's own laminates list none)
        let real = include_str!("../../../data/glazing/igsdb_product_11148.json");
        let plain = read_igsdb_json(real.as_bytes(), "l.json").unwrap();
        assert_eq!(plain.product.product_type.as_deref(), Some("laminate"));
        assert!(plain.product.composition.is_empty());
        let with_parts = real.replacen(
            "\"composition\":[]",
            r#""composition": [
              {"child_product": {"name": "SB70 on Pacifica 6mm", "subtype": "coated-glass",
                                 "measured_data": {"thickness": 6.0}}},
              {"child_product": {"name": "SentryGlas 0.090", "subtype": "interlayer",
                                 "measured_data": {"thickness": 2.286}}},
              {"child_product": {"name": "Clear 6mm", "subtype": "monolithic"}}]"#,
            1,
        );
        assert_ne!(
            with_parts, real,
            "the file has an empty composition to fill"
        );
        let d = read_igsdb_json(with_parts.as_bytes(), "l.json").unwrap();
        assert_eq!(
            d.product.composition,
            [
                "SB70 on Pacifica 6mm (coated-glass, 6 mm)",
                "SentryGlas 0.090 (interlayer, 2.286 mm)",
                "Clear 6mm (monolithic)"
            ]
        );
        assert_eq!(d.wavelength_nm, plain.wavelength_nm);
    }

    #[test]
    fn v2_errors_point_at_the_normal_blocks_rows() {
        let bad = block("0", "0.9").replacen("\"rf\": 0.07", "\"rf\": \"x\"", 1);
        let text = v2(&[block("10", "0.5"), bad].join(","), "");
        let e = read(&text).unwrap_err().to_string();
        let line = 1 + text
            .lines()
            .position(|l| l.contains("\"x\""))
            .expect("bad row");
        assert_eq!(
            e,
            format!("p.json:{line}: wavelength_data[1].specular.rf `x` is not a number")
        );
        let e = read(&v2(&block("8", "0.5"), "")).unwrap_err().to_string();
        assert!(
            e.contains("no normal-incidence angle block") && e.contains("8°"),
            "{e}"
        );
        let e = read("[{}, {}]").unwrap_err().to_string();
        assert!(e.contains("list of 2 products"), "{e}");
    }

    #[test]
    fn shading_materials_and_diffuse_products_are_named() {
        let unsupported = |text: &str| match read(text) {
            Err(SpectralError::Unsupported { kind, .. }) => kind,
            other => panic!("{other:?}"),
        };
        let kind = unsupported(
            r#"{"type": "SHADING", "subtype": "VENETIAN_BLIND", "product_description": {"name": "Slat 25"}}"#,
        );
        assert_eq!(
            kind.to_string(),
            "is an IGSDB shading product (venetian blind, \"Slat 25\"); glassdb reads glazing (specular) products only"
        );
        let kind = unsupported(r#"{"type": "glazing", "subtype": "woven"}"#);
        assert!(matches!(kind, UnsupportedKind::ShadingProduct { .. }));
        let kind = unsupported(r#"{"type": "material", "subtype": "monolithic", "name": "White"}"#);
        assert_eq!(
            kind,
            UnsupportedKind::ShadeMaterial {
                name: Some("White".into())
            }
        );
        let not_specular =
            v2(&block("0", "0.9"), "").replace("\"is_specular\": true", "\"is_specular\": false");
        assert!(matches!(
            unsupported(&not_specular),
            UnsupportedKind::DiffuseIgsdb { .. }
        ));
        let with_diffuse = v2(&block("0", "0.9"), "").replacen(
            "\"specular\": {\"tf\": 0.9",
            "\"diffuse\": {\"tf\": \"0.01\"}, \"specular\": {\"tf\": 0.9",
            1,
        );
        assert!(with_diffuse.contains("diffuse"));
        assert!(matches!(
            unsupported(&with_diffuse),
            UnsupportedKind::DiffuseIgsdb { .. }
        ));
        // All-zero diffuse values are specular data.
        let zero_diffuse = with_diffuse.replace("\"0.01\"", "0");
        assert!(read(&zero_diffuse).is_ok());
    }
}
