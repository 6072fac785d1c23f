// Visibility of the lights. Mirrors src/shading/visibility.rs name for name: the same sample grids (Shirley &
// Chiu's concentric map of a k x k midpoint grid), the same weights, ray origins (Hanika's terminator offset, then
// the push along the face normal) and ray extents, so that the GPU's ray queries and the reference's f64 rays
// differ only at rays that graze an occluder's edge. See the Rust for the derivations.
#ifndef SUNSHADE_VISIBILITY_GLSL
#define SUNSHADE_VISIBILITY_GLSL

#include "bindings.glsl"
#include "math.glsl"

// How far along a ray to a point on a disk light the ray is tested: t < 1 - 2^-12 (exact in f32).
#define SEGMENT_T_MAX (1.0 - 1.0 / 4096.0)
// The relative push along the face normal: 2^-16.
#define RAY_OFFSET_RELATIVE (1.0 / 65536.0)
// "Infinitely far" for rays to the sun and the sky: beyond any f32 scene (coordinates are below 1e15 m).
#define RAY_T_INFINITE 1.0e30

#if defined(SUNSHADE_RAY_QUERY) || defined(SUNSHADE_RAY_BVH)
#include "occluders.glsl"
#endif

#ifdef SUNSHADE_RAY_QUERY
layout(set = 0, binding = 4) uniform accelerationStructureEXT scene_tlas;

// Whether any triangle meets origin + t direction for 0 < t < t_max: a ray query that stops at the first hit,
// both faces. The acceleration structure is opaque unless the scene has alpha-masked triangles; then each
// candidate hit is confirmed where the triangle blocks (occluders.glsl's blocks, at the hit's barycentrics;
// src/cpu/occluders.rs in the reference), so light passes where the mask cuts the surface away.
bool occluded(vec3 origin, vec3 direction, float t_max) {
    rayQueryEXT q;
    rayQueryInitializeEXT(q, scene_tlas, gl_RayFlagsTerminateOnFirstHitEXT, 0xFFu, origin, 0.0, direction, t_max);
    while (rayQueryProceedEXT(q)) {
        uvec4 tri = occluder_triangles[rayQueryGetIntersectionPrimitiveIndexEXT(q, false)];
        if (blocks(tri, rayQueryGetIntersectionBarycentricsEXT(q, false))) {
            rayQueryConfirmIntersectionEXT(q);
        }
    }
    return rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionNoneEXT;
}
#elif defined(SUNSHADE_RAY_BVH)
// The same on a device without ray queries: the occluders' tree walked in the shader (occluders.glsl). A zero
// or non-finite direction meets nothing (as WatertightRay::new refuses it).
bool occluded(vec3 origin, vec3 direction, float t_max) {
    if (direction == vec3(0.0) || any(isinf(direction)) || any(isnan(direction))) {
        return false;
    }
    return any_hit(watertight_ray(origin, direction), t_max);
}
#else
bool occluded(vec3 origin, vec3 direction, float t_max) {
    return false;
}
#endif

// Whether the direction `direction` (a light at infinity: the sun, the sky) is unblocked from `origin`.
bool visible_along(vec3 origin, vec3 direction) {
    return !occluded(origin, direction, RAY_T_INFINITE);
}

// Whether the point `target` [m] (on a disk light) is unblocked from `origin`.
bool visible_to(vec3 origin, vec3 target) {
    return !occluded(origin, target - origin, SEGMENT_T_MAX);
}

// The point of the unit disk for (u, v) of the unit square (Shirley & Chiu's concentric map; equal-area).
vec2 concentric_disk(float u, float v) {
    float a = 2.0 * u - 1.0;
    float b = 2.0 * v - 1.0;
    if (a == 0.0 && b == 0.0) {
        return vec2(0.0);
    }
    float r;
    float phi;
    if (a * a > b * b) {
        r = a;
        phi = 0.25 * PI * (b / a);
    } else {
        r = b;
        phi = 0.5 * PI - 0.25 * PI * (a / b);
    }
    return vec2(r * cos(phi), r * sin(phi));
}

// The grid point (i, j) of k x k on the unit disk: the concentric map of the cell's midpoint.
vec2 disk_grid_point(uint i, uint j, uint k) {
    float kf = float(k);
    return concentric_disk((float(i) + 0.5) / kf, (float(j) + 0.5) / kf);
}

// sum(w v) / sum(w): exactly 1 when every weighted sample is visible, and 1 when no sample has weight.
float fraction(float visible, float total) {
    return (visible == total || total <= 0.0) ? 1.0 : visible / total;
}

// The sun's sample through the point xy of the unit disk, in the frame (t, b) about l: its direction (omega) and
// weight (n.omega)+ / |p|^3, 0 below the horizon. Shared by the rays and the shadow map.
float sun_sample(vec3 n, vec3 l, vec3 t, vec3 b, float radius, vec2 xy, out vec3 omega) {
    vec3 p = l + radius * (xy.x * t + xy.y * b);
    float len = length(p);
    omega = p / len;
    float c = dot(n, omega);
    return c > 0.0 ? c / (len * len * len) : 0.0;
}

// A disk light's sample at the point uv of the unit disk, in the frame (a, b) of its plane: the point y [m] and
// its weight (n.omega)+ (-d.omega)+ / |y - x|^2 from x. Shared by the rays and the shadow maps.
float disk_sample(vec3 x, vec3 n, vec3 center, vec3 d, vec3 a, vec3 b, float radius, vec2 uv, out vec3 y) {
    y = center + radius * (uv.x * a + uv.y * b);
    vec3 to = y - x;
    float dist2 = dot(to, to);
    vec3 omega = to / sqrt(dist2);
    float cos_r = dot(n, omega);
    float cos_d = -dot(d, omega);
    return cos_r > 0.0 && cos_d > 0.0 ? cos_r * cos_d / dist2 : 0.0;
}

// The cosine-weighted visible fraction of the sun's disk (direction l, angular diameter [rad]).
float sun_visible_fraction(vec3 origin, uint k, vec3 n, vec3 l, float angular_diameter) {
    float radius = tan(0.5 * angular_diameter);
    vec3 t = orthonormal_to(l);
    vec3 b = cross(l, t);
    float visible = 0.0;
    float total = 0.0;
    for (uint i = 0u; i < k; ++i) {
        for (uint j = 0u; j < k; ++j) {
            vec3 omega;
            float w = sun_sample(n, l, t, b, radius, disk_grid_point(i, j, k), omega);
            if (w > 0.0) {
                total += w;
                if (visible_along(origin, omega)) {
                    visible += w;
                }
            }
        }
    }
    return fraction(visible, total);
}

// The visible fraction of a disk light, weighted by projected solid angle, from x with normal n.
float disk_visible_fraction(vec3 origin, uint k, vec3 x, vec3 n, vec3 center, vec3 d, float radius) {
    vec3 a = orthonormal_to(d);
    vec3 b = cross(d, a);
    float visible = 0.0;
    float total = 0.0;
    for (uint i = 0u; i < k; ++i) {
        for (uint j = 0u; j < k; ++j) {
            vec3 y;
            float w = disk_sample(x, n, center, d, a, b, radius, disk_grid_point(i, j, k), y);
            if (w > 0.0) {
                total += w;
                if (visible_to(origin, y)) {
                    visible += w;
                }
            }
        }
    }
    return fraction(visible, total);
}

// The visible fraction of the sky (directions with y > 0), cosine-weighted, from a point with normal n.
float sky_visible_fraction(vec3 origin, uint k, vec3 n) {
    vec3 t = orthonormal_to(n);
    vec3 b = cross(n, t);
    float visible = 0.0;
    float total = 0.0;
    for (uint i = 0u; i < k; ++i) {
        for (uint j = 0u; j < k; ++j) {
            vec2 xy = disk_grid_point(i, j, k);
            float z = sqrt(max(1.0 - xy.x * xy.x - xy.y * xy.y, 0.0));
            vec3 omega = xy.x * t + xy.y * b + z * n;
            if (omega.y > 0.0) {
                total += 1.0;
                if (visible_along(origin, omega)) {
                    visible += 1.0;
                }
            }
        }
    }
    return fraction(visible, total);
}

// The push along the face normal: 2^-16 max |p_i|_inf.
float ray_offset(vec3 p0, vec3 p1, vec3 p2) {
    vec3 m = max(max(abs(p0), abs(p1)), abs(p2));
    return RAY_OFFSET_RELATIVE * max(max(m.x, m.y), m.z);
}

// The shadow rays' origin from the point x with barycentrics b of the triangle p0, p1, p2 with unit vertex
// normals n0, n1, n2 (on the side being shaded) and shading normal n: Hanika's terminator offset, then the push.
vec3 shadow_ray_origin(vec3 p0, vec3 p1, vec3 p2, vec3 n0, vec3 n1, vec3 n2, vec3 b, vec3 x, vec3 n) {
    vec3 lifted = x;
    lifted -= b.x * min(dot(x - p0, n0), 0.0) * n0;
    lifted -= b.y * min(dot(x - p1, n1), 0.0) * n1;
    lifted -= b.z * min(dot(x - p2, n2), 0.0) * n2;
    vec3 face = cross(p1 - p0, p2 - p0);
    face = dot(face, n) < 0.0 ? -face : face;
    float len2 = dot(face, face);
    float offset = ray_offset(p0, p1, p2);
    return len2 > 0.0 ? lifted + offset * (face * inversesqrt(len2)) : lifted + offset * n;
}

#endif
