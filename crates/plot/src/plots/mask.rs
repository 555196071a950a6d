//! `glassdb plot mask`: the reflectance (or transmittance) each glass pixel of a mask gets from
//! the registry, as a heat map with a colour bar: shows where grazing angles make glass
//! mirror-like.

use std::collections::BTreeMap;
use std::path::Path;

use glassdb_mask::{MaskImage, MaskReadOptions, read_mask};
use glassdb_registry::{ColourBasis, GlassRecord, Registry, Side};

use crate::PlotError;
use crate::heatmap::HeatMapFigure;

/// Which value of the glass the heat map shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MaskQuantity {
    /// r(θ).
    Reflectance,
    /// t(θ).
    Transmittance,
}

/// Which channel, or their Rec.709 luminance (0.2126 R + 0.7152 G + 0.0722 B).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MaskChannel {
    /// Luminance of the three channels.
    Luminance,
    /// The red channel.
    R,
    /// The green channel.
    G,
    /// The blue channel.
    B,
}

/// Options of the mask figure.
#[derive(Debug, Clone, PartialEq)]
pub struct MaskPlotOptions {
    /// r or t.
    pub quantity: MaskQuantity,
    /// Which channel.
    pub channel: MaskChannel,
    /// Planes whose glass is seen from its back face (`--side k=back`).
    pub back_planes: Vec<u16>,
    /// How to read the mask (EXR channel names, binary glass id, pixel cap).
    pub read: MaskReadOptions,
    /// The registry table to evaluate (`None`: its default table).
    pub basis: Option<ColourBasis>,
}

impl Default for MaskPlotOptions {
    fn default() -> Self {
        MaskPlotOptions {
            quantity: MaskQuantity::Reflectance,
            channel: MaskChannel::Luminance,
            back_planes: Vec::new(),
            read: MaskReadOptions::default(),
            basis: None,
        }
    }
}

/// cos θ of pixel `i` as the mask stores it (decoded by the mask's codec); `None` outside
/// the image.
pub fn pixel_cos(mask: &MaskImage, i: usize) -> Option<f64> {
    (i < mask.pixel_count()).then(|| mask.cos_theta_at(i))
}

fn pick(values: [f64; 3], channel: MaskChannel) -> f64 {
    match channel {
        MaskChannel::Luminance => 0.2126 * values[0] + 0.7152 * values[1] + 0.0722 * values[2],
        MaskChannel::R => values[0],
        MaskChannel::G => values[1],
        MaskChannel::B => values[2],
    }
}

/// Per-pixel values of a mask under a registry (`None` where there is no glass). An id the
/// registry lacks is an error listing every such id and its pixel count.
pub fn mask_values(
    mask: &MaskImage,
    reg: &Registry,
    mask_name: &str,
    opts: &MaskPlotOptions,
) -> Result<Vec<Option<f64>>, PlotError> {
    let n = mask.width as usize * mask.height as usize;
    if mask.id.len() != n || mask.plane.len() != n {
        return Err(PlotError::Input {
            path: mask_name.into(),
            message: "mask arrays do not match its size".into(),
        });
    }
    let mut unknown: BTreeMap<u16, usize> = BTreeMap::new();
    let mut lookup: BTreeMap<u16, &GlassRecord> = BTreeMap::new();
    for g in &reg.table_or_error(opts.basis, "the registry")?.glasses {
        lookup.insert(g.id, g);
    }
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let id = mask.id[i];
        if id == 0 {
            out.push(None);
            continue;
        }
        let Some(g) = lookup.get(&id) else {
            *unknown.entry(id).or_default() += 1;
            out.push(None);
            continue;
        };
        let cos = pixel_cos(mask, i).unwrap_or(1.0);
        if !cos.is_finite() {
            let (x, y) = (i % mask.width as usize, i / mask.width as usize);
            return Err(PlotError::Input {
                path: mask_name.into(),
                message: format!("pixel (x {x}, y {y}): cos θ is {cos}"),
            });
        }
        let side = if opts.back_planes.contains(&mask.plane[i]) {
            Side::Back
        } else {
            Side::Front
        };
        let (r, t) = g.eval(side, cos);
        out.push(Some(match opts.quantity {
            MaskQuantity::Reflectance => pick(r, opts.channel),
            MaskQuantity::Transmittance => pick(t, opts.channel),
        }));
    }
    if !unknown.is_empty() {
        let list: Vec<String> = unknown
            .iter()
            .map(|(id, c)| format!("id {id} ({c} pixels)"))
            .collect();
        return Err(PlotError::Input {
            path: mask_name.into(),
            message: format!("glass ids not in the registry: {}", list.join(", ")),
        });
    }
    Ok(out)
}

/// The mask figure: read the mask and registry, evaluate every glass pixel, draw the heat map.
pub fn mask_figure(
    mask_path: &Path,
    registry_path: &Path,
    opts: &MaskPlotOptions,
) -> Result<HeatMapFigure, PlotError> {
    let reg = Registry::from_json_file(registry_path)?;
    let mask = read_mask(mask_path, &opts.read)?;
    mask_figure_of(&mask, &reg, &mask_path.display().to_string(), opts)
}

/// The mask figure of a mask and registry already loaded.
pub fn mask_figure_of(
    mask: &MaskImage,
    reg: &Registry,
    mask_name: &str,
    opts: &MaskPlotOptions,
) -> Result<HeatMapFigure, PlotError> {
    let values = mask_values(mask, reg, mask_name, opts)?;
    let glass: Vec<f64> = values.iter().flatten().copied().collect();
    if glass.is_empty() {
        return Err(PlotError::Empty(format!("{mask_name} has no glass pixel")));
    }
    let (lo, hi) = glass
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let mean = glass.iter().sum::<f64>() / glass.len() as f64;
    let (qname, sym) = match opts.quantity {
        MaskQuantity::Reflectance => ("reflectance", "r"),
        MaskQuantity::Transmittance => ("transmittance", "t"),
    };
    let chan = match opts.channel {
        MaskChannel::Luminance => "luminance (Rec.709 weights)",
        MaskChannel::R => "channel R",
        MaskChannel::G => "channel G",
        MaskChannel::B => "channel B",
    };
    let name = Path::new(mask_name)
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let (w, h) = (mask.width.max(1) as f64, mask.height.max(1) as f64);
    // Map area about 760 px wide at most, 560 px high at most, keeping the image's aspect.
    let scale = (760.0 / w).min(560.0 / h);
    let fig_w = ((w * scale) as u32 + 56 + 20 + 130).max(520);
    let fig_h = ((h * scale) as u32 + 62 + 40 + 20).max(360);
    Ok(HeatMapFigure {
        title: format!("Glass {qname} per pixel: {name}"),
        subtitle: Some(format!(
            "{} glass pixels of {}×{}; {sym} from {lo:.4} to {hi:.4}, mean {mean:.4}; grey: no glass",
            glass.len(),
            mask.width,
            mask.height
        )),
        width: mask.width,
        height: mask.height,
        values,
        value_label: format!("{sym}(θ), {chan}"),
        range: None,
        max_vector_cells: 160,
        figure_size: (fig_w, fig_h),
    })
}
