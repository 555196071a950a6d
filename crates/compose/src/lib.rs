//! The glazing compositor (method.md, "Composite", eqs. 8–10): reflection passes (one per glass
//! plane) and a transmission pass, combined through an id + cos θ mask with each glass's r and
//! t from the registry, in linear light.
//!
//! - [`io`]: passes in (EXR, any compression `exr` reads, layer by name; PNG 8/16-bit, sRGB
//!   decoded), results out (EXR half/float with a chosen compression; PNG 8/16-bit sRGB).
//! - [`pixels`]: linear and encoded pixels as different types.
//! - [`lut`]: the per-id lookup tables built once from the registry.
//! - [`kernel`]: the per-pixel composite, in place, rayon over rows.
//! - [`sequence`]: frame patterns (`r.####.exr`) and frames in parallel.
//! - [`compose_frame`]: one image end to end, with per-stage timings for `--stats`.

pub mod error;
pub mod io;
pub mod kernel;
pub mod lut;
pub mod pixels;
pub mod sequence;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub use error::ComposeError;
use glassdb_mask::{MaskImage, MaskReadOptions};
pub use glassdb_registry::Side;
use rayon::prelude::*;

use crate::io::{OutputOptions, Pass, PassReadOptions, WrittenOutput};
use crate::kernel::{KernelCounts, KernelInput};
use crate::lut::GlassLut;

/// What to do with mask ids the registry does not have.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UnknownIds {
    /// Refuse, listing the ids and their pixel counts.
    #[default]
    Error,
    /// Leave those pixels as the transmission pass.
    Passthrough,
}

/// The input and output files of one image.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ComposeJob {
    /// Reflection passes; the k-th belongs to plane k of the mask.
    pub refl: Vec<PathBuf>,
    pub trans: PathBuf,
    pub mask: PathBuf,
    pub output: PathBuf,
}

impl ComposeJob {
    /// Every input file.
    pub fn inputs(&self) -> impl Iterator<Item = &Path> {
        self.refl
            .iter()
            .map(PathBuf::as_path)
            .chain([self.trans.as_path(), self.mask.as_path()])
    }
}

/// Settings shared by every frame.
#[derive(Debug, Clone)]
pub struct ComposeSettings {
    pub pass: PassReadOptions,
    pub mask: MaskReadOptions,
    /// Side of each plane that faces the camera; planes not listed show the front.
    pub plane_sides: BTreeMap<usize, Side>,
    pub unknown: UnknownIds,
    pub output: OutputOptions,
    /// The registry's name for messages (its path, or "the bundled catalog").
    pub registry_label: String,
    /// Files that must never be overwritten (e.g. the registry JSON).
    pub protected: Vec<PathBuf>,
}

impl Default for ComposeSettings {
    fn default() -> Self {
        ComposeSettings {
            pass: PassReadOptions::default(),
            mask: MaskReadOptions::default(),
            plane_sides: BTreeMap::new(),
            unknown: UnknownIds::Error,
            output: OutputOptions::default(),
            registry_label: "the registry".into(),
            protected: Vec::new(),
        }
    }
}

/// Wall-clock time of each stage.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StageTimings {
    /// Reading and decoding every input (in parallel).
    pub decode: Duration,
    /// Checks and the per-pixel composite.
    pub compose: Duration,
    /// Encoding and writing the output.
    pub encode: Duration,
}

impl StageTimings {
    pub fn total(&self) -> Duration {
        self.decode + self.compose + self.encode
    }
}

/// What one image's composite did (for `--stats` and messages).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameReport {
    pub output: WrittenOutput,
    pub width: u32,
    pub height: u32,
    pub timings: StageTimings,
    /// Glass pixels per id (id 0 not counted).
    pub id_counts: BTreeMap<u16, u64>,
    /// cos θ range over glass pixels.
    pub cos_range: Option<(f64, f64)>,
    pub counts: KernelCounts,
    /// Number of reflection passes (planes).
    pub planes: usize,
}

impl FrameReport {
    /// Megapixels per second over the whole run.
    pub fn megapixels_per_second(&self) -> f64 {
        let s = self.timings.total().as_secs_f64();
        if s > 0.0 {
            f64::from(self.width) * f64::from(self.height) / 1e6 / s
        } else {
            0.0
        }
    }
}

/// Plane sides from a `planes.json` written by `glassdb mirror` (`planes[k].eye_side`), read
/// by the scene crate's own reader (format and plane order checked).
pub fn sides_from_planes_json(
    path: &Path,
    passes: usize,
) -> Result<BTreeMap<usize, Side>, ComposeError> {
    let file = glassdb_scene::PlanesFile::load(path)?;
    if file.planes.len() != passes {
        return Err(ComposeError::PlaneCountMismatch {
            planes_file: path.to_path_buf(),
            planes: file.planes.len(),
            passes,
        });
    }
    Ok(file.planes.iter().map(|p| (p.index, p.eye_side)).collect())
}

/// Reads the inputs of one image in parallel.
fn decode_inputs(
    job: &ComposeJob,
    settings: &ComposeSettings,
) -> Result<(Pass, Vec<Pass>, MaskImage), ComposeError> {
    let (trans, (mask, refl)) = rayon::join(
        || io::read_pass(&job.trans, &settings.pass),
        || {
            rayon::join(
                || glassdb_mask::read_mask(&job.mask, &settings.mask),
                || {
                    job.refl
                        .par_iter()
                        .map(|p| io::read_pass(p, &settings.pass))
                        .collect::<Result<Vec<_>, _>>()
                },
            )
        },
    );
    Ok((trans?, refl?, mask?))
}

/// Checks sizes, ids and planes before compositing.
fn check_inputs(
    job: &ComposeJob,
    settings: &ComposeSettings,
    lut: &GlassLut,
    trans: &Pass,
    refl: &[Pass],
    mask: &MaskImage,
    id_counts: &BTreeMap<u16, u64>,
) -> Result<(), ComposeError> {
    let size = |i: &pixels::LinearImage| (i.width, i.height);
    let t_size = size(&trans.image);
    for (p, path) in refl.iter().zip(&job.refl) {
        if size(&p.image) != t_size {
            return Err(ComposeError::SizeMismatch {
                a: job.trans.clone(),
                a_size: t_size,
                b: path.clone(),
                b_size: size(&p.image),
            });
        }
    }
    if (mask.width, mask.height) != t_size {
        return Err(ComposeError::SizeMismatch {
            a: job.trans.clone(),
            a_size: t_size,
            b: job.mask.clone(),
            b_size: (mask.width, mask.height),
        });
    }
    let unknown: Vec<(u16, u64)> = id_counts
        .iter()
        .filter(|(id, _)| !lut.contains(**id))
        .map(|(a, b)| (*a, *b))
        .collect();
    if !unknown.is_empty() && settings.unknown == UnknownIds::Error {
        return Err(ComposeError::UnknownIds {
            mask: job.mask.clone(),
            registry: settings.registry_label.clone(),
            none_known: unknown.len() == id_counts.len(),
            ids: unknown,
        });
    }
    if mask.max_plane() as usize >= refl.len() {
        let mut per_plane: BTreeMap<u16, u64> = BTreeMap::new();
        for (&id, &p) in mask.id.iter().zip(&mask.plane) {
            if id != 0 && p as usize >= refl.len() {
                *per_plane.entry(p).or_default() += 1;
            }
        }
        if let Some((&plane, &pixels)) = per_plane.iter().next() {
            return Err(ComposeError::PlaneWithoutPass {
                mask: job.mask.clone(),
                plane,
                pixels,
                passes: refl.len(),
            });
        }
    }
    Ok(())
}

/// Composites one image end to end: decode (all inputs in parallel), check, composite in
/// place, encode and write atomically. The output may not be one of the inputs.
pub fn compose_frame(
    job: &ComposeJob,
    settings: &ComposeSettings,
    lut: &GlassLut,
) -> Result<FrameReport, ComposeError> {
    if job.refl.is_empty() {
        return Err(ComposeError::NoReflectionPass);
    }
    io::output_format(&job.output)?;
    glassdb_io::refuse_input_as_output(
        &job.output,
        job.inputs()
            .chain(settings.protected.iter().map(PathBuf::as_path)),
    )?;

    let t0 = Instant::now();
    let (mut trans, refl, mask) = decode_inputs(job, settings)?;
    let decode = t0.elapsed();

    let t1 = Instant::now();
    let id_counts = mask.id_pixel_counts();
    check_inputs(job, settings, lut, &trans, &refl, &mask, &id_counts)?;
    let plane_sides: Vec<Side> = (0..refl.len())
        .map(|k| settings.plane_sides.get(&k).copied().unwrap_or(Side::Front))
        .collect();
    let refl_planes: Vec<[&[f32]; 3]> = refl
        .iter()
        .map(|p| {
            let [r, g, b] = &p.image.rgb;
            [r.as_slice(), g.as_slice(), b.as_slice()]
        })
        .collect();
    let [r, g, b] = &mut trans.image.rgb;
    let input = KernelInput::new([r, g, b], &refl_planes, &plane_sides, &mask, lut)?;
    let counts = kernel::compose_in_place(input);
    let cos_range = mask.cos_theta_range();
    let (width, height) = (trans.image.width, trans.image.height);
    drop(refl_planes);
    drop(refl);
    drop(mask);
    let compose = t1.elapsed();

    let t2 = Instant::now();
    let output = io::write_output(&job.output, trans.image, &trans.source, &settings.output)?;
    let encode = t2.elapsed();

    Ok(FrameReport {
        output,
        width,
        height,
        timings: StageTimings {
            decode,
            compose,
            encode,
        },
        id_counts,
        cos_range,
        counts,
        planes: job.refl.len(),
    })
}

#[cfg(test)]
mod tests;
