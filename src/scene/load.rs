//! glTF 2.0 → [`Scene`]: `.gltf` with external `.bin` or data URIs, and `.glb`.
//!
//! What is read: the chosen scene's node hierarchy (matrix or TRS transforms, posed by an animation when asked;
//! without any scene, the file's root nodes), every TRIANGLES primitive (`load_mesh`: attributes, morph targets,
//! skins; other modes are skipped with a warning), materials and their textures (`load_material`), cameras,
//! KHR_lights_punctual directional lights (the sun), disk skylights from node `extras`
//! (`{"sunshade": {"light": "disk", "radius": R, "radiance": [r, g, b]}}`: a disk in the node's local XY plane at
//! its origin, emitting towards local −Z) and the overcast sky from the scene's `extras`
//! (`{"sunshade": {"sky_radiance": [r, g, b]}}`).
//!
//! Every problem is an error naming the file and the glTF object; nothing here panics or recurses on bad input:
//! the hierarchy is walked with an explicit stack, each node at most once.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{DMat4, DQuat, DVec3};
use serde_json::Value;

use super::animation::{self, NodePose};
use super::camera::{Camera, Projection};
use super::gltf::accessor::AccessorReader;
use super::gltf::document::{lookup, CameraDef, LightDef, NodeDef, PrimitiveDef, Root};
use super::gltf::files::AssetFiles;
use super::gltf::files::UriScope;
use super::gltf::{self, SUPPORTED_EXTENSIONS};
use super::light::{DiskLight, Sun, MAX_DISK_EXTENT_M};
use super::load_material::{rgb, sunshade_extras, MaterialReader};
use super::load_mesh::node_world_matrices;
use super::material::Material;
use super::Scene;
use crate::scene::light::SUN_ANGULAR_DIAMETER_DEGREES;

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
    /// Pose the scene by animation N at time T \[s\] (`--animation N --animation-time T`); `None`: the file's own transforms
    /// and weights (the rest pose).
    pub animation: Option<(usize, f64)>,
    /// Textures larger than this many texels on a side start at their first mip level that fits
    /// (`--max-texture-size`; `None`: as the images are).
    pub max_texture_size: Option<u32>,
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

pub(super) struct Loader<'a> {
    pub(super) root: &'a Root,
    pub(super) reader: AccessorReader<'a>,
    files: &'a AssetFiles,
    /// Every node's world matrix (`None` for nodes that no hierarchy walk from a parentless node reaches), for
    /// skins' joints.
    pub(super) node_world: Vec<Option<DMat4>>,
    /// Nodes posed by the sampled animation (`LoadOptions::animation`).
    poses: HashMap<u64, NodePose>,
    pub(super) scene: Scene,
    /// Index of glTF's default material in `scene.materials`, once a primitive needs it.
    default_material: Option<usize>,
    pub(super) vertex_count: usize,
}

/// glTF's names of the primitive modes.
pub(super) fn mode_name(mode: u64) -> String {
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
        materials.max_texture_size = options.max_texture_size;
        for (index, material) in root.materials.iter().enumerate() {
            let m = materials.read(index, material)?;
            self.scene.materials.push(m);
        }
        self.scene.textures = materials.decode_textures()?;
        self.scene.warnings.extend(materials.warnings);
        if let Some((index, time)) = options.animation {
            if !time.is_finite() {
                return Err(format!("--time {time} is not a finite number of seconds"));
            }
            self.poses = animation::sample(root, &self.reader, index, time)?;
        } else if !root.animations.is_empty() {
            self.scene.warnings.push(format!(
                "the file has {} animation(s); drawn at rest (--animation N --animation-time T poses it)",
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

    pub(super) fn material_index(&mut self, name: &str, primitive: &PrimitiveDef) -> Result<usize, String> {
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
                    angular_diameter: SUN_ANGULAR_DIAMETER_DEGREES.to_radians() as f32,
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
pub(super) fn f32s<const N: usize>(v: [f64; N]) -> [f64; N] {
    v.map(|x| x as f32 as f64)
}

/// A node's local matrix: its matrix, or its TRS with any property the sampled animation drives replaced
/// (glTF animates only TRS nodes).
pub(super) fn local_transform(index: u64, node: &NodeDef, pose: Option<&NodePose>) -> Result<DMat4, String> {
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
