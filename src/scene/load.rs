//! glTF 2.0 → [`Scene`]: `.gltf` with external `.bin` or data URIs, and `.glb`.
//!
//! What is read: the chosen scene's node hierarchy (matrix or TRS transforms), every TRIANGLES primitive (other
//! modes are skipped with a warning), u8/u16/u32 or no indices, POSITION and NORMAL (flat normals where a
//! primitive has none, as the glTF spec requires), TANGENT or TEXCOORD_0 (for tangents), materials
//! (`baseColorFactor` as the Lambertian albedo, or the BRDF of the material's
//! `{"sunshade": {"brdf": …}}` extras),
//! cameras, KHR_lights_punctual directional lights (the sun), disk skylights from node `extras`
//! (`{"sunshade": {"light": "disk", "radius": R, "radiance": [r, g, b]}}`: a disk in the node's local XY plane at its
//! origin, emitting towards local −Z) and the overcast sky from the scene's `extras`
//! (`{"sunshade": {"sky_radiance": [r, g, b]}}`). Every problem is an error naming the file and the glTF object;
//! nothing here panics on bad input.

use std::path::{Path, PathBuf};

use glam::{DMat3, DMat4, DQuat, DVec3, Vec3, Vec4};

use super::accessor::AccessorReader;
use super::camera::{Camera, Projection};
use super::light::{DiskLight, Sun};
use super::material::{Brdf, Material, MetallicRoughness};
use super::tangent::{default_tangent, orthonormal_tangent, tangents_from_uv, triangle_tangent};
use super::uri::{self, UriTarget};
use super::{Mesh, Scene};
use crate::shading::radiometry::{degrees_to_radians, SUN_ANGULAR_DIAMETER_DEGREES};

/// A glTF file that could not be loaded: `path: problem`, one line.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", path.display())]
pub struct LoadError {
    pub path: PathBuf,
    pub message: String,
}

/// Choices made while loading.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Which glTF scene to load; `None` = the file's default scene (or its first).
    pub scene: Option<usize>,
}

/// Loads the default scene of a glTF file.
pub fn load(path: &Path) -> Result<Scene, LoadError> {
    load_with_options(path, &LoadOptions::default())
}

/// Loads a glTF file.
pub fn load_with_options(path: &Path, options: &LoadOptions) -> Result<Scene, LoadError> {
    let fail = |message: String| LoadError { path: path.to_path_buf(), message };
    let bytes = std::fs::read(path).map_err(|e| fail(format!("cannot read file: {e}")))?;
    let gltf = gltf::Gltf::from_slice(&bytes).map_err(|e| fail(describe_gltf_error(&e)))?;
    let buffers = load_buffers(path, &gltf).map_err(fail)?;
    Loader::new(&gltf.document, &buffers).load(options).map_err(fail)
}

fn describe_gltf_error(e: &gltf::Error) -> String {
    match e {
        gltf::Error::Deserialize(e) => format!("invalid glTF JSON: {e}"),
        gltf::Error::Binary(e) => format!("invalid GLB container: {e}"),
        gltf::Error::Validation(errors) => {
            let list: Vec<String> = errors.iter().take(3).map(|(path, err)| format!("{path}: {err}")).collect();
            let more = if errors.len() > 3 { format!(" (and {} more)", errors.len() - 3) } else { String::new() };
            format!("invalid glTF: {}{more}", list.join("; "))
        }
        other => format!("invalid glTF: {other}"),
    }
}

/// The bytes of every buffer: the GLB binary chunk, a data URI, or a file relative to the glTF file.
fn load_buffers(path: &Path, gltf: &gltf::Gltf) -> Result<Vec<Vec<u8>>, String> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    for buffer in gltf.document.buffers() {
        let i = buffer.index();
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => gltf
                .blob
                .clone()
                .ok_or_else(|| format!("buffer {i} refers to the GLB binary chunk, which the file does not have"))?,
            gltf::buffer::Source::Uri(u) => match uri::resolve(u).map_err(|e| format!("buffer {i}: {e}"))? {
                UriTarget::Data(bytes) => bytes,
                UriTarget::File(rel) => {
                    let file = dir.join(&rel);
                    std::fs::read(&file).map_err(|e| format!("buffer {i}: cannot read '{}': {e}", file.display()))?
                }
            },
        };
        if data.len() < buffer.length() {
            return Err(format!("buffer {i} holds {} bytes but declares byteLength {}", data.len(), buffer.length()));
        }
        out.push(data);
    }
    Ok(out)
}

struct Loader<'a> {
    doc: &'a gltf::Document,
    reader: AccessorReader<'a>,
    scene: Scene,
    /// Index of glTF's default material in `scene.materials`, once a primitive needs it.
    default_material: Option<usize>,
}

impl<'a> Loader<'a> {
    fn new(doc: &'a gltf::Document, buffers: &'a [Vec<u8>]) -> Self {
        Self { doc, reader: AccessorReader { buffers }, scene: Scene::default(), default_material: None }
    }

    fn load(mut self, options: &LoadOptions) -> Result<Scene, String> {
        let scene_count = self.doc.scenes().len();
        let gscene = match options.scene {
            Some(n) => self
                .doc
                .scenes()
                .nth(n)
                .ok_or_else(|| format!("scene {n} does not exist (the file has {scene_count})"))?,
            None => self
                .doc
                .default_scene()
                .or_else(|| self.doc.scenes().next())
                .ok_or("the file has no scene to render")?,
        };
        let unmodelled: Vec<&str> = self.doc.extensions_used().filter(|e| *e != "KHR_lights_punctual").collect();
        if !unmodelled.is_empty() {
            self.scene.warnings.push(format!("extensions not modelled, ignored: {}", unmodelled.join(", ")));
        }
        for material in self.doc.materials() {
            let m = read_material(&material)?;
            let ignored = ignored_material_features(&material);
            if !ignored.is_empty() {
                self.scene.warnings.push(format!(
                    "{}: {} not modelled; ignored (the surface is opaque, untextured and not emissive)",
                    m.name,
                    ignored.join(", ")
                ));
            }
            self.scene.materials.push(m);
        }
        if let Some(sky) = sunshade_extras(gscene.extras()).map_err(|e| format!("scene {}: {e}", gscene.index()))? {
            if let Some(v) = sky.get("sky_radiance") {
                let radiance = rgb(v).map_err(|e| format!("scene {} extras: sky_radiance {e}", gscene.index()))?;
                self.scene.lights.sky = Some(radiance);
            }
        }
        let mut path = Vec::new();
        for node in gscene.nodes() {
            self.visit(&node, DMat4::IDENTITY, &mut path)?;
        }
        Ok(self.scene)
    }

    fn visit(&mut self, node: &gltf::Node, parent: DMat4, path: &mut Vec<usize>) -> Result<(), String> {
        if path.contains(&node.index()) {
            return Err(format!("node {} is its own ancestor (the node hierarchy has a cycle)", node.index()));
        }
        let world = parent * local_transform(node)?;
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                self.add_primitive(node, &mesh, &primitive, &world)?;
            }
        }
        if let Some(camera) = node.camera() {
            let c = read_camera(&camera, &world).map_err(|e| format!("node {}: {e}", node.index()))?;
            self.scene.cameras.push((camera.index(), c));
        }
        if let Some(light) = node.light() {
            self.add_light(node, &light, &world);
        }
        if let Some(extras) = sunshade_extras(node.extras()).map_err(|e| format!("node {}: {e}", node.index()))? {
            self.add_extras_light(node, &extras, &world)?;
        }
        path.push(node.index());
        for child in node.children() {
            self.visit(&child, world, path)?;
        }
        path.pop();
        Ok(())
    }

    fn add_primitive(
        &mut self,
        node: &gltf::Node,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        world: &DMat4,
    ) -> Result<(), String> {
        let name = match mesh.name() {
            Some(n) => format!("mesh '{n}' primitive {}", primitive.index()),
            None => format!("mesh {} primitive {}", mesh.index(), primitive.index()),
        };
        if primitive.mode() != gltf::mesh::Mode::Triangles {
            self.scene
                .warnings
                .push(format!("{name}: mode {:?} skipped (only TRIANGLES is rendered)", primitive.mode()));
            return Ok(());
        }
        let linear = DMat3::from_mat4(*world);
        let det = linear.determinant();
        if !det.is_finite() || det == 0.0 {
            self.scene.warnings.push(format!("{name}: node {} has a singular transform; skipped", node.index()));
            return Ok(());
        }
        let pos_acc = primitive.get(&gltf::Semantic::Positions).ok_or_else(|| format!("{name}: no POSITION"))?;
        let local_positions = self.reader.read_vec3_f32(&pos_acc).map_err(|e| format!("{name}: POSITION: {e}"))?;
        if let Some(i) = local_positions.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(format!(
                "{name}: POSITION accessor {} holds a non-finite value at vertex {i}",
                pos_acc.index()
            ));
        }
        let vertex_count = local_positions.len();
        let mut indices = match primitive.indices() {
            Some(acc) => self.reader.read_indices(&acc).map_err(|e| format!("{name}: indices: {e}"))?,
            None => (0..vertex_count as u32).collect(),
        };
        if indices.len() % 3 != 0 {
            return Err(format!("{name}: {} indices is not a whole number of triangles", indices.len()));
        }
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(format!("{name}: index {bad} is out of range ({vertex_count} vertices)"));
        }
        // Mirrored node: the winding flips with the determinant's sign; swap two corners to keep CCW = front.
        if det < 0.0 {
            for tri in indices.chunks_exact_mut(3) {
                tri.swap(1, 2);
            }
        }
        let positions: Vec<Vec3> = local_positions
            .iter()
            .map(|p| world.transform_point3(DVec3::from_array(p.map(f64::from))).as_vec3())
            .collect();
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("{name}: vertex {i} is not finite after the node transform"));
        }

        let mut out = Mesh { name, material: self.material_index(primitive), ..Default::default() };
        // Tangent sources: TANGENT (transformed as a direction, handedness flipped by a mirroring node), else
        // TEXCOORD_0.
        let file_tangents = match primitive.get(&gltf::Semantic::Tangents) {
            Some(acc) => {
                let t = self.reader.read_vec4_f32(&acc).map_err(|e| format!("{}: TANGENT: {e}", out.name))?;
                if t.len() != vertex_count {
                    return Err(format!("{}: TANGENT has {} elements, POSITION {vertex_count}", out.name, t.len()));
                }
                let w_sign = det.signum();
                Some(
                    t.iter()
                        .map(|t| {
                            (linear * DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64), w_sign * t[3].signum() as f64)
                        })
                        .collect::<Vec<_>>(),
                )
            }
            None => None,
        };
        let uvs = match primitive.get(&gltf::Semantic::TexCoords(0)) {
            Some(acc) if file_tangents.is_none() => {
                let uv = self.reader.read_texcoords(&acc).map_err(|e| format!("{}: TEXCOORD_0: {e}", out.name))?;
                if uv.len() != vertex_count {
                    return Err(format!("{}: TEXCOORD_0 has {} elements, POSITION {vertex_count}", out.name, uv.len()));
                }
                Some(uv)
            }
            _ => None,
        };
        match primitive.get(&gltf::Semantic::Normals) {
            Some(acc) => {
                let normals = self.reader.read_vec3_f32(&acc).map_err(|e| format!("{}: NORMAL: {e}", out.name))?;
                if normals.len() != vertex_count {
                    return Err(format!(
                        "{}: NORMAL has {} elements, POSITION {vertex_count}",
                        out.name,
                        normals.len()
                    ));
                }
                // Normals transform by the inverse transpose of the linear part.
                let normal_matrix = linear.inverse().transpose();
                out.normals = normals
                    .iter()
                    .map(|n| {
                        let w = normal_matrix * DVec3::from_array(n.map(f64::from));
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

    fn material_index(&mut self, primitive: &gltf::Primitive) -> usize {
        match primitive.material().index() {
            Some(i) => i,
            None => *self.default_material.get_or_insert_with(|| {
                self.scene.materials.push(Material::default_material());
                self.scene.materials.len() - 1
            }),
        }
    }

    fn add_light(&mut self, node: &gltf::Node, light: &gltf::khr_lights_punctual::Light, world: &DMat4) {
        let label = light.name().map_or_else(|| format!("light {}", light.index()), |n| format!("light '{n}'"));
        match light.kind() {
            gltf::khr_lights_punctual::Kind::Directional => {
                if self.scene.lights.sun.is_some() {
                    self.scene.warnings.push(format!("{label}: a second directional light is ignored (one sun)"));
                    return;
                }
                // The light shines along its node's −Z, so the direction towards the sun is the node's +Z.
                let Some(direction) = world.transform_vector3(DVec3::Z).try_normalize() else {
                    self.scene.warnings.push(format!("{label}: node {} has no direction; ignored", node.index()));
                    return;
                };
                let e = light.intensity();
                self.scene.lights.sun = Some(Sun {
                    direction: direction.as_vec3(),
                    irradiance: light.color().map(|c| c * e),
                    angular_diameter: degrees_to_radians(SUN_ANGULAR_DIAMETER_DEGREES) as f32,
                });
            }
            other => self.scene.warnings.push(format!(
                "{label}: {} light ignored (sunshade renders the sun, disk skylights and the sky)",
                match other {
                    gltf::khr_lights_punctual::Kind::Point => "point",
                    _ => "spot",
                }
            )),
        }
    }
}

impl Loader<'_> {
    /// A disk light given by a node's `extras`.
    fn add_extras_light(&mut self, node: &gltf::Node, extras: &serde_json::Value, world: &DMat4) -> Result<(), String> {
        let at = |what: &str| format!("node {} extras: {what}", node.index());
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
        self.scene.lights.disks.push(DiskLight {
            center: world.transform_point3(DVec3::ZERO).as_vec3(),
            direction: direction.as_vec3(),
            radius: (radius * scale) as f32,
            radiance,
        });
        Ok(())
    }
}

/// The `"sunshade"` object of an `extras` value, if any.
fn sunshade_extras(extras: &gltf::json::Extras) -> Result<Option<serde_json::Value>, String> {
    let Some(raw) = extras else { return Ok(None) };
    let value: serde_json::Value = serde_json::from_str(raw.get()).map_err(|e| format!("extras are not JSON: {e}"))?;
    Ok(value.get("sunshade").cloned())
}

/// A radiance: `[r, g, b]` or one number for all three, finite and non-negative [W/(m²·sr)].
fn rgb(v: &serde_json::Value) -> Result<[f32; 3], String> {
    let values: Vec<f64> = match v {
        serde_json::Value::Number(n) => vec![n.as_f64().unwrap_or(f64::NAN); 3],
        serde_json::Value::Array(a) if a.len() == 3 => a.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect(),
        _ => return Err("must be a number or [r, g, b]".into()),
    };
    if values.iter().any(|x| !(x.is_finite() && *x >= 0.0 && *x <= f32::MAX as f64)) {
        return Err(format!("{values:?} must be finite and non-negative"));
    }
    Ok([values[0] as f32, values[1] as f32, values[2] as f32])
}

fn local_transform(node: &gltf::Node) -> Result<DMat4, String> {
    let m = match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from))),
        gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
            let q = DQuat::from_array(rotation.map(f64::from));
            let q = if q.length_squared() > 0.0 { q.normalize() } else { DQuat::NAN };
            DMat4::from_scale_rotation_translation(
                DVec3::from_array(scale.map(f64::from)),
                q,
                DVec3::from_array(translation.map(f64::from)),
            )
        }
    };
    if !m.is_finite() {
        return Err(format!("node {} has a non-finite or zero-length transform", node.index()));
    }
    Ok(m)
}

/// The parts of a glTF material that sunshade does not model, by their glTF names: textures (the factors alone
/// are used), emission and alpha modes other than OPAQUE.
fn ignored_material_features(material: &gltf::Material) -> Vec<String> {
    let pbr = material.pbr_metallic_roughness();
    let mut ignored = Vec::new();
    let textures = [
        ("baseColorTexture", pbr.base_color_texture().is_some()),
        ("metallicRoughnessTexture", pbr.metallic_roughness_texture().is_some()),
        ("normalTexture", material.normal_texture().is_some()),
        ("occlusionTexture", material.occlusion_texture().is_some()),
        ("emissiveTexture", material.emissive_texture().is_some()),
        ("emissiveFactor", material.emissive_factor() != [0.0; 3]),
    ];
    ignored.extend(textures.iter().filter(|(_, present)| *present).map(|(name, _)| name.to_string()));
    match material.alpha_mode() {
        gltf::material::AlphaMode::Opaque => {}
        gltf::material::AlphaMode::Mask => ignored.push("alphaMode MASK".into()),
        gltf::material::AlphaMode::Blend => ignored.push("alphaMode BLEND".into()),
    }
    ignored
}

fn read_material(material: &gltf::Material) -> Result<Material, String> {
    let index = material.index().unwrap_or(0);
    let name = material.name().map_or_else(|| format!("material {index}"), |n| format!("material '{n}'"));
    let pbr = material.pbr_metallic_roughness();
    let [r, g, b, _] = pbr.base_color_factor();
    let albedo = [r, g, b];
    if albedo.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Err(format!("{name}: baseColorFactor {albedo:?} is outside [0, 1]"));
    }
    let metallic_roughness =
        MetallicRoughness { base_color: albedo, metallic: pbr.metallic_factor(), roughness: pbr.roughness_factor() };
    let extras = sunshade_extras(material.extras()).map_err(|e| format!("{name}: {e}"))?;
    let brdf = match extras.as_ref().and_then(|x| x.get("brdf")) {
        Some(_) => {
            brdf_from_extras(extras.as_ref().expect("checked"), albedo).map_err(|e| format!("{name} extras: {e}"))?
        }
        None => Brdf::Lambert { albedo },
    };
    brdf.validate().map_err(|e| format!("{name}: {e}"))?;
    Ok(Material { name, double_sided: material.double_sided(), brdf, pbr: metallic_roughness })
}

/// `{"brdf": "lambert" | "phong" | "blinn-phong" | "ward", "kd": [..], "ks": [..], "exponent": e,
/// "alpha": a | "alpha_x": ax, "alpha_y": ay}`; Lambert may give `"albedo"` (else baseColorFactor).
fn brdf_from_extras(x: &serde_json::Value, base_color: [f32; 3]) -> Result<Brdf, String> {
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

fn read_camera(camera: &gltf::Camera, world: &DMat4) -> Result<Camera, String> {
    let label = camera.name().map_or_else(|| format!("camera {}", camera.index()), |n| format!("camera '{n}'"));
    let projection = match camera.projection() {
        gltf::camera::Projection::Perspective(p) => {
            let (yfov, znear, zfar) = (p.yfov() as f64, p.znear() as f64, p.zfar().map(f64::from));
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
        gltf::camera::Projection::Orthographic(o) => {
            let (ymag, znear, zfar) = (o.ymag().abs() as f64, o.znear() as f64, o.zfar() as f64);
            let valid = ymag > 0.0 && znear >= 0.0 && zfar > znear;
            if !valid {
                return Err(format!("{label}: needs ymag ≠ 0 and 0 ≤ znear < zfar"));
            }
            Projection::Orthographic { ymag, znear, zfar }
        }
    };
    let eye = world.transform_point3(DVec3::ZERO);
    let forward = world.transform_vector3(-DVec3::Z);
    let up = world.transform_vector3(DVec3::Y);
    Camera::looking(eye, forward, up, projection)
        .ok_or_else(|| format!("{label}: its node transform gives no view direction"))
}
