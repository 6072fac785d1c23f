// Visibility of the lights. Mirrors src/shading/visibility.rs name for name: the same sample grids (the corners of
// k x k squares, mapped to the sun's and disk lights' disks by Shirley & Chiu's concentric map and turned, to the
// sky's lune by its angles), the same weights, ray origins (Hanika's terminator offset, then the push along the
// face normal) and ray extents, so that the GPU's ray queries and the reference's f64 rays
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

// Whether this pipeline casts shadow rays (the pipeline variant; only modules built with SUNSHADE_RAY_QUERY can).
const bool SHADOWS_ON = VARIANT_SHADOWS == SHADOWS_RAY;
// Whether it looks the sun and the first disks up in their shadow maps (further disks and the sky unoccluded).
const bool SHADOWS_MAP_ON = VARIANT_SHADOWS == SHADOWS_MAP;

#if defined(SUNSHADE_RAY_QUERY) || defined(SUNSHADE_RAY_BVH)
#include "occluders.glsl"
#endif

// In the first of two draws (VARIANT_PENUMBRAE == PENUMBRAE_LATER), a pixel that needs a ray through the tree or a
// light's grid is left to the second draw (gpu::second_draw): marked, and `value` returned in place of what the
// ray or grid would give, so that the first draw holds none of their code. On llvmpipe a branch that no lane of a
// SIMD group takes still runs, masked (docs/platform.md, "Branches no pixel takes"): in one draw the grids' code
// costs every pixel.
#define LEAVE_TO_SECOND_DRAW(value) \
    if (VARIANT_PENUMBRAE == PENUMBRAE_LATER) { \
        left_to_second_draw = true; \
        return value; \
    }
// A ray through the tree in either draw that holds no tree (the first of two, and TREE_LATER's): the pixel is
// marked for the draw or frame that has it.
#define LEAVE_THE_TREE(value) \
    if (VARIANT_PENUMBRAE != PENUMBRAE_HERE) { \
        left_to_second_draw = true; \
        return value; \
    }

#ifdef SUNSHADE_RAY_QUERY
layout(set = 0, binding = 4) uniform accelerationStructureEXT scene_tlas;

// Whether any triangle meets origin + t direction for 0 < t < t_max: a ray query that stops at the first hit,
// both faces. The acceleration structure is opaque unless the scene has alpha-masked triangles; then each
// candidate hit is confirmed where the triangle blocks (occluders.glsl's blocks, at the hit's barycentrics;
// src/cpu/occluders.rs in the reference), so light passes where the mask cuts the surface away.
bool occluded(vec3 origin, vec3 direction, float t_max) {
    LEAVE_THE_TREE(false);
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
    LEAVE_THE_TREE(false);
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

// What a disk light's walk (disk_cone.glsl's disk_cone_gather; DiskConeGather in the Rust) found: no triangle near
// its rays, a list of them, or too many (or no walk on this module).
#define DISK_CONE_CLEAR 0u
#define DISK_CONE_LIST 1u
#define DISK_CONE_UNKNOWN 2u

#include "sun_cells.glsl"
#if defined(SUNSHADE_WALK) && defined(SUNSHADE_SHADOW_RAYS)
#include "disk_cone.glsl"
#endif

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

// cos and sin of the turn of the sun's and disk lights' grids in their disks: 2^-6 rad.
#define GRID_TURN_COS 0.9998779321710066
#define GRID_TURN_SIN 0.015624364224883372
// How far off the light's centre turned puts the grid's sample there, in the disk's radii: 2^-10.
#define GRID_CENTRE_SHIFT (1.0 / 1024.0)

// A point of the unit disk turned by that angle, the centre moved off itself: where the sun's and disk lights' grid
// samples lie (see the Rust: otherwise a grid's samples meet the edges of a scene built on a grid exactly, along
// whole lines of pixels).
vec2 turned(vec2 xy) {
    if (xy == vec2(0.0)) {
        return GRID_CENTRE_SHIFT * vec2(GRID_TURN_COS, GRID_TURN_SIN);
    }
    return vec2(GRID_TURN_COS * xy.x - GRID_TURN_SIN * xy.y, GRID_TURN_SIN * xy.x + GRID_TURN_COS * xy.y);
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

#ifdef SUNSHADE_SLICES
#include "slices.glsl"
#endif

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

// The largest k of the located grid (grid_fraction keeps two columns of k + 1 corners); the renderer refuses more.
#define MAX_LOCATED_GRID 256u
// What a visible-fraction grid samples (VisibilityLight.kind).
#define GRID_LIGHT_SUN 0u
#define GRID_LIGHT_DISK 1u
#define GRID_LIGHT_SKY 2u
// The sun, its rays tested against its cell's triangles (sun_cells.glsl) instead of taking occluded.
#define GRID_LIGHT_SUN_CELLS 3u
// A disk light, its rays tested against the triangles its walk listed (disk_cone.glsl) instead of taking occluded
// (only where the shader walks the BVH for its rays: with ray queries the walk lists none).
#define GRID_LIGHT_DISK_LISTED 4u
// grid_fraction's stages at a corner: its own ray, the bisection along v to the corner below, along u to the one
// before.
#define GRID_CORNER 0u
#define GRID_ALONG_V 1u
#define GRID_ALONG_U 2u
#define GRID_NEXT_RAY 0u
#define GRID_NEXT_V 1u
#define GRID_NEXT_U 2u
#define GRID_NEXT_SQUARE 3u

// A located grid's light and the receiving point's frame (GridLight in the Rust). Sun: normal n, direction c,
// frame (a, b) about it, radius tan(sigma). Disk light: seen from x with normal n; centre c [m], emission
// direction d, frame (a, b), radius [m]. Sky (SkyLune in the Rust): the lune's axis a, the horizontal b towards
// which the normal leans, radius the lune's width pi - tilt [rad], tilt the surface's tilt from up [rad].
struct VisibilityLight {
    uint kind;
    vec3 x;
    vec3 n;
    vec3 c;
    vec3 d;
    vec3 a;
    vec3 b;
    float radius;
    float tilt;
};

// A grid that samples nothing: the light of a LightTerm that leaves no grid.
const VisibilityLight NO_GRID_LIGHT = VisibilityLight(GRID_LIGHT_SUN, vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0),
                                                      vec3(0.0), vec3(0.0), 0.0, 0.0);

// A light's term in a shading point's irradiance (sun_term, disk_term, sky_term): `e v`, or `e (omega v)` where
// `by_omega` (a disk light's radiance and projected solid angle, multiplied in that order), v its visible fraction,
// or -1 where the located grid over `grid` (k^2 squares, from the shadow rays' origin) is to find it.
// irradiance_visible takes every light's grid by one call of grid_fraction: the driver inlines each call, and a
// call in each light's term would compile the grid and its rays once a kind of light.
struct LightTerm {
    vec3 e;
    float omega;
    bool by_omega;
    float v;
    uint k;
    VisibilityLight grid;
};

// The sky's lune above a surface of unit normal n (sky_lune in the Rust): the tilt as atan2(|n - n_y y|, n_y),
// a floor's lune the whole hemisphere about a = x cross y.
VisibilityLight sky_lune(vec3 n) {
    vec3 across = vec3(n.x, 0.0, n.z);
    float len = length(across);
    vec3 e = len > 0.0 ? across / len : vec3(1.0, 0.0, 0.0);
    float tilt = atan2_accurate(len, n.y);
    return VisibilityLight(GRID_LIGHT_SKY, vec3(0.0), n, vec3(0.0), vec3(0.0), cross(e, vec3(0.0, 1.0, 0.0)), e,
                           PI - tilt, tilt);
}

// The sky's sample at the point uv of the unit square: the direction omega(beta = pi v, psi = width u) of its lune
// and the weight sin^2(beta) sin(psi + tilt), the sines taken of the smaller of their two equal-sine arguments so
// that they are exactly 0 on the surface's horizon and at the lune's ends (sky_sample in the Rust).
float sky_sample(vec3 a, vec3 e, float tilt, float width, vec2 uv, out vec3 omega) {
    float sin_b = sin(PI * min(uv.y, 1.0 - uv.y));
    float cos_b = cos(PI * uv.y);
    float psi = width * uv.x;
    omega = cos_b * a + sin_b * (cos(psi) * e + sin(psi) * vec3(0.0, 1.0, 0.0));
    return sin_b * sin_b * sin(min(psi + tilt, width * (1.0 - uv.x)));
}

// The weight and shadow ray (a direction, or a point on a disk light) of the point uv of the unit square: the
// sun's and disk lights' through the concentric map, the sky's through its lune.
float light_sample(VisibilityLight L, vec2 uv, out vec3 ray) {
    if (VARIANT_SKY != LIGHT_ABSENT && L.kind == GRID_LIGHT_SKY) {
        return sky_sample(L.a, L.b, L.tilt, L.radius, uv, ray);
    }
    vec2 xy = turned(concentric_disk(uv.x, uv.y));
    if (VARIANT_DISKS == LIGHT_ABSENT || L.kind == GRID_LIGHT_SUN || L.kind == GRID_LIGHT_SUN_CELLS) {
        return sun_sample(L.n, L.c, L.a, L.b, L.radius, xy, ray);
    }
    return disk_sample(L.x, L.n, L.c, L.d, L.a, L.b, L.radius, xy, ray);
}

// Whether a grid sample's shadow ray reaches its light: visible_to for a disk light's point, visible_along for a
// direction, written as one call of occluded so that the driver, which inlines every call, compiles one copy of
// the ray's traversal here instead of two (docs/platform.md, "What the driver compiles"). The arithmetic is
// theirs: target - origin for a point, the direction itself otherwise. Only a frame with the sun's cells has
// lights of kind GRID_LIGHT_SUN_CELLS, so that the cells' test is compiled only for its pipelines.
bool sample_visible(vec3 origin, VisibilityLight L, vec3 ray) {
#ifdef SUNSHADE_SHADOW_RAYS
    if (ONLY_SUN_CELL_RAYS || (VARIANT_SUN_CELLS != SUN_CELLS_NONE && L.kind == GRID_LIGHT_SUN_CELLS)) {
        return !sun_cells_occluded(origin, L.n, ray);
    }
#endif
#ifdef SUNSHADE_RAY_BVH
    // The listed triangles by the walk's own test (the one the BVH's walk would apply to them); with ray queries
    // the walk lists none (disk_cone.glsl's DISK_CONE_LIST_LIMIT): the rays stay the device's.
    if (VARIANT_DISKS != LIGHT_ABSENT && L.kind == GRID_LIGHT_DISK_LISTED) {
        return !disk_cone_occluded(origin, ray - origin, SEGMENT_T_MAX);
    }
#endif
    bool to_point = VARIANT_DISKS != LIGHT_ABSENT && L.kind == GRID_LIGHT_DISK;
    return !occluded(origin, to_point ? ray - origin : ray, to_point ? SEGMENT_T_MAX : RAY_T_INFINITE);
}

// Bisection steps that place a visibility edge between two neighbouring corners: ceil(log2 k), at least 1.
uint edge_bisections(uint k) {
    return max(uint(findMSB(max(k, 1u) - 1u) + 1), 1u);
}

// How many edge crossings one grid locates (2k); past them a crossing is its side's midpoint, without rays.
uint max_located_crossings(uint k) {
    return 2u * k;
}

// Whether the side from a neighbouring corner (its weight signed by its state: > 0 seen, < 0 blocked, 0 none) to a
// corner of weight w and state seen needs its crossing: both have weight and they disagree.
bool disagrees(float w, bool seen, float neighbour) {
    return w > 0.0 && neighbour != 0.0 && seen != (neighbour > 0.0);
}

// The visible share of the square between four grid corners (0,0), (1,0), (1,1), (0,1) (seen0..3), the edge
// drawn straight between its crossings on the sides whose corners disagree (bottom and top at x = their value,
// right and left at y = theirs): the marching-squares polygon, its area by the shoelace formula.
float cell_visible_area(bvec4 seen, float bottom, float right, float top, float left) {
    if (all(seen)) {
        return 1.0;
    }
    if (!any(seen)) {
        return 0.0;
    }
    vec2 corners[4] = vec2[4](vec2(0.0, 0.0), vec2(1.0, 0.0), vec2(1.0, 1.0), vec2(0.0, 1.0));
    vec2 crossings[4] = vec2[4](vec2(bottom, 0.0), vec2(1.0, right), vec2(top, 1.0), vec2(0.0, left));
    bool s[4] = bool[4](seen.x, seen.y, seen.z, seen.w);
    vec2 points[8];
    uint count = 0u;
    for (uint c = 0u; c < 4u; ++c) {
        if (s[c]) {
            points[count] = corners[c];
            count += 1u;
        }
        if (s[c] != s[(c + 1u) % 4u]) {
            points[count] = crossings[c];
            count += 1u;
        }
    }
    float twice = 0.0;
    for (uint p = 0u; p < count; ++p) {
        vec2 a = points[p];
        vec2 b = points[(p + 1u) % count];
        twice += a.x * b.y - b.x * a.y;
    }
    return 0.5 * twice;
}

// sum(w V) / sum(w) over the unit square mapped to the light (light_sample): k = 1, the light's centre (turned)
// alone; otherwise the (k + 1)^2 corners of a k x k grid of squares, each square its corners' mean weight times
// its visible share, the edges between disagreeing corners located by bisection (grid_fraction in the Rust, the
// same rays and the same sums in the same order).
//
// Scheduled as one ray a loop iteration (a small state machine: a corner's ray, then the bisections of the edge
// below it along v and before it along u, then its square), not as the Rust's nested loops with the bisections
// inside: a fragment's SIMD group runs a branch whenever one of its lanes takes it, so bisections nested at a
// corner would run once for every corner where any lane meets an edge (the group paying for the union of its
// lanes' edges), and llvmpipe's loop budget (src/gpu/loop_budget.rs) ran out on sunset.glb at 5^2 shadow rays.
// Here the lanes cast their rays side by side and a group pays for its busiest lane. The Rust's locate_edge is the
// GRID_ALONG_V / GRID_ALONG_U stages.
//
// Two columns of corners are kept (weights signed by visibility: w > 0 seen, w < 0 blocked, 0 no weight, and the
// crossings along v), alternating in one array so that no loop copies them.
float grid_fraction(vec3 origin, uint k, VisibilityLight L) {
    LEAVE_TO_SECOND_DRAW(1.0);
    // With k <= 1 the loop's first ray is the light's centre (turned), and its answer the fraction: one call of
    // sample_visible in the shader, which the driver inlines with every ray test it holds (docs/platform.md, "What
    // the driver compiles").
    float kf = float(max(k, 1u));
    uint steps = edge_bisections(k);
    uint left = max_located_crossings(k);
    float visible = 0.0;
    float total = 0.0;
    float column_w[2u * (MAX_LOCATED_GRID + 1u)];
    float column_up[2u * (MAX_LOCATED_GRID + 1u)];
    // The corner (i, j) and what is being done at it: GRID_CORNER its ray, GRID_ALONG_V / GRID_ALONG_U a bisection
    // (step of steps, bracket [lo, hi]); w and seen its weight and state; across the crossing along u into it,
    // across_below the one into the corner below.
    uint i = 0u;
    uint j = 0u;
    uint stage = GRID_CORNER;
    uint step = 0u;
    float lo = 0.0;
    float hi = 1.0;
    float w = 0.0;
    bool seen = false;
    float across = 0.0;
    float across_below = 0.0;
    while (i <= k) {
        uint cur = (i & 1u) * (MAX_LOCATED_GRID + 1u);
        uint prev = MAX_LOCATED_GRID + 1u - cur;
        // Exact in f32: the bracket's ends are dyadic with at most edge_bisections(256) + 1 = 9 bits, added to a
        // grid index of at most 256, so uv is the Rust's point to the bit before the map divides by k.
        float mid = 0.5 * (lo + hi);
        vec2 uv = stage == GRID_CORNER ? vec2(float(i), float(j))
                : stage == GRID_ALONG_V ? vec2(float(i), float(j) - 1.0 + mid)
                                        : vec2(float(i) - 1.0 + mid, float(j));
        vec3 ray;
        float weight = light_sample(L, k <= 1u ? vec2(0.5) : vec2(uv.x / kf, uv.y / kf), ray);
        // The iteration's one ray (a corner of no weight casts none).
        bool ray_seen = (stage != GRID_CORNER || weight > 0.0) && sample_visible(origin, L, ray);
        if (k <= 1u) {
            return fraction(ray_seen ? weight : 0.0, weight);
        }
        // What comes next at this corner: GRID_NEXT_V / GRID_NEXT_U, whether its side along v (to the corner below)
        // / along u (to the one before) needs a crossing; GRID_NEXT_RAY, a bisection goes on; GRID_NEXT_SQUARE, its
        // square. A crossing past the grid's allowance is the side's midpoint, without rays.
        uint next = GRID_NEXT_RAY;
        if (stage == GRID_CORNER) {
            w = weight;
            seen = ray_seen;
            column_w[cur + j] = seen ? w : -w;
            across = 0.0;
            next = GRID_NEXT_V;
        } else {
            // The bracket's lo end keeps the first (earlier) corner's state, the opposite of this one's.
            if (ray_seen != seen) {
                lo = mid;
            } else {
                hi = mid;
            }
            step += 1u;
            if (step == steps) {
                float edge = 0.5 * (lo + hi);
                if (stage == GRID_ALONG_V) {
                    column_up[cur + j - 1u] = edge;
                    next = GRID_NEXT_U;
                } else {
                    across = edge;
                    next = GRID_NEXT_SQUARE;
                }
            }
        }
        // A side that needs its crossing starts a bisection while the grid's allowance lasts.
        bool start = false;
        if (next == GRID_NEXT_V) {
            next = GRID_NEXT_U;
            if (disagrees(w, seen, j > 0u ? column_w[cur + j - 1u] : 0.0)) {
                if (left > 0u) {
                    stage = GRID_ALONG_V;
                    start = true;
                } else {
                    column_up[cur + j - 1u] = 0.5;
                }
            }
        }
        if (next == GRID_NEXT_U && !start) {
            next = GRID_NEXT_SQUARE;
            if (disagrees(w, seen, i > 0u ? column_w[prev + j] : 0.0)) {
                if (left > 0u) {
                    stage = GRID_ALONG_U;
                    start = true;
                } else {
                    across = 0.5;
                }
            }
        }
        if (start) {
            left -= 1u;
            next = GRID_NEXT_RAY;
            lo = 0.0;
            hi = 1.0;
            step = 0u;
        }
        bool corner_done = next == GRID_NEXT_SQUARE;
        if (corner_done) {
            if (i > 0u && j > 0u) {
                // The square with corners (i-1, j-1), (i, j-1), (i, j), (i-1, j), counter-clockwise in (u, v).
                vec4 signed_w = vec4(column_w[prev + j - 1u], column_w[cur + j - 1u], column_w[cur + j], column_w[prev + j]);
                vec4 ws = abs(signed_w);
                bvec4 seen4 = greaterThan(signed_w, vec4(0.0));
                if (all(greaterThan(ws, vec4(0.0)))) {
                    float mean = 0.25 * (ws.x + ws.y + ws.z + ws.w);
                    total += mean;
                    visible += mean * cell_visible_area(seen4, across_below, column_up[cur + j - 1u], across,
                                                        column_up[prev + j - 1u]);
                } else {
                    for (uint c = 0u; c < 4u; ++c) {
                        if (ws[c] > 0.0) {
                            total += 0.25 * ws[c];
                            if (seen4[c]) {
                                visible += 0.25 * ws[c];
                            }
                        }
                    }
                }
            }
            across_below = across;
            stage = GRID_CORNER;
            j += 1u;
            if (j > k) {
                j = 0u;
                i += 1u;
                across_below = 0.0;
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
