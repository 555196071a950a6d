//! Which named things are glass: `PATTERN=ID` mappings from glob patterns over names (material
//! or object names, `Glass*`, `Clear_?mm`) to registration ids. One syntax for every place a
//! user names glass: `glassdb mask --glass` (OBJ materials) and Cryptomatte masks (the names in
//! a render's manifest).

use crate::MaskError;

/// `PATTERN=ID`: names matching the glob pattern are glass with registration id ID.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GlassMapping {
    /// The glob pattern.
    pub pattern: String,
    /// The registry id of what it matches.
    pub id: u16,
}

impl GlassMapping {
    /// Parses `PATTERN=ID` (split at the last `=`; ID in 1…65535, 0 means "no glass").
    pub fn parse(spec: &str) -> Result<GlassMapping, MaskError> {
        let bad = |message: &str| MaskError::BadGlassMapping {
            spec: spec.to_string(),
            message: message.into(),
        };
        let (pattern, id) = spec
            .rsplit_once('=')
            .ok_or_else(|| bad("expected PATTERN=ID, e.g. \"Clear*=1\""))?;
        if pattern.is_empty() {
            return Err(bad("empty name pattern"));
        }
        let id: u32 = id
            .trim()
            .parse()
            .map_err(|_| bad("the id after '=' is not a whole number"))?;
        if id == 0 || id > u16::MAX as u32 {
            return Err(bad("the id must be between 1 and 65535 (0 means no glass)"));
        }
        glob::Pattern::new(pattern).map_err(|e| bad(&format!("bad pattern: {e}")))?;
        Ok(GlassMapping {
            pattern: pattern.to_string(),
            id: id as u16,
        })
    }
}

/// Compiled [`GlassMapping`]s: the id of a name is that of the first pattern it matches.
#[derive(Debug, Clone)]
pub struct GlassNames {
    mappings: Vec<(GlassMapping, glob::Pattern)>,
}

impl PartialEq for GlassNames {
    fn eq(&self, other: &Self) -> bool {
        self.mappings
            .iter()
            .map(|m| &m.0)
            .eq(other.mappings.iter().map(|m| &m.0))
    }
}

impl GlassNames {
    /// Compiles the mappings (their patterns were checked by [`GlassMapping::parse`]; a
    /// hand-built mapping with a bad pattern is an error here).
    pub fn new(mappings: &[GlassMapping]) -> Result<GlassNames, MaskError> {
        let mappings = mappings
            .iter()
            .map(|m| {
                glob::Pattern::new(&m.pattern)
                    .map(|g| (m.clone(), g))
                    .map_err(|e| MaskError::BadGlassMapping {
                        spec: format!("{}={}", m.pattern, m.id),
                        message: format!("bad pattern: {e}"),
                    })
            })
            .collect::<Result<_, _>>()?;
        Ok(GlassNames { mappings })
    }

    /// The glass id of `name`, if a pattern matches it.
    pub fn id_of(&self, name: &str) -> Option<u16> {
        self.mappings
            .iter()
            .find(|(_, g)| g.matches(name))
            .map(|(m, _)| m.id)
    }

    /// The patterns that match none of `names`.
    pub fn unmatched<'a>(&self, names: impl Iterator<Item = &'a str> + Clone) -> Vec<String> {
        self.mappings
            .iter()
            .filter(|(_, g)| !names.clone().any(|n| g.matches(n)))
            .map(|(m, _)| m.pattern.clone())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mappings_parse_and_the_first_match_wins() {
        assert_eq!(
            GlassMapping::parse("Clear*=1").unwrap(),
            GlassMapping {
                pattern: "Clear*".into(),
                id: 1
            }
        );
        assert_eq!(GlassMapping::parse("a=b=7").unwrap().pattern, "a=b");
        for bad in ["Clear", "=3", "x=0", "x=70000", "x=one", "[=1"] {
            assert!(GlassMapping::parse(bad).is_err(), "{bad}");
        }
        let names = GlassNames::new(&[
            GlassMapping::parse("Glass_clear=1").unwrap(),
            GlassMapping::parse("Glass*=2").unwrap(),
        ])
        .unwrap();
        assert_eq!(names.id_of("Glass_clear"), Some(1));
        assert_eq!(names.id_of("Glass_bronze"), Some(2));
        assert_eq!(names.id_of("Wall"), None);
        assert_eq!(
            names.unmatched(["Glass_bronze"].into_iter()),
            vec!["Glass_clear"]
        );
    }
}
