// The scene's triangles as occluders of shadow rays. Mirrors src/cpu/occluders.rs (`blocks`: an alpha-masked
// triangle lets light through where its alpha is below the cutoff) and, for devices without ray queries
// (SUNSHADE_RAY_BVH), src/visibility/bvh.rs and ray_triangle.rs: the same tree (gpu::shadow_bvh lays it out,
// its boxes padded for f32), walked with an explicit stack, and Woop, Benthin & Wald's watertight test
// ("Watertight Ray/Triangle Intersection", JCGT 2(1), 2013) in f32, so that a ray through an edge that two
// triangles share meets one of them. See the Rust for the derivations.
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
    MaterialGpu material = materials[tri.w & 0x7fffffffu];
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
        s.uv[set] = uv;
        s.uv_x[set] = uv;
        s.uv_y[set] = uv;
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
#define OCCLUDER_CORNER(i) vec3(vertex_data[(i) * FLOATS_PER_VERTEX + VERTEX_POSITION], \
    vertex_data[(i) * FLOATS_PER_VERTEX + VERTEX_POSITION + 1u], \
    vertex_data[(i) * FLOATS_PER_VERTEX + VERTEX_POSITION + 2u])
#endif

#ifdef SUNSHADE_WALK
// What the shadow rays' walk (devices without ray queries) and the slices' walks (shaders/slices.glsl, on every
// device with shadow rays) share: the tree, the walk.
// The most triangles a leaf holds (visibility::bvh's LEAF_SIZE): one, which LEAF_TEST assumes.
#define BVH_LEAF_SIZE 1u
// The walk's stack entries (visibility::bvh's STACK_SIZE: more than the deepest tree's levels).
#define BVH_STACK_SIZE 96
// The walk below an inner root: nodes taken from an explicit stack (at most one pending sibling a level of a tree
// fewer than 78 levels deep), each visiting its two children with VISIT(child), which stacks an inner child it
// enters (`stack`, `top`) and may return from the caller. One iteration of llvmpipe's budget a node taken
// (gpu::loop_budget). Shared by any_hit and the slices' gather (slices.glsl).
#define BVH_WALK(VISIT) \
    { \
        uint stack[BVH_STACK_SIZE]; \
        uint top = 1u; \
        stack[0] = 0u; \
        while (top > 0u) { \
            top -= 1u; \
            BvhNode node = bvh_nodes[stack[top]]; \
            VISIT(node.first) \
            VISIT(node.first + 1u) \
        } \
    }
#endif

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

#ifdef SUNSHADE_RAY_BVH

// One axis of the slab test (slab): the interval [lo, hi] of t narrowed to the box's slab [box_lo, box_hi] along
// it, or, where the ray does not move along it (d = 0), `outside` set when the origin lies outside the slab.
void slab_axis(float box_lo, float box_hi, float o, float d, float inv_d, inout float lo, inout float hi,
               inout bool outside) {
    if (d == 0.0) {
        outside = outside || o < box_lo || o > box_hi;
        return;
    }
    float a = (box_lo - o) * inv_d;
    float b = (box_hi - o) * inv_d;
    lo = max(lo, min(a, b));
    hi = min(hi, max(a, b));
}

// The slab test of a node's box for 0 < t < t_max (`inv`: 1/direction where it is not 0). An axis along which
// the ray does not move keeps the box exactly when the origin lies within its slab (the Rust's ±inf and NaN
// products give the same answer; division by 0 is avoided here). The three axes are called one by one, not
// looped over: llvmpipe counts every iteration of every loop against one budget a fragment (gpu::loop_budget),
// and a loop of three spent three of it on every box a walk tests. The same operations in the same order as the
// loop had, without its early exit: the interval only narrows, so the one comparison at the end rejects what an
// exit after any axis would (a NaN, which no comparison rejects, keeps the box, as it did).
bool slab(BvhNode node, vec3 origin, vec3 direction, vec3 inv, float t_max) {
    float lo = 0.0;
    float hi = t_max;
    bool outside = false;
    slab_axis(node.lo.x, node.hi.x, origin.x, direction.x, inv.x, lo, hi, outside);
    slab_axis(node.lo.y, node.hi.y, origin.y, direction.y, inv.y, lo, hi, outside);
    slab_axis(node.lo.z, node.hi.z, origin.z, direction.z, inv.z, lo, hi, outside);
    return !outside && !(lo > hi);
}

// The triangle of the leaf node `leaf`: where the ray meets it and it blocks the ray, any_hit returns true.
#define LEAF_TEST(leaf) \
    { \
        uvec4 tri = occluder_triangles[(leaf).first]; \
        vec2 bary; \
        if (intersect(r, OCCLUDER_CORNER(tri.x), OCCLUDER_CORNER(tri.y), OCCLUDER_CORNER(tri.z), t_max, bary) \
            && blocks(tri, bary)) { \
            return true; \
        } \
    }
// Child `c` of an inner node, if the ray meets its box: a leaf tested at once, an inner node stacked.
#define VISIT_CHILD(c) \
    { \
        BvhNode child = bvh_nodes[c]; \
        if (slab(child, r.origin, d, inv, t_max)) { \
            if (child.count == 0u) { \
                stack[top] = (c); \
                top += 1u; \
            } else LEAF_TEST(child) \
        } \
    }

// Whether the ray meets, with 0 < t < t_max, a triangle that blocks it: the tree walked from the root with an
// explicit stack (at most one pending sibling a level of a tree fewer than 78 levels deep). Each node taken from
// the stack is one iteration of llvmpipe's budget (gpu::loop_budget), so an inner node tests its children's boxes,
// tests at once the triangle of a child leaf the ray meets, and stacks only the inner children it meets: the
// walk's iterations are the inner nodes it enters, not the boxes or triangles it tests. (One triangle a leaf:
// on lavapipe a SIMD group runs a leaf's tests whenever one lane is at a leaf; visibility::bvh's LEAF_SIZE.)
bool any_hit(WatertightRay r, float t_max) {
    vec3 d = r.direction;
    vec3 inv = vec3(d.x != 0.0 ? 1.0 / d.x : 0.0, d.y != 0.0 ? 1.0 / d.y : 0.0, d.z != 0.0 ? 1.0 / d.z : 0.0);
    BvhNode root = bvh_nodes[0];
    if (!slab(root, r.origin, d, inv, t_max)) {
        return false;
    }
    if (root.count > 0u) {
        // A tree of one leaf (a scene of one triangle, or none: gpu::shadow_bvh's degenerate record).
        LEAF_TEST(root)
        return false;
    }
    BVH_WALK(VISIT_CHILD)
    return false;
}

#endif
#endif
