#version 460
#ifdef SUNSHADE_RAY_QUERY
#extension GL_EXT_ray_query : require
#endif
#if defined(SUNSHADE_RAY_QUERY) || defined(SUNSHADE_RAY_BVH)
#extension GL_ARB_shader_stencil_export : require
#endif
// Radiance of each covered pixel, linear, in W/(m^2 sr); alpha 1 marks coverage.
//
// The fragment fetches its triangle's three vertices (gl_PrimitiveID) and interpolates position and normal with
// barycentrics it computes itself (transform.glsl), instead of using the device's interpolated varyings.
#include "bindings.glsl"
#include "transform.glsl"
#include "shade.glsl"
#include "surface.glsl"
#include "fragment.glsl"

layout(location = 0) out vec4 out_radiance;

#ifdef SUNSHADE_DEVICE_INTERPOLATION
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec4 v_tangent;
#endif

// The coverage alpha (fragment.glsl's coverage_alpha); in a first draw that marks by stencil (VARIANT_MARK), also
// the fragment's stencil value: 1 where the alpha holds the mark, 0 elsewhere, so that the stencil the depth test
// leaves is the mark of the surface it keeps, as the pass that reads the mark from the colour would set it
// (gpu::second_draw). The specializer removes the write, and with it the output, from every other variant.
float marked_coverage_alpha() {
    float alpha = coverage_alpha();
#ifdef SUNSHADE_SHADOW_RAYS
    if (VARIANT_PENUMBRAE == PENUMBRAE_LATER && VARIANT_MARK == MARK_BY_STENCIL) {
        gl_FragStencilRefARB = alpha == LEFT_TO_SECOND_DRAW ? 1 : 0;
    }
#endif
    return alpha;
}

// A vertex's position (offset VERTEX_POSITION, 0), normal (3) or tangent (6, a vec4): its texel offset / 3.
vec3 vertex_vec3(uint index, uint offset) {
    return VERTEX_TEXEL(index, offset / 3u).xyz;
}

vec4 vertex_vec4(uint index, uint offset) {
    return VERTEX_TEXEL(index, offset / 3u);
}

// The part of t orthogonal to the unit normal n, normalised; the default tangent (world +X projected, else +Z)
// where that vanishes. Mirrors orthonormal_tangent / default_tangent in src/scene/tangent.rs.
vec3 orthonormal_tangent(vec3 t, vec3 n) {
    vec3 o = t - n * dot(n, t);
    if (dot(o, o) > 1e-20) {
        return normalize(o);
    }
    vec3 x = vec3(1.0, 0.0, 0.0) - n * n.x;
    return dot(x, x) > 1e-12 ? normalize(x) : normalize(vec3(0.0, 0.0, 1.0) - n * n.z);
}

void main() {
    MaterialGpu material = material_at(pc.material);
    // The triangle's corners and the fragment's own barycentrics, for the position and normal (unless the device
    // interpolates them) and for the shadow rays' origin.
    uint first = pc.first_index + 3u * uint(gl_PrimitiveID);
    uint i0 = uint(int(indices[first]) + pc.vertex_offset);
    uint i1 = uint(int(indices[first + 1u]) + pc.vertex_offset);
    uint i2 = uint(int(indices[first + 2u]) + pc.vertex_offset);
    vec3 p0 = vertex_vec3(i0, 0u), p1 = vertex_vec3(i1, 0u), p2 = vertex_vec3(i2, 0u);
#ifdef SUNSHADE_DEVICE_INTERPOLATION
    vec3 position = v_position;
    vec3 normal = safe_normalize(v_normal);
    vec4 tangent = v_tangent;
    vec3 l = vec3(0.0);
    if (SHADOWS_ON || SHADOWS_MAP_ON) {
        l = triangle_barycentrics(clip_position(p0), clip_position(p1), clip_position(p2), pixel_ndc(gl_FragCoord.xy));
    }
#else
    vec3 l = triangle_barycentrics(clip_position(p0), clip_position(p1), clip_position(p2), pixel_ndc(gl_FragCoord.xy));
    vec3 position = l.x * p0 + l.y * p1 + l.z * p2;
    vec3 normal = safe_normalize(l.x * vertex_vec3(i0, 3u) + l.y * vertex_vec3(i1, 3u) + l.z * vertex_vec3(i2, 3u));
    vec4 tangent = l.x * vertex_vec4(i0, 6u) + l.y * vertex_vec4(i1, 6u) + l.z * vertex_vec4(i2, 6u);
#endif
    // Only double-sided materials reach here with back faces (single-sided ones are culled); glTF reverses
    // their normal.
    if (!gl_FrontFacing) {
        normal = -normal;
    }
    vec3 to_viewer = pc.viewer.w != 0.0 ? safe_normalize(pc.viewer.xyz - position) : pc.viewer.xyz;
    Frame frame;
    frame.position = position;
    frame.normal = normal;
    frame.tangent = orthonormal_tangent(tangent.xyz, normal);
    frame.bitangent = (tangent.w < 0.0 ? -1.0 : 1.0) * cross(normal, frame.tangent);
    frame.to_viewer = to_viewer;
    frame.shadow_origin = position;
    frame.face_normal = normal;
    if (SHADOWS_ON || SHADOWS_MAP_ON) {
        // The shadow rays' origin from the triangle's corners and vertex normals on the side being shaded, at the
        // fragment's own barycentrics (visibility.glsl).
        float side = gl_FrontFacing ? 1.0 : -1.0;
        vec3 n0 = side * safe_normalize(vertex_vec3(i0, 3u));
        vec3 n1 = side * safe_normalize(vertex_vec3(i1, 3u));
        vec3 n2 = side * safe_normalize(vertex_vec3(i2, 3u));
        frame.shadow_origin = shadow_ray_origin(p0, p1, p2, n0, n1, n2, l, position, normal);
        vec3 face = cross(p1 - p0, p2 - p0);
        face = dot(face, normal) < 0.0 ? -face : face;
        frame.face_normal = safe_normalize(face);
    }
    // The material at this pixel (textures, vertex colours, alpha mask, normal map, emission): only in the
    // variants whose material needs it (VARIANT_SURFACE), so that other draws run the code they ran before.
    vec3 emission = vec3(0.0);
    if (VARIANT_SURFACE != 0u) {
        SurfaceSample s = surface_sample();
        // The textures the variant reads, by one lookup (surface_texels): the base colour for the mask and the
        // BRDF, metallic-roughness for a BRDF but Lambert's (surface_brdf), the normal map, the emission.
        const bool reads_base = (VARIANT_SURFACE & (SURFACE_ALPHA_MASK | SURFACE_EVAL)) != 0u;
        bool reads_mr = false;
        switch (VARIANT_BRDF) {
        case BRDF_LAMBERT:
            break;
        case BRDF_PHONG:
        case BRDF_BLINN_PHONG:
        case BRDF_WARD:
        case BRDF_MEASURED:
        case BRDF_GLTF:
            reads_mr = (VARIANT_SURFACE & SURFACE_EVAL) != 0u;
            break;
        }
        uint reads = (reads_base ? 1u << TEX_BASE : 0u) | (reads_mr ? 1u << TEX_METALLIC_ROUGHNESS : 0u)
            | ((VARIANT_SURFACE & SURFACE_NORMAL_MAP) != 0u ? 1u << TEX_NORMAL : 0u)
            | ((VARIANT_SURFACE & SURFACE_EMISSION) != 0u ? 1u << TEX_EMISSIVE : 0u);
        SurfaceTexels t = surface_texels(material, s, reads);
        // The base colour once, for the mask and the BRDF (only the variants that use it look it up).
        vec4 base = reads_base ? base_color(material, s, t) : vec4(1.0);
        if ((VARIANT_SURFACE & SURFACE_ALPHA_MASK) != 0u && !alpha_covers(material, base.a)) {
            discard;
        }
        if ((VARIANT_SURFACE & SURFACE_EVAL) != 0u) {
            material = surface_brdf(material, t, base);
        }
        if ((VARIANT_SURFACE & SURFACE_NORMAL_MAP) != 0u) {
            // Back faces of double-sided materials turn the whole frame (the normal and bitangent already are).
            vec3 tn = tangent_space_normal(material, t);
            vec3 t_side = gl_FrontFacing ? frame.tangent : -frame.tangent;
            frame.normal = perturbed_normal(tn, t_side, frame.bitangent, frame.normal);
            frame.tangent = orthonormal_tangent(tangent.xyz, frame.normal);
            frame.bitangent = (tangent.w < 0.0 ? -1.0 : 1.0) * cross(frame.normal, frame.tangent);
        }
        if ((VARIANT_SURFACE & SURFACE_EMISSION) != 0u) {
            emission = emitted_radiance(material, t);
        }
    }
#ifdef SUNSHADE_SLICES
    if (VARIANT_QUANTITY == QUANTITY_LIGHT_ROWS) {
        // One pass of a light's slices: its rows' visible and unoccluded weights (gpu::slice_passes sums them).
        uint rows = 4u * lights.sampling.y * lights.sampling.y;
        uint light = lights.light_rows.z;
        uvec2 taken = lights.light_rows.xy;
        vec2 weights = vec2(0.0);
        if (light == ROWS_OF_SKY) {
            if (frame.normal.y > -1.0) {
                weights = sky_rows_weights(frame.shadow_origin, frame.normal, rows, taken.x, taken.y);
            }
        } else if (light == ROWS_OF_SUN) {
            weights = sun_rows_weights(frame.shadow_origin, frame.normal, lights.sun.direction.xyz,
                                       lights.sun.direction.w, rows, taken.x, taken.y);
        } else {
            DiskGpu d = lights.disks[light - ROWS_OF_DISK];
            weights = disk_rows_weights(frame.shadow_origin, frame.normal, d.center_radius.xyz, d.direction.xyz,
                                        d.center_radius.w, rows, taken.x, taken.y);
        }
        out_radiance = vec4(weights, 0.0, coverage_alpha());
        return;
    }
#endif
    if (VARIANT_QUANTITY == QUANTITY_IRRADIANCE) {
        // The irradiance at the surface [W/m^2] (shading::quantity): the lights' visible parts, no material.
        out_radiance = vec4(irradiance_visible(frame), marked_coverage_alpha());
        return;
    }
    vec3 radiance = radiance_out(material, frame);
    if ((VARIANT_SURFACE & SURFACE_EMISSION) != 0u) {
        radiance = radiance + emission;
    }
    out_radiance = vec4(radiance, marked_coverage_alpha());
}
