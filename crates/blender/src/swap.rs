//! What a glass swap on a run's passes can and cannot change. The passes are rendered with the
//! glass as a thin pane in the scene, so the light that entered the room through the glazing
//! (sun patches, sky light, everything seen through the glass) was filtered by the glass of the
//! render. Compositing with another registry re-tints the glass pixels only; until the passes
//! keep that light apart (issue 28's light-path split), a swap leaves the room lit by the old
//! glass. The run record names the glasses that lit its passes ([`PassGlass`]), and
//! [`swap_warnings`] says, per glass id, when a composite uses another.

use std::fmt;

use glassdb_colour::RgbSpace;
use glassdb_registry::{ColourBasis, RegistryTable};
use serde::{Deserialize, Serialize};

use crate::job::RunRecord;
use crate::pipeline::RegistryChoice;

/// Two glasses whose normal or hemispherical transmittance differ by less than this (in any
/// channel) light a room alike: the registry's own rounding in a JSON round trip is far smaller.
const SAME_GLASS_TOLERANCE: f64 = 1e-6;

/// A glass whose thin-pane shader lit a run's passes, as the run record keeps it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PassGlass {
    /// Its registry id.
    pub id: u16,
    /// Its name in the render's registry.
    pub name: String,
    /// Transmittance at normal incidence, per channel (the shader's table).
    pub t0: [f64; 3],
    /// Hemispherical transmittance per channel: what it passes of the sky.
    pub t_dif: [f64; 3],
}

/// The registry table the thin-pane shader draws from: linear Rec.709 (Blender's default
/// working space), else the registry's default table.
pub(crate) fn shader_table(registry: &RegistryChoice) -> &RegistryTable {
    registry
        .registry
        .table(ColourBasis::Space(RgbSpace::Srgb))
        .unwrap_or_else(|| registry.registry.default_table())
}

/// The glasses of `ids` (the run's glass materials' ids, repeats allowed) as the run record
/// keeps them, in id order; an id the table lacks is left out (the render refused it before).
pub(crate) fn pass_glasses(
    ids: impl IntoIterator<Item = u16>,
    registry: &RegistryChoice,
) -> Vec<PassGlass> {
    let table = shader_table(registry);
    let mut ids: Vec<u16> = ids.into_iter().collect();
    ids.sort_unstable();
    ids.dedup();
    ids.into_iter()
        .filter_map(|id| table.glass(id))
        .map(|g| PassGlass {
            id: g.id,
            name: g.name.clone(),
            t0: g.t0,
            t_dif: g.t_dif(),
        })
        .collect()
}

/// What a swap leaves wrong, for the command's warnings and the run report.
#[derive(Debug, Clone, PartialEq)]
pub enum SwapWarning {
    /// Glass `id` lit the passes as one glass and is composited as another: its pixels change,
    /// the light it let into the room does not.
    RoomLitByRenderedGlass {
        /// The glass id.
        id: u16,
        /// The glass the passes were rendered with.
        rendered: String,
        /// The glass composited.
        composited: String,
        /// Composited over rendered hemispherical transmittance, green channel: about how much
        /// brighter or darker the room's daylight through this glass should be.
        t_dif_ratio: f64,
    },
    /// The run record does not say which glasses lit its passes (a run before it did).
    GlassesOfThePassesUnknown {
        /// The registry composited with.
        registry: String,
    },
}

impl fmt::Display for SwapWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SwapWarning::RoomLitByRenderedGlass {
                id,
                rendered,
                composited,
                t_dif_ratio,
            } => write!(
                f,
                "glass id {id}: the passes were rendered with \"{rendered}\" and are composited as \"{composited}\"; \
                 only its pixels change: the light that came into the scene through it (sun patches, sky light, \
                 what is seen through the glass) stays that of \"{rendered}\" (the new glass passes {t_dif_ratio:.2}× \
                 its diffuse light), because these passes keep no light-path split; render the scene with the new \
                 glass for a right image"
            ),
            SwapWarning::GlassesOfThePassesUnknown { registry } => write!(
                f,
                "the run record does not say which glasses lit its passes (a run before glassdb recorded them): \
                 if {registry}'s glasses differ from the render's, only the glass pixels change and the light that \
                 came into the scene through the glazing stays the render's"
            ),
        }
    }
}

/// The warnings of compositing `record`'s passes with `registry`: one per recorded glass that
/// the registry holds differently (another name, t0 or t_dif), or one saying the record does
/// not know its glasses. A glass the registry lacks is compose's error, not a warning.
pub fn swap_warnings(record: &RunRecord, registry: &RegistryChoice) -> Vec<SwapWarning> {
    if record.lit_by.is_empty() {
        return vec![SwapWarning::GlassesOfThePassesUnknown {
            registry: registry.label.clone(),
        }];
    }
    let now = pass_glasses(record.lit_by.iter().map(|g| g.id), registry);
    record
        .lit_by
        .iter()
        .filter_map(|was| {
            let is = now.iter().find(|g| g.id == was.id)?;
            let differs = |a: &[f64; 3], b: &[f64; 3]| {
                a.iter()
                    .zip(b)
                    .any(|(x, y)| (x - y).abs() > SAME_GLASS_TOLERANCE)
            };
            (is.name != was.name || differs(&is.t0, &was.t0) || differs(&is.t_dif, &was.t_dif))
                .then(|| SwapWarning::RoomLitByRenderedGlass {
                    id: was.id,
                    rendered: was.name.clone(),
                    composited: is.name.clone(),
                    t_dif_ratio: is.t_dif[1] / was.t_dif[1],
                })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bundled() -> RegistryChoice {
        RegistryChoice {
            registry: glassdb_registry::default_registry().unwrap(),
            label: "the bundled catalog".into(),
        }
    }

    fn record(lit_by: Vec<PassGlass>) -> RunRecord {
        RunRecord {
            format: crate::job::RECORD_FORMAT.into(),
            blend: "s.blend".into(),
            blender: "3.4.1".into(),
            glass: vec!["Glass=1".into()],
            samples: None,
            width: 4,
            height: 4,
            overrides: Vec::new(),
            frames: Vec::new(),
            lit_by,
            surfaces: None,
            lights: Vec::new(),
            group_layers: false,
        }
    }

    /// The same registry: no warning. Glass 1 replaced by glass 5's values under id 1: one
    /// warning naming both glasses and the ratio of their t_dif. An old record: one warning
    /// that says what a swap cannot fix.
    #[test]
    fn a_swap_is_named_with_what_it_leaves_lit_by_the_old_glass() {
        let same = bundled();
        let lit_by = pass_glasses([5, 1, 1], &same);
        assert_eq!(lit_by.iter().map(|g| g.id).collect::<Vec<_>>(), [1, 5]);
        assert!(swap_warnings(&record(lit_by.clone()), &same).is_empty());

        let mut other = bundled();
        for table in other.registry.tables_mut() {
            let dark = table.glass(5).unwrap().clone();
            let clear = table.glasses.iter_mut().find(|g| g.id == 1).unwrap();
            *clear = glassdb_registry::GlassRecord { id: 1, ..dark };
        }
        let warnings = swap_warnings(&record(lit_by.clone()), &other);
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        let SwapWarning::RoomLitByRenderedGlass {
            id, t_dif_ratio, ..
        } = &warnings[0]
        else {
            panic!("{warnings:?}")
        };
        assert_eq!(*id, 1);
        let (clear, dark) = (&lit_by[0], &lit_by[1]);
        assert!((t_dif_ratio - dark.t_dif[1] / clear.t_dif[1]).abs() < 1e-12);
        assert!(*t_dif_ratio < 0.95, "{t_dif_ratio}");
        let text = warnings[0].to_string();
        assert!(
            text.contains(&format!("rendered with \"{}\"", clear.name))
                && text.contains(&format!("composited as \"{}\"", dark.name))
                && text.contains("sun patches"),
            "{text}"
        );

        let old = swap_warnings(&record(Vec::new()), &same);
        assert_eq!(
            old,
            [SwapWarning::GlassesOfThePassesUnknown {
                registry: "the bundled catalog".into()
            }]
        );
        assert!(old[0].to_string().contains("does not say which glasses"));
    }
}
