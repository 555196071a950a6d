//! A layer from the catalog: its spectral file read into a stack-engine [`Layer`] (or its
//! explicit values), and its normal-incidence values integrated per channel (and to ISO 9050
//! luminous values).

use glassdb_spectral::Integrator;
use glassdb_stack::{Layer, LayerData, LayerOptions, StackError};

use crate::catalog::{LayerSpec, NormalSource};
use crate::catalog_files::{CatalogFiles, sha256_hex};
use crate::{FileRef, LuminousRecord, ProductRecord, RegistryError};

/// Per-channel normal-incidence values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct NormalValues {
    pub r0: [f64; 3],
    pub t0: [f64; 3],
    pub r0_back: [f64; 3],
}

impl NormalValues {
    /// The values of the layer turned round (front and back reflectance swapped).
    pub(crate) fn flipped(self) -> NormalValues {
        NormalValues {
            r0: self.r0_back,
            t0: self.t0,
            r0_back: self.r0,
        }
    }
}

/// A layer read from the catalog, with the provenance of its spectral file.
pub(crate) struct CatalogLayer {
    pub layer: Layer,
    /// The spectral file and the product it describes (none for explicit values).
    pub source: Option<(FileRef, ProductRecord)>,
}

/// The layer options of a catalog layer.
pub(crate) fn layer_options(spec: &LayerSpec) -> LayerOptions {
    LayerOptions {
        model: spec.model,
        ior: spec.ior,
        flipped: spec.flip,
        thickness_mm: spec.thickness_mm,
    }
}

/// Reads a catalog layer with spectral data or explicit values (a layer given by its angle
/// table alone is read with the table, by the unit builder).
pub(crate) fn read_layer(
    spec: &LayerSpec,
    files: &CatalogFiles<'_>,
    glass: &str,
) -> Result<CatalogLayer, RegistryError> {
    let opts = layer_options(spec);
    let (path, percent) = match &spec.normal {
        NormalSource::Spectral { path, percent } => (path, *percent),
        NormalSource::Explicit { r0, t0, r0_back } => {
            return Ok(CatalogLayer {
                layer: Layer::from_channels("r0/t0 values", *t0, *r0, *r0_back, &opts),
                source: None,
            });
        }
        NormalSource::AngleTable => {
            unreachable!("layers given by an angle table are read by the unit builder")
        }
    };
    let (full, bytes) = files.read(path, glass, glassdb_spectral::SPECTRAL_FILE)?;
    let read_opts = glassdb_spectral::ReadOptions { percent };
    let data =
        glassdb_spectral::read_spectral_bytes(&bytes, &full.display().to_string(), &read_opts)
            .map_err(|source| RegistryError::Spectral {
                glass: glass.to_string(),
                path: full.clone(),
                source: Box::new(source),
            })?;
    let product = ProductRecord {
        name: data.product.name.clone(),
        manufacturer: data.product.manufacturer.clone(),
        product_type: data.product.product_type.clone(),
        coated_side: data.product.coated_side.clone(),
        thickness_mm: data.product.thickness_mm,
        composition: data.product.composition.clone(),
    };
    let layer = Layer::from_spectral_data(data, &opts, &full.display().to_string()).map_err(
        |e| match e {
            StackError::LayerSpectrum { source, .. } => RegistryError::Spectral {
                glass: glass.to_string(),
                path: full.clone(),
                source,
            },
            StackError::Layer { message, .. } => RegistryError::SpectralContent {
                glass: glass.to_string(),
                path: full.clone(),
                detail: message,
            },
            other => RegistryError::SpectralContent {
                glass: glass.to_string(),
                path: full.clone(),
                detail: other.to_string(),
            },
        },
    )?;
    Ok(CatalogLayer {
        layer,
        source: Some((
            FileRef {
                path: path.clone(),
                sha256: sha256_hex(&bytes),
            },
            product,
        )),
    })
}

/// The normal-incidence values of a layer as given (before any flip): its explicit values, or
/// its spectra integrated per channel (clamped to [0, 1]; t + r ≤ 1 per channel and side,
/// [`glassdb_spectral::check_channel_balance`]) with their luminous values.
pub(crate) fn normal_values(
    layer: &Layer,
    integrator: &Integrator,
    glass: &str,
) -> Result<(NormalValues, Option<LuminousRecord>), RegistryError> {
    let (wavelength_nm, t, rf, rb) = match &layer.data {
        LayerData::Channels { t, rf, rb } => {
            let values = NormalValues {
                r0: *rf,
                t0: *t,
                r0_back: *rb,
            };
            return Ok((values, None));
        }
        LayerData::Spectral {
            wavelength_nm,
            t,
            rf,
            rb,
        } => (wavelength_nm, t, rf, rb),
    };
    let lum = |v: &[f64], what: &str| {
        glassdb_spectral::luminous_iso9050(wavelength_nm, v).map_err(|source| {
            RegistryError::Integration {
                glass: glass.to_string(),
                what: format!("luminous {what}"),
                source: Box::new(source),
            }
        })
    };
    let luminous = LuminousRecord {
        transmittance: lum(t, "transmittance")?,
        reflectance: lum(rf, "reflectance")?,
        reflectance_back: lum(rb, "back reflectance")?,
    };
    let channels = |v: &[f64], what: &str| {
        integrator
            .channels(wavelength_nm, v)
            .map(|c| c.map(|x| x.clamp(0.0, 1.0)))
            .map_err(|source| RegistryError::Integration {
                glass: glass.to_string(),
                what: what.to_string(),
                source: Box::new(source),
            })
    };
    let values = NormalValues {
        r0: channels(rf, "front reflectance")?,
        t0: channels(t, "transmittance")?,
        r0_back: channels(rb, "back reflectance")?,
    };
    // the check `glassdb spectral` applies to the same integrated values
    for (r, side) in [(values.r0, "front"), (values.r0_back, "back")] {
        glassdb_spectral::check_channel_balance(values.t0, r, side, wavelength_nm).map_err(
            |source| RegistryError::Spectral {
                glass: glass.to_string(),
                path: layer.label.clone().into(),
                source: Box::new(source),
            },
        )?;
    }
    Ok((values, Some(luminous)))
}
