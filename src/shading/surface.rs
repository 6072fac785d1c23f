//! The material at one pixel: texture coordinates, the textures looked up there, the base colour (factor ×
//! texture × vertex colour), the BRDF of the metallic-roughness mapping, the normal map and emission. Mirrored by
//! `shaders/surface.glsl` name for name. Everything up to the BRDF's parameters is the same arithmetic on both
//! sides (f64 coordinates, f32 products in the same order), so GPU and reference agree on them bitwise where the
//! device interpolates in f64; the shading that follows is f64 in the reference.

use glam::DVec3;

use super::texture_filter::{texture_lookup, texture_magnified};
use crate::scene::material::brdf_from_metallic_roughness;
use crate::scene::{AlphaMode, Brdf, BrdfKind, Material, Texture, TextureRef};

/// Bits of what a draw's material needs per pixel (the `VARIANT_SURFACE` specialization constant on the GPU; the
/// reference's triangles carry the same): 0 for an untextured, opaque, non-emissive material without vertex
/// colours, whose pixels are shaded exactly as before textures existed.
pub const SURFACE_EVAL: u32 = 1;
/// The normal map.
pub const SURFACE_NORMAL_MAP: u32 = 2;
/// Emission.
pub const SURFACE_EMISSION: u32 = 4;
/// Alpha MASK.
pub const SURFACE_ALPHA_MASK: u32 = 8;
/// The mesh's COLOR_0.
pub const SURFACE_COLORS: u32 = 16;

/// The `SURFACE_*` bits of a material on a mesh with (or without) COLOR_0.
pub fn surface_flags(material: &Material, has_colors: bool) -> u32 {
    let mut bits = 0;
    if material.varies_per_pixel(has_colors) {
        bits |= SURFACE_EVAL;
    }
    if material.normal_texture.is_some() {
        bits |= SURFACE_NORMAL_MAP;
    }
    if material.emission.iter().any(|&e| e > 0.0) {
        bits |= SURFACE_EMISSION;
    }
    if matches!(material.alpha, AlphaMode::Mask(_)) {
        bits |= SURFACE_ALPHA_MASK;
    }
    if has_colors && bits & (SURFACE_EVAL | SURFACE_ALPHA_MASK) != 0 {
        bits |= SURFACE_COLORS;
    }
    bits
}

/// What a pixel's surface is evaluated from: texture coordinates of each set at the pixel centre and at the
/// centres of its right and lower neighbours (the footprint, on the triangle's plane extended), interpolated in
/// f64 with the pixel's perspective-correct barycentrics; and the vertex colour, interpolated in f64 and rounded
/// to f32 (`None`: the mesh has no COLOR_0).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceSample {
    pub uv: [[f64; 2]; 2],
    pub uv_x: [[f64; 2]; 2],
    pub uv_y: [[f64; 2]; 2],
    pub color: Option<[f32; 4]>,
}

/// KHR_texture_transform's affine map `(m0 u + m1 v) + m2, (m3 u + m4 v) + m5` in f64.
pub fn transform_uv(m: &[f32; 6], uv: [f64; 2]) -> [f64; 2] {
    let m = m.map(f64::from);
    [m[0] * uv[0] + m[1] * uv[1] + m[2], m[3] * uv[0] + m[4] * uv[1] + m[5]]
}

/// A material's texture at the pixel: its set's coordinates, transformed, looked up ([`texture_lookup`]).
pub fn material_texture(textures: &[Texture], r: &TextureRef, s: &SurfaceSample) -> [f32; 4] {
    let set = r.tex_coord as usize;
    let uv = transform_uv(&r.transform, s.uv[set]);
    let uv_x = transform_uv(&r.transform, s.uv_x[set]);
    let uv_y = transform_uv(&r.transform, s.uv_y[set]);
    texture_lookup(&textures[r.texture], uv, uv_x, uv_y)
}

/// Linear base colour and alpha: `(factor × texture) × vertex colour`, each factor present, in f32.
pub fn base_color(material: &Material, textures: &[Texture], s: &SurfaceSample) -> [f32; 4] {
    let mut c =
        [material.pbr.base_color[0], material.pbr.base_color[1], material.pbr.base_color[2], material.base_alpha];
    if let Some(r) = &material.base_color_texture {
        let t = material_texture(textures, r, s);
        c = [0, 1, 2, 3].map(|k| c[k] * t[k]);
    }
    if let Some(v) = s.color {
        c = [0, 1, 2, 3].map(|k| c[k] * v[k]);
    }
    c
}

/// The BRDF at the pixel: the mapping of the base colour and the metallic-roughness texture (B metallic, G
/// roughness) times the factors; a material without a mapping (sunshade extras) keeps its BRDF.
pub fn surface_brdf(material: &Material, textures: &[Texture], s: &SurfaceSample, base: [f32; 4]) -> Brdf {
    let Some(kind) = material.mapping else { return material.brdf.clone() };
    let (mut metallic, mut roughness) = (material.pbr.metallic, material.pbr.roughness);
    if let (Some(r), false) = (&material.metallic_roughness_texture, kind == BrdfKind::Lambert) {
        let t = material_texture(textures, r, s);
        metallic *= t[2];
        roughness *= t[1];
    }
    brdf_from_metallic_roughness(kind, [base[0], base[1], base[2]], metallic, roughness, material.pbr.specular)
}

/// Whether the pixel is covered under the material's alpha mode: MASK keeps `alpha ≥ cutoff`.
pub fn alpha_covers(material: &Material, alpha: f32) -> bool {
    match material.alpha {
        AlphaMode::Mask(cutoff) => alpha >= cutoff,
        AlphaMode::Opaque | AlphaMode::Blend => true,
    }
}

/// Whether a shadow ray's hit on an alpha-masked triangle blocks it, and how near its alpha is to the cutoff:
/// the base colour's alpha at the hit ([`base_color`]'s, `(factor × texture) × vertex colour`; the texture read at
/// the hit's coordinates with no footprint, [`texture_magnified`]) against the cutoff ([`alpha_covers`]).
pub fn masked_hit_blocks(material: &Material, textures: &[Texture], s: &SurfaceSample) -> (bool, f64) {
    let mut alpha = material.base_alpha;
    if let Some(r) = &material.base_color_texture {
        alpha *= texture_magnified(&textures[r.texture], transform_uv(&r.transform, s.uv[r.tex_coord as usize]))[3];
    }
    if let Some(v) = s.color {
        alpha *= v[3];
    }
    let margin = match material.alpha {
        AlphaMode::Mask(cutoff) => (alpha as f64 - cutoff as f64).abs(),
        AlphaMode::Opaque | AlphaMode::Blend => f64::INFINITY,
    };
    (alpha_covers(material, alpha), margin)
}

/// Emitted radiance [W/(m²·sr)]: the material's emission times its emissive texture (sRGB decoded), in f32.
pub fn emitted_radiance(material: &Material, textures: &[Texture], s: &SurfaceSample) -> [f32; 3] {
    let e = material.emission;
    match &material.emissive_texture {
        Some(r) => {
            let t = material_texture(textures, r, s);
            [e[0] * t[0], e[1] * t[1], e[2] * t[2]]
        }
        None => e,
    }
}

/// The normal map's tangent-space normal, unnormalised: `(2t − 1) · (scale, scale, 1)`, in f32.
pub fn tangent_space_normal(textures: &[Texture], r: &TextureRef, scale: f32, s: &SurfaceSample) -> [f32; 3] {
    let t = material_texture(textures, r, s);
    [(t[0] * 2.0 - 1.0) * scale, (t[1] * 2.0 - 1.0) * scale, t[2] * 2.0 - 1.0]
}

/// The shading normal from a tangent-space normal in the frame (t, b, n): `normalize(t x + b y + n z)`; the
/// zero vector (nothing reflected) where that vanishes.
pub fn perturbed_normal(tn: [f32; 3], t: DVec3, b: DVec3, n: DVec3) -> DVec3 {
    super::safe_normalize(t * tn[0] as f64 + b * tn[1] as f64 + n * tn[2] as f64)
}

/// How near the pixel's material is to a jump of its textures or its alpha mask (the smallest
/// [`discontinuity_margin`] of the textures it reads, and `|alpha − cutoff|` under MASK); infinity where every
/// lookup is continuous. Rust only (the reference's flags for image comparison).
pub fn discontinuity_margin(material: &Material, textures: &[Texture], s: &SurfaceSample, flags: u32) -> f64 {
    let mut margin = f64::INFINITY;
    for r in material.textures() {
        let set = r.tex_coord as usize;
        let (uv, uv_x, uv_y) = (
            transform_uv(&r.transform, s.uv[set]),
            transform_uv(&r.transform, s.uv_x[set]),
            transform_uv(&r.transform, s.uv_y[set]),
        );
        margin = margin.min(super::texture_filter::discontinuity_margin(&textures[r.texture], uv, uv_x, uv_y));
    }
    if let (AlphaMode::Mask(cutoff), true) = (material.alpha, flags & SURFACE_ALPHA_MASK != 0) {
        margin = margin.min((base_color(material, textures, s)[3] as f64 - cutoff as f64).abs());
    }
    margin
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transform_uv_applies_the_matrix() {
        let m = [2.0, 0.0, 0.5, 0.0, 3.0, 0.25];
        assert_eq!(transform_uv(&m, [1.0, 1.0]), [2.5, 3.25]);
    }

    #[test]
    fn mapping_is_the_scene_mapping() {
        for kind in [BrdfKind::Lambert, BrdfKind::Phong, BrdfKind::BlinnPhong, BrdfKind::Ward] {
            let p = crate::scene::MetallicRoughness {
                base_color: [0.9, 0.5, 0.1],
                metallic: 0.3,
                roughness: 0.6,
                specular: crate::scene::material::DielectricSpecular::DEFAULT,
            };
            assert_eq!(
                Brdf::from_metallic_roughness(kind, p),
                brdf_from_metallic_roughness(kind, p.base_color, 0.3, 0.6, p.specular)
            );
        }
    }

    #[test]
    fn flat_normal_map_keeps_the_normal() {
        let n = perturbed_normal([0.0, 0.0, 1.0], DVec3::X, DVec3::Z, DVec3::Y);
        assert_eq!(n, DVec3::Y);
        let tilted = perturbed_normal([1.0, 0.0, 1.0], DVec3::X, DVec3::Z, DVec3::Y);
        assert!((tilted - DVec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-15);
    }
}
