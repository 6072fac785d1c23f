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
            vec3 omega;
            float w = sun_sample(n, l, t, b, radius, ab, omega);
            if (w > 0.0) {
                total += w;
                if (!sun_map_occludes(q.xy + spread * ab, q, gradient)) {
                    visible += w;
                }
            }
        }
    }
    return fraction(visible, total);
}

// Linear depth [m] along the disk's axis of the nearest surface in texel `tc` of disk map i, far beyond anything
// outside the map or where the texel holds nothing. (Constant indices: no dynamic indexing of the array needed.)
float disk_map_depth(uint i, vec2 tc) {
    vec4 m = lights.disk_map[i];
    if (tc.x < 0.0 || tc.y < 0.0 || tc.x >= m.w || tc.y >= m.w) {
        return RAY_T_INFINITE;
    }
    ivec2 t = ivec2(tc);
    float z = i == 0u ? texelFetch(disk_shadow_maps[0], t, 0).r
            : i == 1u ? texelFetch(disk_shadow_maps[1], t, 0).r
            : i == 2u ? texelFetch(disk_shadow_maps[2], t, 0).r
                      : texelFetch(disk_shadow_maps[3], t, 0).r;
    // Perspective depth back to linear: z = f n / (f - z_ndc (f - n)).
    return z < 1.0 ? m.z * m.y / (m.z - z * (m.z - m.y)) : RAY_T_INFINITE;
}

// The visible fraction of disk light i (centre, emission direction d, radius) from the point x with normal n and
// face normal `face`, by its map (PCSS for an area light, Fernando 2005): the receiver's depth z along the axis,
// a blocker search, the mean blocker depth z_b, then every sample of the same k x k grid as the rays looked up
// where its ray crosses depth z_b, and weighted as the rays are. Outside the map's field of view (more than 80
// degrees off the axis) the light is unoccluded. The comparison allows one texel at the receiver's distance times
// (1 + tan of the face's angle to the light), plus the tangent plane's depth change out to each lookup.
float disk_visible_fraction_map(uint i, vec3 origin, uint k, vec3 x, vec3 n, vec3 face, vec3 center, vec3 d, float radius, bool pcss) {
    vec4 m = lights.disk_map[i];
    vec4 q = lights.disk_map_from_world[i] * vec4(origin, 1.0);
    float z = q.w;
    if (!(z > m.y) || abs(q.x) > z || abs(q.y) > z) {
        return 1.0;
    }
    float size = m.w;
    vec2 tc = (q.xy / z * 0.5 + 0.5) * size;
    // The side of one texel at the receiver's distance [m], and per metre of depth at the near plane.
    float texel_at = 2.0 * z * m.x / size;
    vec3 toward = center - origin;
    float len2 = dot(toward, toward);
    vec3 to_light = len2 > 0.0 ? toward * inversesqrt(len2) : -d;
    float c = abs(dot(face, to_light));
    float t = c > 1e-3 ? sqrt(max(1.0 - c * c, 0.0)) / c : 1e3;
    float bias = texel_at * (1.0 + t);
    // A lookup r texels away meets the receiver's own (tangent) plane up to r texel_at tan(theta) nearer: allowed
    // for, so that a curved or tilted receiver does not shadow itself through the filter's offsets.
    float slope = texel_at * min(t, 1e3);
    if (!pcss) {
        return disk_map_depth(i, tc) < z - bias ? 0.0 : 1.0;
    }
    // The ray from x to the disk point c + R (a, b) crosses depth z' at the map position of x plus
    // R (a, b) (z - z') / (z' z) in tan units, size / (2 tan) texels each: the search covers blockers from halfway
    // to the disk (z' = z / 2: R / z tan units, R / texel_at texels); nearer ones are found only in part.
    float search = min(radius / texel_at, 0.5 * size);
    float blockers = 0.0;
    float depth_sum = 0.0;
    for (uint a = 0u; a < k; ++a) {
        for (uint b = 0u; b < k; ++b) {
            vec2 o = disk_grid_point(a, b, k);
            float dz = disk_map_depth(i, tc + search * o);
            if (dz < z - bias - slope * search * length(o)) {
                blockers += 1.0;
                depth_sum += dz;
            }
        }
    }
    if (blockers == 0.0 && !(disk_map_depth(i, tc) < z - bias)) {
        return 1.0;
    }
    float zb = blockers > 0.0 ? depth_sum / blockers : disk_map_depth(i, tc);
    // The offset of the disk's rim at the mean blocker depth: R (z - z_b) / (z_b z) tan units, in texels.
    float spread = min(radius * max(z - zb, 0.0) / max(zb, m.y) / texel_at, 0.5 * size);
    vec3 ax = orthonormal_to(d);
    vec3 ay = cross(d, ax);
    float visible = 0.0;
    float total = 0.0;
    for (uint a = 0u; a < k; ++a) {
        for (uint b = 0u; b < k; ++b) {
            vec2 o = disk_grid_point(a, b, k);
            vec3 y;
            float w = disk_sample(x, n, center, d, ax, ay, radius, o, y);
            if (w > 0.0) {
                total += w;
                if (!(disk_map_depth(i, tc + spread * o) < z - bias - slope * spread * length(o))) {
                    visible += w;
                }
            }
        }
    }
    return fraction(visible, total);
}

#endif
