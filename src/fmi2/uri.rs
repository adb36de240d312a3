//! Decoding of the resource-location URI passed to `fmi2Instantiate`.
//!
//! Importers write the `resources/` directory of the unpacked FMU as a `file` URI in several
//! spellings: `file:///abs/path` (RFC 8089), `file://localhost/abs/path`, and the short
//! `file:/abs/path`. Reserved and non-ASCII bytes are percent-encoded (`%20` for a space).

use std::path::PathBuf;

/// Decodes a `file:` URI into a local path.
///
/// Errors (as text naming the URI and the rule) for other schemes, for a host other than empty
/// or `localhost`, and for malformed percent escapes.
pub fn file_uri_to_path(uri: &str) -> Result<PathBuf, String> {
    let rest = match uri.get(..5) {
        Some(s) if s.eq_ignore_ascii_case("file:") => &uri[5..],
        _ => return Err(format!("resource location `{uri}` is not a file: URI")),
    };
    let path = if let Some(after) = rest.strip_prefix("//") {
        // Authority up to the next '/'.
        let (host, path) = match after.find('/') {
            Some(i) => (&after[..i], &after[i..]),
            None => (after, "/"),
        };
        if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
            return Err(format!(
                "resource location `{uri}` names host `{host}`: only local files (no host or \
                 `localhost`) are supported"
            ));
        }
        path
    } else if rest.starts_with('/') {
        rest
    } else {
        return Err(format!("resource location `{uri}` is not an absolute file: URI"));
    };
    let bytes = percent_decode(path).map_err(|e| format!("resource location `{uri}`: {e}"))?;
    Ok(bytes_to_path(bytes))
}

fn percent_decode(s: &str) -> Result<Vec<u8>, String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = b.get(i + 1..i + 3).ok_or_else(|| format!("truncated escape at byte {i}"))?;
            let text = std::str::from_utf8(hex).map_err(|_| format!("bad escape at byte {i}"))?;
            let v = u8::from_str_radix(text, 16)
                .map_err(|_| format!("bad escape `%{text}` at byte {i}"))?;
            out.push(v);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    Ok(out)
}

#[cfg(unix)]
fn bytes_to_path(bytes: Vec<u8>) -> PathBuf {
    use std::os::unix::ffi::OsStringExt;
    PathBuf::from(std::ffi::OsString::from_vec(bytes))
}

#[cfg(not(unix))]
fn bytes_to_path(bytes: Vec<u8>) -> PathBuf {
    let s = String::from_utf8_lossy(&bytes).into_owned();
    // `file:///C:/dir` decodes to `/C:/dir`; drop the slash before a drive letter.
    let t = match s.as_bytes() {
        [b'/', d, b':', ..] if d.is_ascii_alphabetic() => s[1..].to_string(),
        _ => s,
    };
    PathBuf::from(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spellings_of_a_local_file_uri() {
        let p = PathBuf::from("/tmp/my fmu/resources");
        assert_eq!(file_uri_to_path("file:///tmp/my%20fmu/resources").unwrap(), p);
        assert_eq!(file_uri_to_path("file:/tmp/my%20fmu/resources").unwrap(), p);
        assert_eq!(file_uri_to_path("file://localhost/tmp/my%20fmu/resources").unwrap(), p);
        assert_eq!(file_uri_to_path("FILE:///tmp/my fmu/resources").unwrap(), p);
        assert_eq!(
            file_uri_to_path("file:///tmp/a%25b/%C3%A4/").unwrap(),
            PathBuf::from("/tmp/a%b/ä/")
        );
    }

    #[test]
    fn bad_uris_are_named() {
        for (uri, what) in [
            ("http://x/y", "not a file: URI"),
            ("file://server/share", "host `server`"),
            ("file:relative/path", "not an absolute"),
            ("file:///a%2", "truncated escape"),
            ("file:///a%zz", "bad escape `%zz`"),
            ("", "not a file: URI"),
        ] {
            let e = file_uri_to_path(uri).unwrap_err();
            assert!(e.contains(what), "{uri}: {e}");
        }
    }
}
