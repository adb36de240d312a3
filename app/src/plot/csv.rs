//! The numbers behind a figure as a CSV table.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use super::PlotError;

/// Writes a CSV table: one header line (omitted if `header` is empty), then one line per row.
///
/// Numbers are written at full precision: the shortest decimal text that parses back to the
/// same `f64` (`1e-7`-style exponents outside 10⁻⁵ ≤ |v| < 10¹⁶); non-finite values are written
/// as `NaN`, `inf`, `-inf`. Header fields containing a comma, quote or line break are quoted
/// (RFC 4180). Every row must have as many values as the header has names (without a header,
/// as the first row); otherwise the writing stops with [`PlotError::Invalid`] and the file is
/// left incomplete.
pub fn write_csv(
    path: &Path,
    header: &[&str],
    rows: impl IntoIterator<Item = Vec<f64>>,
) -> Result<(), PlotError> {
    let io = |source| PlotError::Io { path: path.to_path_buf(), source };
    let mut out = BufWriter::new(File::create(path).map_err(io)?);
    let mut width = (!header.is_empty()).then_some(header.len());
    if !header.is_empty() {
        let fields: Vec<String> = header.iter().map(|h| quote(h)).collect();
        writeln!(out, "{}", fields.join(",")).map_err(io)?;
    }
    for (i, row) in rows.into_iter().enumerate() {
        let expected = *width.get_or_insert(row.len());
        if row.len() != expected {
            return Err(PlotError::invalid(
                path,
                format!("row {i} has {} values, expected {expected}", row.len()),
            ));
        }
        let fields: Vec<String> = row.iter().map(|&v| number(v)).collect();
        writeln!(out, "{}", fields.join(",")).map_err(io)?;
    }
    out.flush().map_err(io)
}

/// Shortest round-trip text of `v`.
fn number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !v.is_finite() || (1e-5..1e16).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A header field, quoted if needed.
fn quote(field: &str) -> String {
    if field.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", field.replace('"', "\"\""))
    } else {
        field.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_round_trip_and_stay_short() {
        for v in [0.1, 1.0 / 3.0, -2.5e-300, 1e16, 123456.789, 5e-324, f64::MAX, 1e-5, -0.0] {
            let s = number(v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
        assert_eq!(number(0.1), "0.1");
        assert_eq!(number(1e-7), "1e-7");
        assert_eq!(number(f64::NAN), "NaN");
        assert_eq!(number(f64::NEG_INFINITY), "-inf");
    }

    #[test]
    fn header_fields_are_quoted_when_needed() {
        assert_eq!(quote("t (s)"), "t (s)");
        assert_eq!(quote("a,b"), "\"a,b\"");
        assert_eq!(quote("say \"x\""), "\"say \"\"x\"\"\"");
    }
}
