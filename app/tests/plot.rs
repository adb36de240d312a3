//! Tests of `plot`: every chart kind writes a PNG of the requested size, bad data (NaN, ±∞,
//! non-positive values on log axes, empty series) neither panics nor fails, invalid requests
//! give errors naming the file, a waterfall's text (title, axis and scale descriptions) lies
//! inside the image, and CSV tables read back to the same numbers.
//!
//! The images go to the system temp directory and are removed afterwards; set
//! `PLOT_TEST_KEEP=1` to keep them (their paths are printed) for a look.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use helical_gear_app::plot::{
    Heatmap, LineChart, PlotError, Series, SeriesStyle, Waterfall, heatmap, line_chart, waterfall,
    waterfall_rgb, write_csv,
};

/// A fresh file name in the temp directory, unique per process and call.
fn temp_file(name: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("hgm-plot-{}-{n}-{name}", std::process::id()))
}

/// Removes `path` unless `PLOT_TEST_KEEP` is set.
fn done(path: &Path) {
    if std::env::var_os("PLOT_TEST_KEEP").is_some() {
        println!("kept {}", path.display());
    } else {
        let _ = std::fs::remove_file(path);
    }
}

/// Width and height from the IHDR chunk, after checking the PNG signature.
fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).expect("the PNG exists");
    assert!(bytes.len() > 24, "{} is too short for a PNG", path.display());
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR", "IHDR is the first chunk");
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    (be(16), be(20))
}

fn series(name: &str, points: Vec<(f64, f64)>, style: SeriesStyle) -> Series {
    Series { name: name.into(), points, style }
}

fn chart(series: Vec<Series>) -> LineChart {
    LineChart {
        title: "Transmission error".into(),
        x_label: "φp (rad)".into(),
        y_label: "TE (µm)".into(),
        series,
        ..LineChart::default()
    }
}

/// Draws `c` at `size` into a fresh file, checks the PNG and returns its bytes.
fn draw_line_chart(name: &str, c: &LineChart, size: (u32, u32)) -> Vec<u8> {
    let path = temp_file(name);
    line_chart(&path, c, size).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(png_size(&path), size);
    let bytes = std::fs::read(&path).unwrap();
    done(&path);
    bytes
}

/// Synthetic Fig. 7-like data: Hertzian pressure ellipses (MPa) along ζ moving with φp.
fn pressure_curves() -> Vec<(f64, Vec<(f64, f64)>)> {
    (0..25)
        .map(|k| {
            let phi = 0.01 * k as f64;
            let centre = 2.0 + 40.0 * phi;
            let points = (0..=120)
                .map(|i| {
                    let zeta = 0.1 * i as f64;
                    let u = (zeta - centre) / 3.0;
                    (zeta, 900.0 * (1.0 - u * u).max(0.0).sqrt())
                })
                .collect();
            (phi, points)
        })
        .collect()
}

fn pressure_waterfall() -> Waterfall {
    Waterfall {
        title: "Contact pressure".into(),
        x_label: "ζ = z/m_n".into(),
        y_label: "φp (rad)".into(),
        z_label: "contact pressure (MPa)".into(),
        curves: pressure_curves(),
    }
}

#[test]
fn line_chart_writes_a_png_of_the_requested_size() {
    let sine = (0..200).map(|i| (0.05 * i as f64, (0.05 * i as f64).sin())).collect();
    let cosine = (0..40).map(|i| (0.25 * i as f64, (0.25 * i as f64).cos())).collect();
    let c = chart(vec![
        series("sin", sine, SeriesStyle::Line),
        series("cos", cosine, SeriesStyle::LinePoints),
        series("samples", vec![(1.0, 0.5), (2.0, -0.5)], SeriesStyle::Points),
    ]);
    draw_line_chart("line.png", &c, (800, 600));
    draw_line_chart("line-small.png", &c, (64, 64));
    draw_line_chart("line-wide.png", &c, (1500, 300));
}

#[test]
fn work_precision_chart_on_log_axes() {
    let rk4 = (1..8).map(|k| (1e-3 * 2f64.powi(k), 1e-2 / 16f64.powi(k))).collect();
    let dopri = (1..8).map(|k| (2e-3 * 1.5f64.powi(k), 1e-4 / 8f64.powi(k))).collect();
    let c = LineChart {
        title: "Work–precision".into(),
        x_label: "CPU time (s)".into(),
        y_label: "max error (rad)".into(),
        series: vec![
            series("RK4", rk4, SeriesStyle::LinePoints),
            series("Dormand–Prince 5(4)", dopri, SeriesStyle::LinePoints),
        ],
        x_log: true,
        y_log: true,
        ..LineChart::default()
    };
    draw_line_chart("work-precision.png", &c, (700, 500));
}

#[test]
fn nan_and_infinite_points_are_skipped_without_panic() {
    let bad = vec![
        (0.0, 1.0),
        (f64::NAN, 2.0),
        (2.0, f64::NAN),
        (3.0, f64::INFINITY),
        (f64::NEG_INFINITY, 4.0),
        (5.0, 2.0),
    ];
    let only_bad = vec![(f64::NAN, f64::NAN), (f64::INFINITY, 1.0)];
    for style in [SeriesStyle::Line, SeriesStyle::Points, SeriesStyle::LinePoints] {
        let c = chart(vec![
            series("bad", bad.clone(), style),
            series("worse", only_bad.clone(), style),
        ]);
        draw_line_chart("nan.png", &c, (400, 300));
        let log = LineChart { x_log: true, y_log: true, ..c };
        draw_line_chart("nan-log.png", &log, (400, 300));
    }
    // Skipped, not clamped: markers of the bad points leave no trace.
    let with_bad = chart(vec![series("p", bad, SeriesStyle::Points)]);
    let without = chart(vec![series("p", vec![(0.0, 1.0), (5.0, 2.0)], SeriesStyle::Points)]);
    assert_eq!(
        draw_line_chart("nan-a.png", &with_bad, (300, 200)),
        draw_line_chart("nan-b.png", &without, (300, 200))
    );
}

#[test]
fn log_axes_skip_non_positive_values() {
    let points = vec![(1.0, 1.0), (10.0, 0.0), (-3.0, 5.0), (0.0, 2.0), (10.0, -1.0), (100.0, 1e3)];
    let kept = vec![(1.0, 1.0), (100.0, 1e3)];
    for (x_log, y_log) in [(true, false), (false, true), (true, true)] {
        let c = |p: Vec<(f64, f64)>| LineChart {
            x_log,
            y_log,
            ..chart(vec![series("p", p, SeriesStyle::Points)])
        };
        let a = draw_line_chart("log-a.png", &c(points.clone()), (300, 200));
        if x_log && y_log {
            // Every dropped point has a non-positive coordinate on a log axis.
            let b = draw_line_chart("log-b.png", &c(kept.clone()), (300, 200));
            assert_eq!(a, b, "non-positive points are skipped on log–log axes");
        }
    }
    // Nothing positive at all: empty log axes.
    let c = LineChart {
        x_log: true,
        y_log: true,
        ..chart(vec![series("zero", vec![(0.0, 0.0), (-1.0, -1.0)], SeriesStyle::Line)])
    };
    draw_line_chart("log-empty.png", &c, (300, 200));
}

#[test]
fn empty_charts_have_axes() {
    draw_line_chart("empty.png", &chart(vec![]), (320, 240));
    draw_line_chart(
        "empty-series.png",
        &chart(vec![series("none", vec![], SeriesStyle::Line)]),
        (320, 240),
    );
    let untitled = LineChart::default();
    draw_line_chart("untitled.png", &untitled, (320, 240));
    let fixed =
        LineChart { x_range: Some((0.0, 2.0)), y_range: Some((5.0, -5.0)), ..chart(vec![]) };
    draw_line_chart("fixed.png", &fixed, (320, 240));
}

#[test]
fn extreme_values_do_not_panic() {
    let points = vec![(-f64::MAX, f64::MAX), (f64::MAX, -f64::MAX), (5e-324, 1e-300)];
    draw_line_chart(
        "extreme.png",
        &chart(vec![series("x", points.clone(), SeriesStyle::LinePoints)]),
        (300, 200),
    );
    let log = LineChart {
        x_log: true,
        y_log: true,
        ..chart(vec![series("x", points, SeriesStyle::LinePoints)])
    };
    draw_line_chart("extreme-log.png", &log, (300, 200));
    // A fixed range far from the data: the lines are clipped, not overflowed.
    let far = chart(vec![series(
        "x",
        vec![(0.0, 0.0), (1e12, 1e12), (0.5, 1e-9)],
        SeriesStyle::LinePoints,
    )]);
    let zoom = LineChart { x_range: Some((0.0, 1e-6)), y_range: Some((0.0, 1e-6)), ..far };
    draw_line_chart("zoom.png", &zoom, (300, 200));
    let zoom_log = LineChart {
        x_log: true,
        y_log: true,
        x_range: Some((1e-9, 1e-8)),
        y_range: Some((1e-9, 1e-8)),
        ..zoom
    };
    draw_line_chart("zoom-log.png", &zoom_log, (300, 200));
    let same = vec![(1e20, 3.0), (1e20, 3.0)];
    draw_line_chart(
        "degenerate.png",
        &chart(vec![series("x", same, SeriesStyle::Points)]),
        (300, 200),
    );
}

#[test]
fn invalid_requests_are_errors_naming_the_file() {
    let c = chart(vec![series("a", vec![(1.0, 1.0)], SeriesStyle::Line)]);
    let expect_err = |path: &Path, result: Result<(), PlotError>| {
        let e = result.expect_err("an error");
        assert_eq!(e.path(), path);
        let text = e.to_string();
        assert!(text.contains(&path.display().to_string()), "{text}");
        text
    };
    let path = temp_file("line.svg");
    let text = expect_err(&path, line_chart(&path, &c, (300, 200)));
    assert!(text.contains(".png"), "{text}");
    assert!(!path.exists());

    let path = temp_file("tiny.png");
    expect_err(&path, line_chart(&path, &c, (10, 200)));
    expect_err(&path, line_chart(&path, &c, (300, 100_000)));

    let bad_range = LineChart { x_log: true, x_range: Some((0.0, 10.0)), ..c.clone() };
    let text = expect_err(&path, line_chart(&path, &bad_range, (300, 200)));
    assert!(text.contains("logarithmic"), "{text}");
    let empty_range = LineChart { y_range: Some((1.0, 1.0)), ..c.clone() };
    expect_err(&path, line_chart(&path, &empty_range, (300, 200)));
    let nan_range = LineChart { y_range: Some((f64::NAN, 1.0)), ..c.clone() };
    expect_err(&path, line_chart(&path, &nan_range, (300, 200)));

    let missing = temp_file("no-such-dir").join("line.png");
    let e = line_chart(&missing, &c, (300, 200)).expect_err("missing directory");
    assert!(matches!(e, PlotError::Draw { .. }), "{e:?}");
    expect_err(&missing, Err(e));
    expect_err(&missing, waterfall(&missing, &pressure_waterfall(), (300, 200)));
    expect_err(&missing, heatmap(&missing, &Heatmap::from(&pressure_waterfall()), (300, 200)));

    let bad_z = Heatmap { z_range: Some((f64::INFINITY, 0.0)), ..Heatmap::default() };
    expect_err(&path, heatmap(&path, &bad_z, (300, 200)));
}

#[test]
fn waterfall_writes_a_png_of_the_requested_size() {
    let path = temp_file("waterfall.png");
    waterfall(&path, &pressure_waterfall(), (900, 700)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(png_size(&path), (900, 700));
    done(&path);
}

#[test]
fn waterfall_survives_bad_and_empty_data() {
    let mut w = pressure_waterfall();
    w.curves[3].1[10].1 = f64::NAN;
    w.curves[4].1[0].0 = f64::INFINITY;
    w.curves[5].0 = f64::NAN;
    w.curves[6].1.clear();
    w.curves.push((0.5, vec![(f64::NAN, f64::NAN)]));
    let empty = Waterfall { curves: vec![], ..pressure_waterfall() };
    let flat =
        Waterfall { curves: vec![(0.0, vec![(0.0, 0.0), (1.0, 0.0)])], ..Waterfall::default() };
    let single =
        Waterfall { curves: vec![(0.3, vec![(0.0, -1.0), (1.0, 2.0)])], ..Waterfall::default() };
    let extreme = Waterfall {
        curves: vec![
            (0.0, vec![(-f64::MAX, f64::MAX), (f64::MAX, 1.0), (0.0, -f64::MAX)]),
            (f64::MAX, vec![(0.0, 1.0), (1.0, 2.0)]),
            (-f64::MAX, vec![(5e-324, 1.0)]),
        ],
        ..Waterfall::default()
    };
    let cases =
        [("bad", w), ("empty", empty), ("flat", flat), ("single", single), ("extreme", extreme)];
    for (name, w) in cases {
        let path = temp_file(&format!("waterfall-{name}.png"));
        waterfall(&path, &w, (400, 300)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(png_size(&path), (400, 300));
        done(&path);
    }
}

#[test]
fn heatmap_writes_a_png_of_the_requested_size() {
    let path = temp_file("heatmap.png");
    let map = Heatmap::from(&pressure_waterfall());
    heatmap(&path, &map, (900, 600)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(png_size(&path), (900, 600));
    done(&path);

    let mut bad = Heatmap { z_range: Some((0.0, 500.0)), ..map };
    bad.rows[2].1[5].1 = f64::NAN;
    bad.rows[3].0 = f64::INFINITY;
    bad.rows.push((0.4, vec![(1.0, f64::NEG_INFINITY), (f64::NAN, 1.0)]));
    let empty = Heatmap::default();
    let constant =
        Heatmap { rows: vec![(1.0, vec![(0.0, 7.0), (1.0, 7.0)])], ..Heatmap::default() };
    let extreme = Heatmap {
        rows: vec![
            (-f64::MAX, vec![(-f64::MAX, 1.0), (f64::MAX, 2.0), (0.0, f64::MAX)]),
            (f64::MAX, vec![(0.0, -f64::MAX), (5e-324, 0.0)]),
        ],
        ..Heatmap::default()
    };
    let cases = [("bad", bad), ("empty", empty), ("constant", constant), ("extreme", extreme)];
    for (name, map) in cases {
        let path = temp_file(&format!("heatmap-{name}.png"));
        heatmap(&path, &map, (400, 300)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(png_size(&path), (400, 300));
        done(&path);
    }
}

#[test]
fn csv_round_trip_keeps_every_bit() {
    let rows: Vec<Vec<f64>> = vec![
        vec![0.0, 0.1, 1.0 / 3.0],
        vec![-2.5e-300, 1e16, f64::MAX],
        vec![5e-324, -0.0, 123_456.789_012_345_68],
        vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY],
    ];
    let path = temp_file("table.csv");
    write_csv(&path, &["t (s)", "φp (rad)", "p, max (MPa)"], rows.clone())
        .unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t (s),φp (rad),\"p, max (MPa)\""));
    let back: Vec<Vec<f64>> =
        lines.map(|l| l.split(',').map(|f| f.parse::<f64>().unwrap()).collect()).collect();
    assert_eq!(back.len(), rows.len());
    for (a, b) in rows.iter().flatten().zip(back.iter().flatten()) {
        assert!(a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()), "{a} vs {b}");
    }
    done(&path);

    // No header: the first row fixes the width; a wrong width is an error naming the file.
    let path = temp_file("ragged.csv");
    write_csv(&path, &[], [vec![1.0, 2.0], vec![3.0, 4.0]]).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "1,2\n3,4\n");
    let e = write_csv(&path, &["a", "b"], [vec![1.0, 2.0], vec![3.0]]).expect_err("ragged");
    assert!(e.to_string().contains("row 1 has 1 values, expected 2"), "{e}");
    assert!(e.to_string().contains(&path.display().to_string()), "{e}");
    done(&path);

    let missing = temp_file("no-such-dir").join("t.csv");
    let e = write_csv(&missing, &["a"], [vec![1.0]]).expect_err("missing directory");
    assert!(matches!(e, PlotError::Io { .. }) && e.to_string().contains("t.csv"), "{e}");
}

/// Rows and columns of `rgb` (width `w`) that hold a dark pixel (any channel below 128).
fn ink(rgb: &[u8], (w, h): (u32, u32)) -> (Vec<bool>, Vec<bool>) {
    let (mut rows, mut cols) = (vec![false; h as usize], vec![false; w as usize]);
    for (i, px) in rgb.chunks_exact(3).enumerate() {
        if px.iter().any(|&c| c < 128) {
            rows[i / w as usize] = true;
            cols[i % w as usize] = true;
        }
    }
    (rows, cols)
}

#[test]
fn waterfall_text_lies_inside_the_image() {
    // The paper run's dynamic waterfalls at 1000 × 800 px: a long title, and long axis and
    // scale descriptions. The text must not touch the image's edges (clipped text does), and
    // the title band must hold ink away from both sides.
    let long = Waterfall {
        title: "Contact pressure at ω_p = 532 rad/s (this model's omega_crit resonance)".into(),
        x_label: "ζ = z/m_n".into(),
        y_label: "time (ms)".into(),
        z_label: "contact pressure (MPa)".into(),
        curves: pressure_curves().into_iter().map(|(o, p)| (1e3 * o, p)).collect(),
    };
    let longer = Waterfall {
        title: "A title far longer than any image is wide: ".repeat(3),
        curves: pressure_curves().into_iter().map(|(o, p)| (-123.456 + o, p)).collect(),
        ..long.clone()
    };
    for (w, size) in [(&long, (1000, 800)), (&long, (400, 300)), (&longer, (1000, 800))] {
        let rgb = waterfall_rgb(w, size).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(rgb.len(), 3 * (size.0 * size.1) as usize);
        let (rows, cols) = ink(&rgb, size);
        let edge = 2;
        let margin = |v: &[bool]| v[..edge].iter().chain(&v[v.len() - edge..]).any(|&b| b);
        assert!(!margin(&cols), "{size:?}: ink in the left or right edge columns: {:.40}", w.title);
        assert!(!margin(&rows), "{size:?}: ink in the top or bottom edge rows: {:.40}", w.title);
        // The title band (the top tenth of the image) holds the title, inside the edges.
        let band = size.1 as usize / 10;
        let (mut left, mut right) = (usize::MAX, 0);
        for (i, px) in rgb[..3 * size.0 as usize * band].chunks_exact(3).enumerate() {
            if px.iter().any(|&c| c < 128) {
                left = left.min(i % size.0 as usize);
                right = right.max(i % size.0 as usize);
            }
        }
        assert!(left < right, "{size:?}: no title drawn");
        assert!(left > edge && right < size.0 as usize - edge, "{size:?}: title {left}..{right}");
    }
}
