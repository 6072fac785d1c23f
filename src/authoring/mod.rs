//! Writing small glTF 2.0 scenes: the one helper behind the generated scenes in `models/` and in the tests.
//!
//! It knows glTF (JSON and GLB) and nothing else. Geometry helpers ([`shapes`]) build the meshes.

pub mod chart;
pub mod shapes;

use std::path::Path;

use base64::Engine;
use serde_json::{json, Map, Value};

/// Index data of a primitive, in the component type the file will use.
#[derive(Clone, Debug)]
pub enum Indices {
    U8(Vec<u8>),
    U16(Vec<u16>),
    U32(Vec<u32>),
}

impl Indices {
    /// The narrowest type that holds every index.
    pub fn narrowest(indices: &[u32]) -> Self {
        let max = indices.iter().copied().max().unwrap_or(0);
        if max <= u8::MAX as u32 {
            Indices::U8(indices.iter().map(|&i| i as u8).collect())
        } else if max <= u16::MAX as u32 {
            Indices::U16(indices.iter().map(|&i| i as u16).collect())
        } else {
            Indices::U32(indices.to_vec())
        }
    }
}

/// Triangle data of one primitive.
#[derive(Clone, Debug, Default)]
pub struct Primitive {
    pub positions: Vec<[f32; 3]>,
    /// `None`: the file carries no NORMAL (the loader must make flat normals).
    pub normals: Option<Vec<[f32; 3]>>,
    /// TEXCOORD_0 (f32), if any.
    pub tex_coords: Option<Vec<[f32; 2]>>,
    /// COLOR_0 (f32 RGBA), if any.
    pub colors: Option<Vec<[f32; 4]>>,
    /// `None`: non-indexed.
    pub indices: Option<Indices>,
    pub material: Option<usize>,
    /// glTF primitive mode; 4 = TRIANGLES (the default).
    pub mode: Option<u32>,
}

/// A node's local transform.
#[derive(Clone, Debug, Default)]
pub enum Transform {
    #[default]
    Identity,
    /// Column-major 4×4.
    Matrix([f32; 16]),
    /// Translation, rotation quaternion (x, y, z, w), scale.
    Trs { translation: [f32; 3], rotation: [f32; 4], scale: [f32; 3] },
}

/// A node of the hierarchy.
#[derive(Clone, Debug, Default)]
pub struct Node {
    pub name: Option<String>,
    pub transform: Transform,
    pub mesh: Option<usize>,
    pub camera: Option<usize>,
    /// KHR_lights_punctual light index.
    pub light: Option<usize>,
    pub children: Vec<usize>,
    pub extras: Option<Value>,
}

/// An 8-bit RGBA PNG of `width × height` pixels, row by row from the top.
pub fn png_rgba8(width: u32, height: u32, rgba: &[[u8; 4]]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    let data: Vec<u8> = rgba.iter().flatten().copied().collect();
    enc.write_header().and_then(|mut w| w.write_image_data(&data)).expect("PNG in memory");
    out
}

/// A glTF document being built, with one binary buffer.
#[derive(Clone, Debug)]
pub struct GltfBuilder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    images: Vec<Value>,
    textures: Vec<Value>,
    samplers: Vec<Value>,
    nodes: Vec<Value>,
    cameras: Vec<Value>,
    lights: Vec<Value>,
    scenes: Vec<Value>,
}

impl Default for GltfBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl GltfBuilder {
    pub fn new() -> Self {
        Self {
            bin: Vec::new(),
            views: Vec::new(),
            accessors: Vec::new(),
            meshes: Vec::new(),
            materials: Vec::new(),
            images: Vec::new(),
            textures: Vec::new(),
            samplers: Vec::new(),
            nodes: Vec::new(),
            cameras: Vec::new(),
            lights: Vec::new(),
            scenes: Vec::new(),
        }
    }

    fn push_view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut view = json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(view);
        self.views.len() - 1
    }

    fn push_vec3_accessor(&mut self, data: &[[f32; 3]], with_bounds: bool) -> usize {
        let bytes: Vec<u8> = data.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.push_view(&bytes, Some(34962));
        let mut acc = json!({ "bufferView": view, "componentType": 5126, "count": data.len(), "type": "VEC3" });
        if with_bounds && !data.is_empty() {
            let mut min = [f32::INFINITY; 3];
            let mut max = [f32::NEG_INFINITY; 3];
            for p in data {
                for k in 0..3 {
                    min[k] = min[k].min(p[k]);
                    max[k] = max[k].max(p[k]);
                }
            }
            acc["min"] = json!(min);
            acc["max"] = json!(max);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    /// Adds an accessor of f32 elements of `n` components each (`"VEC2"`, `"VEC4"`...); returns its index.
    pub fn add_accessor_f32(&mut self, data: &[f32], n: usize, kind: &str) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.push_view(&bytes, Some(34962));
        self.accessors
            .push(json!({ "bufferView": view, "componentType": 5126, "count": data.len() / n, "type": kind }));
        self.accessors.len() - 1
    }

    fn push_index_accessor(&mut self, indices: &Indices) -> usize {
        let (bytes, component, count): (Vec<u8>, u32, usize) = match indices {
            Indices::U8(v) => (v.clone(), 5121, v.len()),
            Indices::U16(v) => (v.iter().flat_map(|i| i.to_le_bytes()).collect(), 5123, v.len()),
            Indices::U32(v) => (v.iter().flat_map(|i| i.to_le_bytes()).collect(), 5125, v.len()),
        };
        let view = self.push_view(&bytes, Some(34963));
        self.accessors
            .push(json!({ "bufferView": view, "componentType": component, "count": count, "type": "SCALAR" }));
        self.accessors.len() - 1
    }

    /// Adds a mesh of the given primitives; returns its index.
    pub fn add_mesh(&mut self, name: &str, primitives: &[Primitive]) -> usize {
        let mut prims = Vec::new();
        for p in primitives {
            let mut attributes = Map::new();
            attributes.insert("POSITION".into(), json!(self.push_vec3_accessor(&p.positions, true)));
            if let Some(n) = &p.normals {
                attributes.insert("NORMAL".into(), json!(self.push_vec3_accessor(n, false)));
            }
            if let Some(uv) = &p.tex_coords {
                let flat: Vec<f32> = uv.iter().flatten().copied().collect();
                attributes.insert("TEXCOORD_0".into(), json!(self.add_accessor_f32(&flat, 2, "VEC2")));
            }
            if let Some(c) = &p.colors {
                let flat: Vec<f32> = c.iter().flatten().copied().collect();
                attributes.insert("COLOR_0".into(), json!(self.add_accessor_f32(&flat, 4, "VEC4")));
            }
            let mut prim = json!({ "attributes": attributes });
            if let Some(i) = &p.indices {
                prim["indices"] = json!(self.push_index_accessor(i));
            }
            if let Some(m) = p.material {
                prim["material"] = json!(m);
            }
            if let Some(mode) = p.mode {
                prim["mode"] = json!(mode);
            }
            prims.push(prim);
        }
        self.meshes.push(json!({ "name": name, "primitives": prims }));
        self.meshes.len() - 1
    }

    /// Adds a material with a Lambertian albedo (`baseColorFactor` RGB, and the extras `{"sunshade": {"brdf":
    /// "lambert"}}` where `extras` is `None`, so that sunshade reads it as Lambertian rather than as glTF's
    /// metallic-roughness BRDF); returns its index.
    pub fn add_material(&mut self, name: &str, albedo: [f32; 3], double_sided: bool, extras: Option<Value>) -> usize {
        let mut m = json!({
            "name": name,
            "pbrMetallicRoughness": { "baseColorFactor": [albedo[0], albedo[1], albedo[2], 1.0], "metallicFactor": 0.0 },
        });
        if double_sided {
            m["doubleSided"] = json!(true);
        }
        m["extras"] = extras.unwrap_or_else(|| json!({ "sunshade": { "brdf": "lambert" } }));
        self.materials.push(m);
        self.materials.len() - 1
    }

    /// Adds a material given as its glTF JSON object; returns its index.
    pub fn add_material_json(&mut self, material: Value) -> usize {
        self.materials.push(material);
        self.materials.len() - 1
    }

    /// Adds a PNG image stored in the binary buffer; returns its index.
    pub fn add_png_image(&mut self, png: &[u8]) -> usize {
        let view = self.push_view(png, None);
        self.images.push(json!({ "bufferView": view, "mimeType": "image/png" }));
        self.images.len() - 1
    }

    /// Adds a texture of an image with a sampler (glTF codes: `magFilter`, `minFilter`, `wrapS`, `wrapT`; `None`
    /// leaves a code out); returns its index.
    pub fn add_texture(&mut self, image: usize, mag: Option<u32>, min: Option<u32>, wrap: [u32; 2]) -> usize {
        let mut sampler = json!({ "wrapS": wrap[0], "wrapT": wrap[1] });
        if let Some(m) = mag {
            sampler["magFilter"] = json!(m);
        }
        if let Some(m) = min {
            sampler["minFilter"] = json!(m);
        }
        self.samplers.push(sampler);
        self.textures.push(json!({ "source": image, "sampler": self.samplers.len() - 1 }));
        self.textures.len() - 1
    }

    /// Adds a perspective camera (`yfov` \[rad\], `zfar = None` infinite); returns its index.
    pub fn add_perspective_camera(&mut self, yfov: f32, znear: f32, zfar: Option<f32>) -> usize {
        let mut p = json!({ "yfov": yfov, "znear": znear, "aspectRatio": 1.0 });
        if let Some(f) = zfar {
            p["zfar"] = json!(f);
        }
        self.cameras.push(json!({ "type": "perspective", "perspective": p }));
        self.cameras.len() - 1
    }

    /// Adds an orthographic camera (half-sizes \[m\]); returns its index.
    pub fn add_orthographic_camera(&mut self, xmag: f32, ymag: f32, znear: f32, zfar: f32) -> usize {
        self.cameras.push(json!({
            "type": "orthographic",
            "orthographic": { "xmag": xmag, "ymag": ymag, "znear": znear, "zfar": zfar },
        }));
        self.cameras.len() - 1
    }

    /// Adds a KHR_lights_punctual directional light (intensity read by sunshade as E⊥ [W/m²]).
    pub fn add_directional_light(&mut self, color: [f32; 3], intensity: f32) -> usize {
        self.lights.push(json!({ "type": "directional", "color": color, "intensity": intensity }));
        self.lights.len() - 1
    }

    /// Adds a KHR_lights_punctual point light (which sunshade ignores with a warning).
    pub fn add_point_light(&mut self, intensity: f32) -> usize {
        self.lights.push(json!({ "type": "point", "intensity": intensity }));
        self.lights.len() - 1
    }

    /// Adds a node; returns its index.
    pub fn add_node(&mut self, node: Node) -> usize {
        let mut n = json!({});
        if let Some(name) = node.name {
            n["name"] = json!(name);
        }
        match node.transform {
            Transform::Identity => {}
            Transform::Matrix(m) => n["matrix"] = json!(m),
            Transform::Trs { translation, rotation, scale } => {
                n["translation"] = json!(translation);
                n["rotation"] = json!(rotation);
                n["scale"] = json!(scale);
            }
        }
        if let Some(m) = node.mesh {
            n["mesh"] = json!(m);
        }
        if let Some(c) = node.camera {
            n["camera"] = json!(c);
        }
        if let Some(l) = node.light {
            n["extensions"] = json!({ "KHR_lights_punctual": { "light": l } });
        }
        if !node.children.is_empty() {
            n["children"] = json!(node.children);
        }
        if let Some(e) = node.extras {
            n["extras"] = e;
        }
        self.nodes.push(n);
        self.nodes.len() - 1
    }

    /// Adds a scene with these root nodes; the first scene added is the default one.
    pub fn add_scene(&mut self, roots: &[usize], extras: Option<Value>) -> usize {
        let mut s = json!({ "nodes": roots });
        if let Some(e) = extras {
            s["extras"] = e;
        }
        self.scenes.push(s);
        self.scenes.len() - 1
    }

    /// The JSON document; `buffer_uri` = `None` means the GLB binary chunk.
    pub fn document(&self, buffer_uri: Option<&str>) -> Value {
        let mut buffer = json!({ "byteLength": self.bin.len() });
        if let Some(uri) = buffer_uri {
            buffer["uri"] = json!(uri);
        }
        let mut doc = json!({
            "asset": { "version": "2.0", "generator": "sunshade authoring" },
            "buffers": [buffer],
            "bufferViews": self.views,
            "accessors": self.accessors,
            "meshes": self.meshes,
            "nodes": self.nodes,
            "scenes": self.scenes,
        });
        if !self.scenes.is_empty() {
            doc["scene"] = json!(0);
        }
        if !self.materials.is_empty() {
            doc["materials"] = json!(self.materials);
        }
        if !self.cameras.is_empty() {
            doc["cameras"] = json!(self.cameras);
        }
        if !self.images.is_empty() {
            doc["images"] = json!(self.images);
            doc["textures"] = json!(self.textures);
            doc["samplers"] = json!(self.samplers);
        }
        if !self.lights.is_empty() {
            doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
            doc["extensions"] = json!({ "KHR_lights_punctual": { "lights": self.lights } });
        }
        doc
    }

    /// The binary buffer.
    pub fn bin(&self) -> &[u8] {
        &self.bin
    }

    /// A binary glTF (GLB) file.
    pub fn to_glb(&self) -> Vec<u8> {
        let mut json = serde_json::to_vec(&self.document(None)).expect("serialisable");
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }

    /// A `.gltf` whose buffer is a base64 data URI.
    pub fn to_embedded_gltf(&self) -> String {
        let b64 = base64::engine::general_purpose::STANDARD.encode(&self.bin);
        let doc = self.document(Some(&format!("data:application/octet-stream;base64,{b64}")));
        serde_json::to_string_pretty(&doc).expect("serialisable")
    }

    /// Writes `path` by its extension: `.glb`, or `.gltf` with the buffer in `<stem>.bin` beside it.
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        match path.extension().and_then(|e| e.to_str()) {
            Some("glb") => std::fs::write(path, self.to_glb()),
            _ => {
                let bin_name = format!("{}.bin", path.file_stem().and_then(|s| s.to_str()).unwrap_or("buffer"));
                std::fs::write(path.with_file_name(&bin_name), &self.bin)?;
                let doc = self.document(Some(&bin_name));
                std::fs::write(path, serde_json::to_string_pretty(&doc).expect("serialisable"))
            }
        }
    }

    /// Writes a `.gltf` with its buffer embedded as a data URI.
    pub fn write_embedded(&self, path: &Path) -> std::io::Result<()> {
        std::fs::write(path, self.to_embedded_gltf())
    }
}
