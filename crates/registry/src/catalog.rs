//! The catalog (`catalog.toml`): one `[[glass]]` table per product. Keys are documented in
//! `docs/registry.md`; unknown keys and wrong types are errors naming the key, line and column.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::RegistryError;

/// The whole catalog file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Catalog {
    /// The products, in file order.
    #[serde(default)]
    pub glass: Vec<CatalogEntry>,
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
}

/// The `model` key.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModelChoice {
    /// From the data file's product type (see `docs/registry.md`).
    #[default]
    Auto,
    /// WINDOW/EnergyPlus Fresnel slab model for uncoated glass.
    Uncoated,
    /// WINDOW-4 coated curves, clear or bronze chosen per wavelength (T0(λ) > 0.645 → clear).
    Coated,
    /// WINDOW-4 clear curve everywhere.
    CoatedClear,
    /// WINDOW-4 bronze curve everywhere.
    CoatedBronze,
    /// An opaque specular surface: t0 = 0, single-surface Fresnel reflectance.
    Opaque,
}

impl ModelChoice {
    /// The name used in catalogs and in the registry's `angle_model.kind`.
    pub fn name(self) -> &'static str {
        match self {
            ModelChoice::Auto => "auto",
            ModelChoice::Uncoated => "uncoated",
            ModelChoice::Coated => "coated",
            ModelChoice::CoatedClear => "coated-clear",
            ModelChoice::CoatedBronze => "coated-bronze",
            ModelChoice::Opaque => "opaque",
        }
    }
}

/// The `ior` key: a real index, a complex `[n, k]`, or one `[n, k]` per channel (metals).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum IorValue {
    /// One real index n (k = 0), every channel.
    Real(f64),
    /// One complex index `[n, k]`, every channel.
    Complex([f64; 2]),
    /// `[n, k]` per channel (R, G, B).
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
    /// Its registry id.
    pub id: u16,
    /// Its name.
    pub name: String,
    /// Where its normal-incidence values come from.
    pub normal: NormalSource,
    /// Its measured angle table and whether it is in percent, if any.
    pub angles: Option<(String, bool)>,
    /// Its angle model.
    pub model: ModelChoice,
    /// The complex refractive index per channel (the opaque model), if given.
    pub ior: Option<[(f64, f64); 3]>,
}

/// Where the normal-incidence values come from.
#[derive(Debug, Clone)]
pub enum NormalSource {
    /// A spectral file (path relative to the catalog) and whether it is in percent.
    Spectral {
        /// The spectral file, relative to the catalog.
        path: String,
        /// Whether its values are in percent.
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
}

/// Parses catalog text; `path` names it in errors.
pub fn parse_catalog(text: &str, path: &Path) -> Result<Vec<GlassSpec>, RegistryError> {
    let catalog: Catalog = toml::from_str(text).map_err(|source| RegistryError::CatalogToml {
        path: path.to_path_buf(),
        source: Box::new(source),
    })?;
    if catalog.glass.is_empty() {
        return Err(RegistryError::CatalogSyntax {
            path: path.to_path_buf(),
            message: "no [[glass]] tables: a catalog lists at least one product".into(),
        });
    }
    let mut specs: Vec<GlassSpec> = Vec::with_capacity(catalog.glass.len());
    for entry in catalog.glass {
        let spec = validate_entry(entry, path)?;
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

fn rgb(values: &[f64], key: &str, path: &Path, glass: &str) -> Result<[f64; 3], RegistryError> {
    let err = |message: String| RegistryError::CatalogEntry {
        path: path.to_path_buf(),
        glass: glass.to_string(),
        message,
    };
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

fn validate_entry(e: CatalogEntry, path: &Path) -> Result<GlassSpec, RegistryError> {
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
    let ior = match &e.ior {
        None => None,
        Some(v) => {
            let per = v.per_channel();
            for (n, k) in per {
                if !n.is_finite() || !k.is_finite() || n <= 0.0 || k < 0.0 {
                    return Err(err(format!(
                        "`ior` needs n > 0 and k ≥ 0 (finite), got n = {n}, k = {k}"
                    )));
                }
            }
            Some(per)
        }
    };
    if ior.is_some() && !matches!(e.model, ModelChoice::Opaque | ModelChoice::Auto) {
        return Err(err(format!(
            "`ior` applies to the `opaque` model only, but model is `{}`",
            e.model.name()
        )));
    }
    let explicit = e.r0.is_some() || e.t0.is_some() || e.r0_back.is_some();
    let opaque = e.model == ModelChoice::Opaque || (e.model == ModelChoice::Auto && ior.is_some());
    let normal = match (&e.spectral, explicit) {
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
                percent: e.spectral_percent,
            }
        }
        (None, _) => {
            if e.spectral_percent {
                return Err(err("`spectral_percent` without `spectral`".into()));
            }
            let t0 = match &e.t0 {
                Some(v) => rgb(v, "t0", path, &label)?,
                None if opaque => [0.0; 3],
                None => {
                    return Err(err(
                        "no normal-incidence data: give `spectral` (a file) or `r0` and `t0`"
                            .into(),
                    ));
                }
            };
            let r0 = match (&e.r0, &ior) {
                (Some(v), _) => rgb(v, "r0", path, &label)?,
                (None, Some(per)) if opaque => {
                    per.map(|(n, k)| crate::physics::fresnel_single_surface(n, k, 1.0))
                }
                (None, _) => {
                    return Err(err(
                        "`t0` without `r0`: give both (or `ior` for an opaque surface)".into(),
                    ));
                }
            };
            let r0_back = match &e.r0_back {
                Some(v) => rgb(v, "r0_back", path, &label)?,
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
    let angles = match &e.angles {
        Some(p) if p.trim().is_empty() => return Err(err("`angles` is an empty path".into())),
        Some(p) => Some((p.clone(), e.angles_percent)),
        None => {
            if e.angles_percent {
                return Err(err("`angles_percent` without `angles`".into()));
            }
            None
        }
    };
    Ok(GlassSpec {
        id,
        name: e.name,
        normal,
        angles,
        model: e.model,
        ior,
    })
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
        match &specs[0].normal {
            NormalSource::Explicit { r0_back, .. } => assert_eq!(*r0_back, [0.1; 3]),
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
        match &specs[0].normal {
            NormalSource::Explicit { r0, t0, .. } => {
                let expect = ((1.333f64 - 1.0) / 2.333).powi(2);
                assert!((r0[0] - expect).abs() < 1e-12);
                assert_eq!(*t0, [0.0; 3]);
            }
            other => panic!("{other:?}"),
        }
    }
}
