//! The scene's own light groups (issue 29, docs/blender.md "Light groups"): each Cycles light
//! group of a scene (`object.lightgroup`, `world.lightgroup`) is a light with its own spectrum,
//! said by the render's lights (`GROUP=ILLUMINANT`) or by a `glassdb_light` custom property on
//! the group's lamps, objects or world. The run record keeps each group's illuminant; compose
//! composites each group's light with the registry table of that light ([`LightTables`]).
//! Without groups the whole scene is one light, as before.

use std::path::Path;

use glassdb_registry::{NamedLight, Registry, RegistryLight};
use glassdb_spectral::Illuminant;
use serde::{Deserialize, Serialize};

use crate::BlenderError;
use crate::pipeline::RegistryChoice;

/// The scene's light groups as the Blender-side export reports them (`export.json`'s
/// `light_groups`).
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
pub struct SceneLightGroups {
    /// The groups named by the scene's rendered objects or its world, the view layer's order
    /// first.
    #[serde(default)]
    pub groups: Vec<String>,
    /// Emitters in no group (`lamp Lamp`, `world World`, `object Neon (emissive material)`):
    /// their light would be in no group's layer.
    #[serde(default)]
    pub ungrouped: Vec<String>,
    /// `glassdb_light` custom properties: which object (or world) of which group says what.
    #[serde(default)]
    pub properties: Vec<LightProperty>,
}

/// One `glassdb_light` custom property of a group's object, lamp data or world.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct LightProperty {
    /// The group of its holder.
    pub group: String,
    /// What holds it (`lamp Desk`, `world World`).
    pub holder: String,
    /// Its value: an illuminant's name or an SPD file (made absolute by the script).
    pub value: String,
}

/// A light group of the scene and its spectrum, as the run record keeps it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneLight {
    /// The Cycles light group (and the registry light that composites it).
    pub group: String,
    /// Its spectrum.
    pub illuminant: Illuminant,
    /// Where the spectrum was said: `the render's lights` or the property's holder.
    pub from: String,
}

/// Where a group's spectrum came from when the render's lights gave it.
const FROM_REQUEST: &str = "the render's lights";

/// Each scene group with its spectrum: `requested` (`GROUP=ILLUMINANT`) first, else the
/// group's `glassdb_light` properties (all of one value). A requested group the scene does not
/// have, a group without a spectrum, properties that disagree and emitters in no group (when
/// the scene has groups) are errors naming them. A scene without groups is one light: no
/// scene lights, and none may be requested.
pub fn resolve_scene_lights(
    scene: &SceneLightGroups,
    requested: &[NamedLight],
    blend: &Path,
) -> Result<Vec<SceneLight>, BlenderError> {
    for (k, light) in requested.iter().enumerate() {
        if requested[..k].iter().any(|l| l.name == light.name) {
            return Err(BlenderError::LightTwice {
                group: light.name.clone(),
            });
        }
        if !scene.groups.contains(&light.name) {
            return Err(BlenderError::UnknownLightGroup {
                group: light.name.clone(),
                blend: blend.to_path_buf(),
                groups: scene.groups.clone(),
            });
        }
    }
    if scene.groups.is_empty() {
        return Ok(Vec::new());
    }
    if !scene.ungrouped.is_empty() {
        return Err(BlenderError::UngroupedEmitters {
            blend: blend.to_path_buf(),
            emitters: scene.ungrouped.clone(),
            groups: scene.groups.clone(),
        });
    }
    let mut lights = Vec::with_capacity(scene.groups.len());
    for group in &scene.groups {
        if let Some(l) = requested.iter().find(|l| &l.name == group) {
            lights.push(SceneLight {
                group: group.clone(),
                illuminant: l.illuminant.clone(),
                from: FROM_REQUEST.into(),
            });
            continue;
        }
        let said: Vec<&LightProperty> = scene
            .properties
            .iter()
            .filter(|p| &p.group == group)
            .collect();
        let Some(first) = said.first() else {
            return Err(BlenderError::LightGroupWithoutSpectrum {
                group: group.clone(),
                blend: blend.to_path_buf(),
            });
        };
        let parse = |p: &LightProperty| {
            Illuminant::from_name_or_file(&p.value).map_err(|e| BlenderError::BadLightProperty {
                holder: p.holder.clone(),
                value: p.value.clone(),
                source: Box::new(e),
            })
        };
        let illuminant = parse(first)?;
        for p in &said[1..] {
            if !same_spectrum(&parse(p)?, &illuminant) {
                return Err(BlenderError::LightPropertiesDisagree {
                    group: group.clone(),
                    first: format!("{} says {}", first.holder, first.value),
                    second: format!("{} says {}", p.holder, p.value),
                });
            }
        }
        lights.push(SceneLight {
            group: group.clone(),
            illuminant,
            from: format!("{}'s glassdb_light property", first.holder),
        });
    }
    Ok(lights)
}

/// Whether two illuminants are the same light: the same CIE illuminant, or SPDs of the same
/// bytes (their SHA-256; the file may have moved).
pub fn same_spectrum(a: &Illuminant, b: &Illuminant) -> bool {
    match (a, b) {
        (Illuminant::Cie(x), Illuminant::Cie(y)) => x == y,
        (Illuminant::Spd(x), Illuminant::Spd(y)) => x.sha256 == y.sha256,
        _ => false,
    }
}

/// Which registry light composites each scene group's light.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LightTables {
    /// Each scene group and the registry light of its tables (`None`: the registry's default
    /// tables), in the run record's order.
    pub groups: Vec<(String, Option<String>)>,
    /// Set when the registry has one light and every group composites with it: what the
    /// report says (`one table for all lights: …`).
    pub one_table: Option<String>,
}

impl LightTables {
    /// The registry light of scene group `group` (`None`: the default tables; also for a
    /// group the run does not have, which the caller checked).
    pub fn light_of(&self, group: &str) -> Option<String> {
        self.groups
            .iter()
            .find(|(g, _)| g == group)
            .and_then(|(_, l)| l.clone())
    }
}

/// The registry tables for a run's scene lights: a registry with one light composites every
/// group with it (the one-table comparison); otherwise each group needs a registry light of its
/// name whose illuminant is the group's. `record` names the run in errors.
pub fn light_tables(
    lights: &[SceneLight],
    registry: &RegistryChoice,
    record: &Path,
) -> Result<LightTables, BlenderError> {
    let reg: &Registry = &registry.registry;
    let have = reg.lights();
    if lights.is_empty() {
        return Ok(LightTables {
            groups: Vec::new(),
            one_table: None,
        });
    }
    if have.len() == 1 {
        let only = &have[0];
        return Ok(LightTables {
            groups: lights
                .iter()
                .map(|l| (l.group.clone(), only.name.map(str::to_string)))
                .collect(),
            one_table: Some(format!(
                "one table for all lights: {} has one light, {}, and composites the groups {} with it",
                registry.label,
                only.describe(),
                lights
                    .iter()
                    .map(|l| format!("{} ({})", l.group, l.illuminant))
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        });
    }
    let mut groups = Vec::with_capacity(lights.len());
    for light in lights {
        let Some(table) = have.iter().find(|l| l.name == Some(light.group.as_str())) else {
            return Err(BlenderError::RegistryLacksLight {
                group: light.group.clone(),
                illuminant: light.illuminant.to_string(),
                registry: registry.label.clone(),
                lights: have.iter().map(RegistryLight::describe).collect(),
            });
        };
        if !table
            .illuminant
            .is_some_and(|i| same_spectrum(i, &light.illuminant))
        {
            return Err(BlenderError::LightMismatch {
                group: light.group.clone(),
                rendered: light.illuminant.to_string(),
                record: record.to_path_buf(),
                registry: registry.label.clone(),
                table: table.describe(),
            });
        }
        groups.push((light.group.clone(), Some(light.group.clone())));
    }
    Ok(LightTables {
        groups,
        one_table: None,
    })
}

/// The light groups of `tables` with their lookup tables from `registry`, for compose's
/// light-group composite ([`glassdb_compose::compose_light_groups`]).
pub fn compose_groups(
    tables: &LightTables,
    registry: &Registry,
) -> Vec<glassdb_compose::LightGroup> {
    use glassdb_compose::colour::RegistryLuts;
    tables
        .groups
        .iter()
        .map(|(group, light)| glassdb_compose::LightGroup {
            name: group.clone(),
            // `light_tables` chose a light the registry has.
            luts: light
                .as_deref()
                .and_then(|l| RegistryLuts::for_light(registry, l))
                .unwrap_or_else(|| RegistryLuts::new(registry)),
        })
        .collect()
}

/// `lights` said in a line: `sun (D65), warm (A)`.
pub fn describe_lights(lights: &[SceneLight]) -> String {
    lights
        .iter()
        .map(|l| format!("{} ({})", l.group, l.illuminant))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(groups: &[&str]) -> SceneLightGroups {
        SceneLightGroups {
            groups: groups.iter().map(|g| g.to_string()).collect(),
            ..SceneLightGroups::default()
        }
    }

    fn light(arg: &str) -> NamedLight {
        NamedLight::parse(arg).unwrap()
    }

    #[test]
    fn each_group_takes_its_requested_light_or_its_property() {
        let mut s = scene(&["sun", "warm"]);
        s.properties.push(LightProperty {
            group: "warm".into(),
            holder: "lamp Desk".into(),
            value: "A".into(),
        });
        let lights = resolve_scene_lights(&s, &[light("sun=D65")], Path::new("s.blend")).unwrap();
        assert_eq!(describe_lights(&lights), "sun (D65), warm (A)");
        assert_eq!(lights[1].from, "lamp Desk's glassdb_light property");
        // The request wins over a property.
        let lights =
            resolve_scene_lights(&s, &[light("warm=FL2"), light("sun=D65")], Path::new("s"))
                .unwrap();
        assert_eq!(describe_lights(&lights), "sun (D65), warm (FL2)");
    }

    #[test]
    fn bad_lights_are_refused_by_name() {
        let s = scene(&["sun", "warm"]);
        let blend = Path::new("s.blend");
        let e = resolve_scene_lights(&s, &[light("sun=D65")], blend).unwrap_err();
        assert!(
            matches!(&e, BlenderError::LightGroupWithoutSpectrum { group, .. } if group == "warm"),
            "{e}"
        );
        let e = resolve_scene_lights(&s, &[light("led=A")], blend).unwrap_err();
        assert!(e.to_string().contains("`led`") && e.to_string().contains("sun, warm"));
        let e = resolve_scene_lights(&scene(&[]), &[light("sun=D65")], blend).unwrap_err();
        assert!(e.to_string().contains("has no light groups"), "{e}");
        let mut lamp = s.clone();
        lamp.ungrouped.push("lamp Stray".into());
        let e =
            resolve_scene_lights(&lamp, &[light("sun=D65"), light("warm=A")], blend).unwrap_err();
        assert!(e.to_string().contains("lamp Stray"), "{e}");
        let mut two = s.clone();
        for (holder, value) in [("lamp A", "A"), ("lamp B", "D50")] {
            two.properties.push(LightProperty {
                group: "warm".into(),
                holder: holder.into(),
                value: value.into(),
            });
        }
        let e = resolve_scene_lights(&two, &[light("sun=D65")], blend).unwrap_err();
        assert!(e.to_string().contains("lamp B says D50"), "{e}");
        assert!(
            resolve_scene_lights(&scene(&[]), &[], blend)
                .unwrap()
                .is_empty()
        );
    }
}
