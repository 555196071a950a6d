//! Which face of a glass pane the camera sees. A registry record holds values for both faces
//! (`r0`, `r0_back`), a scene's plane knows which one faces the eye (`planes.json`'s
//! `eye_side`), and the compositor looks up the side each plane shows: all three name it with
//! this one type, low in the crate graph so that none of them depends on another for it.

#![warn(missing_docs)]

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// Which face of the glass the viewer sees (`front` or `back` in JSON and on the command line).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// The front face (the catalog's Rf; the viewer's side in the scene).
    Front,
    /// The back face (Rb).
    Back,
}

impl Side {
    /// The lowercase name: `front` or `back`.
    pub fn name(self) -> &'static str {
        match self {
            Side::Front => "front",
            Side::Back => "back",
        }
    }
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A side name that is neither `front` nor `back`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown side `{0}`; expected front or back")]
pub struct UnknownSide(pub String);

impl FromStr for Side {
    type Err = UnknownSide;

    /// `front` or `back`, any case, surrounding spaces ignored.
    fn from_str(s: &str) -> Result<Side, UnknownSide> {
        [Side::Front, Side::Back]
            .into_iter()
            .find(|side| s.trim().eq_ignore_ascii_case(side.name()))
            .ok_or_else(|| UnknownSide(s.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_names_parse_print_and_serialise() {
        for side in [Side::Front, Side::Back] {
            assert_eq!(side.to_string().parse::<Side>().unwrap(), side);
            assert_eq!(serde_json::to_string(&side).unwrap(), format!("\"{side}\""));
        }
        assert_eq!(" Back ".parse::<Side>().unwrap(), Side::Back);
        assert!("left".parse::<Side>().is_err());
        assert!(serde_json::from_str::<Side>("\"up\"").is_err());
    }
}
