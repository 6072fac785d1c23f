//! The sun's cells on the device (binding 15, `sun_cells_texels` in shaders/bindings.glsl, a texel a vec4): the
//! header, each cell's first entry, then every entry's corners, top and occluder record
//! (`layout::occluder_records`), so that the shader reads a cell's triangles in one place, without an indirection. Built by `visibility::sun_cells` for each
//! frame's sun.

use bytemuck::{Pod, Zeroable};

use crate::visibility::sun_cells::SunCells;

/// The buffer's header (four texels, 64 bytes): see `sun_cells_texels`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct SunCellsHeader {
    pub u: [f32; 4],
    pub v: [f32; 4],
    pub l: [f32; 4],
    pub dims: [u32; 4],
}

/// The bytes of a frame without cells: the header alone with `dims.w = 0` and one vec4 of data (the sun's rays
/// then take `occluded`).
pub fn absent() -> Vec<u8> {
    let mut bytes = bytemuck::bytes_of(&SunCellsHeader::zeroed()).to_vec();
    bytes.extend_from_slice(&[0; 16]);
    bytes
}

/// Words an entry takes: its corners and top as `(c0, top), (c1, 0), (c2, 0)` in f32, then its occluder record.
pub const ENTRY_WORDS: usize = 16;

/// The most entries a buffer of `max_bytes` holds beside the header and the cells' starts: seven eighths of it
/// (at most 1024² cells, 4 MiB of starts: an eighth of lavapipe's 128 MiB of storage-buffer range, the bound the
/// renderer takes with the device's texel-buffer size).
pub fn max_entries(max_bytes: u32) -> usize {
    max_bytes as usize / 8 * 7 / (ENTRY_WORDS * 4)
}

/// The texels (four words each) the buffer of `cells` takes: the header's four, the starts padded to whole texels,
/// four an entry.
pub fn texel_count(cells: &SunCells) -> usize {
    4 + cells.starts.len().div_ceil(4) + (ENTRY_WORDS / 4) * cells.triangles.len()
}

/// Writes the buffer of `cells` into `out` ([`texel_count`] texels: the device's mapped memory), whose triangle
/// indices point into `triangles` (world corners \[m\], the vertex buffer's f32 positions) and `records` (their
/// occluder records). The entries start at a multiple of four words; they are written on every core (a low sun's
/// cells hold millions of words).
pub fn write(cells: &SunCells, triangles: &[[glam::DVec3; 3]], records: &[[u32; 4]], out: &mut [[u32; 4]]) {
    use rayon::prelude::*;
    let f = |a: glam::DVec3, w: f64| [a.x as f32, a.y as f32, a.z as f32, w as f32];
    let offset = cells.starts.len().next_multiple_of(4);
    let header = SunCellsHeader {
        u: f(cells.u, cells.origin[0]),
        v: f(cells.v, cells.origin[1]),
        l: f(cells.l, cells.per_metre),
        dims: [cells.dims[0], cells.dims[1], offset as u32, 1],
    };
    assert_eq!(out.len(), texel_count(cells), "the sun cells' buffer");
    let (head, rest) = out.split_at_mut(4);
    bytemuck::cast_slice_mut::<[u32; 4], u8>(head).copy_from_slice(bytemuck::bytes_of(&header));
    // The shader reads data in vec4s: the starts padded to four words (offset), the entries sixteen each.
    let (starts, entries) = rest.split_at_mut(offset / 4);
    let starts: &mut [u32] = bytemuck::cast_slice_mut(starts);
    starts[..cells.starts.len()].copy_from_slice(&cells.starts);
    starts[cells.starts.len()..].fill(0);
    entries.par_chunks_mut(ENTRY_WORDS / 4).zip(cells.triangles.par_iter()).for_each(|(entry, &t)| {
        let [c0, c1, c2] = triangles[t as usize];
        // The top rounded up to f32, so that the shader's cut-off never passes over a triangle the f64 keeps.
        let top = cells.tops[t as usize];
        let top32 = if (top as f32 as f64) < top { (top as f32).next_up() } else { top as f32 };
        for (texel, (c, w)) in entry.iter_mut().zip([(c0, top32), (c1, 0.0), (c2, 0.0)]) {
            *texel = [c.x as f32, c.y as f32, c.z as f32, w].map(f32::to_bits);
        }
        entry[3] = records[t as usize];
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The buffer of `cells` as bytes: [`write()`] into memory of its own.
    fn bytes(cells: &SunCells, triangles: &[[glam::DVec3; 3]], records: &[[u32; 4]]) -> Vec<u8> {
        let mut texels = vec![[0u32; 4]; texel_count(cells)];
        write(cells, triangles, records, &mut texels);
        bytemuck::cast_slice(&texels).to_vec()
    }

    /// The header's texels are the shader's (vec4, vec4, vec4, uvec4, then the data from texel 4), the records
    /// follow the starts, and a cell's entries are its triangles' records.
    #[test]
    fn the_buffer_holds_the_starts_then_each_entrys_record() {
        assert_eq!(std::mem::size_of::<SunCellsHeader>(), 64);
        let glsl = include_str!("../../shaders/bindings.glsl");
        for (i, field) in ["U", "V", "L"].iter().enumerate() {
            let fetch = format!("#define SUN_CELLS_{field} uintBitsToFloat(texelFetch(sun_cells_texels, {i}))\n");
            assert!(glsl.contains(&fetch), "{fetch}");
        }
        assert!(glsl.contains("#define SUN_CELLS_DIMS texelFetch(sun_cells_texels, 3)\n"));
        assert!(glsl.contains("#define SUN_CELLS_DATA(i) texelFetch(sun_cells_texels, int(4u + (i)))\n"));
        let triangles = vec![
            [DVec3::ZERO, DVec3::X, DVec3::Z],
            [DVec3::new(5.0, 1.0, 0.0), DVec3::new(6.0, 1.0, 0.0), DVec3::new(5.0, 1.0, 1.0)],
        ];
        let records = [[1, 2, 3, 7], [4, 5, 6, 8]];
        let cells = SunCells::build(&triangles, DVec3::Y, 0.0, 100).unwrap();
        let b = bytes(&cells, &triangles, &records);
        let words: &[u32] = bytemuck::cast_slice(&b[64..]);
        let header: SunCellsHeader = bytemuck::pod_read_unaligned(&b[..64]);
        assert_eq!(header.dims[3], 1);
        let offset = header.dims[2] as usize;
        assert_eq!(offset % 4, 0);
        assert_eq!(&words[..cells.starts.len()], &cells.starts[..]);
        for c in 0..(cells.dims[0] * cells.dims[1]) as usize {
            for (k, &t) in cells.cell(c).iter().enumerate() {
                let e = &words[offset + ENTRY_WORDS * (cells.starts[c] as usize + k)..][..ENTRY_WORDS];
                let corner = |i: usize| {
                    DVec3::new(
                        f32::from_bits(e[4 * i]) as f64,
                        f32::from_bits(e[4 * i + 1]) as f64,
                        f32::from_bits(e[4 * i + 2]) as f64,
                    )
                };
                assert_eq!([corner(0), corner(1), corner(2)], triangles[t as usize]);
                assert!(f32::from_bits(e[3]) as f64 >= cells.tops[t as usize]);
                assert_eq!(&e[12..16], &records[t as usize]);
            }
        }
        assert_eq!(bytemuck::pod_read_unaligned::<SunCellsHeader>(&absent()[..64]).dims[3], 0);
        // The shader's constants are the Rust's.
        use crate::visibility::sun_cells::{MAX_SUN_CELL_CLASSIFIED, MAX_SUN_CELL_TRIANGLES, SUN_CONE_MARGIN};
        let glsl = include_str!("../../shaders/sun_cells.glsl");
        assert!(glsl.contains(&format!("#define SUN_CELL_ENTRY_WORDS {ENTRY_WORDS}u\n")));
        assert!(glsl.contains(&format!("#define MAX_SUN_CELL_TRIANGLES {MAX_SUN_CELL_TRIANGLES}u\n")));
        assert!(glsl.contains(&format!("#define MAX_SUN_CELL_CLASSIFIED {MAX_SUN_CELL_CLASSIFIED}u\n")));
        assert_eq!(SUN_CONE_MARGIN, 1.0 / 1_048_576.0);
        assert!(glsl.contains("#define SUN_CONE_MARGIN (1.0 / 1048576.0)\n"));
    }
}
