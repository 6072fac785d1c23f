// The material at one pixel: texture coordinates, textures, base colour, the metallic-roughness mapping, the
// normal map and emission. Mirrors src/shading/surface.rs name for name (f32 products in the same order, marked
// `precise`), so that the GPU and the reference agree on the BRDF's parameters bitwise where the device
// interpolates in f64.
#ifndef SUNSHADE_SURFACE_GLSL
#define SUNSHADE_SURFACE_GLSL

#include "bindings.glsl"
#include "texture_filter.glsl"

// The pixel's surface inputs (Rust: SurfaceSample): each set's texture coordinates at the pixel centre and at its
// right and lower neighbours, and the vertex colour (white where the mesh has none).
struct SurfaceSample {
    REAL2 uv[2];
    REAL2 uv_x[2];
    REAL2 uv_y[2];
    vec4 color;
};

// KHR_texture_transform's affine map, (m0 u + m1 v) + m2, (m3 u + m4 v) + m5.
REAL2 transform_uv(TextureRefGpu r, REAL2 uv) {
    precise REAL u = REAL(r.row0.x) * uv.x + REAL(r.row0.y) * uv.y + REAL(r.row0.z);
    precise REAL v = REAL(r.row1.x) * uv.x + REAL(r.row1.y) * uv.y + REAL(r.row1.z);
    return REAL2(u, v);
}

// A material's texture at the pixel.
vec4 material_texture(TextureRefGpu r, SurfaceSample s) {
    uint set = r.texture.y;
    return texture_lookup(r.texture.x, transform_uv(r, s.uv[set]), transform_uv(r, s.uv_x[set]),
                          transform_uv(r, s.uv_y[set]));
}

// The material's textures at the pixel that a draw reads (`reads`: bit 1 << TEX_* for each), looked up by one call
// of material_texture in a loop over the four, so that the driver, which inlines every call, compiles one lookup
// however many a variant reads (the Rust looks each up where it is used). One not read or absent stays white.
struct SurfaceTexels {
    vec4 base;
    vec4 metallic_roughness;
    vec4 normal;
    vec4 emissive;
};

SurfaceTexels surface_texels(MaterialGpu m, SurfaceSample s, uint reads) {
    SurfaceTexels t = SurfaceTexels(vec4(1.0), vec4(1.0), vec4(1.0), vec4(1.0));
    for (uint k = 0u; k < 4u; ++k) {
        // The slot by constant indices (a local array indexed by k is read lane by lane on llvmpipe).
        TextureRefGpu r = k == TEX_BASE ? m.tex[TEX_BASE]
            : (k == TEX_METALLIC_ROUGHNESS ? m.tex[TEX_METALLIC_ROUGHNESS]
            : (k == TEX_NORMAL ? m.tex[TEX_NORMAL] : m.tex[TEX_EMISSIVE]));
        if ((reads & (1u << k)) == 0u || r.texture.x == NO_TEXTURE) {
            continue;
        }
        vec4 v = material_texture(r, s);
        if (k == TEX_BASE) {
            t.base = v;
        } else if (k == TEX_METALLIC_ROUGHNESS) {
            t.metallic_roughness = v;
        } else if (k == TEX_NORMAL) {
            t.normal = v;
        } else {
            t.emissive = v;
        }
    }
    return t;
}

// Linear base colour and alpha: (factor x texture) x vertex colour (t.base: surface_texels's).
vec4 base_color(MaterialGpu m, SurfaceSample s, SurfaceTexels t) {
    precise vec4 c = m.base;
    if (m.tex[TEX_BASE].texture.x != NO_TEXTURE) {
        c = c * t.base;
    }
    if ((VARIANT_SURFACE & SURFACE_COLORS) != 0u) {
        c = c * s.color;
    }
    return c;
}

// The metallic-roughness mapping onto the draw's BRDF (VARIANT_BRDF): kd, ks, exponent, Ward alpha of m.
MaterialGpu brdf_from_metallic_roughness(MaterialGpu m, vec3 base, float metallic, float roughness) {
    precise float mm = clamp(metallic, 0.0, 1.0);
    precise vec3 ks = 0.04 * (1.0 - mm) + base * mm;
    precise vec3 kd = base * (1.0 - mm) * (1.0 - ks);
    precise float r = clamp(roughness, 0.0, 1.0);
    precise float alpha = max(r * r, 1e-3);
    precise float exponent = clamp(2.0 / (alpha * alpha) - 2.0, 0.0, 1e7);
    switch (VARIANT_BRDF) {
    case BRDF_LAMBERT:
        m.kd = vec4(base, 0.0);
        break;
    case BRDF_WARD:
        m.kd = vec4(kd, 0.0);
        m.ks = vec4(ks, 0.0);
        m.params = vec4(vec2(alpha), 0.0, 0.0);
        break;
    case BRDF_GLTF: {
        // Its own model (shading::brdf::metallic_roughness): kd = (1 - m)(1 - max f0) base, ks = 1, and the lobe's
        // parameters (f0 and f90 stay the material's).
        precise float keep = 1.0 - max(max(m.specular.r, m.specular.g), m.specular.b);
        precise vec3 gltf_kd = base * (1.0 - mm) * keep;
        m.kd = vec4(gltf_kd, 0.0);
        m.ks = vec4(1.0, 1.0, 1.0, 0.0);
        m.params = vec4(alpha, mm, 0.0, 0.0);
        m.base = vec4(base, m.base.a);
        break;
    }
    case BRDF_PHONG:
    case BRDF_BLINN_PHONG:
    case BRDF_MEASURED:
        m.kd = vec4(kd, 0.0);
        m.ks = vec4(ks, exponent);
        m.params = vec4(vec2(0.0), 0.0, 0.0);
        break;
    }
    return m;
}

// The BRDF at the pixel: the mapping of the base colour and the metallic-roughness texture (B metallic, G
// roughness; t.metallic_roughness, read for every BRDF but Lambert's) times the factors.
MaterialGpu surface_brdf(MaterialGpu m, SurfaceTexels t, vec4 base) {
    precise float metallic = m.pbr.x;
    precise float roughness = m.pbr.y;
    switch (VARIANT_BRDF) {
    case BRDF_LAMBERT:
        // The mapping's Lambertian BRDF is the base colour: neither factor counts.
        break;
    case BRDF_PHONG:
    case BRDF_BLINN_PHONG:
    case BRDF_WARD:
    case BRDF_MEASURED:
    case BRDF_GLTF:
        if (m.tex[TEX_METALLIC_ROUGHNESS].texture.x != NO_TEXTURE) {
            metallic = metallic * t.metallic_roughness.b;
            roughness = roughness * t.metallic_roughness.g;
        }
        break;
    }
    return brdf_from_metallic_roughness(m, base.rgb, metallic, roughness);
}

// Whether the pixel is covered under alpha MASK: alpha >= cutoff.
bool alpha_covers(MaterialGpu m, float alpha) {
    return alpha >= m.pbr.w;
}

// Emitted radiance [W/(m^2 sr)]: the material's emission times its emissive texture (t.emissive).
vec3 emitted_radiance(MaterialGpu m, SurfaceTexels t) {
    precise vec3 e = m.emission.rgb;
    if (m.tex[TEX_EMISSIVE].texture.x != NO_TEXTURE) {
        e = e * t.emissive.rgb;
    }
    return e;
}

// The normal map's tangent-space normal, unnormalised: (2 t - 1) (scale, scale, 1), t the normal texture's
// texel (t.normal).
vec3 tangent_space_normal(MaterialGpu m, SurfaceTexels texels) {
    vec4 t = texels.normal;
    precise vec3 n = (t.rgb * 2.0 - 1.0) * vec3(m.pbr.z, m.pbr.z, 1.0);
    return n;
}

// The shading normal from a tangent-space normal in the frame (t, b, n); 0 where that vanishes (safe_normalize's
// arithmetic, written out: this file is also included before shade.glsl, by visibility.glsl).
vec3 perturbed_normal(vec3 tn, vec3 t, vec3 b, vec3 n) {
    vec3 v = t * tn.x + b * tn.y + n * tn.z;
    float len2 = dot(v, v);
    return len2 > 0.0 ? v * inversesqrt(len2) : vec3(0.0);
}

// Whether a shadow ray's hit on an alpha-masked triangle blocks it: the base colour's alpha (factor x texture x
// vertex colour, s.color white without colours) at the hit reaches the cutoff. The texture is read at the hit's
// coordinates with no footprint (texture_magnified: level 0, magnification filter).
bool masked_hit_blocks(MaterialGpu m, SurfaceSample s) {
    precise float alpha = m.base.a;
    TextureRefGpu r = m.tex[TEX_BASE];
    if (r.texture.x != NO_TEXTURE) {
        alpha = alpha * texture_magnified(r.texture.x, transform_uv(r, s.uv[r.texture.y])).a;
    }
    alpha = alpha * s.color.a;
    return alpha_covers(m, alpha);
}

#endif
