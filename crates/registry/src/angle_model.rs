//! Angle tables of a glass: its physical model (from the stack engine's single-layer models,
//! `glassdb_stack::model`) sampled at 0–90° per wavelength or per channel and integrated in
//! every table's colour basis, and a measured angle table replacing it up to its last angle,
//! continued by the model to grazing incidence (`docs/registry.md`).

use glassdb_fit::AngleSamples;
use glassdb_spectral::Integrator;
use glassdb_stack::measured::model_angles_deg;
use glassdb_stack::{Application, Combination, EvalOptions, Layer, Stack};

use crate::catalog::LayerSpec;
use crate::catalog_files::{CatalogFiles, sha256_hex};
use crate::normal::NormalValues;
use crate::{FileRef, RegistryError};

/// The physical model sampled every degree from 0° to 90°: per angle, per channel, front
/// reflectance, transmittance and back reflectance (row 0: the normal values).
pub(crate) struct ModelTables {
    pub angles: Vec<f64>,
    pub rf: Vec<[f64; 3]>,
    pub t: Vec<[f64; 3]>,
    pub rb: Vec<[f64; 3]>,
}

impl ModelTables {
    /// Samples one layer's model in each integrator's basis: per wavelength (then integrated)
    /// when `application` says so and the layer has a spectrum, else per channel from its
    /// normal values. Row 0 holds `normals` (one per integrator) exactly.
    pub(crate) fn sample(
        layer: &Layer,
        normals: &[NormalValues],
        application: Application,
        integrators: &[Integrator],
        glass: &str,
    ) -> Result<Vec<ModelTables>, RegistryError> {
        let stack_err = |source| RegistryError::Unit {
            path: Default::default(),
            line: 0,
            glass: glass.to_string(),
            source: Box::new(source),
        };
        let stack = Stack::new(vec![glassdb_stack::Element::Layer(Box::new(layer.clone()))])
            .map_err(stack_err)?;
        let angles = model_angles_deg();
        let opts = EvalOptions {
            application,
            combination: Combination::PerWavelength,
        };
        let eval = stack
            .evaluate(&angles, integrators, false, opts)
            .map_err(|e| integration_error(e, glass))?;
        Ok(eval
            .colour
            .into_iter()
            .zip(normals)
            .map(|(per_angle, normal)| {
                let mut tables = ModelTables {
                    angles: angles.clone(),
                    rf: per_angle.iter().map(|o| o.rf).collect(),
                    t: per_angle.iter().map(|o| o.t).collect(),
                    rb: per_angle.iter().map(|o| o.rb).collect(),
                };
                tables.rf[0] = normal.r0;
                tables.t[0] = normal.t0;
                tables.rb[0] = normal.r0_back;
                tables
            })
            .collect())
    }

    /// One channel of one table as fit samples.
    pub(crate) fn samples(&self, table: &[[f64; 3]], channel: usize) -> AngleSamples {
        AngleSamples {
            angle_deg: self.angles.clone(),
            value: table.iter().map(|v| v[channel]).collect(),
        }
    }
}

/// A stack engine's integration error as the registry reports it (the glass and what was
/// integrated; other stack errors keep their own message).
pub(crate) fn integration_error(e: glassdb_stack::StackError, glass: &str) -> RegistryError {
    match e {
        glassdb_stack::StackError::Integration { what, source } => RegistryError::Integration {
            glass: glass.to_string(),
            what,
            source,
        },
        other => RegistryError::Unit {
            path: Default::default(),
            line: 0,
            glass: glass.to_string(),
            source: Box::new(other),
        },
    }
}

/// A measured angle table of a glass: its front R and T samples (either may be absent).
pub(crate) struct MeasuredTable {
    pub reflectance: Option<AngleSamples>,
    pub transmittance: Option<AngleSamples>,
    /// The largest measured angle.
    pub max_angle_deg: f64,
    pub file: FileRef,
}

/// Reads the catalog's angle table of a layer (none when it names none): the file's only
/// glass, or the one named `name`.
pub(crate) fn read_measured_table(
    spec: &LayerSpec,
    name: &str,
    files: &CatalogFiles<'_>,
    glass: &str,
) -> Result<Option<MeasuredTable>, RegistryError> {
    let Some((rel, percent)) = &spec.angles else {
        return Ok(None);
    };
    let (full, bytes) = files.read(rel, glass, glassdb_fit::ANGLE_TABLE_FILE)?;
    let stem = full
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "glass".into());
    let tables =
        glassdb_fit::parse_angle_table(&bytes, &full, &stem, *percent).map_err(|source| {
            RegistryError::AngleTable {
                glass: glass.to_string(),
                path: full.clone(),
                source: Box::new(source),
            }
        })?;
    let names: Vec<String> = tables.iter().map(|t| t.name.clone()).collect();
    let table = if tables.len() == 1 {
        tables.into_iter().next()
    } else {
        tables.into_iter().find(|t| t.name == name)
    };
    let table = table.ok_or_else(|| RegistryError::AngleTableGlass {
        glass: glass.to_string(),
        path: full.clone(),
        detail: if names.is_empty() {
            "holds no glass".to_string()
        } else {
            format!(
                "holds several glasses ({}) and none is named \"{name}\"",
                names.join(", "),
            )
        },
    })?;
    let mut max_angle_deg: f64 = 0.0;
    for s in [&table.reflectance, &table.transmittance]
        .into_iter()
        .flatten()
    {
        max_angle_deg = max_angle_deg.max(s.angle_deg.iter().copied().fold(0.0, f64::max));
    }
    Ok(Some(MeasuredTable {
        reflectance: table.reflectance,
        transmittance: table.transmittance,
        max_angle_deg,
        file: FileRef {
            path: rel.clone(),
            sha256: sha256_hex(&bytes),
        },
    }))
}
