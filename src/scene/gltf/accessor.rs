//! Bounds-checked reading of glTF accessors.
//!
//! Every byte range is computed with checked arithmetic and checked against its buffer view and buffer before it
//! is read, so a malformed file gives an error naming the accessor instead of a panic or a huge allocation.
//! An accessor without a buffer view is all zeros (glTF 2.0 §3.6.2.1), optionally with sparse values on top.
//! Components are returned as f64, which holds every glTF component type exactly; `normalized` integers are
//! mapped to [0, 1] or [−1, 1] by the spec's formulas (§3.11, e.g. `max(c / 127, −1)` for signed bytes), which
//! KHR_mesh_quantization relies on.

use super::document::{lookup, AccessorDef, BufferViewDef, Index, Root};

/// The most elements one accessor may have: 2^25 (33.5 M). A vertex stream that long already needs over 1 GiB on
/// the device; the bound keeps a declared count of 2^31 or 2^64 − 1 from allocating before anything is read.
pub const MAX_ACCESSOR_ELEMENTS: u64 = 1 << 25;

/// glTF component types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Component {
    I8,
    U8,
    I16,
    U16,
    U32,
    F32,
}

impl Component {
    pub fn from_gl(code: u64) -> Option<Self> {
        Some(match code {
            5120 => Self::I8,
            5121 => Self::U8,
            5122 => Self::I16,
            5123 => Self::U16,
            5125 => Self::U32,
            5126 => Self::F32,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::U32 | Self::F32 => 4,
        }
    }

    fn read(self, b: &[u8]) -> f64 {
        match self {
            Self::I8 => b[0] as i8 as f64,
            Self::U8 => b[0] as f64,
            Self::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Self::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Self::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Self::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        }
    }

    /// The normalized value of an integer component (glTF 2.0 §3.11).
    fn normalize(self, c: f64) -> f64 {
        match self {
            Self::I8 => (c / 127.0).max(-1.0),
            Self::U8 => c / 255.0,
            Self::I16 => (c / 32767.0).max(-1.0),
            Self::U16 => c / 65535.0,
            Self::U32 | Self::F32 => c,
        }
    }
}

/// Components per element of an accessor `type`.
fn multiplicity(kind: &str) -> Option<usize> {
    Some(match kind {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" | "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        _ => return None,
    })
}

/// Reads accessors out of the loaded buffers.
pub struct AccessorReader<'a> {
    pub root: &'a Root,
    /// Buffer contents, indexed like the glTF `buffers` array.
    pub buffers: &'a [Vec<u8>],
}

/// An accessor's data: `n` components per element, normalization applied.
#[derive(Debug)]
pub struct Elements {
    pub values: Vec<f64>,
    pub n: usize,
    pub component: Component,
}

impl Elements {
    pub fn count(&self) -> usize {
        self.values.len() / self.n
    }
}

impl AccessorReader<'_> {
    /// Accessor `index` (referenced by `owner`), which must be of type `kind` (`"VEC3"`...), as f64 components with
    /// normalization applied.
    pub fn read(&self, index: Index, owner: &str, kind: &str) -> Result<Elements, String> {
        let acc = lookup(&self.root.accessors, index, owner, "accessor")?;
        let what = format!("accessor {index}");
        if acc.kind != kind {
            return Err(format!("{owner}: {what} is {}, expected {kind}", acc.kind));
        }
        self.components(acc, &what).map_err(|e| format!("{owner}: {e}"))
    }

    /// Accessor `index` as indices: SCALAR of unsigned bytes, shorts or ints, not normalized.
    pub fn read_indices(&self, index: Index, owner: &str) -> Result<Vec<u32>, String> {
        let e = self.read(index, owner, "SCALAR")?;
        let acc = lookup(&self.root.accessors, index, owner, "accessor")?;
        if !matches!(e.component, Component::U8 | Component::U16 | Component::U32) || acc.normalized {
            return Err(format!("{owner}: accessor {index} indices must be unsigned integers, not normalized"));
        }
        Ok(e.values.into_iter().map(|v| v as u32).collect())
    }

    fn components(&self, acc: &AccessorDef, what: &str) -> Result<Elements, String> {
        let component = Component::from_gl(acc.component_type)
            .ok_or_else(|| format!("{what}: componentType {} is not a glTF component type", acc.component_type))?;
        let n = multiplicity(&acc.kind).ok_or_else(|| format!("{what}: type '{}' is not a glTF type", acc.kind))?;
        if acc.count > MAX_ACCESSOR_ELEMENTS {
            return Err(format!(
                "{what}: count {} is more than sunshade reads from one accessor ({MAX_ACCESSOR_ELEMENTS})",
                acc.count
            ));
        }
        let count = acc.count as usize;
        let mut values = match acc.buffer_view {
            Some(v) => self.strided(v, acc.byte_offset, count, component, n, what)?,
            None => vec![0.0; count * n],
        };
        if let Some(sparse) = &acc.sparse {
            let what = format!("{what} sparse");
            if sparse.count > acc.count {
                return Err(format!("{what}: {} sparse values for {count} elements", sparse.count));
            }
            let k = sparse.count as usize;
            let idx_component = Component::from_gl(sparse.indices.component_type)
                .filter(|c| matches!(c, Component::U8 | Component::U16 | Component::U32))
                .ok_or_else(|| {
                    format!("{what}: indices componentType {} is not unsigned", sparse.indices.component_type)
                })?;
            let indices = self.strided(
                sparse.indices.buffer_view,
                sparse.indices.byte_offset,
                k,
                idx_component,
                1,
                &format!("{what} indices"),
            )?;
            let replacements = self.strided(
                sparse.values.buffer_view,
                sparse.values.byte_offset,
                k,
                component,
                n,
                &format!("{what} values"),
            )?;
            for (j, &i) in indices.iter().enumerate() {
                let i = i as usize;
                if i >= count {
                    return Err(format!("{what}: index {i} is past the accessor's {count} elements"));
                }
                values[i * n..(i + 1) * n].copy_from_slice(&replacements[j * n..(j + 1) * n]);
            }
        }
        if acc.normalized {
            if component == Component::F32 || component == Component::U32 {
                return Err(format!("{what}: normalized is only allowed for 8- and 16-bit integers"));
            }
            values.iter_mut().for_each(|v| *v = component.normalize(*v));
        }
        Ok(Elements { values, n, component })
    }

    /// `count` elements of `n` components each, from a buffer view at byte `offset`, honouring `byteStride`.
    fn strided(
        &self,
        view_index: Index,
        offset: u64,
        count: usize,
        component: Component,
        n: usize,
        what: &str,
    ) -> Result<Vec<f64>, String> {
        let view: &BufferViewDef = lookup(&self.root.buffer_views, view_index, what, "bufferView")?;
        let data = self.view_bytes(view, view_index, what)?;
        let size = component.size();
        let elem = size * n;
        let stride = match view.byte_stride {
            Some(s) => usize::try_from(s).map_err(|_| format!("{what}: byteStride {s} is too large"))?,
            None => elem,
        };
        if stride < elem {
            return Err(format!(
                "{what}: bufferView {view_index} stride {stride} is smaller than an element ({elem} bytes)"
            ));
        }
        let offset = usize::try_from(offset).map_err(|_| format!("{what}: byteOffset {offset} is too large"))?;
        if count > 0 {
            let needed =
                (count - 1).checked_mul(stride).and_then(|b| b.checked_add(offset)).and_then(|b| b.checked_add(elem));
            if needed.is_none_or(|needed| needed > data.len()) {
                return Err(format!(
                    "{what}: {count} elements at offset {offset} with stride {stride} run past the end of bufferView {view_index} ({} bytes)",
                    data.len()
                ));
            }
        }
        let mut out = Vec::with_capacity(count * n);
        for i in 0..count {
            let base = offset + i * stride;
            for c in 0..n {
                out.push(component.read(&data[base + c * size..base + (c + 1) * size]));
            }
        }
        Ok(out)
    }

    /// The bytes of a buffer view, checked against its buffer.
    fn view_bytes(&self, view: &BufferViewDef, view_index: Index, what: &str) -> Result<&[u8], String> {
        let owner = format!("{what}: bufferView {view_index}");
        lookup(&self.root.buffers, view.buffer, &owner, "buffer")?;
        let buffer = usize::try_from(view.buffer).ok().and_then(|b| self.buffers.get(b)).map_or(&[][..], |b| b);
        let range = usize::try_from(view.byte_offset).ok().zip(usize::try_from(view.byte_length).ok()).and_then(
            |(start, len)| {
                let end = start.checked_add(len)?;
                (end <= buffer.len()).then_some(start..end)
            },
        );
        let range = range.ok_or_else(|| {
            format!(
                "{owner} (bytes {}..+{}) is out of range of buffer {} ({} bytes)",
                view.byte_offset,
                view.byte_length,
                view.buffer,
                buffer.len()
            )
        })?;
        Ok(&buffer[range])
    }
}

#[cfg(test)]
mod tests {
    use super::super::document::parse;
    use super::*;

    fn reader_of(json: &str, buffer: Vec<u8>) -> (Root, Vec<Vec<u8>>) {
        (parse(json.as_bytes()).unwrap(), vec![buffer])
    }

    #[test]
    fn strided_normalized_and_zero_accessors() {
        let bytes: Vec<u8> = [-127i8, 0, 127, 99, 64, -128, 0, 99].iter().map(|&b| b as u8).collect();
        let (root, buffers) = reader_of(
            r#"{"buffers":[{"byteLength":8}],"bufferViews":[{"buffer":0,"byteLength":8,"byteStride":4}],
                "accessors":[{"bufferView":0,"componentType":5120,"normalized":true,"count":2,"type":"VEC3"},
                             {"componentType":5126,"count":3,"type":"VEC2"}]}"#,
            bytes,
        );
        let r = AccessorReader { root: &root, buffers: &buffers };
        let e = r.read(0, "test", "VEC3").unwrap();
        assert_eq!(e.values, [-1.0, 0.0, 1.0, 64.0 / 127.0, -1.0, 0.0]);
        let zeros = r.read(1, "test", "VEC2").unwrap();
        assert_eq!((zeros.count(), zeros.values.iter().all(|v| *v == 0.0)), (3, true));
        assert!(r.read(0, "test", "VEC2").unwrap_err().contains("expected VEC2"));
        assert!(r.read(5, "mesh 0", "VEC3").unwrap_err().contains("accessor 5 does not exist"));
    }

    #[test]
    fn huge_counts_and_offsets_are_errors_without_allocating() {
        for (count, offset) in [(1u64 << 31, 0u64), (u64::MAX, 0), (1, u64::MAX), (1, u64::MAX - 3)] {
            let json = format!(
                r#"{{"buffers":[{{"byteLength":8}}],"bufferViews":[{{"buffer":0,"byteLength":8}}],
                    "accessors":[{{"bufferView":0,"byteOffset":{offset},"componentType":5126,"count":{count},"type":"SCALAR"}},
                                 {{"componentType":5126,"count":{count},"type":"SCALAR"}}]}}"#
            );
            let (root, buffers) = reader_of(&json, vec![0; 8]);
            let r = AccessorReader { root: &root, buffers: &buffers };
            assert!(r.read(0, "t", "SCALAR").is_err(), "count {count} offset {offset}");
            if count > MAX_ACCESSOR_ELEMENTS {
                assert!(r.read(1, "t", "SCALAR").is_err());
            }
        }
        let (root, buffers) = reader_of(
            r#"{"buffers":[{"byteLength":8}],"bufferViews":[{"buffer":0,"byteOffset":18446744073709551615,"byteLength":8}],
                "accessors":[{"bufferView":0,"componentType":5126,"count":1,"type":"SCALAR"}]}"#,
            vec![0; 8],
        );
        let r = AccessorReader { root: &root, buffers: &buffers };
        assert!(r.read(0, "t", "SCALAR").unwrap_err().contains("out of range"));
    }
}
