//! Pseudo-3D "waterfall" stacks of curves, as in the paper's Figs. 7 and 11–13.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{
    Clip, DrawResult, Fonts, PlotError, auto_range, linear_tick_label, log_tick_label, render_png,
    render_rgb, runs,
};

/// A stack of curves `value(x)`, one per offset (e.g. contact pressure along ζ for successive
/// pinion angles φp).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Waterfall {
    /// Title above the chart (empty: none).
    pub title: String,
    /// Description of x, along each curve, e.g. `"ζ = z/m_n"`.
    pub x_label: String,
    /// Description of the offset, e.g. `"φp (rad)"`.
    pub y_label: String,
    /// Description of the value, e.g. `"contact pressure (MPa)"`.
    pub z_label: String,
    /// `(offset, points)`: each curve's offset (e.g. φp) and its `(x, value)` points.
    pub curves: Vec<(f64, Vec<(f64, f64)>)>,
}

/// Peak height of the largest |value|, in mean offset spacings.
const PEAK_SPACINGS: f64 = 4.0;
/// Largest peak height as a fraction of the whole offset range.
const PEAK_MAX_FRACTION: f64 = 0.5;
/// Rightward shift of the last curve relative to the first, as a fraction of the x extent.
const DEPTH_FRACTION: f64 = 0.15;

/// Runs of drawable points of one curve, in chart coordinates.
type Pieces = Vec<Vec<(f64, f64)>>;

/// Maps `(offset, x, value)` to chart coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Layout {
    /// Chart height per unit of value.
    scale: f64,
    /// Rightward x shift per unit of offset above `offset_min`.
    shift: f64,
    offset_min: f64,
}

impl Layout {
    fn new(curves: &[(f64, Vec<(f64, f64)>)]) -> Self {
        let offsets = || curves.iter().map(|c| c.0).filter(|o| o.is_finite());
        let points = || {
            curves
                .iter()
                .filter(|c| c.0.is_finite())
                .flat_map(|c| c.1.iter())
                .filter(|p| p.0.is_finite() && p.1.is_finite())
        };
        let min_max = |it: &mut dyn Iterator<Item = f64>| {
            it.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
        };
        let (offset_min, offset_max) = min_max(&mut offsets());
        let mut distinct: Vec<f64> = offsets().collect();
        distinct.sort_by(f64::total_cmp);
        distinct.dedup();
        let range = offset_max - offset_min;
        let peak = if distinct.len() > 1 && range.is_finite() && range > 0.0 {
            let spacing = range / (distinct.len() - 1) as f64;
            (PEAK_SPACINGS * spacing).min(PEAK_MAX_FRACTION * range)
        } else {
            1.0
        };
        let v_max = points().map(|p| p.1.abs()).fold(0.0, f64::max);
        let scale = if v_max > 0.0 && (peak / v_max).is_finite() { peak / v_max } else { 0.0 };
        let (x_min, x_max) = min_max(&mut points().map(|p| p.0));
        let x_extent =
            if x_max > x_min && (x_max - x_min).is_finite() { x_max - x_min } else { 1.0 };
        let shift = if distinct.len() > 1 && range.is_finite() && range > 0.0 {
            DEPTH_FRACTION * x_extent / range
        } else {
            0.0
        };
        Self { scale, shift, offset_min: if offset_min.is_finite() { offset_min } else { 0.0 } }
    }

    /// Chart coordinates of point `(x, value)` of the curve at `offset`.
    fn map(&self, offset: f64, (x, value): (f64, f64)) -> (f64, f64) {
        (x + self.shift * (offset - self.offset_min), offset + self.scale * value)
    }
}

/// Draws `w` as a waterfall PNG of `size` (width, height) pixels at `path`.
///
/// Each curve is drawn at the height of its offset (the y axis reads the offset, e.g. φp) with
/// its values scaled to heights: the largest |value| rises 4 mean offset spacings (at most half
/// the offset range) above its baseline. Each curve is also shifted right in proportion to its
/// offset (the last by 15 % of the x extent) to suggest depth, so the x axis reads x for the
/// curve with the smallest offset. Curves are drawn from the back with a white fill down to
/// their baseline, so nearer curves hide farther ones. A scale bar at the right gives the
/// value scale and `z_label`.
///
/// The margins come from the text's measured extents: the title is centred on the whole
/// width and set smaller when it would not fit, the y label area takes the widest tick label
/// and the right margin the scale bar's label and the rotated `z_label`, so all text lies
/// inside the image at any size.
///
/// Curves with a non-finite offset and non-finite points are skipped (a skipped point breaks
/// the curve); no curves give empty axes. Errors as for [`line_chart`](super::line_chart).
pub fn waterfall(path: &Path, w: &Waterfall, size: (u32, u32)) -> Result<(), PlotError> {
    render_png(path, size, |root, fonts| draw(root, fonts, w))
}

/// Draws `w` as [`waterfall`] does into an in-memory RGB bitmap of `size` (width, height)
/// pixels: 3 bytes a pixel, rows from the top. For checks of the layout; errors as for
/// [`waterfall`].
pub fn waterfall_rgb(w: &Waterfall, size: (u32, u32)) -> Result<Vec<u8>, PlotError> {
    render_rgb(size, |root, fonts| draw(root, fonts, w))
}

fn draw(root: &DrawingArea<BitMapBackend<'_>, Shift>, fonts: Fonts, w: &Waterfall) -> DrawResult {
    let layout = Layout::new(&w.curves);
    // Curves in chart coordinates, back (largest offset) first.
    let mut curves: Vec<(f64, Pieces)> = w
        .curves
        .iter()
        .filter(|c| c.0.is_finite())
        .map(|(offset, points)| {
            let mapped: Vec<(f64, f64)> = points.iter().map(|&p| layout.map(*offset, p)).collect();
            (*offset, runs(&mapped, false, false))
        })
        .collect();
    curves.sort_by(|a, b| b.0.total_cmp(&a.0));

    let xs = curves.iter().flat_map(|c| c.1.iter().flatten().map(|p| p.0));
    let ys = curves.iter().flat_map(|c| c.1.iter().flatten().map(|p| p.1).chain([c.0]));
    let (x0, x1) = auto_range(xs, false);
    let (y0, y1) = auto_range(ys, false);

    let x_labels = |v: &f64| linear_tick_label(*v, (x0, x1));
    let y_labels = |v: &f64| linear_tick_label(*v, (y0, y1));
    let v_max = w
        .curves
        .iter()
        .filter(|c| c.0.is_finite())
        .flat_map(|c| c.1.iter())
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .map(|p| p.1.abs())
        .fold(0.0, f64::max);
    let bar = (layout.scale > 0.0).then(|| nice_below(v_max));
    let bar_label = bar.map(log_tick_label);
    let text = TextLayout::new(root, fonts, w, (y0, y1), bar_label.as_deref())?;

    // The title centred on the whole image width (a chart caption would centre it between
    // the margins, which are not symmetric here).
    let area = if w.title.is_empty() {
        root.clone()
    } else {
        let top = (0.5 * fonts.tick) as i32;
        root.margin(top, 0, 0, 0).titled(&w.title, Fonts::style(text.title_px))?
    };
    let mut chart = ChartBuilder::on(&area)
        .margin(fonts.tick as i32)
        .margin_right(text.right_margin)
        .x_label_area_size((3.2 * fonts.tick) as i32)
        .y_label_area_size(text.y_label_area)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_label_formatter(&x_labels)
        .y_label_formatter(&y_labels)
        .x_desc(&w.x_label)
        .y_desc(&w.y_label)
        .label_style(Fonts::style(fonts.tick))
        .axis_desc_style(Fonts::style(fonts.axis))
        .draw()?;

    // Only absurd data (beyond ±1e300) reaches outside the ranges; keep pixels in i32.
    let clip = Clip::new((x0, x1), (y0, y1), false, false);
    let n = curves.len().max(2) as f64;
    for (i, (offset, runs)) in curves.iter().enumerate() {
        // Back curves light, front curves dark (viridis from yellow-green to purple).
        let colour = ViridisRGB::get_color(0.8 * (1.0 - i as f64 / (n - 1.0)));
        for run in runs {
            let (first, last) = (run[0], run[run.len() - 1]);
            let mut fill = run.clone();
            fill.push((last.0, *offset));
            fill.push((first.0, *offset));
            let fill = fill.into_iter().map(|p| clip.clamp(p)).collect::<Vec<_>>();
            chart.draw_series([Polygon::new(fill, WHITE.filled())])?;
            let baseline = vec![clip.clamp((first.0, *offset)), clip.clamp((last.0, *offset))];
            chart.draw_series([PathElement::new(baseline, RGBColor(190, 190, 190))])?;
            for piece in clip.polyline(run) {
                chart.draw_series(LineSeries::new(piece, colour.stroke_width(2)))?;
            }
        }
    }

    // Scale bar in the right margin: a nice value below the largest |value|.
    if let (Some(bar), Some(bar_label)) = (bar, bar_label) {
        let base = clip.clamp((x1, layout.offset_min));
        let top = clip.clamp((x1, layout.offset_min + layout.scale * bar));
        let (px_right, py_base) = chart.backend_coord(&base);
        let (_, py_top) = chart.backend_coord(&top);
        let px = px_right + (0.8 * fonts.tick) as i32;
        let tick = (0.3 * fonts.tick) as i32;
        let style = BLACK.stroke_width(2);
        root.draw(&PathElement::new(vec![(px, py_base), (px, py_top)], style))?;
        root.draw(&PathElement::new(vec![(px - tick, py_base), (px + tick, py_base)], style))?;
        root.draw(&PathElement::new(vec![(px - tick, py_top), (px + tick, py_top)], style))?;
        let label = Fonts::style(fonts.tick).pos(Pos::new(HPos::Left, VPos::Center));
        root.draw(&Text::new(bar_label, (px + 2 * tick, (py_base + py_top) / 2), label))?;
        let (_, py_range) = chart.plotting_area().get_pixel_range();
        let desc = Fonts::style(fonts.axis)
            .transform(FontTransform::Rotate90)
            .pos(Pos::new(HPos::Center, VPos::Top));
        let pz = px + text.z_label_offset;
        root.draw(&Text::new(w.z_label.clone(), (pz, (py_range.start + py_range.end) / 2), desc))?;
    }
    Ok(())
}

/// Text sizes and margins measured from the text itself (plotters' estimate of each string's
/// extent in the embedded font), so that the title, the axis descriptions, the tick labels and
/// the scale bar's label all lie inside the image at any image size and any text length.
#[derive(Debug, Clone, Copy, PartialEq)]
struct TextLayout {
    /// Title size, px: `fonts.title`, reduced so that the title fits the image width less a
    /// margin of one tick-label size on each side.
    title_px: f64,
    /// Right margin, px: the gap to the scale bar, the bar's label, the rotated `z_label` and a
    /// margin.
    right_margin: i32,
    /// Width of the y label area, px: the widest y tick label, the rotated `y_label` and gaps.
    y_label_area: i32,
    /// Distance from the plotting area's right edge to the rotated `z_label`'s anchor, px.
    z_label_offset: i32,
}

impl TextLayout {
    fn new(
        root: &DrawingArea<BitMapBackend<'_>, Shift>,
        fonts: Fonts,
        w: &Waterfall,
        (y0, y1): (f64, f64),
        bar_label: Option<&str>,
    ) -> Result<Self, Box<dyn std::error::Error>> {
        let size = |text: &str, px: f64| -> Result<(f64, f64), Box<dyn std::error::Error>> {
            if text.is_empty() {
                return Ok((0.0, 0.0));
            }
            let (w, h) = root.estimate_text_size(text, &Fonts::style(px))?;
            Ok((f64::from(w), f64::from(h)))
        };
        let (width, _) = root.dim_in_pixel();
        let tick = fonts.tick;
        let available = f64::from(width) - 2.0 * tick;
        let (title_w, _) = size(&w.title, fonts.title)?;
        let title_px = if title_w > available && title_w > 0.0 {
            // Text width scales with the font size; 2 % below the exact fit for rounding.
            (fonts.title * 0.98 * available / title_w).max(1.0)
        } else {
            fonts.title
        };
        // The line height of the axis descriptions (rotated: their width on the page).
        let (_, axis_h) = size("Ág", fonts.axis)?;
        // The widest y tick label at eleven evenly spread values (plotters picks its ticks
        // among round values of the range; their labels are no wider than these).
        let mut tick_w: f64 = 0.0;
        for k in 0..=10 {
            let v = y0 + (y1 - y0) * f64::from(k) / 10.0;
            tick_w = tick_w.max(size(&linear_tick_label(v, (y0, y1)), tick)?.0);
        }
        let y_label_area = (tick_w + axis_h + 1.5 * tick).max(5.5 * tick).ceil() as i32;
        // Scale bar: 0.8·tick right of the plot, its label 0.6·tick right of the bar, the
        // z description 0.5·tick right of the label, then one tick size of margin.
        let (bar_w, _) = size(bar_label.unwrap_or(""), tick)?;
        let z_label_offset = (0.8 * tick + 0.6 * tick + bar_w + 0.5 * tick).ceil() as i32;
        let right_margin = if bar_label.is_some() {
            (f64::from(z_label_offset) + axis_h + tick).ceil() as i32
        } else {
            tick.ceil() as i32
        };
        Ok(Self { title_px, right_margin, y_label_area, z_label_offset })
    }
}

/// The largest 1, 2 or 5 × 10ᵏ not above `v` (`v` > 0 and finite).
fn nice_below(v: f64) -> f64 {
    let decade = 10f64.powf(v.log10().floor());
    [5.0, 2.0, 1.0].into_iter().map(|m| m * decade).find(|&c| c <= v).unwrap_or(decade)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_values() {
        assert_eq!(nice_below(730.0), 500.0);
        assert_eq!(nice_below(1.0), 1.0);
        assert_eq!(nice_below(0.031), 0.02);
    }

    #[test]
    fn layout_scales_peaks_to_spacings_and_shifts_depth() {
        let curve = |o: f64| (o, vec![(0.0, 0.0), (1.0, 100.0), (2.0, -50.0)]);
        let curves: Vec<_> = (0..11).map(|i| curve(0.1 * i as f64)).collect();
        let l = Layout::new(&curves);
        // 11 offsets over 1.0: spacing 0.1, peak 0.4 for |value| 100.
        assert!((l.scale - 0.004).abs() < 1e-12);
        // Last curve shifted by 15 % of the x extent 2.
        let (x, y) = l.map(1.0, (1.0, 100.0));
        assert!((x - 1.3).abs() < 1e-12 && (y - 1.4).abs() < 1e-12);
        // Two curves: the peak is capped at half the offset range.
        let l = Layout::new(&[curve(0.0), curve(2.0)]);
        assert!((l.scale - 0.01).abs() < 1e-12);
    }

    #[test]
    fn layout_of_degenerate_input_is_finite() {
        for curves in [
            vec![],
            vec![(f64::NAN, vec![(1.0, 1.0)])],
            vec![(0.5, vec![(f64::NAN, 1.0), (1.0, f64::INFINITY)])],
            vec![(0.5, vec![(1.0, 0.0)]), (0.5, vec![(1.0, 0.0)])],
            vec![(0.0, vec![(0.0, f64::MAX)]), (f64::MAX, vec![(0.0, 1.0)])],
        ] {
            let l = Layout::new(&curves);
            assert!(l.scale.is_finite() && l.shift.is_finite() && l.offset_min.is_finite());
        }
    }
}
