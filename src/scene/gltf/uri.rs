//! glTF buffer URIs: base64 `data:` URIs and relative, percent-encoded file paths.

use base64::Engine;

/// What a buffer URI refers to.
#[derive(Debug, PartialEq)]
pub enum UriTarget {
    /// The decoded bytes of a `data:` URI.
    Data(Vec<u8>),
    /// A path relative to the glTF file, percent-decoded.
    File(String),
}

/// Resolves a buffer URI. Errors are one line describing the problem (the caller adds the file name).
pub fn resolve(uri: &str) -> Result<UriTarget, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest.split_once(',').ok_or("data URI has no ',' before its payload")?;
        if !header.ends_with(";base64") {
            return Err(format!("data URI '{}' is not base64", truncate(uri)));
        }
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(payload.trim())
            .map_err(|e| format!("data URI is not valid base64: {e}"))?;
        return Ok(UriTarget::Data(bytes));
    }
    if uri.contains("://") {
        return Err(format!("URI '{}' is not a relative file path (network URIs are not fetched)", truncate(uri)));
    }
    Ok(UriTarget::File(percent_decode(uri)?))
}

fn percent_decode(s: &str) -> Result<String, String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = s.get(i + 1..i + 3).ok_or_else(|| format!("URI '{s}' has a truncated %-escape"))?;
            out.push(u8::from_str_radix(hex, 16).map_err(|_| format!("URI '{s}' has a bad %-escape '%{hex}'"))?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("URI '{s}' does not decode to UTF-8"))
}

fn truncate(s: &str) -> String {
    if s.len() <= 48 {
        s.to_string()
    } else {
        format!("{}…", &s[..s.char_indices().nth(40).map_or(s.len(), |(i, _)| i)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decodes_data_uris() {
        assert_eq!(
            resolve("data:application/octet-stream;base64,AAEC/w==").unwrap(),
            UriTarget::Data(vec![0, 1, 2, 255])
        );
        assert_eq!(resolve("data:application/gltf-buffer;base64,").unwrap(), UriTarget::Data(vec![]));
        assert!(resolve("data:text/plain,hello").unwrap_err().contains("not base64"));
        assert!(resolve("data:application/octet-stream;base64,@@@").unwrap_err().contains("base64"));
        assert!(resolve("data:application/octet-stream;base64").is_err());
    }

    #[test]
    fn decodes_paths() {
        assert_eq!(resolve("my%20mesh.bin").unwrap(), UriTarget::File("my mesh.bin".into()));
        assert_eq!(resolve("sub/a.bin").unwrap(), UriTarget::File("sub/a.bin".into()));
        assert!(resolve("a%2").is_err());
        assert!(resolve("a%zz").is_err());
        assert!(resolve("https://example.com/a.bin").is_err());
    }
}
