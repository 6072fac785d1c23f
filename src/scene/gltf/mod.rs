//! glTF 2.0 files as untrusted input: the container, the JSON document, the buffers, the accessors.
//!
//! sunshade reads glTF itself rather than through the `gltf` crate, whose validation panics on some dangling
//! indices and refuses files that glTF-Validator calls valid (accessors without a buffer view, textures without a
//! source, required extensions it has no feature for). Here nothing is validated up front that is not needed:
//! every reference is resolved where it is used ([`document::lookup`]), so a bad one is an error naming the object
//! that holds it, and a file with unused oddities still renders.

pub mod accessor;
pub mod document;
pub mod files;
pub mod glb;
pub mod image;
pub mod uri;

use std::path::Path;

use document::Root;
use files::{AssetFiles, UriScope};
use uri::UriTarget;

/// Extensions sunshade implements.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
];

/// Extensions whose whole effect is on appearance that sunshade does not draw yet: texture transforms (textures
/// are not drawn), emission strength (emission is not drawn) and material lobes (KHR_materials_*: materials are
/// drawn from their glTF factors or sunshade extras). A file that *requires* one is still drawn, with a warning
/// naming the requirement: its geometry, lights and cameras are exact, and the material warnings say what is
/// missing. A file that requires any other extension (geometry compression such as Draco or meshopt, GPU
/// instancing, textures in KTX2 or WebP that could not be decoded, or an extension unknown to sunshade) is refused:
/// sunshade cannot draw it.
pub fn is_appearance_only(extension: &str) -> bool {
    extension == "KHR_texture_transform" || extension.starts_with("KHR_materials_")
}

/// A parsed glTF file and the bytes of each of its buffers.
pub struct Gltf {
    pub root: Root,
    pub buffers: Vec<Vec<u8>>,
    /// Where the file's images are read from (the same rules as its buffers).
    pub files: AssetFiles,
}

/// Reads and parses a `.gltf` or `.glb` file and every buffer it declares. Errors are one line without the file
/// name (the caller adds it).
pub fn read(path: &Path, scope: &UriScope) -> Result<Gltf, String> {
    let bytes = files::read_regular_file(path, None).map_err(|e| format!("cannot read the scene: {e}"))?;
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(if bytes.is_empty() {
            "empty file (0 bytes)".into()
        } else {
            "the file holds only whitespace".into()
        });
    }
    let (json, bin) = if glb::is_glb(&bytes) {
        let g = glb::parse(&bytes)?;
        (g.json, g.bin)
    } else {
        (&bytes[..], None)
    };
    let root = document::parse(json)?;
    check_version(&root)?;
    check_required_extensions(&root)?;
    let files = AssetFiles::new(path, scope)?;
    let buffers = read_buffers(&root, bin, &files)?;
    Ok(Gltf { root, buffers, files })
}

fn check_version(root: &Root) -> Result<(), String> {
    let asset = root.asset.as_ref().ok_or("the file has no 'asset' object (is it glTF 2.0?)")?;
    let major = asset.version.split('.').next().unwrap_or("");
    if major != "2" {
        return Err(format!("asset.version '{}' is not glTF 2.x", asset.version));
    }
    Ok(())
}

fn check_required_extensions(root: &Root) -> Result<(), String> {
    let unsupported: Vec<&str> = root
        .extensions_required
        .iter()
        .map(String::as_str)
        .filter(|e| !SUPPORTED_EXTENSIONS.contains(e) && !is_appearance_only(e))
        .collect();
    if unsupported.is_empty() {
        Ok(())
    } else {
        Err(format!("the file requires extensions sunshade does not support: {}", unsupported.join(", ")))
    }
}

/// The bytes of every buffer: the GLB binary chunk, a data URI, or a file inside the asset folder. Each holds at
/// least its `byteLength`; only that many bytes are kept or read.
fn read_buffers(root: &Root, bin: Option<&[u8]>, files: &AssetFiles) -> Result<Vec<Vec<u8>>, String> {
    let mut out = Vec::with_capacity(root.buffers.len());
    for (i, buffer) in root.buffers.iter().enumerate() {
        let declared = buffer.byte_length;
        let short = |have: usize| format!("buffer {i} holds {have} bytes but declares byteLength {declared}");
        let data = match &buffer.uri {
            None if i == 0 => {
                let b = bin.ok_or_else(|| format!("buffer {i} has no uri and the file has no GLB binary chunk"))?;
                let n = usize::try_from(declared).ok().filter(|&n| n <= b.len()).ok_or_else(|| short(b.len()))?;
                b[..n].to_vec()
            }
            None => return Err(format!("buffer {i} has no uri (only buffer 0 may be the GLB binary chunk)")),
            Some(u) => match uri::resolve(u).map_err(|e| format!("buffer {i}: {e}"))? {
                UriTarget::Data(mut bytes) => {
                    let n = usize::try_from(declared)
                        .ok()
                        .filter(|&n| n <= bytes.len())
                        .ok_or_else(|| short(bytes.len()))?;
                    bytes.truncate(n);
                    bytes
                }
                UriTarget::File(rel) => files
                    .read(&rel, u, Some(declared))
                    .map_err(|e| format!("buffer {i} (byteLength {declared}): {e}"))?,
            },
        };
        out.push(data);
    }
    Ok(out)
}
