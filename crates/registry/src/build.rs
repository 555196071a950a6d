//! Catalog → registry: per glass, the normal-incidence values ([`crate::normal`]), the angle
//! model tables and any measured table ([`crate::angle_model`]) and the fitted curves
//! ([`crate::curves`]), assembled into a validated [`Registry`]. Equations in
//! `docs/registry.md`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glassdb_spectral::{IntegrationSettings, Integrator, RgbSpace};
use glassdb_stack::LayerModel;
use rayon::prelude::*;

use crate::angle_model::{ModelTables, read_measured_table};
use crate::catalog::{
    ElementSpec, GlassBuild, GlassSpec, LayerSpec, NormalSource, parse_catalog, resolve,
};
use crate::catalog_files::{CatalogFiles, sha256_hex};
use crate::curves::{GlassCurves, fit_glass_curves};
use crate::normal::{NormalValues, normal_values, read_layer};
use crate::{
    AngleModelRecord, FileRef, GlassRecord, HemisphericalRecord, Provenance, Registry,
    RegistryError, RegistryTable,
};

/// Where the angle model is applied (the stack engine's choice, for every layer).
pub use glassdb_stack::Application;

/// The glass ids a scene's masks use: a build restricted to them builds only these.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MaskIds {
    /// Glass pixels per id over all the masks (id 0 excluded).
    pub pixel_counts: BTreeMap<u16, u64>,
    /// An 8-bit mask among them (ids in one byte), which cannot address a glass above 255.
    pub eight_bit_mask: Option<PathBuf>,
}

/// How to build a registry.
#[derive(Debug, Clone)]
pub struct BuildOptions {
    /// The spectral method of each table to build, the default table first (one per colour
    /// basis: e.g. colorimetric in linear Rec.709 and in ACEScg).
    pub tables: Vec<IntegrationSettings>,
    /// Named lights: when given, every table of `tables` is built under each light (the
    /// light's illuminant replacing the table's), light by light, the first light the default;
    /// each table then names its light. Empty: one table per entry of `tables`, naming none.
    pub lights: Vec<crate::NamedLight>,
    /// With the ids of a scene's masks, only those glasses are built.
    pub mask_ids: Option<MaskIds>,
    /// Fit tolerance on r and t (absolute), in (0, [`glassdb_fit::MAX_CURVE_TOLERANCE`]]: it
    /// becomes each curve's recorded validation tolerance.
    pub fit_tol: f64,
    /// Highest polynomial degree tried.
    pub max_degree: u32,
    /// Where the physical angle model is applied when a spectrum is given.
    pub application: Application,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            tables: vec![IntegrationSettings::default()],
            lights: Vec::new(),
            mask_ids: None,
            fit_tol: glassdb_fit::DEFAULT_TOL,
            max_degree: 12,
            application: Application::PerWavelength,
        }
    }
}

impl BuildOptions {
    /// Options that build one colorimetric table per space of `spaces`, the first the
    /// default ([`IntegrationSettings::colorimetric`] under the default illuminant; other
    /// options default).
    pub fn colorimetric_in(spaces: &[RgbSpace]) -> BuildOptions {
        BuildOptions {
            tables: spaces
                .iter()
                .map(|&space| IntegrationSettings::colorimetric(space, Default::default()))
                .collect(),
            ..BuildOptions::default()
        }
    }
}

/// The bytes of a catalog file, of at most [`crate::CATALOG_FILE`].
fn read_catalog(catalog_path: &Path) -> Result<Vec<u8>, RegistryError> {
    glassdb_io::read_input(catalog_path, crate::CATALOG_FILE).map_err(|source| {
        RegistryError::Read {
            path: catalog_path.to_path_buf(),
            source,
        }
    })
}

/// Parses a catalog file.
pub(crate) fn load_catalog(catalog_path: &Path) -> Result<(Vec<GlassSpec>, String), RegistryError> {
    let bytes = read_catalog(catalog_path)?;
    let catalog_sha = sha256_hex(&bytes);
    let text = String::from_utf8(bytes).map_err(|e| RegistryError::CatalogSyntax {
        path: catalog_path.to_path_buf(),
        message: format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
    })?;
    Ok((parse_catalog(&text, catalog_path)?, catalog_sha))
}

/// Every file a build from `catalog_path` reads: the catalog itself and each spectral file and
/// angle table it names (resolved against the catalog's directory), so that an output can be
/// refused before building when it is one of them.
pub fn catalog_inputs(catalog_path: &Path) -> Result<Vec<PathBuf>, RegistryError> {
    let (specs, _) = load_catalog(catalog_path)?;
    let mut files = vec![catalog_path.to_path_buf()];
    for spec in &specs {
        for layer in spec_layers(spec) {
            if let NormalSource::Spectral { path, .. } = &layer.normal {
                files.push(resolve(catalog_path, path));
            }
            if let Some((path, _)) = &layer.angles {
                files.push(resolve(catalog_path, path));
            }
        }
    }
    files.sort();
    files.dedup();
    Ok(files)
}

/// Builds a registry from a catalog file (paths in it are relative to the catalog; the
/// catalog's provenance records `catalog_path` as given).
pub fn build_registry(catalog_path: &Path, opts: &BuildOptions) -> Result<Registry, RegistryError> {
    let (mut tables, integrators) = integrators_of(opts)?;
    let (specs, catalog_sha) = load_catalog(catalog_path)?;
    let wanted = wanted_ids(&specs, catalog_path, opts.mask_ids.as_ref())?;
    let catalog_ref = FileRef {
        path: catalog_path.display().to_string(),
        sha256: catalog_sha,
    };
    let ctx = BuildContext {
        files: CatalogFiles { catalog_path },
        integrators: &integrators,
        opts,
    };
    let chosen: Vec<&GlassSpec> = specs
        .iter()
        .filter(|spec| wanted.as_ref().is_none_or(|w| w.contains(&spec.id)))
        .collect();
    // Glasses build independently (in parallel); the first failure in catalog order is the
    // one reported, whichever thread met it.
    let built: Vec<Result<Vec<GlassRecord>, RegistryError>> = chosen
        .par_iter()
        .map(|spec| build_entry(spec, &ctx))
        .collect();
    for records in built {
        for (table, mut g) in tables.iter_mut().zip(records?) {
            g.provenance.catalog = Some(catalog_ref.clone());
            g.hemispherical = Some(HemisphericalRecord::of(&g));
            table.glasses.push(g);
        }
    }
    for table in &mut tables {
        table.glasses.sort_by_key(|g| g.id);
    }
    let registry = Registry::from_tables_unchecked(tables);
    registry.validate_named(&format!("registry built from {}", catalog_path.display()))?;
    Ok(registry)
}

/// The layers a catalog entry names (one for a single glass).
fn spec_layers(spec: &GlassSpec) -> Vec<&LayerSpec> {
    match &spec.build {
        GlassBuild::Single(l) => vec![l],
        GlassBuild::Unit(elements) => elements
            .iter()
            .filter_map(|e| match e {
                ElementSpec::Layer(l) => Some(l),
                ElementSpec::Gap { .. } => None,
            })
            .collect(),
    }
}

/// The empty tables of the build ([`crate::lights::planned_tables`]) and one integrator per
/// table, checking the fit tolerance first.
pub(crate) fn integrators_of(
    opts: &BuildOptions,
) -> Result<(Vec<RegistryTable>, Vec<Integrator>), RegistryError> {
    let max = glassdb_fit::MAX_CURVE_TOLERANCE;
    if !(opts.fit_tol > 0.0 && opts.fit_tol <= max) {
        return Err(RegistryError::FitTolerance {
            tol: opts.fit_tol,
            max,
        });
    }
    let tables = crate::lights::planned_tables(opts)?;
    let integrators = tables
        .iter()
        .map(|t| {
            Integrator::new(&t.spectral).map_err(|e| RegistryError::SpectralMethod(Box::new(e)))
        })
        .collect::<Result<_, _>>()?;
    Ok((tables, integrators))
}

/// What every glass of one build shares: the catalog's files, one integrator per table and
/// the options.
pub(crate) struct BuildContext<'a> {
    pub(crate) files: CatalogFiles<'a>,
    pub(crate) integrators: &'a [Integrator],
    pub(crate) opts: &'a BuildOptions,
}

/// One catalog entry's record in each table (one per integrator).
pub(crate) fn build_entry(
    spec: &GlassSpec,
    ctx: &BuildContext<'_>,
) -> Result<Vec<GlassRecord>, RegistryError> {
    match &spec.build {
        GlassBuild::Single(layer) => build_glass(spec, layer, ctx),
        GlassBuild::Unit(elements) => crate::unit::build_unit(spec, elements, ctx),
    }
}

/// The ids to build (None: all); errors for mask ids missing from the catalog and for catalog
/// ids an 8-bit mask cannot hold.
fn wanted_ids(
    specs: &[GlassSpec],
    catalog_path: &Path,
    mask_ids: Option<&MaskIds>,
) -> Result<Option<Vec<u16>>, RegistryError> {
    let Some(mask_ids) = mask_ids else {
        return Ok(None);
    };
    if let Some(mask) = &mask_ids.eight_bit_mask
        && let Some(big) = specs.iter().find(|s| s.id > 255)
    {
        return Err(RegistryError::IdTooLargeForMask {
            path: catalog_path.to_path_buf(),
            name: big.name.clone(),
            id: big.id,
            mask: mask.clone(),
        });
    }
    let missing: Vec<(u16, u64)> = mask_ids
        .pixel_counts
        .iter()
        .filter(|(id, _)| !specs.iter().any(|s| s.id == **id))
        .map(|(&id, &n)| (id, n))
        .collect();
    if !missing.is_empty() {
        return Err(RegistryError::IdsNotInCatalog {
            catalog: catalog_path.to_path_buf(),
            ids: missing,
        });
    }
    Ok(Some(mask_ids.pixel_counts.keys().copied().collect()))
}

/// One glass in each table: its spectral file (if any), normal values, physical model and its
/// tables, any measured table, and the fitted curves. A flipped layer (a unit of one layer)
/// is built as given, then turned round.
pub(crate) fn build_glass(
    spec: &GlassSpec,
    layer_spec: &LayerSpec,
    ctx: &BuildContext<'_>,
) -> Result<Vec<GlassRecord>, RegistryError> {
    let (files, integrators, opts) = (&ctx.files, ctx.integrators, ctx.opts);
    let glass = format!("{} (\"{}\")", spec.id, spec.name);
    let mut read = read_layer(layer_spec, files, &glass)?;
    read.layer.flipped = false;
    let layer = &read.layer;
    let mut normals = Vec::with_capacity(integrators.len());
    let mut luminous = None;
    for integrator in integrators {
        let (normal, lum) = normal_values(layer, integrator, &glass)?;
        normals.push(normal);
        luminous = lum;
    }
    let application = if layer.is_spectral() {
        opts.application
    } else {
        Application::PerChannel
    };
    let tables = ModelTables::sample(layer, &normals, application, integrators, &glass)?;
    let measured = read_measured_table(layer_spec, &spec.name, files, &glass)?;
    let mut records = Vec::with_capacity(integrators.len());
    for (normal, tables) in normals.iter().zip(&tables) {
        let curves = fit_glass_curves(normal, tables, measured.as_ref(), opts, &glass)?;
        let angle_model = angle_model_record(
            layer.model,
            layer.model_reason.clone(),
            application,
            layer_spec,
            measured.as_ref(),
        );
        let provenance = Provenance {
            catalog: None,
            spectral: read.source.as_ref().map(|s| s.0.clone()),
            angles: measured.as_ref().map(|m| m.file.clone()),
            product: read.source.as_ref().map(|s| s.1.clone()),
        };
        let mut g = glass_record(spec, normal, curves, luminous, angle_model, provenance);
        if layer_spec.flip {
            g.turn_round();
        }
        records.push(g);
    }
    Ok(records)
}

/// A glass record of `spec` from its normal values, curves and the records about them (a
/// unit's record is added by the caller).
pub(crate) fn glass_record(
    spec: &GlassSpec,
    normal: &NormalValues,
    curves: GlassCurves,
    luminous: Option<crate::LuminousRecord>,
    angle_model: AngleModelRecord,
    provenance: Provenance,
) -> GlassRecord {
    GlassRecord {
        id: spec.id,
        name: spec.name.clone(),
        r0: normal.r0,
        t0: normal.t0,
        r0_back: normal.r0_back,
        c_r: curves.c_r,
        c_t: curves.c_t,
        c_r_back: curves.c_r_back,
        luminous,
        angle_model,
        provenance,
        unit: None,
        hemispherical: None,
    }
}

/// The normal values of a layer as a unit sees it (after any flip).
pub(crate) fn oriented(normal: NormalValues, flipped: bool) -> NormalValues {
    if flipped { normal.flipped() } else { normal }
}

/// What the registry records about the angle model of a glass.
fn angle_model_record(
    model: LayerModel,
    chosen_by: String,
    application: Application,
    spec: &LayerSpec,
    measured: Option<&crate::angle_model::MeasuredTable>,
) -> AngleModelRecord {
    AngleModelRecord {
        kind: match measured {
            Some(_) => "measured".into(),
            None => model.name().to_string(),
        },
        applied: application.name().to_string(),
        ior: spec.ior.map(|v| v[1]).map(|(n, k)| [n, k]),
        measured_max_angle_deg: measured.map(|m| m.max_angle_deg),
        continued_by: measured.map(|_| model.name().to_string()),
        chosen_by,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Side;

    /// Lossless slab of index n, textbook Fresnel with incoherent multiple reflections.
    fn slab(n: f64, theta_deg: f64) -> (f64, f64) {
        if theta_deg == 0.0 {
            let rho = ((n - 1.0) / (n + 1.0)).powi(2);
            return (2.0 * rho / (1.0 + rho), (1.0 - rho) / (1.0 + rho));
        }
        let th = theta_deg.to_radians();
        let tt = (th.sin() / n).asin();
        let rs = ((th - tt).sin() / (th + tt).sin()).powi(2);
        let rp = ((th - tt).tan() / (th + tt).tan()).powi(2);
        let r = |x: f64| 2.0 * x / (1.0 + x);
        let t = |x: f64| (1.0 - x) / (1.0 + x);
        ((r(rs) + r(rp)) / 2.0, (t(rs) + t(rp)) / 2.0)
    }

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn measured_table_to_60_degrees_is_continued_to_grazing() {
        let dir = tempfile::tempdir().unwrap();
        let mut csv = String::from("angle_deg,R,T\n");
        for a in (0..=60).step_by(5) {
            let (r, t) = slab(1.52, a as f64);
            csv.push_str(&format!("{a},{r:.8},{t:.8}\n"));
        }
        write(dir.path(), "slab.csv", &csv);
        let (r0, t0) = slab(1.52, 0.0);
        let catalog = write(
            dir.path(),
            "catalog.toml",
            &format!(
                "[[glass]]\nid = 1\nname = \"slab\"\nr0 = [{r0}, {r0}, {r0}]\nt0 = [{t0}, {t0}, {t0}]\nangles = \"slab.csv\"\nmodel = \"uncoated\"\n"
            ),
        );
        let reg = build_registry(&catalog, &BuildOptions::default()).unwrap();
        let g = reg.default_table().glass(1).unwrap();
        assert_eq!(g.angle_model.kind, "measured");
        assert_eq!(g.angle_model.measured_max_angle_deg, Some(60.0));
        assert_eq!(g.angle_model.continued_by.as_deref(), Some("uncoated"));
        assert_eq!(g.provenance.angles.as_ref().unwrap().path, "slab.csv");
        // Inside the table and in the continued range the curves follow the same physics
        // (the table and the model are the same slab); the fit tolerance is 0.002.
        for a in [0.0, 20.0, 45.0, 60.0, 65.0, 75.0, 85.0] {
            let (r, t) = g.eval(Side::Front, f64::to_radians(a).cos());
            let (re, te) = slab(1.52, a);
            assert!(
                (r[1] - re).abs() < 0.0025 && (t[1] - te).abs() < 0.0025,
                "{a}°: {r:?} {t:?} vs {re} {te}"
            );
        }
        let (r, t) = g.eval(Side::Front, 0.0);
        assert!(r[0] > 0.995 && t[0] < 0.005, "grazing: {r:?} {t:?}");
    }

    #[test]
    fn angle_table_with_other_glasses_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        write(
            dir.path(),
            "t.csv",
            "glass,angle_deg,R\na,0,0.08\na,30,0.09\na,60,0.15\nb,0,0.08\nb,30,0.09\nb,60,0.15\n",
        );
        let catalog = write(
            dir.path(),
            "catalog.toml",
            "[[glass]]\nid = 1\nname = \"c\"\nr0 = [0.08, 0.08, 0.08]\nt0 = [0.9, 0.9, 0.9]\nangles = \"t.csv\"\n",
        );
        let err = build_registry(&catalog, &BuildOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("t.csv") && err.contains("(a, b)") && err.contains("\"c\""),
            "{err}"
        );
    }

    #[test]
    fn mask_ids_restrict_the_build_and_are_checked_against_the_catalog() {
        let dir = tempfile::tempdir().unwrap();
        let glass = |id: u16| {
            format!(
                "[[glass]]\nid = {id}\nname = \"g{id}\"\nr0 = [0.08, 0.08, 0.08]\nt0 = [0.9, 0.9, 0.9]\n"
            )
        };
        let catalog = write(
            dir.path(),
            "catalog.toml",
            &[glass(1), glass(2), glass(300)].concat(),
        );
        let only = |counts: &[(u16, u64)], eight_bit: bool| BuildOptions {
            mask_ids: Some(MaskIds {
                pixel_counts: counts.iter().copied().collect(),
                eight_bit_mask: eight_bit.then(|| PathBuf::from("m8.png")),
            }),
            ..BuildOptions::default()
        };
        let reg = build_registry(&catalog, &only(&[(2, 10)], false)).unwrap();
        assert_eq!(
            reg.default_table()
                .glasses
                .iter()
                .map(|g| g.id)
                .collect::<Vec<_>>(),
            [2]
        );
        let err = build_registry(&catalog, &only(&[(2, 10), (7, 3)], false)).unwrap_err();
        assert!(
            matches!(&err, RegistryError::IdsNotInCatalog { ids, .. } if ids == &[(7, 3)]),
            "{err}"
        );
        let err = build_registry(&catalog, &only(&[(1, 4)], true)).unwrap_err();
        assert!(
            matches!(&err, RegistryError::IdTooLargeForMask { id: 300, .. }),
            "{err}"
        );
        assert!(err.to_string().contains("m8.png"), "{err}");
    }

    #[test]
    fn opaque_metal_from_complex_ior() {
        let dir = tempfile::tempdir().unwrap();
        // Per-channel complex index; r0 is the Fresnel value |(N−1)/(N+1)|².
        let catalog = write(
            dir.path(),
            "catalog.toml",
            "[[glass]]\nid = 12\nname = \"metal\"\nmodel = \"opaque\"\nior = [[1.5, 7.8], [1.0, 6.7], [0.6, 5.5]]\n",
        );
        let reg = build_registry(&catalog, &BuildOptions::default()).unwrap();
        let g = reg.default_table().glass(12).unwrap();
        let f0 = |n: f64, k: f64| ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        assert!((g.r0[0] - f0(1.5, 7.8)).abs() < 1e-12);
        assert!((g.r0[2] - f0(0.6, 5.5)).abs() < 1e-12);
        assert_eq!(g.t0, [0.0; 3]);
        let (r, t) = g.eval(Side::Front, f64::to_radians(60.0).cos());
        assert_eq!(t, [0.0; 3]);
        for c in 0..3 {
            let (n, k) = [(1.5, 7.8), (1.0, 6.7), (0.6, 5.5)][c];
            let want = crate::physics::fresnel_single_surface(n, k, f64::to_radians(60.0).cos());
            assert!(
                (r[c] - want).abs() < 0.002,
                "channel {c}: {} vs {want}",
                r[c]
            );
        }
    }
}
