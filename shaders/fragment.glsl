// The fragment's own surface inputs, for the entry points that evaluate a material (scene.frag, and the
// alpha-masked shadow-map pass, shadow_mask.frag). Mirrors src/cpu/fragment.rs's surface_sample.
#ifndef SUNSHADE_FRAGMENT_GLSL
#define SUNSHADE_FRAGMENT_GLSL

#include "bindings.glsl"
#include "transform.glsl"
#include "surface.glsl"

// The coverage alpha of a shaded fragment: 1, or LOOP_BUDGET_SPENT where llvmpipe's loop limiter has cut the
// fragment's loops short. llvmpipe (Mesa 22.3's lavapipe; not seen on 25.0.7) gives every shader invocation one
// budget of 65535 loop iterations, all loops together (Mesa's LP_MAX_TGSI_LOOP_ITERATIONS); once it is spent,
// every loop exits after its current iteration, silently: a lobe grid or a shadow ray's walk left unfinished
// (docs/platform.md). This probe loop runs
// lights.counts.z (2) iterations, not known to the compiler, so it is not unrolled; it stops after one exactly when
// the budget is spent, and the renderer refuses an image with such pixels (gpu::loop_budget). SLICES_OVERFLOWED
// where the slices of a light gathered more triangles than they keep (gpu::slice_gather), refused too.
// LEFT_TO_SECOND_DRAW where the first of two draws leaves the pixel to the second (gpu::second_draw).
float coverage_alpha() {
    uint probe = 0u;
    for (uint i = 0u; i < lights.counts.z; ++i) {
        probe += 1u;
    }
    return probe != lights.counts.z ? LOOP_BUDGET_SPENT
         : (slices_overflowed ? SLICES_OVERFLOWED : (left_to_second_draw ? LEFT_TO_SECOND_DRAW : 1.0));
}

vec3 fragment_vertex_position(uint index) {
    return VERTEX_TEXEL(index, 0u).xyz;
}

vec2 surface_vec2(uint index, uint offset) {
    uint base = index * FLOATS_PER_SURFACE_VERTEX + offset;
    return vec2(surface_data[base], surface_data[base + 1u]);
}

vec4 surface_vec4(uint index, uint offset) {
    uint base = index * FLOATS_PER_SURFACE_VERTEX + offset;
    return vec4(surface_data[base], surface_data[base + 1u], surface_data[base + 2u], surface_data[base + 3u]);
}

// The pixel's surface inputs (src/cpu/fragment.rs surface_sample): each set's texture coordinates at the pixel centre
// and at its right and lower neighbours, and the vertex colour, interpolated in REAL with the exact barycentrics.
SurfaceSample surface_sample() {
    uint first = pc.first_index + 3u * uint(gl_PrimitiveID);
    uint i0 = uint(int(indices[first]) + pc.vertex_offset);
    uint i1 = uint(int(indices[first + 1u]) + pc.vertex_offset);
    uint i2 = uint(int(indices[first + 2u]) + pc.vertex_offset);
    vec4 c0 = clip_position(fragment_vertex_position(i0));
    vec4 c1 = clip_position(fragment_vertex_position(i1));
    vec4 c2 = clip_position(fragment_vertex_position(i2));
    REAL3 centre = triangle_barycentrics_exact(c0, c1, c2, pixel_ndc(gl_FragCoord.xy));
    REAL3 right = triangle_barycentrics_exact(c0, c1, c2, pixel_ndc(gl_FragCoord.xy + vec2(1.0, 0.0)));
    REAL3 below = triangle_barycentrics_exact(c0, c1, c2, pixel_ndc(gl_FragCoord.xy + vec2(0.0, 1.0)));
    SurfaceSample s;
    for (uint set = 0u; set < 2u; ++set) {
        uint offset = set == 0u ? SURFACE_VERTEX_UV0 : SURFACE_VERTEX_UV1;
        REAL2 a = REAL2(surface_vec2(i0, offset));
        REAL2 b = REAL2(surface_vec2(i1, offset));
        REAL2 c = REAL2(surface_vec2(i2, offset));
        precise REAL2 at_centre = centre.x * a + centre.y * b + centre.z * c;
        precise REAL2 at_right = right.x * a + right.y * b + right.z * c;
        precise REAL2 at_below = below.x * a + below.y * b + below.z * c;
        s.uv[set] = at_centre;
        s.uv_x[set] = at_right;
        s.uv_y[set] = at_below;
    }
    s.color = vec4(1.0);
    if ((VARIANT_SURFACE & SURFACE_COLORS) != 0u) {
        precise REAL4 color = centre.x * REAL4(surface_vec4(i0, SURFACE_VERTEX_COLOR))
            + centre.y * REAL4(surface_vec4(i1, SURFACE_VERTEX_COLOR)) + centre.z * REAL4(surface_vec4(i2, SURFACE_VERTEX_COLOR));
        s.color = vec4(color);
    }
    return s;
}

#endif
