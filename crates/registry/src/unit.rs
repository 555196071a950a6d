//! Units in the registry: a catalog entry with `layers` built by the stack engine into a glass
//! record per table (system curves, as for any glass, plus the [`UnitRecord`]: build-up,
//! per-layer values, per-pane-group reflectance curves and depths).

use std::path::{Path, PathBuf};

use glassdb_fit::{AngleSamples, Quantity};
use glassdb_spectral::{Integrator, WindowMethod, WindowWeights};
use glassdb_stack::measured::{MeasuredRatio, RatioFit, cos_deg, model_angles_deg};
use glassdb_stack::{
    Combination, Element, EvalOptions, Evaluation, Gap, Layer, LayerData, Optics, Stack, StackError,
};

use crate::angle_model::{ModelTables, integration_error, read_measured_table};
use crate::build::{BuildContext, BuildOptions, build_glass, glass_record, oriented};
use crate::catalog::{ElementSpec, GlassSpec, LayerSpec, NormalSource};
use crate::catalog_files::CatalogFiles;
use crate::curves::{fit_glass_curves, fit_share_curves};
use crate::normal::{CatalogLayer, normal_values, read_layer};
use crate::unit_record::{
    Absorptance, GapRecord, PaneGroupRecord, SystemValues, UnitElement, UnitLayerRecord, UnitRecord,
};
use crate::{AngleModelRecord, GlassRecord, LuminousRecord, Provenance, RegistryError};

/// Wavelengths (nm) of a grey layer (one given by its angle table alone): 300–2500 nm in 10 nm
/// steps, the same value at each.
const GREY_STEP_NM: f64 = 10.0;

/// A layer of a unit read from the catalog, with what its record needs.
struct UnitLayer {
    read: CatalogLayer,
    angles_file: Option<crate::FileRef>,
    model_kind: String,
}

/// The glass label of a unit's element in messages.
fn element_label(glass: &str, position: usize, line: usize) -> String {
    if line == 0 {
        format!("{glass}, element {position}")
    } else {
        format!("{glass}, element {position} of `layers` (catalog line {line})")
    }
}

/// Reads one layer of a unit: its spectral file or explicit values, or a grey layer from its
/// angle table alone; with a table, the table's ratio curves replace the model for Rf and T.
fn read_unit_layer(
    spec: &LayerSpec,
    unit_name: &str,
    files: &CatalogFiles<'_>,
    label: &str,
    opts: &BuildOptions,
) -> Result<UnitLayer, RegistryError> {
    let measured = read_measured_table(spec, unit_name, files, label)?;
    let mut read = match (&spec.normal, &measured) {
        (NormalSource::AngleTable, Some(m)) => grey_layer(spec, m, label)?,
        _ => read_layer(spec, files, label)?,
    };
    let mut model_kind = read.layer.model.name().to_string();
    if let Some(m) = &measured {
        // the model's broadband curve continues the table beyond its last angle
        let mut plain = read.layer.clone();
        plain.flipped = false;
        let (model_r, model_t) =
            broadband_model(&plain).map_err(|e| integration_error(e, label))?;
        let ratio = MeasuredRatio::fit(
            m.reflectance.as_ref(),
            m.transmittance.as_ref(),
            &model_r,
            &model_t,
            RatioFit {
                tol: opts.fit_tol,
                max_degree: opts.max_degree,
            },
            label,
        )
        .map_err(|e| match e {
            StackError::Fit { curve, source, .. } => RegistryError::Fit {
                glass: label.to_string(),
                curve: format!("measured {curve}"),
                source,
            },
            other => integration_error(other, label),
        })?;
        read.layer.measured = Some(ratio);
        model_kind = "measured".into();
    }
    Ok(UnitLayer {
        read,
        angles_file: measured.map(|m| m.file),
        model_kind,
    })
}

/// A grey layer: the table's 0° R and T at every wavelength of 300–2500 nm.
fn grey_layer(
    spec: &LayerSpec,
    m: &crate::angle_model::MeasuredTable,
    label: &str,
) -> Result<CatalogLayer, RegistryError> {
    let at_zero = |s: &Option<AngleSamples>, what: &str| {
        s.as_ref()
            .and_then(|s| {
                s.angle_deg
                    .iter()
                    .position(|&a| a == 0.0)
                    .map(|i| s.value[i])
            })
            .ok_or_else(|| RegistryError::AngleTableGlass {
                glass: label.to_string(),
                path: PathBuf::from(&m.file.path),
                detail: format!(
                    "a layer given by its angle table alone needs {what} at 0° (the layer's normal value)"
                ),
            })
    };
    let r0 = at_zero(&m.reflectance, "R")?;
    let t0 = at_zero(&m.transmittance, "T")?;
    let n = ((2500.0 - 300.0) / GREY_STEP_NM).round() as usize + 1;
    let wavelength_nm: Vec<f64> = (0..n).map(|i| 300.0 + GREY_STEP_NM * i as f64).collect();
    let layer = Layer::from_spectra(
        &m.file.path,
        wavelength_nm,
        vec![t0; n],
        vec![r0; n],
        vec![r0; n],
        None,
        &crate::normal::layer_options(spec),
    )
    .map_err(|e| RegistryError::SpectralContent {
        glass: label.to_string(),
        path: PathBuf::from(&m.file.path),
        detail: e.to_string(),
    })?;
    Ok(CatalogLayer {
        layer,
        source: None,
    })
}

/// The layer's model at 0–90° (1° steps) as one broadband value of Rf and T: the WINDOW
/// photopic average of a spectral layer, channel G of a channel layer.
fn broadband_model(layer: &Layer) -> Result<(Vec<f64>, Vec<f64>), StackError> {
    let angles = model_angles_deg();
    let weights = match &layer.data {
        LayerData::Spectral { wavelength_nm, .. } => Some(
            WindowWeights::new(WindowMethod::Photopic, wavelength_nm).map_err(|source| {
                StackError::Integration {
                    what: format!("photopic average of layer {}", layer.label),
                    source: Box::new(source),
                }
            })?,
        ),
        LayerData::Channels { .. } => None,
    };
    let average = |v: &[f64]| match &weights {
        Some(w) => w.average(v).unwrap_or(0.0),
        None => v[1],
    };
    let (mut r, mut t) = (Vec::new(), Vec::new());
    for a in angles {
        let v = layer.values_at(cos_deg(a));
        r.push(average(&v.rf));
        t.push(average(&v.t));
    }
    Ok((r, t))
}

/// The unit's records, one per integrator.
pub(crate) fn build_unit(
    spec: &GlassSpec,
    elements: &[ElementSpec],
    ctx: &BuildContext<'_>,
) -> Result<Vec<GlassRecord>, RegistryError> {
    let (files, integrators, opts) = (&ctx.files, ctx.integrators, ctx.opts);
    let unit = UnitBuild::read(spec, elements, files, opts)?;
    if unit.layers.len() == 1 {
        let (_, l, unit_layer) = &unit.layers[0];
        return one_layer_unit(spec, l, unit_layer, &unit.stack, ctx);
    }
    let angles = model_angles_deg();
    let eval_opts = EvalOptions {
        application: opts.application,
        combination: Combination::PerWavelength,
    };
    let evaluate = |angles: &[f64], integrators: &[Integrator], window: bool| {
        unit.stack
            .evaluate(angles, integrators, window, eval_opts)
            .map_err(|e| match e {
                StackError::Integration { .. } => integration_error(e, &unit.glass),
                other => unit.error(other),
            })
    };
    // the colours at every angle; WINDOW's values (recorded at normal incidence) at 0° only
    let eval = evaluate(&angles, integrators, false)?;
    let at_normal = evaluate(&[0.0], &[], true)?;
    let luminous = unit.luminous()?;
    integrators
        .iter()
        .enumerate()
        .map(|(k, integrator)| unit.record(k, integrator, &eval, &at_normal, luminous, opts))
        .collect()
}

/// A unit of several layers being built: its glass, its layers as read (with their position
/// among the elements) and its validated stack.
struct UnitBuild<'a> {
    spec: &'a GlassSpec,
    elements: &'a [ElementSpec],
    /// The glass's label in messages.
    glass: String,
    catalog: PathBuf,
    layers: Vec<(usize, &'a LayerSpec, UnitLayer)>,
    stack: Stack,
}

impl<'a> UnitBuild<'a> {
    /// Reads the unit's layers and builds its stack.
    fn read(
        spec: &'a GlassSpec,
        elements: &'a [ElementSpec],
        files: &CatalogFiles<'_>,
        opts: &BuildOptions,
    ) -> Result<Self, RegistryError> {
        let glass = format!("{} (\"{}\")", spec.id, spec.name);
        let mut layers: Vec<(usize, &LayerSpec, UnitLayer)> = Vec::new();
        let mut stack_elements = Vec::with_capacity(elements.len());
        for (i, e) in elements.iter().enumerate() {
            match e {
                ElementSpec::Layer(l) => {
                    let label = element_label(&glass, i + 1, l.line);
                    let unit_layer = read_unit_layer(l, &spec.name, files, &label, opts)?;
                    stack_elements.push(Element::Layer(Box::new(unit_layer.read.layer.clone())));
                    layers.push((i, l, unit_layer));
                }
                ElementSpec::Gap {
                    thickness_mm, gas, ..
                } => stack_elements.push(Element::Gap(Gap {
                    thickness_mm: *thickness_mm,
                    gas: *gas,
                })),
            }
        }
        let catalog = files.catalog_path.to_path_buf();
        let stack = Stack::new(stack_elements)
            .map_err(|e| unit_error(e, spec, elements, &catalog, &glass))?;
        Ok(UnitBuild {
            spec,
            elements,
            glass,
            catalog,
            layers,
            stack,
        })
    }

    /// A stack error as the registry's, on the catalog line of the element it names.
    fn error(&self, e: StackError) -> RegistryError {
        unit_error(e, self.spec, self.elements, &self.catalog, &self.glass)
    }

    /// The unit's luminous values (ISO 9050) at normal incidence, when its layers have spectra.
    fn luminous(&self) -> Result<Option<LuminousRecord>, RegistryError> {
        let Some(s) = self.stack.spectra_at(0.0).map_err(|e| self.error(e))? else {
            return Ok(None);
        };
        let lum = |v: &[f64], what: &str| {
            glassdb_spectral::luminous_iso9050(&s.wavelength_nm, v).map_err(|source| {
                RegistryError::Integration {
                    glass: self.glass.clone(),
                    what: format!("luminous {what}"),
                    source: Box::new(source),
                }
            })
        };
        Ok(Some(LuminousRecord {
            transmittance: lum(&s.optics.t, "transmittance")?,
            reflectance: lum(&s.optics.rf, "reflectance")?,
            reflectance_back: lum(&s.optics.rb, "back reflectance")?,
        }))
    }

    /// The unit's record in the basis of `integrator`, the `k`-th of `eval`'s.
    fn record(
        &self,
        k: usize,
        integrator: &Integrator,
        eval: &Evaluation,
        at_normal: &Evaluation,
        luminous: Option<LuminousRecord>,
        opts: &BuildOptions,
    ) -> Result<GlassRecord, RegistryError> {
        let per_angle = &eval.colour[k];
        let row = |f: &dyn Fn(&Optics<[f64; 3]>) -> [f64; 3]| -> Vec<[f64; 3]> {
            per_angle.iter().map(f).collect()
        };
        let normal = crate::normal::NormalValues {
            r0: clamp_unit(per_angle[0].rf),
            t0: clamp_unit(per_angle[0].t),
            r0_back: clamp_unit(per_angle[0].rb),
        };
        let mut tables = ModelTables {
            angles: eval.angles_deg.clone(),
            rf: row(&|o| o.rf),
            t: row(&|o| o.t),
            rb: row(&|o| o.rb),
        };
        tables.rf[0] = normal.r0;
        tables.t[0] = normal.t0;
        tables.rb[0] = normal.r0_back;
        let curves = fit_glass_curves(&normal, &tables, None, opts, &self.glass)?;
        let groups = self.group_records(per_angle, &tables, opts)?;
        let unit_elements = self.element_records(integrator, at_normal)?;
        let angle_model = AngleModelRecord {
            kind: "unit".into(),
            applied: opts.application.name().to_string(),
            ior: None,
            measured_max_angle_deg: None,
            continued_by: None,
            chosen_by: format!(
                "{} layers combined {}",
                self.layers.len(),
                eval.combination.name()
            ),
        };
        let mut record = glass_record(
            self.spec,
            &normal,
            curves,
            luminous,
            angle_model,
            Provenance::default(),
        );
        let system = |o: Option<&Vec<Optics<f64>>>| {
            o.map(|v| SystemValues {
                transmittance: v[0].t,
                reflectance: v[0].rf,
                reflectance_back: v[0].rb,
            })
        };
        record.unit = Some(UnitRecord {
            elements: unit_elements,
            groups,
            thickness_mm: self.stack.thickness_mm(),
            combined: eval.combination.name().to_string(),
            photopic: system(at_normal.photopic.as_ref()),
            solar: system(at_normal.solar.as_ref()),
        });
        Ok(record)
    }

    /// Each pane group's share of the reflectance, front and back, with its fitted curves.
    fn group_records(
        &self,
        per_angle: &[Optics<[f64; 3]>],
        tables: &ModelTables,
        opts: &BuildOptions,
    ) -> Result<Vec<PaneGroupRecord>, RegistryError> {
        let n_groups = self.stack.groups().len();
        let row = |f: &dyn Fn(&Optics<[f64; 3]>) -> [f64; 3]| -> Vec<[f64; 3]> {
            per_angle.iter().map(f).collect()
        };
        let shares_front = stored_shares(
            (0..n_groups).map(|g| row(&|o| o.share.front[g])).collect(),
            &tables.rf,
        );
        let shares_back = stored_shares(
            (0..n_groups).map(|g| row(&|o| o.share.back[g])).collect(),
            &tables.rb,
        );
        let mut groups = Vec::with_capacity(n_groups);
        for (g, group) in self.stack.groups().iter().enumerate() {
            let share = |front: bool| -> Result<([f64; 3], [crate::AngleCurve; 3]), RegistryError> {
                let table = if front {
                    shares_front[g].clone()
                } else {
                    shares_back[g].clone()
                };
                // the group facing the light reflects everything at grazing; the others nothing
                let facing = if front { g == 0 } else { g + 1 == n_groups };
                let quantity = if facing {
                    Quantity::Reflectance
                } else {
                    Quantity::Transmittance
                };
                let name = format!(
                    "reflectance share of pane group {} ({})",
                    g + 1,
                    if front { "front" } else { "back" }
                );
                let curves =
                    fit_share_curves(table[0], tables, &table, quantity, opts, &self.glass, &name)?;
                Ok((table[0], curves))
            };
            let (r0, c_r) = share(true)?;
            let (r0_back, c_r_back) = share(false)?;
            groups.push(PaneGroupRecord {
                layers: group.layers.clone().collect(),
                thickness_mm: group.thickness_mm,
                depth_mm: group.depth_mm,
                depth_back_mm: group.depth_back_mm,
                r0,
                c_r,
                r0_back,
                c_r_back,
            });
        }
        Ok(groups)
    }

    /// The build-up as recorded: gaps, and each layer's record in `integrator`'s basis with
    /// its solar absorptance in the unit.
    fn element_records(
        &self,
        integrator: &Integrator,
        at_normal: &Evaluation,
    ) -> Result<Vec<UnitElement>, RegistryError> {
        let mut unit_elements = Vec::with_capacity(self.elements.len());
        let mut next_layer = self.layers.iter().enumerate().peekable();
        for (i, e) in self.elements.iter().enumerate() {
            match e {
                ElementSpec::Gap {
                    thickness_mm, gas, ..
                } => unit_elements.push(UnitElement::Gap(GapRecord {
                    thickness_mm: *thickness_mm,
                    gas: *gas,
                })),
                ElementSpec::Layer(_) => {
                    let (index, (_, l, unit_layer)) = next_layer.next().expect("one per layer");
                    debug_assert_eq!(self.layers[index].0, i);
                    let absorptance = at_normal.solar.as_ref().map(|s| Absorptance {
                        front: s[0].absorptance.front[index],
                        back: s[0].absorptance.back[index],
                    });
                    unit_elements.push(UnitElement::Layer(Box::new(layer_record(
                        l,
                        unit_layer,
                        self.stack.layers().nth(index).expect("layer").thickness_mm,
                        integrator,
                        absorptance,
                        &self.glass,
                    )?)));
                }
            }
        }
        Ok(unit_elements)
    }
}

/// A stack error as the registry's, on the catalog line of the element it names (the unit's
/// line when it names none).
fn unit_error(
    e: StackError,
    spec: &GlassSpec,
    elements: &[ElementSpec],
    catalog: &Path,
    glass: &str,
) -> RegistryError {
    let line = e
        .position()
        .and_then(|p| elements.get(p - 1))
        .map_or(spec.line, ElementSpec::line);
    RegistryError::Unit {
        path: catalog.to_path_buf(),
        line,
        glass: glass.to_string(),
        source: Box::new(e),
    }
}

/// Each channel clamped to 0–1.
fn clamp_unit(v: [f64; 3]) -> [f64; 3] {
    v.map(|x| x.clamp(0.0, 1.0))
}

/// One layer's record in its unit (in `integrator`'s basis, as it faces in the unit).
fn layer_record(
    spec: &LayerSpec,
    unit_layer: &UnitLayer,
    thickness_mm: Option<f64>,
    integrator: &Integrator,
    absorptance: Option<Absorptance>,
    glass: &str,
) -> Result<UnitLayerRecord, RegistryError> {
    let layer = &unit_layer.read.layer;
    let (normal, mut luminous) = normal_values(layer, integrator, glass)?;
    let normal = oriented(normal, spec.flip);
    if spec.flip
        && let Some(l) = &mut luminous
    {
        std::mem::swap(&mut l.reflectance, &mut l.reflectance_back);
    }
    Ok(UnitLayerRecord {
        flipped: spec.flip,
        thickness_mm,
        model: unit_layer.model_kind.clone(),
        model_chosen_by: layer.model_reason.clone(),
        r0: normal.r0,
        t0: normal.t0,
        r0_back: normal.r0_back,
        luminous,
        absorptance,
        provenance: Provenance {
            catalog: None,
            spectral: unit_layer.read.source.as_ref().map(|s| s.0.clone()),
            angles: unit_layer.angles_file.clone(),
            product: unit_layer.read.source.as_ref().map(|s| s.1.clone()),
        },
    })
}

/// A unit of one layer: exactly the single glass's records (turned round when flipped), with
/// the build-up recorded and one pane group whose shares are the glass's reflectances.
fn one_layer_unit(
    spec: &GlassSpec,
    layer_spec: &LayerSpec,
    unit_layer: &UnitLayer,
    stack: &Stack,
    ctx: &BuildContext<'_>,
) -> Result<Vec<GlassRecord>, RegistryError> {
    let integrators = ctx.integrators;
    let mut single = layer_spec.clone();
    if let NormalSource::AngleTable = single.normal {
        let LayerData::Spectral { t, rf, rb, .. } = &unit_layer.read.layer.data else {
            unreachable!("a grey layer is spectral")
        };
        single.normal = NormalSource::Explicit {
            r0: [rf[0]; 3],
            t0: [t[0]; 3],
            r0_back: [rb[0]; 3],
        };
    }
    let glass = format!("{} (\"{}\")", spec.id, spec.name);
    let mut records = build_glass(spec, &single, ctx)?;
    let group = &stack.groups()[0];
    for (record, integrator) in records.iter_mut().zip(integrators) {
        let layer = layer_record(
            layer_spec,
            unit_layer,
            stack.layers().next().and_then(|l| l.thickness_mm),
            integrator,
            None,
            &glass,
        )?;
        record.unit = Some(UnitRecord {
            elements: vec![UnitElement::Layer(Box::new(layer))],
            groups: vec![PaneGroupRecord {
                layers: vec![0],
                thickness_mm: group.thickness_mm,
                depth_mm: group.depth_mm,
                depth_back_mm: group.depth_back_mm,
                r0: record.r0,
                c_r: record.c_r.clone(),
                r0_back: record.r0_back,
                c_r_back: record.c_r_back.clone(),
            }],
            thickness_mm: stack.thickness_mm(),
            combined: Combination::PerWavelength.name().to_string(),
            photopic: None,
            solar: None,
        });
    }
    Ok(records)
}

/// How far a pane group's integrated share may stray outside [0, 1] and still be rounding:
/// the facing group's share is 1 at grazing (90°) and the others 0, reached through sums of
/// products that land just either side. In the bundled catalog under D65 the largest is
/// `1 + 2.9e-11` (green, glass 13, a triple unit); such a share is not a defect and is stored
/// as before lights (only the normal-incidence value clamped), so `data/registry.json` is
/// unchanged. A colour out of the space's gamut strays by orders of magnitude more: a bundled
/// unit's front group in sRGB red under LED-RGB1 is −1.8e-2 at every angle.
pub(crate) const SHARE_ROUNDING: f64 = 1e-9;

/// The pane groups' reflectance shares as the registry stores them (`[group][angle]`, per
/// channel). A channel can integrate negative: an out-of-gamut colour, e.g. a blue coating's
/// back reflectance in sRGB's red under the narrow-band LED-RGB1. A negative share is a real
/// defect of the stored values: the compositor would subtract light in that channel, and a
/// curve fitted as a ratio to a clamped `r0` of 0 is meaningless. So in a channel where some
/// group's share leaves [0, 1] by more than [`SHARE_ROUNDING`] at some angle, every angle's
/// shares are redrawn as the unit's reflectance there (`unit`, clamped to [0, 1] as every
/// stored value is) split between the groups as their shares of all three channels together
/// split it, so that the shares stay non-negative and smooth and still sum to the unit's
/// reflectance (eq. 6). Every other channel is kept bit for bit, its normal-incidence value
/// clamped to [0, 1] as every stored `r0` is. Under broad lights (the CIE daylights, A) no
/// bundled unit strays beyond rounding, so their tables are what they were before lights.
fn stored_shares(mut shares: Vec<Vec<[f64; 3]>>, unit: &[[f64; 3]]) -> Vec<Vec<[f64; 3]>> {
    let outside = |v: f64| !(-SHARE_ROUNDING..=1.0 + SHARE_ROUNDING).contains(&v);
    for c in 0..3 {
        if !shares.iter().any(|s| s.iter().any(|v| outside(v[c]))) {
            continue;
        }
        for (a, total) in unit.iter().enumerate() {
            let target = total[c].clamp(0.0, 1.0);
            let weights: Vec<f64> = shares.iter().map(|s| s[a].iter().sum()).collect();
            let sum: f64 = weights.iter().sum();
            let clamped: Vec<f64> = shares.iter().map(|s| s[a][c].clamp(0.0, 1.0)).collect();
            let clamped_sum: f64 = clamped.iter().sum();
            for (k, s) in shares.iter_mut().enumerate() {
                s[a][c] = if sum > 0.0 && weights.iter().all(|&w| w >= 0.0) {
                    target * weights[k] / sum
                } else if clamped_sum > 0.0 {
                    target * clamped[k] / clamped_sum
                } else {
                    0.0
                };
            }
        }
    }
    for s in &mut shares {
        if let Some(normal) = s.first_mut() {
            *normal = clamp_unit(*normal);
        }
    }
    shares
}

#[cfg(test)]
mod share_tests {
    use super::stored_shares;

    #[test]
    fn rounding_outside_unit_interval_keeps_the_shares() {
        // grazing: the facing group's share a rounding error above 1 in blue
        let shares = vec![
            vec![[0.04, 0.05, 0.06], [1.0, 1.0, 1.0 + 2e-16]],
            vec![[0.03, 0.035, 0.02], [0.0, 0.0, -1e-17]],
        ];
        let unit = [[0.07, 0.085, 0.08], [1.0, 1.0, 1.0]];
        let stored = stored_shares(shares.clone(), &unit);
        assert_eq!(stored, shares);
    }

    #[test]
    fn negative_share_is_redistributed_in_its_channel_only() {
        // red integrates negative for group 2 (out of gamut): red is redrawn, green and blue kept
        let shares = vec![
            vec![[0.05, 0.05, 0.06], [0.5, 0.4, 0.4]],
            vec![[-0.01, 0.02, 0.09], [0.1, 0.1, 0.2]],
        ];
        let unit = [[0.04, 0.07, 0.15], [0.6, 0.5, 0.6]];
        let stored = stored_shares(shares.clone(), &unit);
        for (g, s) in stored.iter().enumerate() {
            for (a, v) in s.iter().enumerate() {
                assert!((0.0..=1.0).contains(&v[0]), "{v:?}");
                assert_eq!(v[1], shares[g][a][1]);
                assert_eq!(v[2], shares[g][a][2]);
            }
        }
        for (a, total) in unit.iter().enumerate() {
            let red: f64 = stored.iter().map(|s| s[a][0]).sum();
            assert!((red - total[0]).abs() < 1e-15, "{red} vs {}", total[0]);
        }
    }
}
