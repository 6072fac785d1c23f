//! glTF materials → [`Material`]: factors, textures (decoded once per texture and colour space), alpha mode,
//! emission, and the `sunshade` extras; with one warning line per material for whatever is still not drawn.

use std::collections::HashMap;

use serde_json::Value;

use super::gltf::document::{lookup, MaterialDef, Root, TextureInfo};
use super::gltf::files::AssetFiles;
use super::gltf::image::{check, decode, image_bytes, ColorSpace, MAX_SCENE_TEXELS};
use super::gltf::uri::{resolve, UriTarget};
use super::material::{
    brdf_from_metallic_roughness, AlphaMode, Brdf, BrdfKind, DielectricSpecular, Material, MetallicRoughness,
};
use super::measured::{parse_merl, SharedMeasuredBrdf, MERL_FILE_BYTES};
use super::texture::{uv_transform, Sampler, Texture, TextureRef, IDENTITY_UV_TRANSFORM};

/// Texture sources other than PNG/JPEG that a texture may name in an extension (sunshade decodes none of them).
const UNDECODED_SOURCES: [&str; 3] = ["KHR_texture_basisu", "EXT_texture_webp", "MSFT_texture_dds"];

/// Material extensions sunshade draws (KHR_materials_specular without its textures).
pub const DRAWN_MATERIAL_EXTENSIONS: [&str; 3] =
    ["KHR_materials_emissive_strength", "KHR_materials_ior", "KHR_materials_specular"];

/// Reads materials and the textures they use, each (texture, colour space) decoded once.
pub struct MaterialReader<'a> {
    pub root: &'a Root,
    pub buffers: &'a [Vec<u8>],
    pub files: &'a AssetFiles,
    /// (glTF texture, colour space) → index into `textures`.
    cache: HashMap<(u64, ColorSpace), usize>,
    /// The images to decode, in the order of their scene textures ([`MaterialReader::decode_textures`]).
    textures: Vec<PendingTexture>,
    /// Measured BRDF tables by the URI that names them: materials naming the same URI share one table.
    measured: HashMap<String, SharedMeasuredBrdf>,
    pub warnings: Vec<String>,
    /// What is left of the scene's texel budget.
    texels_left: u64,
    /// `--max-texture-size`: textures larger on either side start at their first mip level that fits.
    pub max_texture_size: Option<u32>,
}

impl<'a> MaterialReader<'a> {
    pub fn new(root: &'a Root, buffers: &'a [Vec<u8>], files: &'a AssetFiles) -> Self {
        Self {
            root,
            buffers,
            files,
            cache: HashMap::new(),
            measured: HashMap::new(),
            textures: Vec::new(),
            warnings: Vec::new(),
            texels_left: MAX_SCENE_TEXELS,
            max_texture_size: None,
        }
    }

    /// Material `index`.
    pub fn read(&mut self, index: usize, material: &MaterialDef) -> Result<Material, String> {
        let name = material.name.as_ref().map_or_else(|| format!("material {index}"), |n| format!("material '{n}'"));
        let pbr = &material.pbr_metallic_roughness;
        let [r, g, b, a] = pbr.base_color_factor.map(|c| c as f32);
        let albedo = [r, g, b];
        if albedo.iter().chain([&a]).any(|c| !(0.0..=1.0).contains(c)) {
            return Err(format!("{name}: baseColorFactor {:?} is outside [0, 1]", pbr.base_color_factor));
        }
        let mut ignored = Vec::new();
        let specular = super::load_specular::dielectric_specular(&material.extensions, &mut ignored)
            .map_err(|e| format!("{name}: {e}"))?;
        let metallic_roughness = MetallicRoughness {
            base_color: albedo,
            specular,
            metallic: pbr.metallic_factor as f32,
            roughness: pbr.roughness_factor as f32,
        };
        let extras = sunshade_extras(&material.extras);
        let explicit = extras.as_ref().filter(|x| x.get("brdf").is_some());
        let (brdf, mapping) = match explicit {
            Some(x) if x.get("brdf").and_then(|v| v.as_str()) == Some("merl") => {
                (self.measured_brdf(x).map_err(|e| format!("{name} extras: {e}"))?, None)
            }
            // "lambert" alone: the metallic-roughness mapping onto Lambert (the base colour, its texture and vertex
            // colours), as `--brdf lambert` does.
            Some(x) if x.get("brdf").and_then(|v| v.as_str()) == Some("lambert") && x.get("albedo").is_none() => {
                (Brdf::Lambert { albedo }, Some(BrdfKind::Lambert))
            }
            Some(x) => (brdf_from_extras(x, albedo, specular).map_err(|e| format!("{name} extras: {e}"))?, None),
            // The glTF specification's own BRDF.
            None => (Brdf::from_metallic_roughness(BrdfKind::Gltf, metallic_roughness), Some(BrdfKind::Gltf)),
        };
        brdf.validate().map_err(|e| format!("{name}: {e}"))?;
        let mut texture = |info: &Option<TextureInfo>, slot: &str, space: ColorSpace, this: &mut Self| {
            let Some(info) = info else { return Ok(None) };
            this.texture_ref(info, space, &format!("{name} {slot}")).inspect(|t| {
                if t.is_none() {
                    ignored.push(slot.to_string());
                }
            })
        };
        let base_color_texture = texture(&pbr.base_color_texture, "baseColorTexture", ColorSpace::Srgb, self)?;
        let metallic_roughness_texture =
            texture(&pbr.metallic_roughness_texture, "metallicRoughnessTexture", ColorSpace::Linear, self)?;
        let normal_texture = texture(&material.normal_texture, "normalTexture", ColorSpace::Linear, self)?;
        let emissive_texture = texture(&material.emissive_texture, "emissiveTexture", ColorSpace::Srgb, self)?;
        let normal_scale = material.normal_texture.as_ref().map_or(1.0, |t| t.scale as f32);
        if !normal_scale.is_finite() {
            return Err(format!("{name}: normalTexture scale {normal_scale} is not finite"));
        }
        let strength = match material.extensions.get("KHR_materials_emissive_strength") {
            Some(x) => x
                .get("emissiveStrength")
                .map_or(Some(1.0), |v| v.as_f64())
                .filter(|s| s.is_finite() && *s >= 0.0)
                .ok_or_else(|| {
                    format!("{name}: KHR_materials_emissive_strength needs a non-negative emissiveStrength")
                })?,
            None => 1.0,
        };
        let scale = match extras.as_ref().and_then(|x| x.get("emission_scale")) {
            Some(v) => v
                .as_f64()
                .filter(|s| s.is_finite() && *s >= 0.0)
                .ok_or_else(|| format!("{name} extras: emission_scale must be a non-negative number [W/(m²·sr)]"))?,
            None => 1.0,
        };
        let emission = material.emissive_factor.map(|f| f * strength * scale);
        if emission.iter().any(|e| !(*e >= 0.0 && *e <= f32::MAX as f64)) {
            return Err(format!(
                "{name}: emissiveFactor {:?} × strength × scale must be finite and non-negative",
                material.emissive_factor
            ));
        }
        let alpha = match material.alpha_mode.as_str() {
            "OPAQUE" => AlphaMode::Opaque,
            "MASK" => {
                let cutoff = material.alpha_cutoff.unwrap_or(0.5);
                if !(cutoff.is_finite() && cutoff >= 0.0) {
                    return Err(format!("{name}: alphaCutoff {cutoff} must be a non-negative number"));
                }
                AlphaMode::Mask(cutoff as f32)
            }
            "BLEND" => {
                ignored.push("alphaMode BLEND (drawn opaque: sunshade does not blend)".into());
                AlphaMode::Blend
            }
            other => return Err(format!("{name}: alphaMode '{other}' is not OPAQUE, MASK or BLEND")),
        };
        if material.occlusion_texture.is_some() {
            ignored.push(
                "occlusionTexture (baked ambient occlusion: sunshade computes visibility itself, by its shadows, and \
                 has no ambient term for it to darken)"
                    .into(),
            );
        }
        if explicit.is_some() && (base_color_texture.is_some() || metallic_roughness_texture.is_some()) {
            ignored.push("baseColor and metallicRoughness textures (the sunshade extras give the BRDF)".into());
        }
        ignored.extend(
            material
                .extensions
                .keys()
                .filter(|e| !DRAWN_MATERIAL_EXTENSIONS.contains(&e.as_str()))
                .map(|e| format!("extension {e}")),
        );
        if !ignored.is_empty() {
            self.warnings.push(format!("{name}: {} not drawn; ignored", ignored.join(", ")));
        }
        Ok(Material {
            name,
            double_sided: material.double_sided,
            brdf,
            pbr: metallic_roughness,
            mapping,
            base_alpha: a,
            base_color_texture: base_color_texture.filter(|_| mapping.is_some()),
            metallic_roughness_texture: metallic_roughness_texture.filter(|_| mapping.is_some()),
            normal_texture: normal_texture.map(|t| (t, normal_scale)),
            emission: emission.map(|e| e as f32),
            emissive_texture,
            alpha,
        })
    }

    /// The scene texture a texture info refers to, decoding its image on first use; `None` (the caller warns)
    /// where the texture has no PNG/JPEG source or uses a texture-coordinate set past TEXCOORD_1.
    fn texture_ref(
        &mut self,
        info: &TextureInfo,
        space: ColorSpace,
        owner: &str,
    ) -> Result<Option<TextureRef>, String> {
        let root = self.root;
        let def = lookup(&root.textures, info.index, owner, "texture")?;
        let transform = info.extensions.texture_transform.as_ref();
        let tex_coord = transform.and_then(|t| t.tex_coord).unwrap_or(info.tex_coord);
        if tex_coord > 1 {
            self.warnings.push(format!("{owner}: TEXCOORD_{tex_coord} (sunshade reads sets 0 and 1); texture ignored"));
            return Ok(None);
        }
        let matrix = match transform {
            Some(t) => {
                let m = uv_transform(t.offset, t.rotation, t.scale);
                if m.iter().any(|v| !v.is_finite()) {
                    return Err(format!("{owner}: KHR_texture_transform {t:?} is not finite"));
                }
                m
            }
            None => IDENTITY_UV_TRANSFORM,
        };
        let key = (info.index, space);
        if let Some(&texture) = self.cache.get(&key) {
            return Ok(Some(TextureRef { texture, tex_coord: tex_coord as u32, transform: matrix }));
        }
        let what = format!("texture {}", info.index);
        let Some(source) = def.source else {
            let other: Vec<&str> =
                UNDECODED_SOURCES.iter().copied().filter(|e| def.extensions.contains_key(*e)).collect();
            let why = if other.is_empty() {
                "has no source image".to_string()
            } else {
                format!("has only a {} source, which sunshade does not decode", other.join("/"))
            };
            self.warnings.push(format!("{owner}: {what} {why}; texture ignored"));
            return Ok(None);
        };
        let sampler = match def.sampler {
            Some(s) => {
                let s = lookup(&root.samplers, s, &what, "sampler")?;
                Sampler::from_gl(s.mag_filter, s.min_filter, s.wrap_s, s.wrap_t).map_err(|e| format!("{what}: {e}"))?
            }
            None => Sampler::default(),
        };
        let (bytes, _mime) = image_bytes(root, self.buffers, self.files, source, &what)?;
        check(&bytes, &format!("{what} image {source}"), &mut self.texels_left)?;
        self.textures.push(PendingTexture { what, source, bytes, space, sampler });
        let index = self.textures.len() - 1;
        self.cache.insert(key, index);
        Ok(Some(TextureRef { texture: index, tex_coord: tex_coord as u32, transform: matrix }))
    }
}

/// A texture whose image passed [`check`] and waits to be decoded.
struct PendingTexture {
    /// "texture N".
    what: String,
    /// The glTF image.
    source: u64,
    bytes: Vec<u8>,
    space: ColorSpace,
    sampler: Sampler,
}

impl MaterialReader<'_> {
    /// Decodes every texture the materials read used, with its mip chain, in parallel (each image alone, so the
    /// texels do not depend on the order); the first error in texture order is the one returned.
    pub fn decode_textures(&mut self) -> Result<Vec<Texture>, String> {
        use rayon::prelude::*;
        let max = self.max_texture_size;
        let decoded: Vec<Result<Texture, String>> = std::mem::take(&mut self.textures)
            .into_par_iter()
            .map(|t| {
                let level0 = decode(&t.bytes, t.space, &format!("{} image {}", t.what, t.source))?;
                drop(t.bytes);
                let mut texture = Texture::new(format!("{} (image {})", t.what, t.source), level0, t.sampler);
                if let Some(max) = max {
                    texture.limit_size(max);
                }
                Ok(texture)
            })
            .collect();
        decoded.into_iter().collect()
    }
}

impl MaterialReader<'_> {
    /// `{"brdf": "merl", "file": URI, "lookup": "linear" | "nearest"}`: a MERL table in a file inside the scene's
    /// folder (the buffer URIs' rules: relative, percent-decoded, confined; or a base64 `data:` URI), read once per
    /// URI; `lookup` linear by default (`shading::measured`).
    fn measured_brdf(&mut self, x: &Value) -> Result<Brdf, String> {
        let uri = x.get("file").and_then(|v| v.as_str()).ok_or("merl needs \"file\": the table's URI")?;
        let lookup = match x.get("lookup") {
            None => Default::default(),
            Some(v) => v.as_str().ok_or("\"lookup\" must be a string")?.parse()?,
        };
        let table = match self.measured.get(uri) {
            Some(t) => t.clone(),
            None => {
                let bytes = match resolve(uri)? {
                    UriTarget::Data(bytes) => bytes,
                    UriTarget::File(rel) => self
                        .files
                        .read_at_most(&rel, uri, MERL_FILE_BYTES as u64)
                        .map_err(|e| format!("MERL BRDF {e}"))?,
                };
                let table = SharedMeasuredBrdf::new(parse_merl(uri, &bytes)?);
                self.warnings.extend(table.missing_warning());
                self.measured.insert(uri.to_string(), table.clone());
                table
            }
        };
        Ok(Brdf::Measured { table, lookup })
    }
}

/// `{"brdf": "lambert" | "phong" | "blinn-phong" | "ward", "kd": [..], "ks": [..], "exponent": e,
/// "alpha": a | "alpha_x": ax, "alpha_y": ay}`; Lambert may give `"albedo"` (else baseColorFactor); `{"brdf": "gltf",
/// "metallic": m, "roughness": r}` with `"base_color"` (else baseColorFactor), the glTF specification's BRDF with the
/// material's dielectric `specular` (KHR_materials_ior and KHR_materials_specular).
fn brdf_from_extras(x: &Value, base_color: [f32; 3], specular: DielectricSpecular) -> Result<Brdf, String> {
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
        "gltf" => {
            let base = if x.get("base_color").is_some() { color("base_color")? } else { base_color };
            let (metallic, roughness) = (number("metallic")?, number("roughness")?);
            if !(0.0..=1.0).contains(&metallic) || !(0.0..=1.0).contains(&roughness) {
                return Err(format!("gltf metallic {metallic} and roughness {roughness} must lie in [0, 1]"));
            }
            brdf_from_metallic_roughness(BrdfKind::Gltf, base, metallic, roughness, specular)
        }
        other => return Err(format!("brdf '{other}' is not one of lambert, phong, blinn-phong, ward, gltf, merl")),
    })
}

/// The `"sunshade"` object of an `extras` value, if any.
pub fn sunshade_extras(extras: &Option<Value>) -> Option<Value> {
    match extras {
        Some(v @ Value::Object(_)) => v.get("sunshade").cloned(),
        _ => None,
    }
}

/// A radiance: `[r, g, b]` or one number for all three, finite and non-negative [W/(m²·sr)].
pub fn rgb(v: &Value) -> Result<[f32; 3], String> {
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
