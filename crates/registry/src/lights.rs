//! Lights: a registry's tables integrated under several illuminants, one table per (colour
//! basis, light), so that each light group of a render is composited with the table of its own
//! light (`docs/colour.md`, "Lights"). A light is a name (`sun`, `warm`: the render's light
//! group) and a spectrum ([`Illuminant`]: a bundled CIE illuminant or an SPD file); the
//! camera's white balance is part of the table's method ([`WhiteBalance`]).

use glassdb_spectral::{Illuminant, IntegrationSettings, Method, WhiteBalance};

use crate::{BuildOptions, ColourBasis, Registry, RegistryError, RegistryTable};

/// The longest light name (a light group's name in a render).
pub const MAX_LIGHT_NAME: usize = 64;

/// A named light of a build: every colorimetric table is integrated under it once.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NamedLight {
    /// The name a scene's light group has (`sun`, `warm`, `lamp`).
    pub name: String,
    /// Its spectrum.
    pub illuminant: Illuminant,
}

impl NamedLight {
    /// Parses `NAME=ILLUMINANT` (what `--light` takes): a valid name ([`check_light_name`]) and
    /// a bundled CIE illuminant's name or an SPD CSV file, read now
    /// ([`Illuminant::from_name_or_file`]).
    pub fn parse(arg: &str) -> Result<NamedLight, RegistryError> {
        let spec_error = |message: String| RegistryError::LightSpec {
            arg: arg.to_string(),
            message,
            source: None,
        };
        let Some((name, illuminant)) = arg.split_once('=') else {
            return Err(spec_error(
                "expected NAME=ILLUMINANT (e.g. warm=A, led=LED-B3, lamp=lamp.csv)".into(),
            ));
        };
        check_light_name(name).map_err(spec_error)?;
        let illuminant =
            Illuminant::from_name_or_file(illuminant).map_err(|e| RegistryError::LightSpec {
                arg: arg.to_string(),
                message: "cannot use its illuminant".into(),
                source: Some(Box::new(e)),
            })?;
        Ok(NamedLight {
            name: name.to_string(),
            illuminant,
        })
    }
}

/// A light name must be something a compositor can match to a light group and a command line
/// can carry: 1 to [`MAX_LIGHT_NAME`] characters, no surrounding spaces, no control characters,
/// and none of `=` and `,` (the separators of `NAME=ILLUMINANT` and of lists of lights).
pub fn check_light_name(name: &str) -> Result<(), String> {
    let reason = if name.is_empty() {
        "is empty"
    } else if name.chars().count() > MAX_LIGHT_NAME {
        "is longer than 64 characters"
    } else if name.trim() != name {
        "has surrounding spaces"
    } else if name.chars().any(|c| c.is_control() || c == '=' || c == ',') {
        "holds a control character, `=` or `,`"
    } else {
        return Ok(());
    };
    Err(format!("the name {reason}"))
}

/// A light a registry's tables are integrated under ([`Registry::lights`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegistryLight<'a> {
    /// Its name; `None` for the one unnamed light of a registry built without lights.
    pub name: Option<&'a str>,
    /// Its spectrum; `None` for tables whose method has none (paper, luminous).
    pub illuminant: Option<&'a Illuminant>,
    /// The white the camera is balanced to in its tables.
    pub white_balance: WhiteBalance,
}

impl RegistryLight<'_> {
    /// `warm (A)`, `lamp (lamp.csv, camera balanced to D65)`, or the illuminant alone for the
    /// unnamed light.
    pub fn describe(&self) -> String {
        let spectrum = match self.illuminant {
            Some(i) => i.name().to_string(),
            None => "no illuminant".into(),
        };
        let balance = match self.white_balance {
            WhiteBalance::Light => String::new(),
            WhiteBalance::Fixed(w) => format!(", camera balanced to {w}"),
        };
        match self.name {
            Some(name) => format!("{name} ({spectrum}{balance})"),
            None => format!("{spectrum}{balance}"),
        }
    }
}

impl RegistryTable {
    /// The light of this table: its name, illuminant and white balance.
    pub fn registry_light(&self) -> RegistryLight<'_> {
        let (illuminant, white_balance) = match &self.spectral.method {
            Method::Colorimetric(c) => (Some(&c.illuminant), c.white_balance),
            _ => (None, WhiteBalance::Light),
        };
        RegistryLight {
            name: self.light.as_deref(),
            illuminant,
            white_balance,
        }
    }
}

impl Registry {
    /// The lights the tables are integrated under, each once, in table order: the first is the
    /// default light. A registry built without lights has one unnamed light.
    pub fn lights(&self) -> Vec<RegistryLight<'_>> {
        let mut lights: Vec<RegistryLight<'_>> = Vec::new();
        for t in self.tables() {
            if !lights.iter().any(|l| l.name == t.light.as_deref()) {
                lights.push(t.registry_light());
            }
        }
        lights
    }

    /// The names of the lights, in table order (empty for a registry without named lights).
    pub fn light_names(&self) -> Vec<&str> {
        self.lights().iter().filter_map(|l| l.name).collect()
    }

    /// The default light's name (the first table's), `None` when the tables name no light.
    pub fn default_light(&self) -> Option<&str> {
        self.default_table().light.as_deref()
    }

    /// The tables of the default light, one per colour basis, the default table first: what a
    /// compositor that composites every light group with one table uses.
    pub fn default_light_tables(&self) -> impl Iterator<Item = &RegistryTable> {
        let light = self.default_light();
        self.tables()
            .iter()
            .filter(move |t| t.light.as_deref() == light)
    }

    /// The table in `basis` under the light `light`; an error naming the light and the lights
    /// there are ([`RegistryError::NoSuchLight`]), or the basis and the bases of that light
    /// ([`RegistryError::NoSuchTable`]). `source_name` names the registry in errors.
    pub fn table_under(
        &self,
        basis: ColourBasis,
        light: &str,
        source_name: &str,
    ) -> Result<&RegistryTable, RegistryError> {
        let of_light: Vec<&RegistryTable> = self
            .tables()
            .iter()
            .filter(|t| t.light.as_deref() == Some(light))
            .collect();
        if of_light.is_empty() {
            let lights = self.lights();
            return Err(RegistryError::NoSuchLight {
                source_name: source_name.to_string(),
                wanted: light.to_string(),
                have: lights
                    .iter()
                    .filter(|l| l.name.is_some())
                    .map(RegistryLight::describe)
                    .collect(),
                unnamed: lights
                    .first()
                    .map(RegistryLight::describe)
                    .unwrap_or_default(),
            });
        }
        of_light
            .iter()
            .find(|t| t.basis() == basis)
            .copied()
            .ok_or_else(|| RegistryError::NoSuchTable {
                source_name: format!("{source_name} (light {light})"),
                wanted: basis.to_string(),
                have: of_light.iter().map(|t| t.basis().to_string()).collect(),
            })
    }

    /// The lights' rules: every table names its light or none does; names are valid; a light's
    /// tables are all colorimetric, of one illuminant, observer and white balance; every light
    /// has a table in every basis that another has.
    pub(crate) fn validate_lights(&self, source_name: &str) -> Result<(), RegistryError> {
        let tables = self.tables();
        if let (Some(named), Some(unnamed)) = (
            tables.iter().position(|t| t.light.is_some()),
            tables.iter().position(|t| t.light.is_none()),
        ) {
            return Err(RegistryError::LightsMixed {
                source_name: source_name.to_string(),
                named: named + 1,
                light: tables[named].light.clone().unwrap_or_default(),
                unnamed: unnamed + 1,
            });
        }
        for (k, t) in tables.iter().enumerate() {
            let Some(light) = &t.light else { continue };
            check_light_name(light).map_err(|reason| RegistryError::LightName {
                source_name: source_name.to_string(),
                name: light.clone(),
                reason,
            })?;
            let Method::Colorimetric(colorimetric) = &t.spectral.method else {
                return Err(RegistryError::LightNotColorimetric {
                    source_name: source_name.to_string(),
                    light: light.clone(),
                    method: t.spectral.method.kind().to_string(),
                });
            };
            let first = tables[..k].iter().find(|e| e.light.as_ref() == Some(light));
            if let Some(first) = first {
                let (a, b) = (first.registry_light(), t.registry_light());
                let first_observer = match &first.spectral.method {
                    Method::Colorimetric(c) => Some(c.observer),
                    _ => None,
                };
                if a != b || first_observer != Some(colorimetric.observer) {
                    let say = |l: RegistryLight<'_>, t: &RegistryTable| {
                        format!("{} ({})", l.describe(), t.spectral.method)
                    };
                    return Err(RegistryError::LightInconsistent {
                        source_name: source_name.to_string(),
                        light: light.clone(),
                        first: say(a, first),
                        second: say(b, t),
                    });
                }
            }
        }
        self.validate_light_grid(source_name)
    }

    /// Every named light has a table in every basis some light has.
    fn validate_light_grid(&self, source_name: &str) -> Result<(), RegistryError> {
        let tables = self.tables();
        for a in tables {
            for b in tables {
                let (Some(light), Some(other)) = (&b.light, &a.light) else {
                    continue;
                };
                let has = tables
                    .iter()
                    .any(|t| t.light.as_ref() == Some(light) && t.basis() == a.basis());
                if !has {
                    return Err(RegistryError::LightMissingTable {
                        source_name: source_name.to_string(),
                        light: light.clone(),
                        basis: a.basis().to_string(),
                        other: other.clone(),
                    });
                }
            }
        }
        Ok(())
    }
}

impl BuildOptions {
    /// Options that build the tables `registry` holds: the default light's methods (one per
    /// colour basis) under each of its named lights (other options default).
    pub fn with_tables_of(registry: &Registry) -> BuildOptions {
        BuildOptions {
            tables: registry
                .default_light_tables()
                .map(|t| t.spectral.clone())
                .collect(),
            lights: registry
                .tables()
                .iter()
                .filter_map(|t| {
                    let name = t.light.clone()?;
                    let Method::Colorimetric(c) = &t.spectral.method else {
                        return None;
                    };
                    Some(NamedLight {
                        name,
                        illuminant: c.illuminant.clone(),
                    })
                })
                .fold(Vec::new(), |mut lights: Vec<NamedLight>, l| {
                    if !lights.iter().any(|k| k.name == l.name) {
                        lights.push(l);
                    }
                    lights
                }),
            ..BuildOptions::default()
        }
    }
}

/// The empty tables a build makes, in the registry's order: without lights, one per entry of
/// `opts.tables`; with lights, light by light, every entry under that light (its illuminant
/// replacing the entry's; its observer, space and white balance kept).
pub(crate) fn planned_tables(opts: &BuildOptions) -> Result<Vec<RegistryTable>, RegistryError> {
    let table = |light: Option<String>, spectral: IntegrationSettings| RegistryTable {
        light,
        spectral,
        glasses: Vec::new(),
    };
    if opts.lights.is_empty() {
        return Ok(opts.tables.iter().map(|s| table(None, s.clone())).collect());
    }
    let mut planned = Vec::with_capacity(opts.lights.len() * opts.tables.len());
    for (k, light) in opts.lights.iter().enumerate() {
        check_light_name(&light.name).map_err(|message| RegistryError::LightSpec {
            arg: light.name.clone(),
            message,
            source: None,
        })?;
        if opts.lights[..k].iter().any(|l| l.name == light.name) {
            return Err(RegistryError::DuplicateLight {
                name: light.name.clone(),
            });
        }
        for settings in &opts.tables {
            let mut spectral = settings.clone();
            match &mut spectral.method {
                Method::Colorimetric(c) => c.illuminant = light.illuminant.clone(),
                other => {
                    return Err(RegistryError::LightsNeedColorimetric {
                        method: other.kind().to_string(),
                    });
                }
            }
            planned.push(table(Some(light.name.clone()), spectral));
        }
    }
    Ok(planned)
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use glassdb_spectral::{CieIlluminant, RgbSpace};

    use super::*;
    use crate::build_registry;

    fn data(rel: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../data")
            .join(rel)
    }

    /// A catalog of the green-tinted float (a spectrum) and a hand-made grey glass.
    fn catalog(dir: &Path) -> PathBuf {
        let path = dir.join("catalog.toml");
        let text = format!(
            "[[glass]]\nid = 5\nname = \"green\"\nspectral = \"{}\"\nmodel = \"uncoated\"\n\n\
             [[glass]]\nid = 7\nname = \"grey\"\nr0 = [0.08, 0.08, 0.08]\nt0 = [0.5, 0.5, 0.5]\n",
            data("glazing/913.json").display()
        );
        std::fs::write(&path, text).unwrap();
        path
    }

    fn light(name: &str, illuminant: &str) -> NamedLight {
        NamedLight::parse(&format!("{name}={illuminant}")).unwrap()
    }

    fn two_lights(dir: &Path) -> Registry {
        let opts = BuildOptions {
            lights: vec![light("sun", "D65"), light("warm", "A")],
            ..BuildOptions::colorimetric_in(&[RgbSpace::Srgb, RgbSpace::AcesCg])
        };
        build_registry(&catalog(dir), &opts).unwrap()
    }

    #[test]
    fn a_build_with_lights_has_one_table_per_space_and_light() {
        let dir = tempfile::tempdir().unwrap();
        let reg = two_lights(dir.path());
        let labels: Vec<String> = reg.tables().iter().map(RegistryTable::label).collect();
        assert_eq!(
            labels,
            [
                "srgb, light sun",
                "acescg, light sun",
                "srgb, light warm",
                "acescg, light warm"
            ]
        );
        assert_eq!(reg.light_names(), ["sun", "warm"]);
        assert_eq!(reg.default_light(), Some("sun"));
        assert_eq!(reg.lights()[1].describe(), "warm (A)");
        let srgb = ColourBasis::Space(RgbSpace::Srgb);
        let warm = reg.table_under(srgb, "warm", "r.json").unwrap();
        assert_eq!(warm.light.as_deref(), Some("warm"));
        // The default light's tables serve the one-table API (what compose uses today).
        assert_eq!(reg.table(srgb).unwrap().light.as_deref(), Some("sun"));
        assert_eq!(reg.bases().len(), 2);
        assert_eq!(reg.default_light_tables().count(), 2);
        // The tinted glass differs under A; the grey one (flat) does not.
        let sun = reg.table(srgb).unwrap();
        assert!((warm.glass(5).unwrap().t0[0] - sun.glass(5).unwrap().t0[0]).abs() > 0.01);
        assert_eq!(warm.glass(7).unwrap().t0, sun.glass(7).unwrap().t0);
        // Schema 5, and back.
        let text = reg.to_json_string().unwrap();
        assert!(text.contains("\"schema\": 5") && text.contains("\"light\": \"warm\""));
        assert_eq!(Registry::from_json_str(&text, "r.json").unwrap(), reg);
        // The options that rebuild it.
        let again = BuildOptions::with_tables_of(&reg);
        assert_eq!(again.lights.len(), 2);
        assert_eq!(again.tables.len(), 2);
        assert_eq!(build_registry(&catalog(dir.path()), &again).unwrap(), reg);
    }

    #[test]
    fn lookups_name_the_missing_light_and_the_lights_there_are() {
        let dir = tempfile::tempdir().unwrap();
        let reg = two_lights(dir.path());
        let srgb = ColourBasis::Space(RgbSpace::Srgb);
        let e = reg.table_under(srgb, "lamp", "r.json").unwrap_err();
        assert!(
            matches!(&e, RegistryError::NoSuchLight { wanted, have, .. }
                if wanted == "lamp" && have == &["sun (D65)", "warm (A)"]),
            "{e}"
        );
        assert_eq!(
            e.to_string(),
            "r.json has no light `lamp` (its lights: sun (D65), warm (A))"
        );
        let e = reg
            .table_under(ColourBasis::Space(RgbSpace::Rec2020), "warm", "r.json")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "r.json (light warm) has no table in rec2020 (it holds: srgb, acescg)"
        );
        // A registry without lights has one unnamed light.
        let plain = build_registry(&catalog(dir.path()), &BuildOptions::default()).unwrap();
        assert!(plain.light_names().is_empty() && plain.default_light().is_none());
        assert_eq!(plain.schema_version(), 4);
        let e = plain
            .table_under(srgb, "sun", "p.json")
            .unwrap_err()
            .to_string();
        assert!(e.contains("name no light") && e.contains("D65"), "{e}");
    }

    #[test]
    fn broken_light_registries_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let reg = two_lights(dir.path());
        let refused = |edit: &dyn Fn(&mut Vec<RegistryTable>)| {
            let mut bad = reg.clone();
            edit(bad.tables_mut());
            bad.validate().unwrap_err()
        };
        let e = refused(&|t| t[2].light = None);
        assert!(
            matches!(
                e,
                RegistryError::LightsMixed {
                    named: 1,
                    unnamed: 3,
                    ..
                }
            ),
            "{e}"
        );
        let e = refused(&|t| t[3].light = Some("sun".into()));
        assert!(matches!(e, RegistryError::DuplicateTable { .. }), "{e}");
        let e = refused(&|t| {
            t[3].spectral =
                IntegrationSettings::colorimetric(RgbSpace::AcesCg, CieIlluminant::Fl2.into())
        });
        assert!(e.to_string().contains("light `warm` is warm (A)"), "{e}");
        let e = refused(&|t| {
            t.remove(3);
        });
        assert!(
            e.to_string()
                .contains("light `warm` has no acescg table but light `sun` has one"),
            "{e}"
        );
        let e = refused(&|t| t[0].light = Some("a,b".into()));
        assert!(matches!(e, RegistryError::LightName { .. }), "{e}");
        let e = refused(&|t| t[0].spectral.method = Method::Luminous);
        assert!(
            matches!(e, RegistryError::LightNotColorimetric { .. }),
            "{e}"
        );
        // Lights in a file that says schema 4 are refused.
        let text = reg
            .to_json_string()
            .unwrap()
            .replace("\"schema\": 5", "\"schema\": 4");
        let e = Registry::from_json_str(&text, "old.json").unwrap_err();
        assert!(
            matches!(e, RegistryError::LightsInOldSchema { found: 4, .. }),
            "{e}"
        );
    }

    #[test]
    fn build_options_with_bad_lights_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let build = |tables: Vec<IntegrationSettings>, lights: Vec<NamedLight>| {
            let opts = BuildOptions {
                tables,
                lights,
                ..BuildOptions::default()
            };
            build_registry(&catalog(dir.path()), &opts).unwrap_err()
        };
        let e = build(
            BuildOptions::colorimetric_in(&[RgbSpace::Srgb]).tables,
            vec![light("sun", "D65"), light("sun", "A")],
        );
        assert!(matches!(e, RegistryError::DuplicateLight { .. }), "{e}");
        let luminous = IntegrationSettings {
            method: Method::Luminous,
            extrapolate: false,
        };
        let e = build(vec![luminous], vec![light("sun", "D65")]);
        assert!(
            matches!(e, RegistryError::LightsNeedColorimetric { .. }),
            "{e}"
        );
        for (arg, want) in [
            ("warm", "expected NAME=ILLUMINANT"),
            ("=A", "the name is empty"),
            (" warm=A", "surrounding spaces"),
            ("warm=F99", "cannot use its illuminant"),
        ] {
            let e = NamedLight::parse(arg).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!("light `{arg}`")) && e.contains(want),
                "{e}"
            );
        }
    }
}
