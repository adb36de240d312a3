//! Figures in the hand-written guides come from the generated reports: every measured number
//! that `README.md` or `docs/fmus.md` quotes must appear in a generated report
//! (`docs/bench/*.md`, `docs/bench/*.json`, `docs/performance.md`, `docs/paper/summary.*`,
//! `docs/fmu/*.md`), at the precision it is quoted with.
//!
//! A figure here is a number followed by `%` or `×` (or preceded by `×`), a decimal number
//! (with a decimal point or an exponent) followed by a unit, or any number followed by a unit
//! of time or size (`s`, `ms`, `µs`, `ns`, `min`, `MB`, `kB`, `B`): what a measurement prints.
//! Code blocks, inline code and HTML comments are not read. Numbers that are inputs or
//! definitions rather than measurements (Table 1's data, step sizes the user chooses, limits
//! that tests assert) are in [`ALLOWED`], each with its reason.

use std::path::{Path, PathBuf};

/// Figures (number and unit as the guide writes them) that are inputs or definitions, not
/// measurements, with the reason.
const ALLOWED: &[(&str, &str)] = &[
    ("3 mm", "Table 1 input: the normal module m_n"),
    ("15 mm", "Table 1 input: face width b and bore diameter"),
    ("0.015·m_n", "Table 1 input: basic-rack tip relief depth"),
    ("0.5·m_n", "Table 1 input: basic-rack tip relief height"),
    ("0.05·m_n", "Table 1 input: tip rounding radius"),
    ("1 ms", "a communication step the user chooses (H = 1 ms)"),
    ("1 s", "the definition of a rate (simulated s per wall s) or a chosen run length"),
    ("100 N·m", "Table 1 input: the driving torque"),
    ("1 N·m", "the smallest design torque of the table, a definition in the code"),
    ("1e9 N·m", "the largest design torque of the table, the range of an option"),
    ("6.5 MB", "the limit tests/python/test_sizes.py asserts on every zipped FMU"),
    ("8 MB", "the limit tests/python/test_sizes.py asserts on the linux64 library"),
];

/// Units that make a decimal number a figure.
const UNITS: &[&str] = &[
    "µm", "mm", "ms", "µs", "ns", "min", "MB", "kB", "rad/s", "N·m", "N/µm", "kg·m²", "GPa", "MPa",
    "Hz", "s", "B", "m", "·m_n",
];
/// Units that make any number (integers too) a figure: times and sizes.
const MEASURED_UNITS: &[&str] = &["ms", "µs", "ns", "min", "MB", "kB", "s", "B"];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `text` without fenced code blocks, HTML comments and inline code spans.
fn prose(text: &str) -> String {
    let mut out = String::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            out.push_str(line);
            out.push('\n');
        }
    }
    let mut s = String::new();
    let mut rest = out.as_str();
    while let Some(i) = rest.find("<!--") {
        s.push_str(&rest[..i]);
        rest = rest[i..].find("-->").map_or("", |j| &rest[i + j + 3..]);
    }
    s.push_str(rest);
    // Inline code spans and link targets.
    let mut t = String::new();
    let mut in_code = false;
    for c in s.chars() {
        if c == '`' {
            in_code = !in_code;
            t.push(' ');
        } else if !in_code {
            t.push(c);
        }
    }
    let mut u = String::new();
    let mut rest = t.as_str();
    while let Some(i) = rest.find("](") {
        u.push_str(&rest[..i + 1]);
        rest = rest[i..].find(')').map_or("", |j| &rest[i + j + 1..]);
    }
    u.push_str(rest);
    u
}

const SUPERSCRIPTS: &[(char, char)] = &[
    ('⁰', '0'),
    ('¹', '1'),
    ('²', '2'),
    ('³', '3'),
    ('⁴', '4'),
    ('⁵', '5'),
    ('⁶', '6'),
    ('⁷', '7'),
    ('⁸', '8'),
    ('⁹', '9'),
    ('⁻', '-'),
];

/// A number read at byte `i` of `s`: its value, significant digits, whether it has a decimal
/// point or exponent, and the byte after it. Reads `12.5`, `6.5e-7`, `8.9·10⁻⁸`, `15 362`.
fn number_at(s: &str, i: usize) -> Option<(f64, usize, bool, usize)> {
    let b = s.as_bytes();
    if !b.get(i)?.is_ascii_digit() {
        return None;
    }
    let mut j = i;
    let mut mantissa = String::new();
    while j < b.len() && b[j].is_ascii_digit() {
        mantissa.push(b[j] as char);
        j += 1;
        // Digit groups separated by a thin or ordinary space: "15 362" (exactly three digits).
        for sep in ["\u{2009}", "\u{202f}", " "] {
            let g = j + sep.len();
            if s[j..].starts_with(sep)
                && b.len() >= g + 3
                && b[g..g + 3].iter().all(u8::is_ascii_digit)
                && !b.get(g + 3).is_some_and(u8::is_ascii_digit)
                && mantissa.len() <= 3
            {
                mantissa.push_str(&s[g..g + 3]);
                j = g + 3;
            }
        }
    }
    let mut decimal = false;
    if b.get(j) == Some(&b'.') && b.get(j + 1).is_some_and(u8::is_ascii_digit) {
        decimal = true;
        mantissa.push('.');
        j += 1;
        while j < b.len() && b[j].is_ascii_digit() {
            mantissa.push(b[j] as char);
            j += 1;
        }
    }
    let mut exp = 0i32;
    if (b.get(j) == Some(&b'e') || b.get(j) == Some(&b'E'))
        && let Some(k) = (j + 1..(j + 3).min(b.len()))
            .find(|&k| b[k].is_ascii_digit())
            .filter(|&k| b[j + 1..k].iter().all(|&c| c == b'-' || c == b'+'))
    {
        let mut e = k;
        while e < b.len() && b[e].is_ascii_digit() {
            e += 1;
        }
        exp = s[j + 1..e].parse().ok()?;
        decimal = true;
        j = e;
    } else if s[j..].starts_with("·10") {
        let mut e = j + "·10".len();
        let mut digits = String::new();
        for c in s[e..].chars() {
            match SUPERSCRIPTS.iter().find(|(sup, _)| *sup == c) {
                Some((_, d)) => {
                    digits.push(*d);
                    e += c.len_utf8();
                }
                None => break,
            }
        }
        if !digits.is_empty() {
            exp = digits.parse().ok()?;
            decimal = true;
            j = e;
        }
    }
    let sig = mantissa.trim_start_matches(['0', '.']).chars().filter(char::is_ascii_digit).count();
    let v: f64 = mantissa.parse::<f64>().ok()? * 10f64.powi(exp);
    Some((v, sig.max(1), decimal, j))
}

/// Every number of `s` (a report): value and its byte position.
fn numbers(s: &str) -> Vec<f64> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        if s.is_char_boundary(i)
            && (i == 0 || !s.as_bytes()[i - 1].is_ascii_digit())
            && let Some((v, _, _, j)) = number_at(s, i)
        {
            out.push(v);
            i = j;
            continue;
        }
        i += 1;
    }
    out
}

/// One figure of a guide: the text it is matched by, its value and significant digits.
#[derive(Debug)]
struct Figure {
    text: String,
    values: Vec<(f64, usize)>,
    unit: String,
    decimal: bool,
    context: String,
}

/// The figures of a guide's prose; with `every`, every number with a unit, `%` or `×` (how a
/// report is read).
fn figures_of(text: &str, every: bool) -> Vec<Figure> {
    let s = if every { text.to_string() } else { prose(text) };
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        let starts = s.is_char_boundary(i)
            && (i == 0
                || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_' || b[i - 1] == b'.'))
            && !s[..i].ends_with("T_m/");
        let Some((v, sig, decimal, mut j)) = starts.then(|| number_at(&s, i)).flatten() else {
            i += 1;
            continue;
        };
        let mut values = vec![(v, sig)];
        // A range "5–30×": both ends take the unit.
        for dash in ["–", "-"] {
            if s[j..].starts_with(dash)
                && let Some((v2, sig2, _, j2)) = number_at(&s, j + dash.len())
            {
                values.push((v2, sig2));
                j = j2;
                break;
            }
        }
        let after = s[j..].strip_prefix(' ').or_else(|| s[j..].strip_prefix('\u{a0}'));
        let after = after.unwrap_or(&s[j..]);
        let unit_end = |u: &str| {
            after.starts_with(u)
                && !after[u.len()..].chars().next().is_some_and(|c| c.is_alphanumeric() || c == '_')
        };
        let times_before = s[..i].trim_end().ends_with('×');
        let unit = if after.starts_with('%') || after.starts_with('×') || times_before {
            Some(if times_before {
                "×".to_string()
            } else {
                after[..after.chars().next().unwrap().len_utf8()].to_string()
            })
        } else {
            UNITS
                .iter()
                .find(|u| unit_end(u) && (every || decimal || MEASURED_UNITS.contains(u)))
                .map(|u| u.to_string())
        };
        if let Some(unit) = unit {
            let number = &s[i..j];
            let sep = if unit == "%" || unit == "×" || unit.starts_with('·') { "" } else { " " };
            let line_start = s[..i].rfind('\n').map_or(0, |k| k + 1);
            let line_end = s[j..].find('\n').map_or(s.len(), |k| j + k);
            out.push(Figure {
                text: format!("{number}{sep}{unit}"),
                values,
                unit: unit.clone(),
                decimal,
                context: s[line_start..line_end].to_string(),
            });
        }
        i = j.max(i + 1);
    }
    out
}

/// The figures of a guide's prose.
fn figures(text: &str) -> Vec<Figure> {
    figures_of(text, false)
}

/// True when a report number rounds to `v` at `sig` significant digits.
fn rounds_to(report: f64, v: f64, sig: usize) -> bool {
    let (r, v) = (report.abs(), v.abs());
    if v == 0.0 {
        return r == 0.0;
    }
    let e = v.log10().floor() as i32 - (sig as i32 - 1);
    let scale = 10f64.powi(e);
    ((r / scale).round() - v / scale).abs() < 1e-6
}

/// What the generated reports say: every number with its unit in the pages (value, unit), and
/// every number of the JSON reports (whose keys carry the units).
struct Reports {
    figures: Vec<(f64, String)>,
    json: Vec<f64>,
}

fn reports() -> Reports {
    let root = root();
    let mut files: Vec<PathBuf> = Vec::new();
    for (dir, exts) in [
        ("docs/bench", &["md", "json"][..]),
        ("docs/fmu", &["md"][..]),
        ("docs/paper", &["md", "json"][..]),
    ] {
        for e in std::fs::read_dir(root.join(dir)).unwrap_or_else(|e| panic!("{dir}: {e}")) {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            let ext_ok = p.extension().is_some_and(|x| exts.iter().any(|e| x == *e));
            if ext_ok && (dir != "docs/paper" || name.starts_with("summary.")) {
                files.push(p);
            }
        }
    }
    files.push(root.join("docs/performance.md"));
    let mut r = Reports { figures: Vec::new(), json: Vec::new() };
    for p in files {
        let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        if p.extension().is_some_and(|x| x == "json") {
            r.json.extend(numbers(&text));
        } else {
            for f in figures_of(&text, true) {
                for (v, _) in f.values {
                    r.figures.push((v, f.unit.clone()));
                }
            }
        }
    }
    r
}

impl Reports {
    /// True when a report has `v` (at `sig` significant digits) with `unit`, or, for a decimal
    /// of at least two significant digits, anywhere in a JSON report.
    fn has(&self, v: f64, sig: usize, unit: &str, decimal: bool) -> bool {
        self.figures.iter().any(|(r, u)| u == unit && rounds_to(*r, v, sig))
            || (decimal && sig >= 2 && self.json.iter().any(|&r| rounds_to(r, v, sig)))
    }
}

#[test]
fn the_scanner_reads_the_forms_of_a_figure() {
    let f = figures("a 5–30× b, 33.8 MB, 4.4e-5 s, 8.9·10⁻⁸ s, 2 s, z = 30 teeth, `7.5 s`, 12 %");
    let texts: Vec<_> = f.iter().map(|f| f.text.as_str()).collect();
    assert_eq!(texts, ["5–30×", "33.8 MB", "4.4e-5 s", "8.9·10⁻⁸ s", "2 s", "12%"]);
    assert_eq!(f[0].values, [(5.0, 1), (30.0, 2)]);
    assert!((f[3].values[0].0 - 8.9e-8).abs() < 1e-20);
    assert!(rounds_to(31.4123, 31.4, 3) && !rounds_to(31.46, 31.4, 3));
    assert_eq!(numbers("15 362 evaluations, 2.96 ms"), [15362.0, 2.96]);
}

#[test]
fn guides_quote_only_generated_figures() {
    let report = reports();
    let mut missing = Vec::new();
    for guide in ["README.md", "docs/fmus.md"] {
        let text = std::fs::read_to_string(root().join(guide)).unwrap();
        for f in figures(&text) {
            if ALLOWED.iter().any(|(a, _)| *a == f.text) {
                continue;
            }
            let found = f.values.iter().all(|&(v, sig)| report.has(v, sig, &f.unit, f.decimal));
            if !found {
                missing.push(format!("{guide}: `{}` in: {}", f.text, f.context.trim()));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "figures that no generated report (docs/bench, docs/performance.md, docs/paper/summary.*, \
         docs/fmu) has; link the generated page instead, or add an input or definition to \
         ALLOWED with its reason:\n{}",
        missing.join("\n")
    );
}
