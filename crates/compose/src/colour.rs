//! The passes' colour space and the registry table that goes with it (docs/colour.md): each
//! pass's space is read from its header (`colorInteropID`, then `chromaticities`) or declared
//! (`--input-space`), the passes of a frame must agree, and the registry's table in that space
//! is the one composited with. r0 and t0 are per-channel integrals in one RGB basis; applied to
//! passes in another basis they tint the glass (a clear glass's t0 in linear Rec.709 is not its
//! t0 in ACEScg).

use std::fmt;
use std::path::{Path, PathBuf};

use glassdb_colour::RgbSpace;
use glassdb_image::ExrColourTag;
use std::sync::OnceLock;

use glassdb_registry::{ColourBasis, Registry, RegistryTable};

use crate::ComposeError;
use crate::lut::GlassLut;

/// Where a pass's colour space came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SpaceSource {
    /// Declared by the caller (the command line's `--input-space`), over anything the files
    /// say.
    Declared,
    /// The part's `colorInteropID` (Blender 5 writes one per part).
    InteropId(String),
    /// The part's `chromaticities`.
    Chromaticities,
    /// Nothing: linear Rec.709, OpenEXR's default primaries (and a PNG's, being sRGB).
    Untagged,
}

impl fmt::Display for SpaceSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SpaceSource::Declared => f.write_str("declared"),
            SpaceSource::InteropId(id) => write!(f, "colorInteropID \"{id}\""),
            SpaceSource::Chromaticities => f.write_str("chromaticities"),
            SpaceSource::Untagged => f.write_str("no colour tag, taken as linear Rec.709"),
        }
    }
}

/// A pass's linear RGB space and how it was known.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PassSpace {
    /// The linear RGB space.
    pub space: RgbSpace,
    /// How it was known.
    pub source: SpaceSource,
}

impl fmt::Display for PassSpace {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", space_label(self.space), self.source)
    }
}

/// A space's name as users know it, with glassdb's name for flags.
pub fn space_label(space: RgbSpace) -> String {
    let common = match space {
        RgbSpace::Srgb => "linear Rec.709",
        RgbSpace::Rec2020 => "linear Rec.2020",
        RgbSpace::AcesCg => "ACEScg",
        RgbSpace::Aces2065_1 => "ACES2065-1",
        RgbSpace::DisplayP3 => "linear Display P3",
        RgbSpace::Xyz => "CIE XYZ",
    };
    format!("{common} [{}]", space.name())
}

/// The space of one pass from its header's colour tag (`declared` overrides it).
pub fn pass_space(
    path: &Path,
    tag: &ExrColourTag,
    declared: Option<RgbSpace>,
) -> Result<PassSpace, ComposeError> {
    if let Some(space) = declared {
        return Ok(PassSpace {
            space,
            source: SpaceSource::Declared,
        });
    }
    let unsupported = |what: String, why: &str| ComposeError::UnsupportedPassSpace {
        path: path.to_path_buf(),
        what,
        why: why.to_string(),
    };
    let from_chromaticities = tag
        .chromaticities
        .map(|c| (c, RgbSpace::from_chromaticities(c.map(f64::from))));
    if let Some(id) = &tag.interop_id {
        let Some(space) = RgbSpace::from_interop_id(id) else {
            let why = if id.trim().eq_ignore_ascii_case("data") {
                "data, not colour (a Normal, Position or id pass?); choose the colour layer"
            } else if id.ends_with("_display") {
                "display-referred; passes must be scene-linear"
            } else if id.contains('_') && !id.starts_with("lin_") {
                "an encoded (non-linear) space; passes must be scene-linear"
            } else {
                "not a space glassdb knows"
            };
            return Err(unsupported(format!("colorInteropID \"{id}\""), why));
        };
        if let Some((c, other)) = from_chromaticities
            && other != Some(space)
        {
            return Err(ComposeError::ConflictingColourTags {
                path: path.to_path_buf(),
                interop_id: id.clone(),
                chromaticities: c,
            });
        }
        return Ok(PassSpace {
            space,
            source: SpaceSource::InteropId(id.clone()),
        });
    }
    match from_chromaticities {
        Some((_, Some(space))) => Ok(PassSpace {
            space,
            source: SpaceSource::Chromaticities,
        }),
        Some((c, None)) => Err(unsupported(
            format!("chromaticities {c:?}"),
            "not the primaries and white of a space glassdb knows",
        )),
        None => Ok(PassSpace {
            space: RgbSpace::Srgb,
            source: SpaceSource::Untagged,
        }),
    }
}

/// The one space of a frame's passes: the transmission pass's, which every reflection pass
/// must share (an untagged pass counts as linear Rec.709).
pub fn frame_space(
    trans: (&Path, PassSpace),
    refl: &[(PathBuf, PassSpace)],
) -> Result<PassSpace, ComposeError> {
    let (trans_path, trans_space) = trans;
    if let Some((path, other)) = refl.iter().find(|(_, s)| s.space != trans_space.space) {
        return Err(ComposeError::PassSpacesDisagree {
            a: trans_path.to_path_buf(),
            a_space: trans_space.to_string(),
            b: path.clone(),
            b_space: other.to_string(),
        });
    }
    Ok(trans_space)
}

/// The registry's tables as compositor lookup tables, one per colour basis, each built the
/// first time a frame needs it (building every table up front would cost a single-frame run
/// more than its composite).
#[derive(Debug)]
pub struct RegistryLuts {
    tables: Vec<(ColourBasis, LazyLut)>,
}

/// A lookup table given built, or a registry table and its lookup table once built.
#[derive(Debug)]
enum LazyLut {
    Built(GlassLut),
    Table(RegistryTable, OnceLock<GlassLut>),
}

impl LazyLut {
    fn get(&self) -> &GlassLut {
        match self {
            LazyLut::Built(lut) => lut,
            LazyLut::Table(table, lut) => lut.get_or_init(|| GlassLut::from_table(table)),
        }
    }
}

/// The table a frame is composited with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChosenTable {
    /// The registry table's colour basis.
    pub basis: ColourBasis,
    /// Whether the table is not in the passes' own space (a luminous grey table, or the paper
    /// method's RGB for untagged passes).
    pub approximate: bool,
}

impl RegistryLuts {
    /// Lookup tables for every table of `registry`'s default light (built when first used).
    pub fn new(registry: &Registry) -> RegistryLuts {
        RegistryLuts {
            tables: registry
                .default_light_tables()
                .map(|t| (t.basis(), LazyLut::Table(t.clone(), OnceLock::new())))
                .collect(),
        }
    }

    /// Lookup tables for every table of `registry` under the light named `light` (built when
    /// first used); `None` when no table names that light.
    pub fn for_light(registry: &Registry, light: &str) -> Option<RegistryLuts> {
        let tables: Vec<(ColourBasis, LazyLut)> = registry
            .tables()
            .iter()
            .filter(|t| t.light.as_deref() == Some(light))
            .map(|t| (t.basis(), LazyLut::Table(t.clone(), OnceLock::new())))
            .collect();
        (!tables.is_empty()).then_some(RegistryLuts { tables })
    }

    /// One lookup table in one basis (tests, benchmarks).
    pub fn single(basis: ColourBasis, lut: GlassLut) -> RegistryLuts {
        RegistryLuts {
            tables: vec![(basis, LazyLut::Built(lut))],
        }
    }

    /// The lookup table in `basis` (built now if no frame needed it yet).
    pub fn get(&self, basis: ColourBasis) -> Option<&GlassLut> {
        self.tables
            .iter()
            .find(|(b, _)| *b == basis)
            .map(|(_, l)| l.get())
    }

    /// The registry table in `basis` (`None` for one given built, [`RegistryLuts::single`]).
    pub fn table(&self, basis: ColourBasis) -> Option<&RegistryTable> {
        self.tables
            .iter()
            .find(|(b, _)| *b == basis)
            .and_then(|(_, l)| match l {
                LazyLut::Built(_) => None,
                LazyLut::Table(table, _) => Some(table),
            })
    }

    /// The bases held, in the registry's order.
    pub fn bases(&self) -> Vec<ColourBasis> {
        self.tables.iter().map(|(b, _)| *b).collect()
    }

    /// The table for passes in `space`: the registry's table in that space; else a luminous
    /// table (grey, the same in every space); else, for untagged passes only, a paper-method
    /// table (the paper's CIE RGB, which no renderer uses but untagged passes do not contradict).
    /// Otherwise an error naming the passes' space, how it was known, and the tables there are.
    pub fn for_space(
        &self,
        space: &PassSpace,
        trans: &Path,
        registry: &str,
    ) -> Result<(ChosenTable, &GlassLut), ComposeError> {
        let exact = ColourBasis::Space(space.space);
        if let Some(lut) = self.get(exact) {
            let chosen = ChosenTable {
                basis: exact,
                approximate: false,
            };
            return Ok((chosen, lut));
        }
        let mut fallbacks = vec![ColourBasis::Luminous];
        if space.source == SpaceSource::Untagged {
            fallbacks.push(ColourBasis::PaperRgb);
        }
        for basis in fallbacks {
            if let Some(lut) = self.get(basis) {
                let chosen = ChosenTable {
                    basis,
                    approximate: true,
                };
                return Ok((chosen, lut));
            }
        }
        Err(ComposeError::NoTableForSpace {
            trans: trans.to_path_buf(),
            space: space.to_string(),
            space_name: space.space.name(),
            registry: registry.to_string(),
            have: self.bases().iter().map(ToString::to_string).collect(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tag(chromaticities: Option<RgbSpace>, id: Option<&str>) -> ExrColourTag {
        ExrColourTag {
            chromaticities: chromaticities.map(|s| s.chromaticities().map(|v| v as f32)),
            interop_id: id.map(str::to_string),
        }
    }

    #[test]
    fn a_pass_space_comes_from_its_tags_or_the_flag() {
        let p = Path::new("t.exr");
        let s = pass_space(p, &tag(None, Some("lin_ap1_scene")), None).unwrap();
        assert_eq!(s.space, RgbSpace::AcesCg);
        let s = pass_space(p, &tag(Some(RgbSpace::Rec2020), None), None).unwrap();
        assert_eq!(
            (s.space, s.source),
            (RgbSpace::Rec2020, SpaceSource::Chromaticities)
        );
        let s = pass_space(p, &tag(None, None), None).unwrap();
        assert_eq!((s.space, s.source), (RgbSpace::Srgb, SpaceSource::Untagged));
        // Both tags agreeing is fine; disagreeing is refused; the flag overrides both.
        let both = tag(Some(RgbSpace::AcesCg), Some("lin_ap1_scene"));
        assert_eq!(pass_space(p, &both, None).unwrap().space, RgbSpace::AcesCg);
        let clash = tag(Some(RgbSpace::Srgb), Some("lin_ap1_scene"));
        let e = pass_space(p, &clash, None).unwrap_err().to_string();
        assert!(e.contains("t.exr") && e.contains("lin_ap1_scene"), "{e}");
        let s = pass_space(p, &clash, Some(RgbSpace::Rec2020)).unwrap();
        assert_eq!(
            (s.space, s.source),
            (RgbSpace::Rec2020, SpaceSource::Declared)
        );
        for (id, why) in [
            ("data", "data, not colour"),
            ("srgb_rec709_scene", "non-linear"),
            ("srgb_rec709_display", "display-referred"),
            ("mystery", "not a space glassdb knows"),
        ] {
            let e = pass_space(p, &tag(None, Some(id)), None)
                .unwrap_err()
                .to_string();
            assert!(e.contains(id) && e.contains(why), "{e}");
        }
        let mut odd = tag(Some(RgbSpace::Srgb), None);
        odd.chromaticities.as_mut().unwrap()[0] = 0.5;
        let e = pass_space(p, &odd, None).unwrap_err().to_string();
        assert!(e.contains("chromaticities"), "{e}");
    }

    #[test]
    fn the_frame_takes_the_transmission_space_and_refuses_a_disagreeing_pass() {
        let aces = PassSpace {
            space: RgbSpace::AcesCg,
            source: SpaceSource::InteropId("lin_ap1_scene".into()),
        };
        let untagged = PassSpace {
            space: RgbSpace::Srgb,
            source: SpaceSource::Untagged,
        };
        let ok = frame_space(
            (Path::new("t.exr"), aces.clone()),
            &[(PathBuf::from("r0.exr"), aces.clone())],
        )
        .unwrap();
        assert_eq!(ok, aces);
        let e = frame_space(
            (Path::new("t.exr"), aces),
            &[
                (PathBuf::from("r0.exr"), ok),
                (PathBuf::from("r1.png"), untagged),
            ],
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("t.exr") && e.contains("r1.png") && e.contains("ACEScg"),
            "{e}"
        );
    }
}
