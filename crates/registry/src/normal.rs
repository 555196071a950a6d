//! Normal-incidence values of a glass: its spectra read from the catalog's spectral file and
//! integrated per channel (and to ISO 9050 luminous values), or the catalog's explicit values.

use std::path::{Path, PathBuf};

use glassdb_spectral::{Integrator, SpectralData};

use crate::catalog::{GlassSpec, ModelChoice, NormalSource};
use crate::catalog_files::{CatalogFiles, sha256_hex};
use crate::{FileRef, LuminousRecord, ProductRecord, RegistryError};

/// Spectra of one glass at normal incidence on the file's own wavelengths.
pub(crate) struct Spectra {
    /// The spectral file, for messages.
    pub path: PathBuf,
    pub wavelength_nm: Vec<f64>,
    pub t: Vec<f64>,
    pub rf: Vec<f64>,
    pub rb: Vec<f64>,
}

/// A glass's spectral file, read: the spectra, the product type the file states, and the
/// provenance records of the file and the product.
pub(crate) struct SpectralSource {
    pub spectra: Spectra,
    pub product_type: Option<String>,
    pub file: FileRef,
    pub product: ProductRecord,
}

/// Per-channel normal-incidence values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct NormalValues {
    pub r0: [f64; 3],
    pub t0: [f64; 3],
    pub r0_back: [f64; 3],
}

/// Integrates one spectrum of a glass to three channels; `what` names it in errors.
pub(crate) fn integrate(
    integrator: &Integrator,
    spectra: &Spectra,
    values: &[f64],
    glass: &str,
    what: String,
) -> Result<[f64; 3], RegistryError> {
    integrator
        .channels(&spectra.wavelength_nm, values)
        .map_err(|source| RegistryError::Integration {
            glass: glass.to_string(),
            what,
            source: Box::new(source),
        })
}

/// Reads the spectral file of a glass (none for explicit values).
pub(crate) fn read_spectral_source(
    spec: &GlassSpec,
    files: &CatalogFiles<'_>,
    glass: &str,
) -> Result<Option<SpectralSource>, RegistryError> {
    let NormalSource::Spectral { path, percent } = &spec.normal else {
        return Ok(None);
    };
    let (full, bytes) = files.read(path, glass, glassdb_spectral::SPECTRAL_FILE)?;
    let read_opts = glassdb_spectral::ReadOptions { percent: *percent };
    let data =
        glassdb_spectral::read_spectral_bytes(&bytes, &full.display().to_string(), &read_opts)
            .map_err(|source| RegistryError::Spectral {
                glass: glass.to_string(),
                path: full.clone(),
                source: Box::new(source),
            })?;
    let product_type = data.product.product_type.clone();
    let product = ProductRecord {
        name: data.product.name.clone(),
        manufacturer: data.product.manufacturer.clone(),
        product_type: data.product.product_type.clone(),
        coated_side: data.product.coated_side.clone(),
        thickness_mm: data.product.thickness_mm,
    };
    Ok(Some(SpectralSource {
        spectra: spectra_of(data, spec, glass, &full)?,
        product_type,
        file: FileRef {
            path: path.clone(),
            sha256: sha256_hex(&bytes),
        },
        product,
    }))
}

/// The normal-incidence values: the catalog's explicit ones, or the spectra integrated per
/// channel (clamped to [0, 1]; t + r ≤ 1 per channel and side,
/// [`glassdb_spectral::check_channel_balance`]) with their luminous values.
pub(crate) fn normal_values(
    spec: &GlassSpec,
    spectra: Option<&Spectra>,
    integrator: &Integrator,
    glass: &str,
) -> Result<(NormalValues, Option<LuminousRecord>), RegistryError> {
    let s = match (&spec.normal, spectra) {
        (NormalSource::Explicit { r0, t0, r0_back }, _) => {
            let values = NormalValues {
                r0: *r0,
                t0: *t0,
                r0_back: *r0_back,
            };
            return Ok((values, None));
        }
        (NormalSource::Spectral { .. }, Some(s)) => s,
        (NormalSource::Spectral { path, .. }, None) => {
            return Err(RegistryError::SpectralContent {
                glass: glass.to_string(),
                path: PathBuf::from(path),
                detail: "the spectral file was not read".into(),
            });
        }
    };
    let lum = |v: &[f64], what: &str| {
        glassdb_spectral::luminous_iso9050(&s.wavelength_nm, v).map_err(|source| {
            RegistryError::Integration {
                glass: glass.to_string(),
                what: format!("luminous {what}"),
                source: Box::new(source),
            }
        })
    };
    let luminous = LuminousRecord {
        transmittance: lum(&s.t, "transmittance")?,
        reflectance: lum(&s.rf, "reflectance")?,
        reflectance_back: lum(&s.rb, "back reflectance")?,
    };
    let channels = |v: &[f64], what: &str| {
        integrate(integrator, s, v, glass, what.to_string()).map(|c| c.map(|x| x.clamp(0.0, 1.0)))
    };
    let values = NormalValues {
        r0: channels(&s.rf, "front reflectance")?,
        t0: channels(&s.t, "transmittance")?,
        r0_back: channels(&s.rb, "back reflectance")?,
    };
    // the check `glassdb spectral` applies to the same integrated values
    for (r, side) in [(values.r0, "front"), (values.r0_back, "back")] {
        glassdb_spectral::check_channel_balance(values.t0, r, side, &s.wavelength_nm).map_err(
            |source| RegistryError::Spectral {
                glass: glass.to_string(),
                path: s.path.clone(),
                source: Box::new(source),
            },
        )?;
    }
    Ok((values, Some(luminous)))
}

/// The spectra of a parsed file, checked against the glass: T (zero for opaque glass), Rf, Rb
/// (Rf when absent), equal lengths, and T + R ≤ 1 at every wavelength
/// ([`glassdb_spectral::check_spectrum_balance`], as `glassdb spectral` checks it).
fn spectra_of(
    data: SpectralData,
    spec: &GlassSpec,
    glass: &str,
    path: &Path,
) -> Result<Spectra, RegistryError> {
    let err = |detail: String| RegistryError::SpectralContent {
        glass: glass.to_string(),
        path: path.to_path_buf(),
        detail,
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
    glassdb_spectral::check_spectrum_balance(
        &data.wavelength_nm,
        Some(&t),
        &[Some(&rf), Some(&rb)],
    )
    .map_err(|source| RegistryError::Spectral {
        glass: glass.to_string(),
        path: path.to_path_buf(),
        source: Box::new(source),
    })?;
    Ok(Spectra {
        path: path.to_path_buf(),
        wavelength_nm: data.wavelength_nm,
        t,
        rf,
        rb,
    })
}
