//! The glTF 2.0 JSON document, as sunshade reads it: only the properties it uses, each optional where the spec
//! allows, unknown properties ignored.
//!
//! This is deliberately more permissive than a schema validator and stricter than nothing: types must match (an
//! index is a non-negative integer, a factor a number), but references between objects are not checked here.
//! Every reference is resolved through [`lookup`], which turns a dangling index into an error that names the
//! object holding it, so no index can panic however the file is built. Counts, lengths and offsets are `u64`, as
//! large as JSON integers that glTF allows, and every arithmetic on them downstream is checked.

use std::collections::BTreeMap;

use serde::Deserialize;
use serde_json::Value;

/// An index into one of the document's top-level arrays.
pub type Index = u64;

/// The root object.
#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct Root {
    pub asset: Option<Asset>,
    pub scene: Option<Index>,
    pub scenes: Vec<SceneDef>,
    pub nodes: Vec<NodeDef>,
    pub meshes: Vec<MeshDef>,
    pub accessors: Vec<AccessorDef>,
    pub buffer_views: Vec<BufferViewDef>,
    pub buffers: Vec<BufferDef>,
    pub materials: Vec<MaterialDef>,
    pub textures: Vec<TextureDef>,
    pub images: Vec<ImageDef>,
    pub samplers: Vec<SamplerDef>,
    pub cameras: Vec<CameraDef>,
    pub skins: Vec<SkinDef>,
    pub animations: Vec<Value>,
    pub extensions_used: Vec<String>,
    pub extensions_required: Vec<String>,
    pub extensions: RootExtensions,
    pub extras: Option<Value>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct Asset {
    pub version: String,
    pub min_version: Option<String>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub struct RootExtensions {
    #[serde(rename = "KHR_lights_punctual")]
    pub lights_punctual: Option<LightsPunctual>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub struct LightsPunctual {
    pub lights: Vec<LightDef>,
}

/// A KHR_lights_punctual light.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct LightDef {
    pub name: Option<String>,
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default = "white")]
    pub color: [f64; 3],
    #[serde(default = "one")]
    pub intensity: f64,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub struct SceneDef {
    pub name: Option<String>,
    pub nodes: Vec<Index>,
    pub extras: Option<Value>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub struct NodeDef {
    pub name: Option<String>,
    pub children: Vec<Index>,
    pub mesh: Option<Index>,
    pub camera: Option<Index>,
    pub skin: Option<Index>,
    /// Column-major 4×4; when present, TRS must be absent.
    pub matrix: Option<[f64; 16]>,
    pub translation: Option<[f64; 3]>,
    /// Unit quaternion (x, y, z, w).
    pub rotation: Option<[f64; 4]>,
    pub scale: Option<[f64; 3]>,
    pub weights: Option<Vec<f64>>,
    pub extensions: NodeExtensions,
    pub extras: Option<Value>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub struct NodeExtensions {
    #[serde(rename = "KHR_lights_punctual")]
    pub lights_punctual: Option<NodeLight>,
}

#[derive(Debug, Deserialize)]
pub struct NodeLight {
    pub light: Index,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub struct MeshDef {
    pub name: Option<String>,
    pub primitives: Vec<PrimitiveDef>,
    pub weights: Option<Vec<f64>>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub struct PrimitiveDef {
    /// Semantic → accessor, e.g. `"POSITION": 0`.
    pub attributes: BTreeMap<String, Index>,
    pub indices: Option<Index>,
    pub material: Option<Index>,
    /// 4 = TRIANGLES, the default.
    pub mode: Option<u64>,
    pub targets: Vec<BTreeMap<String, Index>>,
}

/// Primitive modes (glTF `mesh.primitive.mode`).
pub const MODE_TRIANGLES: u64 = 4;

#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct AccessorDef {
    pub buffer_view: Option<Index>,
    pub byte_offset: u64,
    pub component_type: u64,
    pub normalized: bool,
    pub count: u64,
    #[serde(rename = "type")]
    pub kind: String,
    pub sparse: Option<SparseDef>,
}

#[derive(Debug, Deserialize)]
pub struct SparseDef {
    pub count: u64,
    pub indices: SparseIndicesDef,
    pub values: SparseValuesDef,
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SparseIndicesDef {
    pub buffer_view: Index,
    #[serde(default)]
    pub byte_offset: u64,
    pub component_type: u64,
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SparseValuesDef {
    pub buffer_view: Index,
    #[serde(default)]
    pub byte_offset: u64,
}

#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct BufferViewDef {
    pub buffer: Index,
    pub byte_offset: u64,
    pub byte_length: u64,
    pub byte_stride: Option<u64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct BufferDef {
    pub uri: Option<String>,
    pub byte_length: u64,
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct MaterialDef {
    pub name: Option<String>,
    #[serde(default)]
    pub pbr_metallic_roughness: PbrDef,
    pub normal_texture: Option<TextureInfo>,
    pub occlusion_texture: Option<TextureInfo>,
    pub emissive_texture: Option<TextureInfo>,
    #[serde(default)]
    pub emissive_factor: [f64; 3],
    #[serde(default = "opaque")]
    pub alpha_mode: String,
    pub alpha_cutoff: Option<f64>,
    #[serde(default)]
    pub double_sided: bool,
    /// Extension name → its object; sunshade names the ones it does not model.
    #[serde(default)]
    pub extensions: BTreeMap<String, Value>,
    pub extras: Option<Value>,
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct PbrDef {
    #[serde(default = "white4")]
    pub base_color_factor: [f64; 4],
    pub base_color_texture: Option<TextureInfo>,
    #[serde(default = "one")]
    pub metallic_factor: f64,
    #[serde(default = "one")]
    pub roughness_factor: f64,
    pub metallic_roughness_texture: Option<TextureInfo>,
}

/// A material's reference to a texture (`textureInfo`, and the normal and occlusion variants' `scale` and
/// `strength`).
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct TextureInfo {
    pub index: Index,
    #[serde(default)]
    pub tex_coord: u64,
    /// normalTextureInfo.scale (1 by default).
    #[serde(default = "one")]
    pub scale: f64,
    #[serde(default)]
    pub extensions: TextureInfoExtensions,
}

#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub struct TextureInfoExtensions {
    #[serde(rename = "KHR_texture_transform")]
    pub texture_transform: Option<TextureTransformDef>,
}

/// KHR_texture_transform: `uv' = T(offset) R(rotation) S(scale) uv`, and a texCoord override.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct TextureTransformDef {
    #[serde(default)]
    pub offset: [f64; 2],
    /// Radians, counter-clockwise in UV space.
    #[serde(default)]
    pub rotation: f64,
    #[serde(default = "one2")]
    pub scale: [f64; 2],
    pub tex_coord: Option<u64>,
}

/// An image: a URI (file or data), or a buffer view with a MIME type.
#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct ImageDef {
    pub name: Option<String>,
    pub uri: Option<String>,
    pub mime_type: Option<String>,
    pub buffer_view: Option<Index>,
}

/// A sampler: glTF's (OpenGL's) filter and wrap codes; absent filters are the implementation's choice.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct SamplerDef {
    pub mag_filter: Option<u64>,
    pub min_filter: Option<u64>,
    #[serde(default = "repeat")]
    pub wrap_s: u64,
    #[serde(default = "repeat")]
    pub wrap_t: u64,
}

/// A skin: joints (nodes) and their inverse bind matrices (MAT4 accessor; identity when absent).
#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase", default)]
pub struct SkinDef {
    pub name: Option<String>,
    pub inverse_bind_matrices: Option<Index>,
    pub joints: Vec<Index>,
    pub skeleton: Option<Index>,
}

impl Default for PbrDef {
    fn default() -> Self {
        Self {
            base_color_factor: white4(),
            base_color_texture: None,
            metallic_factor: 1.0,
            roughness_factor: 1.0,
            metallic_roughness_texture: None,
        }
    }
}

/// A texture: `source` is optional in glTF 2.0 (an extension such as KHR_texture_basisu may provide it).
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub struct TextureDef {
    pub sampler: Option<Index>,
    pub source: Option<Index>,
    /// Extension name → its object (KHR_texture_basisu, EXT_texture_webp... give another `source`).
    pub extensions: BTreeMap<String, Value>,
}

#[derive(Debug, Deserialize)]
pub struct CameraDef {
    pub name: Option<String>,
    #[serde(rename = "type")]
    pub kind: String,
    pub perspective: Option<PerspectiveDef>,
    pub orthographic: Option<OrthographicDef>,
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub struct PerspectiveDef {
    pub yfov: f64,
    pub znear: f64,
    pub zfar: Option<f64>,
}

#[derive(Debug, Deserialize)]
pub struct OrthographicDef {
    pub ymag: f64,
    pub znear: f64,
    pub zfar: f64,
}

fn one() -> f64 {
    1.0
}
fn one2() -> [f64; 2] {
    [1.0; 2]
}
fn repeat() -> u64 {
    10497
}
fn white() -> [f64; 3] {
    [1.0; 3]
}
fn white4() -> [f64; 4] {
    [1.0; 4]
}
fn opaque() -> String {
    "OPAQUE".into()
}

/// Parses the JSON of a glTF file. The error names the JSON path of the offending value, e.g.
/// `nodes[3].mesh: invalid type: string "a", expected u64 at line 1 column 40`. serde_json's recursion limit
/// (128 levels) refuses deeply nested values, in `extras` too, with an error rather than a stack overflow.
pub fn parse(json: &[u8]) -> Result<Root, String> {
    let mut de = serde_json::Deserializer::from_slice(json);
    let root: Root = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        if path == "." || path.is_empty() {
            format!("invalid glTF JSON: {inner}")
        } else {
            format!("invalid glTF JSON at {path}: {inner}")
        }
    })?;
    de.end().map_err(|e| format!("invalid glTF JSON: {e}"))?;
    Ok(root)
}

/// `list[index]`, or an error naming what refers to it: "`node 3: mesh 9 does not exist (the file has 2)`"
/// with `owner` = "node 3" and `kind` = "mesh".
pub fn lookup<'a, T>(list: &'a [T], index: Index, owner: &str, kind: &str) -> Result<&'a T, String> {
    usize::try_from(index)
        .ok()
        .and_then(|i| list.get(i))
        .ok_or_else(|| format!("{owner}: {kind} {index} does not exist (the file has {})", list.len()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimal_and_defaults() {
        let root = parse(br#"{"asset":{"version":"2.0"}}"#).unwrap();
        assert!(root.scenes.is_empty() && root.scene.is_none());
        let root =
            parse(br#"{"asset":{"version":"2.0"},"materials":[{}],"textures":[{}],"unknown":[1,{"x":2}]}"#).unwrap();
        assert_eq!(root.materials[0].pbr_metallic_roughness.base_color_factor, [1.0; 4]);
        assert_eq!(root.materials[0].alpha_mode, "OPAQUE");
        assert!(root.textures[0].source.is_none());
    }

    #[test]
    fn type_errors_name_the_path() {
        let err = parse(br#"{"nodes":[{},{"mesh":"a"}]}"#).unwrap_err();
        assert!(err.contains("nodes[1].mesh"), "{err}");
        let err = parse(br#"{"accessors":[{"count":-1}]}"#).unwrap_err();
        assert!(err.contains("accessors[0].count"), "{err}");
        assert!(parse(b"{} trailing").is_err());
        assert!(parse(b"").is_err());
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_crash() {
        let deep = format!(r#"{{"extras":{}{}}}"#, "[".repeat(100_000), "]".repeat(100_000));
        let err = parse(deep.as_bytes()).unwrap_err();
        assert!(err.contains("recursion limit"), "{err}");
    }

    #[test]
    fn lookup_names_the_owner() {
        let list = [1, 2];
        assert_eq!(lookup(&list, 1, "node 0", "mesh"), Ok(&2));
        let err = lookup(&list, 2, "node 0", "mesh").unwrap_err();
        assert_eq!(err, "node 0: mesh 2 does not exist (the file has 2)");
        assert!(lookup(&list, u64::MAX, "node 0", "mesh").is_err());
    }
}
