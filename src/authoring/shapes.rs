//! Simple triangle meshes for generated scenes: every triangle counter-clockwise seen from its front side.

use glam::Vec3;

use super::{Indices, Primitive};

/// Positions, unit normals and a triangle list.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub indices: Vec<u32>,
}

impl MeshData {
    /// As an indexed primitive with normals, indices in the narrowest type.
    pub fn primitive(&self, material: Option<usize>) -> Primitive {
        Primitive {
            positions: self.positions.clone(),
            normals: Some(self.normals.clone()),
            indices: Some(Indices::narrowest(&self.indices)),
            material,
            mode: None,
            ..Default::default()
        }
    }

    /// The same triangles without an index buffer (vertices repeated).
    pub fn unindexed(&self) -> MeshData {
        MeshData {
            positions: self.indices.iter().map(|&i| self.positions[i as usize]).collect(),
            normals: self.indices.iter().map(|&i| self.normals[i as usize]).collect(),
            indices: (0..self.indices.len() as u32).collect(),
        }
    }

    /// Appends another mesh.
    pub fn append(&mut self, other: &MeshData) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

/// A parallelogram with corners `center ± u ± v`, facing `u × v`.
pub fn quad(center: Vec3, u: Vec3, v: Vec3) -> MeshData {
    let n = u.cross(v).normalize();
    let corners = [center - u - v, center + u - v, center + u + v, center - u + v];
    MeshData {
        positions: corners.map(|c| c.to_array()).to_vec(),
        normals: vec![n.to_array(); 4],
        indices: vec![0, 1, 2, 0, 2, 3],
    }
}

/// An axis-aligned cube of half-size `half` around the origin, flat-shaded (24 vertices), faces outwards.
pub fn cube(half: f32) -> MeshData {
    let mut m = MeshData::default();
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            let n = Vec3::from_array(std::array::from_fn(|k| if k == axis { sign } else { 0.0 }));
            // Two tangents with u × v = n.
            let u = Vec3::from_array(std::array::from_fn(|k| if k == (axis + 1) % 3 { half } else { 0.0 }));
            let v = n.cross(u);
            m.append(&quad(n * half, u, v));
        }
    }
    m
}

/// A UV sphere with smooth normals: `stacks` ≥ 2 rings of latitude, `slices` ≥ 3 of longitude.
pub fn uv_sphere(center: Vec3, radius: f32, stacks: u32, slices: u32) -> MeshData {
    let mut m = MeshData::default();
    for i in 0..=stacks {
        let theta = std::f64::consts::PI * i as f64 / stacks as f64;
        // The poles and the seam exactly where their neighbours put them (sin π and sin 2π are 1e-16, not 0), so
        // that the surface is closed to the last bit (`visibility::can_occlude` welds exact coordinates).
        let (sin_t, cos_t) = if i == stacks { (0.0, -1.0) } else { theta.sin_cos() };
        for j in 0..=slices {
            let phi = if j == slices { 0.0 } else { 2.0 * std::f64::consts::PI * j as f64 / slices as f64 };
            let n = glam::DVec3::new(sin_t * phi.sin(), cos_t, sin_t * phi.cos());
            m.normals.push(n.as_vec3().to_array());
            m.positions.push((center + n.as_vec3() * radius).to_array());
        }
    }
    let row = slices + 1;
    for i in 0..stacks {
        for j in 0..slices {
            let (a, b, c, d) = (i * row + j, (i + 1) * row + j, (i + 1) * row + j + 1, i * row + j + 1);
            // Seen from outside, going down a stack (b) then along the slice (c) is counter-clockwise.
            if i != 0 {
                m.indices.extend([a, b, d]);
            }
            if i != stacks - 1 {
                m.indices.extend([d, b, c]);
            }
        }
    }
    m
}

/// An icosphere: the icosahedron (20 triangles) with each triangle split into four `subdivisions` times (80 at
/// 1, 320 at 2), vertices shared and pushed out to the sphere, counter-clockwise seen from outside, smooth normals.
/// Closed: every edge is shared by two triangles through the same vertex indices.
pub fn icosphere(center: Vec3, radius: f32, subdivisions: u32) -> MeshData {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut points: Vec<glam::DVec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| glam::DVec3::from_array(*p).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoints = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, points: &mut Vec<glam::DVec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                points.push(((points[a as usize] + points[b as usize]) * 0.5).normalize());
                points.len() as u32 - 1
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b, &mut points), mid(b, c, &mut points), mid(c, a, &mut points));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    MeshData {
        positions: points.iter().map(|p| (center + p.as_vec3() * radius).to_array()).collect(),
        normals: points.iter().map(|p| p.as_vec3().to_array()).collect(),
        indices: faces.into_iter().flatten().collect(),
    }
}

/// A `size × size` square in the XZ plane at height `y`, facing +Y, split into `n × n` cells (2 triangles each).
pub fn grid(center: Vec3, size: f32, n: u32) -> MeshData {
    let mut m = MeshData::default();
    for i in 0..=n {
        for j in 0..=n {
            let x = center.x + size * (j as f32 / n as f32 - 0.5);
            let z = center.z + size * (i as f32 / n as f32 - 0.5);
            m.positions.push([x, center.y, z]);
            m.normals.push([0.0, 1.0, 0.0]);
        }
    }
    let row = n + 1;
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (i * row + j, i * row + j + 1, (i + 1) * row + j + 1, (i + 1) * row + j);
            // +X then +Z is clockwise seen from +Y, so go a → d → c (CCW from above).
            m.indices.extend([a, d, c, a, c, b]);
        }
    }
    m
}

/// `count` random triangles (deterministic for a seed) inside the box `center ± half`, each with edges up to
/// `max_edge` long and a flat normal; sizes spread over three decades so that slivers and sub-pixel triangles
/// occur.
pub fn triangle_soup(center: Vec3, half: Vec3, count: usize, max_edge: f32, seed: u64) -> MeshData {
    let mut state = seed.max(1);
    let mut next = move || {
        // xorshift64*: enough for test geometry.
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut m = MeshData::default();
    for _ in 0..count {
        let a = center + half * Vec3::new(next() * 2.0 - 1.0, next() * 2.0 - 1.0, next() * 2.0 - 1.0);
        let scale = max_edge * 10f32.powf(-3.0 * next());
        let mut rnd = || Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 2.0 * scale;
        let (b, c) = (a + rnd(), a + rnd());
        let n = (b - a).cross(c - a).normalize_or_zero();
        let base = m.positions.len() as u32;
        m.positions.extend([a.to_array(), b.to_array(), c.to_array()]);
        m.normals.extend([n.to_array(); 3]);
        m.indices.extend([base, base + 1, base + 2]);
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle's geometric normal agrees with its vertex normals (CCW = front).
    fn assert_front_faces_agree(m: &MeshData) {
        for t in m.indices.chunks_exact(3) {
            let p: [Vec3; 3] = std::array::from_fn(|k| Vec3::from_array(m.positions[t[k] as usize]));
            let g = (p[1] - p[0]).cross(p[2] - p[0]);
            if g.length() < 1e-12 {
                continue;
            }
            let n = Vec3::from_array(m.normals[t[0] as usize]);
            assert!(g.dot(n) > 0.0, "triangle {t:?} winds against its normal");
        }
    }

    #[test]
    fn shapes_wind_counter_clockwise() {
        assert_front_faces_agree(&quad(Vec3::ZERO, Vec3::X, Vec3::Y));
        assert_front_faces_agree(&cube(0.5));
        assert_front_faces_agree(&uv_sphere(Vec3::ONE, 2.0, 8, 12));
        assert_front_faces_agree(&grid(Vec3::ZERO, 2.0, 4));
        assert_eq!(cube(1.0).triangle_count(), 12);
        assert_eq!(grid(Vec3::ZERO, 1.0, 10).triangle_count(), 200);
        assert_eq!(uv_sphere(Vec3::ZERO, 1.0, 4, 6).triangle_count(), 2 * 6 * 4 - 2 * 6);
    }
}
