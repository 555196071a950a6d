//! Unit tests of the primitives: clipping, tick labels, formats, heat-map reduction, the mask
//! evaluation against hand-computed values, and rendering that must produce real figures.

use std::path::Path;

use glassdb_fit::{Basis, CosPolynomial, FitSummary};
use glassdb_mask::MaskImage;
use glassdb_registry::{AngleCurve, GlassRecord, Registry, RegistryTable};
use glassdb_spectral::{IntegrationSettings, Method};

use crate::chart::{Line, Panel, clipped_runs, format_axis_tick, format_tick};
use crate::figure::{Cell, GridFigure};
use crate::heatmap::HeatMapFigure;
use crate::plots::mask::{MaskChannel, MaskPlotOptions, MaskQuantity, mask_values};
use crate::render::{render_png, render_svg};
use crate::{ImageFormat, PlotError};

#[test]
fn format_from_extension() {
    assert_eq!(
        ImageFormat::from_path(Path::new("a/b.PNG")).unwrap(),
        ImageFormat::Png
    );
    assert_eq!(
        ImageFormat::from_path(Path::new("b.svg")).unwrap(),
        ImageFormat::Svg
    );
    for bad in ["b.jpg", "b", "b.png.tmp"] {
        let e = ImageFormat::from_path(Path::new(bad))
            .unwrap_err()
            .to_string();
        assert!(e.contains(bad) && e.contains(".png or .svg"), "{e}");
    }
}

#[test]
fn tick_labels() {
    assert_eq!(format_tick(0.0), "0");
    assert_eq!(format_tick(0.25), "0.25");
    assert_eq!(format_tick(90.0), "90");
    assert_eq!(format_tick(-0.002), "-2.0e-3");
    assert_eq!(format_axis_tick(-2.2e-16, 1.0), "0");
    assert_eq!(format_axis_tick(1e-6, 1e-5), "1.0e-6");
}

#[test]
fn polylines_are_clipped_to_the_box_and_split_at_gaps() {
    // A line leaving the box through the top at x = 1.5 and coming back at x = 2.5.
    let pts = vec![
        (0.0, 0.5),
        (1.0, 0.5),
        (2.0, 1.5),
        (3.0, 0.5),
        (4.0, f64::NAN),
        (5.0, 0.5),
        (6.0, 0.5),
    ];
    let runs = clipped_runs(&pts, (0.0, 6.0), (0.0, 1.0));
    assert_eq!(runs.len(), 3, "{runs:?}");
    assert_eq!(runs[0], vec![(0.0, 0.5), (1.0, 0.5), (1.5, 1.0)]);
    assert_eq!(runs[1], vec![(2.5, 1.0), (3.0, 0.5)]);
    assert_eq!(runs[2], vec![(5.0, 0.5), (6.0, 0.5)]);
    // Entirely outside: nothing.
    assert!(clipped_runs(&[(0.0, 5.0), (1.0, 6.0)], (0.0, 1.0), (0.0, 1.0)).is_empty());
}

fn one_panel_figure(points: Vec<(f64, f64)>) -> GridFigure {
    let mut p = Panel::new("x (unit)", "y (unit)", (0.0, 10.0));
    p.lines.push(Line::new(
        Some("line".into()),
        crate::chart::palette(0),
        crate::chart::Stroke::SOLID,
        points,
    ));
    GridFigure {
        title: "test figure".into(),
        subtitle: None,
        cells: vec![Cell {
            main: p,
            lower: None,
        }],
        columns: 1,
        cell_size: (400, 300),
    }
}

#[test]
fn a_figure_renders_as_png_and_svg_with_text() {
    let fig = one_panel_figure(
        (0..=100)
            .map(|i| (i as f64 / 10.0, (i as f64 / 10.0).sin()))
            .collect(),
    );
    let png = render_png(&fig).unwrap();
    assert!(png.starts_with(&[0x89, b'P', b'N', b'G']));
    assert!(png.len() > 3000);
    let svg = render_svg(&fig).unwrap();
    assert!(svg.contains("test figure") && svg.contains("x (unit)"));
}

#[test]
fn empty_and_degenerate_figures_are_errors_not_panics() {
    let mut fig = one_panel_figure(vec![]);
    fig.cells.clear();
    assert!(matches!(render_png(&fig), Err(PlotError::Empty(_))));
    let mut fig = one_panel_figure(vec![(0.0, 1.0)]);
    fig.cells[0].main.x_range = (5.0, 5.0);
    assert!(matches!(render_png(&fig), Err(PlotError::Empty(_))));
    let mut fig = one_panel_figure(vec![(0.0, 1.0)]);
    fig.cells[0].main.x_range = (0.0, f64::NAN);
    assert!(matches!(render_svg(&fig), Err(PlotError::NotFinite { .. })));
    let mut fig = one_panel_figure(vec![(0.0, 1.0)]);
    fig.cell_size = (0, 300);
    assert!(matches!(render_png(&fig), Err(PlotError::BadSize { .. })));
    // All-NaN data still draws (an empty panel with the default range).
    let fig = one_panel_figure(vec![(f64::NAN, f64::NAN); 3]);
    assert!(render_png(&fig).is_ok());
}

fn heat(values: Vec<Option<f64>>, w: u32, h: u32) -> HeatMapFigure {
    HeatMapFigure {
        title: "heat".into(),
        subtitle: None,
        width: w,
        height: h,
        values,
        value_label: "v".into(),
        range: None,
        max_vector_cells: 16,
        figure_size: (500, 400),
    }
}

#[test]
fn heat_map_range_and_rendering() {
    let values: Vec<Option<f64>> = (0..64)
        .map(|i| if i % 7 == 0 { None } else { Some(i as f64) })
        .collect();
    let fig = heat(values, 8, 8);
    assert_eq!(fig.effective_range().unwrap(), (1.0, 62.0)); // 0 and 63 are multiples of 7: no value
    assert!(render_png(&fig).unwrap().len() > 3000);
    let svg = render_svg(&fig).unwrap();
    // Vector output is reduced to at most 16×16 cells merged in runs: bounded element count.
    assert!(
        svg.matches("<rect").count() < 16 * 16 + 200,
        "too many SVG rectangles"
    );
    let none = heat(vec![None; 4], 2, 2);
    assert!(matches!(render_png(&none), Err(PlotError::Empty(_))));
    let wrong = heat(vec![Some(1.0); 3], 2, 2);
    assert!(render_png(&wrong).is_err());
}

fn curve(powers: Vec<u32>, coefficients: Vec<f64>) -> AngleCurve {
    AngleCurve {
        fit: FitSummary::exact(powers.last().copied().unwrap_or(0)),
        polynomial: CosPolynomial {
            basis: if powers.first() == Some(&0) {
                Basis::Full
            } else {
                Basis::Paper
            },
            powers,
            coefficients,
        },
        tolerance: 0.002,
    }
}

/// A registry with one glass: r = r0·cos θ (front), r_back = r0_back (constant), t = t0.
fn linear_registry() -> Registry {
    let lin = curve(vec![1], vec![1.0]);
    let one = curve(vec![0], vec![1.0]);
    Registry::single(RegistryTable {
        light: None,
        spectral: IntegrationSettings {
            method: Method::Luminous,
            extrapolate: false,
        },
        glasses: vec![GlassRecord::with_shared_curves(
            3,
            "linear",
            "measured",
            [[0.1, 0.2, 0.3], [0.5, 0.6, 0.7], [0.4, 0.4, 0.4]],
            [&lin, &one, &one],
        )],
    })
}

#[test]
fn mask_values_follow_the_registry_per_pixel() {
    let reg = linear_registry();
    // Pixels (plane, id, cos code): no glass; glass 3 at cos 255/255; at cos 51/255 = 0.2;
    // on plane 1 (back face).
    let mask = MaskImage::from_packed8(4, 1, 3, &[0, 0, 0, 0, 3, 255, 0, 3, 51, 1, 3, 51]);
    let opts = MaskPlotOptions {
        back_planes: vec![1],
        ..MaskPlotOptions::default()
    };
    let v = mask_values(&mask, &reg, "m.png", &opts).unwrap();
    // Luminance of r0 = (0.1, 0.2, 0.3): 0.02126 + 0.14304 + 0.02166 = 0.18596.
    assert_eq!(v[0], None);
    assert!((v[1].unwrap() - 0.18596).abs() < 1e-12, "{v:?}");
    assert!((v[2].unwrap() - 0.2 * 0.18596).abs() < 1e-12, "{v:?}");
    assert!((v[3].unwrap() - 0.4).abs() < 1e-12, "back face: {v:?}");
    let g = MaskPlotOptions {
        quantity: MaskQuantity::Transmittance,
        channel: MaskChannel::G,
        ..MaskPlotOptions::default()
    };
    let v = mask_values(&mask, &reg, "m.png", &g).unwrap();
    assert!((v[2].unwrap() - 0.6).abs() < 1e-12);
    // An unknown id is an error naming it and its pixel count.
    let bad = MaskImage {
        id: vec![7, 7, 3, 0],
        ..mask
    };
    let e = mask_values(&bad, &reg, "m.png", &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("m.png") && e.contains("id 7 (2 pixels)"), "{e}");
}
