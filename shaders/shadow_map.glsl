// The sun's shadow map: GPU only (the reference casts rays; docs/accuracy.md, "Shadows", measures this against
// it). The map's frame is fitted in src/visibility/shadow_map.rs; lookups are texel by texel (texelFetch), so the
// filter is this code's, not the device's.
#ifndef SUNSHADE_SHADOW_MAP_GLSL
#define SUNSHADE_SHADOW_MAP_GLSL

#include "bindings.glsl"
#include "visibility.glsl"

// A world point in the map: (texel x, texel y, depth from the sun [m]).
vec3 sun_map_point(vec3 p) {
    vec4 q = lights.sun_map_from_world * vec4(p, 1.0);
    float n = lights.sun_map.z;
    return vec3((q.x * 0.5 + 0.5) * n, (q.y * 0.5 + 0.5) * n, q.z * lights.sun_map.y);
}

// Depth from the sun [m] of the nearest surface in the texel at `tc` (texel units); far beyond anything outside
// the map and where the texel holds no surface.
float sun_map_depth(vec2 tc) {
    float n = lights.sun_map.z;
    if (tc.x < 0.0 || tc.y < 0.0 || tc.x >= n || tc.y >= n) {
        return RAY_T_INFINITE;
    }
    // A texel left at the cleared far plane holds nothing (the receiver's plane, extended, may lie beyond it).
    float z = texelFetch(shadow_map, ivec2(tc), 0).r;
    return z < 1.0 ? z * lights.sun_map.y : RAY_T_INFINITE;
}

// The receiver's plane in the map: its depth [m] changes by grad . (dx, dy) for a sideways step (dx, dy) [m]
// along the map's axes (x = orthonormal_to(l), y = l x x): grad = (n.x, n.y) / (n.l) for the face normal n (the
// receiver-plane depth bias of Isidoro 2006). Comparing an occluder with the receiver's own plane at the texel
// looked up, instead of with the receiver's depth, keeps a plane from shadowing itself at any slope, grazing
// sun included. Capped at 1e3 (0.06 degrees from grazing).
vec2 sun_map_gradient(vec3 face, vec3 l) {
    vec3 x = orthonormal_to(l);
    vec3 y = cross(l, x);
    float nl = dot(face, l);
    vec2 g = vec2(dot(face, x), dot(face, y)) / (abs(nl) > 1e-3 ? nl : (nl < 0.0 ? -1e-3 : 1e-3));
    float m = length(g);
    return m > 1e3 ? g * (1e3 / m) : g;
}

// Whether the texel at `tc` (texel units) holds an occluder nearer to the sun than the receiver's plane there by
// more than the tolerance: a quarter texel, plus 2^-14 of the depth range (the f32 depth's rounding, with margin).
bool sun_map_occludes(vec2 tc, vec3 q, vec2 gradient) {
    float texel = lights.sun_map.x;
    vec2 center = floor(tc) + 0.5;
    float receiver = q.z + dot(gradient, (center - q.xy) * texel);
    float tolerance = 0.25 * texel + lights.sun_map.y / 16384.0;
    return sun_map_depth(tc) < receiver - tolerance;
}

// The sun's visible fraction from the map, on the same k x k grid and weights as sun_visible_fraction
// (visibility.glsl): a sample (a, b) of the disk is a ray that moves tan(sigma) (a, b) sideways per metre towards
// the sun, so it meets an occluder at depth d at the map position of the origin plus (z - d) tan(sigma) (a, b).
// d is not known per ray: a blocker search over the widest penumbra (z tan sigma) averages the occluders' depth
// (PCSS, Fernando 2005), and every sample is looked up at that average's offset. Exactly 1 where nothing in the
// search occludes. Delta sun: the one texel under the origin.
float sun_visible_fraction_map(vec3 origin, uint k, vec3 n, vec3 face, vec3 l, float angular_diameter, bool disk) {
    vec3 q = sun_map_point(origin);
    vec2 gradient = sun_map_gradient(face, l);
    float texel = lights.sun_map.x;
    if (!disk) {
        return sun_map_occludes(q.xy, q, gradient) ? 0.0 : 1.0;
    }
    float radius = tan(0.5 * angular_diameter);
    float search = q.z * radius / texel;
    float blockers = 0.0;
    float depth_sum = 0.0;
    for (uint i = 0u; i < k; ++i) {
        for (uint j = 0u; j < k; ++j) {
            vec2 tc = q.xy + search * disk_grid_point(i, j, k);
            if (sun_map_occludes(tc, q, gradient)) {
                blockers += 1.0;
                depth_sum += sun_map_depth(tc);
            }
        }
    }
    bool under = sun_map_occludes(q.xy, q, gradient);
    if (blockers == 0.0 && !under) {
        return 1.0;
    }
    float mean_depth = blockers > 0.0 ? depth_sum / blockers : sun_map_depth(q.xy);
    float spread = max(q.z - mean_depth, 0.0) * radius / texel;
    vec3 t = orthonormal_to(l);
    vec3 b = cross(l, t);
    float visible = 0.0;
    float total = 0.0;
    for (uint i = 0u; i < k; ++i) {
        for (uint j = 0u; j < k; ++j) {
            vec2 ab = disk_grid_point(i, j, k);
            vec3 p = l + radius * (ab.x * t + ab.y * b);
            float len = length(p);
            float c = dot(n, p / len);
            if (c > 0.0) {
                float w = c / (len * len * len);
                total += w;
                if (!sun_map_occludes(q.xy + spread * ab, q, gradient)) {
                    visible += w;
                }
            }
        }
    }
    return fraction(visible, total);
}

#endif
