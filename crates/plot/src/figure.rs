//! A figure made of panels: a title (and a smaller subtitle) above a grid of cells, each cell a
//! main panel with an optional lower panel beneath it (residuals, colour-matching functions).

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::chart::{Panel, draw_panel};
use crate::error::draw_err;
use crate::font::FAMILY;
use crate::{Figure, ImageFormat, PlotError};

/// One cell of a [`GridFigure`].
#[derive(Debug, Clone)]
pub struct Cell {
    /// The main panel.
    pub main: Panel,
    /// A panel beneath the main one and the fraction of the cell height it takes.
    pub lower: Option<(Panel, f64)>,
}

/// Panels in a grid under a title.
#[derive(Debug, Clone)]
pub struct GridFigure {
    /// The figure's title.
    pub title: String,
    /// A line under it, if any.
    pub subtitle: Option<String>,
    /// Its cells, row by row.
    pub cells: Vec<Cell>,
    /// Cells per row.
    pub columns: usize,
    /// Size of one cell in pixels.
    pub cell_size: (u32, u32),
}

const TITLE_PX: u32 = 40;
const SUBTITLE_PX: u32 = 22;

impl GridFigure {
    fn rows(&self) -> usize {
        let cols = self.columns.max(1);
        self.cells.len().div_ceil(cols).max(1)
    }
    fn header_px(&self) -> u32 {
        TITLE_PX
            + if self.subtitle.is_some() {
                SUBTITLE_PX
            } else {
                0
            }
    }
}

impl Figure for GridFigure {
    fn size(&self) -> (u32, u32) {
        let cols = self.columns.clamp(1, self.cells.len().max(1)) as u32;
        let rows = self.rows() as u32;
        (
            cols.saturating_mul(self.cell_size.0),
            rows.saturating_mul(self.cell_size.1) + self.header_px(),
        )
    }

    fn describe(&self) -> String {
        format!("the figure \"{}\"", self.title)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> Result<(), PlotError> {
        if self.cells.is_empty() {
            return Err(PlotError::Empty(format!(
                "{} has no panel",
                self.describe()
            )));
        }
        let (w, _) = root.dim_in_pixel();
        let (head, body) = root.split_vertically(self.header_px());
        let title_style =
            TextStyle::from((FAMILY, 22).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
        head.draw_text(
            &self.title,
            &title_style,
            (w as i32 / 2, TITLE_PX as i32 / 2 + 2),
        )
        .map_err(draw_err)?;
        if let Some(sub) = &self.subtitle {
            let style = (FAMILY, 14)
                .into_font()
                .color(&RGBColor(80, 80, 80))
                .pos(Pos::new(HPos::Center, VPos::Center));
            head.draw_text(
                sub,
                &style,
                (w as i32 / 2, (TITLE_PX + SUBTITLE_PX / 2) as i32 - 2),
            )
            .map_err(draw_err)?;
        }
        let cols = self.columns.clamp(1, self.cells.len());
        let areas = body.split_evenly((self.rows(), cols));
        for (cell, area) in self.cells.iter().zip(areas.iter()) {
            match &cell.lower {
                None => draw_panel(area, &cell.main)?,
                Some((lower, frac)) => {
                    let (_, h) = area.dim_in_pixel();
                    let split = ((1.0 - frac.clamp(0.1, 0.9)) * h as f64).round() as u32;
                    let (top, bottom) = area.split_vertically(split);
                    draw_panel(&top, &cell.main)?;
                    draw_panel(&bottom, lower)?;
                }
            }
        }
        Ok(())
    }
}
