//! The catalog (`catalog.toml`): one `[[glass]]` table per product, a single glass or a unit
//! built from `layers`. Keys are documented in `docs/registry.md` and `docs/stack.md`; unknown
//! keys and wrong types are errors naming the key, line and column, and every error about a
//! unit's layer names that layer's line.

use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

use crate::RegistryError;
pub use glassdb_stack::{Gas, ModelChoice};

/// The whole catalog file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Catalog {
    /// The products, in file order, with where each starts in the file.
    #[serde(default)]
    pub glass: Vec<Spanned<CatalogEntry>>,
}

/// One `[[glass]]` table.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CatalogEntry {
    /// Registration id (1–255 for 8-bit masks, up to 65535 for 16-bit masks). Read as a wide
    /// integer so that 0, negative and too-large ids get their own messages.
    pub id: i64,
    /// Product name.
    pub name: String,
    /// Spectral data file (any format `glassdb spectral` reads), relative to the catalog.
    #[serde(default)]
    pub spectral: Option<String>,
    /// The spectral file is in percent.
    #[serde(default)]
    pub spectral_percent: bool,
    /// Explicit front reflectance at normal incidence, R, G, B fractions.
    #[serde(default)]
    pub r0: Option<Vec<f64>>,
    /// Explicit transmittance at normal incidence, R, G, B fractions.
    #[serde(default)]
    pub t0: Option<Vec<f64>>,
    /// Explicit back reflectance at normal incidence (defaults to `r0`).
    #[serde(default)]
    pub r0_back: Option<Vec<f64>>,
    /// Measured angle table in the `glassdb fit` CSV format, relative to the catalog.
    #[serde(default)]
    pub angles: Option<String>,
    /// The angle table is in percent.
    #[serde(default)]
    pub angles_percent: bool,
    /// Which angle model to use when no table is given (and to continue a table to 90°).
    #[serde(default)]
    pub model: ModelChoice,
    /// Refractive index for the `opaque` model: `n`, `[n, k]`, or one `[n, k]` per channel.
    #[serde(default)]
    pub ior: Option<IorValue>,
    /// A unit: its layers and gaps, outside first (instead of the keys above).
    #[serde(default)]
    pub layers: Option<Vec<Spanned<LayerEntry>>>,
}

/// One element of a unit's `layers`: a layer (`spectral`, `angles` or `r0`/`t0`, with `model`,
/// `ior`, `thickness_mm`, `flip`) or a gap (`gap_mm`, `gas`).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerEntry {
    /// Spectral data file of the layer, relative to the catalog.
    pub spectral: Option<String>,
    /// The spectral file is in percent.
    pub spectral_percent: Option<bool>,
    /// Explicit front reflectance at normal incidence, R, G, B fractions.
    pub r0: Option<Vec<f64>>,
    /// Explicit transmittance at normal incidence, R, G, B fractions.
    pub t0: Option<Vec<f64>>,
    /// Explicit back reflectance at normal incidence (defaults to `r0`).
    pub r0_back: Option<Vec<f64>>,
    /// Measured angle table of the layer (alone: a grey layer of the table's 0° values).
    pub angles: Option<String>,
    /// The angle table is in percent.
    pub angles_percent: Option<bool>,
    /// The layer's angle model.
    pub model: Option<ModelChoice>,
    /// Refractive index for an `opaque` layer.
    pub ior: Option<IorValue>,
    /// Thickness (mm), overriding the file's.
    pub thickness_mm: Option<f64>,
    /// The layer faces the other way (its coating on the other surface).
    pub flip: Option<bool>,
    /// A gap's thickness (mm): this element is a gap.
    pub gap_mm: Option<f64>,
    /// A gap's gas: air (default), argon, krypton, xenon.
    pub gas: Option<String>,
}

/// The `ior` key: a real index, a complex `[n, k]`, or one `[n, k]` per channel (metals).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum IorValue {
    /// A real index `n` (k = 0).
    Real(f64),
    /// One complex index `[n, k]` for every channel.
    Complex([f64; 2]),
    /// One `[n, k]` per channel R, G, B.
    PerChannel([[f64; 2]; 3]),
}

impl IorValue {
    /// `(n, k)` per channel.
    pub fn per_channel(&self) -> [(f64, f64); 3] {
        match *self {
            IorValue::Real(n) => [(n, 0.0); 3],
            IorValue::Complex([n, k]) => [(n, k); 3],
            IorValue::PerChannel(v) => v.map(|[n, k]| (n, k)),
        }
    }
}

/// A validated catalog entry, ready to build.
#[derive(Debug, Clone)]
pub struct GlassSpec {
    /// Registration id.
    pub id: u16,
    /// Product name.
    pub name: String,
    /// The 1-based line of its `[[glass]]` table in the catalog.
    pub line: usize,
    /// A single glass or a unit.
    pub build: GlassBuild,
}

/// What a catalog entry is.
#[derive(Debug, Clone)]
pub enum GlassBuild {
    /// One glass (the entry's own keys).
    Single(LayerSpec),
    /// A unit: layers and gaps, outside first.
    Unit(Vec<ElementSpec>),
}

/// One layer: a single glass, or a layer of a unit.
#[derive(Debug, Clone)]
pub struct LayerSpec {
    /// Where its normal-incidence values come from.
    pub normal: NormalSource,
    /// A measured angle table (path relative to the catalog) and whether it is in percent.
    pub angles: Option<(String, bool)>,
    /// The angle model.
    pub model: ModelChoice,
    /// `(n, k)` per channel for the opaque model.
    pub ior: Option<[(f64, f64); 3]>,
    /// Faces the other way (only in a unit).
    pub flip: bool,
    /// Thickness override (mm; only in a unit).
    pub thickness_mm: Option<f64>,
    /// The 1-based catalog line of the layer (of the entry for a single glass).
    pub line: usize,
}

/// One element of a unit.
#[derive(Debug, Clone)]
pub enum ElementSpec {
    /// A layer.
    Layer(LayerSpec),
    /// A gap: thickness (mm), gas and its catalog line.
    Gap {
        /// Thickness (mm).
        thickness_mm: f64,
        /// The fill.
        gas: Gas,
        /// The 1-based catalog line.
        line: usize,
    },
}

impl ElementSpec {
    /// The element's catalog line.
    pub fn line(&self) -> usize {
        match self {
            ElementSpec::Layer(l) => l.line,
            ElementSpec::Gap { line, .. } => *line,
        }
    }
}

/// Where the normal-incidence values come from.
#[derive(Debug, Clone)]
pub enum NormalSource {
    /// A spectral file (path relative to the catalog) and whether it is in percent.
    Spectral {
        /// The file, relative to the catalog.
        path: String,
        /// Its values are in percent.
        percent: bool,
    },
    /// Explicit per-channel values.
    Explicit {
        /// Front reflectance per channel.
        r0: [f64; 3],
        /// Transmittance per channel.
        t0: [f64; 3],
        /// Back reflectance per channel.
        r0_back: [f64; 3],
    },
    /// The 0° values of the layer's measured angle table, the same at every wavelength (a grey
    /// layer; only in a unit).
    AngleTable,
}

/// The 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// Parses catalog text; `path` names it in errors.
pub fn parse_catalog(text: &str, path: &Path) -> Result<Vec<GlassSpec>, RegistryError> {
    let catalog: Catalog = toml::from_str(text).map_err(|source| RegistryError::CatalogToml {
        path: path.to_path_buf(),
        // The parser's message shows the line it stopped on, which may be megabytes long.
        message: glassdb_io::bounded_message(&source.to_string()),
    })?;
    if catalog.glass.is_empty() {
        return Err(RegistryError::CatalogSyntax {
            path: path.to_path_buf(),
            message: "no [[glass]] tables: a catalog lists at least one product".into(),
        });
    }
    let mut specs: Vec<GlassSpec> = Vec::with_capacity(catalog.glass.len());
    for entry in catalog.glass {
        let line = line_of(text, entry.span().start);
        let spec = validate_entry(entry.into_inner(), line, text, path)?;
        if let Some(first) = specs.iter().find(|s| s.id == spec.id) {
            return Err(RegistryError::DuplicateId {
                source_name: path.display().to_string(),
                id: spec.id,
                first: first.name.clone(),
                second: spec.name,
            });
        }
        specs.push(spec);
    }
    Ok(specs)
}

/// Three fractions `[R, G, B]` in [0, 1]; `err` builds the error from a message.
fn rgb(
    values: &[f64],
    key: &str,
    err: &dyn Fn(String) -> RegistryError,
) -> Result<[f64; 3], RegistryError> {
    let arr: [f64; 3] = values.try_into().map_err(|_| {
        err(format!(
            "`{key}` must be an array of three fractions [R, G, B], got {} values",
            values.len()
        ))
    })?;
    for (c, v) in arr.iter().enumerate() {
        if !v.is_finite() || !(0.0..=1.0).contains(v) {
            let hint = if v.is_finite() && *v > 1.0 && *v <= 100.0 {
                " (fractions, not percent)"
            } else {
                ""
            };
            return Err(err(format!(
                "`{key}` channel {} = {v} is not a fraction in [0, 1]{hint}",
                crate::CHANNELS[c]
            )));
        }
    }
    Ok(arr)
}

/// The keys that describe one layer, from a `[[glass]]` table or an element of its `layers`.
struct LayerKeys<'a> {
    spectral: &'a Option<String>,
    spectral_percent: bool,
    r0: &'a Option<Vec<f64>>,
    t0: &'a Option<Vec<f64>>,
    r0_back: &'a Option<Vec<f64>>,
    angles: &'a Option<String>,
    angles_percent: bool,
    model: ModelChoice,
    ior: &'a Option<IorValue>,
    /// A layer of a unit (which may be given by its angle table alone).
    in_unit: bool,
}

/// Validates the keys of one layer (`err` names the glass, and the layer's line in a unit).
fn validate_layer(
    k: LayerKeys<'_>,
    line: usize,
    err: &dyn Fn(String) -> RegistryError,
) -> Result<LayerSpec, RegistryError> {
    let ior = match k.ior {
        None => None,
        Some(v) => {
            let per = v.per_channel();
            for (n, kk) in per {
                if !n.is_finite() || !kk.is_finite() || n <= 0.0 || kk < 0.0 {
                    return Err(err(format!(
                        "`ior` needs n > 0 and k ≥ 0 (finite), got n = {n}, k = {kk}"
                    )));
                }
            }
            Some(per)
        }
    };
    if ior.is_some() && !matches!(k.model, ModelChoice::Opaque | ModelChoice::Auto) {
        return Err(err(format!(
            "`ior` applies to the `opaque` model only, but model is `{}`",
            k.model.name()
        )));
    }
    let explicit = k.r0.is_some() || k.t0.is_some() || k.r0_back.is_some();
    let opaque = k.model == ModelChoice::Opaque || (k.model == ModelChoice::Auto && ior.is_some());
    let normal = match (k.spectral, explicit) {
        (Some(_), true) => {
            return Err(err(
                "give either `spectral` or explicit `r0`/`t0`, not both".into(),
            ));
        }
        (Some(p), false) => {
            if p.trim().is_empty() {
                return Err(err("`spectral` is an empty path".into()));
            }
            NormalSource::Spectral {
                path: p.clone(),
                percent: k.spectral_percent,
            }
        }
        (None, false) if k.in_unit && k.angles.is_some() && !opaque => {
            if k.spectral_percent {
                return Err(err("`spectral_percent` without `spectral`".into()));
            }
            NormalSource::AngleTable
        }
        (None, _) => {
            if k.spectral_percent {
                return Err(err("`spectral_percent` without `spectral`".into()));
            }
            let t0 = match k.t0 {
                Some(v) => rgb(v, "t0", err)?,
                None if opaque => [0.0; 3],
                None => {
                    let give = if k.in_unit {
                        "give `spectral` (a file), `angles` (a measured table) or `r0` and `t0`"
                    } else {
                        "give `spectral` (a file) or `r0` and `t0`"
                    };
                    return Err(err(format!("no normal-incidence data: {give}")));
                }
            };
            let r0 = match (k.r0, &ior) {
                (Some(v), _) => rgb(v, "r0", err)?,
                (None, Some(per)) if opaque => {
                    per.map(|(n, kk)| glassdb_stack::physics::fresnel_single_surface(n, kk, 1.0))
                }
                (None, _) => {
                    return Err(err(
                        "`t0` without `r0`: give both (or `ior` for an opaque surface)".into(),
                    ));
                }
            };
            let r0_back = match k.r0_back {
                Some(v) => rgb(v, "r0_back", err)?,
                None => r0,
            };
            for c in 0..3 {
                for (key, r) in [("r0", r0[c]), ("r0_back", r0_back[c])] {
                    if r + t0[c] > 1.0 + 1e-12 {
                        return Err(err(format!(
                            "{key} + t0 = {} + {} > 1 in channel {}: more light out than in",
                            r,
                            t0[c],
                            crate::CHANNELS[c]
                        )));
                    }
                }
            }
            if opaque && t0.iter().any(|&t| t > 0.0) {
                return Err(err(format!(
                    "model `opaque` means t0 = 0, but t0 = {t0:?} (drop `t0` or pick another model)"
                )));
            }
            NormalSource::Explicit { r0, t0, r0_back }
        }
    };
    let angles = match k.angles {
        Some(p) if p.trim().is_empty() => return Err(err("`angles` is an empty path".into())),
        Some(p) => Some((p.clone(), k.angles_percent)),
        None => {
            if k.angles_percent {
                return Err(err("`angles_percent` without `angles`".into()));
            }
            None
        }
    };
    Ok(LayerSpec {
        normal,
        angles,
        model: k.model,
        ior,
        flip: false,
        thickness_mm: None,
        line,
    })
}

fn validate_entry(
    e: CatalogEntry,
    line: usize,
    text: &str,
    path: &Path,
) -> Result<GlassSpec, RegistryError> {
    let label = format!("\"{}\" (id {})", e.name, e.id);
    let err = |message: String| RegistryError::CatalogEntry {
        path: path.to_path_buf(),
        glass: label.clone(),
        message,
    };
    if e.id == 0 {
        return Err(RegistryError::IdZero {
            source_name: path.display().to_string(),
            name: e.name,
        });
    }
    let id = u16::try_from(e.id).map_err(|_| {
        err(format!(
            "id {} is outside 1–65535 (1–255 for 8-bit masks)",
            e.id
        ))
    })?;
    if e.name.trim().is_empty() {
        return Err(err("`name` is empty".into()));
    }
    let build = match &e.layers {
        Some(layers) => {
            let single_keys = [
                ("spectral", e.spectral.is_some()),
                ("spectral_percent", e.spectral_percent),
                ("r0", e.r0.is_some()),
                ("t0", e.t0.is_some()),
                ("r0_back", e.r0_back.is_some()),
                ("angles", e.angles.is_some()),
                ("angles_percent", e.angles_percent),
                ("model", e.model != ModelChoice::Auto),
                ("ior", e.ior.is_some()),
            ];
            if let Some((key, _)) = single_keys.iter().find(|(_, given)| *given) {
                return Err(err(format!(
                    "`{key}` and `layers` together: a unit's keys go in its layers"
                )));
            }
            GlassBuild::Unit(
                layers
                    .iter()
                    .enumerate()
                    .map(|(i, l)| {
                        let line = line_of(text, l.span().start);
                        validate_element(l.get_ref(), i + 1, line, path, &label)
                    })
                    .collect::<Result<_, _>>()?,
            )
        }
        None => GlassBuild::Single(validate_layer(
            LayerKeys {
                spectral: &e.spectral,
                spectral_percent: e.spectral_percent,
                r0: &e.r0,
                t0: &e.t0,
                r0_back: &e.r0_back,
                angles: &e.angles,
                angles_percent: e.angles_percent,
                model: e.model,
                ior: &e.ior,
                in_unit: false,
            },
            line,
            &err,
        )?),
    };
    Ok(GlassSpec {
        id,
        name: e.name,
        line,
        build,
    })
}

/// Validates one element of a unit's `layers` (at 1-based `position`, on catalog `line`).
fn validate_element(
    l: &LayerEntry,
    position: usize,
    line: usize,
    path: &Path,
    glass: &str,
) -> Result<ElementSpec, RegistryError> {
    let err = |message: String| RegistryError::CatalogLayer {
        path: path.to_path_buf(),
        line,
        glass: glass.to_string(),
        position,
        message,
    };
    let layer_keys = [
        ("spectral", l.spectral.is_some()),
        ("spectral_percent", l.spectral_percent.is_some()),
        ("r0", l.r0.is_some()),
        ("t0", l.t0.is_some()),
        ("r0_back", l.r0_back.is_some()),
        ("angles", l.angles.is_some()),
        ("angles_percent", l.angles_percent.is_some()),
        ("model", l.model.is_some()),
        ("ior", l.ior.is_some()),
        ("thickness_mm", l.thickness_mm.is_some()),
        ("flip", l.flip.is_some()),
    ];
    let positive = |key: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(err(format!(
                "`{key}` = {v} is not a positive number of millimetres"
            )))
        }
    };
    if let Some(gap_mm) = l.gap_mm {
        if let Some((key, _)) = layer_keys.iter().find(|(_, given)| *given) {
            let what = if *key == "flip" {
                "a flip on a gap: only a layer can face the other way".to_string()
            } else {
                format!("`{key}` on a gap (`gap_mm`): a gap has `gap_mm` and `gas` only")
            };
            return Err(err(what));
        }
        let gas = match &l.gas {
            None => Gas::Air,
            Some(g) => g.parse::<Gas>().map_err(err)?,
        };
        return Ok(ElementSpec::Gap {
            thickness_mm: positive("gap_mm", gap_mm)?,
            gas,
            line,
        });
    }
    if l.gas.is_some() {
        return Err(err(
            "`gas` without `gap_mm`: a gap needs its thickness".into()
        ));
    }
    let mut spec = validate_layer(
        LayerKeys {
            spectral: &l.spectral,
            spectral_percent: l.spectral_percent.unwrap_or(false),
            r0: &l.r0,
            t0: &l.t0,
            r0_back: &l.r0_back,
            angles: &l.angles,
            angles_percent: l.angles_percent.unwrap_or(false),
            model: l.model.unwrap_or_default(),
            ior: &l.ior,
            in_unit: true,
        },
        line,
        &err,
    )?;
    spec.flip = l.flip.unwrap_or(false);
    spec.thickness_mm = l
        .thickness_mm
        .map(|v| positive("thickness_mm", v))
        .transpose()?;
    Ok(ElementSpec::Layer(spec))
}

/// Resolves a catalog-relative path.
pub fn resolve(catalog_path: &Path, rel: &str) -> PathBuf {
    let base = catalog_path.parent().unwrap_or(Path::new("."));
    base.join(rel)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Vec<GlassSpec>, RegistryError> {
        parse_catalog(text, Path::new("cat.toml"))
    }

    #[test]
    fn explicit_entry_parses() {
        let specs =
            parse("[[glass]]\nid = 3\nname = \"x\"\nr0 = [0.1, 0.1, 0.1]\nt0 = [0.8, 0.8, 0.8]\n")
                .unwrap();
        assert_eq!(specs.len(), 1);
        assert_eq!(specs[0].id, 3);
        match &specs[0].build {
            GlassBuild::Single(LayerSpec {
                normal: NormalSource::Explicit { r0_back, .. },
                ..
            }) => assert_eq!(*r0_back, [0.1; 3]),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn errors_name_the_problem() {
        let cases = [
            (
                "[[glass]]\nid = 1\nname = \"a\"\nr0 = [0.1,0.1,0.1]\nt0 = [0.8,0.8,0.8]\ncolour = 1\n",
                "unknown field `colour`",
            ),
            ("[[glass]]\nid = \"one\"\nname = \"a\"\n", "invalid type"),
            (
                "[[glass]]\nid = 0\nname = \"a\"\nr0 = [0.1,0.1,0.1]\nt0 = [0.8,0.8,0.8]\n",
                "id 0",
            ),
            (
                "[[glass]]\nid = 70000\nname = \"a\"\nr0 = [0.1,0.1,0.1]\nt0 = [0.8,0.8,0.8]\n",
                "outside 1–65535",
            ),
            (
                "[[glass]]\nid = 1\nname = \"a\"\nr0 = [0.1,0.1]\nt0 = [0.8,0.8,0.8]\n",
                "three fractions",
            ),
            (
                "[[glass]]\nid = 1\nname = \"a\"\nr0 = [10,10,10]\nt0 = [80,80,80]\n",
                "not percent",
            ),
            (
                "[[glass]]\nid = 1\nname = \"a\"\nr0 = [0.3,0.3,0.3]\nt0 = [0.8,0.8,0.8]\n",
                "more light out than in",
            ),
            (
                "[[glass]]\nid = 1\nname = \"a\"\n",
                "no normal-incidence data",
            ),
            (
                "[[glass]]\nid = 1\nname = \"a\"\nspectral = \"x.DAT\"\nr0 = [0.1,0.1,0.1]\n",
                "not both",
            ),
            (
                "[[glass]]\nid = 1\nname = \"a\"\nr0 = [0.1,0.1,0.1]\nt0 = [0.8,0.8,0.8]\nmodel = \"shiny\"\n",
                "unknown variant `shiny`",
            ),
            (
                "[[glass]]\nid = 1\nname = \"a\"\nmodel = \"opaque\"\nr0 = [0.1,0.1,0.1]\nt0 = [0.8,0.8,0.8]\n",
                "t0 = 0",
            ),
            ("", "no [[glass]] tables"),
            (
                "[[glass]]\nid = 2\nname = \"a\"\nr0 = [0.1,0.1,0.1]\nt0 = [0.8,0.8,0.8]\n[[glass]]\nid = 2\nname = \"b\"\nr0 = [0.1,0.1,0.1]\nt0 = [0.8,0.8,0.8]\n",
                "id 2 is used twice",
            ),
        ];
        for (text, want) in cases {
            let msg = glassdb_io::ErrorChain(&parse(text).unwrap_err()).to_string();
            assert!(
                msg.contains(want),
                "catalog {text:?}: message {msg:?} lacks {want:?}"
            );
            assert!(msg.contains("cat.toml"), "{msg}");
        }
    }

    #[test]
    fn opaque_from_ior_gets_fresnel_r0() {
        let specs = parse("[[glass]]\nid = 9\nname = \"water\"\nmodel = \"opaque\"\nior = 1.333\n")
            .unwrap();
        match &specs[0].build {
            GlassBuild::Single(LayerSpec {
                normal: NormalSource::Explicit { r0, t0, .. },
                ..
            }) => {
                let expect = ((1.333f64 - 1.0) / 2.333).powi(2);
                assert!((r0[0] - expect).abs() < 1e-12);
                assert_eq!(*t0, [0.0; 3]);
            }
            other => panic!("{other:?}"),
        }
    }
}
