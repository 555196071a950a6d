//! Catalog → registry: normal-incidence values per channel (spectral integration or explicit),
//! angle tables (measured, or from a physical model applied per wavelength before integration),
//! and the fitted curves C_r, C_t, C_r_back per channel. Equations in `docs/registry.md`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glassdb_fit::{AngleSamples, CurveFit, FitOptions, Quantity};
use glassdb_spectral::{IntegrationSettings, Integrator, SpectralData};
use sha2::{Digest, Sha256};

use crate::catalog::{GlassSpec, ModelChoice, NormalSource, parse_catalog, resolve};
use crate::physics::{
    CoatedCurve, UncoatedSlab, fresnel_single_surface, ior_from_reflectance, opaque_reflectance,
};
use crate::{
    AngleModelRecord, CHANNELS, CurveRecord, FileRef, GlassRecord, LuminousRecord, ProductRecord,
    Provenance, Registry, RegistryError, SCHEMA_VERSION, SpectralMethodRecord,
};

/// Angles (degrees) at which a physical model is sampled for fitting: 0–90° in 1° steps.
const MODEL_STEP_DEG: f64 = 1.0;

/// Front and back reflectance of a glass are "equal" (uncoated) when they differ by less than
/// this everywhere (the rule of the Modelica Buildings library, `glassProperty`, tol = 0.005).
const UNCOATED_RF_RB_TOL: f64 = 0.005;

/// Where the angle model is applied.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Application {
    /// To the spectrum, wavelength by wavelength, before integration (what WINDOW does).
    #[default]
    PerWavelength,
    /// To the integrated per-channel values (the cheaper approximation; for comparison).
    PerChannel,
}

impl Application {
    pub fn name(self) -> &'static str {
        match self {
            Application::PerWavelength => "per-wavelength",
            Application::PerChannel => "per-channel",
        }
    }
}

/// How to build a registry.
#[derive(Debug, Clone)]
pub struct BuildOptions {
    /// Spectral method for the whole build (recorded in the registry).
    pub spectral: IntegrationSettings,
    /// With masks, only the ids that appear in them are built.
    pub masks: Vec<PathBuf>,
    /// Options for reading the masks.
    pub mask_options: glassdb_mask::MaskReadOptions,
    /// Fit tolerance on r and t (absolute).
    pub fit_tol: f64,
    /// Highest polynomial degree tried.
    pub max_degree: u32,
    /// Where the physical angle model is applied when a spectrum is given.
    pub application: Application,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            spectral: IntegrationSettings::default(),
            masks: Vec::new(),
            mask_options: glassdb_mask::MaskReadOptions::default(),
            fit_tol: glassdb_fit::DEFAULT_TOL,
            max_degree: 12,
            application: Application::PerWavelength,
        }
    }
}

/// Reads the files a catalog names: from disk (relative to the catalog) or from the bundled
/// data compiled into the binary.
enum Files<'a> {
    Disk { catalog_path: &'a Path },
    Bundled,
}

impl Files<'_> {
    fn read(&self, rel: &str) -> Result<(PathBuf, Vec<u8>), (PathBuf, String)> {
        match self {
            Files::Disk { catalog_path } => {
                let p = resolve(catalog_path, rel);
                match std::fs::read(&p) {
                    Ok(bytes) => Ok((p, bytes)),
                    Err(e) => Err((p, format!("cannot read it: {e}"))),
                }
            }
            Files::Bundled => crate::bundled::file(rel)
                .map(|b| (PathBuf::from(rel), b.to_vec()))
                .ok_or_else(|| {
                    (
                        PathBuf::from(rel),
                        "not among the bundled files".to_string(),
                    )
                }),
        }
    }
}

fn sha256_hex(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// Builds a registry from a catalog file (paths in it are relative to the catalog).
pub fn build_registry(catalog_path: &Path, opts: &BuildOptions) -> Result<Registry, RegistryError> {
    let bytes = std::fs::read(catalog_path).map_err(|source| RegistryError::Read {
        path: catalog_path.to_path_buf(),
        source,
    })?;
    let text = String::from_utf8(bytes.clone()).map_err(|e| RegistryError::CatalogSyntax {
        path: catalog_path.to_path_buf(),
        message: format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
    })?;
    build_from_text(
        &text,
        &sha256_hex(&bytes),
        catalog_path,
        &Files::Disk { catalog_path },
        opts,
    )
}

/// The registry of the bundled default catalog (`data/catalog.toml` and its spectral files,
/// compiled in): no file lookups. Built once per process and cloned afterwards.
pub fn default_registry() -> Result<Registry, RegistryError> {
    static DEFAULT: std::sync::OnceLock<Result<Registry, String>> = std::sync::OnceLock::new();
    DEFAULT
        .get_or_init(|| {
            let text = crate::bundled::CATALOG;
            build_from_text(
                text,
                &sha256_hex(text.as_bytes()),
                Path::new(crate::bundled::CATALOG_NAME),
                &Files::Bundled,
                &BuildOptions::default(),
            )
            .map_err(|e| e.to_string())
        })
        .clone()
        .map_err(RegistryError::Bundled)
}

fn build_from_text(
    text: &str,
    catalog_sha: &str,
    catalog_path: &Path,
    files: &Files<'_>,
    opts: &BuildOptions,
) -> Result<Registry, RegistryError> {
    let specs = parse_catalog(text, catalog_path)?;
    let wanted = mask_filter(&specs, catalog_path, opts)?;
    let integrator = Integrator::new(&opts.spectral).map_err(|e| RegistryError::Integration {
        glass: "(all)".into(),
        message: e.to_string(),
    })?;
    let catalog_ref = FileRef {
        path: catalog_path.display().to_string(),
        sha256: catalog_sha.to_string(),
    };
    let mut glasses = Vec::new();
    for spec in &specs {
        if let Some(w) = &wanted
            && !w.contains(&spec.id)
        {
            continue;
        }
        let mut g = build_glass(spec, files, &integrator, opts)?;
        g.provenance.catalog = Some(catalog_ref.clone());
        glasses.push(g);
    }
    glasses.sort_by_key(|g| g.id);
    let registry = Registry {
        schema: SCHEMA_VERSION,
        spectral: method_record(&opts.spectral),
        glasses,
    };
    registry.validate_named(&format!("registry built from {}", catalog_path.display()))?;
    Ok(registry)
}

/// The ids the masks use (None without masks); errors for ids missing from the catalog and for
/// catalog ids an 8-bit mask cannot hold.
fn mask_filter(
    specs: &[GlassSpec],
    catalog_path: &Path,
    opts: &BuildOptions,
) -> Result<Option<Vec<u16>>, RegistryError> {
    if opts.masks.is_empty() {
        return Ok(None);
    }
    let mut counts: BTreeMap<u16, u64> = BTreeMap::new();
    for path in &opts.masks {
        let mask = glassdb_mask::read_mask(path, &opts.mask_options)?;
        if matches!(mask.cos_theta, glassdb_mask::CosTheta::Quantized8(_))
            && let Some(big) = specs.iter().find(|s| s.id > 255)
        {
            return Err(RegistryError::IdTooLargeForMask {
                path: catalog_path.to_path_buf(),
                name: big.name.clone(),
                id: big.id,
                mask: path.clone(),
            });
        }
        for (id, n) in mask.id_pixel_counts() {
            *counts.entry(id).or_insert(0) += n;
        }
    }
    let missing: Vec<(u16, u64)> = counts
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
    Ok(Some(counts.keys().copied().collect()))
}

fn method_record(s: &IntegrationSettings) -> SpectralMethodRecord {
    use glassdb_spectral::Method;
    let mut rec = SpectralMethodRecord {
        method: String::new(),
        cmf: None,
        observer: None,
        illuminant: None,
        space: None,
        extrapolate: s.extrapolate,
    };
    match &s.method {
        Method::Paper(cmf) => {
            rec.method = "paper".into();
            rec.cmf = Some(cmf.name().to_string());
        }
        Method::Colorimetric {
            observer,
            illuminant,
            space,
        } => {
            rec.method = "colorimetric".into();
            rec.observer = Some(observer.name().to_string());
            rec.illuminant = Some(illuminant.name().to_string());
            rec.space = Some(space.name().to_string());
        }
        Method::Luminous => rec.method = "luminous".into(),
    }
    rec
}

/// Spectra of one glass at normal incidence on the file's own wavelengths.
struct Spectra {
    wavelength_nm: Vec<f64>,
    t: Vec<f64>,
    rf: Vec<f64>,
    rb: Vec<f64>,
}

/// The physical model chosen for a glass.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Physical {
    Uncoated,
    /// Clear/bronze chosen per wavelength (or per channel) by T0 > 0.645.
    Coated,
    CoatedFixed(CoatedCurve),
    Opaque,
}

impl Physical {
    fn name(self) -> &'static str {
        match self {
            Physical::Uncoated => "uncoated",
            Physical::Coated => "coated",
            Physical::CoatedFixed(CoatedCurve::Clear) => "coated-clear",
            Physical::CoatedFixed(CoatedCurve::Bronze) => "coated-bronze",
            Physical::Opaque => "opaque",
        }
    }
}

/// `(Rf, T, Rb)` of one wavelength (or channel) at `cos θ`.
fn model_at(
    model: Physical,
    t0: f64,
    rf0: f64,
    rb0: f64,
    ior: Option<(f64, f64)>,
    cos_theta: f64,
) -> (f64, f64, f64) {
    match model {
        Physical::Uncoated => {
            let (rf, t) = UncoatedSlab::from_normal(t0, rf0).at(cos_theta);
            let (rb, _) = UncoatedSlab::from_normal(t0, rb0).at(cos_theta);
            (rf, t, rb)
        }
        Physical::Coated | Physical::CoatedFixed(_) => {
            let curve = match model {
                Physical::CoatedFixed(c) => c,
                _ => CoatedCurve::for_t0(t0),
            };
            let (rf, t) = curve.at(t0, rf0, cos_theta);
            let (rb, _) = curve.at(t0, rb0, cos_theta);
            (rf, t, rb)
        }
        Physical::Opaque => {
            let f = |r0: f64| match ior {
                Some(nk) => opaque_reflectance(r0, nk, cos_theta),
                None => fresnel_single_surface(ior_from_reflectance(r0), 0.0, cos_theta),
            };
            (f(rf0), 0.0, f(rb0))
        }
    }
}

/// Picks the physical model for `auto` from the product type, or from the data.
fn choose_model(
    spec: &GlassSpec,
    product_type: Option<&str>,
    t: &[f64],
    rf: &[f64],
    rb: &[f64],
) -> (Physical, String) {
    let fixed = match spec.model {
        ModelChoice::Uncoated => Some(Physical::Uncoated),
        ModelChoice::Coated => Some(Physical::Coated),
        ModelChoice::CoatedClear => Some(Physical::CoatedFixed(CoatedCurve::Clear)),
        ModelChoice::CoatedBronze => Some(Physical::CoatedFixed(CoatedCurve::Bronze)),
        ModelChoice::Opaque => Some(Physical::Opaque),
        ModelChoice::Auto => None,
    };
    if let Some(m) = fixed {
        return (m, "catalog `model`".into());
    }
    if spec.ior.is_some() {
        return (Physical::Opaque, "catalog `ior`".into());
    }
    if t.iter().all(|&v| v <= 0.0) {
        return (Physical::Opaque, "zero transmittance".into());
    }
    if let Some(pt) = product_type {
        let p = pt.to_ascii_lowercase();
        if p.contains("monolithic") {
            return (Physical::Uncoated, format!("product type \"{pt}\""));
        }
        let coated = ["coat", "laminate", "film", "interlayer"];
        if coated.iter().any(|k| p.contains(k)) {
            return (Physical::Coated, format!("product type \"{pt}\""));
        }
    }
    let max_diff = rf
        .iter()
        .zip(rb)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    if max_diff < UNCOATED_RF_RB_TOL {
        let why = format!("Rf = Rb within {UNCOATED_RF_RB_TOL} (max difference {max_diff:.4})");
        (Physical::Uncoated, why)
    } else {
        (
            Physical::Coated,
            format!("Rf differs from Rb by up to {max_diff:.4}"),
        )
    }
}

fn build_glass(
    spec: &GlassSpec,
    files: &Files<'_>,
    integrator: &Integrator,
    opts: &BuildOptions,
) -> Result<GlassRecord, RegistryError> {
    let glass = format!("{} (\"{}\")", spec.id, spec.name);
    let mut provenance = Provenance::default();

    // Normal-incidence data.
    let (spectra, product_type) = match &spec.normal {
        NormalSource::Spectral { path, percent } => {
            let (full, bytes) =
                files
                    .read(path)
                    .map_err(|(p, message)| RegistryError::Spectral {
                        glass: glass.clone(),
                        path: p,
                        message,
                    })?;
            let read_opts = glassdb_spectral::ReadOptions { percent: *percent };
            let data = glassdb_spectral::read_spectral_bytes(
                &bytes,
                &full.display().to_string(),
                &read_opts,
            )
            .map_err(|e| RegistryError::Spectral {
                glass: glass.clone(),
                path: full.clone(),
                message: e.to_string(),
            })?;
            provenance.spectral = Some(FileRef {
                path: path.clone(),
                sha256: sha256_hex(&bytes),
            });
            let pt = data.product.product_type.clone();
            provenance.product = Some(ProductRecord {
                name: data.product.name.clone(),
                manufacturer: data.product.manufacturer.clone(),
                product_type: data.product.product_type.clone(),
                coated_side: data.product.coated_side.clone(),
                thickness_mm: data.product.thickness_mm,
            });
            (Some(spectra_of(data, spec, &glass, &full)?), pt)
        }
        NormalSource::Explicit { .. } => (None, None),
    };

    let integrate = |values: &[f64], what: &str| -> Result<[f64; 3], RegistryError> {
        let s = spectra.as_ref().ok_or_else(|| RegistryError::Integration {
            glass: glass.clone(),
            message: "no spectrum".into(),
        })?;
        integrator
            .channels(&s.wavelength_nm, values)
            .map_err(|e| RegistryError::Integration {
                glass: glass.clone(),
                message: format!("{what}: {e}"),
            })
    };

    let (r0, t0, r0_back, luminous) = match (&spec.normal, &spectra) {
        (NormalSource::Explicit { r0, t0, r0_back }, _) => (*r0, *t0, *r0_back, None),
        (NormalSource::Spectral { .. }, Some(s)) => {
            let lum = |v: &[f64], what: &str| {
                glassdb_spectral::luminous_iso9050(&s.wavelength_nm, v).map_err(|e| {
                    RegistryError::Integration {
                        glass: glass.clone(),
                        message: format!("luminous {what}: {e}"),
                    }
                })
            };
            let luminous = LuminousRecord {
                transmittance: lum(&s.t, "transmittance")?,
                reflectance: lum(&s.rf, "reflectance")?,
                reflectance_back: lum(&s.rb, "back reflectance")?,
            };
            let clamp3 = |v: [f64; 3]| v.map(|x| x.clamp(0.0, 1.0));
            (
                clamp3(integrate(&s.rf, "front reflectance")?),
                clamp3(integrate(&s.t, "transmittance")?),
                clamp3(integrate(&s.rb, "back reflectance")?),
                Some(luminous),
            )
        }
        (NormalSource::Spectral { .. }, None) => {
            return Err(RegistryError::Integration {
                glass: glass.clone(),
                message: "the spectral file was not read".into(),
            });
        }
    };

    // The physical model (used alone, or to continue a measured table to 90°).
    let (model, why) = match &spectra {
        Some(s) => choose_model(spec, product_type.as_deref(), &s.t, &s.rf, &s.rb),
        None => choose_model(spec, None, &t0, &r0, &r0_back),
    };
    let ior_per_channel = spec.ior;
    let ior_single = ior_per_channel.map(|v| v[1]);

    // Model tables per channel at MODEL_STEP_DEG: (angle, rf, t, rb).
    let steps = (90.0 / MODEL_STEP_DEG).round() as usize;
    let angles: Vec<f64> = (0..=steps).map(|i| i as f64 * MODEL_STEP_DEG).collect();
    let cos_of = |deg: f64| {
        if deg >= 90.0 {
            0.0
        } else {
            deg.to_radians().cos()
        }
    };
    let application = if spectra.is_some() {
        opts.application
    } else {
        Application::PerChannel
    };
    let mut rf_tab = vec![[0.0; 3]; angles.len()];
    let mut t_tab = vec![[0.0; 3]; angles.len()];
    let mut rb_tab = vec![[0.0; 3]; angles.len()];
    for (i, &deg) in angles.iter().enumerate() {
        let c = cos_of(deg);
        if i == 0 {
            rf_tab[i] = r0;
            t_tab[i] = t0;
            rb_tab[i] = r0_back;
            continue;
        }
        match (application, &spectra) {
            (Application::PerWavelength, Some(s)) => {
                let n = s.wavelength_nm.len();
                let (mut rf, mut t, mut rb) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
                for k in 0..n {
                    (rf[k], t[k], rb[k]) = model_at(model, s.t[k], s.rf[k], s.rb[k], ior_single, c);
                }
                rf_tab[i] = integrate(&rf, &format!("front reflectance at {deg}°"))?;
                t_tab[i] = if model == Physical::Opaque {
                    [0.0; 3]
                } else {
                    integrate(&t, &format!("transmittance at {deg}°"))?
                };
                rb_tab[i] = integrate(&rb, &format!("back reflectance at {deg}°"))?;
            }
            _ => {
                for ch in 0..3 {
                    let nk = ior_per_channel.map(|v| v[ch]);
                    (rf_tab[i][ch], t_tab[i][ch], rb_tab[i][ch]) =
                        model_at(model, t0[ch], r0[ch], r0_back[ch], nk, c);
                }
            }
        }
    }

    // A measured table replaces the model for front R and T up to its last angle.
    let mut kind = model.name().to_string();
    let mut measured_max_angle_deg = None;
    let mut continued_by = None;
    let mut measured_r: Option<AngleSamples> = None;
    let mut measured_t: Option<AngleSamples> = None;
    if let Some((rel, percent)) = &spec.angles {
        let (full, bytes) = files
            .read(rel)
            .map_err(|(p, message)| RegistryError::AngleTable {
                glass: glass.clone(),
                path: p,
                message,
            })?;
        let stem = full
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "glass".into());
        let tables =
            glassdb_fit::parse_angle_table(&bytes, &full, &stem, *percent).map_err(|e| {
                RegistryError::AngleTable {
                    glass: glass.clone(),
                    path: full.clone(),
                    message: e.to_string(),
                }
            })?;
        let names: Vec<String> = tables.iter().map(|t| t.name.clone()).collect();
        let table = if tables.len() == 1 {
            tables.into_iter().next()
        } else {
            tables.into_iter().find(|t| t.name == spec.name)
        };
        let table = table.ok_or_else(|| RegistryError::AngleTable {
            glass: glass.clone(),
            path: full.clone(),
            message: if names.is_empty() {
                "holds no glass".to_string()
            } else {
                format!(
                    "holds several glasses ({}) and none is named \"{}\"",
                    names.join(", "),
                    spec.name
                )
            },
        })?;
        provenance.angles = Some(FileRef {
            path: rel.clone(),
            sha256: sha256_hex(&bytes),
        });
        kind = "measured".into();
        continued_by = Some(model.name().to_string());
        let mut max_angle: f64 = 0.0;
        for s in [&table.reflectance, &table.transmittance]
            .into_iter()
            .flatten()
        {
            max_angle = max_angle.max(s.angle_deg.iter().copied().fold(0.0, f64::max));
        }
        measured_max_angle_deg = Some(max_angle);
        measured_r = table.reflectance;
        measured_t = table.transmittance;
    }

    let fit = |samples: &AngleSamples,
               quantity: Quantity,
               curve: String|
     -> Result<CurveRecord, RegistryError> {
        fit_record(samples, quantity, opts).map_err(|message| RegistryError::Fit {
            glass: glass.clone(),
            curve,
            message,
        })
    };
    let model_samples = |tab: &[[f64; 3]], ch: usize| AngleSamples {
        angle_deg: angles.clone(),
        value: tab.iter().map(|v| v[ch]).collect(),
    };

    let mut c_r: Vec<CurveRecord> = Vec::with_capacity(3);
    let mut c_t: Vec<CurveRecord> = Vec::with_capacity(3);
    let mut c_r_back: Vec<CurveRecord> = Vec::with_capacity(3);
    // Measured curves are shared by the three channels: the ratio C(θ) of the table.
    let shared_r = match &measured_r {
        Some(m) => Some(fit(
            &continue_measured(m, &angles, &rf_tab, true),
            Quantity::Reflectance,
            "measured R".into(),
        )?),
        None => None,
    };
    let shared_t = match &measured_t {
        Some(m) => Some(fit(
            &continue_measured(m, &angles, &t_tab, false),
            Quantity::Transmittance,
            "measured T".into(),
        )?),
        None => None,
    };
    for ch in 0..3 {
        let name = CHANNELS[ch];
        c_r.push(match &shared_r {
            Some(c) => c.clone(),
            None if r0[ch] <= 1e-9 => CurveRecord::nominal_transmittance(),
            None => fit(
                &model_samples(&rf_tab, ch),
                Quantity::Reflectance,
                format!("C_r channel {name}"),
            )?,
        });
        c_t.push(match &shared_t {
            Some(c) => c.clone(),
            None if t0[ch] <= 1e-9 => CurveRecord::nominal_transmittance(),
            None => fit(
                &model_samples(&t_tab, ch),
                Quantity::Transmittance,
                format!("C_t channel {name}"),
            )?,
        });
        c_r_back.push(if r0_back[ch] <= 1e-9 {
            CurveRecord::nominal_transmittance()
        } else {
            fit(
                &model_samples(&rb_tab, ch),
                Quantity::Reflectance,
                format!("C_r_back channel {name}"),
            )?
        });
    }
    let arr = |v: Vec<CurveRecord>| -> [CurveRecord; 3] {
        let mut it = v.into_iter();
        std::array::from_fn(|_| it.next().unwrap_or_else(CurveRecord::nominal_transmittance))
    };

    Ok(GlassRecord {
        id: spec.id,
        name: spec.name.clone(),
        r0,
        t0,
        r0_back,
        c_r: arr(c_r),
        c_t: arr(c_t),
        c_r_back: arr(c_r_back),
        luminous,
        angle_model: AngleModelRecord {
            kind,
            applied: application.name().to_string(),
            ior: ior_single.map(|(n, k)| [n, k]),
            measured_max_angle_deg,
            continued_by,
            chosen_by: why,
        },
        provenance,
    })
}

fn spectra_of(
    data: SpectralData,
    spec: &GlassSpec,
    glass: &str,
    path: &Path,
) -> Result<Spectra, RegistryError> {
    let err = |message: String| RegistryError::Spectral {
        glass: glass.to_string(),
        path: path.to_path_buf(),
        message,
    };
    let n = data.wavelength_nm.len();
    let opaque = spec.model == ModelChoice::Opaque || spec.ior.is_some();
    let t = match data.transmittance {
        Some(t) if opaque => {
            if t.iter().any(|&v| v > 0.0) {
                return Err(err(
                    "model `opaque` means T = 0, but the file has a non-zero transmittance".into(),
                ));
            }
            t
        }
        Some(t) => t,
        None if opaque => vec![0.0; n],
        None => return Err(err("has no transmittance column (T)".into())),
    };
    let rf = data
        .reflectance_front
        .ok_or_else(|| err("has no front reflectance column (R or Rf)".into()))?;
    let rb = data.reflectance_back.unwrap_or_else(|| rf.clone());
    if t.len() != n || rf.len() != n || rb.len() != n {
        return Err(err("columns of different lengths".into()));
    }
    for k in 0..n {
        if t[k] + rf[k] > 1.0 + 1e-6 || t[k] + rb[k] > 1.0 + 1e-6 {
            return Err(err(format!(
                "at {} nm, T + R = {:.4} > 1: more light out than in",
                data.wavelength_nm[k],
                t[k] + rf[k].max(rb[k])
            )));
        }
    }
    Ok(Spectra {
        wavelength_nm: data.wavelength_nm,
        t,
        rf,
        rb,
    })
}

/// A measured table continued by the physical model beyond its last angle so that R → 1 and
/// T → 0 at 90°: for θ > θmax, `R(θ) = Rm + (Rp(θ) − Rp(θmax))·(1 − Rm)/(1 − Rp(θmax))` and
/// `T(θ) = Tm·Tp(θ)/Tp(θmax)`, with Rm, Tm the measured values at θmax and Rp, Tp the model's
/// (channel G).
fn continue_measured(
    m: &AngleSamples,
    angles: &[f64],
    tab: &[[f64; 3]],
    reflect: bool,
) -> AngleSamples {
    let mut out = m.clone();
    let Some((last_i, &theta_max)) = m
        .angle_deg
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
    else {
        return out;
    };
    if theta_max >= 90.0 - 1e-9 {
        return out;
    }
    let measured_at_max = m.value[last_i];
    // The model's absolute value (channel G) at an angle, interpolated in the 1° model table.
    let g = 1;
    let model = |deg: f64| -> f64 {
        let x = deg.clamp(0.0, 90.0) / MODEL_STEP_DEG;
        let i = (x.floor() as usize).min(angles.len().saturating_sub(2));
        let f = x - i as f64;
        tab[i][g] * (1.0 - f) + tab[i + 1][g] * f
    };
    let at_max = model(theta_max);
    for &deg in angles.iter().filter(|&&d| d > theta_max + 0.5) {
        let v = if reflect {
            if at_max < 1.0 {
                measured_at_max + (model(deg) - at_max) * (1.0 - measured_at_max) / (1.0 - at_max)
            } else {
                1.0
            }
        } else if at_max > 0.0 {
            measured_at_max * model(deg) / at_max
        } else {
            0.0
        };
        out.angle_deg.push(deg);
        out.value.push(v.clamp(0.0, 1.0));
    }
    out
}

/// Fits one curve and turns it into a registry curve record.
fn fit_record(
    samples: &AngleSamples,
    quantity: Quantity,
    opts: &BuildOptions,
) -> Result<CurveRecord, String> {
    let mut fo = FitOptions::new(quantity);
    fo.tol = opts.fit_tol;
    fo.max_degree = opts.max_degree;
    let fit: CurveFit = glassdb_fit::fit_curve(samples, &fo).map_err(|e| e.to_string())?;
    Ok(curve_record(&fit, opts.fit_tol))
}

/// A fitted curve as a registry record; the validation tolerance is the larger of the fit
/// tolerance and the fit's own largest residual.
pub fn curve_record(fit: &CurveFit, tol: f64) -> CurveRecord {
    let d = &fit.diagnostics;
    CurveRecord {
        basis: fit.polynomial.basis.name().to_string(),
        powers: fit.polynomial.powers.clone(),
        coefficients: fit.polynomial.coefficients.clone(),
        degree: d.degree,
        rms_error: d.rms_error,
        max_abs_error: d.max_abs_error,
        max_error_angle_deg: d.max_error_angle_deg,
        condition_number: d.condition_number,
        tolerance: tol.max(d.max_abs_error),
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
        let g = reg.glass(1).unwrap();
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
    fn auto_model_from_product_type_and_from_rf_rb() {
        let spec = GlassSpec {
            id: 1,
            name: "x".into(),
            normal: NormalSource::Explicit {
                r0: [0.1; 3],
                t0: [0.8; 3],
                r0_back: [0.1; 3],
            },
            angles: None,
            model: ModelChoice::Auto,
            ior: None,
        };
        let t = [0.8, 0.8];
        let (m, _) = choose_model(&spec, Some("Monolithic"), &t, &[0.1, 0.1], &[0.3, 0.3]);
        assert_eq!(m, Physical::Uncoated);
        let (m, _) = choose_model(&spec, Some("applied-film"), &t, &[0.1, 0.1], &[0.1, 0.1]);
        assert_eq!(m, Physical::Coated);
        let (m, why) = choose_model(&spec, None, &t, &[0.1, 0.1], &[0.104, 0.1]);
        assert_eq!(m, Physical::Uncoated, "{why}");
        let (m, _) = choose_model(&spec, None, &t, &[0.1, 0.1], &[0.106, 0.1]);
        assert_eq!(m, Physical::Coated);
        let (m, _) = choose_model(&spec, None, &[0.0, 0.0], &[0.9, 0.9], &[0.9, 0.9]);
        assert_eq!(m, Physical::Opaque);
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
        let g = reg.glass(12).unwrap();
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
