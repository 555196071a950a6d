//! What the registry records of a unit besides its system curves (schema 4): the build-up
//! (layers and gaps), each layer's own values, and each pane group's depth and share of the
//! reflectance per angle and side, which is what a ghost-reflection compositor needs
//! (`docs/stack.md`, "Registry record").

use serde::{Deserialize, Serialize};

use crate::record::{AngleCurve, LuminousRecord, Provenance};
use glassdb_side::Side;
use glassdb_stack::FrontBack;

/// A unit's build-up and per-group reflectances.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnitRecord {
    /// The layers and gaps, outside first.
    pub elements: Vec<UnitElement>,
    /// The pane groups (runs of layers between gaps), outside first.
    pub groups: Vec<PaneGroupRecord>,
    /// The unit's thickness (mm), when every layer's is known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness_mm: Option<f64>,
    /// Where the layers were combined: `per-wavelength`, or `per-band` (per channel: some layer
    /// has no spectrum, or the models were applied per channel).
    pub combined: String,
    /// The system's WINDOW photopic values at normal incidence (NFRC 300: D65 × CIE 1931 ȳ),
    /// when every layer has a spectrum.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub photopic: Option<SystemValues>,
    /// The system's WINDOW solar values at normal incidence (NFRC 300: ASTM E891 AM1.5 direct).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solar: Option<SystemValues>,
}

impl UnitRecord {
    /// Its pane groups' mid-plane depths behind surface #1, outside first, in metres (as a
    /// scene places its mirror planes, issue 27); `None` when a depth is not recorded.
    pub fn group_depths_m(&self) -> Option<Vec<f64>> {
        self.groups
            .iter()
            .map(|g| g.depth_mm.map(|d| d * 1e-3))
            .collect()
    }
}

/// One element of a unit's build-up.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum UnitElement {
    /// A solid layer.
    Layer(Box<UnitLayerRecord>),
    /// A gap.
    Gap(GapRecord),
}

/// One layer of a unit, as it faces in the unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnitLayerRecord {
    /// The layer is turned round (its back faces outdoors).
    pub flipped: bool,
    /// Thickness (mm), from its file or the catalog.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness_mm: Option<f64>,
    /// Its angle model (`uncoated`, `coated`, …, or `measured` with a table).
    pub model: String,
    /// Why that model.
    pub model_chosen_by: String,
    /// The layer alone at normal incidence, per channel: front (outdoor-side) reflectance.
    pub r0: [f64; 3],
    /// The layer alone: transmittance per channel.
    pub t0: [f64; 3],
    /// The layer alone: back (indoor-side) reflectance per channel.
    pub r0_back: [f64; 3],
    /// The layer alone: ISO 9050 luminous values (with a spectrum).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub luminous: Option<LuminousRecord>,
    /// In the unit at normal incidence: the WINDOW solar fraction this layer absorbs of light
    /// from outdoors (`front`) and from indoors (`back`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub absorptance: Option<Absorptance>,
    /// Its files and product.
    pub provenance: Provenance,
}

/// A layer's absorptance in its unit for light from either side: the stack engine's
/// [`FrontBack`] of one value (JSON `{"front": …, "back": …}`).
pub type Absorptance = FrontBack<f64>;

/// A gap of a unit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GapRecord {
    /// Thickness (mm).
    pub thickness_mm: f64,
    /// Its gas.
    pub gas: glassdb_stack::Gas,
}

/// System values of a unit at normal incidence under one WINDOW method.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SystemValues {
    /// Transmittance.
    pub transmittance: f64,
    /// Reflectance for light from outdoors.
    pub reflectance: f64,
    /// Reflectance for light from indoors.
    pub reflectance_back: f64,
}

/// A pane group: consecutive layers with no gap between them, reflecting as one slab about
/// its mid-plane; its share of the unit's reflectance per channel and angle, from each side
/// (`r_k(θ) = r0·C_r(cos θ)`; the shares of all groups sum to the unit's r).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PaneGroupRecord {
    /// Its layers, as indices among the unit's layers (0: the outermost).
    pub layers: Vec<usize>,
    /// Its thickness (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness_mm: Option<f64>,
    /// Its mid-plane's depth behind the unit's outer surface #1 (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_mm: Option<f64>,
    /// Its mid-plane's depth behind the unit's inner surface, seen from indoors (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_back_mm: Option<f64>,
    /// Its share of the front reflectance at normal incidence, per channel.
    pub r0: [f64; 3],
    /// `C` of its front share per channel.
    pub c_r: [AngleCurve; 3],
    /// Its share of the back reflectance at normal incidence, per channel.
    pub r0_back: [f64; 3],
    /// `C` of its back share per channel.
    pub c_r_back: [AngleCurve; 3],
}

impl PaneGroupRecord {
    /// The group's share of the reflectance seen from `side` at `cos θ`, per channel,
    /// unclamped.
    pub fn eval_raw(&self, side: Side, cos_theta: f64) -> [f64; 3] {
        let (r0, c) = match side {
            Side::Front => (&self.r0, &self.c_r),
            Side::Back => (&self.r0_back, &self.c_r_back),
        };
        std::array::from_fn(|k| r0[k] * c[k].eval(cos_theta))
    }

    /// [`PaneGroupRecord::eval_raw`] with `cos θ` clamped to [0, 1] and the share to [0, 1].
    pub fn eval(&self, side: Side, cos_theta: f64) -> [f64; 3] {
        let c = if cos_theta.is_finite() {
            cos_theta.clamp(0.0, 1.0)
        } else {
            1.0
        };
        self.eval_raw(side, c).map(|v| {
            if v.is_finite() {
                v.clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
    }
}
