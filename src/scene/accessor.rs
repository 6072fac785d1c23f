//! Bounds-checked reading of glTF accessors.
//!
//! Every byte range is checked against its buffer view and buffer before it is read, so a malformed file gives an
//! error naming the accessor instead of a panic. Sparse accessors are applied on top of their base data.

use gltf::accessor::{DataType, Dimensions};

/// Reads accessors out of the loaded buffers.
pub struct AccessorReader<'a> {
    /// Buffer contents, indexed like the glTF `buffers` array.
    pub buffers: &'a [Vec<u8>],
}

impl AccessorReader<'_> {
    /// Reads `VEC3` `FLOAT` data (positions, normals).
    pub fn read_vec3_f32(&self, accessor: &gltf::Accessor) -> Result<Vec<[f32; 3]>, String> {
        expect_layout(accessor, Dimensions::Vec3, &[DataType::F32])?;
        let raw = self.read_components(accessor)?;
        Ok(raw.chunks_exact(3).map(|c| [c[0] as f32, c[1] as f32, c[2] as f32]).collect())
    }

    /// Reads `VEC4` `FLOAT` data (tangents: xyz and the handedness w).
    pub fn read_vec4_f32(&self, accessor: &gltf::Accessor) -> Result<Vec<[f32; 4]>, String> {
        expect_layout(accessor, Dimensions::Vec4, &[DataType::F32])?;
        let raw = self.read_components(accessor)?;
        Ok(raw.chunks_exact(4).map(|c| [c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32]).collect())
    }

    /// Reads `VEC2` texture coordinates: `FLOAT`, or normalized unsigned bytes or shorts (glTF allows those).
    pub fn read_texcoords(&self, accessor: &gltf::Accessor) -> Result<Vec<[f32; 2]>, String> {
        expect_layout(accessor, Dimensions::Vec2, &[DataType::F32, DataType::U8, DataType::U16])?;
        let scale = match accessor.data_type() {
            DataType::U8 if accessor.normalized() => 1.0 / 255.0,
            DataType::U16 if accessor.normalized() => 1.0 / 65535.0,
            DataType::F32 => 1.0,
            _ => return Err(format!("accessor {}: integer texture coordinates must be normalized", accessor.index())),
        };
        let raw = self.read_components(accessor)?;
        Ok(raw.chunks_exact(2).map(|c| [(c[0] * scale) as f32, (c[1] * scale) as f32]).collect())
    }

    /// Reads `SCALAR` unsigned-integer data of any width (indices).
    pub fn read_indices(&self, accessor: &gltf::Accessor) -> Result<Vec<u32>, String> {
        expect_layout(accessor, Dimensions::Scalar, &[DataType::U8, DataType::U16, DataType::U32])?;
        if accessor.normalized() {
            return Err(format!("accessor {}: indices must not be normalized", accessor.index()));
        }
        Ok(self.read_components(accessor)?.into_iter().map(|v| v as u32).collect())
    }

    /// All components of an accessor, as f64 (every glTF component type converts to f64 exactly), sparse
    /// substitution applied, not normalised.
    fn read_components(&self, accessor: &gltf::Accessor) -> Result<Vec<f64>, String> {
        let n = accessor.dimensions().multiplicity();
        let count = accessor.count();
        let total = count.checked_mul(n).ok_or_else(|| format!("accessor {}: count overflows", accessor.index()))?;
        let mut out = match accessor.view() {
            Some(view) => self.read_strided(
                &view,
                accessor.offset(),
                count,
                accessor.data_type(),
                n,
                &format!("accessor {}", accessor.index()),
            )?,
            None => vec![0.0; total],
        };
        if let Some(sparse) = accessor.sparse() {
            let what = format!("accessor {} sparse", accessor.index());
            let k = sparse.count();
            if k > count {
                return Err(format!("{what}: {k} sparse values for {count} elements"));
            }
            let idx_type = match sparse.indices().index_type() {
                gltf::accessor::sparse::IndexType::U8 => DataType::U8,
                gltf::accessor::sparse::IndexType::U16 => DataType::U16,
                gltf::accessor::sparse::IndexType::U32 => DataType::U32,
            };
            let indices = self.read_strided(
                &sparse.indices().view(),
                sparse.indices().offset(),
                k,
                idx_type,
                1,
                &format!("{what} indices"),
            )?;
            let values = self.read_strided(
                &sparse.values().view(),
                sparse.values().offset(),
                k,
                accessor.data_type(),
                n,
                &format!("{what} values"),
            )?;
            for (j, &i) in indices.iter().enumerate() {
                let i = i as usize;
                if i >= count {
                    return Err(format!("{what}: index {i} is past the accessor's {count} elements"));
                }
                out[i * n..(i + 1) * n].copy_from_slice(&values[j * n..(j + 1) * n]);
            }
        }
        Ok(out)
    }

    /// `count` elements of `n` components each, from a buffer view at byte `offset`, honouring `byteStride`.
    fn read_strided(
        &self,
        view: &gltf::buffer::View,
        offset: usize,
        count: usize,
        data_type: DataType,
        n: usize,
        what: &str,
    ) -> Result<Vec<f64>, String> {
        let size = data_type.size();
        let elem = size * n;
        let stride = view.stride().unwrap_or(elem);
        if stride < elem {
            return Err(format!(
                "{what}: buffer view {} stride {stride} is smaller than an element ({elem} bytes)",
                view.index()
            ));
        }
        let buffer = self
            .buffers
            .get(view.buffer().index())
            .ok_or_else(|| format!("{what}: buffer {} is missing", view.buffer().index()))?;
        let view_end = view.offset().checked_add(view.length());
        if view_end.is_none_or(|end| end > buffer.len()) {
            return Err(format!(
                "buffer view {} (bytes {}..+{}) is out of range of buffer {} ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                buffer.len()
            ));
        }
        let data = &buffer[view.offset()..view.offset() + view.length()];
        if count > 0 {
            let needed =
                (count - 1).checked_mul(stride).and_then(|b| b.checked_add(offset)).and_then(|b| b.checked_add(elem));
            if needed.is_none_or(|needed| needed > data.len()) {
                return Err(format!(
                    "{what}: {count} elements at offset {offset} with stride {stride} run past the end of buffer view {} ({} bytes)",
                    view.index(),
                    data.len()
                ));
            }
        }
        let mut out = Vec::with_capacity(count * n);
        for i in 0..count {
            let base = offset + i * stride;
            for c in 0..n {
                let b = &data[base + c * size..base + (c + 1) * size];
                out.push(match data_type {
                    DataType::I8 => b[0] as i8 as f64,
                    DataType::U8 => b[0] as f64,
                    DataType::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
                    DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
                    DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                });
            }
        }
        Ok(out)
    }
}

fn expect_layout(accessor: &gltf::Accessor, dims: Dimensions, types: &[DataType]) -> Result<(), String> {
    if accessor.dimensions() != dims || !types.contains(&accessor.data_type()) {
        return Err(format!(
            "accessor {} is {:?} {:?}, expected {:?} of {:?}",
            accessor.index(),
            accessor.dimensions(),
            accessor.data_type(),
            dims,
            types
        ));
    }
    Ok(())
}
