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

use std::path::{Path, PathBuf};

use glam::{DMat3, DMat4, DQuat, DVec3, Vec3, Vec4};
use serde_json::Value;

use super::camera::{Camera, Projection};
use super::gltf::accessor::AccessorReader;
use super::gltf::document::{self, lookup, CameraDef, LightDef, MaterialDef, NodeDef, PrimitiveDef, Root};
use super::gltf::files::UriScope;
use super::gltf::{self, SUPPORTED_EXTENSIONS};
use super::light::{DiskLight, Sun, MAX_DISK_EXTENT_M};
use super::material::{Brdf, Material, MetallicRoughness};
use super::tangent::{default_tangent, orthonormal_tangent, tangents_from_uv, triangle_tangent};
use super::{Mesh, Scene};
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
}

/// Loads the default scene of a glTF file.
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    load_with_options(path, &LoadOptions::default())
}

/// Loads a glTF file.
pub fn load_with_options(path: &Path, options: &LoadOptions) -> Result<Scene, LoadError> {
    let fail = |message: String| LoadError { path: path.to_path_buf(), message };
    let file = gltf::read(path, &options.uris).map_err(fail)?;
    Loader::new(&file.root, &file.buffers).load(options).map_err(fail)
}

struct Loader<'a> {
    root: &'a Root,
    reader: AccessorReader<'a>,
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
    fn new(root: &'a Root, buffers: &'a [Vec<u8>]) -> Self {
        Self {
            root,
            reader: AccessorReader { root, buffers },
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
        for (index, material) in root.materials.iter().enumerate() {
            let m = read_material(index, material)?;
            let ignored = ignored_material_features(material);
            if !ignored.is_empty() {
                self.scene.warnings.push(format!(
                    "{}: {} not modelled; ignored (the surface is opaque, untextured and not emissive)",
                    m.name,
                    ignored.join(", ")
                ));
            }
            self.scene.materials.push(m);
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
        if let Some(sky) = sunshade_extras(&gscene.extras).map_err(|e| format!("{owner}: {e}"))? {
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
            let world = parent * local_transform(index, node)?;
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
            for (p, primitive) in mesh.primitives.iter().enumerate() {
                self.add_primitive(index, &format!("{mesh_name} primitive {p}"), primitive, world)?;
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
        if let Some(extras) = sunshade_extras(&node.extras).map_err(|e| format!("{owner}: {e}"))? {
            self.add_extras_light(index, &extras, world)?;
        }
        Ok(())
    }

    fn add_primitive(&mut self, node: u64, name: &str, primitive: &PrimitiveDef, world: &DMat4) -> Result<(), String> {
        let mode = primitive.mode.unwrap_or(document::MODE_TRIANGLES);
        if mode != document::MODE_TRIANGLES {
            self.scene.warnings.push(format!("{name}: mode {} skipped (only TRIANGLES is rendered)", mode_name(mode)));
            return Ok(());
        }
        let linear = DMat3::from_mat4(*world);
        let det = linear.determinant();
        if !det.is_finite() || det == 0.0 {
            self.scene.warnings.push(format!("{name}: node {node} has a singular transform; skipped"));
            return Ok(());
        }
        let attribute = |semantic: &str| primitive.attributes.get(semantic).copied();
        let Some(pos_acc) = attribute("POSITION") else {
            self.scene.warnings.push(format!("{name}: no POSITION; skipped (the glTF spec asks for that)"));
            return Ok(());
        };
        let local_positions = self.reader.read(pos_acc, &format!("{name} POSITION"), "VEC3")?.values;
        if let Some(i) = local_positions.iter().position(|c| !c.is_finite()) {
            return Err(format!("{name}: POSITION accessor {pos_acc} holds a non-finite value at vertex {}", i / 3));
        }
        let vertex_count = local_positions.len() / 3;
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
        // Flat normals un-index: three vertices a triangle.
        let added = if attribute("NORMAL").is_some() { vertex_count } else { indices.len() };
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
        let positions: Vec<Vec3> = local_positions
            .chunks_exact(3)
            .map(|p| world.transform_point3(DVec3::new(p[0], p[1], p[2])).as_vec3())
            .collect();
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("{name}: vertex {i} is not finite after the node transform"));
        }

        let mut out =
            Mesh { name: name.to_string(), material: self.material_index(name, primitive)?, ..Default::default() };
        let per_vertex = |semantic: &str, kind: &str| -> Result<Option<Vec<f64>>, String> {
            let Some(acc) = attribute(semantic) else { return Ok(None) };
            let e = self.reader.read(acc, &format!("{name} {semantic}"), kind)?;
            if e.count() != vertex_count {
                return Err(format!("{name}: {semantic} has {} elements, POSITION {vertex_count}", e.count()));
            }
            Ok(Some(e.values))
        };
        // Tangent sources: TANGENT (transformed as a direction, handedness flipped by a mirroring node), else
        // TEXCOORD_0.
        let file_tangents = per_vertex("TANGENT", "VEC4")?.map(|t| {
            let w_sign = det.signum();
            t.chunks_exact(4)
                .map(|t| (linear * DVec3::new(t[0], t[1], t[2]), w_sign * t[3].signum()))
                .collect::<Vec<_>>()
        });
        let uvs = match file_tangents {
            None => per_vertex("TEXCOORD_0", "VEC2")?
                .map(|uv| uv.chunks_exact(2).map(|c| [c[0] as f32, c[1] as f32]).collect::<Vec<_>>()),
            Some(_) => None,
        };
        match per_vertex("NORMAL", "VEC3")? {
            Some(normals) => {
                // Normals transform by the inverse transpose of the linear part.
                let normal_matrix = linear.inverse().transpose();
                out.normals = normals
                    .chunks_exact(3)
                    .map(|n| {
                        let w = normal_matrix * DVec3::new(n[0], n[1], n[2]);
                        w.try_normalize().unwrap_or(DVec3::ZERO).as_vec3()
                    })
                    .collect();
                out.tangents = match (&file_tangents, &uvs) {
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
                    let tangents: [Vec4; 3] = match (&file_tangents, &uvs) {
                        (Some(t), _) => [0, 1, 2].map(|k| {
                            let (t, w) = t[tri[k] as usize];
                            orthonormal_tangent(t, nd).as_vec3().extend(w as f32)
                        }),
                        (None, Some(uv)) => {
                            let p = [a, b, c].map(|p| p.as_dvec3());
                            let (t, w) = match triangle_tangent(p, [0, 1, 2].map(|k| uv[tri[k] as usize])) {
                                Some((t, bt)) => {
                                    let t = orthonormal_tangent(t, nd);
                                    (t, if nd.cross(t).dot(bt) < 0.0 { -1.0 } else { 1.0 })
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
        if !out.indices.is_empty() {
            self.scene.meshes.push(out);
        }
        Ok(())
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

/// The `"sunshade"` object of an `extras` value, if any.
fn sunshade_extras(extras: &Option<Value>) -> Result<Option<Value>, String> {
    match extras {
        None => Ok(None),
        Some(v @ Value::Object(_)) => Ok(v.get("sunshade").cloned()),
        Some(_) => Ok(None),
    }
}

/// A radiance: `[r, g, b]` or one number for all three, finite and non-negative [W/(m²·sr)].
fn rgb(v: &Value) -> Result<[f32; 3], String> {
    let values: Vec<f64> = match v {
        Value::Number(n) => vec![n.as_f64().unwrap_or(f64::NAN); 3],
        Value::Array(a) if a.len() == 3 => a.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect(),
        _ => return Err("must be a number or [r, g, b]".into()),
    };
    if values.iter().any(|x| !(x.is_finite() && *x >= 0.0 && *x <= f32::MAX as f64)) {
        return Err(format!("{values:?} must be finite and non-negative"));
    }
    Ok([values[0] as f32, values[1] as f32, values[2] as f32])
}

/// glTF's matrix and TRS are single-precision floats: each is rounded to f32 (as the gltf crate and viewers read
/// them), then composed in f64 and rounded to f32 once per vertex.
fn f32s<const N: usize>(v: [f64; N]) -> [f64; N] {
    v.map(|x| x as f32 as f64)
}

fn local_transform(index: u64, node: &NodeDef) -> Result<DMat4, String> {
    let m = match node.matrix {
        Some(matrix) => DMat4::from_cols_array(&f32s(matrix)),
        None => {
            let q = DQuat::from_array(f32s(node.rotation.unwrap_or([0.0, 0.0, 0.0, 1.0])));
            let q = if q.length_squared() > 0.0 { q.normalize() } else { DQuat::NAN };
            DMat4::from_scale_rotation_translation(
                DVec3::from_array(f32s(node.scale.unwrap_or([1.0; 3]))),
                q,
                DVec3::from_array(f32s(node.translation.unwrap_or([0.0; 3]))),
            )
        }
    };
    if !m.is_finite() {
        return Err(format!("node {index} has a non-finite or zero-length transform"));
    }
    Ok(m)
}

/// The parts of a glTF material that sunshade does not model, by their glTF names: textures (the factors alone
/// are used), emission, alpha modes other than OPAQUE, and material extensions (KHR_materials_*).
fn ignored_material_features(material: &MaterialDef) -> Vec<String> {
    let pbr = &material.pbr_metallic_roughness;
    let mut ignored = Vec::new();
    let textures = [
        ("baseColorTexture", pbr.base_color_texture.is_some()),
        ("metallicRoughnessTexture", pbr.metallic_roughness_texture.is_some()),
        ("normalTexture", material.normal_texture.is_some()),
        ("occlusionTexture", material.occlusion_texture.is_some()),
        ("emissiveTexture", material.emissive_texture.is_some()),
        ("emissiveFactor", material.emissive_factor != [0.0; 3]),
    ];
    ignored.extend(textures.iter().filter(|(_, present)| *present).map(|(name, _)| name.to_string()));
    match material.alpha_mode.as_str() {
        "OPAQUE" => {}
        "MASK" | "BLEND" => ignored.push(format!("alphaMode {}", material.alpha_mode)),
        other => ignored.push(format!("alphaMode '{other}' (not a glTF alpha mode)")),
    }
    ignored.extend(material.extensions.keys().map(|e| format!("extension {e}")));
    ignored
}

fn read_material(index: usize, material: &MaterialDef) -> Result<Material, String> {
    let name = material.name.as_ref().map_or_else(|| format!("material {index}"), |n| format!("material '{n}'"));
    let pbr = &material.pbr_metallic_roughness;
    let [r, g, b, _] = pbr.base_color_factor.map(|c| c as f32);
    let albedo = [r, g, b];
    if albedo.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Err(format!("{name}: baseColorFactor {albedo:?} is outside [0, 1]"));
    }
    let metallic_roughness = MetallicRoughness {
        base_color: albedo,
        metallic: pbr.metallic_factor as f32,
        roughness: pbr.roughness_factor as f32,
    };
    let extras = sunshade_extras(&material.extras).map_err(|e| format!("{name}: {e}"))?;
    let brdf = match extras.as_ref().filter(|x| x.get("brdf").is_some()) {
        Some(x) => brdf_from_extras(x, albedo).map_err(|e| format!("{name} extras: {e}"))?,
        None => Brdf::Lambert { albedo },
    };
    brdf.validate().map_err(|e| format!("{name}: {e}"))?;
    Ok(Material { name, double_sided: material.double_sided, brdf, pbr: metallic_roughness })
}

/// `{"brdf": "lambert" | "phong" | "blinn-phong" | "ward", "kd": [..], "ks": [..], "exponent": e,
/// "alpha": a | "alpha_x": ax, "alpha_y": ay}`; Lambert may give `"albedo"` (else baseColorFactor).
fn brdf_from_extras(x: &Value, base_color: [f32; 3]) -> Result<Brdf, String> {
    let kind = x.get("brdf").and_then(|v| v.as_str()).ok_or("\"brdf\" must be a string")?;
    let color = |key: &str| -> Result<[f32; 3], String> {
        rgb(x.get(key).ok_or_else(|| format!("{kind} needs \"{key}\""))?).map_err(|e| format!("{key} {e}"))
    };
    let number = |key: &str| -> Result<f32, String> {
        x.get(key)
            .and_then(|v| v.as_f64())
            .filter(|v| v.is_finite())
            .map(|v| v as f32)
            .ok_or_else(|| format!("{kind} needs \"{key}\": a number"))
    };
    Ok(match kind {
        "lambert" => Brdf::Lambert { albedo: if x.get("albedo").is_some() { color("albedo")? } else { base_color } },
        "phong" => Brdf::Phong { kd: color("kd")?, ks: color("ks")?, exponent: number("exponent")? },
        "blinn-phong" => Brdf::BlinnPhong { kd: color("kd")?, ks: color("ks")?, exponent: number("exponent")? },
        "ward" => {
            let (alpha_x, alpha_y) = if x.get("alpha").is_some() {
                let a = number("alpha")?;
                (a, a)
            } else {
                (number("alpha_x")?, number("alpha_y")?)
            };
            Brdf::Ward { kd: color("kd")?, ks: color("ks")?, alpha_x, alpha_y }
        }
        other => return Err(format!("brdf '{other}' is not one of lambert, phong, blinn-phong, ward")),
    })
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
