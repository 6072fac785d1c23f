// A BRDF's specular lobe and how it is sampled: the lobe of a material at a surface point, its width, the graded
// grids that integrate it over a light's disk or segment (with visibility), and the inverse-CDF directions about
// its axis. Mirrors src/shading/lobe.rs name for name (the same sample points, so that the GPU and the reference
// differ only by rounding); the lights (lights/) integrate the lobe over themselves with these.
#ifndef SUNSHADE_LOBE_GLSL
#define SUNSHADE_LOBE_GLSL

#include "bindings.glsl"
#include "brdf.glsl"
#include "brdf/phong.glsl"
#include "brdf/blinn_phong.glsl"
#include "brdf/ward.glsl"
#include "brdf/metallic_roughness.glsl"
#include "measured.glsl"
#include "visibility.glsl"

// Which shadow rays a lobe integral's samples cast (Rust: Option<SampleRays>).
#define RAYS_NONE 0u
#define RAYS_ALONG 1u
#define RAYS_TO_POINT 2u

// v/|v|, or 0 when |v|^2 is 0 (or flushed to 0) so that a degenerate normal shades to 0 instead of NaN.
vec3 safe_normalize(vec3 v) {
    float len2 = dot(v, v);
    return len2 > 0.0 ? v * inversesqrt(len2) : vec3(0.0);
}

// The local frame of a surface point.
struct Frame {
    vec3 position;
    vec3 normal;
    vec3 tangent;
    vec3 bitangent;
    vec3 to_viewer;
    vec3 shadow_origin; // the shadow rays' origin [m] (visibility.glsl's shadow_ray_origin)
    vec3 face_normal;   // the triangle's unit normal on the shaded side (shadow-map bias)
};

// The table of models: each question asked of the variant's lobe is a `switch` naming every BRDF kind and calling
// its file (brdf/*.glsl, measured.glsl), as src/shading/lobe.rs's matches do.

// The specular lobe of a material (without ks) for light from l; a measured table's, the mean of its channels'.
float specular_lobe(MaterialGpu m, Frame p, vec3 l) {
    switch (VARIANT_BRDF) {
    case BRDF_LAMBERT:
        return 0.0;
    case BRDF_PHONG:
        return phong_lobe(p.normal, l, p.to_viewer, m.ks.w);
    case BRDF_BLINN_PHONG:
        return blinn_phong_lobe(p.normal, l, p.to_viewer, m.ks.w);
    case BRDF_WARD:
        return ward_lobe(p.normal, p.tangent, p.bitangent, l, p.to_viewer, m.params.x, m.params.y);
    case BRDF_MEASURED: {
        vec3 rgb = measured_residual(m, p.normal, l, p.to_viewer);
        return (rgb.r + rgb.g + rgb.b) / 3.0;
    }
    case BRDF_GLTF: {
        vec3 rgb = gltf_lobe_rgb(p.normal, l, p.to_viewer, m.base.rgb, m.params.y, m.params.x, m.specular.rgb, m.specular.w);
        return (rgb.r + rgb.g + rgb.b) / 3.0;
    }
    }
    return 0.0;
}

// The specular lobe of a material (without ks) per channel for light from l: an analytic lobe's one value in each.
// A measured table's: its part above its floor.
vec3 specular_lobe_rgb(MaterialGpu m, Frame p, vec3 l) {
    switch (VARIANT_BRDF) {
    case BRDF_MEASURED:
        return measured_residual(m, p.normal, l, p.to_viewer);
    case BRDF_GLTF:
        return gltf_lobe_rgb(p.normal, l, p.to_viewer, m.base.rgb, m.params.y, m.params.x, m.specular.rgb, m.specular.w);
    case BRDF_LAMBERT:
    case BRDF_PHONG:
    case BRDF_BLINN_PHONG:
    case BRDF_WARD:
        return vec3(specular_lobe(m, p, l));
    }
    return vec3(0.0);
}

// The angular width [rad] about a lobe's peak over which the disk integral crowds its samples (see the Rust).
float lobe_width(MaterialGpu m) {
    switch (VARIANT_BRDF) {
    case BRDF_LAMBERT:
        return PI;
    case BRDF_PHONG:
        return phong_lobe_width(m.ks.w);
    case BRDF_BLINN_PHONG:
        return blinn_phong_lobe_width(m.ks.w);
    case BRDF_WARD:
        return ward_lobe_width(m.params.x, m.params.y);
    case BRDF_MEASURED:
        return m.ks.w;
    case BRDF_GLTF:
        return gltf_lobe_width(m.params.x);
    }
    return PI;
}

// The axis a lobe's inverse-CDF directions are drawn about: Phong's mirror direction of the viewer, the others'
// normal.
vec3 sampling_axis(Frame p) {
    switch (VARIANT_BRDF) {
    case BRDF_PHONG:
        return mirror(p.to_viewer, p.normal);
    case BRDF_LAMBERT:
    case BRDF_BLINN_PHONG:
    case BRDF_WARD:
    case BRDF_MEASURED:
    case BRDF_GLTF:
        return p.normal;
    }
    return p.normal;
}

// One sample (xi1, phi) of a stratified grid through the lobe's own inverse CDF about (axis, t, b): the weight
// lobe(w) (n.w)+ / pdf(w) per channel, and the direction in `omega`. A Lambertian BRDF has no lobe: weight 0.
vec3 lobe_sample(MaterialGpu m, Frame p, vec3 axis, vec3 t, vec3 b, float xi1, float phi, out vec3 omega) {
    vec3 n = p.normal;
    vec3 v = p.to_viewer;
    switch (VARIANT_BRDF) {
    case BRDF_LAMBERT:
        omega = n;
        return vec3(0.0);
    case BRDF_PHONG:
        return vec3(phong_lobe_sample(n, axis, t, b, m.ks.w, xi1, phi, omega));
    case BRDF_BLINN_PHONG:
        return vec3(blinn_phong_lobe_sample(n, v, axis, t, b, m.ks.w, xi1, phi, omega));
    case BRDF_WARD:
        return vec3(ward_lobe_sample(n, p.tangent, p.bitangent, v, m.params.x, m.params.y, xi1, phi, omega));
    case BRDF_MEASURED:
        return measured_lobe_sample(m, n, v, t, b, xi1, phi, omega);
    case BRDF_GLTF:
        return gltf_lobe_sample(n, t, b, v, m.base.rgb, m.params.y, m.params.x, m.specular.rgb, m.specular.w, xi1, phi,
                                omega);
    }
    omega = n;
    return vec3(0.0);
}

// The count per axis of the sky's inverse-CDF grid for a lobe asked `per_axis`: glTF's mixture takes an even one.
uint sky_grid_per_axis(uint per_axis) {
    switch (VARIANT_BRDF) {
    case BRDF_GLTF:
        return per_axis + per_axis % 2u;
    case BRDF_LAMBERT:
    case BRDF_PHONG:
    case BRDF_BLINN_PHONG:
    case BRDF_WARD:
    case BRDF_MEASURED:
        return per_axis;
    }
    return per_axis;
}

// The point for u in (0, 1) of a grid on [a, b] graded about c with width w, x = c + w sinh(z), and its density
// dx/du: (x, dx/du); `ends` = (za, zb) from sinh_warp_ends, once per grid. sinh and asinh without cancellation
// near 0 (math.glsl).
vec2 sinh_warp(float a, float b, float c, float w, vec2 ends, float u) {
    float z = ends.x + u * (ends.y - ends.x);
    return vec2(clamp(c + w * sinh_accurate(z), a, b), w * (ends.y - ends.x) * cosh(z));
}

// How far a graded grid of width w on an interval of length `span` is blended towards the uniform grid: 0 while
// w <= 8 span, rising linearly to 1 at 16 span (see the Rust).
float uniform_blend(float w, float span) {
    return clamp((w / span - 8.0) / 8.0, 0.0, 1.0);
}

// A graded point (x, dx/du) on [a, b] moved by `lambda` towards the uniform grid's (a + u (b - a), b - a).
vec2 blended_point(float a, float b, vec2 point, float lambda, float u) {
    return vec2(point.x + lambda * ((a + u * (b - a)) - point.x), point.y + lambda * ((b - a) - point.y));
}

// The ends (za, zb) = (asinh((a - c)/w), asinh((b - c)/w)) of sinh_warp's z range.
vec2 sinh_warp_ends(float a, float b, float c, float w) {
    return vec2(asinh_accurate((a - c) / w), asinh_accurate((b - c) / w));
}

// One axis of a graded grid: [a, b] graded about c with width w, with its warp's ends and its blend towards the
// uniform grid over the span, computed once per grid (see the Rust).
struct GradedAxis {
    float a;
    float b;
    float c;
    float w;
    vec2 ends;
    float blend;
};

// The graded axis on [a, b] about c with width w.
GradedAxis graded_axis(float a, float b, float c, float w) {
    return GradedAxis(a, b, c, w, sinh_warp_ends(a, b, c, w), uniform_blend(w, b - a));
}

// The axis' point (x, dx/du) for u in (0, 1): the graded point moved towards the uniform one by the blend.
vec2 graded_point(GradedAxis g, float u) {
    return blended_point(g.a, g.b, sinh_warp(g.a, g.b, g.c, g.w, g.ends, u), g.blend, u);
}

// The grid's sums over a disk, per unit radiance (see the Rust): the lobe's per channel over the visible samples,
// the cosine's over all, and how uniform the grid was.
struct SegmentSums {
    vec3 lobe;
    float projected;
    float uniformity;
};

// The segment a light's specular term integrates its lobe over (segment_lobe_integral_visible's arguments:
// `wanted` false where it needs none, a delta sun and a small-source disk), asked by sun_specular_segment and
// disk_specular_segment so that radiance_out integrates every light's by one call: the driver inlines each call,
// and a call in each light's term would compile the lobe's grid, its BRDF and its rays once a kind of light.
struct SegmentAsk {
    bool wanted;
    vec3 q;
    vec3 d;
    float radius;
    uint per_axis;
    uint rays;
};
const SegmentAsk NO_SEGMENT = SegmentAsk(false, vec3(0.0), vec3(0.0), 0.0, 0u, RAYS_NONE);
const SegmentSums NO_SEGMENT_SUMS = SegmentSums(vec3(0.0), 0.0, 0.0);

// The lobe integral with the grid's weights normalised, as far as the grid is uniform, to integrate the cosine
// exactly: lobe (1 + uniformity (exact/projected - 1)) (a ratio estimator; see the Rust).
vec3 normalized_lobe_integral(SegmentSums sums, float exact) {
    return sums.projected > 0.0 ? sums.lobe * (1.0 + sums.uniformity * (exact / sums.projected - 1.0)) : sums.lobe;
}

// The grid's sums over a disk, per unit radiance, for the disk of radius `radius` centred at q from the point,
// emitting along d: segment coordinates, the grid graded about the lobe's peak (see the Rust).
SegmentSums segment_lobe_integral_visible(MaterialGpu m, Frame p, vec3 q, vec3 d, float radius, uint per_axis, uint rays) {
    vec3 n = p.normal;
    float h = -dot(d, q);
    SegmentSums none = SegmentSums(vec3(0.0), 0.0, 0.0);
    if (!(h > 0.0 && radius > 0.0)) {
        return none;
    }
    vec3 n_perp = n - dot(n, d) * d;
    float mlen = length(n_perp);
    float nq = dot(n, q);
    vec3 w;
    float alpha;
    if (nq - radius * mlen >= 0.0) {
        w = mlen > 0.0 ? n_perp / mlen : orthonormal_to(d);
        alpha = PI;
    } else if (nq + radius * mlen <= 0.0) {
        return none;
    } else {
        float kappa = clamp(-nq / (radius * mlen), -1.0, 1.0);
        w = n_perp / mlen;
        alpha = atan2_accurate(sqrt((1.0 - kappa) * (1.0 + kappa)), kappa);
    }
    vec3 v = cross(d, w);
    vec3 r = mirror(p.to_viewer, n);
    float toward = min(dot(r, d), -1e-6);
    float t = h / -toward;
    vec3 rel = t * r - q;
    float footprint = t * lobe_width(m) / -toward;
    float off = length(rel);
    if (off > radius) {
        float outside = off - radius;
        footprint = footprint * footprint / (footprint + outside);
        rel *= radius / off;
    }
    float a = dot(rel, w) / radius;
    float beta_c = min(a >= 1.0 ? 0.0 : (a <= -1.0 ? PI : atan2_accurate(sqrt((1.0 - a) * (1.0 + a)), a)), alpha);
    float sbc = sin(beta_c);
    float cbc = cos(beta_c);
    float s_c = sbc > 0.0 ? clamp(dot(rel, v) / (radius * sbc), -1.0, 1.0) : 0.0;
    float rate_beta = radius * sqrt(sbc * sbc + cbc * cbc * s_c * s_c);
    float width_beta = min(footprint / max(rate_beta, 1e-30), 16.0 * alpha);
    float width_s = min(footprint / max(radius * sbc, 1e-30), 32.0);
    float k = float(per_axis);
    vec3 sum = vec3(0.0);
    float projected = 0.0;
    GradedAxis beta_axis = graded_axis(0.0, alpha, beta_c, width_beta);
    GradedAxis s_axis = graded_axis(-1.0, 1.0, s_c, width_s);
    for (uint i = 0u; i < per_axis; ++i) {
        vec2 bw = graded_point(beta_axis, (float(i) + 0.5) / k);
        float sb = sin(bw.x);
        float cb = cos(bw.x);
        for (uint j = 0u; j < per_axis; ++j) {
            vec2 sw = graded_point(s_axis, (float(j) + 0.5) / k);
            vec3 y = q + radius * cb * w + radius * sb * sw.x * v;
            float dist2 = dot(y, y);
            float dist = sqrt(dist2);
            vec3 omega = y / dist;
            float c = dot(n, omega);
            if (c > 0.0) {
                float weight = c * h / (dist2 * dist) * radius * radius * sb * sb * bw.y * sw.y;
                projected += weight;
                // A sample that contributes casts its shadow ray (|| short-circuits): visible_along omega, or
                // visible_to the point p.position + y, as one call of occluded so that the driver inlines one copy
                // of the ray's traversal (visibility.glsl's sample_visible).
                // The sun's samples (RAYS_ALONG) take its cells where the frame has them (sun_visible_along).
                bool along = rays == RAYS_ALONG;
                bool cells = ONLY_SUN_CELL_RAYS || (along && SUN_CELLS_USABLE(p.shadow_origin));
                if (rays == RAYS_NONE || (cells ? !SUN_CELLS_OCCLUDED(p.shadow_origin, n, omega)
                                                : !occluded(p.shadow_origin, along ? omega : (p.position + y) - p.shadow_origin,
                                                            along ? RAY_T_INFINITE : SEGMENT_T_MAX))) {
                    sum += specular_lobe_rgb(m, p, omega) * weight;
                }
            }
        }
    }
    return SegmentSums(sum / (k * k), projected / (k * k), min(beta_axis.blend, s_axis.blend));
}

#endif
