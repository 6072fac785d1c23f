//! glTF 2.0 → [`Scene`]: `.gltf` with external `.bin` or data URIs, and `.glb`.
//!
//! What is read: the chosen scene's node hierarchy (matrix or TRS transforms; without any scene, the file's root
//! nodes), every TRIANGLES primitive (other modes are skipped with a warning), u8/u16/u32 or no indices, POSITION
//! and NORMAL (flat normals where a primitive has none, as the glTF spec requires), TANGENT or TEXCOORD_0 (for
//! tangents), float or KHR_mesh_quantization integer attributes, sparse accessors and accessors without a buffer
//! view (zeros), materials (`baseColorFactor` as the Lambertian albedo, or the BRDF of the material's
//! `{"sunshade": {"brdf": …}}` extras), cameras, KHR_lights_punctual directional lights (the sun), disk skylights
//! from node `extras` (`{"sunshade": {"light": "disk", "radius": R, "radiance": [r, g, b]}}`: a disk in the node's
//! local XY plane at its origin, emitting towards local −Z) and the overcast sky from the scene's `extras`
//! (`{"sunshade": {"sky_radiance": [r, g, b]}}`).
//!
//! Every problem is an error naming the file and the glTF object; nothing here panics or recurses on bad input:
//! the hierarchy is walked with an explicit stack, each node at most once.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{DMat3, DMat4, DQuat, DVec3, Vec3, Vec4};
use serde_json::Value;

use super::animation::{self, NodePose};
use super::camera::{Camera, Projection};
use super::gltf::accessor::AccessorReader;
use super::gltf::document::{self, lookup, CameraDef, LightDef, NodeDef, PrimitiveDef, Root};
use super::gltf::files::AssetFiles;
use super::gltf::files::UriScope;
use super::gltf::{self, SUPPORTED_EXTENSIONS};
use super::light::{DiskLight, Sun, MAX_DISK_EXTENT_M};
use super::load_material::{rgb, sunshade_extras, MaterialReader};
use super::material::Material;
use super::tangent::{default_tangent, orthonormal_tangent, tangents_from_uv, triangle_tangent};
use super::{deform, Mesh, Scene};
use crate::shading::radiometry::{degrees_to_radians, SUN_ANGULAR_DIAMETER_DEGREES};

/// A glTF file that could not be loaded: `path: problem`, one line.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", path.display())]
pub struct LoadError {
    pub path: PathBuf,
    pub message: String,
}

/// The most vertices a loaded scene may have, after instancing and flat-normal un-indexing: 2^26 (67 M). At the
/// 40 bytes a vertex takes on the device this is over 2.5 GiB, past lavapipe's largest allocation; the bound stops
/// a file that instances one mesh from many nodes from exhausting memory while it loads.
pub const MAX_SCENE_VERTICES: usize = 1 << 26;

/// Choices made while loading.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Which glTF scene to load; `None` = the file's default scene (or its first, or its root nodes).
    pub scene: Option<usize>,
    /// Where buffer and image files may be (default: inside the scene's folder).
    pub uris: UriScope,
    /// Pose the scene by animation N at time T [s] (`--animation N --time T`); `None`: the file's own transforms
    /// and weights (the rest pose).
    pub animation: Option<(usize, f64)>,
}

/// Loads the default scene of a glTF file.
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    load_with_options(path, &LoadOptions::default())
}

/// Loads a glTF file.
pub fn load_with_options(path: &Path, options: &LoadOptions) -> Result<Scene, LoadError> {
    let fail = |message: String| LoadError { path: path.to_path_buf(), message };
    let file = gltf::read(path, &options.uris).map_err(fail)?;
    Loader::new(&file.root, &file.buffers, &file.files).load(options).map_err(fail)
}

struct Loader<'a> {
    root: &'a Root,
    reader: AccessorReader<'a>,
    files: &'a AssetFiles,
    /// Every node's world matrix (`None` for nodes that no hierarchy walk from a parentless node reaches), for
    /// skins' joints.
    node_world: Vec<Option<DMat4>>,
    /// Nodes posed by the sampled animation (`LoadOptions::animation`).
    poses: HashMap<u64, NodePose>,
    scene: Scene,
    /// Index of glTF's default material in `scene.materials`, once a primitive needs it.
    default_material: Option<usize>,
    vertex_count: usize,
}

/// glTF's names of the primitive modes.
fn mode_name(mode: u64) -> String {
    match mode {
        0 => "POINTS".into(),
        1 => "LINES".into(),
        2 => "LINE_LOOP".into(),
        3 => "LINE_STRIP".into(),
        4 => "TRIANGLES".into(),
        5 => "TRIANGLE_STRIP".into(),
        6 => "TRIANGLE_FAN".into(),
        other => format!("{other} (not a glTF mode)"),
    }
}

impl<'a> Loader<'a> {
    fn new(root: &'a Root, buffers: &'a [Vec<u8>], files: &'a AssetFiles) -> Self {
        Self {
            root,
            reader: AccessorReader { root, buffers },
            files,
            node_world: Vec::new(),
            poses: HashMap::new(),
            scene: Scene::default(),
            default_material: None,
            vertex_count: 0,
        }
    }

    fn load(mut self, options: &LoadOptions) -> Result<Scene, String> {
        let root = self.root;
        let roots = self.root_nodes(options)?;
        let unmodelled: Vec<&str> =
            root.extensions_used.iter().map(String::as_str).filter(|e| !SUPPORTED_EXTENSIONS.contains(e)).collect();
        if !unmodelled.is_empty() {
            self.scene.warnings.push(format!("extensions not modelled, ignored: {}", unmodelled.join(", ")));
        }
        // Required ones that reach here affect appearance only (`gltf::is_appearance_only`); say that the image
        // lacks what the file demands.
        let required: Vec<&str> =
            root.extensions_required.iter().map(String::as_str).filter(|e| !SUPPORTED_EXTENSIONS.contains(e)).collect();
        if !required.is_empty() {
            self.scene.warnings.push(format!(
                "the file requires {}, which sunshade does not implement: drawn without it (materials from their \
                 factors; see the material warnings)",
                required.join(", ")
            ));
        }
        let mut materials = MaterialReader::new(root, self.reader.buffers, self.files);
        for (index, material) in root.materials.iter().enumerate() {
            let m = materials.read(index, material)?;
            self.scene.materials.push(m);
        }
        self.scene.textures = materials.textures;
        self.scene.warnings.extend(materials.warnings);
        if let Some((index, time)) = options.animation {
            if !time.is_finite() {
                return Err(format!("--time {time} is not a finite number of seconds"));
            }
            self.poses = animation::sample(root, &self.reader, index, time)?;
        } else if !root.animations.is_empty() {
            self.scene.warnings.push(format!(
                "the file has {} animation(s); drawn at rest (--animation N --time T poses it)",
                root.animations.len()
            ));
        }
        if !root.skins.is_empty() {
            self.node_world = node_world_matrices(root, &self.poses)?;
        }
        self.walk(&roots)?;
        Ok(self.scene)
    }

    /// The nodes to draw: the chosen scene's, the default scene's, the first scene's, or (in a file without
    /// scenes) every node that is no other node's child.
    fn root_nodes(&mut self, options: &LoadOptions) -> Result<Vec<u64>, String> {
        let root = self.root;
        let count = root.scenes.len();
        let chosen = match (options.scene, root.scene) {
            (Some(n), _) => Some(
                root.scenes
                    .get(n)
                    .map(|s| (n, s))
                    .ok_or_else(|| format!("scene {n} does not exist (the file has {count})"))?,
            ),
            (None, Some(n)) => Some((n as usize, lookup(&root.scenes, n, "the file's default 'scene'", "scene")?)),
            (None, None) => root.scenes.first().map(|s| (0, s)),
        };
        let Some((index, gscene)) = chosen else {
            if root.nodes.is_empty() {
                return Err("nothing to draw: the file has no scenes and no nodes".into());
            }
            let mut is_child = vec![false; root.nodes.len()];
            for (i, node) in root.nodes.iter().enumerate() {
                for &c in &node.children {
                    lookup(&root.nodes, c, &format!("node {i}"), "child node")?;
                    is_child[c as usize] = true;
                }
            }
            let roots: Vec<u64> = (0..root.nodes.len() as u64).filter(|&i| !is_child[i as usize]).collect();
            self.scene.warnings.push(format!(
                "the file has no scene; drawing its {} root node(s) (nodes that are no node's child)",
                roots.len()
            ));
            return Ok(roots);
        };
        let owner = format!("scene {index}");
        if let Some(sky) = sunshade_extras(&gscene.extras) {
            if let Some(v) = sky.get("sky_radiance") {
                let radiance = rgb(v).map_err(|e| format!("{owner} extras: sky_radiance {e}"))?;
                self.scene.lights.sky = Some(radiance);
            }
        }
        for &n in &gscene.nodes {
            lookup(&root.nodes, n, &owner, "node")?;
        }
        Ok(gscene.nodes.clone())
    }

    /// Visits the hierarchy depth first, parents before children and children in order, with an explicit stack
    /// (a chain of 10⁵ nodes must not overflow the call stack). A node reached a second time means a cycle or a node
    /// with two parents; glTF requires the hierarchy to be a set of disjoint trees.
    fn walk(&mut self, roots: &[u64]) -> Result<(), String> {
        let root = self.root;
        let mut visited = vec![false; root.nodes.len()];
        let mut stack: Vec<(u64, DMat4)> = roots.iter().rev().map(|&n| (n, DMat4::IDENTITY)).collect();
        while let Some((index, parent)) = stack.pop() {
            let node = lookup(&root.nodes, index, "the hierarchy", "node")?;
            let seen = &mut visited[index as usize];
            if *seen {
                return Err(format!(
                    "node {index} is reached twice: the node hierarchy has a cycle or a node with two parents"
                ));
            }
            *seen = true;
            let world = parent * local_transform(index, node, self.poses.get(&index))?;
            self.visit(index, node, &world)?;
            for &child in node.children.iter().rev() {
                lookup(&root.nodes, child, &format!("node {index}"), "child node")?;
                stack.push((child, world));
            }
        }
        Ok(())
    }

    /// What one node holds: a mesh, a camera, a KHR_lights_punctual light, a disk light in its extras.
    fn visit(&mut self, index: u64, node: &NodeDef, world: &DMat4) -> Result<(), String> {
        let root = self.root;
        let owner = format!("node {index}");
        if let Some(m) = node.mesh {
            let mesh = lookup(&root.meshes, m, &owner, "mesh")?;
            let mesh_name = match &mesh.name {
                Some(n) => format!("mesh '{n}'"),
                None => format!("mesh {m}"),
            };
            let posed = self.poses.get(&index).and_then(|p| p.weights.clone());
            let weights = posed.as_deref().or(node.weights.as_deref()).or(mesh.weights.as_deref()).unwrap_or(&[]);
            let joints = match node.skin {
                Some(skin) => Some(self.joint_matrices(index, skin)?),
                None => None,
            };
            for (p, primitive) in mesh.primitives.iter().enumerate() {
                let name = format!("{mesh_name} primitive {p}");
                self.add_primitive(index, &name, primitive, world, weights, joints.as_deref())?;
            }
        }
        if let Some(c) = node.camera {
            let camera = lookup(&root.cameras, c, &owner, "camera")?;
            let placed = read_camera(c, camera, world).map_err(|e| format!("{owner}: {e}"))?;
            self.scene.cameras.push((c as usize, placed));
        }
        if let Some(l) = &node.extensions.lights_punctual {
            let lights = root.extensions.lights_punctual.as_ref().map_or(&[][..], |x| &x.lights[..]);
            let light = lookup(lights, l.light, &format!("{owner} KHR_lights_punctual"), "light")?;
            self.add_light(index, l.light, light, world)?;
        }
        if let Some(extras) = sunshade_extras(&node.extras) {
            self.add_extras_light(index, &extras, world)?;
        }
        Ok(())
    }

    /// One primitive of a node's mesh: its vertex streams read (morphed by `weights`), carried to world space by
    /// the node's transform or, for a skinned node, by each vertex's blend of `joints` (each joint's world matrix
    /// times its inverse bind matrix; the node's own transform is then ignored, as glTF says), and flattened.
    fn add_primitive(
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
    fn joint_matrices(&self, node: u64, skin: u64) -> Result<Vec<DMat4>, String> {
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

    fn material_index(&mut self, name: &str, primitive: &PrimitiveDef) -> Result<usize, String> {
        match primitive.material {
            Some(i) => lookup(&self.root.materials, i, name, "material").map(|_| i as usize),
            None => Ok(*self.default_material.get_or_insert_with(|| {
                self.scene.materials.push(Material::default_material());
                self.scene.materials.len() - 1
            })),
        }
    }

    fn add_light(&mut self, node: u64, index: u64, light: &LightDef, world: &DMat4) -> Result<(), String> {
        let label = light.name.as_ref().map_or_else(|| format!("light {index}"), |n| format!("light '{n}'"));
        match light.kind.as_str() {
            "directional" => {
                if self.scene.lights.sun.is_some() {
                    self.scene.warnings.push(format!("{label}: a second directional light is ignored (one sun)"));
                    return Ok(());
                }
                // glTF's color and intensity are single-precision floats, as the gltf crate read them.
                let e = light.intensity as f32;
                let color = light.color.map(|c| c as f32);
                let irradiance = color.map(|c| c * e);
                let valid = |v: f32| v.is_finite() && v >= 0.0;
                if !valid(e) || !color.iter().all(|&c| valid(c)) || !irradiance.iter().all(|&v| valid(v)) {
                    return Err(format!(
                        "{label} (node {node}): intensity {} × color {:?} must be finite and non-negative \
                         (the sun's E⊥ in W/m²)",
                        light.intensity, light.color
                    ));
                }
                // The light shines along its node's −Z, so the direction towards the sun is the node's +Z.
                let Some(direction) = world.transform_vector3(DVec3::Z).try_normalize() else {
                    self.scene.warnings.push(format!("{label}: node {node} has no direction; ignored"));
                    return Ok(());
                };
                self.scene.lights.sun = Some(Sun {
                    direction: direction.as_vec3(),
                    irradiance,
                    angular_diameter: degrees_to_radians(SUN_ANGULAR_DIAMETER_DEGREES) as f32,
                });
            }
            "point" | "spot" => self.scene.warnings.push(format!(
                "{label}: {} light ignored (sunshade renders the sun, disk skylights and the sky)",
                light.kind
            )),
            other => {
                self.scene.warnings.push(format!("{label}: type '{other}' is not a KHR_lights_punctual type; ignored"))
            }
        }
        Ok(())
    }

    /// A disk light given by a node's `extras`.
    fn add_extras_light(&mut self, node: u64, extras: &Value, world: &DMat4) -> Result<(), String> {
        let at = |what: &str| format!("node {node} extras: {what}");
        match extras.get("light").and_then(|v| v.as_str()) {
            Some("disk") => {}
            Some(other) => {
                self.scene
                    .warnings
                    .push(format!("{}; ignored", at(&format!("light '{other}' is not a sunshade light (disk)"))));
                return Ok(());
            }
            None => return Ok(()),
        }
        let radius = extras
            .get("radius")
            .and_then(|v| v.as_f64())
            .filter(|r| r.is_finite() && *r > 0.0)
            .ok_or_else(|| at("disk light needs \"radius\": a positive number [m]"))?;
        let radiance = rgb(extras.get("radiance").ok_or_else(|| at("disk light needs \"radiance\" [W/(m²·sr)]"))?)
            .map_err(|e| at(&format!("radiance {e}")))?;
        // The disk lies in the local XY plane; in world space it spans ex, ey. Its emission direction is the
        // plane's normal on the side of the node's −Z (a mirrored node mirrors the light with it).
        let (ex, ey) = (world.transform_vector3(DVec3::X), world.transform_vector3(DVec3::Y));
        let normal = ex.cross(ey);
        let minus_z = world.transform_vector3(-DVec3::Z);
        let Some(direction) = (normal * normal.dot(minus_z).signum()).try_normalize() else {
            return Err(at("the node's transform flattens the disk"));
        };
        let (lx, ly) = (ex.length(), ey.length());
        if (lx - ly).abs() > 1e-6 * lx.max(ly) || ex.dot(ey).abs() > 1e-6 * lx * ly {
            self.scene
                .warnings
                .push(at("disk light under a non-uniform scale or shear: drawn as the disk of equal area"));
        }
        let scale = normal.length().sqrt();
        let radius = radius * scale;
        let center = world.transform_point3(DVec3::ZERO);
        if center.abs().max_element().max(radius) > MAX_DISK_EXTENT_M || (radius as f32) < f32::MIN_POSITIVE {
            return Err(at(&format!(
                "the disk (radius {radius:e} m at {center}) must lie within {MAX_DISK_EXTENT_M:e} m, its radius a normal f32"
            )));
        }
        let radius = radius as f32;
        self.scene.lights.disks.push(DiskLight {
            center: center.as_vec3(),
            direction: direction.as_vec3(),
            radius,
            radiance,
        });
        Ok(())
    }
}

/// glTF's matrix and TRS are single-precision floats: each is rounded to f32 (as the gltf crate and viewers read
/// them), then composed in f64 and rounded to f32 once per vertex.
fn f32s<const N: usize>(v: [f64; N]) -> [f64; N] {
    v.map(|x| x as f32 as f64)
}

/// A matrix's components rounded to f32, as glTF stores them (see [`f32s`]).
fn f32s_slice(m: &[f64]) -> Vec<f64> {
    m.iter().map(|&x| x as f32 as f64).collect()
}

/// Every node's world matrix, walked down from each node that is no node's child with an explicit stack; a node
/// reached twice keeps its first matrix (the scene walk reports the malformed hierarchy if it draws it).
fn node_world_matrices(root: &Root, poses: &HashMap<u64, NodePose>) -> Result<Vec<Option<DMat4>>, String> {
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

/// A node's local matrix: its matrix, or its TRS with any property the sampled animation drives replaced
/// (glTF animates only TRS nodes).
fn local_transform(index: u64, node: &NodeDef, pose: Option<&NodePose>) -> Result<DMat4, String> {
    let posed = pose.filter(|p| p.translation.is_some() || p.rotation.is_some() || p.scale.is_some());
    let m = match (node.matrix, posed) {
        (Some(matrix), None) => DMat4::from_cols_array(&f32s(matrix)),
        _ => {
            let q = DQuat::from_array(f32s(node.rotation.unwrap_or([0.0, 0.0, 0.0, 1.0])));
            let q = posed.and_then(|p| p.rotation).unwrap_or(q);
            let q = if q.length_squared() > 0.0 { q.normalize() } else { DQuat::NAN };
            let scale = DVec3::from_array(f32s(node.scale.unwrap_or([1.0; 3])));
            let translation = DVec3::from_array(f32s(node.translation.unwrap_or([0.0; 3])));
            DMat4::from_scale_rotation_translation(
                posed.and_then(|p| p.scale).unwrap_or(scale),
                q,
                posed.and_then(|p| p.translation).unwrap_or(translation),
            )
        }
    };
    if !m.is_finite() {
        return Err(format!("node {index} has a non-finite or zero-length transform"));
    }
    Ok(m)
}

fn read_camera(index: u64, camera: &CameraDef, world: &DMat4) -> Result<Camera, String> {
    let label = camera.name.as_ref().map_or_else(|| format!("camera {index}"), |n| format!("camera '{n}'"));
    // Camera properties are single-precision floats in glTF (see `f32s`).
    let f = |v: f64| v as f32 as f64;
    let projection = match (camera.kind.as_str(), &camera.perspective, &camera.orthographic) {
        ("perspective", Some(p), _) => {
            let (yfov, znear, zfar) = (f(p.yfov), f(p.znear), p.zfar.map(f));
            if !(yfov > 0.0 && yfov < std::f64::consts::PI) {
                return Err(format!("{label}: yfov {yfov} rad is not in (0, π)"));
            }
            // Written so that NaN fails the check.
            let valid = znear > 0.0 && zfar.is_none_or(|f| f > znear);
            if !valid {
                return Err(format!("{label}: needs 0 < znear < zfar (znear {znear}, zfar {zfar:?})"));
            }
            Projection::Perspective { yfov, znear, zfar }
        }
        ("orthographic", _, Some(o)) => {
            let (ymag, znear, zfar) = (f(o.ymag).abs(), f(o.znear), f(o.zfar));
            let valid = ymag > 0.0 && znear >= 0.0 && zfar > znear && ymag.is_finite() && zfar.is_finite();
            if !valid {
                return Err(format!("{label}: needs ymag ≠ 0 and 0 ≤ znear < zfar, all finite"));
            }
            Projection::Orthographic { ymag, znear, zfar }
        }
        (kind, _, _) => {
            return Err(format!("{label}: type '{kind}' needs its 'perspective' or 'orthographic' object"));
        }
    };
    let eye = world.transform_point3(DVec3::ZERO);
    let forward = world.transform_vector3(-DVec3::Z);
    let up = world.transform_vector3(DVec3::Y);
    Camera::looking(eye, forward, up, projection)
        .ok_or_else(|| format!("{label}: its node transform gives no view direction"))
}
