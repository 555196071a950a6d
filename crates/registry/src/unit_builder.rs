//! [`UnitBuilder`]: the entry point a front-end calls to build a unit from a catalog's glasses
//! on demand (the viewer's "build a unit on the page"), with the same records as a catalog's
//! units.

use std::path::{Path, PathBuf};

use glassdb_spectral::Integrator;
use glassdb_stack::Gas;

use crate::build::{BuildContext, BuildOptions, integrators_of, load_catalog};
use crate::catalog::{ElementSpec, GlassBuild, GlassSpec};
use crate::catalog_files::CatalogFiles;
use crate::unit::build_unit;
use crate::{Registry, RegistryError, RegistryTable};

/// One element of a unit chosen from a catalog's glasses.
#[derive(Debug, Clone, PartialEq)]
pub enum ChosenElement {
    /// A single glass of the catalog, by id, turned round or not.
    Glass {
        /// Its catalog id.
        id: u16,
        /// Turned round (coating on the other surface).
        flip: bool,
    },
    /// A gap.
    Gap {
        /// Thickness (mm).
        thickness_mm: f64,
        /// Its gas.
        gas: Gas,
    },
}

/// A unit chosen on a front-end (the viewer's picker): its id and name and its elements,
/// outside first.
#[derive(Debug, Clone, PartialEq)]
pub struct UnitChoice {
    /// The id the unit gets.
    pub id: u16,
    /// Its name.
    pub name: String,
    /// Layers (the catalog's single glasses) and gaps, outside first.
    pub elements: Vec<ChosenElement>,
}

/// A catalog loaded once, building units from its single glasses on demand: the entry point
/// a front-end calls (`glassdb view` builds a unit on the page with it). Each build reads the
/// chosen glasses' files, runs the stack engine and fits the curves of every table.
#[derive(Debug)]
pub struct UnitBuilder {
    catalog_path: PathBuf,
    specs: Vec<GlassSpec>,
    /// The tables a build makes, empty.
    tables: Vec<RegistryTable>,
    integrators: Vec<Integrator>,
    opts: BuildOptions,
}

impl UnitBuilder {
    /// Loads the catalog and prepares the integrators of `opts.tables`.
    pub fn new(catalog_path: &Path, opts: BuildOptions) -> Result<UnitBuilder, RegistryError> {
        let (tables, integrators) = integrators_of(&opts)?;
        let (specs, _) = load_catalog(catalog_path)?;
        Ok(UnitBuilder {
            catalog_path: catalog_path.to_path_buf(),
            specs,
            tables,
            integrators,
            opts,
        })
    }

    /// The catalog's single glasses (the layers a unit can be built from): id and name.
    pub fn glasses(&self) -> Vec<(u16, &str)> {
        self.specs
            .iter()
            .filter(|s| matches!(s.build, GlassBuild::Single(_)))
            .map(|s| (s.id, s.name.as_str()))
            .collect()
    }

    /// Builds the chosen unit: a validated registry of one glass in each table of the options.
    pub fn build(&self, choice: &UnitChoice) -> Result<Registry, RegistryError> {
        let bad = |message: String| RegistryError::CatalogEntry {
            path: self.catalog_path.clone(),
            glass: format!("\"{}\" (id {})", choice.name, choice.id),
            message,
        };
        if choice.id == 0 {
            return Err(bad("id 0 is \"no glass\" in every mask".into()));
        }
        let mut elements = Vec::with_capacity(choice.elements.len());
        for (i, e) in choice.elements.iter().enumerate() {
            elements.push(match e {
                ChosenElement::Gap { thickness_mm, gas } => ElementSpec::Gap {
                    thickness_mm: *thickness_mm,
                    gas: *gas,
                    line: 0,
                },
                ChosenElement::Glass { id, flip } => {
                    let spec = self.specs.iter().find(|s| s.id == *id).ok_or_else(|| {
                        bad(format!("element {}: the catalog has no glass with id {id}", i + 1))
                    })?;
                    let GlassBuild::Single(layer) = &spec.build else {
                        return Err(bad(format!(
                            "element {}: glass {id} (\"{}\") is a unit itself; a layer is a single glass",
                            i + 1,
                            spec.name
                        )));
                    };
                    let mut layer = layer.clone();
                    layer.flip = *flip;
                    layer.line = spec.line;
                    ElementSpec::Layer(layer)
                }
            });
        }
        let spec = GlassSpec {
            id: choice.id,
            name: choice.name.clone(),
            line: 0,
            build: GlassBuild::Unit(elements.clone()),
        };
        let ctx = BuildContext {
            files: CatalogFiles {
                catalog_path: &self.catalog_path,
            },
            integrators: &self.integrators,
            opts: &self.opts,
        };
        let records = build_unit(&spec, &elements, &ctx).map_err(|e| match e {
            RegistryError::Unit { glass, source, .. } => RegistryError::UnitChoice {
                path: self.catalog_path.clone(),
                glass,
                source,
            },
            other => other,
        })?;
        let tables = self
            .tables
            .iter()
            .zip(records)
            .map(|(table, g)| RegistryTable {
                glasses: vec![g],
                ..table.clone()
            })
            .collect();
        Registry::new(tables)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bundled() -> UnitBuilder {
        let catalog = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/catalog.toml");
        UnitBuilder::new(&catalog, BuildOptions::default()).unwrap()
    }

    fn gap() -> ChosenElement {
        ChosenElement::Gap {
            thickness_mm: 12.7,
            gas: Gas::Argon,
        }
    }

    fn glass(id: u16) -> ChosenElement {
        ChosenElement::Glass { id, flip: false }
    }

    #[test]
    fn the_viewer_builds_a_unit_from_the_catalogs_glasses() {
        let b = bundled();
        assert!(b.glasses().iter().any(|&(id, _)| id == 6));
        assert!(
            b.glasses().iter().all(|&(id, _)| id != 11),
            "units are not layers"
        );
        let choice = UnitChoice {
            id: 300,
            name: "R67 | argon | clear 6".into(),
            elements: vec![glass(6), gap(), glass(2)],
        };
        let reg = b.build(&choice).unwrap();
        let g = reg.default_table().glass(300).unwrap();
        let unit = g.unit.as_ref().unwrap();
        assert_eq!(unit.groups.len(), 2);
        assert_eq!(unit.elements.len(), 3);
        // the same unit in the bundled catalog (id 12) has the same optics
        let bundled = crate::default_registry().unwrap();
        let twelve = bundled.default_table().glass(12).unwrap();
        assert_eq!(
            (g.r0, g.t0, g.r0_back),
            (twelve.r0, twelve.t0, twelve.r0_back)
        );
    }

    #[test]
    fn bad_choices_say_what_is_wrong() {
        let b = bundled();
        let build = |elements: Vec<ChosenElement>| {
            let choice = UnitChoice {
                id: 300,
                name: "bad".into(),
                elements,
            };
            glassdb_io::ErrorChain(&b.build(&choice).unwrap_err()).to_string()
        };
        let e = build(vec![glass(99)]);
        assert!(e.contains("no glass with id 99"), "{e}");
        let e = build(vec![glass(11)]);
        assert!(e.contains("is a unit itself"), "{e}");
        let e = build(vec![glass(2), gap(), gap(), glass(2)]);
        assert!(e.contains("two gaps in a row") && !e.contains(":0:"), "{e}");
        let e = build(vec![glass(2), gap()]);
        assert!(e.contains("gap at the inner end"), "{e}");
        let e = build(vec![glass(20), gap(), glass(2)]);
        assert!(e.contains("is opaque but layer 3"), "{e}");
    }
}
