//! `glassdb plot stack`: a unit's WINDOW photopic T, Rf and Rb against angle beside each of its
//! layers alone (as it faces in the unit), and the pane groups' shares of Rf.

use glassdb_spectral::WindowMethod;
use glassdb_stack::{Evaluation, Stack};

use super::{ANGLE_AXIS, angle_grid};
use crate::PlotError;
use crate::chart::{LegendCorner, Line, Panel, Stroke, palette};
use crate::figure::{Cell, GridFigure};

/// One panel of T, Rf, Rb against angle; `rows` per angle `[T, Rf, Rb]`.
fn panel(title: String, angles: &[f64], rows: &[[f64; 3]]) -> Panel {
    let mut p = Panel::new(ANGLE_AXIS, "photopic T, R (fraction)", (0.0, 90.0));
    p.title = Some(title);
    p.y_range = Some((0.0, 1.0));
    p.legend = Some(LegendCorner::Auto);
    for (k, name) in ["T", "Rf (outdoor side)", "Rb (indoor side)"]
        .iter()
        .enumerate()
    {
        let points = angles.iter().zip(rows).map(|(&a, r)| (a, r[k])).collect();
        let line = Line::new(Some(name.to_string()), palette(k), Stroke::SOLID, points);
        p.lines.push(if k == 0 { line } else { line.dashed() });
    }
    p
}

/// The figure of `stack`, whose layers the command line names `labels` (outside first).
pub fn stack_figure(
    stack: &Stack,
    labels: &[String],
    title: &str,
) -> Result<GridFigure, PlotError> {
    let angles = angle_grid(90);
    let eval: Evaluation = stack
        .evaluate(&angles, &[], true, Default::default())
        .map_err(|e| PlotError::Empty(format!("the unit cannot be evaluated: {e}")))?;
    let Some(system) = &eval.photopic else {
        return Err(PlotError::Empty(
            "a layer has no spectrum, so the unit has no photopic values".into(),
        ));
    };
    let rows: Vec<[f64; 3]> = system.iter().map(|o| [o.t, o.rf, o.rb]).collect();
    let mut unit = panel(
        format!("the unit ({} layers)", stack.layers().len()),
        &angles,
        &rows,
    );
    if stack.groups().len() > 1 {
        for g in 0..stack.groups().len() {
            let points = angles
                .iter()
                .zip(system)
                .map(|(&a, o)| (a, o.share.front[g]))
                .collect();
            let label = format!("Rf share of pane group {}", g + 1);
            unit.lines
                .push(Line::new(Some(label), palette(3 + g), Stroke::SOLID, points).width(1));
        }
    }
    let mut cells = vec![Cell {
        main: unit,
        lower: None,
    }];
    let layers = stack
        .layer_averages(&angles, WindowMethod::Photopic)
        .map_err(|e| PlotError::Empty(format!("a layer cannot be evaluated: {e}")))?;
    for (k, (rows, layer)) in layers.iter().zip(stack.layers()).enumerate() {
        let Some(rows) = rows else { continue };
        let name = labels
            .get(k)
            .cloned()
            .unwrap_or_else(|| layer.label.clone());
        let flipped = if layer.flipped { ", flipped" } else { "" };
        let title = format!("layer {}: {name} ({}{flipped})", k + 1, layer.model.name());
        cells.push(Cell {
            main: panel(title, &angles, rows),
            lower: None,
        });
    }
    let columns = cells.len().clamp(1, 3);
    Ok(GridFigure {
        title: title.to_string(),
        subtitle: Some(format!(
            "WINDOW photopic values (NFRC 300: D65 × CIE 1931 ȳ), layers combined {}",
            eval.combination.name()
        )),
        cells,
        columns,
        cell_size: (600, 480),
    })
}
