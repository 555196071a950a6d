//! Light parts (issue 28, docs/compose.md "Relit swap"): a frame's passes split by the path
//! its light took, so that a glass swap relights the room. Each part is a light group of the
//! passes (a `Combined_<group>` layer in the transmission pass and in every reflection pass,
//! read by [`crate::group_passes`]) rendered with the glazing it came through clear to light
//! rays; compose scales it by what the glass of that aperture lets through: the sun by
//! `t(id, θ_sun)` per channel at the sun's angle to the aperture's plane, sky light by the
//! glass's hemispherical transmittance `t_dif`, light that met no glazing (interior lamps,
//! the exterior in daylight) by 1. The composite is linear in the passes, so the relit frame is
//! `Σ_p f_p · (trans_p·t + refl_p·r)` (method eqs. 8–10 per part).
//!
//! This file is the record's shape (`light_parts.json`, written by `glassdb blender render` per
//! frame and read by `compose --light-parts`); its validation is [`LightParts::check`].

use serde::{Deserialize, Serialize};

/// Value of [`LightParts::format`].
pub const LIGHT_PARTS_FORMAT: &str = "glassdb-light-parts/1";

/// One frame's light parts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LightParts {
    /// [`LIGHT_PARTS_FORMAT`].
    pub format: String,
    /// The parts; their sum is the frame's light.
    pub parts: Vec<LightPart>,
}

/// One part of the light: a light group of the passes and the path its light took.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LightPart {
    /// The light group naming its layers in the passes (`sun_p0_id1` for the layer
    /// `ViewLayer.Combined_sun_p0_id1`).
    pub group: String,
    /// What emitted the light, which sets how a glass scales it.
    pub source: LightSource,
    /// The glazing the light came through, clear to light rays in the passes; `None` for light
    /// that met no glazing (scaled by 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub through: Option<Aperture>,
    /// The registry light whose tables composite this part (issue 29; `None`: the default
    /// table).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub light: Option<String>,
}

/// What emitted a part's light.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum LightSource {
    /// A distant sun: parallel light from `direction_to_sun` (world coordinates, towards the
    /// sun, any length), scaled by `t(id, θ)` with `cos θ = |n · direction|`.
    Sun {
        /// Towards the sun, world coordinates.
        direction_to_sun: [f64; 3],
    },
    /// The sky (the world background): light from every direction of the hemisphere, scaled by
    /// the glass's hemispherical transmittance (sky treated as uniform for the glazing's angle
    /// response).
    Sky,
    /// Any other emitter (lamps, emissive surfaces): scaled like sky light when it came through
    /// glazing, by 1 when it did not.
    Other,
}

/// The glazing a part's light came through: the faces of one glass id on one plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Aperture {
    /// The plane's index (planes.json, the mask's plane ids).
    pub plane: usize,
    /// The plane's unit normal `[a, b, c]` (planes.json's equation), pointing to the front.
    pub normal: [f64; 3],
    /// The registry id of the glass.
    pub id: u32,
}

/// Why a light-parts record cannot be used.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LightPartsProblem(pub String);

impl LightParts {
    /// Checks the record: its format, at least one part, group names non-empty and unique
    /// (they name layers), finite non-zero directions and unit normals (to 1e-6).
    pub fn check(&self) -> Result<(), LightPartsProblem> {
        let bad = |m: String| Err(LightPartsProblem(m));
        if self.format != LIGHT_PARTS_FORMAT {
            return bad(format!(
                "format {:?}, expected {LIGHT_PARTS_FORMAT:?}",
                self.format
            ));
        }
        if self.parts.is_empty() {
            return bad("no parts".into());
        }
        for (i, part) in self.parts.iter().enumerate() {
            if part.group.is_empty() {
                return bad(format!("part {i} has an empty group name"));
            }
            if self.parts[..i].iter().any(|p| p.group == part.group) {
                return bad(format!("group {:?} is listed twice", part.group));
            }
            if let LightSource::Sun { direction_to_sun } = part.source {
                let len = direction_to_sun.iter().map(|x| x * x).sum::<f64>().sqrt();
                if !len.is_finite() || len == 0.0 {
                    return bad(format!(
                        "part {:?}: the sun direction {direction_to_sun:?} is not a direction",
                        part.group
                    ));
                }
            }
            if let Some(a) = part.through {
                let len = a.normal.iter().map(|x| x * x).sum::<f64>().sqrt();
                if !len.is_finite() || (len - 1.0).abs() > 1e-6 {
                    return bad(format!(
                        "part {:?}: plane {}'s normal {:?} is not a unit vector",
                        part.group, a.plane, a.normal
                    ));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record() -> LightParts {
        LightParts {
            format: LIGHT_PARTS_FORMAT.into(),
            parts: vec![
                LightPart {
                    group: "interior".into(),
                    source: LightSource::Other,
                    through: None,
                    light: None,
                },
                LightPart {
                    group: "sun_p0_id1".into(),
                    source: LightSource::Sun {
                        direction_to_sun: [0.3, -1.0, 0.8],
                    },
                    through: Some(Aperture {
                        plane: 0,
                        normal: [0.0, -1.0, 0.0],
                        id: 1,
                    }),
                    light: None,
                },
            ],
        }
    }

    #[test]
    fn a_record_round_trips_and_checks() {
        let r = record();
        let text = serde_json::to_string(&r).unwrap();
        assert!(text.contains(r#""kind":"sun""#), "{text}");
        let back: LightParts = serde_json::from_str(&text).unwrap();
        assert_eq!(back, r);
        assert_eq!(back.check(), Ok(()));
    }

    #[test]
    fn bad_records_are_refused_by_name() {
        let mut twice = record();
        twice.parts[1].group = "interior".into();
        assert!(twice.check().unwrap_err().0.contains("listed twice"));
        let mut normal = record();
        normal.parts[1].through.as_mut().unwrap().normal = [0.0, -2.0, 0.0];
        assert!(normal.check().unwrap_err().0.contains("not a unit vector"));
        let mut sun = record();
        sun.parts[1].source = LightSource::Sun {
            direction_to_sun: [f64::NAN, 0.0, 1.0],
        };
        assert!(sun.check().unwrap_err().0.contains("not a direction"));
    }
}
