//! `glassdb plot spectral`: τ(λ) and ρ(λ) over the visible range, the channel weights of the
//! chosen method (the colour-matching functions, or for the colorimetric method the effective
//! per-channel sensitivities) drawn beneath, and the resulting channel values marked.

use std::path::Path;

use glassdb_spectral::{
    IntegrationSettings, Integrator, Method, ReadOptions, SpectralData, read_spectral_file,
};

use crate::PlotError;
use crate::chart::{
    Annotation, CHANNEL_COLOURS, LegendCorner, Line, Marker, MarkerShape, Markers, Panel, Stroke,
};
use crate::figure::{Cell, GridFigure};
use crate::plots::fit::{REFLECTANCE_COLOUR, TRANSMITTANCE_COLOUR};

/// Options of the spectral figure.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SpectralPlotOptions {
    /// How values are integrated.
    pub settings: IntegrationSettings,
    /// How the file is read.
    pub read: ReadOptions,
}

/// Wavelength range drawn (nm): the visible range of the CIE tables.
pub const VISIBLE_NM: (f64, f64) = (360.0, 780.0);

/// The wavelength at which each channel's weights peak (where its value is marked).
fn channel_peaks(grid: &[f64], weights: &[[f64; 3]]) -> [f64; 3] {
    let mut peaks = [550.0; 3];
    for (c, peak) in peaks.iter_mut().enumerate() {
        let mut best = f64::NEG_INFINITY;
        for (&wl, w) in grid.iter().zip(weights) {
            if w[c] > best {
                best = w[c];
                *peak = wl;
            }
        }
    }
    peaks
}

/// The spectral figure of a file with the given method.
pub fn spectral_figure(path: &Path, opts: &SpectralPlotOptions) -> Result<GridFigure, PlotError> {
    let data = read_spectral_file(path, &opts.read)?;
    spectral_figure_of(&data, opts)
}

/// The spectral figure of spectra already read.
pub fn spectral_figure_of(
    data: &SpectralData,
    opts: &SpectralPlotOptions,
) -> Result<GridFigure, PlotError> {
    let integrator = Integrator::new(&opts.settings)?;
    let grid = integrator.grid_nm().to_vec();
    let weights = integrator.weights().to_vec();
    let peaks = channel_peaks(&grid, &weights);
    let luminous = matches!(opts.settings.method, Method::Luminous);
    let quantities = [
        (
            "τ",
            "transmittance",
            &data.transmittance,
            TRANSMITTANCE_COLOUR,
            MarkerShape::Triangle,
            false,
        ),
        (
            "ρ",
            "front reflectance",
            &data.reflectance_front,
            REFLECTANCE_COLOUR,
            MarkerShape::Circle,
            false,
        ),
        (
            "ρ back",
            "back reflectance",
            &data.reflectance_back,
            REFLECTANCE_COLOUR,
            MarkerShape::Square,
            true,
        ),
    ];
    let mut main = Panel::new("wavelength λ (nm)", "τ(λ), ρ(λ) (fraction)", VISIBLE_NM);
    main.title = Some(format!(
        "{} — {}",
        short_name(&data.source),
        opts.settings.method
    ));
    main.legend = Some(LegendCorner::Auto);
    let mut summary = Vec::new();
    for (sym, _name, values, colour, shape, dashed) in quantities {
        let Some(values) = values else { continue };
        let pts: Vec<(f64, f64)> = data
            .wavelength_nm
            .iter()
            .copied()
            .zip(values.iter().copied())
            .collect();
        let mut line = Line::new(Some(format!("{sym}(λ)")), colour, Stroke::SOLID, pts);
        if dashed {
            line = line.dashed();
        }
        main.lines.push(line);
        let rgb = integrator.channels(&data.wavelength_nm, values)?;
        let channels = if luminous { 1 } else { 3 };
        for c in 0..channels {
            let (x, ch_colour) = if luminous {
                (555.0, colour)
            } else {
                (peaks[c], CHANNEL_COLOURS[c])
            };
            let label = if luminous {
                format!("{sym}v = {:.4}", rgb[0])
            } else {
                format!("{sym} {} = {:.4}", ["R", "G", "B"][c], rgb[c])
            };
            let marker = Marker { shape, size: 6 };
            main.markers.push(Markers::new(
                Some(label),
                ch_colour,
                marker,
                vec![(x, rgb[c])],
            ));
            main.annotations.push(Annotation {
                x: x + 6.0,
                y: rgb[c],
                text: format!("{:.3}", rgb[c]),
                colour: ch_colour,
            });
        }
        summary.push(if luminous {
            format!("{sym}v {:.4}", rgb[0])
        } else {
            format!("{sym} ({:.4}, {:.4}, {:.4})", rgb[0], rgb[1], rgb[2])
        });
    }
    if main.lines.is_empty() {
        return Err(PlotError::Input {
            path: data.source.clone().into(),
            message: "has no τ or ρ spectrum".into(),
        });
    }
    let mut y_hi: f64 = 1.0;
    for m in &main.markers {
        for &(_, y) in &m.points {
            y_hi = y_hi.max(y + 0.02);
        }
    }
    main.y_range = Some((0.0, y_hi));

    let lower = weights_panel(opts, &grid, &weights);
    Ok(GridFigure {
        title: format!("Spectra: {}", short_name(&data.source)),
        subtitle: Some(summary.join("; ")),
        cells: vec![Cell {
            main,
            lower: Some((lower, 0.4)),
        }],
        columns: 1,
        cell_size: (900, 760),
    })
}

/// The lower panel: the method's channel weights over wavelength, each divided by its peak.
fn weights_panel(opts: &SpectralPlotOptions, grid: &[f64], weights: &[[f64; 3]]) -> Panel {
    let luminous = matches!(opts.settings.method, Method::Luminous);
    let mut lower = Panel::new("wavelength λ (nm)", "channel weight (peak = 1)", VISIBLE_NM);
    lower.zero_line = true;
    lower.legend = Some(LegendCorner::Auto);
    let names: [&str; 3] = match opts.settings.method {
        Method::Paper(_) => ["r̄(λ)", "ḡ(λ)", "b̄(λ)"],
        Method::Colorimetric(_) => ["R weight", "G weight", "B weight"],
        Method::Luminous => ["D65·V(λ)", "", ""],
    };
    for c in 0..(if luminous { 1 } else { 3 }) {
        let peak = weights.iter().map(|w| w[c].abs()).fold(0.0, f64::max);
        if peak <= 0.0 {
            continue;
        }
        let pts: Vec<(f64, f64)> = grid
            .iter()
            .zip(weights)
            .map(|(&wl, w)| (wl, w[c] / peak))
            .collect();
        let colour = if luminous {
            crate::chart::palette(7)
        } else {
            CHANNEL_COLOURS[c]
        };
        lower.lines.push(Line::new(
            Some(names[c].to_string()),
            colour,
            Stroke::SOLID,
            pts,
        ));
    }
    lower.title = Some(match opts.settings.method {
        Method::Paper(_) => {
            "colour-matching functions (each divided by its peak; ∫ over the CMF's own grid)".into()
        }
        Method::Colorimetric(_) => {
            "effective channel weights: illuminant × CIE CMFs → RGB, over the illuminant's RGB"
                .into()
        }
        Method::Luminous => "D65 × V(λ), 380–780 nm at 10 nm".into(),
    });
    lower
}

fn short_name(source: &str) -> String {
    Path::new(source)
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| source.to_string())
}
