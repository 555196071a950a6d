//! The one error type of this crate: one variant per failure a user can act on, each naming the
//! file, glass (id and name), side, channel and angle involved.

use std::path::PathBuf;

/// Everything that can go wrong loading, validating, building or writing a registry.
#[derive(Debug, thiserror::Error)]
pub enum RegistryError {
    /// A registry or catalog file could not be read.
    #[error("cannot read {path}")]
    Read {
        /// The registry or catalog.
        path: PathBuf,
        /// Why it could not be read.
        source: glassdb_io::InputError,
    },

    /// The registry JSON is malformed or does not follow the schema (serde names line and column).
    #[error("{source_name}: not a valid glassdb registry")]
    Json {
        /// The registry's name.
        source_name: String,
        /// serde's error (line and column).
        source: serde_json::Error,
    },

    /// The registry was written by a different, incompatible schema version.
    #[error(
        "{source_name}: registry schema {found} is not supported (this build reads schemas 2 to {expected}); rebuild it from its catalog"
    )]
    SchemaVersion {
        /// The registry's name.
        source_name: String,
        /// Its schema.
        found: u32,
        /// The newest schema this build reads.
        expected: u32,
    },

    /// A registry file of an older schema whose tables use lights (schema 5's).
    #[error(
        "{source_name}: schema {found} has no lights, but a table names a light, an SPD or a white balance (schema 5)"
    )]
    LightsInOldSchema {
        /// The registry's name.
        source_name: String,
        /// Its schema.
        found: u32,
    },

    /// A registry with no table.
    #[error("{source_name}: the registry has no table (`tables` needs at least one)")]
    NoTables {
        /// The registry's name.
        source_name: String,
    },

    /// The registry holds no table in the colour basis asked for.
    #[error("{source_name} has no table in {wanted} (it holds: {})", have.join(", "))]
    NoSuchTable {
        /// The registry's name.
        source_name: String,
        /// The table asked for.
        wanted: String,
        /// The tables it holds.
        have: Vec<String>,
    },

    /// The registry has no light of the name asked for; `have` lists its lights (empty when
    /// its tables name none: a registry built under one unnamed illuminant).
    #[error(
        "{source_name} has no light `{wanted}` ({})",
        if have.is_empty() {
            format!("its tables name no light: they are integrated under one unnamed illuminant, {unnamed}")
        } else {
            format!("its lights: {}", have.join(", "))
        }
    )]
    NoSuchLight {
        /// The registry's name.
        source_name: String,
        /// The table asked for.
        wanted: String,
        /// The tables it holds.
        have: Vec<String>,
        /// The illuminant of the unnamed light (when `have` is empty).
        unnamed: String,
    },

    /// A light's name that a compositor could not match to a light group.
    #[error("{source_name}: light name `{name}`: {reason}")]
    LightName {
        /// The registry's name.
        source_name: String,
        /// The light's name.
        name: String,
        /// What is wrong with it.
        reason: String,
    },

    /// Some tables name their light and others do not.
    #[error(
        "{source_name}: table {named} names light `{light}` but table {unnamed} names none; either every table names its light or none does"
    )]
    LightsMixed {
        /// The registry's name.
        source_name: String,
        /// The 1-based position of a table that names its light.
        named: usize,
        /// The light it names.
        light: String,
        /// The 1-based position of a table that names none.
        unnamed: usize,
    },

    /// A light lacks a table in a colour basis that another light has.
    #[error(
        "{source_name}: light `{light}` has no {basis} table but light `{other}` has one; every light needs a table in every space"
    )]
    LightMissingTable {
        /// The registry's name.
        source_name: String,
        /// The light without the table.
        light: String,
        /// The colour basis it lacks.
        basis: String,
        /// A light that has a table in that basis.
        other: String,
    },

    /// Two tables of one light are integrated under different illuminants (or observers, or
    /// white balances): a light name must mean one spectrum.
    #[error(
        "{source_name}: light `{light}` is {first} in one table and {second} in another; a light is one spectrum"
    )]
    LightInconsistent {
        /// The registry's name.
        source_name: String,
        /// The light.
        light: String,
        /// Its spectrum (illuminant and white balance) in one table.
        first: String,
        /// Its spectrum in another.
        second: String,
    },

    /// A named light on a table whose method has no illuminant.
    #[error(
        "{source_name}: light `{light}` on a table of the {method} method, which has no illuminant; lights name the illuminant of colorimetric tables"
    )]
    LightNotColorimetric {
        /// The registry's name.
        source_name: String,
        /// The light.
        light: String,
        /// The table's spectral method.
        method: String,
    },

    /// A build with lights whose spectral method has no illuminant.
    #[error("lights apply to the colorimetric method only; the {method} method has no illuminant")]
    LightsNeedColorimetric {
        /// The build's spectral method.
        method: String,
    },

    /// The same light name twice in a build.
    #[error("light `{name}` is given twice")]
    DuplicateLight {
        /// The light's name.
        name: String,
    },

    /// A light given as `NAME=ILLUMINANT` that is not of that form, or whose illuminant cannot
    /// be read; the spectral error (a bad SPD file) is the source.
    #[error("light `{arg}`: {message}")]
    LightSpec {
        /// The argument as given.
        arg: String,
        /// What is wrong.
        message: String,
        /// Why it could not be read.
        #[source]
        source: Option<Box<glassdb_spectral::SpectralError>>,
    },

    /// Two tables in one colour basis (under one light): a compositor could not tell which to
    /// use.
    #[error("{source_name}: two tables in {basis}: {first} and {second}; keep one table per space")]
    DuplicateTable {
        /// The registry's name.
        source_name: String,
        /// Their colour basis.
        basis: String,
        /// The first table.
        first: String,
        /// The second table.
        second: String,
    },

    /// The tables of one registry hold different glasses.
    #[error(
        "{source_name}: the {other} table holds other glasses than the {first} table ({other_glasses:?} against {first_glasses:?}); build every table from one catalog"
    )]
    TablesDiffer {
        /// The registry's name.
        source_name: String,
        /// The first table's basis.
        first: String,
        /// The other table's basis.
        other: String,
        /// The first table's glasses.
        first_glasses: Vec<String>,
        /// The other table's glasses.
        other_glasses: Vec<String>,
    },

    /// Id 0 is reserved for "no glass" in every mask.
    #[error(
        "{source_name}: glass \"{name}\" has id 0, which masks reserve for \"no glass\" (use 1–65535)"
    )]
    IdZero {
        /// The registry's name.
        source_name: String,
        /// The glass.
        name: String,
    },

    /// Two glasses share one id.
    #[error("{source_name}: id {id} is used twice: by \"{first}\" and by \"{second}\"")]
    DuplicateId {
        /// The registry's name.
        source_name: String,
        /// The id.
        id: u16,
        /// The first glass with it.
        first: String,
        /// The second glass with it.
        second: String,
    },

    /// A number in a glass record is NaN or infinite.
    #[error("{source_name}: glass {glass}: {field} is not a finite number")]
    NonFinite {
        /// The registry's name.
        source_name: String,
        /// The glass.
        glass: String,
        /// The field.
        field: String,
    },

    /// A normal-incidence value is outside [0, 1] or r0 + t0 > 1.
    #[error("{source_name}: glass {glass}: {what}")]
    NormalValue {
        /// The registry's name.
        source_name: String,
        /// The glass.
        glass: String,
        /// Which value, and what is wrong with it.
        what: String,
    },

    /// A stored hemispherical value is not the integral of the glass's curves.
    #[error(
        "{source_name}: glass {glass}: {field} = {stored} is not the hemispherical integral of its curves ({computed:.6}); remove the `hemispherical` values or rebuild the registry from its catalog"
    )]
    Hemispherical {
        /// The registry's name.
        source_name: String,
        /// The glass.
        glass: String,
        /// Which value and channel.
        field: String,
        /// The stored value.
        stored: f64,
        /// The integral of the curves.
        computed: f64,
    },

    /// A curve object is malformed (no terms, powers and coefficients of different lengths, …).
    #[error("{source_name}: glass {glass}: curve {field}")]
    CurveShape {
        /// The registry's name.
        source_name: String,
        /// The glass.
        glass: String,
        /// The curve.
        field: String,
        /// What is wrong with its polynomial.
        #[source]
        shape: glassdb_fit::PolynomialShape,
    },

    /// A curve's recorded validation tolerance is negative.
    #[error("{source_name}: glass {glass}: curve {field}: negative tolerance {tolerance}")]
    NegativeTolerance {
        /// The registry's name.
        source_name: String,
        /// The glass.
        glass: String,
        /// The curve.
        field: String,
        /// Its tolerance.
        tolerance: f64,
    },

    /// A curve's recorded validation tolerance is above the cap every file is held to
    /// ([`glassdb_fit::MAX_CURVE_TOLERANCE`]): it would let unphysical curves pass.
    #[error(
        "{source_name}: glass {glass}: curve {field}: tolerance {tolerance} is above the largest validation tolerance {max} (a file cannot widen validation)"
    )]
    ToleranceTooLarge {
        /// The registry's name.
        source_name: String,
        /// The glass.
        glass: String,
        /// The curve.
        field: String,
        /// Its tolerance.
        tolerance: f64,
        /// The largest a curve may record.
        max: f64,
    },

    /// The fit tolerance of a build is not positive or is above the largest tolerance a curve
    /// may record ([`glassdb_fit::MAX_CURVE_TOLERANCE`]).
    #[error("fit tolerance {tol} is outside (0, {max}], the range a registry's curves may record")]
    FitTolerance {
        /// The tolerance given.
        tol: f64,
        /// The largest a curve may record.
        max: f64,
    },

    /// The curves give an unphysical value at some angle (outside [0, 1] or r + t > 1) by more
    /// than the fit tolerance recorded for the curve.
    #[error(
        "{source_name}: glass {glass}: {side} side, channel {channel}, at {angle_deg}°: {what} (allowed tolerance {tolerance:.2e})"
    )]
    Unphysical {
        /// The registry's name.
        source_name: String,
        /// The glass.
        glass: String,
        /// The face of the glass.
        side: crate::Side,
        /// The channel.
        channel: &'static str,
        /// The angle of incidence, degrees.
        angle_deg: f64,
        /// What is out of range.
        what: String,
        /// The tolerance it exceeds.
        tolerance: f64,
    },

    /// The registry could not be written (atomic write: the old file, if any, is untouched).
    #[error(transparent)]
    Write(#[from] glassdb_io::OutputError),

    /// Serialising the registry failed (should not happen with finite numbers).
    #[error("cannot serialise the registry: {0}")]
    Serialize(serde_json::Error),

    /// The catalog TOML is malformed, has an unknown key or a value of the wrong type
    /// (the source names the key, line and column).
    #[error("{path}: not a valid catalog: {message}")]
    CatalogToml {
        /// The catalog.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },

    /// The catalog is not UTF-8 text, or lists no glass.
    #[error("{path}: {message}")]
    CatalogSyntax {
        /// The catalog.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },

    /// A catalog entry is well formed TOML but says something impossible or incomplete.
    #[error("{path}: glass {glass}: {message}")]
    CatalogEntry {
        /// The catalog.
        path: PathBuf,
        /// The entry's glass.
        glass: String,
        /// What is wrong.
        message: String,
    },

    /// An element of a unit's `layers` says something impossible or incomplete.
    #[error("{path}:{line}: glass {glass}: element {position} of `layers`: {message}")]
    CatalogLayer {
        /// The catalog.
        path: PathBuf,
        /// The element's 1-based line.
        line: usize,
        /// The glass (name and id).
        glass: String,
        /// The element's 1-based position in `layers`.
        position: usize,
        /// What is wrong.
        message: String,
    },

    /// A unit's build-up is impossible (two gaps in a row, a gap at an end, an opaque layer
    /// before another, spectra that do not overlap, …) or its layers cannot be combined; the
    /// line is the element's at fault, or the glass's.
    #[error("{path}:{line}: glass {glass}")]
    Unit {
        /// The catalog.
        path: PathBuf,
        /// The 1-based line.
        line: usize,
        /// The glass (id and name).
        glass: String,
        /// The stack engine's error.
        source: Box<glassdb_stack::StackError>,
    },

    /// A unit chosen from a catalog's glasses ([`crate::UnitBuilder`]) cannot be built.
    #[error("unit {glass} chosen from {path}")]
    UnitChoice {
        /// The catalog.
        path: PathBuf,
        /// The unit (id and name).
        glass: String,
        /// The stack engine's error.
        source: Box<glassdb_stack::StackError>,
    },

    /// A file named by the catalog (spectral data or angle table) could not be read.
    #[error("glass {glass}: cannot read {path}")]
    InputFile {
        /// The glass that names it.
        glass: String,
        /// The file.
        path: PathBuf,
        /// Why it could not be read.
        source: glassdb_io::InputError,
    },

    /// A spectral file named by the catalog could not be parsed.
    #[error("glass {glass}: spectral file {path}")]
    Spectral {
        /// The glass that names it.
        glass: String,
        /// The spectral file.
        path: PathBuf,
        /// The reader's error.
        source: Box<glassdb_spectral::SpectralError>,
    },

    /// A spectral file parses but its data do not describe this glass (missing column, more
    /// light out than in, …).
    #[error("glass {glass}: spectral file {path}: {detail}")]
    SpectralContent {
        /// The glass that names it.
        glass: String,
        /// The spectral file.
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },

    /// The spectral method's settings cannot be used (its tables failed to build).
    #[error("spectral method")]
    SpectralMethod(#[source] Box<glassdb_spectral::SpectralError>),

    /// Integration of one spectrum (normal or per-wavelength angle model) failed, e.g. partial
    /// wavelength coverage.
    #[error("glass {glass}: spectral integration of the {what}")]
    Integration {
        /// The glass.
        glass: String,
        /// Which spectrum.
        what: String,
        /// The integrator's error.
        source: Box<glassdb_spectral::SpectralError>,
    },

    /// A measured angle table named by the catalog could not be parsed.
    #[error("glass {glass}: angle table {path}")]
    AngleTable {
        /// The glass that names it.
        glass: String,
        /// The angle table.
        path: PathBuf,
        /// The reader's error.
        source: Box<glassdb_fit::FitError>,
    },

    /// A measured angle table holds no glass, or several and none of this glass's name.
    #[error("glass {glass}: angle table {path}: {detail}")]
    AngleTableGlass {
        /// The glass that names it.
        glass: String,
        /// The angle table.
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },

    /// Fitting the angle curves failed.
    #[error("glass {glass}: fitting {curve}")]
    Fit {
        /// The glass.
        glass: String,
        /// The curve.
        curve: String,
        /// The fitter's error.
        source: Box<glassdb_fit::FitError>,
    },

    /// Masks use ids that the catalog does not define.
    #[error("{}", missing_ids_message(catalog, ids))]
    IdsNotInCatalog {
        /// The catalog.
        catalog: PathBuf,
        /// The missing ids and their pixel counts.
        ids: Vec<(u16, u64)>,
    },

    /// An 8-bit mask (ids stored in one byte) cannot address a glass with id > 255.
    #[error(
        "{path}: glass \"{name}\" has id {id}, but the 8-bit mask {mask} can only hold ids 1–255 (use a 16-bit mask)"
    )]
    IdTooLargeForMask {
        /// The catalog.
        path: PathBuf,
        /// The glass.
        name: String,
        /// Its id.
        id: u16,
        /// The 8-bit mask.
        mask: PathBuf,
    },
}

impl RegistryError {
    /// The class of this error: a file that cannot be read is the reader's class, a failure
    /// of a catalog's spectral file, angle table, fit or unit keeps its own class, a registry
    /// that cannot be serialised is glassdb's bug; anything else is a registry or catalog to
    /// fix.
    pub fn kind(&self) -> glassdb_io::ErrorKind {
        use glassdb_io::ErrorKind;
        match self {
            RegistryError::Read { source, .. } | RegistryError::InputFile { source, .. } => {
                source.kind()
            }
            RegistryError::Write(e) => e.kind(),
            RegistryError::Spectral { source, .. } | RegistryError::Integration { source, .. } => {
                source.kind()
            }
            RegistryError::SpectralMethod(e) => e.kind(),
            RegistryError::AngleTable { source, .. } | RegistryError::Fit { source, .. } => {
                source.kind()
            }
            RegistryError::Unit { source, .. } | RegistryError::UnitChoice { source, .. } => {
                source.kind()
            }
            RegistryError::Serialize(_) => ErrorKind::Internal,
            _ => ErrorKind::Invalid,
        }
    }
}

fn missing_ids_message(catalog: &std::path::Path, ids: &[(u16, u64)]) -> String {
    let list: Vec<String> = ids
        .iter()
        .map(|(id, n)| format!("id {id} ({n} pixels)"))
        .collect();
    format!(
        "the masks use {} id{} that {} does not define: {}",
        ids.len(),
        if ids.len() == 1 { "" } else { "s" },
        catalog.display(),
        list.join(", ")
    )
}
