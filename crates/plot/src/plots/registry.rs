//! `glassdb plot registry`: r and t against angle for every glass of a scene's registry, one
//! colour per channel (r solid, t dashed, the back-face r thin where it differs).

use std::path::Path;

use glassdb_registry::{ColourBasis, GlassRecord, Registry, Side};

use super::{ANGLE_AXIS, curve_points};
use crate::PlotError;
use crate::chart::{CHANNEL_COLOURS, LegendCorner, Line, Panel, Stroke};
use crate::figure::{Cell, GridFigure};

const CHANNEL_NAMES: [&str; 3] = ["R", "G", "B"];

/// Options of the registry figure.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RegistryPlotOptions {
    /// Only these ids (empty: every glass).
    pub ids: Vec<u16>,
    /// The table to draw (`None`: the registry's default table).
    pub basis: Option<ColourBasis>,
}

fn glass_cell(g: &GlassRecord) -> Cell {
    let mut p = Panel::new(ANGLE_AXIS, "r, t (fraction)", (0.0, 90.0));
    p.title = Some(format!("id {}: {}", g.id, g.name));
    p.y_range = Some((0.0, 1.0));
    p.legend = Some(LegendCorner::Auto);
    let back_differs = {
        let probe = [1.0, 0.8, 0.5, 0.2];
        probe.iter().any(|&c| {
            let (rf, _) = g.eval(Side::Front, c);
            let (rb, _) = g.eval(Side::Back, c);
            rf.iter().zip(&rb).any(|(a, b)| (a - b).abs() > 1e-3)
        })
    };
    for (ch, &colour) in CHANNEL_COLOURS.iter().enumerate() {
        let name = CHANNEL_NAMES[ch];
        // Channel `ch` of r (`reflectance`) or else t, seen from `side`, against angle.
        let line = |label: String, side: Side, reflectance: bool| {
            let points = curve_points(|c| {
                let (r, t) = g.eval(side, c);
                if reflectance { r[ch] } else { t[ch] }
            });
            Line::new(Some(label), colour, Stroke::SOLID, points)
        };
        let r_label = format!("r {name} (r0 {:.4})", g.r0[ch]);
        p.lines.push(line(r_label, Side::Front, true));
        let t_label = format!("t {name} (t0 {:.4})", g.t0[ch]);
        p.lines.push(line(t_label, Side::Front, false).dashed());
        if back_differs {
            let back_label = format!("r back {name} ({:.4})", g.r0_back[ch]);
            p.lines.push(line(back_label, Side::Back, true).width(1));
        }
    }
    Cell {
        main: p,
        lower: None,
    }
}

/// The registry figure: one panel per glass.
pub fn registry_figure(path: &Path, opts: &RegistryPlotOptions) -> Result<GridFigure, PlotError> {
    let reg = Registry::from_json_file(path)?;
    registry_figure_of(&reg, &path.display().to_string(), opts)
}

/// The registry figure of a registry already loaded; `source` names it in the title.
pub fn registry_figure_of(
    reg: &Registry,
    source: &str,
    opts: &RegistryPlotOptions,
) -> Result<GridFigure, PlotError> {
    let table = reg.table_or_error(opts.basis, source)?;
    let mut glasses: Vec<&GlassRecord> = table.glasses.iter().collect();
    if !opts.ids.is_empty() {
        let missing: Vec<u16> = opts
            .ids
            .iter()
            .copied()
            .filter(|id| table.glass(*id).is_none())
            .collect();
        if !missing.is_empty() {
            let have: Vec<String> = table.glasses.iter().map(|g| g.id.to_string()).collect();
            return Err(PlotError::Input {
                path: source.into(),
                message: format!("no glass with id {missing:?} (ids: {})", have.join(", ")),
            });
        }
        glasses.retain(|g| opts.ids.contains(&g.id));
    }
    if glasses.is_empty() {
        return Err(PlotError::Input {
            path: source.into(),
            message: "holds no glass".into(),
        });
    }
    let cells: Vec<Cell> = glasses.iter().map(|g| glass_cell(g)).collect();
    let columns = cells.len().clamp(1, 3);
    let name = Path::new(source)
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let method = table.spectral.method.kind();
    let basis = table.basis();
    Ok(GridFigure {
        title: format!("Glass registry: {name}"),
        subtitle: Some(format!(
            "per channel R, G, B in {basis} (spectral method: {method}); r solid, t dashed, back-face r thin"
        )),
        cells,
        columns,
        cell_size: (600, 520),
    })
}
