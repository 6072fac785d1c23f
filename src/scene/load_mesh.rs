//! One primitive of a node's mesh into world space (the loader's largest step): its vertex streams read, morphed
//! by the default (or animated) weights, carried to world space by the node's transform or by each vertex's skin
//! matrix, flattened (flat normals un-index), with tangents from the file, MikkTSpace or texture coordinates; and
//! the skins' joint matrices it needs.

use std::collections::HashMap;

use glam::{DMat3, DMat4, DVec3, Vec3, Vec4};

use super::animation::NodePose;
use super::gltf::document::{self, lookup, PrimitiveDef, Root};
use super::load::{local_transform, mode_name, Loader, MAX_SCENE_VERTICES};
use super::tangent::{default_tangent, orthonormal_tangent, tangents_from_uv, triangle_tangent};
use super::{deform, Mesh};

impl Loader<'_> {
    /// One primitive of a node's mesh: its vertex streams read (morphed by `weights`), carried to world space by
    /// the node's transform or, for a skinned node, by each vertex's blend of `joints` (each joint's world matrix
    /// times its inverse bind matrix; the node's own transform is then ignored, as glTF says), and flattened.
    pub(super) fn add_primitive(
        &mut self,
        node: u64,
        name: &str,
        primitive: &PrimitiveDef,
        world: &DMat4,
        weights: &[f64],
        joints: Option<&[DMat4]>,
    ) -> Result<(), String> {
        let mode = primitive.mode.unwrap_or(document::MODE_TRIANGLES);
        if mode != document::MODE_TRIANGLES {
            self.scene.warnings.push(format!("{name}: mode {} skipped (only TRIANGLES is rendered)", mode_name(mode)));
            return Ok(());
        }
        let attribute = |semantic: &str| primitive.attributes.get(semantic).copied();
        let Some(pos_acc) = attribute("POSITION") else {
            self.scene.warnings.push(format!("{name}: no POSITION; skipped (the glTF spec asks for that)"));
            return Ok(());
        };
        let mut local_positions = self.reader.read(pos_acc, &format!("{name} POSITION"), "VEC3")?.values;
        if let Some(i) = local_positions.iter().position(|c| !c.is_finite()) {
            return Err(format!("{name}: POSITION accessor {pos_acc} holds a non-finite value at vertex {}", i / 3));
        }
        let vertex_count = local_positions.len() / 3;
        let per_vertex = |semantic: &str, kind: &str| -> Result<Option<Vec<f64>>, String> {
            let Some(acc) = attribute(semantic) else { return Ok(None) };
            let e = self.reader.read(acc, &format!("{name} {semantic}"), kind)?;
            if e.count() != vertex_count {
                return Err(format!("{name}: {semantic} has {} elements, POSITION {vertex_count}", e.count()));
            }
            Ok(Some(e.values))
        };
        let mut local_normals = per_vertex("NORMAL", "VEC3")?;
        let mut local_tangents = per_vertex("TANGENT", "VEC4")?;
        let (mut uv0, mut uv1) = (per_vertex("TEXCOORD_0", "VEC2")?, per_vertex("TEXCOORD_1", "VEC2")?);
        let color_kind = attribute("COLOR_0").and_then(|a| self.root.accessors.get(a as usize)).map(|a| a.kind.clone());
        let mut colors = match color_kind.as_deref() {
            Some("VEC3") => per_vertex("COLOR_0", "VEC3")?
                .map(|c| c.chunks_exact(3).flat_map(|c| [c[0], c[1], c[2], 1.0]).collect::<Vec<f64>>()),
            Some(_) => per_vertex("COLOR_0", "VEC4")?,
            None => None,
        };
        // Morph targets with their default weights (the node's, else the mesh's); zero weights leave the streams
        // bitwise as read.
        for (t, target) in primitive.targets.iter().enumerate() {
            let w = weights.get(t).copied().unwrap_or(0.0);
            if w == 0.0 {
                continue;
            }
            if !w.is_finite() {
                return Err(format!("{name}: morph weight {t} is {w}"));
            }
            let streams: [(&str, &str, Option<&mut Vec<f64>>); 6] = [
                ("POSITION", "VEC3", Some(&mut local_positions)),
                ("NORMAL", "VEC3", local_normals.as_mut()),
                ("TANGENT", "VEC3", local_tangents.as_mut()),
                ("TEXCOORD_0", "VEC2", uv0.as_mut()),
                ("TEXCOORD_1", "VEC2", uv1.as_mut()),
                ("COLOR_0", "VEC4", colors.as_mut()),
            ];
            for (semantic, kind, base) in streams {
                let (Some(acc), Some(base)) = (target.get(semantic), base) else { continue };
                let owner = format!("{name} morph target {t} {semantic}");
                let kind = if semantic == "COLOR_0" {
                    self.root
                        .accessors
                        .get(*acc as usize)
                        .map_or(kind, |a| if a.kind == "VEC3" { "VEC3" } else { "VEC4" })
                } else {
                    kind
                };
                let d = self.reader.read(*acc, &owner, kind)?;
                if d.count() != vertex_count {
                    return Err(format!("{owner}: {} elements, POSITION {vertex_count}", d.count()));
                }
                deform::morph(base, &d.values, d.n, w);
            }
        }
        let mut uv_sets = [uv0, uv1];
        let mut indices = match primitive.indices {
            Some(acc) => self.reader.read_indices(acc, &format!("{name} indices"))?,
            None => (0..vertex_count as u32).collect(),
        };
        if indices.len() % 3 != 0 {
            return Err(format!("{name}: {} indices is not a whole number of triangles", indices.len()));
        }
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(format!("{name}: index {bad} is out of range ({vertex_count} vertices)"));
        }
        // Skinning: each vertex's own matrix.
        let skin = match joints {
            Some(joints) => {
                let js = per_vertex("JOINTS_0", "VEC4")?;
                let ws = per_vertex("WEIGHTS_0", "VEC4")?;
                let (Some(js), Some(ws)) = (js, ws) else {
                    return Err(format!(
                        "{name}: node {node} has a skin but the primitive lacks JOINTS_0 or WEIGHTS_0"
                    ));
                };
                Some(deform::skin_matrices(joints, &js, &ws).map_err(|e| format!("{name}: {e}"))?)
            }
            None => None,
        };
        let linear = DMat3::from_mat4(skin.as_ref().and_then(|s| s.first()).copied().unwrap_or(*world));
        let det = linear.determinant();
        if !det.is_finite() || det == 0.0 {
            self.scene.warnings.push(format!("{name}: node {node} has a singular transform; skipped"));
            return Ok(());
        }
        // Flat normals un-index: three vertices a triangle.
        let added = if local_normals.is_some() { vertex_count } else { indices.len() };
        self.vertex_count = self.vertex_count.saturating_add(added);
        if self.vertex_count > MAX_SCENE_VERTICES {
            return Err(format!(
                "{name} (node {node}): the scene has more than {MAX_SCENE_VERTICES} vertices, the most sunshade loads"
            ));
        }
        // Mirrored node: the winding flips with the determinant's sign; swap two corners to keep CCW = front.
        if det < 0.0 {
            for tri in indices.chunks_exact_mut(3) {
                tri.swap(1, 2);
            }
        }
        let matrix_of = |i: usize| skin.as_ref().map_or(*world, |s| s[i]);
        let positions: Vec<Vec3> = local_positions
            .chunks_exact(3)
            .enumerate()
            .map(|(i, p)| matrix_of(i).transform_point3(DVec3::new(p[0], p[1], p[2])).as_vec3())
            .collect();
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("{name}: vertex {i} is not finite after the node transform"));
        }

        let mut out =
            Mesh { name: name.to_string(), material: self.material_index(name, primitive)?, ..Default::default() };
        let material_sets: Vec<u32> = self.scene.materials[out.material].textures().map(|t| t.tex_coord).collect();
        for set in material_sets {
            if uv_sets[set as usize].is_none() {
                self.scene
                    .warnings
                    .push(format!("{name}: its material reads TEXCOORD_{set}, which the primitive lacks; (0, 0) used"));
                uv_sets[set as usize] = Some(vec![0.0; 2 * vertex_count]);
            }
        }
        let uv_sets: [Option<Vec<[f32; 2]>>; 2] =
            uv_sets.map(|s| s.map(|uv| uv.chunks_exact(2).map(|c| [c[0] as f32, c[1] as f32]).collect()));
        let colors: Option<Vec<[f32; 4]>> =
            colors.map(|c| c.chunks_exact(4).map(|c| [c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32]).collect());
        // Tangent sources: TANGENT (transformed as a direction, handedness flipped by a mirroring node), else
        // TEXCOORD_0.
        let had_tangents = local_tangents.is_some();
        let file_tangents = local_tangents.map(|t| {
            let w_sign = det.signum();
            t.chunks_exact(4)
                .enumerate()
                .map(|(i, t)| (DMat3::from_mat4(matrix_of(i)) * DVec3::new(t[0], t[1], t[2]), w_sign * t[3].signum()))
                .collect::<Vec<_>>()
        });
        let uvs = match file_tangents {
            None => uv_sets[0].as_ref(),
            Some(_) => None,
        };
        match local_normals {
            Some(normals) => {
                // Normals transform by the inverse transpose of the linear part.
                let normal_matrix = linear.inverse().transpose();
                out.normals = normals
                    .chunks_exact(3)
                    .enumerate()
                    .map(|(i, n)| {
                        let m = match &skin {
                            Some(s) => DMat3::from_mat4(s[i]).inverse().transpose(),
                            None => normal_matrix,
                        };
                        let w = m * DVec3::new(n[0], n[1], n[2]);
                        w.try_normalize().unwrap_or(DVec3::ZERO).as_vec3()
                    })
                    .collect();
                out.tangents = match (&file_tangents, uvs) {
                    (Some(t), _) => t
                        .iter()
                        .zip(&out.normals)
                        .map(|((t, w), n)| orthonormal_tangent(*t, n.as_dvec3()).as_vec3().extend(*w as f32))
                        .collect(),
                    (None, Some(uv)) => tangents_from_uv(&positions, &out.normals, uv, &indices),
                    (None, None) => {
                        out.normals.iter().map(|n| default_tangent(n.as_dvec3()).as_vec3().extend(1.0)).collect()
                    }
                };
                out.positions = positions;
                out.indices = indices;
                out.tex_coords = uv_sets.map(Option::unwrap_or_default);
                out.colors = colors.unwrap_or_default();
            }
            None => {
                // Flat normals: every triangle gets its own three vertices carrying its face normal, computed from the
                // world-space (re-wound) corners so that it points to the front side.
                for tri in indices.chunks_exact(3) {
                    let [a, b, c] = [0, 1, 2].map(|k| positions[tri[k] as usize]);
                    let nd = (b.as_dvec3() - a.as_dvec3())
                        .cross(c.as_dvec3() - a.as_dvec3())
                        .try_normalize()
                        .unwrap_or(DVec3::ZERO);
                    let n = nd.as_vec3();
                    let base = out.positions.len() as u32;
                    out.positions.extend([a, b, c]);
                    out.normals.extend([n, n, n]);
                    out.indices.extend([base, base + 1, base + 2]);
                    for (set, stream) in uv_sets.iter().enumerate() {
                        if let Some(uv) = stream {
                            out.tex_coords[set].extend(tri.iter().map(|&i| uv[i as usize]));
                        }
                    }
                    if let Some(c) = &colors {
                        out.colors.extend(tri.iter().map(|&i| c[i as usize]));
                    }
                    let tangents: [Vec4; 3] = match (&file_tangents, uvs) {
                        (Some(t), _) => [0, 1, 2].map(|k| {
                            let (t, w) = t[tri[k] as usize];
                            orthonormal_tangent(t, nd).as_vec3().extend(w as f32)
                        }),
                        (None, Some(uv)) => {
                            let p = [a, b, c].map(|p| p.as_dvec3());
                            let (t, w) = match triangle_tangent(p, [0, 1, 2].map(|k| uv[tri[k] as usize])) {
                                Some((t, bt)) => {
                                    // glTF's handedness: the bitangent against ∂p/∂v (super::tangent).
                                    let t = orthonormal_tangent(t, nd);
                                    (t, if nd.cross(t).dot(bt) > 0.0 { -1.0 } else { 1.0 })
                                }
                                None => (default_tangent(nd), 1.0),
                            };
                            [t.as_vec3().extend(w); 3]
                        }
                        (None, None) => [default_tangent(nd).as_vec3().extend(1.0); 3],
                    };
                    out.tangents.extend(tangents);
                }
            }
        }
        // A normal map without the file's tangents: MikkTSpace on its texture-coordinate set, as glTF asks.
        let normal_map_set = self.scene.materials[out.material].normal_texture.map(|(t, _)| t.tex_coord as usize);
        if let (Some(set), false) = (normal_map_set, had_tangents) {
            if !super::tangent::mikktspace_tangents(&mut out, set) {
                self.scene.warnings.push(format!("{name}: MikkTSpace could not make tangents; UV-derived ones used"));
            }
        }
        if !out.indices.is_empty() {
            self.scene.meshes.push(out);
        }
        Ok(())
    }

    /// A skin's joint matrices `W(joint) · IBM` (glTF 2.0 §3.7.3), the bind pose as the file's node transforms
    /// place the joints.
    pub(super) fn joint_matrices(&self, node: u64, skin: u64) -> Result<Vec<DMat4>, String> {
        let owner = format!("node {node}");
        let def = lookup(&self.root.skins, skin, &owner, "skin")?;
        let what = format!("skin {skin}");
        let ibms = match def.inverse_bind_matrices {
            Some(acc) => {
                let e = self.reader.read(acc, &format!("{what} inverseBindMatrices"), "MAT4")?;
                if e.count() < def.joints.len() {
                    return Err(format!("{what}: {} inverse bind matrices for {} joints", e.count(), def.joints.len()));
                }
                e.values.chunks_exact(16).map(|m| DMat4::from_cols_slice(&f32s_slice(m))).collect()
            }
            None => vec![DMat4::IDENTITY; def.joints.len()],
        };
        def.joints
            .iter()
            .zip(ibms)
            .map(|(&j, ibm)| {
                lookup(&self.root.nodes, j, &what, "joint node")?;
                let w = self.node_world.get(j as usize).copied().flatten().ok_or_else(|| {
                    format!("{what}: joint node {j} is in no node hierarchy (a cycle or a node with two parents)")
                })?;
                let m = w * ibm;
                if m.is_finite() {
                    Ok(m)
                } else {
                    Err(format!("{what}: joint node {j}'s matrix is not finite"))
                }
            })
            .collect()
    }
}

/// A matrix's components rounded to f32, as glTF stores them (see [`f32s`]).
fn f32s_slice(m: &[f64]) -> Vec<f64> {
    m.iter().map(|&x| x as f32 as f64).collect()
}

/// Every node's world matrix, walked down from each node that is no node's child with an explicit stack; a node
/// reached twice keeps its first matrix (the scene walk reports the malformed hierarchy if it draws it).
pub(super) fn node_world_matrices(root: &Root, poses: &HashMap<u64, NodePose>) -> Result<Vec<Option<DMat4>>, String> {
    let n = root.nodes.len();
    let mut is_child = vec![false; n];
    for node in &root.nodes {
        for &c in &node.children {
            if let Some(flag) = is_child.get_mut(c as usize) {
                *flag = true;
            }
        }
    }
    let mut world = vec![None; n];
    let mut stack: Vec<(usize, DMat4)> = (0..n).filter(|&i| !is_child[i]).map(|i| (i, DMat4::IDENTITY)).collect();
    while let Some((i, parent)) = stack.pop() {
        if world[i].is_some() {
            continue;
        }
        let m = parent * local_transform(i as u64, &root.nodes[i], poses.get(&(i as u64)))?;
        world[i] = Some(m);
        for &c in &root.nodes[i].children {
            if (c as usize) < n {
                stack.push((c as usize, m));
            }
        }
    }
    Ok(world)
}
