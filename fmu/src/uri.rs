//! The `fmuResourceLocation` of `fmi2Instantiate` as a path.
//!
//! FMI 2.0 passes the unpacked `resources/` folder as a URI (RFC 3986), in practice
//! `file:///abs/path/resources/` — some importers write `file:/abs/path` or
//! `file://localhost/abs/path`, some percent-encode spaces and non-ASCII bytes (`%20`). This
//! module accepts those forms (and, leniently, a plain absolute path) and refuses other schemes
//! and hosts, with a message naming the location.

use std::ffi::OsString;
use std::os::unix::ffi::OsStringExt;
use std::path::PathBuf;

/// The local folder named by the resource location `uri`.
pub fn resource_dir(uri: &str) -> Result<PathBuf, String> {
    let path = if let Some(rest) = strip_prefix_ignore_case(uri, "file:") {
        if let Some(after) = rest.strip_prefix("//") {
            // An authority: empty or `localhost` only (a local file).
            let slash = after.find('/').unwrap_or(after.len());
            let host = &after[..slash];
            if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
                return Err(format!(
                    "fmuResourceLocation `{uri}` names the host `{host}`: only local files \
                     (file:///path) can be read"
                ));
            }
            &after[slash..]
        } else {
            rest
        }
    } else if uri.starts_with('/') {
        uri
    } else {
        return Err(format!(
            "fmuResourceLocation `{uri}` is not a file: URI (expected file:///path/to/resources)"
        ));
    };
    if !path.starts_with('/') {
        return Err(format!(
            "fmuResourceLocation `{uri}` does not name an absolute path"
        ));
    }
    let bytes = percent_decode(path).ok_or_else(|| {
        format!("fmuResourceLocation `{uri}` has a malformed percent escape (%XX)")
    })?;
    if bytes.contains(&0) {
        return Err(format!("fmuResourceLocation `{uri}` encodes a NUL byte"));
    }
    Ok(PathBuf::from(OsString::from_vec(bytes)))
}

/// `text` without `prefix` (ASCII case-insensitive), if it starts with it.
fn strip_prefix_ignore_case<'a>(text: &'a str, prefix: &str) -> Option<&'a str> {
    let head = text.get(..prefix.len())?;
    head.eq_ignore_ascii_case(prefix)
        .then(|| &text[prefix.len()..])
}

/// The bytes of `text` with every `%XX` (two hex digits) decoded; `None` for a `%` not followed
/// by two hex digits.
fn percent_decode(text: &str) -> Option<Vec<u8>> {
    let b = text.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = text.get(i + 1..i + 3)?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_usual_forms_give_the_same_path() {
        for uri in [
            "file:///tmp/fmu x/resources/",
            "file:/tmp/fmu x/resources/",
            "file://localhost/tmp/fmu x/resources/",
            "FILE:///tmp/fmu%20x/resources/",
            "/tmp/fmu x/resources/",
        ] {
            assert_eq!(
                resource_dir(uri).unwrap(),
                PathBuf::from("/tmp/fmu x/resources/"),
                "{uri}"
            );
        }
        assert_eq!(
            resource_dir("file:///tmp/%C3%A9t%C3%A9").unwrap(),
            PathBuf::from("/tmp/été")
        );
    }

    #[test]
    fn other_schemes_hosts_and_bad_escapes_are_refused() {
        for (uri, why) in [
            ("http://example.org/resources", "not a file"),
            ("file://server/share/resources", "host `server`"),
            ("file:relative/resources", "absolute"),
            ("resources", "not a file"),
            ("file:///tmp/%zz", "percent"),
            ("file:///tmp/%2", "percent"),
            ("file:///tmp/%00x", "NUL"),
            ("", "not a file"),
        ] {
            let e = resource_dir(uri).unwrap_err();
            assert!(e.contains(why), "{uri}: {e}");
        }
    }
}
