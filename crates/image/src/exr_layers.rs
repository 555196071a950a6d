//! The names users type for EXR channels and RGB layers, resolved against a file's parts in one
//! place for passes and masks alike: a channel's full name (`ViewLayer.Combined.R`), a part
//! name that channels inside may repeat (Blender 5 and Nuke store `ViewLayer.Combined.R` in the
//! part `ViewLayer.Combined`), a view (`left`), the last component of a layer
//! (`Combined` for `ViewLayer.Combined`), single-value passes without their one-letter channel
//! (`IndexMA` for `ViewLayer.IndexMA.X`), and Blender's renamed passes (3.x `IndexMA` is 5.x
//! `Material Index`).

use crate::ExrPart;

/// Blender pass names that differ between 3.x (first) and 4.x–5.x (second).
const BLENDER_PASS_ALIASES: &[(&str, &str)] =
    &[("IndexMA", "Material Index"), ("IndexOB", "Object Index")];

impl ExrPart {
    /// The name a user gives to select channel `index`: in a multi-part file the part name and
    /// the channel name (`layer.channel`), without repeating a prefix the channel name already
    /// carries; the channel name as stored otherwise.
    pub fn qualified_name(&self, index: usize) -> Option<String> {
        let c = self.channels.get(index)?;
        Some(match self.layer_name.as_deref() {
            Some(layer)
                if self.multi_part
                    && !layer.is_empty()
                    && !c.name.starts_with(&format!("{layer}.")) =>
            {
                format!("{layer}.{}", c.name)
            }
            _ => c.name.clone(),
        })
    }
}

/// Every selectable channel name in the file (for error messages).
pub fn all_channel_names(parts: &[ExrPart]) -> Vec<String> {
    parts
        .iter()
        .flat_map(|p| (0..p.channels.len()).filter_map(|i| p.qualified_name(i)))
        .collect()
}

/// What a channel name resolved to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ChannelMatch {
    /// (part, channel index in the part).
    Found(usize, usize),
    /// No channel fits the name.
    Missing,
    /// Several channels fit a shortened name; their full names.
    Ambiguous(Vec<String>),
}

/// Spellings of `name` with Blender's renamed passes swapped, the name itself first.
fn spellings(name: &str) -> Vec<String> {
    let mut out = vec![name.to_string()];
    for (old, new) in BLENDER_PASS_ALIASES {
        for (from, to) in [(old, new), (new, old)] {
            let swapped = name
                .split('.')
                .map(|c| if c == *from { *to } else { c })
                .collect::<Vec<_>>()
                .join(".");
            if !out.contains(&swapped) {
                out.push(swapped);
            }
        }
    }
    out
}

/// How a typed name may fit a channel's full name, from strictest to loosest.
#[derive(Debug, Clone, Copy)]
enum NameRule {
    /// `ViewLayer.IndexMA.X` is `ViewLayer.IndexMA.X`.
    Exact,
    /// `ViewLayer.IndexMA` fits `ViewLayer.IndexMA.X` (one more component, a channel letter).
    PlusLetter,
    /// `IndexMA.X` fits `ViewLayer.IndexMA.X`.
    EndsWith,
    /// `IndexMA` fits `ViewLayer.IndexMA.X`.
    EndsWithPlusLetter,
}

impl NameRule {
    fn fits(self, full_name: &str, typed: &str) -> bool {
        let suffix = format!(".{typed}");
        match self {
            NameRule::Exact => full_name == typed,
            NameRule::PlusLetter => full_name
                .rsplit_once('.')
                .is_some_and(|(stem, letter)| stem == typed && !letter.is_empty()),
            NameRule::EndsWith => full_name.ends_with(&suffix),
            NameRule::EndsWithPlusLetter => full_name
                .rsplit_once('.')
                .is_some_and(|(stem, letter)| stem.ends_with(&suffix) && !letter.is_empty()),
        }
    }
}

/// Finds the channel `name` (inside `layer`, when given: `layer.name`) names, trying in order:
/// the full name; the name plus one channel letter (`IndexMA` → `IndexMA.X`); then, without a
/// layer, any channel whose full name ends with `.name` or `.name.<letter>`. Blender's renamed
/// passes are tried under both spellings at each step.
pub fn find_channel(parts: &[ExrPart], name: &str, layer: Option<&str>) -> ChannelMatch {
    let full = match layer {
        Some(l) if !l.is_empty() => format!("{}.{name}", l.trim_end_matches('.')),
        _ => name.to_string(),
    };
    let all: Vec<(usize, usize, String)> = parts
        .iter()
        .enumerate()
        .flat_map(|(p, part)| {
            (0..part.channels.len()).filter_map(move |c| part.qualified_name(c).map(|n| (p, c, n)))
        })
        .collect();
    let pick = |found: Vec<&(usize, usize, String)>| match found.as_slice() {
        [] => ChannelMatch::Missing,
        [one] => ChannelMatch::Found(one.0, one.1),
        many => ChannelMatch::Ambiguous(many.iter().map(|f| f.2.clone()).collect()),
    };
    let rules: &[NameRule] = if layer.is_none_or(str::is_empty) {
        &[
            NameRule::Exact,
            NameRule::PlusLetter,
            NameRule::EndsWith,
            NameRule::EndsWithPlusLetter,
        ]
    } else {
        &[NameRule::Exact, NameRule::PlusLetter]
    };
    for rule in rules {
        for spelling in spellings(&full) {
            match pick(
                all.iter()
                    .filter(|(_, _, n)| rule.fits(n, &spelling))
                    .collect(),
            ) {
                ChannelMatch::Missing => continue,
                found => return found,
            }
        }
    }
    ChannelMatch::Missing
}

/// An RGB layer of an EXR file: channels `name.R`, `name.G`, `name.B` (and `name.A`) of one part.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbLayer {
    /// The part holding the channels.
    pub part: usize,
    /// The layer's full name (`ViewLayer.Combined`); empty for bare `R`, `G`, `B` in a part
    /// without a name.
    pub name: String,
    /// Indices of R, G and B in the part's channel list.
    pub rgb: [usize; 3],
    /// Index of A, when present.
    pub alpha: Option<usize>,
    /// The view the layer belongs to (multi-view files).
    pub view: Option<String>,
}

impl RgbLayer {
    /// The name as shown to users: `(R, G, B)` for the bare layer.
    pub fn label(&self) -> String {
        if self.name.is_empty() {
            "(R, G, B)".into()
        } else {
            self.name.clone()
        }
    }
}

/// Every RGB layer of the file, in part and channel order.
pub fn rgb_layers(parts: &[ExrPart]) -> Vec<RgbLayer> {
    let mut out = Vec::new();
    for (p, part) in parts.iter().enumerate() {
        part_rgb_layers(p, part, &mut out);
    }
    out
}

/// Whether part `part` may hold an RGB layer named `name`, judged without building its
/// channels' names: a channel name starts with `name`, or `name` starts with the part's name.
fn may_hold_layer(part: &ExrPart, name: &str) -> bool {
    part.channels.iter().any(|c| c.name.starts_with(name))
        || part
            .layer_name
            .as_deref()
            .is_some_and(|l| !l.is_empty() && name.starts_with(l))
}

/// The RGB layers of part `part` (index `p`), in channel order, appended to `out`.
fn part_rgb_layers(p: usize, part: &ExrPart, out: &mut Vec<RgbLayer>) {
    {
        let names: Vec<String> = (0..part.channels.len())
            .filter_map(|i| part.qualified_name(i))
            .collect();
        for name in &names {
            let prefix = match name.strip_suffix('R') {
                Some(pre) if pre.is_empty() || pre.ends_with('.') => pre.trim_end_matches('.'),
                _ => continue,
            };
            let find = |c: &str| {
                let full = if prefix.is_empty() {
                    c.to_string()
                } else {
                    format!("{prefix}.{c}")
                };
                names.iter().position(|n| *n == full)
            };
            let (Some(r), Some(g), Some(b)) = (find("R"), find("G"), find("B")) else {
                continue;
            };
            let view = part
                .view
                .clone()
                .or_else(|| match part.multi_view.as_slice() {
                    [] => None,
                    [hero, others @ ..] => {
                        if prefix.is_empty() {
                            Some(hero.clone())
                        } else {
                            others
                                .iter()
                                .find(|v| {
                                    prefix == v.as_str() || prefix.starts_with(&format!("{v}."))
                                })
                                .cloned()
                        }
                    }
                });
            out.push(RgbLayer {
                part: p,
                name: prefix.to_string(),
                rgb: [r, g, b],
                alpha: find("A"),
                view,
            });
        }
    }
}

/// The reflection passes of several glass planes in one file: the RGB layers named `plane<K>`
/// (a part or channel prefix `plane0`, `plane1`, …; Blender's `plane<K>.Combined` too), as
/// (K, layer name) by increasing K. Empty when the file has no such layer.
pub fn plane_layers(parts: &[ExrPart]) -> Vec<(u32, String)> {
    let mut out: Vec<(u32, String)> = rgb_layers(parts)
        .into_iter()
        .filter_map(|l| {
            let first = l.name.strip_suffix(".Combined").unwrap_or(&l.name);
            let k = first.strip_prefix("plane")?;
            (!k.is_empty()
                && k.bytes().all(|b| b.is_ascii_digit())
                && (k == "0" || !k.starts_with('0')))
            .then(|| k.parse::<u32>().ok())
            .flatten()
            .map(|k| (k, l.name.clone()))
        })
        .collect();
    out.sort();
    out
}

/// The reflection passes of units' pane groups in one file (issue 27): the RGB layers named
/// `plane<K>.group<G>` (G ≥ 1; group 0 is the plane's own layer `plane<K>`), as (K, G, layer
/// name) by increasing K, then G.
pub fn plane_group_layers(parts: &[ExrPart]) -> Vec<(u32, u32, String)> {
    let number = |s: &str| -> Option<u32> {
        (!s.is_empty()
            && s.bytes().all(|b| b.is_ascii_digit())
            && (s == "0" || !s.starts_with('0')))
        .then(|| s.parse().ok())
        .flatten()
    };
    let mut out: Vec<(u32, u32, String)> = rgb_layers(parts)
        .into_iter()
        .filter_map(|l| {
            let name = l.name.strip_suffix(".Combined").unwrap_or(&l.name);
            let (plane, group) = name.strip_prefix("plane")?.split_once(".group")?;
            let (k, g) = (number(plane)?, number(group)?);
            (g >= 1).then(|| (k, g, l.name.clone()))
        })
        .collect();
    out.sort();
    out
}

/// Why no RGB layer could be chosen.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LayerChoiceError {
    /// The file has no R, G, B channels at all; every channel it has.
    NoRgb {
        /// Every channel the file has.
        available: Vec<String>,
    },
    /// No layer has the name asked for; the layers there are.
    NotFound {
        /// The layer asked for.
        wanted: String,
        /// The RGB layers the file has.
        layers: Vec<String>,
    },
    /// Several layers fit (the name, or no name was given).
    Ambiguous {
        /// The layer asked for (`None`: the default choice).
        wanted: Option<String>,
        /// The RGB layers that fit it.
        layers: Vec<String>,
    },
}

/// Chooses the RGB layer `wanted` names, trying in order: a layer's full name, a view name (the
/// view's main layer), the last components of a name (`Combined` for `ViewLayer.Combined`).
/// Without a name: the only layer; else the bare `R`, `G`, `B`; else the one layer named
/// `…Combined`.
pub fn choose_rgb_layer(
    parts: &[ExrPart],
    wanted: Option<&str>,
) -> Result<RgbLayer, LayerChoiceError> {
    // A layer's full name: the first layer of that name, found without listing every part's
    // layers (the planes of a file of many parts each ask for their own).
    if let Some(want) = wanted.map(|w| w.trim_end_matches('.')) {
        let mut found = Vec::new();
        for (p, part) in parts.iter().enumerate() {
            if may_hold_layer(part, want) {
                part_rgb_layers(p, part, &mut found);
                if let Some(l) = found.iter().find(|l| l.name == want) {
                    return Ok(l.clone());
                }
                found.clear();
            }
        }
    }
    let layers = rgb_layers(parts);
    let labels = || layers.iter().map(RgbLayer::label).collect::<Vec<_>>();
    if layers.is_empty() {
        return Err(LayerChoiceError::NoRgb {
            available: all_channel_names(parts),
        });
    }
    let unique = |found: Vec<&RgbLayer>| match found.as_slice() {
        [one] => Some(Ok((*one).clone())),
        [] => None,
        many => Some(Err(LayerChoiceError::Ambiguous {
            wanted: wanted.map(str::to_string),
            layers: many.iter().map(|l| l.label()).collect(),
        })),
    };
    let Some(want) = wanted.map(|w| w.trim_end_matches('.')) else {
        if let [only] = layers.as_slice() {
            return Ok(only.clone());
        }
        if let Some(bare) = layers.iter().find(|l| l.name.is_empty()) {
            return Ok(bare.clone());
        }
        return unique(
            layers
                .iter()
                .filter(|l| l.name.ends_with("Combined"))
                .collect(),
        )
        .unwrap_or_else(|| {
            Err(LayerChoiceError::Ambiguous {
                wanted: None,
                layers: labels(),
            })
        });
    };
    if let Some(l) = layers.iter().find(|l| l.name == want) {
        return Ok(l.clone());
    }
    let in_view: Vec<&RgbLayer> = layers
        .iter()
        .filter(|l| l.view.as_deref() == Some(want))
        .collect();
    // A view's main layer: the bare one, the one named after the view, or its part's own.
    let main: Vec<&RgbLayer> = in_view
        .iter()
        .copied()
        .filter(|l| {
            l.name.is_empty()
                || l.name == want
                || parts.get(l.part).and_then(|p| p.layer_name.as_deref()) == Some(&l.name)
        })
        .collect();
    if let Some(found) = unique(main).or_else(|| unique(in_view)) {
        return found;
    }
    let suffix = format!(".{want}");
    if let Some(found) = unique(
        layers
            .iter()
            .filter(|l| l.name.ends_with(&suffix))
            .collect(),
    ) {
        return found;
    }
    Err(LayerChoiceError::NotFound {
        wanted: want.to_string(),
        layers: labels(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ExrChannelInfo, ExrSampleType, PixelWindow};

    fn part(name: Option<&str>, channels: &[&str]) -> ExrPart {
        let w = PixelWindow::at_origin(2, 2);
        ExrPart {
            layer_name: name.map(str::to_string),
            width: 2,
            height: 2,
            data_window: w,
            display_window: w,
            channels: channels
                .iter()
                .map(|c| ExrChannelInfo {
                    name: c.to_string(),
                    sample_type: ExrSampleType::Half,
                    sampling: (1, 1),
                })
                .collect(),
            compression: exr::compression::Compression::ZIP16,
            deep: false,
            colour: crate::ExrColourTag::default(),
            view: None,
            multi_view: Vec::new(),
            multi_resolution: false,
            multi_part: name.is_some(),
        }
    }

    #[test]
    fn blender_single_part_and_multi_part_names_resolve_alike() {
        let b3 = [part(
            None,
            &[
                "ViewLayer.Combined.A",
                "ViewLayer.Combined.B",
                "ViewLayer.Combined.G",
                "ViewLayer.Combined.R",
                "ViewLayer.IndexMA.X",
                "ViewLayer.facing.X",
            ],
        )];
        let b5 = [
            part(
                Some("ViewLayer.Combined"),
                &[
                    "ViewLayer.Combined.A",
                    "ViewLayer.Combined.B",
                    "ViewLayer.Combined.G",
                    "ViewLayer.Combined.R",
                ],
            ),
            part(
                Some("ViewLayer.Material Index"),
                &["ViewLayer.Material Index.X"],
            ),
            part(Some("ViewLayer.facing"), &["ViewLayer.facing.X"]),
        ];
        for (parts, index_part) in [(&b3[..], 0), (&b5[..], 1)] {
            for want in [None, Some("ViewLayer.Combined"), Some("Combined")] {
                let l = choose_rgb_layer(parts, want).unwrap();
                assert_eq!(l.name, "ViewLayer.Combined");
                assert!(l.alpha.is_some());
            }
            for (name, layer) in [
                ("IndexMA", None),
                ("Material Index", None),
                ("ViewLayer.IndexMA", None),
                ("IndexMA", Some("ViewLayer")),
                ("ViewLayer.IndexMA.X", None),
            ] {
                assert!(
                    matches!(find_channel(parts, name, layer), ChannelMatch::Found(p, _) if p == index_part),
                    "{name} in {layer:?}"
                );
            }
            assert!(matches!(
                find_channel(parts, "facing", None),
                ChannelMatch::Found(..)
            ));
            assert_eq!(find_channel(parts, "id", None), ChannelMatch::Missing);
        }
        assert_eq!(b5[0].qualified_name(3).unwrap(), "ViewLayer.Combined.R");
    }

    #[test]
    fn a_single_part_name_does_not_prefix_its_channels() {
        // OpenEXR's Beachball/singlepart: one part named "rgba", views [right, left].
        let mut p = part(Some("rgba"), &["B", "G", "R", "left.B", "left.G", "left.R"]);
        p.multi_part = false;
        p.multi_view = vec!["right".into(), "left".into()];
        let parts = [p];
        let default = choose_rgb_layer(&parts, None).unwrap();
        assert_eq!(
            (default.name.as_str(), default.view.as_deref()),
            ("", Some("right"))
        );
        assert_eq!(choose_rgb_layer(&parts, Some("left")).unwrap().name, "left");
        assert_eq!(choose_rgb_layer(&parts, Some("right")).unwrap().name, "");
    }

    #[test]
    fn views_nuke_layers_and_ambiguity() {
        let mut stereo = part(None, &["B", "G", "R", "right.B", "right.G", "right.R"]);
        stereo.multi_view = vec!["left".into(), "right".into()];
        let parts = [stereo];
        assert_eq!(choose_rgb_layer(&parts, Some("left")).unwrap().name, "");
        assert_eq!(
            choose_rgb_layer(&parts, Some("right")).unwrap().name,
            "right"
        );
        assert_eq!(choose_rgb_layer(&parts, None).unwrap().name, "");

        let nuke = [
            part(Some("rgba"), &["B", "G", "R"]),
            part(Some("diffuse"), &["diffuse.B", "diffuse.G", "diffuse.R"]),
        ];
        assert_eq!(choose_rgb_layer(&nuke, Some("diffuse")).unwrap().part, 1);
        assert!(matches!(
            choose_rgb_layer(&nuke, None),
            Err(LayerChoiceError::Ambiguous { .. })
        ));
        assert!(matches!(
            choose_rgb_layer(&nuke, Some("specular")),
            Err(LayerChoiceError::NotFound { .. })
        ));
        let two = [part(None, &["a.IndexMA.X", "b.IndexMA.X"])];
        assert!(
            matches!(find_channel(&two, "IndexMA", None), ChannelMatch::Ambiguous(v) if v.len() == 2)
        );
    }
}
