//! Plotting primitives shared by every figure: a [`Panel`] of curves, markers, shaded x ranges
//! and labels, drawn with axis titles (units in them), a light grid and a legend.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::PlotError;
use crate::error::draw_err;
use crate::font::FAMILY;

/// Colours of the R, G, B channels (curves of one channel share its colour).
pub const CHANNEL_COLOURS: [RGBColor; 3] = [
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(31, 119, 180),
];

/// A categorical palette (Tableau 10) for curves that are not channels.
pub const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// The `i`-th palette colour (cycling).
pub fn palette(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// A plotted series: points in data coordinates, their colour and legend entry, drawn in the
/// style `S` ([`Line`] and [`Markers`]).
#[derive(Debug, Clone)]
pub struct Series<S> {
    /// Its legend entry, if any.
    pub label: Option<String>,
    /// Its colour.
    pub colour: RGBColor,
    /// How it is drawn.
    pub style: S,
    /// Its points, in data coordinates.
    pub points: Vec<(f64, f64)>,
}

impl<S> Series<S> {
    /// `points` drawn in `style` and `colour`, with an optional legend entry.
    pub fn new(
        label: impl Into<Option<String>>,
        colour: RGBColor,
        style: S,
        points: Vec<(f64, f64)>,
    ) -> Self {
        Self {
            label: label.into(),
            colour,
            style,
            points,
        }
    }
}

/// How a [`Line`] is stroked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Stroke {
    /// Drawn dashed.
    pub dashed: bool,
    /// Stroke width in pixels.
    pub width: u32,
}

impl Stroke {
    /// A solid line, 2 px wide.
    pub const SOLID: Stroke = Stroke {
        dashed: false,
        width: 2,
    };
}

/// A polyline. Non-finite points break the line (they are never joined across).
pub type Line = Series<Stroke>;

impl Line {
    /// The same line, dashed.
    pub fn dashed(mut self) -> Self {
        self.style.dashed = true;
        self
    }
    /// The same line with another stroke width in pixels.
    pub fn width(mut self, px: u32) -> Self {
        self.style.width = px;
        self
    }
}

/// Marker shapes for measured points and marked values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MarkerShape {
    /// A filled circle.
    Circle,
    /// A cross.
    Cross,
    /// A filled triangle.
    Triangle,
    /// A filled square.
    Square,
}

/// How [`Markers`] are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Marker {
    /// Its shape.
    pub shape: MarkerShape,
    /// Its size in pixels.
    pub size: u32,
}

/// A set of markers (measured points, marked channel values).
pub type Markers = Series<Marker>;

/// A shaded vertical band from `x0` to `x1` over the whole height of the panel.
#[derive(Debug, Clone)]
pub struct Shade {
    /// Where it starts on the x axis.
    pub x0: f64,
    /// Where it ends on the x axis.
    pub x1: f64,
    /// Its legend entry, if any.
    pub label: Option<String>,
    /// Its colour (drawn translucent).
    pub colour: RGBColor,
}

/// A text label at a data position.
#[derive(Debug, Clone)]
pub struct Annotation {
    /// x of the text's left end, data coordinates.
    pub x: f64,
    /// y of the text, data coordinates.
    pub y: f64,
    /// The text.
    pub text: String,
    /// Its colour.
    pub colour: RGBColor,
}

/// Where a panel's legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LegendCorner {
    /// Top left.
    UpperLeft,
    /// Top right.
    UpperRight,
    /// Bottom left.
    LowerLeft,
    /// Bottom right.
    LowerRight,
    /// Middle of the right side.
    MiddleRight,
    /// Middle of the left side.
    MiddleLeft,
    /// Middle of the top.
    UpperMiddle,
    /// Middle of the bottom.
    LowerMiddle,
    /// The position where the legend box covers the fewest drawn points.
    Auto,
}

/// One chart: axes with titles, and the things drawn in it (shades first, then lines, then
/// markers and text on top).
#[derive(Debug, Clone)]
pub struct Panel {
    /// The panel's title, if any.
    pub title: Option<String>,
    /// The x axis's label.
    pub x_label: String,
    /// The y axis's label.
    pub y_label: String,
    /// The x range shown.
    pub x_range: (f64, f64),
    /// `None`: fit the data (finite values inside the x range) with a small margin.
    pub y_range: Option<(f64, f64)>,
    /// Its lines.
    pub lines: Vec<Line>,
    /// Its markers.
    pub markers: Vec<Markers>,
    /// Its shaded x ranges.
    pub shades: Vec<Shade>,
    /// Its text annotations.
    pub annotations: Vec<Annotation>,
    /// Draw the line y = 0 when it is inside the range (residual panels).
    pub zero_line: bool,
    /// `None`: no legend.
    pub legend: Option<LegendCorner>,
}

impl Panel {
    /// An empty panel with axis titles and an x range.
    pub fn new(x_label: &str, y_label: &str, x_range: (f64, f64)) -> Self {
        Self {
            title: None,
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            x_range,
            y_range: None,
            lines: Vec::new(),
            markers: Vec::new(),
            shades: Vec::new(),
            annotations: Vec::new(),
            zero_line: false,
            legend: Some(LegendCorner::Auto),
        }
    }

    /// The y range drawn: the explicit one, or one fitted to the data.
    pub fn effective_y_range(&self) -> (f64, f64) {
        if let Some(r) = self.y_range {
            return r;
        }
        let (x0, x1) = self.x_range;
        let inside = |&(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && x >= x0 && x <= x1;
        let ys = self
            .lines
            .iter()
            .flat_map(|l| l.points.iter())
            .chain(self.markers.iter().flat_map(|m| m.points.iter()))
            .filter(|p| inside(p))
            .map(|&(_, y)| y);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for y in ys {
            lo = lo.min(y);
            hi = hi.max(y);
        }
        if self.zero_line && lo.is_finite() {
            lo = lo.min(0.0);
            hi = hi.max(0.0);
        }
        if !lo.is_finite() || !hi.is_finite() {
            return (0.0, 1.0);
        }
        let span = hi - lo;
        let pad = if span <= 1e-12 * hi.abs().max(1e-300) {
            (hi.abs() * 0.05).max(1e-9)
        } else {
            0.06 * span
        };
        (lo - pad, hi + pad)
    }
}

/// Picks the legend position whose box (estimated from the labels' lengths) covers the fewest
/// drawn points of the panel; ties go to the earlier candidate.
fn auto_legend_position(
    panel: &Panel,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    (pw, ph): (u32, u32),
) -> SeriesLabelPosition {
    let labels: Vec<&String> = panel
        .shades
        .iter()
        .filter_map(|s| s.label.as_ref())
        .chain(panel.lines.iter().filter_map(|l| l.label.as_ref()))
        .chain(panel.markers.iter().filter_map(|m| m.label.as_ref()))
        .collect();
    let longest = labels.iter().map(|l| l.chars().count()).max().unwrap_or(0) as f64;
    let w = ((longest * 7.5 + 45.0) / pw.max(1) as f64).min(1.0);
    let h = ((labels.len() as f64 * 18.0 + 16.0) / ph.max(1) as f64).min(1.0);
    // Candidate boxes in fractions of the plot (x from the left, y from the bottom).
    let candidates = [
        (SeriesLabelPosition::UpperRight, 1.0 - w, 1.0 - h),
        (SeriesLabelPosition::UpperLeft, 0.0, 1.0 - h),
        (SeriesLabelPosition::LowerRight, 1.0 - w, 0.0),
        (SeriesLabelPosition::LowerLeft, 0.0, 0.0),
        (SeriesLabelPosition::MiddleRight, 1.0 - w, 0.5 - h / 2.0),
        (SeriesLabelPosition::MiddleLeft, 0.0, 0.5 - h / 2.0),
        (SeriesLabelPosition::UpperMiddle, 0.5 - w / 2.0, 1.0 - h),
        (SeriesLabelPosition::LowerMiddle, 0.5 - w / 2.0, 0.0),
    ];
    let points: Vec<(f64, f64)> = panel
        .lines
        .iter()
        .flat_map(|l| densify(&l.points))
        .chain(panel.markers.iter().flat_map(|m| m.points.iter().copied()))
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .map(|(x, y)| ((x - x0) / (x1 - x0), (y - y0) / (y1 - y0)))
        .collect();
    let mut best = (usize::MAX, SeriesLabelPosition::UpperRight);
    for (pos, bx, by) in candidates {
        // A small margin around the box: lines just touching it are hard to read too.
        let (mx, my) = (0.02, 0.03);
        let covered = points
            .iter()
            .filter(|(x, y)| {
                *x >= bx - mx && *x <= bx + w + mx && *y >= by - my && *y <= by + h + my
            })
            .count();
        if covered < best.0 {
            best = (covered, pos);
        }
    }
    best.1
}

/// The points of a polyline with 8 extra points on each segment (so long segments count).
fn densify(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(points.len() * 9);
    for w in points.windows(2) {
        for k in 0..8 {
            let t = k as f64 / 8.0;
            out.push((
                w[0].0 + (w[1].0 - w[0].0) * t,
                w[0].1 + (w[1].1 - w[0].1) * t,
            ));
        }
    }
    if let Some(&last) = points.last() {
        out.push(last);
    }
    out
}

/// Tick labels: plain decimals for ordinary magnitudes, scientific for tiny ones.
pub fn format_tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        return "0".to_string();
    }
    if !(1e-2..1e5).contains(&a) {
        return format!("{v:.1e}");
    }
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// A tick label on an axis spanning `span`: values within rounding noise of 0 print as 0.
pub fn format_axis_tick(v: f64, span: f64) -> String {
    if v.abs() <= span.abs() * 1e-9 {
        "0".to_string()
    } else {
        format_tick(v)
    }
}

/// Clips the segment a→b to the box, or `None` when it lies outside (Liang–Barsky).
fn clip_segment(
    a: (f64, f64),
    b: (f64, f64),
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let mut t0: f64 = 0.0;
    let mut t1: f64 = 1.0;
    for (p, q) in [
        (-dx, a.0 - x0),
        (dx, x1 - a.0),
        (-dy, a.1 - y0),
        (dy, y1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then_some((
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ))
}

/// Splits a polyline into runs that are finite and inside the box, clipping at its edges, so
/// that plotters (which does not clip) never draws outside the plotting area.
pub fn clipped_runs(points: &[(f64, f64)], xr: (f64, f64), yr: (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    for w in points.windows(2) {
        let (a, b) = (w[0], w[1]);
        let clipped = if finite(&a) && finite(&b) {
            clip_segment(a, b, xr, yr)
        } else {
            None
        };
        match clipped {
            Some((ca, cb)) => {
                let joins = current.last().is_some_and(|&l| l == ca);
                if !joins {
                    if current.len() >= 2 {
                        runs.push(std::mem::take(&mut current));
                    } else {
                        current.clear();
                    }
                    current.push(ca);
                }
                current.push(cb);
            }
            None => {
                if current.len() >= 2 {
                    runs.push(std::mem::take(&mut current));
                } else {
                    current.clear();
                }
            }
        }
    }
    if current.len() >= 2 {
        runs.push(current);
    }
    runs
}

fn check_range(what: &str, (a, b): (f64, f64)) -> Result<(), PlotError> {
    for v in [a, b] {
        if !v.is_finite() {
            return Err(PlotError::NotFinite {
                what: format!("the {what} range"),
                value: v,
            });
        }
    }
    if b <= a {
        return Err(PlotError::Empty(format!(
            "the {what} range {a}…{b} is empty"
        )));
    }
    Ok(())
}

/// The chart of a panel: f64 coordinates on both axes.
type PanelChart<'a, DB> = ChartContext<
    'a,
    DB,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Draws a panel into `area`: its axes and grid, then its shades, zero line, lines, markers
/// and annotations, then the legend of what has a label.
pub fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
) -> Result<(), PlotError> {
    let (x0, x1) = panel.x_range;
    check_range("x", panel.x_range)?;
    let (y0, y1) = panel.effective_y_range();
    check_range("y", (y0, y1))?;

    let mut builder = ChartBuilder::on(area);
    builder
        .margin(10)
        .x_label_area_size(42)
        .y_label_area_size(64);
    if let Some(t) = &panel.title {
        builder.caption(t, (FAMILY, 17));
    }
    let mut chart = builder
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(draw_err)?;
    let x_fmt = |v: &f64| format_axis_tick(*v, x1 - x0);
    let y_fmt = |v: &f64| format_axis_tick(*v, y1 - y0);
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .label_style((FAMILY, 13))
        .axis_desc_style((FAMILY, 15))
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(215, 215, 215))
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .draw()
        .map_err(draw_err)?;

    let mut plot = PanelPlot {
        chart: &mut chart,
        x: (x0, x1),
        y: (y0, y1),
    };
    let mut any_label = plot.shades(&panel.shades)?;
    if panel.zero_line && y0 < 0.0 && y1 > 0.0 {
        plot.chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(x0, 0.0), (x1, 0.0)],
                BLACK.mix(0.55).stroke_width(1),
            )))
            .map_err(draw_err)?;
    }
    any_label |= plot.lines(&panel.lines)?;
    any_label |= plot.markers(&panel.markers)?;
    for a in &panel.annotations {
        if a.x.is_finite() && a.y.is_finite() && a.x >= x0 && a.x <= x1 && a.y >= y0 && a.y <= y1 {
            plot.chart
                .draw_series(std::iter::once(Text::new(
                    a.text.clone(),
                    (a.x, a.y),
                    (FAMILY, 13).into_font().color(&a.colour),
                )))
                .map_err(draw_err)?;
        }
    }
    if let (Some(corner), true) = (panel.legend, any_label) {
        plot.legend(panel, corner)?;
    }
    Ok(())
}

/// A panel's chart and the x and y ranges it shows, into which its parts are drawn.
struct PanelPlot<'c, 'a, DB: DrawingBackend> {
    chart: &'c mut PanelChart<'a, DB>,
    x: (f64, f64),
    y: (f64, f64),
}

impl<'a, DB: DrawingBackend + 'a> PanelPlot<'_, 'a, DB> {
    /// The shaded x ranges (clipped to the panel); whether one has a label.
    fn shades(&mut self, shades: &[Shade]) -> Result<bool, PlotError> {
        let (chart, (x0, x1), (y0, y1)) = (&mut *self.chart, self.x, self.y);
        let mut any_label = false;
        for s in shades {
            let (sx0, sx1) = (s.x0.max(x0), s.x1.min(x1));
            if sx1.partial_cmp(&sx0) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let colour = s.colour;
            let anno = chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(sx0, y0), (sx1, y1)],
                    colour.mix(0.16).filled(),
                )))
                .map_err(draw_err)?;
            if let Some(l) = &s.label {
                any_label = true;
                anno.label(l.as_str()).legend(move |(x, y)| {
                    Rectangle::new([(x, y - 6), (x + 18, y + 6)], colour.mix(0.3).filled())
                });
            }
        }
        Ok(any_label)
    }

    /// The lines, each clipped into runs inside the panel; whether one has a label.
    fn lines(&mut self, lines: &[Line]) -> Result<bool, PlotError> {
        let (chart, (x0, x1), (y0, y1)) = (&mut *self.chart, self.x, self.y);
        let mut any_label = false;
        for line in lines {
            let Stroke { dashed, width } = line.style;
            let style = line.colour.stroke_width(width);
            let mut labelled = false;
            for run in clipped_runs(&line.points, (x0, x1), (y0, y1)) {
                let anno = if dashed {
                    chart
                        .draw_series(DashedLineSeries::new(run, 9, 6, style))
                        .map_err(draw_err)?
                } else {
                    chart
                        .draw_series(LineSeries::new(run, style))
                        .map_err(draw_err)?
                };
                if let (Some(l), false) = (&line.label, labelled) {
                    labelled = true;
                    any_label = true;
                    let colour = line.colour;
                    anno.label(l.as_str()).legend(move |(x, y)| {
                        let style = colour.stroke_width(width);
                        if dashed {
                            EmptyElement::at((x, y))
                                + PathElement::new(vec![(0, 0), (7, 0)], style)
                                + PathElement::new(vec![(11, 0), (18, 0)], style)
                        } else {
                            EmptyElement::at((x, y))
                                + PathElement::new(vec![(0, 0), (18, 0)], style)
                                + PathElement::new(vec![(0, 0), (0, 0)], style)
                        }
                    });
                }
            }
        }
        Ok(any_label)
    }

    /// The markers inside the panel; whether a series of them has a label.
    fn markers(&mut self, markers: &[Markers]) -> Result<bool, PlotError> {
        let (chart, (x0, x1), (y0, y1)) = (&mut *self.chart, self.x, self.y);
        let mut any_label = false;
        for m in markers {
            let inside: Vec<(f64, f64)> = m
                .points
                .iter()
                .copied()
                .filter(|&(x, y)| {
                    x.is_finite() && y.is_finite() && x >= x0 && x <= x1 && y >= y0 && y <= y1
                })
                .collect();
            if inside.is_empty() {
                continue;
            }
            let (colour, size) = (m.colour, m.style.size);
            let sz = size as i32;
            // Each shape is its own element type, so each gets its own series.
            macro_rules! draw_markers {
                ($p:ident => $make:expr) => {{
                    let anno = chart
                        .draw_series(inside.into_iter().map(|$p| $make))
                        .map_err(draw_err)?;
                    if let Some(l) = &m.label {
                        any_label = true;
                        anno.label(l.as_str()).legend(move |(x, y)| {
                            let $p = (x + 9, y);
                            $make
                        });
                    }
                }};
            }
            match m.style.shape {
                MarkerShape::Circle => draw_markers!(p => Circle::new(p, size, colour.filled())),
                MarkerShape::Cross => {
                    draw_markers!(p => Cross::new(p, size, colour.stroke_width(2)))
                }
                MarkerShape::Triangle => {
                    draw_markers!(p => TriangleMarker::new(p, size, colour.filled()))
                }
                MarkerShape::Square => draw_markers!(p => {
                    EmptyElement::at(p) + Rectangle::new([(-sz, -sz), (sz, sz)], colour.filled())
                }),
            }
        }
        Ok(any_label)
    }

    /// The legend of `panel` in `corner` (chosen where the data leave room, for `Auto`).
    fn legend(&mut self, panel: &Panel, corner: LegendCorner) -> Result<(), PlotError> {
        let chart = &mut *self.chart;
        let position = match corner {
            LegendCorner::UpperLeft => SeriesLabelPosition::UpperLeft,
            LegendCorner::UpperRight => SeriesLabelPosition::UpperRight,
            LegendCorner::LowerLeft => SeriesLabelPosition::LowerLeft,
            LegendCorner::LowerRight => SeriesLabelPosition::LowerRight,
            LegendCorner::MiddleRight => SeriesLabelPosition::MiddleRight,
            LegendCorner::MiddleLeft => SeriesLabelPosition::MiddleLeft,
            LegendCorner::UpperMiddle => SeriesLabelPosition::UpperMiddle,
            LegendCorner::LowerMiddle => SeriesLabelPosition::LowerMiddle,
            LegendCorner::Auto => {
                let (pw, ph) = chart.plotting_area().dim_in_pixel();
                auto_legend_position(panel, self.x, self.y, (pw, ph))
            }
        };
        chart
            .configure_series_labels()
            .position(position)
            .label_font((FAMILY, 13))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.35))
            .draw()
            .map_err(draw_err)?;
        Ok(())
    }
}
