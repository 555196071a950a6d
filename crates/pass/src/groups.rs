//! Light groups in a pass: the layers a renderer writes one per group of lights, found from a
//! file's header alone (docs/compose.md, "Light groups"). A pass split by light holds, beside its
//! beauty, one RGB layer per group; compositing each with the table of its own light and summing
//! is exact where one table is not (docs/colour.md, "Lights").
//!
//! Names accepted, the group being `<group>`:
//! - Cycles (Blender 3.2 and later): `<view layer>.Combined_<group>`, e.g.
//!   `ViewLayer.Combined_sun` (checked on Debian's Blender 3.4, fixtures/light_groups);
//! - V-Ray Light Select render elements and LightMix: the element's name is the layer's;
//!   name them `VRayLightSelect_<group>` or `LightSelect_<group>`;
//! - Corona LightMix (CShading_LightSelect elements): `CShading_LightSelect_<group>` or
//!   `LightSelect_<group>`;
//!
//! each optionally after a view layer or part name (`<anything>.`).

use std::path::Path;

use glassdb_image::ImageHeader;

use crate::PassError;
use crate::read::open_seekable;

/// The renderer a group layer's name follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GroupNaming {
    /// Cycles' light groups: `Combined_<group>`.
    Cycles,
    /// V-Ray's Light Select elements: `VRayLightSelect_<group>`.
    VRay,
    /// Corona's LightMix elements: `CShading_LightSelect_<group>`.
    Corona,
    /// `LightSelect_<group>`, as either V-Ray or Corona names an element.
    LightSelect,
}

/// The prefixes of a group layer's last name component, longest first so that
/// `CShading_LightSelect_` is not read as `LightSelect_`.
const PREFIXES: [(&str, GroupNaming); 4] = [
    ("CShading_LightSelect_", GroupNaming::Corona),
    ("VRayLightSelect_", GroupNaming::VRay),
    ("LightSelect_", GroupNaming::LightSelect),
    ("Combined_", GroupNaming::Cycles),
];

/// The light group an RGB layer's name is for, and the naming it follows; `None` for a layer
/// that is not a group's (the beauty `ViewLayer.Combined`, other AOVs).
pub fn light_group_of_layer(layer: &str) -> Option<(&str, GroupNaming)> {
    let last = layer.rsplit('.').next().unwrap_or(layer);
    PREFIXES.iter().find_map(|(prefix, naming)| {
        last.strip_prefix(prefix)
            .filter(|group| !group.is_empty())
            .map(|group| (group, *naming))
    })
}

/// One light group's layer in a pass.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GroupLayer {
    /// The group's name (`sun`).
    pub group: String,
    /// The RGB layer's full name (`ViewLayer.Combined_sun`): what [`crate::read_pass`] reads.
    pub layer: String,
    /// The naming it follows.
    pub naming: GroupNaming,
}

/// The light-group layers of a pass, from its header alone, in file order: empty for a PNG or
/// an EXR without group layers. A group named by two layers is an error naming both.
pub fn light_group_layers_of(path: &Path, max_pixels: u64) -> Result<Vec<GroupLayer>, PassError> {
    let (_, header, _) = open_seekable(path, max_pixels)?;
    let ImageHeader::Exr(headers) = header else {
        return Ok(Vec::new());
    };
    let mut found: Vec<GroupLayer> = Vec::new();
    for layer in glassdb_image::rgb_layers(&headers.parts) {
        let Some((group, naming)) = light_group_of_layer(&layer.name) else {
            continue;
        };
        if let Some(first) = found.iter().find(|g| g.group == group) {
            return Err(PassError::TwoGroupLayers {
                path: path.to_path_buf(),
                group: group.to_string(),
                layers: vec![first.layer.clone(), layer.name.clone()],
            });
        }
        found.push(GroupLayer {
            group: group.to_string(),
            layer: layer.name.clone(),
            naming,
        });
    }
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn group_names_of_each_renderer() {
        let g = light_group_of_layer;
        assert_eq!(
            g("ViewLayer.Combined_sun"),
            Some(("sun", GroupNaming::Cycles))
        );
        assert_eq!(g("Combined_warm"), Some(("warm", GroupNaming::Cycles)));
        assert_eq!(g("VRayLightSelect_lamp"), Some(("lamp", GroupNaming::VRay)));
        assert_eq!(
            g("CShading_LightSelect_sky"),
            Some(("sky", GroupNaming::Corona))
        );
        assert_eq!(
            g("LightSelect_sun"),
            Some(("sun", GroupNaming::LightSelect))
        );
        assert_eq!(g("ViewLayer.Combined"), None);
        assert_eq!(g("ViewLayer.Combined_"), None);
        assert_eq!(g("ViewLayer.DiffCol"), None);
    }
}
