//! PNG figures and CSV tables for the project's plots.
//!
//! * [`line_chart`]: x–y line/point charts with a legend, linear or logarithmic axes
//!   (work-precision diagrams: error against time on log–log axes);
//! * [`waterfall`]: the paper's Fig. 7 / 11–13 style pseudo-3D stack of curves (e.g. contact
//!   pressure along ζ for successive φp), and [`heatmap`], the same data as a colour map;
//! * [`write_csv`]: the numbers behind a figure, at full precision.
//!
//! Rendering uses `plotters` with its bitmap backend and pure-Rust `ab_glyph` text, so neither
//! building nor running needs system font libraries. Text is set in DejaVu Sans
//! (`app/assets/fonts/DejaVuSans.ttf`, DejaVu fonts 2.37), embedded in this application crate,
//! not in the model library. Its licence (Bitstream Vera and Arev font licences, permissive;
//! DejaVu changes are public domain) is in `app/assets/fonts/LICENSE-DejaVu.txt`. The font is registered with plotters under a private
//! family name, see [`FONT_FAMILY`].
//!
//! Bad data never panics: non-finite points (and non-positive ones on a logarithmic axis) are
//! skipped, lines are broken where points are skipped, and empty data gives an empty chart with
//! axes. Every failure is a [`PlotError`] naming the file and what failed.

mod csv;
mod heatmap;
mod line;
mod waterfall;

pub use csv::write_csv;
pub use heatmap::{Heatmap, heatmap};
pub use line::{LineChart, Series, SeriesStyle, line_chart};
pub use waterfall::{Waterfall, waterfall, waterfall_rgb};

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

/// Family name under which the embedded DejaVu Sans face is registered with plotters.
///
/// A private name, so that a `"sans-serif"` font registered by other code is left alone.
pub const FONT_FAMILY: &str = "helical_gear_mesh DejaVu Sans";

/// DejaVu Sans (Book), see `app/assets/fonts/LICENSE-DejaVu.txt`.
static FONT_TTF: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Smallest accepted image side in pixels: below it the axes and labels do not fit.
pub const MIN_SIDE: u32 = 64;
/// Largest accepted image side in pixels (bounds the RGB buffer to 768 MiB).
pub const MAX_SIDE: u32 = 16_384;

/// A failure to write a figure or table; every variant names the file.
#[derive(Debug)]
#[non_exhaustive]
pub enum PlotError {
    /// The file could not be created or written.
    Io {
        /// The file being written.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// Drawing or PNG encoding failed inside plotters (this includes failing to write the file).
    Draw {
        /// The file being written.
        path: PathBuf,
        /// The error reported by plotters.
        message: String,
    },
    /// The embedded font could not be registered with plotters.
    Font {
        /// The file being written.
        path: PathBuf,
    },
    /// The request itself is invalid: image size, file extension, axis range, CSV row width.
    Invalid {
        /// The file that was to be written.
        path: PathBuf,
        /// What is wrong, in words.
        reason: String,
    },
}

impl PlotError {
    /// The file that was being written.
    pub fn path(&self) -> &Path {
        match self {
            Self::Io { path, .. }
            | Self::Draw { path, .. }
            | Self::Font { path }
            | Self::Invalid { path, .. } => path,
        }
    }

    pub(crate) fn invalid(path: &Path, reason: impl Into<String>) -> Self {
        Self::Invalid { path: path.to_path_buf(), reason: reason.into() }
    }

    pub(crate) fn draw(path: &Path, error: impl fmt::Display) -> Self {
        Self::Draw { path: path.to_path_buf(), message: error.to_string() }
    }
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let path = self.path().display();
        match self {
            Self::Io { source, .. } => write!(f, "cannot write `{path}`: {source}"),
            Self::Draw { message, .. } => write!(f, "cannot draw `{path}`: {message}"),
            Self::Font { .. } => {
                write!(f, "cannot draw `{path}`: the embedded font could not be registered")
            }
            Self::Invalid { reason, .. } => write!(f, "cannot write `{path}`: {reason}"),
        }
    }
}

impl std::error::Error for PlotError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Errors inside a drawing routine; converted to [`PlotError::Draw`] with the path.
pub(crate) type DrawResult = Result<(), Box<dyn std::error::Error>>;

/// Registers the embedded font once per process; `false` if plotters rejected it.
fn font_registered() -> bool {
    static DONE: OnceLock<bool> = OnceLock::new();
    *DONE.get_or_init(|| register_font(FONT_FAMILY, FontStyle::Normal, FONT_TTF).is_ok())
}

/// Checks the output path and image size, registers the font, renders with `draw` into a
/// bitmap of `size` and writes it as PNG to `path`.
pub(crate) fn render_png(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>, Fonts) -> DrawResult,
) -> Result<(), PlotError> {
    let is_png = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png {
        return Err(PlotError::invalid(path, "the file name must end in `.png`"));
    }
    let (w, h) = size;
    if !(MIN_SIDE..=MAX_SIDE).contains(&w) || !(MIN_SIDE..=MAX_SIDE).contains(&h) {
        return Err(PlotError::invalid(
            path,
            format!("image size {w}×{h} px: each side must be in {MIN_SIDE}..={MAX_SIDE}"),
        ));
    }
    if !font_registered() {
        return Err(PlotError::Font { path: path.to_path_buf() });
    }
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::draw(path, e))?;
    draw(&root, Fonts::for_size(size)).map_err(|e| PlotError::draw(path, e))?;
    root.present().map_err(|e| PlotError::draw(path, e))
}

/// Renders with `draw` into an in-memory RGB bitmap of `size` (3 bytes a pixel, rows from the
/// top) instead of a file; errors name the pseudo-file `(in memory)`. The same checks and
/// fonts as [`render_png`], for tests that look at the pixels.
pub(crate) fn render_rgb(
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>, Fonts) -> DrawResult,
) -> Result<Vec<u8>, PlotError> {
    let path = Path::new("(in memory)");
    let (w, h) = size;
    if !(MIN_SIDE..=MAX_SIDE).contains(&w) || !(MIN_SIDE..=MAX_SIDE).contains(&h) {
        return Err(PlotError::invalid(
            path,
            format!("image size {w}×{h} px: each side must be in {MIN_SIDE}..={MAX_SIDE}"),
        ));
    }
    if !font_registered() {
        return Err(PlotError::Font { path: path.to_path_buf() });
    }
    let mut buffer = vec![0u8; 3 * w as usize * h as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| PlotError::draw(path, e))?;
        draw(&root, Fonts::for_size(size)).map_err(|e| PlotError::draw(path, e))?;
        root.present().map_err(|e| PlotError::draw(path, e))?;
    }
    Ok(buffer)
}

/// Font sizes (px) scaled to the image, so large images stay legible.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Fonts {
    /// Chart title.
    pub title: f64,
    /// Axis descriptions.
    pub axis: f64,
    /// Tick labels and legend.
    pub tick: f64,
}

impl Fonts {
    fn for_size((w, h): (u32, u32)) -> Self {
        let base = (f64::from(w.min(h)) / 36.0).clamp(9.0, 40.0);
        Self { title: 1.4 * base, axis: 1.1 * base, tick: base }
    }

    /// The embedded font at `px` pixels.
    pub fn style(px: f64) -> TextStyle<'static> {
        (FONT_FAMILY, px).into_font().into()
    }
}

/// Distinct series colours (colour-blind-friendly qualitative palette, Okabe–Ito order, then
/// grey and dark tones); cycled when there are more series.
pub(crate) const PALETTE: [RGBColor; 10] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
    RGBColor(120, 120, 120),
    RGBColor(120, 40, 140),
];

/// Whether `v` can be placed on an axis (`log`: logarithmic).
pub(crate) fn usable(v: f64, log: bool) -> bool {
    v.is_finite() && (!log || v > 0.0)
}

/// Range of the usable values with a margin of 5 % of the span on each side (in log10 space
/// for a logarithmic axis). A single value gets ±10 % around it (±0.5 if it is 0, ±half a decade
/// on a log axis); no values give 0..1 (1..10). The result lies within ±10³⁰⁰ (log:
/// 10⁻³⁰⁰..10³⁰⁰).
pub(crate) fn auto_range(values: impl IntoIterator<Item = f64>, log: bool) -> (f64, f64) {
    let to = |v: f64| if log { v.log10() } else { v };
    let from = |v: f64| if log { 10f64.powf(v) } else { v };
    let (lo, hi) = values
        .into_iter()
        .filter(|&v| usable(v, log))
        .map(to)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo > hi {
        return (from(0.0), from(1.0));
    }
    // Stay within ±1e300 (log: 1e-300..1e300) so that spans are finite and plotters' tick
    // search terminates; points beyond are clipped.
    let limit = if log { 300.0 } else { 1e300 };
    let (lo, hi) = (lo.clamp(-limit, limit), hi.clamp(-limit, limit));
    let span = hi - lo;
    let mid = 0.5 * (lo + hi);
    let pad = if span > 1e-12 * mid.abs() && span > 0.0 {
        0.05 * span
    } else if log || mid == 0.0 {
        0.5
    } else {
        0.1 * mid.abs()
    };
    (from((lo - pad).max(-limit)), from((hi + pad).min(limit)))
}

/// Checks a user-given axis range (ends distinct, within ±10³⁰⁰, on a log axis within
/// 10⁻³⁰⁰..10³⁰⁰); `None` if valid.
pub(crate) fn range_problem(axis: &str, (lo, hi): (f64, f64), log: bool) -> Option<String> {
    let within = |v: f64| if log { (1e-300..=1e300).contains(&v) } else { v.abs() <= 1e300 };
    if lo.is_nan() || hi.is_nan() || lo == hi {
        Some(format!("{axis} range {lo}..{hi} must have two distinct numbers as ends"))
    } else if log && (lo <= 0.0 || hi <= 0.0) {
        Some(format!("{axis} range {lo}..{hi} must be positive on a logarithmic axis"))
    } else if !(within(lo) && within(hi)) {
        let allowed = if log { "1e-300 to 1e300" } else { "-1e300 to 1e300" };
        Some(format!("{axis} range {lo}..{hi} must lie within {allowed}"))
    } else {
        None
    }
}

/// Splits `points` into runs of consecutive usable points; skipped points break the runs.
pub(crate) fn runs(points: &[(f64, f64)], x_log: bool, y_log: bool) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current = Vec::new();
    for &(x, y) in points {
        if usable(x, x_log) && usable(y, y_log) {
            current.push((x, y));
        } else if !current.is_empty() {
            out.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

/// Keeps drawn geometry within a box around the axis ranges, so that plotters' pixel arithmetic
/// (i32) cannot overflow on points far outside the visible range.
///
/// The box extends [`Clip::SPANS`] axis spans beyond each end, measured in axis space (log10 on
/// a logarithmic axis); what lies outside is invisible anyway. Coordinates beyond ±10³⁰⁰ (in
/// axis space) are first pulled back to ±10³⁰⁰, so that differences stay finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Clip {
    x: (f64, f64),
    y: (f64, f64),
    x_log: bool,
    y_log: bool,
}

impl Clip {
    /// Box margin beyond each end of an axis, in axis spans.
    const SPANS: f64 = 10.0;

    /// The box around the (usable, possibly reversed) ranges `x` and `y`.
    pub fn new(x: (f64, f64), y: (f64, f64), x_log: bool, y_log: bool) -> Self {
        let expand = |(a, b): (f64, f64), log: bool| {
            let (a, b) = (axis_value(a, log), axis_value(b, log));
            let (lo, hi) = (a.min(b), a.max(b));
            let pad = Self::SPANS * (hi - lo);
            (lo - pad, hi + pad)
        };
        Self { x: expand(x, x_log), y: expand(y, y_log), x_log, y_log }
    }

    fn axis_point(&self, (x, y): (f64, f64)) -> (f64, f64) {
        (axis_value(x, self.x_log), axis_value(y, self.y_log))
    }

    fn data_point(&self, (x, y): (f64, f64)) -> (f64, f64) {
        let back = |v: f64, log: bool| if log { 10f64.powf(v) } else { v };
        (back(x, self.x_log), back(y, self.y_log))
    }

    /// Whether usable point `p` lies in the box.
    pub fn contains(&self, (x, y): (f64, f64)) -> bool {
        let (x, y) =
            (if self.x_log { x.log10() } else { x }, if self.y_log { y.log10() } else { y });
        (self.x.0..=self.x.1).contains(&x) && (self.y.0..=self.y.1).contains(&y)
    }

    /// Usable point `p` moved to the nearest point of the box (and within ±10³⁰⁰).
    pub fn clamp(&self, p: (f64, f64)) -> (f64, f64) {
        if self.contains(p) {
            return p;
        }
        let (x, y) = self.axis_point(p);
        self.data_point((x.clamp(self.x.0, self.x.1), y.clamp(self.y.0, self.y.1)))
    }

    /// The parts of the polyline through the usable points `run` that lie in the box (each
    /// segment clipped edge by edge); a single point is kept if inside.
    pub fn polyline(&self, run: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
        let mut out = Vec::new();
        if let [p] = run {
            if self.contains(*p) {
                out.push(vec![*p]);
            }
            return out;
        }
        let mut current: Vec<(f64, f64)> = Vec::new();
        for w in run.windows(2) {
            let Some((p, q)) = self.clip_segment(w[0], w[1]) else {
                out.extend((!current.is_empty()).then(|| std::mem::take(&mut current)));
                continue;
            };
            if p.1 || current.is_empty() {
                out.extend((!current.is_empty()).then(|| std::mem::take(&mut current)));
                current.push(p.0);
            }
            current.push(q.0);
            if q.1 {
                out.push(std::mem::take(&mut current));
            }
        }
        out.extend((!current.is_empty()).then_some(current));
        out
    }

    /// The part of segment `a`–`b` in the box, each end with whether it was moved; `None` if
    /// the segment misses the box. Ends inside the box are returned unchanged.
    #[allow(clippy::type_complexity)]
    fn clip_segment(
        &self,
        a: (f64, f64),
        b: (f64, f64),
    ) -> Option<(((f64, f64), bool), ((f64, f64), bool))> {
        let (a_in, b_in) = (self.contains(a), self.contains(b));
        if a_in && b_in {
            return Some(((a, false), (b, false)));
        }
        let (pa, pb) = (self.axis_point(a), self.axis_point(b));
        let (mut p, mut q) = ([pa.0, pa.1], [pb.0, pb.1]);
        let edges =
            [(0, self.x.0, true), (0, self.x.1, false), (1, self.y.0, true), (1, self.y.1, false)];
        for (k, bound, is_min) in edges {
            let outside = |v: &[f64; 2]| if is_min { v[k] < bound } else { v[k] > bound };
            let (p_out, q_out) = (outside(&p), outside(&q));
            if p_out && q_out {
                return None;
            }
            if p_out || q_out {
                // Interpolate from the inside end (the ratio is then small and accurate).
                let (inner, outer) = if p_out { (q, p) } else { (p, q) };
                let r = (bound - inner[k]) / (outer[k] - inner[k]);
                let mut cut = [0.0; 2];
                cut[k] = bound;
                cut[1 - k] = inner[1 - k] + r * (outer[1 - k] - inner[1 - k]);
                if p_out { p = cut } else { q = cut }
            }
        }
        let end = |inside: bool, orig: (f64, f64), v: [f64; 2]| {
            if inside { (orig, false) } else { (self.data_point((v[0], v[1])), true) }
        };
        Some((end(a_in, a, p), end(b_in, b, q)))
    }
}

/// A usable value in axis space (log10 on a log axis), bounded to ±10³⁰⁰ so that differences
/// stay finite.
fn axis_value(v: f64, log: bool) -> f64 {
    let v = if log { v.log10() } else { v };
    v.clamp(-1e300, 1e300)
}

/// Tick label for a linear axis over `lo..hi`: as many decimals as the tick spacing needs
/// (plotters spaces ticks 1, 2 or 5 × 10ᵏ apart, at most about 10 per axis), more if the value
/// needs them; scientific notation when the axis reaches beyond 10⁵ or stays below 10⁻³;
/// zero as `0` (never `-0`).
pub(crate) fn linear_tick_label(v: f64, (lo, hi): (f64, f64)) -> String {
    let span = (hi - lo).abs();
    if !v.is_finite() || !span.is_finite() || span == 0.0 {
        return format!("{v}");
    }
    let tolerance = 1e-9 * span;
    let step_exp = (span / 10.0).log10().floor() as i32;
    let magnitude = lo.abs().max(hi.abs());
    let scientific = !(1e-3..1e5).contains(&magnitude);
    if v.abs() <= tolerance && scientific {
        return "0".to_string();
    }
    let min_digits = if scientific {
        (v.abs().log10().floor() as i32 - step_exp).clamp(0, 16) as usize
    } else {
        (-step_exp).clamp(0, 16) as usize
    };
    let text = (min_digits..=16)
        .map(|d| if scientific { format!("{v:.d$e}") } else { format!("{v:.d$}") })
        .find(|s| s.parse::<f64>().is_ok_and(|p| (p - v).abs() <= tolerance))
        .unwrap_or_else(|| format!("{v}"));
    match text.strip_prefix('-') {
        Some(rest) if rest.parse::<f64>() == Ok(0.0) => rest.to_string(),
        _ => text,
    }
}

/// Label count for a logarithmic axis over `lo..hi` that labels only the decades when the range
/// spans at least one (plotters adds 2…9 × 10ᵏ labels when given more room than decades).
pub(crate) fn log_label_count(lo: f64, hi: f64) -> usize {
    let decades = (hi / lo).log10().abs();
    if decades >= 1.0 { decades.floor() as usize } else { 10 }
}

/// Compact tick label for a logarithmic axis: plain decimals between 10⁻³ and 10⁴, otherwise
/// scientific notation, at most 3 significant digits.
pub(crate) fn log_tick_label(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() {
        return format!("{v}");
    }
    if (1e-3..1e4).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{v:.decimals$}");
        if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s }
    } else {
        let s = format!("{v:.2e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        format!("{mantissa}e{exponent}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_range_pads_and_handles_degenerate_input() {
        let (lo, hi) = auto_range([0.0, 10.0], false);
        assert!((lo + 0.5).abs() < 1e-12 && (hi - 10.5).abs() < 1e-12);
        assert_eq!(auto_range([], false), (0.0, 1.0));
        assert_eq!(auto_range([f64::NAN, f64::INFINITY], false), (0.0, 1.0));
        let (lo, hi) = auto_range([2.0], false);
        assert!((lo - 1.8).abs() < 1e-12 && (hi - 2.2).abs() < 1e-12);
        assert_eq!(auto_range([0.0], false), (-0.5, 0.5));
        let (lo, hi) = auto_range([-f64::MAX, f64::MAX], false);
        assert!(lo.is_finite() && hi.is_finite());
        let (lo, hi) = auto_range([1e-6, 1e-2, -1.0, 0.0], true);
        assert!((lo.log10() + 6.2).abs() < 1e-9 && (hi.log10() + 1.8).abs() < 1e-9);
        assert_eq!(auto_range([], true), (1.0, 10.0));
        let (lo, hi) = auto_range([5e-324, f64::MAX], true);
        assert!((lo.log10() + 300.0).abs() < 1e-9 && (hi.log10() - 300.0).abs() < 1e-9);
    }

    #[test]
    fn runs_break_at_skipped_points() {
        let p = [(1.0, 1.0), (2.0, f64::NAN), (3.0, 3.0), (4.0, 4.0), (5.0, -1.0)];
        let linear = vec![vec![(1.0, 1.0)], vec![(3.0, 3.0), (4.0, 4.0), (5.0, -1.0)]];
        assert_eq!(runs(&p, false, false), linear);
        assert_eq!(runs(&p, false, true), vec![vec![(1.0, 1.0)], vec![(3.0, 3.0), (4.0, 4.0)]]);
        assert_eq!(runs(&p[3..], false, false).len(), 1);
    }

    #[test]
    fn log_tick_labels_are_compact() {
        assert_eq!(log_tick_label(1e-5), "1e-5");
        assert_eq!(log_tick_label(f64::from_bits(2e-5f64.to_bits() + 1)), "2e-5");
        assert_eq!(log_tick_label(0.001), "0.001");
        assert_eq!(log_tick_label(0.02), "0.02");
        assert_eq!(log_tick_label(1.0), "1");
        assert_eq!(log_tick_label(300.0), "300");
        assert_eq!(log_tick_label(1e6), "1e6");
        assert_eq!(log_tick_label(2.5e7), "2.5e7");
    }

    #[test]
    fn clipping_keeps_the_box_and_the_direction() {
        let clip = Clip::new((0.0, 1.0), (0.0, 1.0), false, false); // box -10..11 on both axes
        let inside = [(0.0, 0.0), (1.0, 1.0), (0.5, 0.2)];
        assert_eq!(clip.polyline(&inside), vec![inside.to_vec()]);
        // Out to a far point and back: two pieces ending and starting on the box edge x = 11.
        let out_and_back = [(0.0, 0.0), (1e30, 0.0), (0.0, 1.0)];
        let pieces = clip.polyline(&out_and_back);
        assert_eq!(pieces.len(), 2);
        assert_eq!(pieces[0], vec![(0.0, 0.0), (11.0, 0.0)]);
        assert_eq!(pieces[1][1], (0.0, 1.0));
        assert!((pieces[1][0].0 - 11.0).abs() < 1e-9 && (pieces[1][0].1 - 1.0).abs() < 1e-9);
        // A segment crossing the whole box from far away, and one missing it.
        let across = clip.polyline(&[(-f64::MAX, 0.5), (f64::MAX, 0.5)]);
        assert_eq!(across, vec![vec![(-10.0, 0.5), (11.0, 0.5)]]);
        assert!(clip.polyline(&[(-1e9, 50.0), (1e9, 50.0)]).is_empty());
        assert!(clip.polyline(&[(1e9, 0.0)]).is_empty());
        assert_eq!(clip.clamp((1e200, -3.0)), (11.0, -3.0));
        assert_eq!(clip.clamp((0.5, 0.5)), (0.5, 0.5));
        // Ranges near the limits of f64: nothing beyond ±1e300 comes out.
        let clip = Clip::new((-1e300, 1e300), (-1.0, 1.0), false, false);
        let pieces = clip.polyline(&[(-f64::MAX, 0.0), (f64::MAX, 0.0)]);
        assert_eq!(pieces, vec![vec![(-1e300, 0.0), (1e300, 0.0)]]);
        assert_eq!(clip.clamp((f64::MAX, 0.0)), (1e300, 0.0));
        // Log axis: the box is 10 decades beyond each end of 1..10.
        let clip = Clip::new((1.0, 10.0), (10.0, 1.0), true, true);
        assert!(clip.contains((1e-9, 1e11)) && !clip.contains((1e-11, 1.0)));
        let piece = &clip.polyline(&[(1.0, 1.0), (1e40, 1.0)])[0];
        assert!((piece[1].0.log10() - 11.0).abs() < 1e-9 && piece[1].1 == 1.0);
    }

    #[test]
    fn linear_tick_labels_follow_the_spacing() {
        let l = linear_tick_label;
        assert_eq!(l(0.5, (0.0, 10.0)), "0.5");
        assert_eq!(l(2.0, (0.0, 10.0)), "2");
        assert_eq!(l(0.2, (0.0, 1.0)), "0.2");
        assert_eq!(l(0.25, (0.0, 1.0)), "0.25");
        assert_eq!(l(-2.7e-17, (-1.0, 1.0)), "0.0");
        assert_eq!(l(-0.0, (-1.0, 1.0)), "0.0");
        assert_eq!(l(0.1 + 0.2, (-1.0, 1.0)), "0.3");
        assert_eq!(l(900.0, (0.0, 900.0)), "900");
        assert_eq!(l(2e6, (0.0, 1e7)), "2e6");
        assert_eq!(l(2.5e6, (0.0, 1e7)), "2.5e6");
        assert_eq!(l(0.0, (0.0, 1e7)), "0");
        assert_eq!(l(1.00002, (1.0, 1.0002)), "1.00002");
        assert_eq!(l(3e-6, (0.0, 1e-5)), "3e-6");
        assert_eq!(l(0.0, (0.0, 1e-5)), "0");
        assert_eq!(l(f64::NAN, (0.0, 1.0)), "NaN");
    }

    #[test]
    fn log_labels_are_decades_when_the_range_spans_one() {
        assert_eq!(log_label_count(1e-6, 1e-2), 4);
        assert_eq!(log_label_count(1e-2, 1e-6), 4);
        assert_eq!(log_label_count(2.0, 8.0), 10);
    }

    #[test]
    fn range_checks() {
        assert!(range_problem("x", (0.0, 1.0), false).is_none());
        assert!(range_problem("x", (1.0, 0.0), false).is_none());
        assert!(range_problem("x", (0.0, 1.0), true).is_some());
        assert!(range_problem("x", (1.0, 1.0), false).is_some());
        assert!(range_problem("x", (f64::NAN, 1.0), false).is_some());
        assert!(range_problem("x", (-f64::MAX, f64::MAX), false).is_some());
        assert!(range_problem("x", (1e-320, 1.0), true).is_some());
        assert!(range_problem("x", (-1e300, 1e300), false).is_none());
    }
}
