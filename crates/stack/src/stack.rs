//! A build-up: layers and gaps, outside first, validated ([`Stack::new`]); its pane groups and
//! their depths; and the wavelengths its layers share.

use std::ops::Range;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::StackError;
use crate::layer::{Layer, LayerData};

/// The gas filling a gap. It does not change the optics (gaps are recorded to place the
/// panes and for the designer); it is what a unit's description names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Gas {
    /// Air (the default).
    #[default]
    Air,
    /// Argon.
    Argon,
    /// Krypton.
    Krypton,
    /// Xenon.
    Xenon,
}

impl Gas {
    /// Every gas, in the order help texts list them.
    pub const ALL: [Gas; 4] = [Gas::Air, Gas::Argon, Gas::Krypton, Gas::Xenon];
}

glassdb_io::enum_names!(Gas {
    Air => "air",
    Argon => "argon",
    Krypton => "krypton",
    Xenon => "xenon",
});

impl FromStr for Gas {
    type Err = String;

    /// `air`, `argon`, `krypton` or `xenon`, any case.
    fn from_str(s: &str) -> Result<Gas, String> {
        Gas::from_name(s.trim())
            .ok_or_else(|| format!("unknown gas `{s}`; expected air, argon, krypton or xenon"))
    }
}

/// A gap between two layers.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Gap {
    /// Thickness (mm).
    pub thickness_mm: f64,
    /// The fill.
    pub gas: Gas,
}

/// One element of a build-up.
#[derive(Debug, Clone, PartialEq)]
pub enum Element {
    /// A solid layer.
    Layer(Box<Layer>),
    /// A gap.
    Gap(Gap),
}

/// Consecutive layers with no gap between them (one pane, a laminate, glass with a film): they
/// reflect as one slab at one depth (issue 27's "pane group").
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PaneGroup {
    /// The indices of its layers among the stack's layers (outside first).
    pub layers: Range<usize>,
    /// Its thickness (mm), when every layer's is known.
    pub thickness_mm: Option<f64>,
    /// The depth of its mid-plane behind the unit's outer surface (#1), in mm: the thicknesses
    /// and gaps in front of it plus half its own (3 and 21.7 mm for 6 | 12.7 | 6).
    pub depth_mm: Option<f64>,
    /// The depth of its mid-plane behind the unit's inner surface, seen from indoors (mm).
    pub depth_back_mm: Option<f64>,
}

/// The samples a stack is combined on.
#[derive(Debug, Clone, PartialEq)]
pub enum Grid {
    /// The union of the layers' wavelengths where they all have data (Windows-CalcEngine's
    /// `CCommonWavelengths` with `Combine::Interpolate`), nm.
    Wavelengths(Vec<f64>),
    /// Colour channels: some layer has no spectrum.
    Channels,
}

/// A validated build-up: at least one layer, gaps only between layers and never two in a row,
/// no layer behind an opaque one, positive thicknesses, spectra sharing wavelengths.
#[derive(Debug, Clone, PartialEq)]
pub struct Stack {
    elements: Vec<Element>,
    layers: Vec<usize>,
    groups: Vec<PaneGroup>,
    grid: Grid,
}

fn positive(value: f64) -> bool {
    value.is_finite() && value > 0.0
}

impl Stack {
    /// Validates a build-up (outside first). Errors name the element's 1-based position
    /// ([`StackError::position`]).
    pub fn new(elements: Vec<Element>) -> Result<Stack, StackError> {
        let layers: Vec<usize> = elements
            .iter()
            .enumerate()
            .filter(|(_, e)| matches!(e, Element::Layer(_)))
            .map(|(i, _)| i)
            .collect();
        if layers.is_empty() {
            return Err(StackError::NoGlass);
        }
        for (i, e) in elements.iter().enumerate() {
            let position = i + 1;
            match e {
                Element::Gap(g) => {
                    if i == 0 || i + 1 == elements.len() {
                        let end = if i == 0 { "outer" } else { "inner" };
                        return Err(StackError::GapAtEnd { position, end });
                    }
                    if matches!(elements[i - 1], Element::Gap(_)) {
                        return Err(StackError::TwoGapsInARow { position });
                    }
                    if !positive(g.thickness_mm) {
                        return Err(StackError::Thickness {
                            position,
                            what: "gap".into(),
                            value: g.thickness_mm,
                        });
                    }
                }
                Element::Layer(l) => {
                    if let Some(d) = l.thickness_mm
                        && !positive(d)
                    {
                        return Err(StackError::Thickness {
                            position,
                            what: l.label.clone(),
                            value: d,
                        });
                    }
                }
            }
        }
        for w in layers.windows(2) {
            if let Element::Layer(l) = &elements[w[0]]
                && l.is_opaque()
            {
                return Err(StackError::OpaqueBeforeAnother {
                    position: w[0] + 1,
                    label: l.label.clone(),
                    next: w[1] + 1,
                });
            }
        }
        let grid = common_grid(&elements)?;
        let groups = pane_groups(&elements, &layers)?;
        Ok(Stack {
            elements,
            layers,
            groups,
            grid,
        })
    }

    /// The elements, outside first.
    pub fn elements(&self) -> &[Element] {
        &self.elements
    }

    /// The layers, outside first.
    pub fn layers(&self) -> impl ExactSizeIterator<Item = &Layer> + '_ {
        self.layers.iter().map(|&i| match &self.elements[i] {
            Element::Layer(l) => l.as_ref(),
            Element::Gap(_) => unreachable!("layer indices point at layers"),
        })
    }

    /// The 1-based element position of each layer.
    pub fn layer_positions(&self) -> Vec<usize> {
        self.layers.iter().map(|i| i + 1).collect()
    }

    /// The pane groups, outside first.
    pub fn groups(&self) -> &[PaneGroup] {
        &self.groups
    }

    /// The samples the layers are combined on.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The unit's total thickness (mm), when every layer's is known.
    pub fn thickness_mm(&self) -> Option<f64> {
        self.elements.iter().try_fold(0.0, |acc, e| match e {
            Element::Layer(l) => l.thickness_mm.map(|d| acc + d),
            Element::Gap(g) => Some(acc + g.thickness_mm),
        })
    }
}

/// The union of the spectral layers' wavelengths within the range they all cover; channels
/// when some layer has no spectrum.
fn common_grid(elements: &[Element]) -> Result<Grid, StackError> {
    let mut common: Option<Vec<f64>> = None;
    for (i, e) in elements.iter().enumerate() {
        let Element::Layer(l) = e else { continue };
        let LayerData::Spectral { wavelength_nm, .. } = &l.data else {
            return Ok(Grid::Channels);
        };
        common = Some(match common {
            None => wavelength_nm.clone(),
            Some(c) => {
                let lo = c[0].max(wavelength_nm[0]);
                let hi = c[c.len() - 1].min(wavelength_nm[wavelength_nm.len() - 1]);
                let inside = |v: &[f64]| -> Vec<f64> {
                    v.iter().copied().filter(|&w| w >= lo && w <= hi).collect()
                };
                let merged = merge_sorted(&inside(&c), &inside(wavelength_nm));
                if merged.len() < 2 {
                    return Err(StackError::NoOverlap {
                        position: i + 1,
                        label: l.label.clone(),
                        start_nm: wavelength_nm[0],
                        end_nm: wavelength_nm[wavelength_nm.len() - 1],
                        common_start_nm: c[0],
                        common_end_nm: c[c.len() - 1],
                    });
                }
                merged
            }
        });
    }
    Ok(common.map_or(Grid::Channels, Grid::Wavelengths))
}

/// Wavelengths closer than this (nm) are one wavelength of the common grid: WINDOW's own
/// wavelength tolerance (1e-6 µm). Files that store 0.345 µm as 0.344999999 would otherwise
/// put two samples 1e-6 nm apart, which a cubic spline through the grid does not need.
const SAME_WAVELENGTH_NM: f64 = 1e-3;

/// The sorted union of two ascending arrays; a value within [`SAME_WAVELENGTH_NM`] of the one
/// before it is left out.
fn merge_sorted(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut all: Vec<f64> = a.iter().chain(b).copied().collect();
    all.sort_by(f64::total_cmp);
    let mut out: Vec<f64> = Vec::with_capacity(all.len());
    for w in all {
        match out.last() {
            Some(&last) if w - last < SAME_WAVELENGTH_NM => {}
            _ => out.push(w),
        }
    }
    out
}

/// The pane groups (runs of layers between gaps) and their depths. With more than one group,
/// every layer needs a thickness (the depths are recorded for the ghost reflections).
fn pane_groups(
    elements: &[Element],
    layer_elements: &[usize],
) -> Result<Vec<PaneGroup>, StackError> {
    let mut runs: Vec<Vec<usize>> = vec![Vec::new()];
    for (i, e) in elements.iter().enumerate() {
        match e {
            Element::Gap(_) => runs.push(Vec::new()),
            Element::Layer(_) => runs.last_mut().expect("one run at least").push(i),
        }
    }
    if runs.len() > 1 {
        for &i in layer_elements {
            if let Element::Layer(l) = &elements[i]
                && l.thickness_mm.is_none()
            {
                return Err(StackError::MissingThickness {
                    position: i + 1,
                    label: l.label.clone(),
                });
            }
        }
    }
    let thickness_of = |i: usize| match &elements[i] {
        Element::Layer(l) => l.thickness_mm,
        Element::Gap(g) => Some(g.thickness_mm),
    };
    let total: Option<f64> = (0..elements.len()).map(thickness_of).sum();
    let mut groups = Vec::with_capacity(runs.len());
    let mut first_layer = 0;
    for run in runs {
        let before: Option<f64> = (0..run[0]).map(thickness_of).sum();
        let own: Option<f64> = run.iter().map(|&i| thickness_of(i)).sum();
        let depth_mm = before.zip(own).map(|(b, o)| b + o / 2.0);
        groups.push(PaneGroup {
            layers: first_layer..first_layer + run.len(),
            thickness_mm: own,
            depth_mm,
            depth_back_mm: total.zip(depth_mm).map(|(t, d)| t - d),
        });
        first_layer += run.len();
    }
    Ok(groups)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layer::LayerOptions;

    fn pane(label: &str, thickness: f64, t: f64) -> Element {
        let mut l = Layer::from_spectra(
            label,
            vec![300.0, 400.0, 500.0, 2500.0],
            vec![t; 4],
            vec![0.08; 4],
            vec![0.08; 4],
            Some("Monolithic"),
            &LayerOptions::default(),
        )
        .unwrap();
        l.thickness_mm = Some(thickness);
        Element::Layer(Box::new(l))
    }

    fn gap(mm: f64) -> Element {
        Element::Gap(Gap {
            thickness_mm: mm,
            gas: Gas::Argon,
        })
    }

    /// A 4 mm pane, a 10 mm gap, then `layer`.
    fn behind_a_gap(layer: Layer) -> Result<Stack, StackError> {
        Stack::new(vec![
            pane("a", 4.0, 0.8),
            gap(10.0),
            Element::Layer(Box::new(layer)),
        ])
    }

    #[test]
    fn depths_of_6_12_7_6() {
        let s = Stack::new(vec![pane("a", 6.0, 0.8), gap(12.7), pane("b", 6.0, 0.8)]).unwrap();
        let d: Vec<f64> = s.groups().iter().map(|g| g.depth_mm.unwrap()).collect();
        assert!(
            (d[0] - 3.0).abs() < 1e-12 && (d[1] - 21.7).abs() < 1e-12,
            "{d:?}"
        );
        assert!((s.groups()[0].depth_back_mm.unwrap() - 21.7).abs() < 1e-12);
        assert_eq!(s.thickness_mm(), Some(24.7));
    }

    #[test]
    fn bad_build_ups_name_the_element() {
        let cases: Vec<(Vec<Element>, &str)> = vec![
            (vec![], "no glass layer"),
            (vec![gap(12.0)], "no glass layer"),
            (
                vec![gap(12.0), pane("a", 4.0, 0.8)],
                "element 1 is a gap at the outer end",
            ),
            (
                vec![pane("a", 4.0, 0.8), gap(12.0)],
                "element 2 is a gap at the inner end",
            ),
            (
                vec![
                    pane("a", 4.0, 0.8),
                    gap(12.0),
                    gap(6.0),
                    pane("b", 4.0, 0.8),
                ],
                "elements 2 and 3 are two gaps in a row",
            ),
            (
                vec![pane("a", 4.0, 0.8), gap(-1.0), pane("b", 4.0, 0.8)],
                "element 2 (gap): thickness -1",
            ),
            (
                vec![pane("a", 4.0, 0.8), gap(f64::NAN), pane("b", 4.0, 0.8)],
                "thickness NaN",
            ),
            (
                vec![pane("a", -4.0, 0.8), gap(12.0), pane("b", 4.0, 0.8)],
                "element 1 (a): thickness -4",
            ),
            (
                vec![pane("dark", 4.0, 0.0), gap(12.0), pane("b", 4.0, 0.8)],
                "layer 1 (dark) is opaque but layer 3",
            ),
        ];
        for (elements, want) in cases {
            let e = Stack::new(elements).unwrap_err().to_string();
            assert!(e.contains(want), "{e} lacks {want}");
        }
    }

    #[test]
    fn union_of_wavelengths_within_the_common_range() {
        let mut b = Layer::from_spectra(
            "b",
            vec![350.0, 450.0, 500.0, 3000.0],
            vec![0.8; 4],
            vec![0.08; 4],
            vec![0.08; 4],
            None,
            &LayerOptions::default(),
        )
        .unwrap();
        b.thickness_mm = Some(3.0);
        let s = behind_a_gap(b.clone()).unwrap();
        assert_eq!(
            s.grid(),
            &Grid::Wavelengths(vec![350.0, 400.0, 450.0, 500.0, 2500.0])
        );
        let LayerData::Spectral { wavelength_nm, .. } = &mut b.data else {
            unreachable!()
        };
        *wavelength_nm = vec![2600.0, 2700.0, 2800.0, 3000.0];
        let e = behind_a_gap(b).unwrap_err();
        assert!(
            e.to_string()
                .contains("layer 3 (b, 2600–3000 nm) does not overlap"),
            "{e}"
        );
        let mut c = Layer::from_channels(
            "rgb",
            [0.8; 3],
            [0.1; 3],
            [0.1; 3],
            &LayerOptions::default(),
        );
        c.thickness_mm = None;
        let e = behind_a_gap(c).unwrap_err();
        assert!(
            e.to_string().contains("layer 3 (rgb) has no thickness"),
            "{e}"
        );
    }
}
