// The occluders' BVH for devices without ray queries (SUNSHADE_RAY_BVH) and for the slices' walks (SUNSHADE_WALK):
// the same tree as src/visibility/bvh.rs (gpu::shadow_bvh lays it out, its boxes padded for f32): the slices' and
// the disk lights' walks take it with an explicit stack, the shadow rays in depth-first order without one. Mirrors
// src/visibility/bvh.rs (see it for the derivations). Included by occluders.glsl after `blocks` and the watertight
// test, which a leaf's test calls.
#ifndef SUNSHADE_BVH_GLSL
#define SUNSHADE_BVH_GLSL

#ifdef SUNSHADE_WALK
// What the walks of the slices (shaders/slices.glsl) and of the disk lights' cones (disk_cone.glsl), on every
// device with shadow rays, share: the tree, its stack (the slices take BVH_WALK; the cones' walk, disk_cone_gather,
// starts above the root).
// The most triangles a leaf holds (visibility::bvh's LEAF_SIZE): one, which the walks' leaf tests assume.
#define BVH_LEAF_SIZE 1u
// The walk's stack entries (visibility::bvh's STACK_SIZE: more than the deepest tree's levels).
#define BVH_STACK_SIZE 96
// The walk below an inner root: nodes taken from an explicit stack (at most one pending sibling a level of a tree
// fewer than 78 levels deep), each visiting its two children with VISIT(child), which stacks an inner child it
// enters (`stack`, `top`) and may return from the caller. One iteration of llvmpipe's budget a node taken
// (gpu::loop_budget).
#define BVH_WALK(VISIT) \
    { \
        uint stack[BVH_STACK_SIZE]; \
        uint top = 1u; \
        stack[0] = 0u; \
        while (top > 0u) { \
            top -= 1u; \
            BvhNode node = bvh_node(stack[top]); \
            VISIT(node.first) \
            VISIT(node.first + 1u) \
        } \
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

// One node of the shadow rays' walk (any_hit): a leaf whose triangle the ray meets and which blocks it returns
// true; a box the ray misses, or a leaf, is passed over to the node after its subtree (first); an inner node whose
// box the ray meets goes on to its first child, the next node.
#define THREADED_STEP \
    { \
        BvhNode node = threaded_node(i); \
        uint next = node.first; \
        if (slab(node, r.origin, d, inv, t_max)) { \
            if (node.count == THREADED_INNER) { \
                next = i + 1u; \
            } else { \
                uvec4 tri = WALK_RECORD(node.count); \
                vec2 bary; \
                if (intersect(r, OCCLUDER_CORNER(tri.x), OCCLUDER_CORNER(tri.y), OCCLUDER_CORNER(tri.z), t_max, \
                              bary) && blocks(tri, bary)) { \
                    return true; \
                } \
            } \
        } \
        i = next; \
    }

// Whether the ray meets, with 0 < t < t_max, a triangle that blocks it: the tree in depth-first order walked
// without a stack (the Rust walks it with one; a shadow ray may take its hits in any order, so both test the same
// triangles' boxes and return the same answer). On lavapipe a stack is a local array indexed differently in
// each lane, which llvmpipe reads and writes lane by lane; here a lane holds one index. Two nodes a loop iteration:
// llvmpipe's loop budget (gpu::loop_budget) counts iterations, and the walk with a stack took one for each inner
// node it entered, testing its two children.
bool any_hit(WatertightRay r, float t_max) {
    vec3 d = r.direction;
    vec3 inv = vec3(d.x != 0.0 ? 1.0 / d.x : 0.0, d.y != 0.0 ? 1.0 / d.y : 0.0, d.z != 0.0 ? 1.0 / d.z : 0.0);
    uint end = threaded_node(0u).first;
    uint i = 0u;
    while (i < end) {
        THREADED_STEP
        if (i < end) THREADED_STEP
    }
    return false;
}

#endif

#endif
