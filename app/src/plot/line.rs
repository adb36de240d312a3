//! x–y line and point charts with a legend, on linear or logarithmic axes.

use std::path::Path;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::{
    Clip, DrawResult, Fonts, PALETTE, PlotError, auto_range, linear_tick_label, log_label_count,
    log_tick_label, range_problem, render_png, runs,
};

/// How the points of a [`Series`] are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SeriesStyle {
    /// A line through the points (broken where points are skipped).
    #[default]
    Line,
    /// A marker at each point.
    Points,
    /// A line and a marker at each point.
    LinePoints,
}

/// One named set of (x, y) points.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Legend entry; an empty name gives no legend entry.
    pub name: String,
    /// The points, drawn in this order.
    pub points: Vec<(f64, f64)>,
    /// Line, markers or both.
    pub style: SeriesStyle,
}

/// An x–y chart of one or more series.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LineChart {
    /// Title above the chart (empty: none).
    pub title: String,
    /// x-axis description including the unit, e.g. `"time (s)"`.
    pub x_label: String,
    /// y-axis description including the unit.
    pub y_label: String,
    /// The series, coloured from a fixed palette in this order.
    pub series: Vec<Series>,
    /// Logarithmic x axis; points with x ≤ 0 are skipped.
    pub x_log: bool,
    /// Logarithmic y axis; points with y ≤ 0 are skipped.
    pub y_log: bool,
    /// Fixed x range (reversed ends flip the axis); `None`: the data's range plus 5 % margin.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range; `None`: automatic, as for x.
    pub y_range: Option<(f64, f64)>,
}

/// Draws `chart` as a PNG image of `size` (width, height) pixels at `path`.
///
/// Non-finite points, and non-positive ones on a logarithmic axis, are skipped and break the
/// line. Series without usable points still get their legend entry; no series at all gives
/// empty axes. Errors: a path not ending in `.png`, a size outside
/// [`MIN_SIDE`](super::MIN_SIDE)..=[`MAX_SIDE`](super::MAX_SIDE), an invalid fixed range
/// (NaN or equal ends, beyond ±10³⁰⁰, not within 10⁻³⁰⁰..10³⁰⁰ on a log axis), or a failure
/// to draw or write the file.
pub fn line_chart(path: &Path, chart: &LineChart, size: (u32, u32)) -> Result<(), PlotError> {
    let x_range = resolve_range(path, "x", chart.x_range, chart.x_log, chart, |p| p.0)?;
    let y_range = resolve_range(path, "y", chart.y_range, chart.y_log, chart, |p| p.1)?;
    render_png(path, size, |root, fonts| {
        let (x0, x1) = x_range;
        let (y0, y1) = y_range;
        let (f, c, r) = (fonts, chart, (x_range, y_range));
        match (chart.x_log, chart.y_log) {
            (false, false) => draw(root, f, c, r, lin(x0, x1), lin(y0, y1)),
            (true, false) => draw(root, f, c, r, (x0..x1).log_scale(), lin(y0, y1)),
            (false, true) => draw(root, f, c, r, lin(x0, x1), (y0..y1).log_scale()),
            (true, true) => draw(root, f, c, r, (x0..x1).log_scale(), (y0..y1).log_scale()),
        }
    })
}

/// The fixed range if valid, otherwise the automatic one.
fn resolve_range(
    path: &Path,
    axis: &str,
    fixed: Option<(f64, f64)>,
    log: bool,
    chart: &LineChart,
    coordinate: impl Fn(&(f64, f64)) -> f64,
) -> Result<(f64, f64), PlotError> {
    match fixed {
        Some(r) => match range_problem(axis, r, log) {
            Some(reason) => Err(PlotError::invalid(path, reason)),
            None => Ok(r),
        },
        None => {
            // Only points whose other coordinate is also usable count towards the range.
            let usable = chart.series.iter().flat_map(|s| {
                s.points
                    .iter()
                    .filter(|p| super::usable(p.0, chart.x_log) && super::usable(p.1, chart.y_log))
            });
            Ok(auto_range(usable.map(coordinate), log))
        }
    }
}

fn lin(a: f64, b: f64) -> RangedCoordf64 {
    (a..b).into()
}

fn draw<X, Y>(
    root: &DrawingArea<BitMapBackend<'_>, Shift>,
    fonts: Fonts,
    spec: &LineChart,
    (x_range, y_range): ((f64, f64), (f64, f64)),
    x: X,
    y: Y,
) -> DrawResult
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut builder = ChartBuilder::on(root);
    if !spec.title.is_empty() {
        builder.caption(&spec.title, Fonts::style(fonts.title));
    }
    let mut chart = builder
        .margin(fonts.tick as i32)
        .x_label_area_size((3.2 * fonts.tick) as i32)
        .y_label_area_size((5.5 * fonts.tick) as i32)
        .build_cartesian_2d(x, y)?;

    let log_labels = |v: &f64| log_tick_label(*v);
    let x_labels = |v: &f64| linear_tick_label(*v, x_range);
    let y_labels = |v: &f64| linear_tick_label(*v, y_range);
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(&spec.x_label)
        .y_desc(&spec.y_label)
        .label_style(Fonts::style(fonts.tick))
        .axis_desc_style(Fonts::style(fonts.axis));
    if spec.x_log {
        mesh.x_labels(log_label_count(x_range.0, x_range.1)).x_label_formatter(&log_labels);
    } else {
        mesh.x_label_formatter(&x_labels);
    }
    if spec.y_log {
        mesh.y_labels(log_label_count(y_range.0, y_range.1)).y_label_formatter(&log_labels);
    } else {
        mesh.y_label_formatter(&y_labels);
    }
    mesh.draw()?;

    let clip = Clip::new(x_range, y_range, spec.x_log, spec.y_log);

    let marker = (0.3 * fonts.tick).max(2.0) as i32;
    let legend_len = (1.6 * fonts.tick) as i32;
    for (i, series) in spec.series.iter().enumerate() {
        let colour = PALETTE[i % PALETTE.len()];
        let line = colour.stroke_width(2);
        let has_line = series.style != SeriesStyle::Points;
        let has_points = series.style != SeriesStyle::Line;
        for run in runs(&series.points, spec.x_log, spec.y_log) {
            if has_line {
                for piece in clip.polyline(&run) {
                    chart.draw_series(LineSeries::new(piece, line))?;
                }
            }
            if has_points {
                let visible = run.into_iter().filter(|&p| clip.contains(p));
                chart.draw_series(visible.map(|p| Circle::new(p, marker, colour.filled())))?;
            }
        }
        if !series.name.is_empty() {
            // An empty series carries the legend entry, so it exists even without points.
            let line_colour = if has_line { colour.to_rgba() } else { TRANSPARENT };
            let point_colour = if has_points { colour.to_rgba() } else { TRANSPARENT };
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
                .label(&series.name)
                .legend(move |(px, py)| {
                    EmptyElement::at((px, py))
                        + PathElement::new(
                            vec![(0, 0), (legend_len, 0)],
                            line_colour.stroke_width(2),
                        )
                        + Circle::new((legend_len / 2, 0), marker, point_colour.filled())
                });
        }
    }
    if spec.series.iter().any(|s| !s.name.is_empty()) {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font(Fonts::style(fonts.tick))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .legend_area_size(legend_len + 5)
            .draw()?;
    }
    Ok(())
}
