//! The GLB container (glTF 2.0 spec, "Binary glTF Layout"): a 12-byte header (magic `glTF`, version 2, total
//! length), a JSON chunk, then an optional BIN chunk; each chunk is `length: u32, type: u32, data`, 4-byte aligned.
//!
//! Every length is checked against the bytes actually present before anything is sliced, so a chunk length past
//! the end of the file is an error, not a panic or an allocation of what the header claims.

/// The two chunks sunshade uses.
#[derive(Debug, PartialEq)]
pub struct Glb<'a> {
    pub json: &'a [u8],
    pub bin: Option<&'a [u8]>,
}

const MAGIC: u32 = 0x4654_6C67; // "glTF"
const CHUNK_JSON: u32 = 0x4E4F_534A; // "JSON"
const CHUNK_BIN: u32 = 0x004E_4942; // "BIN\0"

/// Whether the bytes start like a GLB file (otherwise they are taken as glTF JSON).
pub fn is_glb(bytes: &[u8]) -> bool {
    bytes.len() >= 4 && u32_at(bytes, 0) == Some(MAGIC)
}

/// Splits a GLB file into its chunks.
pub fn parse(bytes: &[u8]) -> Result<Glb<'_>, String> {
    let header = |at| u32_at(bytes, at).ok_or("invalid GLB container: the file is shorter than its 12-byte header");
    if header(0)? != MAGIC {
        return Err("invalid GLB container: no 'glTF' magic".into());
    }
    let version = header(4)?;
    if version != 2 {
        return Err(format!("invalid GLB container: version {version} (sunshade reads glTF 2.0)"));
    }
    let length = header(8)? as usize;
    if length > bytes.len() {
        return Err(format!(
            "invalid GLB container: header length {length} is past the end of the file ({} bytes)",
            bytes.len()
        ));
    }
    let body = &bytes[..length];
    let mut chunks = Vec::new();
    let mut at = 12usize;
    while at < body.len() {
        let (Some(len), Some(kind)) = (u32_at(body, at), u32_at(body, at + 4)) else {
            return Err(format!("invalid GLB container: chunk header at byte {at} is cut off"));
        };
        let start = at + 8;
        let end = start.checked_add(len as usize).filter(|&e| e <= body.len()).ok_or_else(|| {
            format!(
                "invalid GLB container: chunk at byte {at} declares {len} bytes, past the end of the file ({} bytes)",
                body.len()
            )
        })?;
        chunks.push((kind, &body[start..end]));
        // Chunks are padded to 4 bytes; a writer that did not pad still has its next chunk right after.
        at = end;
    }
    let json = match chunks.first() {
        Some(&(CHUNK_JSON, data)) => data,
        _ => return Err("invalid GLB container: the first chunk is not JSON".into()),
    };
    let bin = match chunks.get(1) {
        Some(&(CHUNK_BIN, data)) => Some(data),
        _ => None,
    };
    Ok(Glb { json, bin })
}

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
        let mut out = Vec::new();
        let chunk = |out: &mut Vec<u8>, kind: u32, data: &[u8]| {
            out.extend((data.len() as u32).to_le_bytes());
            out.extend(kind.to_le_bytes());
            out.extend(data);
        };
        out.extend(MAGIC.to_le_bytes());
        out.extend(2u32.to_le_bytes());
        out.extend(0u32.to_le_bytes());
        chunk(&mut out, CHUNK_JSON, json);
        if let Some(b) = bin {
            chunk(&mut out, CHUNK_BIN, b);
        }
        let n = out.len() as u32;
        out[8..12].copy_from_slice(&n.to_le_bytes());
        out
    }

    #[test]
    fn reads_both_chunks() {
        let bytes = glb(b"{}  ", Some(&[1, 2, 3, 4]));
        assert!(is_glb(&bytes));
        assert_eq!(parse(&bytes).unwrap(), Glb { json: b"{}  ", bin: Some(&[1, 2, 3, 4]) });
        assert_eq!(parse(&glb(b"{}  ", None)).unwrap().bin, None);
    }

    #[test]
    fn lengths_past_the_file_are_errors() {
        let good = glb(b"{}  ", Some(&[0; 8]));
        for cut in 0..good.len() {
            assert!(parse(&good[..cut]).is_err(), "accepted a file cut at {cut}");
        }
        let mut huge_chunk = good.clone();
        huge_chunk[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(parse(&huge_chunk).unwrap_err().contains("past the end"));
        let mut huge_total = good.clone();
        huge_total[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(parse(&huge_total).unwrap_err().contains("past the end"));
        let mut v1 = good;
        v1[4] = 1;
        assert!(parse(&v1).unwrap_err().contains("version 1"));
    }
}
