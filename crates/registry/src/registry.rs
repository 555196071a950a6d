//! The registry JSON (schemas 2 to 5): the id-indexed tables of glass records, one per colour
//! basis and light, their loading with validation and their atomic writing.

use std::fmt;
use std::path::Path;
use std::str::FromStr;

use glassdb_spectral::{IntegrationSettings, Method, RgbSpace};
use serde::{Deserialize, Serialize};

use crate::RegistryError;
use crate::record::GlassRecord;

/// The newest registry schema this crate reads and writes. Schema 5: a table may name the
/// light it is integrated under ([`RegistryTable::light`]), its illuminant may be an SPD from a
/// file (with the samples) and its method may fix the camera's white balance; a registry that
/// uses none of these is written as schema 4, byte for byte as before lights
/// ([`Registry::schema_version`]). Schema 4: a glass may be a unit ([`GlassRecord::unit`]: its
/// build-up, per-layer values and per-pane-group reflectances); schema 3 (the same without
/// units) is read as it is; schema 2 (one table, `spectral` and `glasses` at the top) is read
/// as a registry of one table. Curves are the fit crate's
/// [`CosPolynomial`](glassdb_fit::CosPolynomial) (basis `paper` or `full`, strictly ascending
/// powers) and [`FitSummary`](glassdb_fit::FitSummary); the spectral method is
/// [`IntegrationSettings`].
pub const SCHEMA_VERSION: u32 = 5;

/// The schema before lights (one light, a CIE illuminant), still read and still written for
/// registries without lights.
pub const SCHEMA_VERSION_BEFORE_LIGHTS: u32 = 4;

/// The schema before units (one table per colour basis), still read.
pub const SCHEMA_VERSION_BEFORE_UNITS: u32 = 3;

/// The oldest schema still read (one table).
pub const SCHEMA_VERSION_ONE_TABLE: u32 = 2;

/// Channel names, in the order of every `[_; 3]` array in the registry.
pub const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// The id-indexed glass tables of a scene: the same glasses, integrated once per colour basis
/// (an RGB working space such as linear Rec.709 or ACEScg, the paper's CIE RGB, or luminous
/// grey), so that passes rendered in any of those spaces find their numbers. Never empty; the
/// first table is the default one.
#[derive(Debug, Clone, PartialEq)]
pub struct Registry {
    tables: Vec<RegistryTable>,
}

/// The glasses of a registry integrated with one spectral method (one colour basis) under one
/// light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegistryTable {
    /// The light the table is integrated under, by the name a scene's light groups use
    /// (`sun`, `warm`); `None` in a registry of one unnamed light (every registry built without
    /// lights). Its spectrum is the method's illuminant.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub light: Option<String>,
    /// The spectral method that turned spectra into per-channel values.
    pub spectral: IntegrationSettings,
    /// The glasses, sorted by id.
    pub glasses: Vec<GlassRecord>,
}

/// What a table's three channels are: the colour basis its numbers are in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ColourBasis {
    /// A linear RGB working space (the colorimetric method).
    Space(RgbSpace),
    /// The paper's CIE 1931 RGB colour-matching functions (eqs. 15–20): no renderer's space.
    PaperRgb,
    /// The luminous value in all three channels: a grey, the same in every space.
    Luminous,
}

impl fmt::Display for ColourBasis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ColourBasis::Space(s) => write!(f, "{s}"),
            ColourBasis::PaperRgb => f.write_str("paper-rgb"),
            ColourBasis::Luminous => f.write_str("luminous"),
        }
    }
}

impl FromStr for ColourBasis {
    type Err = String;
    /// An RGB space's name (`srgb`/`rec709`, `rec2020`, `acescg`, …), `paper-rgb` or
    /// `luminous`, any case.
    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim();
        if s.eq_ignore_ascii_case("paper-rgb") || s.eq_ignore_ascii_case("paper") {
            return Ok(ColourBasis::PaperRgb);
        }
        if s.eq_ignore_ascii_case("luminous") {
            return Ok(ColourBasis::Luminous);
        }
        s.parse::<RgbSpace>().map(ColourBasis::Space).map_err(|_| {
            let names: Vec<&str> = RgbSpace::ALL.iter().map(|r| r.name()).collect();
            format!(
                "unknown colour basis `{s}`; expected one of: {}, rec709, paper-rgb, luminous",
                names.join(", ")
            )
        })
    }
}

impl RegistryTable {
    /// The colour basis of this table's channels.
    pub fn basis(&self) -> ColourBasis {
        match self.spectral.method {
            Method::Colorimetric(ref c) => ColourBasis::Space(c.space),
            Method::Paper(_) => ColourBasis::PaperRgb,
            Method::Luminous => ColourBasis::Luminous,
        }
    }

    /// What the table is for messages: its basis, and its light when named (`acescg, light
    /// warm`).
    pub fn label(&self) -> String {
        match &self.light {
            Some(light) => format!("{}, light {light}", self.basis()),
            None => self.basis().to_string(),
        }
    }

    /// Whether the table needs schema 5: a named light, an SPD illuminant or a fixed white
    /// balance.
    pub(crate) fn uses_lights(&self) -> bool {
        self.light.is_some()
            || matches!(
                &self.spectral.method,
                Method::Colorimetric(c)
                    if matches!(c.illuminant, glassdb_spectral::Illuminant::Spd(_))
                        || c.white_balance != glassdb_spectral::WhiteBalance::Light
            )
    }

    /// The glass with this registration id.
    pub fn glass(&self, id: u16) -> Option<&GlassRecord> {
        self.glasses.iter().find(|g| g.id == id)
    }
}

/// The JSON form of schemas 3, 4 and 5.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RegistryJson {
    #[allow(dead_code)] // checked before (`VersionOnly`)
    schema: u32,
    tables: Vec<RegistryTable>,
}

/// The JSON form of schema 2: one table at the top level.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OneTableJson {
    #[allow(dead_code)] // checked before (`VersionOnly`)
    schema: u32,
    spectral: IntegrationSettings,
    glasses: Vec<GlassRecord>,
}

impl Registry {
    /// A registry of one table.
    pub fn single(table: RegistryTable) -> Registry {
        Registry {
            tables: vec![table],
        }
    }

    /// A registry of several tables, the first the default; validated
    /// ([`Registry::validate`]): at least one table, one per colour basis and light, the same
    /// glasses (ids and names) in each.
    pub fn new(tables: Vec<RegistryTable>) -> Result<Registry, RegistryError> {
        let registry = Registry { tables };
        registry.validate()?;
        Ok(registry)
    }

    /// Tables not yet validated (the builder validates them with its own name for messages).
    pub(crate) fn from_tables_unchecked(tables: Vec<RegistryTable>) -> Registry {
        Registry { tables }
    }

    /// Every table, the default first.
    pub fn tables(&self) -> &[RegistryTable] {
        &self.tables
    }

    /// The default (first) table: what commands show and plot unless asked for another basis.
    pub fn default_table(&self) -> &RegistryTable {
        // `tables` is never empty: every constructor and the loader check it.
        &self.tables[0]
    }

    /// Mutable tables, for tools and tests that edit a registry before writing it (validate
    /// again before use; [`Registry::write_json`] does).
    pub fn tables_mut(&mut self) -> &mut Vec<RegistryTable> {
        &mut self.tables
    }

    /// The default light's table in this colour basis, if the registry holds one
    /// ([`Registry::table_under`] for another light).
    pub fn table(&self, basis: ColourBasis) -> Option<&RegistryTable> {
        self.default_light_tables().find(|t| t.basis() == basis)
    }

    /// The default light's table in `basis`, or the default table for `None`; an error naming
    /// the registry and the bases it holds when it has no such table.
    pub fn table_or_error(
        &self,
        basis: Option<ColourBasis>,
        source_name: &str,
    ) -> Result<&RegistryTable, RegistryError> {
        let Some(basis) = basis else {
            return Ok(self.default_table());
        };
        self.table(basis).ok_or_else(|| RegistryError::NoSuchTable {
            source_name: source_name.to_string(),
            wanted: basis.to_string(),
            have: self.bases().iter().map(ToString::to_string).collect(),
        })
    }

    /// The colour bases held (by the default light's tables, and so by every light's), in
    /// table order.
    pub fn bases(&self) -> Vec<ColourBasis> {
        self.default_light_tables()
            .map(RegistryTable::basis)
            .collect()
    }

    /// Reads and validates a registry JSON file.
    pub fn from_json_file(path: &Path) -> Result<Registry, RegistryError> {
        let text =
            glassdb_io::read_input_string(path, glassdb_io::limits::JSON).map_err(|source| {
                RegistryError::Read {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
        Registry::from_json_str(&text, &path.display().to_string())
    }

    /// Parses and validates a registry JSON text (schema 4 or 3, or schema 2 as one table);
    /// `source_name` names it in errors.
    pub fn from_json_str(json: &str, source_name: &str) -> Result<Registry, RegistryError> {
        // Check the version first, so an old or future file gets a version message rather than
        // a missing-key one.
        #[derive(Deserialize)]
        struct VersionOnly {
            schema: u32,
        }
        let json_err = |source| RegistryError::Json {
            source_name: source_name.to_string(),
            source,
        };
        let version: VersionOnly = serde_json::from_str(json).map_err(json_err)?;
        let tables = match version.schema {
            SCHEMA_VERSION | SCHEMA_VERSION_BEFORE_LIGHTS | SCHEMA_VERSION_BEFORE_UNITS => {
                let tables = serde_json::from_str::<RegistryJson>(json)
                    .map_err(json_err)?
                    .tables;
                if version.schema < SCHEMA_VERSION && tables.iter().any(RegistryTable::uses_lights)
                {
                    return Err(RegistryError::LightsInOldSchema {
                        source_name: source_name.to_string(),
                        found: version.schema,
                    });
                }
                tables
            }
            SCHEMA_VERSION_ONE_TABLE => {
                let one: OneTableJson = serde_json::from_str(json).map_err(json_err)?;
                vec![RegistryTable {
                    light: None,
                    spectral: one.spectral,
                    glasses: one.glasses,
                }]
            }
            found => {
                return Err(RegistryError::SchemaVersion {
                    source_name: source_name.to_string(),
                    found,
                    expected: SCHEMA_VERSION,
                });
            }
        };
        let registry = Registry { tables };
        registry.validate_named(source_name)?;
        Ok(registry)
    }

    /// SHA-256 (hex) of the registry's canonical JSON ([`Registry::to_json_string`]): names
    /// the glass data a composite was made with, whatever the file's formatting.
    pub fn content_sha256(&self) -> Result<String, RegistryError> {
        Ok(crate::catalog_files::sha256_hex(
            self.to_json_string()?.as_bytes(),
        ))
    }

    /// The schema the registry is written with: 5 when a table uses lights (a named light, an
    /// SPD illuminant or a fixed white balance), else 4, so that a registry without lights is
    /// written exactly as before lights and older builds still read it.
    pub fn schema_version(&self) -> u32 {
        if self.tables.iter().any(RegistryTable::uses_lights) {
            SCHEMA_VERSION
        } else {
            SCHEMA_VERSION_BEFORE_LIGHTS
        }
    }

    /// The registry as pretty JSON text ([`Registry::schema_version`]).
    pub fn to_json_string(&self) -> Result<String, RegistryError> {
        #[derive(Serialize)]
        struct RegistryJsonOut<'a> {
            schema: u32,
            tables: &'a [RegistryTable],
        }
        let json = RegistryJsonOut {
            schema: self.schema_version(),
            tables: &self.tables,
        };
        let mut s = serde_json::to_string_pretty(&json).map_err(RegistryError::Serialize)?;
        s.push('\n');
        Ok(s)
    }

    /// Validates, then writes the registry JSON atomically (temporary file + rename).
    pub fn write_json(&self, path: &Path) -> Result<(), RegistryError> {
        self.validate_named(&path.display().to_string())?;
        let text = self.to_json_string()?;
        glassdb_io::write_bytes_atomic(path, text.as_bytes())?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use glassdb_fit::{CosPolynomial, FitSummary};
    use glassdb_side::Side;

    use super::*;
    use crate::record::AngleCurve;

    fn curve(powers: Vec<u32>, coefficients: Vec<f64>) -> AngleCurve {
        AngleCurve {
            fit: FitSummary::exact(*powers.iter().max().unwrap_or(&0)),
            polynomial: CosPolynomial {
                basis: if powers.first() == Some(&0) {
                    glassdb_fit::Basis::Full
                } else {
                    glassdb_fit::Basis::Paper
                },
                powers,
                coefficients,
            },
            tolerance: 0.002,
        }
    }

    /// r = 0.1·(1 + 9·(1 − cos θ)²)… a hand-made glass: C_r = 10 − 18c + 9c² reaches 1/r0 = 10
    /// at 90°, C_t = c (paper basis), t0 = 0.8.
    fn sample() -> Registry {
        let cr = curve(vec![0, 1, 2], vec![10.0, -18.0, 9.0]);
        let ct = curve(vec![1], vec![1.0]);
        Registry::single(RegistryTable {
            light: None,
            spectral: IntegrationSettings::default(),
            glasses: vec![GlassRecord::with_shared_curves(
                4,
                "hand-made",
                "uncoated",
                [[0.1; 3], [0.8, 0.7, 0.6], [0.05; 3]],
                [&cr, &ct, &cr],
            )],
        })
    }

    #[test]
    fn eval_and_tables_agree_with_hand_values() {
        let reg = sample();
        reg.validate().unwrap();
        let g = reg.default_table().glass(4).unwrap();
        assert!(reg.default_table().glass(5).is_none());
        // cos θ = 0.5: C_r = 10 − 9 + 2.25 = 3.25 → r = 0.325; t = 0.8·0.5 = 0.4.
        let (r, t) = g.eval(Side::Front, 0.5);
        assert!((r[0] - 0.325).abs() < 1e-15 && (t[0] - 0.4).abs() < 1e-15);
        // Back: r0_back = 0.05 → 0.1625.
        let (rb, _) = g.eval(Side::Back, 0.5);
        assert!((rb[0] - 0.1625).abs() < 1e-15);
        // Grazing: r = 1, t = 0 exactly; out-of-range cos θ is clamped.
        assert_eq!(g.eval(Side::Front, 0.0), ([1.0; 3], [0.0; 3]));
        assert_eq!(g.eval(Side::Front, -0.3), g.eval(Side::Front, 0.0));
        assert_eq!(g.eval(Side::Front, 1.7), g.eval(Side::Front, 1.0));
        assert_eq!(g.eval(Side::Front, f64::NAN), g.eval(Side::Front, 1.0));
    }

    #[test]
    fn clamping_keeps_r_plus_t_at_most_one() {
        let mut reg = sample();
        // t0 = 0.95 with r0 = 0.1: at normal incidence r + t = 1.05 (invalid, but eval must
        // still give a physical pair).
        reg.tables[0].glasses[0].t0 = [0.95; 3];
        let (r, t) = reg.tables[0].glasses[0].eval(Side::Front, 1.0);
        assert!((r[0] - 0.1).abs() < 1e-15 && (t[0] - 0.9).abs() < 1e-15);
        let err = reg.validate().unwrap_err().to_string();
        assert!(err.contains("at 0°") && err.contains("r + t"), "{err}");
    }

    #[test]
    fn validation_names_glass_side_channel_and_angle() {
        let mut reg = sample();
        // Back reflectance curve too steep in channel B only: r_back = 0.05·(30 − 29c) and
        // t = 0.6·c give r + t = 1.5 − 0.85c > 1 + 0.004 where c < 0.58353 → θ > 54.30°; the
        // first angle of the 0.25° grid beyond is 54.5°.
        reg.tables[0].glasses[0].c_r_back[2] = curve(vec![0, 1], vec![30.0, -29.0]);
        let err = reg.validate().unwrap_err().to_string();
        assert!(err.contains("id 4 (\"hand-made\")"), "{err}");
        assert!(err.contains("back side, channel B, at 54.5°"), "{err}");
        let mut reg = sample();
        reg.tables[0].glasses[0].c_t[1].polynomial.coefficients[0] = f64::NAN;
        assert!(
            reg.validate()
                .unwrap_err()
                .to_string()
                .contains("c_t[1] (G).coefficients[0]")
        );
        let mut reg = sample();
        let copy = reg.tables[0].glasses[0].clone();
        reg.tables[0].glasses.push(copy);
        assert!(matches!(
            reg.validate(),
            Err(RegistryError::DuplicateId { id: 4, .. })
        ));
    }

    #[test]
    fn powers_must_ascend_and_the_paper_basis_has_no_constant() {
        let mut reg = sample();
        reg.tables[0].glasses[0].c_r[0] = curve(vec![0, 2, 1], vec![10.0, 9.0, -18.0]);
        let e = glassdb_io::ErrorChain(&reg.validate().unwrap_err()).to_string();
        assert!(
            e.contains("c_r[0] (R)") && e.contains("ascend strictly"),
            "{e}"
        );
        let mut reg = sample();
        reg.tables[0].glasses[0].c_t[0].polynomial.powers = vec![0];
        reg.tables[0].glasses[0].c_t[0].polynomial.basis = glassdb_fit::Basis::Paper;
        let e = glassdb_io::ErrorChain(&reg.validate().unwrap_err()).to_string();
        assert!(e.contains("no constant term"), "{e}");
    }

    #[test]
    fn json_round_trip_in_memory() {
        let reg = sample();
        let text = reg.to_json_string().unwrap();
        let back = Registry::from_json_str(&text, "mem").unwrap();
        assert_eq!(back, reg);
        assert_eq!(back.to_json_string().unwrap(), text);
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.json");
        reg.write_json(&p).unwrap();
        assert_eq!(Registry::from_json_file(&p).unwrap(), reg);
        // An invalid registry is never written.
        let mut bad = reg.clone();
        bad.tables[0].glasses[0].id = 0;
        let q = dir.path().join("bad.json");
        assert!(bad.write_json(&q).is_err());
        assert!(!q.exists());
    }

    #[test]
    fn malformed_json_errors_name_the_source() {
        let err = Registry::from_json_str("{\"schema\": 1, \"glasses\": [}", "x.json").unwrap_err();
        // The message names the file; its cause (serde's) names line and column, once.
        let e = glassdb_io::ErrorChain(&err).to_string();
        assert!(
            e.starts_with("x.json:") && e.matches("line 1").count() == 1,
            "{e}"
        );
        let e = Registry::from_json_str("{\"schema\": 6}", "y.json")
            .unwrap_err()
            .to_string();
        assert!(e.contains("schema 6 is not supported"), "{e}");
        // A schema-1 file says what to do, without naming command-line flags (the binary adds
        // the exact command).
        let err =
            Registry::from_json_str("{\"schema\": 1, \"glasses\": []}", "old.json").unwrap_err();
        assert!(
            matches!(
                err,
                RegistryError::SchemaVersion {
                    found: 1,
                    expected: 5,
                    ..
                }
            ),
            "{err}"
        );
        let e = err.to_string();
        assert!(
            e.contains("schema 1 is not supported") && e.contains("rebuild it from its catalog"),
            "{e}"
        );
        assert!(!e.contains("--"), "{e}");
        let e = Registry::from_json_str("[1, 2]", "z.json")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("z.json:"), "{e}");
    }

    fn in_space(reg: &Registry, space: RgbSpace) -> RegistryTable {
        let mut t = reg.default_table().clone();
        t.spectral = IntegrationSettings::colorimetric(space, Default::default());
        t
    }

    #[test]
    fn several_tables_one_per_basis_with_the_same_glasses() {
        let reg = sample();
        let acescg = in_space(&reg, RgbSpace::AcesCg);
        let two = Registry::new(vec![reg.default_table().clone(), acescg.clone()]).unwrap();
        assert_eq!(
            two.bases(),
            [
                ColourBasis::Space(RgbSpace::Srgb),
                ColourBasis::Space(RgbSpace::AcesCg)
            ]
        );
        assert_eq!(
            two.table(ColourBasis::Space(RgbSpace::AcesCg)),
            Some(&acescg)
        );
        assert_eq!(two.table(ColourBasis::Luminous), None);
        let text = two.to_json_string().unwrap();
        assert!(text.contains("\"schema\": 4"), "{text}");
        assert_eq!(Registry::from_json_str(&text, "two.json").unwrap(), two);

        let e = Registry::new(vec![acescg.clone(), acescg.clone()]).unwrap_err();
        assert!(matches!(e, RegistryError::DuplicateTable { .. }), "{e}");
        let mut other = acescg.clone();
        other.glasses[0].id = 7;
        let e = Registry::new(vec![reg.default_table().clone(), other]).unwrap_err();
        assert!(
            e.to_string().contains("acescg table holds other glasses"),
            "{e}"
        );
        assert!(matches!(
            Registry::new(Vec::new()),
            Err(RegistryError::NoTables { .. })
        ));
        // A per-glass error in a table names the table.
        let mut bad = acescg;
        bad.glasses[0].t0 = [0.95; 3];
        let e = Registry::new(vec![reg.default_table().clone(), bad])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("registry (table 2: acescg)"), "{e}");
    }

    #[test]
    fn schema_2_files_read_as_one_table() {
        let reg = sample();
        let table = serde_json::to_value(reg.default_table()).unwrap();
        let v2 = serde_json::json!({
            "schema": 2,
            "spectral": table["spectral"],
            "glasses": table["glasses"],
        });
        let back = Registry::from_json_str(&v2.to_string(), "v2.json").unwrap();
        assert_eq!(back, reg);
        // Unknown keys stay errors in both schemas.
        let mut typo = v2.clone();
        typo["glases"] = serde_json::json!([]);
        assert!(Registry::from_json_str(&typo.to_string(), "v2.json").is_err());
    }
}
