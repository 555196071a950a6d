//! A heat map of per-pixel values (e.g. the reflectance each glass pixel of a mask gets), with a
//! colour bar. Pixels without a value (no glass) are drawn light grey. Large images are reduced
//! to the plot's resolution by averaging the valued pixels of each block.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::chart::format_tick;
use crate::colormap::viridis;
use crate::error::draw_err;
use crate::font::FAMILY;
use crate::{Figure, ImageFormat, PlotError};

/// Colour of pixels without a value.
pub const NO_VALUE_COLOUR: RGBColor = RGBColor(225, 225, 225);

/// A row-major grid of optional values, row 0 at the top (image convention).
#[derive(Debug, Clone)]
pub struct HeatMapFigure {
    /// The figure's title.
    pub title: String,
    /// A line under it, if any.
    pub subtitle: Option<String>,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// `width * height` values; `None` where nothing is shown (drawn grey).
    pub values: Vec<Option<f64>>,
    /// Label of the colour bar, with units.
    pub value_label: String,
    /// Colour range; `None`: the data's range.
    pub range: Option<(f64, f64)>,
    /// Largest number of cells along one side for vector output (keeps SVG files small).
    pub max_vector_cells: u32,
    /// Size of the whole figure in pixels.
    pub figure_size: (u32, u32),
}

const BAR_WIDTH_PX: u32 = 130;

impl HeatMapFigure {
    /// The colour range drawn.
    pub fn effective_range(&self) -> Result<(f64, f64), PlotError> {
        if let Some((a, b)) = self.range {
            return Ok((a, b));
        }
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in self.values.iter().flatten() {
            if v.is_finite() {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
        if !lo.is_finite() {
            return Err(PlotError::Empty(format!(
                "{}: no pixel has a value",
                self.title
            )));
        }
        if hi - lo < 1e-9 {
            return Ok((lo - 0.005, hi + 0.005));
        }
        Ok((lo, hi))
    }

    /// Block means over a `nx × ny` grid of cells (row 0 at the top).
    fn reduce(&self, nx: u32, ny: u32) -> Vec<Option<f64>> {
        let (w, h) = (self.width as usize, self.height as usize);
        let (nx, ny) = (nx as usize, ny as usize);
        let mut sums = vec![(0.0f64, 0u32); nx * ny];
        for y in 0..h {
            let cy = y * ny / h;
            for x in 0..w {
                if let Some(Some(v)) = self.values.get(y * w + x)
                    && v.is_finite()
                {
                    let cx = x * nx / w;
                    let s = &mut sums[cy * nx + cx];
                    s.0 += v;
                    s.1 += 1;
                }
            }
        }
        sums.into_iter()
            .map(|(s, n)| (n > 0).then(|| s / n as f64))
            .collect()
    }
}

impl Figure for HeatMapFigure {
    fn size(&self) -> (u32, u32) {
        self.figure_size
    }

    fn describe(&self) -> String {
        format!("the heat map \"{}\"", self.title)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        format: ImageFormat,
    ) -> Result<(), PlotError> {
        if self.width == 0 || self.height == 0 {
            return Err(PlotError::Empty(format!(
                "{}: the image is empty",
                self.title
            )));
        }
        if self.values.len() != self.width as usize * self.height as usize {
            return Err(PlotError::Draw(format!(
                "{} values for a {}×{} image",
                self.values.len(),
                self.width,
                self.height
            )));
        }
        let (vmin, vmax) = self.effective_range()?;
        let (fw, _) = root.dim_in_pixel();
        let head_px = if self.subtitle.is_some() { 62 } else { 40 };
        let (head, body) = root.split_vertically(head_px);
        let centred = |size| {
            TextStyle::from((FAMILY, size).into_font()).pos(Pos::new(HPos::Center, VPos::Center))
        };
        head.draw_text(&self.title, &centred(22), (fw as i32 / 2, 21))
            .map_err(draw_err)?;
        if let Some(sub) = &self.subtitle {
            let style = centred(14).color(&RGBColor(80, 80, 80));
            head.draw_text(sub, &style, (fw as i32 / 2, 49))
                .map_err(draw_err)?;
        }
        let (bw, _) = body.dim_in_pixel();
        let (map_area, bar_area) = body.split_horizontally(bw.saturating_sub(BAR_WIDTH_PX));

        let (w, h) = (self.width as f64, self.height as f64);
        let mut chart = ChartBuilder::on(&map_area)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..w, 0.0..h)
            .map_err(draw_err)?;
        let height = self.height;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("pixel column")
            .y_desc("pixel row (0 at top)")
            .label_style((FAMILY, 13))
            .axis_desc_style((FAMILY, 15))
            .x_label_formatter(&|v| format!("{:.0}", v))
            .y_label_formatter(&|v| format!("{:.0}", height as f64 - v))
            .draw()
            .map_err(draw_err)?;
        let (pw, ph) = chart.plotting_area().dim_in_pixel();
        let vector = format == ImageFormat::Svg;
        let cap = if vector {
            self.max_vector_cells.max(8)
        } else {
            u32::MAX
        };
        let nx = self.width.min(pw.max(1)).min(cap);
        let ny = self.height.min(ph.max(1)).min(cap);
        let cells = self.reduce(nx, ny);
        // Quantise to 256 colour levels and merge equal runs along each row: fewer elements.
        let level = |v: Option<f64>| {
            v.map(|v| (((v - vmin) / (vmax - vmin)).clamp(0.0, 1.0) * 255.0).round() as u16)
        };
        let mut rects = Vec::new();
        for cy in 0..ny as usize {
            let row = &cells[cy * nx as usize..(cy + 1) * nx as usize];
            let mut start = 0usize;
            while start < row.len() {
                let l = level(row[start]);
                let mut end = start + 1;
                while end < row.len() && level(row[end]) == l {
                    end += 1;
                }
                let colour = match l {
                    Some(l) => viridis(l as f64 / 255.0),
                    None => NO_VALUE_COLOUR,
                };
                let x0 = start as f64 * w / nx as f64;
                let x1 = end as f64 * w / nx as f64;
                let y_top = h - cy as f64 * h / ny as f64;
                let y_bot = h - (cy + 1) as f64 * h / ny as f64;
                rects.push(Rectangle::new([(x0, y_bot), (x1, y_top)], colour.filled()));
                start = end;
            }
        }
        chart.draw_series(rects).map_err(draw_err)?;

        draw_colour_bar(&bar_area, &self.value_label, (vmin, vmax))
    }
}

/// The colour bar: the viridis scale from `vmin` to `vmax`, labelled `value_label`.
fn draw_colour_bar<DB: DrawingBackend>(
    bar_area: &DrawingArea<DB, Shift>,
    value_label: &str,
    (vmin, vmax): (f64, f64),
) -> Result<(), PlotError> {
    let mut bar = ChartBuilder::on(bar_area)
        .margin_top(10)
        .margin_bottom(50)
        .margin_right(8)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, vmin..vmax)
        .map_err(draw_err)?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(value_label)
        .label_style((FAMILY, 13))
        .axis_desc_style((FAMILY, 14))
        .y_label_formatter(&|v| format_tick(*v))
        .draw()
        .map_err(draw_err)?;
    let steps = 128;
    bar.draw_series((0..steps).map(|k| {
        let a = vmin + (vmax - vmin) * k as f64 / steps as f64;
        let b = vmin + (vmax - vmin) * (k + 1) as f64 / steps as f64;
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            viridis((k as f64 + 0.5) / steps as f64).filled(),
        )
    }))
    .map_err(draw_err)?;
    Ok(())
}
