//! `glassdb plot fit`: measured points and fitted curves r(θ), t(θ) from 0 to 90° per glass,
//! with the residuals (fitted − measured) in a panel below, the paper basis optionally beside
//! the full one, and the measured range shaded so that extrapolation is visible.

use std::path::Path;

use glassdb_fit::{
    AngleSamples, Basis, CurveFit, FitFile, FitOptions, GlassAngleTable, Quantity, fit_curve,
    read_angle_table, read_fit_file,
};
use plotters::style::RGBColor;

use super::{ANGLE_AXIS, curve_points};
use crate::PlotError;
use crate::chart::{
    LegendCorner, Line, Marker, MarkerShape, Markers, Panel, Shade, Stroke, format_tick,
};
use crate::figure::{Cell, GridFigure};

/// Colour of reflectance curves and points.
pub const REFLECTANCE_COLOUR: RGBColor = RGBColor(31, 119, 180);
/// Colour of transmittance curves and points.
pub const TRANSMITTANCE_COLOUR: RGBColor = RGBColor(230, 110, 10);
const MEASURED_RANGE_COLOUR: RGBColor = RGBColor(60, 160, 60);

/// How to fit a measured table for plotting.
#[derive(Debug, Clone, PartialEq)]
pub struct FitPlotOptions {
    /// The table is in percent.
    pub percent: bool,
    /// Fixed degree (default: the fit crate's automatic choice).
    pub degree: Option<u32>,
    /// Tolerance and highest degree of the automatic choice.
    pub tol: f64,
    /// Highest degree tried.
    pub max_degree: u32,
    /// Also fit and draw the paper basis (powers 1…n, no constant) beside the full basis.
    pub compare_paper: bool,
    /// Only these glasses (by name); empty: all.
    pub glasses: Vec<String>,
}

impl Default for FitPlotOptions {
    fn default() -> Self {
        FitPlotOptions {
            percent: false,
            degree: None,
            tol: glassdb_fit::DEFAULT_TOL,
            max_degree: glassdb_fit::DEFAULT_MAX_DEGREE,
            compare_paper: false,
            glasses: Vec::new(),
        }
    }
}

/// One curve to draw: fitted, with a line style, and its label.
struct DrawnFit {
    fit: CurveFit,
    dashed: bool,
    label: String,
}

/// One quantity of one glass: measured samples (if any) and the fits drawn for them.
struct QuantityPlot {
    quantity: Quantity,
    samples: Option<AngleSamples>,
    fits: Vec<DrawnFit>,
}

fn quantity_symbol(q: Quantity) -> &'static str {
    match q {
        Quantity::Reflectance => "r",
        Quantity::Transmittance => "t",
    }
}

fn quantity_style(q: Quantity) -> (RGBColor, MarkerShape) {
    match q {
        Quantity::Reflectance => (REFLECTANCE_COLOUR, MarkerShape::Circle),
        Quantity::Transmittance => (TRANSMITTANCE_COLOUR, MarkerShape::Triangle),
    }
}

fn fit_label(q: Quantity, fit: &CurveFit, measured: bool) -> String {
    let d = &fit.diagnostics;
    let err = if measured {
        format!(", max |err| {}", format_tick(d.summary.max_abs_error))
    } else {
        String::new()
    };
    format!(
        "{} fit ({}, n={}{err})",
        quantity_symbol(q),
        fit.polynomial.basis.name(),
        fit.polynomial.degree()
    )
}

/// Fits one measured curve with the plot options, the given basis (None: the fit crate's default).
fn fit_samples(
    samples: &AngleSamples,
    quantity: Quantity,
    basis: Option<Basis>,
    opts: &FitPlotOptions,
) -> Result<CurveFit, PlotError> {
    let mut fo = FitOptions::new(quantity);
    fo.degree = opts.degree;
    fo.tol = opts.tol;
    fo.max_degree = opts.max_degree;
    fo.basis = basis;
    Ok(fit_curve(samples, &fo)?)
}

fn quantity_from_table(
    q: Quantity,
    samples: &Option<AngleSamples>,
    opts: &FitPlotOptions,
) -> Result<Option<QuantityPlot>, PlotError> {
    let Some(samples) = samples else {
        return Ok(None);
    };
    let main = fit_samples(samples, q, None, opts)?;
    // With the comparison on, the paper basis is drawn dashed, the full basis solid.
    let dashed = |f: &CurveFit| opts.compare_paper && f.polynomial.basis == Basis::Paper;
    let mut fits = vec![DrawnFit {
        label: fit_label(q, &main, true),
        dashed: dashed(&main),
        fit: main,
    }];
    if opts.compare_paper {
        let other = match fits[0].fit.polynomial.basis {
            Basis::Full => Basis::Paper,
            Basis::Paper => Basis::Full,
        };
        // A basis that cannot fit these points (too few of them) is left out, not fatal.
        if let Ok(f) = fit_samples(samples, q, Some(other), opts) {
            fits.push(DrawnFit {
                label: fit_label(q, &f, true),
                dashed: dashed(&f),
                fit: f,
            });
        }
    }
    Ok(Some(QuantityPlot {
        quantity: q,
        samples: Some(samples.clone()),
        fits,
    }))
}

/// The measured range of a set of quantity plots (min, max angle), from samples or diagnostics.
fn measured_range(parts: &[QuantityPlot]) -> Option<(f64, f64)> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for p in parts {
        if let Some(s) = &p.samples {
            for &a in &s.angle_deg {
                lo = lo.min(a);
                hi = hi.max(a);
            }
        } else {
            for f in &p.fits {
                if let (Some(a), Some(b)) = (
                    f.fit.diagnostics.angle_min_deg,
                    f.fit.diagnostics.angle_max_deg,
                ) {
                    lo = lo.min(a);
                    hi = hi.max(b);
                }
            }
        }
    }
    (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
}

fn glass_cell(name: &str, parts: &[QuantityPlot]) -> Cell {
    let mut main = Panel::new(ANGLE_AXIS, "r, t (fraction)", (0.0, 90.0));
    main.title = Some(name.to_string());
    main.y_range = Some((0.0, 1.0));
    main.legend = Some(LegendCorner::Auto);
    if let Some((lo, hi)) = measured_range(parts) {
        let (lo, hi) = if hi - lo < 0.5 {
            (lo - 0.25, hi + 0.25)
        } else {
            (lo, hi)
        };
        main.shades.push(Shade {
            x0: lo,
            x1: hi,
            label: Some(format!(
                "measured range {}–{}°",
                format_tick(lo),
                format_tick(hi)
            )),
            colour: MEASURED_RANGE_COLOUR,
        });
    }
    let mut lower = Panel::new(ANGLE_AXIS, "fit − measured", (0.0, 90.0));
    lower.zero_line = true;
    lower.legend = Some(LegendCorner::Auto);
    let mut has_residuals = false;
    let mut main_residual_max: f64 = 0.0;
    // (|residual|, residual, angle) of the worst residual of a compared (dashed) fit.
    let mut compared_worst = (0.0f64, 0.0f64, 0.0f64);
    for p in parts {
        let (colour, shape) = quantity_style(p.quantity);
        let sym = quantity_symbol(p.quantity);
        for f in &p.fits {
            let fit = f.fit.clone();
            let mut line = Line::new(
                Some(f.label.clone()),
                colour,
                Stroke::SOLID,
                curve_points(move |c| fit.eval_cos(c)),
            );
            if f.dashed {
                line = line.dashed();
            }
            main.lines.push(line);
        }
        if let Some(s) = &p.samples {
            let pts: Vec<(f64, f64)> = s
                .angle_deg
                .iter()
                .copied()
                .zip(s.value.iter().copied())
                .collect();
            main.markers.push(Markers::new(
                Some(format!("{sym} measured")),
                colour,
                Marker { shape, size: 4 },
                pts,
            ));
            for f in &p.fits {
                let res: Vec<(f64, f64)> = s
                    .angle_deg
                    .iter()
                    .zip(&s.value)
                    .map(|(&a, &v)| (a, f.fit.eval_angle_deg(a) - v))
                    .collect();
                let m = Markers::new(
                    Some(format!("{sym}, {}", f.fit.polynomial.basis.name())),
                    colour,
                    Marker {
                        shape: if f.dashed { MarkerShape::Cross } else { shape },
                        size: 3,
                    },
                    res,
                );
                if !f.dashed {
                    for &(_, r) in &m.points {
                        main_residual_max = main_residual_max.max(r.abs());
                    }
                } else {
                    for &(a, r) in &m.points {
                        if r.abs() > compared_worst.0 {
                            compared_worst = (r.abs(), r, a);
                        }
                    }
                }
                lower.markers.push(m);
                has_residuals = true;
            }
        }
    }
    // The y range follows the solid (default) fit's residuals, so that they stay readable when
    // the compared basis misses by far more; what is off scale is said in the title.
    if main_residual_max > 0.0 && compared_worst.0 > 1.6 * main_residual_max {
        let lim = 1.3 * main_residual_max;
        lower.y_range = Some((-lim, lim));
        lower.title = Some(format!(
            "dashed-basis residuals beyond ±{} not shown (worst {:+.3} at {}°)",
            format_tick(lim),
            compared_worst.1,
            format_tick(compared_worst.2)
        ));
    }
    Cell {
        main,
        lower: has_residuals.then_some((lower, 0.36)),
    }
}

/// The fit figure of a measured angle table (CSV): every glass fitted as `glassdb fit` does.
pub fn fit_figure_from_table(path: &Path, opts: &FitPlotOptions) -> Result<GridFigure, PlotError> {
    let tables = read_angle_table(path, opts.percent)?;
    let tables = select(tables, &opts.glasses, |t: &GlassAngleTable| &t.name, path)?;
    let mut cells = Vec::new();
    for t in &tables {
        let mut parts = Vec::new();
        for (q, s) in [
            (Quantity::Reflectance, &t.reflectance),
            (Quantity::Transmittance, &t.transmittance),
        ] {
            if let Some(p) = quantity_from_table(q, s, opts).map_err(|e| in_glass(e, &t.name))? {
                parts.push(p);
            }
        }
        cells.push(glass_cell(&t.name, &parts));
    }
    Ok(grid(
        path,
        cells,
        "measured points, fitted curves and residuals",
    ))
}

/// The fit figure of a fit file (`glassdb fit -o`): its curves, and, with `data`, the measured
/// points of the glasses of the same name and their residuals.
pub fn fit_figure_from_fit_file(
    path: &Path,
    data: Option<&Path>,
    opts: &FitPlotOptions,
) -> Result<GridFigure, PlotError> {
    let file: FitFile = read_fit_file(path)?;
    let tables = match data {
        Some(d) => read_angle_table(d, opts.percent)?,
        None => Vec::new(),
    };
    let glasses = select(file.glasses, &opts.glasses, |g| &g.name, path)?;
    let mut cells = Vec::new();
    for g in &glasses {
        let table = tables.iter().find(|t| t.name == g.name);
        let mut parts = Vec::new();
        for (q, fit) in [
            (Quantity::Reflectance, &g.reflectance),
            (Quantity::Transmittance, &g.transmittance),
        ] {
            let Some(fit) = fit else { continue };
            let samples = table.and_then(|t| match q {
                Quantity::Reflectance => t.reflectance.clone(),
                Quantity::Transmittance => t.transmittance.clone(),
            });
            let label = fit_label(q, fit, true);
            parts.push(QuantityPlot {
                quantity: q,
                samples,
                fits: vec![DrawnFit {
                    fit: fit.clone(),
                    dashed: false,
                    label,
                }],
            });
        }
        cells.push(glass_cell(&g.name, &parts));
    }
    let what = if data.is_some() {
        "fitted curves with the measured points"
    } else {
        "fitted curves"
    };
    Ok(grid(path, cells, what))
}

fn in_glass(e: PlotError, name: &str) -> PlotError {
    match e {
        PlotError::Fit(f) => PlotError::Empty(format!("glass `{name}`: {f}")),
        other => other,
    }
}

/// Keeps the items named in `wanted` (all when empty); an unknown name is an error listing
/// the names there are.
pub(crate) fn select<T>(
    items: Vec<T>,
    wanted: &[String],
    name: impl Fn(&T) -> &String,
    path: &Path,
) -> Result<Vec<T>, PlotError> {
    if items.is_empty() {
        return Err(PlotError::Input {
            path: path.into(),
            message: "holds no glass".into(),
        });
    }
    if wanted.is_empty() {
        return Ok(items);
    }
    let names: Vec<String> = items.iter().map(|i| name(i).clone()).collect();
    let missing: Vec<&String> = wanted.iter().filter(|w| !names.contains(w)).collect();
    if !missing.is_empty() {
        return Err(PlotError::Input {
            path: path.into(),
            message: format!("no glass named {missing:?} (it has: {})", names.join(", ")),
        });
    }
    Ok(items
        .into_iter()
        .filter(|i| wanted.contains(name(i)))
        .collect())
}

fn grid(path: &Path, cells: Vec<Cell>, what: &str) -> GridFigure {
    let file = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let columns = cells.len().clamp(1, 2);
    GridFigure {
        title: format!("Angle dependence: {file}"),
        subtitle: Some(format!("{what}; r(θ) = r0·C_r(θ), t(θ) = t0·C_t(θ)")),
        cells,
        columns,
        cell_size: (680, 620),
    }
}
