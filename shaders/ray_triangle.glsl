// Woop, Benthin & Wald's watertight ray/triangle test ("Watertight Ray/Triangle Intersection", JCGT 2(1), 2013)
// in f32, so that a ray through an edge that two triangles share meets one of them. Mirrors
// src/visibility/ray_triangle.rs (see it for the derivation). Included by occluders.glsl.
#ifndef SUNSHADE_RAY_TRIANGLE_GLSL
#define SUNSHADE_RAY_TRIANGLE_GLSL

#ifdef SUNSHADE_SHADOW_RAYS

// A ray prepared for the watertight test (WatertightRay in the Rust): the direction's dominant axis kz, the other
// two kx, ky (swapped where the direction along kz is negative, keeping the winding), and the shear
// (dx/dz, dy/dz, 1/dz).
struct WatertightRay {
    vec3 origin;
    vec3 direction;
    uvec3 k;
    vec3 shear;
};

WatertightRay watertight_ray(vec3 origin, vec3 direction) {
    vec3 a = abs(direction);
    uint kz = (a.x >= a.y && a.x >= a.z) ? 0u : (a.y >= a.z ? 1u : 2u);
    uint kx = (kz + 1u) % 3u;
    uint ky = (kx + 1u) % 3u;
    if (direction[kz] < 0.0) {
        uint swap = kx;
        kx = ky;
        ky = swap;
    }
    WatertightRay r;
    r.origin = origin;
    r.direction = direction;
    r.k = uvec3(kx, ky, kz);
    r.shear = vec3(direction[kx] / direction[kz], direction[ky] / direction[kz], 1.0 / direction[kz]);
    return r;
}

// Whether the ray meets the triangle (a, b, c) (either winding) with 0 < t < t_max; `bary`: the hit's
// barycentrics of b and c. `precise` keeps each edge function's two products and difference unfused, as the
// Rust computes them: an edge shared by two triangles then gives exactly opposite (or equal) values in both, and
// a ray through it cannot slip between them (a fused multiply-add rounds one product and not the other).
bool intersect(WatertightRay r, vec3 a, vec3 b, vec3 c, float t_max, out vec2 bary) {
    uint kx = r.k.x;
    uint ky = r.k.y;
    uint kz = r.k.z;
    precise vec3 pa = a - r.origin;
    precise vec3 pb = b - r.origin;
    precise vec3 pc = c - r.origin;
    precise float ax = pa[kx] - r.shear.x * pa[kz];
    precise float ay = pa[ky] - r.shear.y * pa[kz];
    precise float bx = pb[kx] - r.shear.x * pb[kz];
    precise float by = pb[ky] - r.shear.y * pb[kz];
    precise float cx = pc[kx] - r.shear.x * pc[kz];
    precise float cy = pc[ky] - r.shear.y * pc[kz];
    precise float u = cx * by - cy * bx;
    precise float v = ax * cy - ay * cx;
    precise float w = bx * ay - by * ax;
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) {
        return false;
    }
    precise float det = u + v + w;
    if (det == 0.0) {
        return false;
    }
    precise float t = (u * (r.shear.z * pa[kz]) + v * (r.shear.z * pb[kz]) + w * (r.shear.z * pc[kz])) / det;
    bary = vec2(v, w) / det;
    return t > 0.0 && t < t_max;
}
#endif

#endif
