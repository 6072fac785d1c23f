//! Surface tangents, the αx direction of anisotropic BRDFs: from the mesh's TANGENT attribute, else derived from
//! texture coordinates, else a default.
//!
//! A tangent is stored as (t, w): t a unit vector orthogonal to the normal, w = ±1 the handedness, so that the
//! bitangent (the αy direction, and the normal map's +y) is `w · (n × t)` (glTF 2.0 §3.7.2.1).
//!
//! glTF's normal maps point +y "up" in the image, towards decreasing v (UV (0, 0) is the image's top-left
//! corner), so a tangent frame derived from texture coordinates takes t along increasing u and the bitangent
//! along *decreasing* v: `w = −sign((n × t) · ∂p/∂v)`. (MikkTSpace, written for v pointing up, gives the opposite
//! sign on glTF's coordinates, which is negated here, as three.js does with its `negateSign` for glTF.)

use glam::{DVec3, Vec3, Vec4};

/// The default tangent where a mesh gives none: world +X projected onto the tangent plane (world +Z where the
/// normal is along X), handedness +1. Isotropic BRDFs do not depend on it.
pub fn default_tangent(n: DVec3) -> DVec3 {
    let t = DVec3::X - n * n.x;
    if t.length_squared() > 1e-12 {
        t.normalize()
    } else {
        (DVec3::Z - n * n.z).normalize()
    }
}

/// Gram–Schmidt: the part of `t` orthogonal to the unit normal `n`, normalised; the default where that vanishes.
pub fn orthonormal_tangent(t: DVec3, n: DVec3) -> DVec3 {
    let o = t - n * n.dot(t);
    if o.length_squared() > 1e-20 {
        o.normalize()
    } else {
        default_tangent(n)
    }
}

/// Per-triangle tangent and bitangent from texture coordinates (Lengyel's method: the directions in which u and v
/// increase), unnormalised (weighted by the triangle's size), or `None` for a degenerate UV mapping.
pub fn triangle_tangent(p: [DVec3; 3], uv: [[f32; 2]; 3]) -> Option<(DVec3, DVec3)> {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (du1, dv1) = ((uv[1][0] - uv[0][0]) as f64, (uv[1][1] - uv[0][1]) as f64);
    let (du2, dv2) = ((uv[2][0] - uv[0][0]) as f64, (uv[2][1] - uv[0][1]) as f64);
    let det = du1 * dv2 - du2 * dv1;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    Some(((e1 * dv2 - e2 * dv1) / det, (e2 * du1 - e1 * du2) / det))
}

/// Per-vertex tangents from texture coordinates, accumulated over the triangles that share each vertex.
pub fn tangents_from_uv(positions: &[Vec3], normals: &[Vec3], uvs: &[[f32; 2]], indices: &[u32]) -> Vec<Vec4> {
    let mut t_acc = vec![DVec3::ZERO; positions.len()];
    let mut b_acc = vec![DVec3::ZERO; positions.len()];
    for tri in indices.chunks_exact(3) {
        let p = [0, 1, 2].map(|k| positions[tri[k] as usize].as_dvec3());
        let uv = [0, 1, 2].map(|k| uvs[tri[k] as usize]);
        if let Some((t, b)) = triangle_tangent(p, uv) {
            for &i in tri {
                t_acc[i as usize] += t;
                b_acc[i as usize] += b;
            }
        }
    }
    (0..positions.len())
        .map(|i| {
            let n = normals[i].as_dvec3();
            let t = orthonormal_tangent(t_acc[i], n);
            let w = if n.cross(t).dot(b_acc[i]) > 0.0 { -1.0 } else { 1.0 };
            t.as_vec3().extend(w)
        })
        .collect()
}

/// MikkTSpace tangents (Mikkelsen 2008, the glTF spec's choice where a file gives none) from texture-coordinate
/// set `set`, with glTF's handedness (see the module doc). Vertices shared by faces that need different tangents
/// are split; the others stay shared. Returns false (the mesh unchanged) where MikkTSpace fails.
pub fn mikktspace_tangents(mesh: &mut super::Mesh, set: usize) -> bool {
    struct Faces<'a> {
        mesh: &'a super::Mesh,
        uv: &'a [[f32; 2]],
        tangents: Vec<[f32; 4]>,
    }
    impl mikktspace::Geometry for Faces<'_> {
        fn num_faces(&self) -> usize {
            self.mesh.indices.len() / 3
        }
        fn num_vertices_of_face(&self, _face: usize) -> usize {
            3
        }
        fn position(&self, face: usize, vert: usize) -> [f32; 3] {
            self.mesh.positions[self.mesh.indices[face * 3 + vert] as usize].to_array()
        }
        fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
            self.mesh.normals[self.mesh.indices[face * 3 + vert] as usize].to_array()
        }
        fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
            self.uv[self.mesh.indices[face * 3 + vert] as usize]
        }
        fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
            self.tangents[face * 3 + vert] = tangent;
        }
    }
    if mesh.tex_coords[set].len() != mesh.positions.len() {
        return false;
    }
    let uv = mesh.tex_coords[set].clone();
    let mut faces = Faces { mesh, uv: &uv, tangents: vec![[0.0; 4]; mesh.indices.len()] };
    if !mikktspace::generate_tangents(&mut faces) {
        return false;
    }
    let corner_tangents = faces.tangents;
    // Weld: one vertex per (original vertex, tangent).
    let mut seen: std::collections::HashMap<(u32, [u32; 4]), u32> = std::collections::HashMap::new();
    let mut out = super::Mesh { name: mesh.name.clone(), material: mesh.material, ..Default::default() };
    for (corner, &i) in mesh.indices.iter().enumerate() {
        let t = corner_tangents[corner];
        let key = (i, t.map(f32::to_bits));
        let index = *seen.entry(key).or_insert_with(|| {
            let k = i as usize;
            out.positions.push(mesh.positions[k]);
            out.normals.push(mesh.normals[k]);
            let n = mesh.normals[k].as_dvec3();
            let w = if t[3] < 0.0 { 1.0 } else { -1.0 };
            out.tangents
                .push(orthonormal_tangent(DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64), n).as_vec3().extend(w));
            for s in 0..2 {
                if let Some(uv) = mesh.tex_coords[s].get(k) {
                    out.tex_coords[s].push(*uv);
                }
            }
            if let Some(c) = mesh.colors.get(k) {
                out.colors.push(*c);
            }
            out.positions.len() as u32 - 1
        });
        out.indices.push(index);
    }
    *mesh = out;
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uv_tangents_follow_u_and_handedness_follows_v() {
        // A square in the XZ plane facing +Y, u along +X, v along −Z: n × t = Y × X = −Z, along ∂p/∂v; the normal
        // map's +y points against v (+Z): w = −1.
        let positions =
            [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, -1.0), Vec3::new(0.0, 0.0, -1.0)];
        let normals = [Vec3::Y; 4];
        let uvs = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let t = tangents_from_uv(&positions, &normals, &uvs, &[0, 1, 2, 0, 2, 3]);
        for v in &t {
            assert!((v.truncate() - Vec3::X).length() < 1e-6 && v.w == -1.0, "{v}");
        }
        // Mirror v: handedness flips.
        let flipped: Vec<[f32; 2]> = uvs.iter().map(|uv| [uv[0], -uv[1]]).collect();
        let t = tangents_from_uv(&positions, &normals, &flipped, &[0, 1, 2, 0, 2, 3]);
        assert!(t.iter().all(|v| v.w == 1.0));
    }

    #[test]
    fn defaults_are_orthonormal() {
        for n in [DVec3::Y, DVec3::X, -DVec3::X, DVec3::new(0.3, 0.4, 0.5).normalize()] {
            let t = default_tangent(n);
            assert!((t.length() - 1.0).abs() < 1e-12 && t.dot(n).abs() < 1e-12, "{n} {t}");
        }
        assert_eq!(orthonormal_tangent(DVec3::Y, DVec3::Y), default_tangent(DVec3::Y));
    }
}
