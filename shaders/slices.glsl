// The lights' visible fractions by slices, in the modules with shadow rays built for them (SUNSHADE_SLICES: the
// shader walks the occluders' BVH for them, with ray queries or without). Mirrors src/shading/sun_slices.rs and
// disk_slices.rs (the rule: half-planes through an axis across the light, rows along psi = mid - half cos u, each
// row's chord of the light cut by the surface's horizon and by the intervals that the triangles in its plane block, a
// disk light's segments first clipped to where its rays end; the visible weight closed-form), sky_slices.rs
// (segments, pseudo-angles), slices_about_centre.rs (the chords measured by gamma = beta - pi/2, which keeps f32's
// digits on the sun's chord within 0.0046 rad of beta = pi/2; see its text) and visibility/bvh.rs (within_reach,
// sphere_meets_cone).
//
// One walk a pixel and light gathers the triangles within its reach (above the surface's horizon, in front, in
// the light's cone, before a disk light's near side) into a local array of MAX_SLICE_TRIANGLES; every row then
// cuts those whose row range holds it. Where the walk finds an alpha-masked triangle (which slices cannot cut),
// the fraction is SLICES_UNSLICEABLE and the caller casts the grid's rays instead, as the reference does; where
// it finds more triangles than the array keeps, the same, and the image is refused (gpu::slice_gather).
//
// llvmpipe's loop budget (gpu::loop_budget: 65535 iterations a fragment, every loop together) shapes the rows'
// work. A penumbra's pixel behind a tessellated sphere's limb gathers 100 to 200 triangles, and a row cuts some
// fifty of them within the sun's chord; the Rust sorts each row's intervals, which here would cost about m^2/4
// iterations for m intervals. So (measured on sunset.glb at 96 x 72, Mesa 22.3.6): the triangles are ordered once
// by where they lie along the chords; each row cuts them four an iteration (the loop's body written out four
// times) and merges its intervals as they come into at most UNION_PIECES sorted disjoint pieces, steps written out
// (no loop), sorting only the intervals that would have made more pieces, with the pieces. Then 4 k^2 rows fit the
// budget up to k = 13 there (676 rows; 1444 cut 4 pixels short, which the renderer refuses), where sorting every
// row's intervals stopped at 64 rows. docs/platform.md has the measurements.
#ifndef SUNSHADE_SLICES_GLSL
#define SUNSHADE_SLICES_GLSL

#include "math.glsl"
#include "occluders.glsl"

// sky_slices::SLICE_AXIS.
#define SLICE_AXIS vec3(0.33232518133916444, 0.8023039599071088, 0.4958511165312262)
// The most triangles one pixel's slices of a light gather (gpu::slice_gather: a pixel whose cone holds more sets
// slices_overflowed, and the renderer refuses the image).
#define MAX_SLICE_TRIANGLES 1024
// What a fraction the slices cannot give reads.
#define SLICES_UNSLICEABLE -1.0

// The gathered triangles' corners relative to the rays' origin [m], three a triangle, and one row's blocked
// intervals (pseudo-angles).
vec3 slice_corners[3 * MAX_SLICE_TRIANGLES];
vec2 slice_blocked[MAX_SLICE_TRIANGLES];

// The slices' axis for the sun in direction l: SLICE_AXIS made perpendicular to l (x's where l is nearly along it).
vec3 sun_slice_axis(vec3 l) {
    vec3 c = SLICE_AXIS - dot(SLICE_AXIS, l) * l;
    if (dot(c, c) > 1e-6) {
        return normalize(c);
    }
    return normalize(vec3(1.0, 0.0, 0.0) - l.x * l);
}

// The chord's half-width chi at psi: sin^2(chi/2) = sin((sigma + psi)/2) sin((sigma - psi)/2) / cos psi, then
// chi = 2 asin (as an atan2: lavapipe's asin loses 4e-4).
float chord_half_width(float sigma, float psi) {
    float s2 = sin(0.5 * (sigma + psi)) * sin(0.5 * (sigma - psi)) / cos(psi);
    float x = sqrt(max(s2, 0.0));
    return 2.0 * atan2_accurate(x, sqrt(max(1.0 - x * x, 0.0)));
}

// Row i of `rows` at the midpoint u = pi (i + 1/2) / rows: (sin u, cos u).
vec2 cosine_row(uint i, uint rows) {
    float u = PI * (float(i) + 0.5) / float(rows);
    return vec2(sin(u), cos(u));
}

// The pseudo-angle -s / (|s| + t) of the direction (s, t), t >= 0: monotone in beta, 0 at gamma = 0.
float pseudo_angle(float s, float t) {
    return -s / (abs(s) + t);
}

// gamma of a pseudo-angle: atan2(k, 1 - |k|).
float gamma_of(float k) {
    return atan2_accurate(k, max(1.0 - abs(k), 0.0));
}

// The pseudo-angle of gamma: that of (-sin gamma, cos gamma).
float pseudo_angle_of_gamma(float g) {
    return pseudo_angle(-sin(g), cos(g));
}

// The interval of gamma in [-pi/2, pi/2] where n.omega >= 0 (slices_about_centre::above_about_centre).
vec2 above_about_centre(float n_c, float n_p) {
    if (n_c > 0.0) {
        return vec2(-0.5 * PI, atan2_accurate(n_p, n_c));
    }
    if (n_c < 0.0) {
        return vec2(atan2_accurate(-n_p, -n_c), 0.5 * PI);
    }
    return n_p >= 0.0 ? vec2(-0.5 * PI, 0.5 * PI) : vec2(0.5 * PI, -0.5 * PI);
}

// The integral over [g0, g1] of (n_p cos gamma - n_c sin gamma) cos gamma: no cancellation on a short interval.
float weight_integral_about_centre(float n_c, float n_p, float g0, float g1) {
    if (g1 <= g0) {
        return 0.0;
    }
    float d = g1 - g0;
    float s = g0 + g1;
    return 0.5 * n_p * (d + sin(d) * cos(s)) - 0.5 * n_c * sin(d) * sin(s);
}

// One edge j -> k of slice_segment: the corner j where it lies in the plane, the edge's crossing where it
// crosses, interpolated from the corner below the plane whichever way the edge runs, so that two triangles
// sharing the edge (running it in opposite directions) find bitwise the same point: their intervals then touch
// exactly and merge, where rounding would leave an ulp's gap between them (a piece more in the row's union).
#define SLICE_EDGE(dj, dk, xj, xk) \
    if (dj == 0.0) { \
        points[n] = vec2(dot(xj, c), dot(xj, p)); \
        n += 1u; \
    } \
    if ((dj < 0.0 && dk > 0.0) || (dj > 0.0 && dk < 0.0)) { \
        vec3 below = dj < 0.0 ? (xj) : (xk); \
        vec3 above_ = dj < 0.0 ? (xk) : (xj); \
        float d_below = min(dj, dk); \
        vec3 x = below + (d_below / (d_below - max(dj, dk))) * (above_ - below); \
        points[n] = vec2(dot(x, c), dot(x, p)); \
        n += 1u; \
    }

// The segment in which the plane through the origin of unit normal m cuts the triangle (a, b, d) (corners
// relative to the origin [m]), in the plane's coordinates (s, t) = (x.c, x.p): false where it misses it, touches
// a corner or holds it. The three edges written out (a loop would spend llvmpipe's budget).
bool slice_segment(vec3 a, vec3 b, vec3 d, vec3 c, vec3 p, vec3 m, out vec2 e0, out vec2 e1) {
    float da = dot(a, m);
    float db = dot(b, m);
    float dd = dot(d, m);
    vec2 points[3];
    uint n = 0u;
    SLICE_EDGE(da, db, a, b)
    SLICE_EDGE(db, dd, b, d)
    SLICE_EDGE(dd, da, d, a)
    e0 = points[0];
    e1 = points[1];
    return n == 2u;
}

// The interval of pseudo-angles that the segment (e0, e1) of the half-plane t >= 0 blocks, clipped to t >= 0;
// false where nothing of it lies there or it passes through the origin.
bool segment_interval(vec2 e0, vec2 e1, out vec2 interval) {
    interval = vec2(0.0);
    if (e0.y < 0.0 && e1.y < 0.0) {
        return false;
    }
    if (e0.y < 0.0) {
        e0 = vec2(e0.x + (e1.x - e0.x) * (-e0.y / (e1.y - e0.y)), 0.0);
    } else if (e1.y < 0.0) {
        e1 = vec2(e1.x + (e0.x - e1.x) * (-e1.y / (e0.y - e1.y)), 0.0);
    }
    float cross_ = e0.x * e1.y - e1.x * e0.y;
    if (e0 == vec2(0.0) || e1 == vec2(0.0) || (cross_ == 0.0 && dot(e0, e1) < 0.0)) {
        return false;
    }
    float k0 = pseudo_angle(e0.x, e0.y);
    float k1 = pseudo_angle(e1.x, e1.y);
    interval = vec2(min(k0, k1), max(k0, k1));
    return true;
}

// The weight over span (gamma) less the union of the row's `count` blocked intervals (slice_blocked, sorted here
// by their starts: an insertion sort, a row holding a few), by the gaps between them.
float visible_weight_about_centre(float n_c, float n_p, vec2 span, uint count) {
    for (uint i = 1u; i < count; ++i) {
        vec2 x = slice_blocked[i];
        uint j = i;
        while (j > 0u && slice_blocked[j - 1u].x > x.x) {
            slice_blocked[j] = slice_blocked[j - 1u];
            j -= 1u;
        }
        slice_blocked[j] = x;
    }
    float key_lo = pseudo_angle_of_gamma(span.x);
    float key_hi = pseudo_angle_of_gamma(span.y);
    float visible = 0.0;
    float reached = key_lo;
    float at_reached = span.x;
    for (uint i = 0u; i < count; ++i) {
        vec2 b = slice_blocked[i];
        if (b.x >= key_hi) {
            break;
        }
        if (b.x > reached) {
            visible += weight_integral_about_centre(n_c, n_p, at_reached, gamma_of(b.x));
        }
        if (b.y > reached) {
            reached = b.y;
            at_reached = gamma_of(b.y);
        }
    }
    if (reached < key_hi) {
        visible += weight_integral_about_centre(n_c, n_p, at_reached, span.y);
    }
    return visible;
}

// Whether a sphere (centre relative to the apex [m], radius [m]) may meet the cone of unit axis `axis` and
// half-angle of cosine cos_a and sine sin_a: its angular radius added to the cone's, a slack of 1e-5 of the
// distance for f32's rounding (the Rust's is 1e-9).
bool sphere_meets_cone(vec3 centre, float r, vec3 axis, float cos_a, float sin_a) {
    float dist = length(centre);
    if (dist <= r) {
        return true;
    }
    float sin_p = r / dist;
    float cos_p = sqrt(max(1.0 - sin_p * sin_p, 0.0));
    float sin_t = sin_a * cos_p + cos_a * sin_p;
    float cos_t = cos_a * cos_p - sin_a * sin_p;
    float along = dot(centre, axis);
    float across = length(cross(centre, axis));
    float slack = 1e-5 * dist;
    return cos_t > 0.0 ? (along > -slack && across <= sin_t * dist + slack) : along >= cos_t * dist - slack;
}

// What a point's slices can reach (the Rust's SliceReach): above the surface (n) and in front towards the light
// (h), within the cone about h of cosine cos_a and sine sin_a (none where cos_a <= -1), and beyond the plane
// beyond_k.x = beyond_b (none where beyond_k = 0, beyond_b < 0): a disk light's near side, where its rays end.
struct SliceReach {
    vec3 origin;
    vec3 n;
    vec3 h;
    float cos_a;
    float sin_a;
    vec3 beyond_k;
    float beyond_b;
};

// Whether a node's box may reach what the slices reach: the box's centre's signed distance plus its half-extent
// projected on each normal above the plane, within a slack of 1e-5 of the box's size and distance (f32's rounding;
// the boxes are padded too), and its bounding sphere meeting the cone.
bool within_reach(BvhNode node, SliceReach r) {
    vec3 centre = 0.5 * (node.lo + node.hi) - r.origin;
    vec3 half_extent = 0.5 * (node.hi - node.lo);
    float slack = 1e-5 * (length(centre) + length(half_extent));
    return dot(centre, r.n) + dot(half_extent, abs(r.n)) > -slack
        && dot(centre, r.h) + dot(half_extent, abs(r.h)) > -slack
        && dot(centre, r.beyond_k) + dot(half_extent, abs(r.beyond_k)) > r.beyond_b - slack
        && (r.cos_a <= -1.0 || sphere_meets_cone(centre, length(half_extent), r.h, r.cos_a, r.sin_a));
}

// A leaf's triangle into the gathered ones where a corner lies above the surface, one in front and one beyond (the
// same tests, exact, on its corners; a disk light's `before`); count -1 where it is alpha-masked (the reference's
// slices too take the grid there), or the array is full (slices_overflowed set: the image is refused).
#define GATHER_LEAF(leaf) \
    { \
        uvec4 tri = WALK_RECORD((leaf).first); \
        if (material_kind_at(tri.w & 0x7fffffffu).z != 0u) { \
            return -1; \
        } \
        if (count >= MAX_SLICE_TRIANGLES) { \
            slices_overflowed = true; \
            return -1; \
        } \
        vec3 a = OCCLUDER_CORNER(tri.x) - r.origin; \
        vec3 b = OCCLUDER_CORNER(tri.y) - r.origin; \
        vec3 d = OCCLUDER_CORNER(tri.z) - r.origin; \
        if (max(max(dot(a, r.n), dot(b, r.n)), dot(d, r.n)) > 0.0 \
            && max(max(dot(a, r.h), dot(b, r.h)), dot(d, r.h)) > 0.0 \
            && max(max(dot(a, r.beyond_k), dot(b, r.beyond_k)), dot(d, r.beyond_k)) > r.beyond_b) { \
            slice_corners[3 * count] = a; \
            slice_corners[3 * count + 1] = b; \
            slice_corners[3 * count + 2] = d; \
            count += 1; \
        } \
    }
#define GATHER_CHILD(ch) \
    { \
        BvhNode child = bvh_node(ch); \
        if (within_reach(child, r)) { \
            if (child.count == 0u) { \
                stack[top] = (ch); \
                top += 1u; \
            } else GATHER_LEAF(child) \
        } \
    }

// The triangles of one walk within reach into slice_corners: their count, or -1 (module text). A node taken from
// the stack is one iteration of the budget, as in any_hit.
int gather(SliceReach r) {
    int count = 0;
    BvhNode root = bvh_node(0u);
    if (!within_reach(root, r)) {
        return 0;
    }
    if (root.count > 0u) {
        GATHER_LEAF(root)
        return count;
    }
    BVH_WALK(GATHER_CHILD)
    return count;
}

// Row i's u = pi (i + 1/2) / rows as a real index, u rows / pi - 1/2, of the direction psi of the rows
// psi = -sigma cos u (clamped to the rows' range): cos u = -psi / sigma, u = acos as an atan2.
float row_of_psi(float psi, float sigma, uint rows) {
    float x = clamp(-psi / sigma, -1.0, 1.0);
    return atan2_accurate(sqrt(max(1.0 - x * x, 0.0)), x) * float(rows) / PI - 0.5;
}

// The rows (psi = mid - half cos u in the frame (h, q) across the axis c) whose half-plane may cut the triangle
// (a, b, d) (corners relative to the origin [m]), as (first, last): the triangle's azimuth range about the axis,
// psi = atan(x.q / x.h) over its corners, where every corner lies in front (x.h > 0: its projection along c then
// lies in the half-plane x.h > 0, whose azimuths from the origin form an interval); every row otherwise. Widened by
// a row on each side (floor, ceil) for rounding; an empty range (first > last) where the triangle lies wholly to
// one side of the rows. (The reference files the triangles under rows by their diamond-angle arcs, slice_buckets;
// the rows found are the same but at the ends.)
uvec2 slice_row_range(vec3 a, vec3 b, vec3 d, vec3 h, vec3 q, vec2 mid_half, uint rows) {
    vec3 along = vec3(dot(a, h), dot(b, h), dot(d, h));
    if (min(min(along.x, along.y), along.z) <= 0.0) {
        return uvec2(0u, rows - 1u);
    }
    vec3 tau = vec3(dot(a, q), dot(b, q), dot(d, q)) / along;
    float psi_lo = atan2_accurate(min(min(tau.x, tau.y), tau.z), 1.0) - mid_half.x;
    float psi_hi = atan2_accurate(max(max(tau.x, tau.y), tau.z), 1.0) - mid_half.x;
    if (psi_lo > mid_half.y || psi_hi < -mid_half.y) {
        return uvec2(1u, 0u);
    }
    float lo = floor(row_of_psi(psi_lo, mid_half.y, rows));
    float hi = ceil(row_of_psi(psi_hi, mid_half.y, rows));
    return uvec2(uint(clamp(lo, 0.0, float(rows - 1u))), uint(clamp(hi, 0.0, float(rows - 1u))));
}

// The gathered triangles' row ranges and keys along the chords, and the order of those with rows by key.
uvec2 slice_ranges[MAX_SLICE_TRIANGLES];
float slice_keys[MAX_SLICE_TRIANGLES];
uint slice_order[MAX_SLICE_TRIANGLES];

// A row's blocked intervals as they come, merged into at most UNION_PIECES disjoint pieces sorted by start
// (`union_piece`); an interval that would make one piece too many is set aside (slice_blocked, `spilled` of
// them), and the row's walk then takes the pieces and those together, sorted (visible_weight_about_centre: the
// same union). Eight steps written out, no loop: llvmpipe's budget pays nothing for them, where a sort pays about
// m^2/4 for m intervals (a penumbra's row through a tessellated sphere's limb holds some fifty, their union one
// or two pieces, but arriving out of order they make more on the way: with four pieces, most rows there spilled).
#define UNION_PIECES 8u
#define UNION_STEP(k) \
    if (k < pieces) { \
        vec2 piece = union_piece[k]; \
        if (piece.y < cur.x) { \
            merged[merged_count] = piece; \
            merged_count += 1u; \
        } else if (piece.x > cur.y) { \
            if (!placed) { \
                merged[merged_count] = cur; \
                merged_count += 1u; \
                placed = true; \
            } \
            merged[merged_count] = piece; \
            merged_count += 1u; \
        } else { \
            cur = vec2(min(cur.x, piece.x), max(cur.y, piece.y)); \
        } \
    }
#define UNION_INSERT(interval) \
    { \
        vec2 cur = interval; \
        vec2 merged[UNION_PIECES + 1u]; \
        uint merged_count = 0u; \
        bool placed = false; \
        UNION_STEP(0u) \
        UNION_STEP(1u) \
        UNION_STEP(2u) \
        UNION_STEP(3u) \
        UNION_STEP(4u) \
        UNION_STEP(5u) \
        UNION_STEP(6u) \
        UNION_STEP(7u) \
        if (!placed) { \
            merged[merged_count] = cur; \
            merged_count += 1u; \
        } \
        if (merged_count > UNION_PIECES) { \
            slice_blocked[spilled] = interval; \
            spilled += 1u; \
        } else { \
            union_piece[0] = merged[0]; \
            union_piece[1] = merged[1]; \
            union_piece[2] = merged[2]; \
            union_piece[3] = merged[3]; \
            union_piece[4] = merged[4]; \
            union_piece[5] = merged[5]; \
            union_piece[6] = merged[6]; \
            union_piece[7] = merged[7]; \
            pieces = merged_count; \
        } \
    }


// The interval [psi0, psi1] of slices that meet the disk (disk_slices::psi_range): the roots in t = tan psi of
// A + 2 B t + C t^2, A = R^2 ((q.d)^2 - 1), B = -R^2 (q.d)(D.d), C = |D|^2 - R^2 (1 - (D.d)^2), the second from
// the product A/C; false where C <= 0 (the origin within the disk's own reach).
bool psi_range(float dist, float radius, float q_d, float dhat_d, out vec2 range) {
    float r2 = radius * radius;
    float a = r2 * (q_d * q_d - 1.0);
    float b = -r2 * q_d * dhat_d;
    float c = dist * dist - r2 * (1.0 - dhat_d * dhat_d);
    range = vec2(0.0);
    if (c <= 0.0) {
        return false;
    }
    float disc = max(b * b - a * c, 0.0);
    float t1 = (-b - (b < 0.0 ? -1.0 : 1.0) * sqrt(disc)) / c;
    float t2 = t1 != 0.0 ? a / (c * t1) : -2.0 * b / c;
    range = vec2(atan2_accurate(min(t1, t2), 1.0), atan2_accurate(max(t1, t2), 1.0));
    return true;
}

// The chord in which the plane through the origin of unit normal m cuts the disk (centre D relative to the origin
// [m], unit direction d, radius [m]): its ends relative to the origin; false where it misses it or the disk lies
// in the plane (disk_slices::chord).
bool chord(vec3 d_vec, vec3 d, float radius, vec3 m, out vec3 y0, out vec3 y1) {
    y0 = vec3(0.0);
    y1 = vec3(0.0);
    float d_m = dot(d, m);
    float across = 1.0 - d_m * d_m;
    if (across <= 0.0) {
        return false;
    }
    float dm = dot(d_vec, m);
    vec3 foot = d_vec + (-dm / across) * (m - d_m * d);
    float half2 = radius * radius - dm * dm / across;
    if (half2 <= 0.0) {
        return false;
    }
    vec3 along = normalize(cross(m, d));
    float half_chord = sqrt(half2);
    y0 = foot - half_chord * along;
    y1 = foot + half_chord * along;
    return true;
}

// The triangle at `w` of the order, cut by row i's plane where its row range holds the row (for a disk light,
// the segment first clipped to the chord line's near side, `line`): its interval kept where it meets the span,
// into the union; `hidden` once the union covers the span (an umbra's rows, mostly).
#define SLICE_TRIANGLE(w) \
    if (!hidden && (w) < count) { \
        uint j = slice_order[w]; \
        vec2 e0; \
        vec2 e1; \
        vec2 interval; \
        if (slice_ranges[j].x <= i && slice_ranges[j].y >= i \
            && slice_segment(slice_corners[3u * j], slice_corners[3u * j + 1u], slice_corners[3u * j + 2u], c, p, m, \
                             e0, e1) \
            && (!disk || clip_segment(e0, e1, line.xy, line.z)) && segment_interval(e0, e1, interval) \
            && interval.y > key_lo && interval.x < key_hi) { \
            UNION_INSERT(interval) \
            hidden = pieces == 1u && union_piece[0].x <= key_lo && union_piece[0].y >= key_hi; \
        } \
    }

// A row's visible weight once its union is built (sky_slices::row_visible_weight): `whole` where nothing blocks
// it, else `jacobian` times the weight over span (gamma) less the union of its `pieces` pieces and the `spilled`
// intervals set aside in slice_blocked (sorted there with the pieces after them; alone, the sort moves nothing).
float row_visible_weight(float n_c, float n_p, vec2 span, vec2 union_piece[UNION_PIECES], uint pieces, uint spilled,
                         float whole, float jacobian) {
    uint blocked = spilled + pieces;
    for (uint k = 0u; k < UNION_PIECES; ++k) {
        if (k < pieces) {
            slice_blocked[spilled + k] = union_piece[k];
        }
    }
    return blocked == 0u ? whole : jacobian * visible_weight_about_centre(n_c, n_p, span, blocked);
}

// A row's union, empty, for UNION_INSERT and the row's triangles to fill: its span's ends as pseudo-angles (key_lo,
// key_hi), its pieces, the intervals set aside (spilled), and whether it hides the span (hidden).
#define ROW_UNION_BEGIN(span) \
    float key_lo = pseudo_angle_of_gamma((span).x); \
    float key_hi = pseudo_angle_of_gamma((span).y); \
    uint pieces = 0u; \
    vec2 union_piece[UNION_PIECES]; \
    uint spilled = 0u; \
    bool hidden = false;

// The part of the segment (e0, e1) where a.(s, t) < b, if any (a and b of a line of the slice's plane).
bool clip_segment(inout vec2 e0, inout vec2 e1, vec2 a, float b) {
    float f0 = dot(a, e0) - b;
    float f1 = dot(a, e1) - b;
    if (f0 >= 0.0 && f1 >= 0.0) {
        return false;
    }
    if (f0 < 0.0 && f1 < 0.0) {
        return true;
    }
    vec2 cut = e0 + (f0 / (f0 - f1)) * (e1 - e0);
    if (f0 < 0.0) {
        e1 = cut;
    } else {
        e0 = cut;
    }
    return true;
}

// The rows first .. first + rows_taken - 1 of a light's `rows`, the part the sun's and disk lights' slices share
// (sky_slices::sliced_rows_weights): one walk within reach gathers the triangles; they are filed under their rows'
// ranges and ordered along the chords; the rows psi = mid - half cos u about the axis c, in the frame (h, q), each
// give their chord's span (the sun's: +-chi about its middle, `sigma` its half-angle; a disk light's, `disk`: its
// chord (D, d, radius) seen from the origin, with the chord line that clips the segments to where the rays end),
// cut by the surface's horizon, and its visible weight: (visible, whole) summed over the rows taken. (0, 0) at once
// where the walk gathers nothing that any row may cut: every row clear, in every pass (the fraction is 1,
// rows_fraction); (SLICES_UNSLICEABLE, 0) where the walk cannot gather.
vec2 sliced_rows_weights(SliceReach r, vec3 c, vec3 q, vec2 mid_half, uint rows, uint first, uint rows_taken,
                         bool disk, vec3 d_vec, vec3 d, float radius, float sigma) {
    vec3 n = r.n;
    vec3 h = r.h;
    int gathered = gather(r);
    if (gathered < 0) {
        return vec2(SLICES_UNSLICEABLE, 0.0);
    }
    // The triangles that some row taken may cut, first ordered by where their centroids lie along the chords (the
    // pseudo-angle about the axis, seen along h; Shell's sort, Ciura's gaps: about count^1.25 of the budget). A
    // pass (gpu::slice_passes) keeps only those of its rows, so that its rows test fewer.
    uint count = 0u;
    uint last = first + rows_taken - 1u;
    bool any_row = false;
    for (uint j = 0u; j < uint(gathered); ++j) {
        vec3 a = slice_corners[3u * j];
        vec3 b = slice_corners[3u * j + 1u];
        vec3 e = slice_corners[3u * j + 2u];
        uvec2 range = slice_row_range(a, b, e, h, q, mid_half, rows);
        slice_ranges[j] = range;
        vec3 g = a + b + e;
        slice_keys[j] = pseudo_angle(dot(g, c), max(dot(g, h), 0.0));
        any_row = any_row || range.x <= range.y;
        if (range.x <= range.y && range.x <= last && range.y >= first) {
            slice_order[count] = j;
            count += 1u;
        }
    }
    // Every row clear, whichever rows are taken: the fraction is 1 at once. (Where only this pass's rows are clear,
    // they still weigh their light, all of it visible: row_visible_weight gives `whole` with nothing blocked.)
    if (!any_row) {
        return vec2(0.0);
    }
    const uint gaps[4] = uint[](23u, 10u, 4u, 1u);
    for (uint g = 0u; g < 4u; ++g) {
        uint gap = gaps[g];
        for (uint a = gap; a < count; ++a) {
            uint x = slice_order[a];
            uint b = a;
            while (b >= gap && slice_keys[slice_order[b - gap]] > slice_keys[x]) {
                slice_order[b] = slice_order[b - gap];
                b -= gap;
            }
            slice_order[b] = x;
        }
    }
    float n_c = dot(n, c);
    float visible = 0.0;
    float total = 0.0;
    for (uint i = first; i < first + rows_taken; ++i) {
        vec2 su = cosine_row(i, rows);
        float psi = mid_half.x - mid_half.y * su.y;
        vec3 p = cos(psi) * h + sin(psi) * q;
        float jacobian = mid_half.y * su.x;
        vec3 m = cos(psi) * q - sin(psi) * h;
        vec2 chord_span;
        vec3 line = vec3(0.0);
        if (disk) {
            // The chord's ends seen from the origin, as gamma = atan2(-s, t); the chord line a.(s, t) = b, a
            // towards its far side, pulled in to where the rays end.
            vec3 y0;
            vec3 y1;
            if (!chord(d_vec, d, radius, m, y0, y1)) {
                continue;
            }
            vec2 e0 = vec2(dot(y0, c), dot(y0, p));
            vec2 e1 = vec2(dot(y1, c), dot(y1, p));
            float g0 = atan2_accurate(-e0.x, max(e0.y, 0.0));
            float g1 = atan2_accurate(-e1.x, max(e1.y, 0.0));
            chord_span = vec2(min(g0, g1), max(g0, g1));
            vec2 a = vec2(e1.y - e0.y, e0.x - e1.x);
            float b = dot(a, e0);
            line = b < 0.0 ? vec3(-a, -SEGMENT_T_MAX * b) : vec3(a, SEGMENT_T_MAX * b);
        } else {
            float chi = chord_half_width(sigma, psi);
            chord_span = vec2(-chi, chi);
        }
        float n_p = dot(n, p);
        vec2 surface = above_about_centre(n_c, n_p);
        vec2 span = vec2(max(chord_span.x, surface.x), min(chord_span.y, surface.y));
        float whole = jacobian * weight_integral_about_centre(n_c, n_p, span.x, span.y);
        if (whole <= 0.0) {
            continue;
        }
        total += whole;
        ROW_UNION_BEGIN(span)
        // Four triangles an iteration (SLICE_TRIANGLE written out four times): the budget counts iterations.
        for (uint w = 0u; w < count && !hidden; w += 4u) {
            SLICE_TRIANGLE(w)
            SLICE_TRIANGLE(w + 1u)
            SLICE_TRIANGLE(w + 2u)
            SLICE_TRIANGLE(w + 3u)
        }
        if (hidden) {
            continue;
        }
        visible += row_visible_weight(n_c, n_p, span, union_piece, pieces, spilled, whole, jacobian);
    }
    return vec2(visible, total);
}

// A light's visible fraction from its rows' summed weights (sky_slices::rows_fraction): SLICES_UNSLICEABLE passed
// on, and (0, 0), nothing to weigh or nothing in the way, 1.
float rows_fraction(vec2 weights) {
    return weights.x < 0.0 ? SLICES_UNSLICEABLE : fraction(weights.x, weights.y);
}

// The rows first .. first + count - 1 of the sun's `rows` slices (sun_slices::sun_rows_weights) from `origin` on a
// surface of unit normal n, the sun in unit direction l with angular diameter [rad]: the rows psi = -sigma cos u
// across an axis perpendicular to l; their cosine-weighted (visible, whole) as sliced_rows_weights gives them.
vec2 sun_rows_weights(vec3 origin, vec3 n, vec3 l, float angular_diameter, uint rows, uint first, uint count) {
    float sigma = 0.5 * angular_diameter;
    vec3 c = sun_slice_axis(l);
    SliceReach r = SliceReach(origin, n, l, cos(sigma), sin(sigma), vec3(0.0), -1.0);
    return sliced_rows_weights(r, c, cross(c, l), vec2(0.0, sigma), rows, first, count, false, vec3(0.0), vec3(0.0),
                               0.0, sigma);
}

// The rows first .. first + count - 1 of the `rows` slices (disk_slices::disk_rows_weights) of the disk light
// (centre [m], unit emission direction d, radius [m]) from `origin` on a surface of unit normal n, weighted by
// projected solid angle, as sliced_rows_weights gives them: (0, 0) where the disk gives nothing (seen from
// behind); (SLICES_UNSLICEABLE, 0) where the origin is too near the disk for the slices' range.
vec2 disk_rows_weights(vec3 origin, vec3 n, vec3 center, vec3 d, float radius, uint rows, uint first,
                       uint count) {
    vec3 d_vec = center - origin;
    float dist = length(d_vec);
    if (!(dot(d, d_vec) < 0.0 && dist > 0.0)) {
        return vec2(0.0);
    }
    vec3 dhat = d_vec / dist;
    vec3 c = sun_slice_axis(dhat);
    vec3 q = cross(c, dhat);
    vec2 range;
    if (!psi_range(dist, radius, dot(q, d), dot(dhat, d), range)) {
        return vec2(SLICES_UNSLICEABLE, 0.0);
    }
    vec2 mid_half = vec2(0.5 * (range.x + range.y), 0.5 * (range.y - range.x));
    float sin_a = radius / dist;
    vec2 cone = dist > radius ? vec2(sqrt(1.0 - sin_a * sin_a), sin_a) : vec2(-2.0, 0.0);
    SliceReach r = SliceReach(origin, n, dhat, cone.x, cone.y, d, SEGMENT_T_MAX * dot(d, d_vec));
    return sliced_rows_weights(r, c, q, mid_half, rows, first, count, true, d_vec, d, radius, 0.0);
}

// The sun's visible fraction by all its `rows` (sun_rows_weights), as the frame takes it where it slices the sun
// itself; SLICES_UNSLICEABLE where the slices cannot be taken.
float sun_visible_fraction_sliced(vec3 origin, vec3 n, vec3 l, float angular_diameter, uint rows) {
    return rows_fraction(sun_rows_weights(origin, n, l, angular_diameter, rows, 0u, rows));
}

// A disk light's visible fraction by all its `rows` (disk_rows_weights), likewise.
float disk_visible_fraction_sliced(vec3 origin, vec3 n, vec3 center, vec3 d, float radius, uint rows) {
    return rows_fraction(disk_rows_weights(origin, n, center, d, radius, rows, 0u, rows));
}

// Whether a node's box may hold a part of the sky row's half-plane {s c + t p : t >= 0} (unit normal m) that lies
// above the surface (n) and the ground: the box straddles the plane, reaches t >= 0 and the two half-spaces, each
// within within_reach's slack (visibility/bvh.rs: within_row, and within_reach's half-spaces `above`).
bool within_row(BvhNode node, vec3 origin, vec3 n, vec3 p, vec3 m) {
    vec3 centre = 0.5 * (node.lo + node.hi) - origin;
    vec3 half_extent = 0.5 * (node.hi - node.lo);
    float slack = 1e-5 * (length(centre) + length(half_extent));
    return abs(dot(centre, m)) <= dot(half_extent, abs(m)) + slack
        && dot(centre, p) + dot(half_extent, abs(p)) > -slack
        && dot(centre, n) + dot(half_extent, abs(n)) > -slack
        && centre.y + half_extent.y > -slack;
}

// The leaves one sky row's walk meets (their triangles' indices), cut after the walk: the walk's iterations then
// hold only the boxes' tests, which llvmpipe runs for all of a SIMD group's lanes whenever one of them needs them
// (measured on overcast.glb at 64 x 48, k = 4: a frame of 8.1 s with the triangles cut inside the walk, 4.6 s
// after it).
uint row_leaves[MAX_SLICE_TRIANGLES];
// Child `ch` of an inner node on a sky row's walk: a leaf noted, an inner node within the row stacked; a row
// meeting more leaves than row_leaves holds sets slices_overflowed (the renderer refuses the image).
#define SKY_ROW_CHILD(ch) \
    { \
        BvhNode child = bvh_node(ch); \
        if (within_row(child, origin, n, p, m)) { \
            if (child.count == 0u) { \
                stack[top] = (ch); \
                top += 1u; \
            } else if (leaves < MAX_SLICE_TRIANGLES) { \
                row_leaves[leaves] = child.first; \
                leaves += 1u; \
            } else { \
                slices_overflowed = true; \
            } \
        } \
    }
// The row's noted leaf `w`: its triangle's interval, where the row's plane cuts it and it meets the span, into
// the row's union (UNION_INSERT); an alpha-masked triangle makes the pixel unsliceable (the reference casts the
// grid's rays there).
#define SKY_ROW_LEAF(w) \
    if (!hidden && (w) < leaves) { \
        uvec4 tri = WALK_RECORD(row_leaves[w]); \
        if (material_kind_at(tri.w & 0x7fffffffu).z != 0u) { \
            return vec2(SLICES_UNSLICEABLE, 0.0); \
        } \
        vec2 e0; \
        vec2 e1; \
        vec2 interval; \
        if (slice_segment(OCCLUDER_CORNER(tri.x) - origin, OCCLUDER_CORNER(tri.y) - origin, \
                          OCCLUDER_CORNER(tri.z) - origin, c, p, m, e0, e1) \
            && segment_interval(e0, e1, interval) && interval.y > key_lo && interval.x < key_hi) { \
            UNION_INSERT(interval) \
            hidden = pieces == 1u && union_piece[0].x <= key_lo && union_piece[0].y >= key_hi; \
        } \
    }

// One pass of the sky's slices (sky_slices::sky_rows_weights): its rows first .. first + count - 1 of `rows`, the
// half great circles through SLICE_AXIS at the midpoints psi = 2 pi (i + 1/2) / rows (sky_slices'
// sky_visible_fraction_sliced), from `origin` on a surface of unit normal n: (visible, whole), their visible and
// unoccluded weights summed over the pass; (SLICES_UNSLICEABLE, 0) where an alpha-masked occluder is cut. The
// renderer sums the passes and divides (gpu::slice_passes). A pixel's sky reaches every occluder above its
// horizons, thousands of triangles, more than one gather keeps (the sun's and disk lights' slices gather once);
// but a plane cuts some hundred of them, so each row walks the BVH for its own (within_row): some hundred of the
// budget's iterations a row on overcast.glb, and the renderer gives each pass as many rows as the budget holds.
vec2 sky_rows_weights(vec3 origin, vec3 n, uint rows, uint first, uint count) {
    vec3 c = SLICE_AXIS;
    vec3 p1 = normalize(cross(c, vec3(0.0, 0.0, 1.0)));
    vec3 p2 = cross(c, p1);
    float step = 2.0 * PI / float(rows);
    float n_c = dot(n, c);
    float visible = 0.0;
    float total = 0.0;
    BvhNode root = bvh_node(0u);
    for (uint i = first; i < first + count; ++i) {
        float psi = (float(i) + 0.5) * step;
        vec3 p = cos(psi) * p1 + sin(psi) * p2;
        vec3 m = cross(c, p);
        float n_p = dot(n, p);
        vec2 surface = above_about_centre(n_c, n_p);
        vec2 ground = above_about_centre(c.y, p.y);
        vec2 span = vec2(max(ground.x, surface.x), min(ground.y, surface.y));
        float whole = weight_integral_about_centre(n_c, n_p, span.x, span.y);
        if (whole <= 0.0) {
            continue;
        }
        total += whole;
        ROW_UNION_BEGIN(span)
        uint leaves = 0u;
        if (within_row(root, origin, n, p, m)) {
            if (root.count > 0u) {
                row_leaves[0] = root.first;
                leaves = 1u;
            } else {
                BVH_WALK(SKY_ROW_CHILD)
            }
        }
        // Two leaves an iteration (the budget counts iterations).
        for (uint w = 0u; w < leaves && !hidden; w += 2u) {
            SKY_ROW_LEAF(w)
            SKY_ROW_LEAF(w + 1u)
        }
        if (!hidden) {
            visible += row_visible_weight(n_c, n_p, span, union_piece, pieces, spilled, whole, 1.0);
        }
    }
    return vec2(visible, total);
}

#endif
