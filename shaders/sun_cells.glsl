// The sun's cells: the occluders binned across the sun's direction (gpu::sun_cells lays them out), so that a
// point's rays towards the sun test its cell's triangles only, and a point whose whole sun cone misses them all,
// or lies within one opaque triangle, casts none. Mirrors src/visibility/sun_cells.rs name for name; see it for
// the derivations (which triangles a cell must hold, the classification and its margin).
#ifndef SUNSHADE_SUN_CELLS_GLSL
#define SUNSHADE_SUN_CELLS_GLSL

#include "bindings.glsl"

// What a cell's triangles do to the sun's cone from a point (visibility::sun_cells::SunCone), and "no cells this
// frame" (the sun's rays then take occluded, the BVH's walk or the device's ray queries).
#define SUN_CONE_MISSES 0u
#define SUN_CONE_COVERED 1u
#define SUN_CONE_PARTIAL 2u
#define SUN_CONE_UNKNOWN 3u
// The margin on the classification's sines (SUN_CONE_MARGIN in the Rust): 2^-20.
#define SUN_CONE_MARGIN (1.0 / 1048576.0)
// sun_cell_of's answer for a point outside every cell.
#define NO_SUN_CELL 0xffffffffu
// The most triangles above a point that its cell may hold for the point's rays to use it (MAX_SUN_CELL_TRIANGLES),
// and for its classification (MAX_SUN_CELL_CLASSIFIED).
#define MAX_SUN_CELL_TRIANGLES 256u
#define MAX_SUN_CELL_CLASSIFIED 8192u

#ifdef SUNSHADE_SHADOW_RAYS
// Words an entry takes (gpu::sun_cells::ENTRY_WORDS): corners and top (c0, top), (c1, 0), (c2, 0) in f32, then its
// occluder record; the entries start at a multiple of four words (dims.z).
#define SUN_CELL_ENTRY_WORDS 16u
// Vec4 q (0 to 3) of entry i, as words (one texel) and as floats; word w of the starts.
#define SUN_CELL_UVEC4(i, q) SUN_CELLS_DATA(SUN_CELLS_DIMS.z / 4u + (SUN_CELL_ENTRY_WORDS / 4u) * (i) + (q))
#define SUN_CELL_VEC4(i, q) uintBitsToFloat(SUN_CELL_UVEC4(i, q))
#define SUN_CELL_RECORD(i) SUN_CELL_UVEC4(i, 3u)
#define SUN_CELL_START(c) SUN_CELLS_DATA((c) / 4u)[(c) % 4u]

// The cell whose triangles the sun rays from `origin` can meet, or NO_SUN_CELL outside every cell (nothing
// blocks the sun there).
uint sun_cell_of(vec3 origin) {
    vec2 at = (vec2(dot(origin, SUN_CELLS_U.xyz), dot(origin, SUN_CELLS_V.xyz)) - vec2(SUN_CELLS_U.w, SUN_CELLS_V.w))
            * SUN_CELLS_L.w;
    vec2 ij = floor(at);
    if (!(ij.x >= 0.0 && ij.y >= 0.0 && ij.x < float(SUN_CELLS_DIMS.x) && ij.y < float(SUN_CELLS_DIMS.y))) {
        return NO_SUN_CELL;
    }
    return uint(ij.x) + SUN_CELLS_DIMS.x * uint(ij.y);
}

// What the triangle (c0, c1, c2) does to the cone of half-angle asin(sin_sigma) about the unit l from `origin`, its
// rays of any length (no surface's horizon): SUN_CONE_MISSES, SUN_CONE_COVERED or SUN_CONE_PARTIAL; the edge
// planes' normals from the edge vectors, not from two long corner vectors (see the Rust). sun_triangle_class after
// its tangent plane; disk lights' cones use it too (disk_cone.glsl).
uint cone_triangle_class(vec3 origin, vec3 l, float sin_sigma, vec3 c0, vec3 c1, vec3 c2) {
    float limit = sin_sigma + SUN_CONE_MARGIN;
    vec3 normal = cross(c1 - c0, c2 - c0);
    float h = dot(normal, origin - c0);
    float n_l = dot(normal, l);
    if (h * n_l >= 0.0 && abs(n_l) > limit * length(normal)) {
        return SUN_CONE_MISSES;
    }
    vec3 e0 = c0 - origin;
    vec3 e1 = c1 - origin;
    vec3 e2 = c2 - origin;
    float triple = dot(e0, cross(e1, e2));
    if (triple == 0.0) {
        return SUN_CONE_PARTIAL;
    }
    float s = sign(triple);
    vec3 m0 = cross(e0, c1 - c0);
    vec3 m1 = cross(e1, c2 - c1);
    vec3 m2 = cross(e2, c0 - c2);
    vec3 lens = vec3(length(m0), length(m1), length(m2));
    if (any(equal(lens, vec3(0.0)))) {
        return SUN_CONE_PARTIAL;
    }
    vec3 c = s * vec3(dot(m0, l), dot(m1, l), dot(m2, l));
    if (any(lessThan(c, -limit * lens))) {
        return SUN_CONE_MISSES;
    }
    return all(greaterThan(c, limit * lens)) ? SUN_CONE_COVERED : SUN_CONE_PARTIAL;
}

// The same for the rays above the horizon of the surface's normal n: SUN_CONE_MISSES also where the triangle lies
// wholly below the tangent plane.
uint sun_triangle_class(vec3 origin, vec3 n, vec3 l, float sin_sigma, vec3 c0, vec3 c1, vec3 c2) {
    if (dot(n, c0 - origin) <= 0.0 && dot(n, c1 - origin) <= 0.0 && dot(n, c2 - origin) <= 0.0) {
        return SUN_CONE_MISSES;
    }
    return cone_triangle_class(origin, l, sin_sigma, c0, c1, c2);
}

// The entries of origin's cell whose tops lie above its depth along the sun (the only triangles its sun rays can
// meet), as [x, y): by bisection, the cell's tops being sorted highest first. Empty outside every cell.
uvec2 sun_cell_range(vec3 origin) {
    uint c = sun_cell_of(origin);
    if (c == NO_SUN_CELL) {
        return uvec2(0u);
    }
    float depth = dot(origin, SUN_CELLS_L.xyz);
    uint lo = SUN_CELL_START(c);
    uint hi = SUN_CELL_START(c + 1u);
    uint start = lo;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (SUN_CELL_VEC4(mid, 0u).w > depth) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return uvec2(start, lo);
}

// The shaded point's entries above it: sun_cell_range of its shadow rays' origin, found once a pixel by
// sun_cells_at before the functions below read it (they are only asked about that origin). The driver inlines
// every call, so a bisection in each of them would be compiled once a caller.
uvec2 sun_cell_range_here = uvec2(0u);

// Finds sun_cell_range_here for the shaded point's shadow-ray origin (sun_term, before any other of
// the sun's terms asks).
void sun_cells_at(vec3 origin) {
    if (VARIANT_SUN_CELLS != SUN_CELLS_NONE) {
        sun_cell_range_here = sun_cell_range(origin);
    }
}

// What the cell's triangles above `origin` do to the sun's cone (direction l, half-angle asin(sin_sigma)) from it
// on a surface of normal n: SUN_CONE_COVERED where one opaque triangle holds it (an alpha-masked one may let light
// through), MISSES where all miss its rays above the surface's horizon, PARTIAL otherwise; SUN_CONE_UNKNOWN where
// the frame has no cells, or where more than MAX_SUN_CELL_TRIANGLES lie above the point and its cone is neither
// proven clear nor covered (more than MAX_SUN_CELL_CLASSIFIED: not classified at all; VARIANT_SUN_CELLS).
uint sun_cone_class(vec3 origin, vec3 n, vec3 l, float sin_sigma) {
    if (VARIANT_SUN_CELLS == SUN_CELLS_NONE) {
        return SUN_CONE_UNKNOWN;
    }
    // The entries above the point (sun_cell_range_here): the scan's stop at the first at or below its depth then
    // never comes early.
    uvec2 range = sun_cell_range_here;
    if (VARIANT_SUN_CELLS == SUN_CELLS_PARTIAL && range.y - range.x > MAX_SUN_CELL_CLASSIFIED) {
        return SUN_CONE_UNKNOWN;
    }
    bool past_rays = VARIANT_SUN_CELLS == SUN_CELLS_PARTIAL && range.y - range.x > MAX_SUN_CELL_TRIANGLES;
    bool partial = false;
    float depth = dot(origin, SUN_CELLS_L.xyz);
    for (uint i = range.x; i < range.y; ++i) {
        vec4 c0_top = SUN_CELL_VEC4(i, 0u);
        if (c0_top.w <= depth) {
            break;
        }
        uint cls = sun_triangle_class(origin, n, l, sin_sigma, c0_top.xyz, SUN_CELL_VEC4(i, 1u).xyz,
                                      SUN_CELL_VEC4(i, 2u).xyz);
        bool opaque = VARIANT_OCCLUDERS_MASKED == 0u || material_kind_at(SUN_CELL_RECORD(i).w & 0x7fffffffu).z == 0u;
        if (cls == SUN_CONE_COVERED && opaque) {
            return SUN_CONE_COVERED;
        }
        partial = partial || cls != SUN_CONE_MISSES;
    }
    return partial ? (past_rays ? SUN_CONE_UNKNOWN : SUN_CONE_PARTIAL) : SUN_CONE_MISSES;
}

// The most triangles a penumbra's sun rays test from a list (sun_cone_list) rather than the cell's whole range: as
// many as a cell's range may hold for its rays (MAX_SUN_CELL_TRIANGLES), so that a point past its cell's bound
// whose cone meets at most this many tests them rather than walking the tree (on sunset.glb, where the low sun
// gives most penumbra pixels 65 to 256 such triangles above 257 to 1024 in their cells, a linear scan of the list
// is faster than the walk: docs/accuracy.md, "What the default shadows cost"). A kilobyte of private memory an
// invocation.
#define MAX_SUN_LISTED 256u
// The entries of the shaded point's cell that its sun cone does not provably miss, where sun_cone_list found at
// most MAX_SUN_LISTED (sun_listed_count of them; sun_listed_valid), for sun_cells_occluded.
uint sun_listed[MAX_SUN_LISTED];
uint sun_listed_count = 0u;
bool sun_listed_valid = false;

// The listed triangles binned over the sun cone's directions, so that each of a penumbra's rays tests only those
// whose directions from the point can hold it (sun_list_bins, sun_bin_of). A direction w of the cone is placed by
// its gnomonic coordinates about the cone's axis l, ((w.t, w.b) / w.l) / tan(sigma) in [-1, 1]^2, (t, b) a frame
// about l; a ray from the point meets a triangle only in a direction inside the triangle's gnomonic image, which
// lies within the box of its corners' images where every corner lies in front of the point along l (within 60
// degrees of l, so that the images stay within tan 60 and keep their digits). A triangle with a corner elsewhere
// is put in every bin. The boxes are grown by SUN_BIN_MARGIN, some thousand times what f32 loses in the images
// and in the watertight test's own answer near an edge: a triangle the test can find a ray's hit on is always in
// the ray's bin, so that the rays' answers are those of the whole list. Only where the cells are partial (a low
// sun, dense occluders: lists of tens to hundreds); elsewhere the lists are short and the bins' code would cost
// every pipeline's creation more than they save.
#define SUN_BINS_SIDE 4u
#define SUN_BIN_WORDS (MAX_SUN_LISTED / 32u)
#define SUN_BIN_MARGIN (1.0 / 4096.0)
uint sun_bins[SUN_BINS_SIDE * SUN_BINS_SIDE * SUN_BIN_WORDS];
// The cone's axis and frame, and 1 / tan(sigma); sun_bins_valid false where the list is not binned (a delta sun).
vec3 sun_bin_axes[3];
float sun_bin_scale = 0.0;
bool sun_bins_valid = false;

// A direction's bin, or SUN_BINS_SIDE^2 outside the binned square (the ray then tests the whole list).
uint sun_bin_of(vec3 direction) {
    float along = dot(direction, sun_bin_axes[0]);
    vec2 g = vec2(dot(direction, sun_bin_axes[1]), dot(direction, sun_bin_axes[2])) / along * sun_bin_scale;
    vec2 cell = floor((g + 1.0) * (0.5 * float(SUN_BINS_SIDE)));
    bool inside = along > 0.0 && all(greaterThanEqual(cell, vec2(0.0)))
                  && all(lessThan(cell, vec2(float(SUN_BINS_SIDE))));
    return inside ? uint(cell.x) + SUN_BINS_SIDE * uint(cell.y) : SUN_BINS_SIDE * SUN_BINS_SIDE;
}

// Bins the listed triangles over the cone of half-angle asin(sin_sigma) about l from origin (see sun_bins).
void sun_list_bins(vec3 origin, vec3 l, float sin_sigma) {
    float tan_sigma = sin_sigma / sqrt(max(1.0 - sin_sigma * sin_sigma, 0.0));
    sun_bins_valid = tan_sigma > 0.0;
    if (!sun_bins_valid) {
        return;
    }
    vec3 t = orthonormal_to(l);
    sun_bin_axes = vec3[3](l, t, cross(l, t));
    sun_bin_scale = 1.0 / tan_sigma;
    for (uint w = 0u; w < SUN_BINS_SIDE * SUN_BINS_SIDE * SUN_BIN_WORDS; ++w) {
        sun_bins[w] = 0u;
    }
    for (uint e = 0u; e < sun_listed_count; ++e) {
        uint i = sun_listed[e];
        vec2 lo = vec2(1e30);
        vec2 hi = vec2(-1e30);
        bool in_front = true;
        for (uint q = 0u; q < 3u; ++q) {
            vec3 c = SUN_CELL_VEC4(i, q).xyz - origin;
            float along = dot(c, l);
            in_front = in_front && along > 0.5 * length(c);
            vec2 g = vec2(dot(c, sun_bin_axes[1]), dot(c, sun_bin_axes[2])) / along * sun_bin_scale;
            lo = min(lo, g);
            hi = max(hi, g);
        }
        // Bins [first, last] along each axis, every bin where a corner is not in front.
        float side = float(SUN_BINS_SIDE);
        vec2 first = in_front ? floor((lo - SUN_BIN_MARGIN * sun_bin_scale + 1.0) * (0.5 * side)) : vec2(0.0);
        vec2 last = in_front ? floor((hi + SUN_BIN_MARGIN * sun_bin_scale + 1.0) * (0.5 * side)) : vec2(side - 1.0);
        uvec2 a = uvec2(clamp(first, vec2(0.0), vec2(side - 1.0)));
        uvec2 b = uvec2(clamp(last, vec2(0.0), vec2(side - 1.0)));
        bool overlaps = all(lessThanEqual(first, vec2(side - 1.0))) && all(greaterThanEqual(last, vec2(0.0)));
        for (uint y = a.y; overlaps && y <= b.y; ++y) {
            for (uint x = a.x; x <= b.x; ++x) {
                sun_bins[(x + SUN_BINS_SIDE * y) * SUN_BIN_WORDS + e / 32u] |= 1u << (e % 32u);
            }
        }
    }
}

// Lists the entries of origin's cell above it whose triangles the cone of half-angle asin(sin_sigma) about l does
// not provably miss above the horizon of the surface's normal n (sun_triangle_class): the only triangles a ray of
// the cone leaving above that horizon can meet, so that a penumbra's rays (its grid's, its lobe's) test them alone,
// with the same answers as the whole range (sun_cells_occluded; a ray leaving below takes the whole range). Leaves
// sun_listed_valid false where they are more than MAX_SUN_LISTED.
void sun_cone_list(vec3 origin, vec3 n, vec3 l, float sin_sigma) {
    uvec2 range = sun_cell_range_here;
    uint count = 0u;
    bool fits = true;
    for (uint i = range.x; i < range.y && fits; ++i) {
        uint cls = sun_triangle_class(origin, n, l, sin_sigma, SUN_CELL_VEC4(i, 0u).xyz, SUN_CELL_VEC4(i, 1u).xyz,
                                      SUN_CELL_VEC4(i, 2u).xyz);
        if (cls != SUN_CONE_MISSES) {
            fits = count < MAX_SUN_LISTED;
            if (fits) {
                sun_listed[count] = i;
                count += 1u;
            }
        }
    }
    sun_listed_count = count;
    sun_listed_valid = fits;
    sun_bins_valid = false;
    if (fits && VARIANT_SUN_CELLS == SUN_CELLS_PARTIAL) {
        sun_list_bins(origin, l, sin_sigma);
    }
}

// Whether the frame has cells and the triangles of `origin`'s cell above it are few enough to classify (at most
// MAX_SUN_CELL_CLASSIFIED), as sun_cone_class does before it answers SUN_CONE_UNKNOWN.
bool sun_cells_classify(vec3 origin) {
    if (VARIANT_SUN_CELLS == SUN_CELLS_NONE) {
        return false;
    }
    uvec2 range = sun_cell_range_here;
    return range.y - range.x <= MAX_SUN_CELL_CLASSIFIED;
}

// Whether the frame has cells and the sun rays from `origin` can be tested against its cell: at most
// MAX_SUN_CELL_TRIANGLES of its triangles lie above it.
bool sun_cells_usable(vec3 origin) {
    if (VARIANT_SUN_CELLS != SUN_CELLS_PARTIAL) {
        return VARIANT_SUN_CELLS == SUN_CELLS_COMPLETE;
    }
    uvec2 range = sun_cell_range_here;
    return range.y - range.x <= MAX_SUN_CELL_TRIANGLES;
}

// Whether the ray from `origin` (on a surface of normal n) along `direction` (within the sun's cone) meets a
// triangle of its cell that blocks it (occluders.glsl's blocks): the cell's triangles above the origin are every
// one such a ray can meet; a ray leaving above the tangent plane skips those wholly below it, and tests only the
// listed ones where sun_cone_list listed them for this point. Only where sun_cells_usable or listed.
bool sun_cells_occluded(vec3 origin, vec3 n, vec3 direction) {
    if (direction == vec3(0.0) || any(isinf(direction)) || any(isnan(direction))) {
        return false;
    }
    // The listed entries where sun_cone_list listed them for this point and the ray leaves above its horizon,
    // else the cell's whole range above it.
    WatertightRay r = watertight_ray(origin, direction);
    bool leaves_above = dot(n, direction) > 0.0;
    bool listed = sun_listed_valid && leaves_above;
    uvec2 range = listed ? uvec2(0u, sun_listed_count) : sun_cell_range_here;
    if (VARIANT_SUN_CELLS == SUN_CELLS_PARTIAL && range.y - range.x > MAX_SUN_CELL_TRIANGLES) {
        // A point past its cell's bound whose list serves only the rays above its horizon: this one takes the
        // traversal, as all its rays would without the list.
        return occluded(origin, direction, RAY_T_INFINITE);
    }
    // Where the list is binned, the entries of the ray's bin alone (sun_bins): each set bit of its words, in order.
    bool use_bins = VARIANT_SUN_CELLS == SUN_CELLS_PARTIAL && listed && sun_bins_valid;
    uint bin = use_bins ? sun_bin_of(direction) : SUN_BINS_SIDE * SUN_BINS_SIDE;
    bool binned = bin < SUN_BINS_SIDE * SUN_BINS_SIDE;
    uint words = (range.y + 31u) / 32u;
    uint word = 0u;
    uint bits = binned ? sun_bins[bin * SUN_BIN_WORDS] : 0u;
    uint e = range.x;
    while (true) {
        uint i = 0u;
        if (binned) {
            while (bits == 0u && word + 1u < words) {
                word += 1u;
                bits = sun_bins[bin * SUN_BIN_WORDS + word];
            }
            if (bits == 0u) {
                break;
            }
            uint j = uint(findLSB(bits));
            bits &= bits - 1u;
            i = sun_listed[32u * word + j];
        } else {
            if (e >= range.y) {
                break;
            }
            i = listed ? sun_listed[e] : e;
            e += 1u;
        }
        vec3 c0 = SUN_CELL_VEC4(i, 0u).xyz;
        vec3 c1 = SUN_CELL_VEC4(i, 1u).xyz;
        vec3 c2 = SUN_CELL_VEC4(i, 2u).xyz;
        bool below = leaves_above && dot(n, c0 - origin) <= 0.0 && dot(n, c1 - origin) <= 0.0
                     && dot(n, c2 - origin) <= 0.0;
        vec2 bary;
        if (!below && intersect(r, c0, c1, c2, RAY_T_INFINITE, bary) && blocks(SUN_CELL_RECORD(i), bary)) {
            return true;
        }
    }
    return false;
}
#endif

// sun_cells_usable and sun_cells_occluded where the module has shadow rays.
#ifdef SUNSHADE_SHADOW_RAYS
#define SUN_CELLS_USABLE(origin) (sun_listed_valid || sun_cells_usable(origin))
#define SUN_CELLS_OCCLUDED(origin, n, direction) sun_cells_occluded(origin, n, direction)
#else
#define SUN_CELLS_USABLE(origin) false
#define SUN_CELLS_OCCLUDED(origin, n, direction) false
#endif

// Whether every shadow ray of this pipeline goes to the sun through its cells (complete cells, no disk light, no
// sky): the callers of occluded then test it first, so that the specialized shader holds no traversal at all.
const bool ONLY_SUN_CELL_RAYS = VARIANT_SUN_CELLS == SUN_CELLS_COMPLETE && VARIANT_DISKS == LIGHT_ABSENT
                                && VARIANT_SKY == LIGHT_ABSENT;

// Whether the sun's ray from `origin` (on a surface of normal n) along `direction` (within its cone: a delta
// sun's) gets through: by the cells where the frame has them and the point is within their bound, else by
// occluded.
bool sun_visible_along(vec3 origin, vec3 n, vec3 direction) {
    if (SUN_CELLS_USABLE(origin)) {
        return !SUN_CELLS_OCCLUDED(origin, n, direction);
    }
    return visible_along(origin, direction);
}

#endif
