// The scene's triangles as occluders of shadow rays. Mirrors src/cpu/occluders.rs (`blocks`: an alpha-masked
// triangle lets light through where its alpha is below the cutoff); the ray/triangle test is ray_triangle.glsl's,
// the BVH's walk (devices without ray queries) bvh.glsl's.
#ifndef SUNSHADE_OCCLUDERS_GLSL
#define SUNSHADE_OCCLUDERS_GLSL

#include "bindings.glsl"
#include "surface.glsl"

// Whether a shadow ray's hit at barycentrics b (of the triangle's second and third corners) on the occluder
// triangle `tri` (global vertex indices; material, bit 31: the mesh has vertex colours) blocks it: always for a
// triangle that is not alpha-masked; for a masked one, where its alpha at the hit reaches the cutoff
// (masked_hit_blocks; the texture read at the hit's coordinates, no footprint).
bool blocks(uvec4 tri, vec2 b) {
    // Where no material of the scene is masked, every triangle blocks: the alpha test below (a texture lookup)
    // would be inlined into every shadow ray's traversal for nothing.
    if (VARIANT_OCCLUDERS_MASKED == 0u) {
        return true;
    }
    MaterialGpu material = material_at(tri.w & 0x7fffffffu);
    if (material.kind.z == 0u) {
        return true;
    }
    REAL3 w = REAL3(REAL(1.0) - REAL(b.x) - REAL(b.y), REAL(b.x), REAL(b.y));
    SurfaceSample s;
    for (uint set = 0u; set < 2u; ++set) {
        uint offset = set == 0u ? SURFACE_VERTEX_UV0 : SURFACE_VERTEX_UV1;
        REAL2 uv = w.x * REAL2(vec2(surface_data[tri.x * FLOATS_PER_SURFACE_VERTEX + offset],
                                    surface_data[tri.x * FLOATS_PER_SURFACE_VERTEX + offset + 1u]))
                 + w.y * REAL2(vec2(surface_data[tri.y * FLOATS_PER_SURFACE_VERTEX + offset],
                                    surface_data[tri.y * FLOATS_PER_SURFACE_VERTEX + offset + 1u]))
                 + w.z * REAL2(vec2(surface_data[tri.z * FLOATS_PER_SURFACE_VERTEX + offset],
                                    surface_data[tri.z * FLOATS_PER_SURFACE_VERTEX + offset + 1u]));
        // masked_hit_blocks reads the texture at s.uv alone (no footprint): uv_x and uv_y are left unset.
        s.uv[set] = uv;
    }
    s.color = vec4(1.0);
    if ((tri.w & 0x80000000u) != 0u) {
        uint c = SURFACE_VERTEX_COLOR + 3u;
        s.color.a = float(w.x * REAL(surface_data[tri.x * FLOATS_PER_SURFACE_VERTEX + c])
            + w.y * REAL(surface_data[tri.y * FLOATS_PER_SURFACE_VERTEX + c])
            + w.z * REAL(surface_data[tri.z * FLOATS_PER_SURFACE_VERTEX + c]));
    }
    return masked_hit_blocks(material, s);
}

#ifdef SUNSHADE_SHADOW_RAYS
// A corner of an occluder triangle: the world position [m] of global vertex i (the vertex buffer's f32, which the
// reference's rays meet as f64). Read by the walks and by the sun's cells (sun_cells.glsl).
#define OCCLUDER_CORNER(i) VERTEX_TEXEL(i, 0u).xyz
#endif


#include "ray_triangle.glsl"
#include "bvh.glsl"

#endif
