// A disk light's shadow rays proven clear before one is cast: a walk of the occluders' BVH with the cone from the
// ray origin to the disk, listing the few triangles it cannot show apart from the rays. None: every ray of the grid
// and of the lobe gets through, the visible fraction is exactly 1 and none is cast; a few: the grid's rays test
// those alone. Mirrors src/visibility/disk_cone.rs name for name (see it for the derivation and the margins).
// Where the shader walks the tree (SUNSHADE_WALK); included by visibility.glsl after sun_cells.glsl, whose
// classification it uses.
#ifndef SUNSHADE_DISK_CONE_GLSL
#define SUNSHADE_DISK_CONE_GLSL

// The margin of the comparisons, relative to the largest coordinate involved: 2^-19 (DISK_CONE_MARGIN).
#define DISK_CONE_MARGIN (1.0 / 524288.0)
// The most triangles a walk lists (DISK_CONE_LISTED); past them the rays take the traversal.
#define DISK_CONE_LISTED 16u
// The most this module's walk lists: where the shader walks the BVH for its rays, which then test the list alone
// (visibility.glsl's sample_visible); with ray queries none (the rays stay the device's), so the walk ends at the
// first triangle it cannot show apart.
#ifdef SUNSHADE_RAY_BVH
const uint DISK_CONE_LIST_LIMIT = DISK_CONE_LISTED;
#else
const uint DISK_CONE_LIST_LIMIT = 0u;
#endif

// The rays from an origin to a disk light (DiskCone in the Rust).
struct DiskCone {
    vec3 origin;
    vec3 x;
    vec3 n;
    float delta;
    float lowest;
    float inv_reach;
    vec3 axis;
    vec3 u;
    vec3 v;
    float sin_half;
    float cos_half;
    vec3 center;
    vec3 d;
    vec3 lo;
    vec3 hi;
    float size;
};

float largest_coordinate(vec3 v) {
    vec3 a = abs(v);
    return max(max(a.x, a.y), a.z);
}

// The cone of the rays from origin (moved off the shading point x of normal n) to the disk light (centre [m], unit
// emission direction d, radius [m]); false where the origin is not in front of the disk or within a radius (and
// 2^-10 of it) of its centre.
bool disk_cone(vec3 origin, vec3 x, vec3 n, vec3 center, vec3 d, float radius, out DiskCone c) {
    vec3 to = center - origin;
    float dist = length(to);
    float h = dot(d, origin - center);
    c.origin = origin;
    c.n = n;
    // The floor under the rays (see the Rust): the origin's height above the tangent plane at x, the disk's
    // lowest point's (at least 0).
    c.x = x;
    c.delta = dot(n, origin - x);
    c.lowest = max(dot(n, center - x) - radius * length(n - dot(n, d) * d), 0.0);
    c.inv_reach = 1.0 / (dist - radius);
    c.center = center;
    c.d = d;
    if (!(h > 0.0 && radius >= 0.0 && dist * (1.0 - 1.0 / 1024.0) > radius)) {
        return false;
    }
    c.sin_half = radius / dist;
    c.cos_half = sqrt((1.0 - c.sin_half) * (1.0 + c.sin_half));
    c.axis = to / dist;
    c.u = orthonormal_to(c.axis);
    c.v = cross(c.axis, c.u);
    vec3 reach = radius * sqrt(max((vec3(1.0) - d) * (vec3(1.0) + d), vec3(0.0)));
    c.lo = min(origin, center - reach);
    c.hi = max(origin, center + reach);
    c.size = max(largest_coordinate(origin), largest_coordinate(center) + radius);
    return true;
}

// Whether the ball (centre [m], radius r [m]) lies outside the cone (its signed distance).
bool disk_cone_apart_from_ball(DiskCone c, vec3 centre, float r) {
    vec3 v = centre - c.origin;
    float along = dot(v, c.axis);
    float across = length(v - along * c.axis);
    return across * c.cos_half - along * c.sin_half > r;
}

// The height above the tangent plane at x [m] under which the rays meet nothing within r [m] of the origin.
float disk_cone_floor(DiskCone c, float r) {
    if (c.delta <= c.lowest) {
        return c.delta;
    }
    float tau = min(r * c.inv_reach, 1.0);
    return (1.0 - tau) * c.delta + tau * c.lowest;
}

// Whether the box (centre, half sizes [m]) lies wholly outside one face of the square pyramid about the cone, by
// margin [m].
bool disk_cone_apart_from_pyramid(DiskCone c, vec3 centre, vec3 half_size, float margin) {
    vec3 v = centre - c.origin;
    vec3 m0 = c.cos_half * c.u - c.sin_half * c.axis;
    vec3 m1 = -c.cos_half * c.u - c.sin_half * c.axis;
    vec3 m2 = c.cos_half * c.v - c.sin_half * c.axis;
    vec3 m3 = -c.cos_half * c.v - c.sin_half * c.axis;
    return dot(m0, v) - dot(abs(m0), half_size) > margin || dot(m1, v) - dot(abs(m1), half_size) > margin
           || dot(m2, v) - dot(abs(m2), half_size) > margin || dot(m3, v) - dot(abs(m3), half_size) > margin;
}

// Whether the box [lo, hi] [m] lies apart from the cone's rays: outside the hull's box, behind the disk's plane,
// below the tangent plane or outside the cone (a face of its pyramid, or its ball), by the margin.
bool disk_cone_apart_from_box(DiskCone c, vec3 lo, vec3 hi) {
    float m = DISK_CONE_MARGIN * max(c.size, max(largest_coordinate(lo), largest_coordinate(hi)));
    if (any(lessThan(hi, c.lo - m)) || any(greaterThan(lo, c.hi + m))) {
        return true;
    }
    vec3 centre = 0.5 * (lo + hi);
    vec3 half_size = 0.5 * (hi - lo);
    if (dot(c.d, centre - c.center) + dot(abs(c.d), half_size) <= -m) {
        return true;
    }
    float reach = length(centre - c.origin) + length(half_size);
    if (dot(c.n, centre - c.x) + dot(abs(c.n), half_size) <= disk_cone_floor(c, reach) - 0.25 * m) {
        return true;
    }
    return disk_cone_apart_from_pyramid(c, centre, half_size, m)
           || disk_cone_apart_from_ball(c, centre, length(half_size) + m);
}

// Whether no ray of the cone can meet the triangle (world corners [m]).
bool disk_cone_misses_triangle(DiskCone c, vec3 c0, vec3 c1, vec3 c2) {
    vec3 lo = min(min(c0, c1), c2);
    vec3 hi = max(max(c0, c1), c2);
    float m = DISK_CONE_MARGIN * max(c.size, max(largest_coordinate(lo), largest_coordinate(hi)));
    if (any(lessThan(hi, c.lo - m)) || any(greaterThan(lo, c.hi + m))) {
        return true;
    }
    if (dot(c.d, c0 - c.center) <= -m && dot(c.d, c1 - c.center) <= -m && dot(c.d, c2 - c.center) <= -m) {
        return true;
    }
    float reach = max(max(length(c0 - c.origin), length(c1 - c.origin)), length(c2 - c.origin));
    float floor_height = disk_cone_floor(c, reach) - 0.25 * m;
    if (dot(c.n, c0 - c.x) <= floor_height && dot(c.n, c1 - c.x) <= floor_height
        && dot(c.n, c2 - c.x) <= floor_height) {
        return true;
    }
    return cone_triangle_class(c.origin, c.axis, c.sin_half, c0, c1, c2) == SUN_CONE_MISSES;
}

// The triangles (occluder records) the last walk listed, for disk_cone_occluded.
uvec4 disk_cone_listed[DISK_CONE_LISTED];
uint disk_cone_listed_count = 0u;

// A leaf's triangle the cone's rays may meet is listed; one past DISK_CONE_LIST_LIMIT ends the walk.
#define DISK_CONE_LEAF(leaf) \
    { \
        uvec4 tri = WALK_RECORD((leaf).first); \
        if (!disk_cone_misses_triangle(c, OCCLUDER_CORNER(tri.x), OCCLUDER_CORNER(tri.y), OCCLUDER_CORNER(tri.z))) { \
            if (disk_cone_listed_count == DISK_CONE_LIST_LIMIT) { \
                return DISK_CONE_UNKNOWN; \
            } \
            disk_cone_listed[disk_cone_listed_count] = tri; \
            disk_cone_listed_count += 1u; \
        } \
    }
// Child `i` of an inner node: skipped where its box is apart; an inner node stacked, a leaf's triangle tested. The
// root (`root`) is tested as a child, but a root leaf by its triangle alone.
#define DISK_CONE_CHILD(i, root) \
    { \
        BvhNode child = bvh_node(i); \
        if (((root) && child.count > 0u) || !disk_cone_apart_from_box(c, child.lo, child.hi)) { \
            if (child.count == 0u) { \
                stack[top] = (i); \
                top += 1u; \
            } else DISK_CONE_LEAF(child) \
        } \
    }

// The occluders the shadow rays from origin (moved off x) to the disk light may meet: the tree walked with the cone,
// the triangles it cannot show apart listed (disk_cone_listed): DISK_CONE_CLEAR where there are none (every ray
// gets through), DISK_CONE_LIST, or DISK_CONE_UNKNOWN where there is no cone or more than DISK_CONE_LIST_LIMIT.
// One iteration of llvmpipe's loop budget an inner node entered, as the rays' walk, and one for the root: the walk
// starts above it (DISK_CONE_ABOVE_ROOT, whose one child is the root), so that its two visits of a node's children
// are the only copies of the box and triangle tests the driver compiles (it inlines every call).
#define DISK_CONE_ABOVE_ROOT 0xffffffffu
uint disk_cone_gather(vec3 origin, vec3 x, vec3 n, vec3 center, vec3 d, float radius) {
    disk_cone_listed_count = 0u;
    DiskCone c;
    if (!disk_cone(origin, x, n, center, d, radius, c)) {
        return DISK_CONE_UNKNOWN;
    }
    uint stack[BVH_STACK_SIZE];
    uint top = 1u;
    stack[0] = DISK_CONE_ABOVE_ROOT;
    while (top > 0u) {
        top -= 1u;
        uint entry = stack[top];
        bool above_root = entry == DISK_CONE_ABOVE_ROOT;
        uint first = above_root ? 0u : bvh_node(entry).first;
        DISK_CONE_CHILD(first, above_root)
        if (!above_root) DISK_CONE_CHILD(first + 1u, false)
    }
    return disk_cone_listed_count == 0u ? DISK_CONE_CLEAR : DISK_CONE_LIST;
}

// Whether the ray from origin along direction meets, with 0 < t < t_max, a listed triangle that blocks it: where the
// walk listed the triangles, occluded's answer (every other triangle misses every ray to the disk).
bool disk_cone_occluded(vec3 origin, vec3 direction, float t_max) {
    if (direction == vec3(0.0) || any(isinf(direction)) || any(isnan(direction))) {
        return false;
    }
    WatertightRay r = watertight_ray(origin, direction);
    for (uint i = 0u; i < disk_cone_listed_count; ++i) {
        uvec4 tri = disk_cone_listed[i];
        vec2 bary;
        if (intersect(r, OCCLUDER_CORNER(tri.x), OCCLUDER_CORNER(tri.y), OCCLUDER_CORNER(tri.z), t_max, bary)
            && blocks(tri, bary)) {
            return true;
        }
    }
    return false;
}

#endif
