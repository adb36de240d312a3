//! Colour maps of a value over (x, y), with a colour bar.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{
    DrawResult, Fonts, PlotError, Waterfall, auto_range, linear_tick_label, range_problem,
    render_png,
};

/// A value over (x, y), stored as rows of constant y (the same data layout as a [`Waterfall`],
/// so one set of curves can be drawn both ways).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Heatmap {
    /// Title above the chart (empty: none).
    pub title: String,
    /// x-axis description including the unit, e.g. `"ζ = z/m_n"`.
    pub x_label: String,
    /// y-axis description including the unit, e.g. `"φp (rad)"`.
    pub y_label: String,
    /// Colour-bar description including the unit, e.g. `"contact pressure (MPa)"`.
    pub z_label: String,
    /// `(y, points)`: each row's y and its `(x, value)` points; rows and points in any order,
    /// the x positions may differ from row to row.
    pub rows: Vec<(f64, Vec<(f64, f64)>)>,
    /// Fixed colour range (values outside get the end colours); `None`: the data's min..max.
    pub z_range: Option<(f64, f64)>,
}

impl From<&Waterfall> for Heatmap {
    /// The same curves as a colour map: offsets become y.
    fn from(w: &Waterfall) -> Self {
        Self {
            title: w.title.clone(),
            x_label: w.x_label.clone(),
            y_label: w.y_label.clone(),
            z_label: w.z_label.clone(),
            rows: w.curves.clone(),
            z_range: None,
        }
    }
}

/// An axis-aligned cell `[x0, x1] × [y0, y1]` with its value.
type Cell = ((f64, f64), (f64, f64), f64);

/// Boundaries around each of the sorted distinct `centres`: midpoints between neighbours, half a
/// neighbour spacing beyond the ends, ±0.5 around a single centre.
fn boundaries(centres: &[f64]) -> Vec<(f64, f64)> {
    let n = centres.len();
    (0..n)
        .map(|k| {
            let c = centres[k];
            let lo = if k > 0 { 0.5 * (centres[k - 1] + c) } else { f64::NAN };
            let hi = if k + 1 < n { 0.5 * (c + centres[k + 1]) } else { f64::NAN };
            match (lo.is_nan(), hi.is_nan()) {
                (false, false) => (lo, hi),
                (true, false) => (c - (hi - c), hi),
                (false, true) => (lo, c + (c - lo)),
                (true, true) => (c - 0.5, c + 0.5),
            }
        })
        .collect()
}

/// Sorted distinct finite values.
fn distinct(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.filter(|v| v.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// The cells of all finite values; each row's cells span half-way to the neighbouring rows
/// (rows without a finite value do not count), each point's half-way to its neighbours in the
/// row (points with a finite x do count).
fn cells(rows: &[(f64, Vec<(f64, f64)>)]) -> Vec<Cell> {
    let drawable =
        |r: &&(f64, Vec<(f64, f64)>)| r.1.iter().any(|p| p.0.is_finite() && p.1.is_finite());
    let ys = distinct(rows.iter().filter(drawable).map(|r| r.0));
    let y_bounds = boundaries(&ys);
    let mut out = Vec::new();
    for (y, points) in rows.iter().filter(|r| r.0.is_finite()) {
        let Ok(j) = ys.binary_search_by(|c| c.total_cmp(y)) else { continue };
        let xs = distinct(points.iter().map(|p| p.0));
        let x_bounds = boundaries(&xs);
        for &(x, v) in points.iter().filter(|p| p.0.is_finite() && p.1.is_finite()) {
            if let Ok(i) = xs.binary_search_by(|c| c.total_cmp(&x)) {
                out.push((x_bounds[i], y_bounds[j], v));
            }
        }
    }
    out
}

/// Draws `map` as a PNG colour map of `size` (width, height) pixels at `path`, with a colour bar
/// labelled `z_label` at the right (viridis colours).
///
/// Non-finite values and coordinates are skipped (their cells stay white); no rows give empty
/// axes. Errors as for [`line_chart`](super::line_chart), and for an invalid `z_range`.
pub fn heatmap(path: &Path, map: &Heatmap, size: (u32, u32)) -> Result<(), PlotError> {
    let cells = cells(&map.rows);
    let z_range = match map.z_range {
        Some(r) => match range_problem("colour", r, false) {
            Some(reason) => return Err(PlotError::invalid(path, reason)),
            None => (r.0.min(r.1), r.0.max(r.1)),
        },
        None => {
            let (lo, hi) = cells
                .iter()
                .map(|c| c.2)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
            if lo < hi && (hi - lo).is_finite() { (lo, hi) } else { auto_range([lo, hi], false) }
        }
    };
    render_png(path, size, |root, fonts| draw(root, fonts, map, &cells, z_range))
}

fn draw(
    root: &DrawingArea<BitMapBackend<'_>, Shift>,
    fonts: Fonts,
    map: &Heatmap,
    cells: &[Cell],
    (z0, z1): (f64, f64),
) -> DrawResult {
    let area = if map.title.is_empty() {
        root.clone()
    } else {
        root.titled(&map.title, Fonts::style(fonts.title))?
    };
    let (width, _) = area.dim_in_pixel();
    let bar_width = ((9.0 * fonts.tick) as u32).min(width / 3);
    let (main, bar) = area.split_horizontally(width - bar_width);
    let margin = fonts.tick as i32;
    let x_label_area = (3.2 * fonts.tick) as i32;

    let finite = |v: f64| v.is_finite();
    let range = |bounds: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = bounds
            .filter(|v| finite(*v))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        if lo < hi && (hi - lo).is_finite() { (lo, hi) } else { auto_range([lo, hi], false) }
    };
    let (x0, x1) = range(&mut cells.iter().flat_map(|c| [c.0.0, c.0.1]));
    let (y0, y1) = range(&mut cells.iter().flat_map(|c| [c.1.0, c.1.1]));

    let mut chart = ChartBuilder::on(&main)
        .margin(margin)
        .x_label_area_size(x_label_area)
        .y_label_area_size((5.5 * fonts.tick) as i32)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    let x_labels = |v: &f64| linear_tick_label(*v, (x0, x1));
    let y_labels = |v: &f64| linear_tick_label(*v, (y0, y1));
    let z_labels = |v: &f64| linear_tick_label(*v, (z0, z1));
    chart
        .configure_mesh()
        .disable_mesh()
        .x_label_formatter(&x_labels)
        .y_label_formatter(&y_labels)
        .x_desc(&map.x_label)
        .y_desc(&map.y_label)
        .label_style(Fonts::style(fonts.tick))
        .axis_desc_style(Fonts::style(fonts.axis))
        .draw()?;
    // Cells are clamped to the ranges: only absurd data (beyond ±1e300) reaches outside.
    let clamp = |(x, y): (f64, f64)| (x.clamp(x0, x1), y.clamp(y0, y1));
    let visible = cells.iter().filter(|c| [c.0.0, c.0.1, c.1.0, c.1.1].iter().all(|v| !v.is_nan()));
    chart.draw_series(visible.map(|&((xa, xb), (ya, yb), v)| {
        let colour = ViridisRGB::get_color_normalized(v.clamp(z0, z1), z0, z1);
        Rectangle::new([clamp((xa, ya)), clamp((xb, yb))], colour.filled())
    }))?;

    // Colour bar: a column of thin rectangles, its axis on the right.
    let mut colour_bar = ChartBuilder::on(&bar)
        .margin(margin)
        .margin_left(0)
        .x_label_area_size(x_label_area)
        .right_y_label_area_size((6.0 * fonts.tick) as i32)
        .build_cartesian_2d(0.0..1.0, z0..z1)?;
    colour_bar
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_label_formatter(&z_labels)
        .y_desc(&map.z_label)
        .label_style(Fonts::style(fonts.tick))
        .axis_desc_style(Fonts::style(fonts.axis))
        .draw()?;
    let steps = 256;
    let dz = (z1 - z0) / f64::from(steps);
    colour_bar.draw_series((0..steps).map(|k| {
        let za = z0 + dz * f64::from(k);
        let colour = ViridisRGB::get_color_normalized(za + 0.5 * dz, z0, z1);
        Rectangle::new([(0.0, za), (1.0, za + dz)], colour.filled())
    }))?;
    colour_bar.draw_series([Rectangle::new([(0.0, z0), (1.0, z1)], BLACK.stroke_width(1))])?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundaries_are_midpoints() {
        assert_eq!(boundaries(&[0.0, 1.0, 3.0]), vec![(-0.5, 0.5), (0.5, 2.0), (2.0, 4.0)]);
        assert_eq!(boundaries(&[2.0]), vec![(1.5, 2.5)]);
        assert!(boundaries(&[]).is_empty());
    }

    #[test]
    fn cells_skip_non_finite_values_and_coordinates() {
        let rows = vec![
            (0.0, vec![(0.0, 1.0), (1.0, f64::NAN), (2.0, 3.0)]),
            (f64::NAN, vec![(0.0, 1.0)]),
            (1.0, vec![(f64::INFINITY, 1.0), (0.5, 2.0)]),
            (9.0, vec![(0.5, f64::NAN)]),
        ];
        let c = cells(&rows);
        assert_eq!(c.len(), 3);
        assert_eq!(c[0], ((-0.5, 0.5), (-0.5, 0.5), 1.0));
        assert_eq!(c[1], ((1.5, 2.5), (-0.5, 0.5), 3.0));
        assert_eq!(c[2], ((0.0, 1.0), (0.5, 1.5), 2.0));
    }
}
