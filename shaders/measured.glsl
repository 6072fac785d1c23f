// Measured (MERL) BRDFs in f32. Mirrors src/shading/measured.rs name for name (conventions and precision notes
// there): Rusinkiewicz's angles by atan2 of |a x b| and a.b, the table's coordinates with samples at the bins'
// centres, and a trilinear lookup over the valid corners (default) or nearest, in the same order as the Rust.
#ifndef SUNSHADE_MEASURED_GLSL
#define SUNSHADE_MEASURED_GLSL

#include "bindings.glsl"
#include "math.glsl"

#define THETA_H_BINS 90u
#define THETA_D_BINS 90u
#define PHI_D_BINS 180u

// The angle between unit vectors a and b: atan2(|a x b|, a.b), accurate near 0 (the mirror peak).
float angle_between(vec3 a, vec3 b) {
    return atan2_accurate(length(cross(a, b)), dot(a, b));
}

// (theta_h, theta_d, phi_d, 1), or w = 0 where l + v = 0.
vec4 half_diff_angles(vec3 n, vec3 l, vec3 v) {
    vec3 s = l + v;
    float len2 = dot(s, s);
    if (!(len2 > 0.0)) {
        return vec4(0.0);
    }
    vec3 h = s * inversesqrt(len2);
    float theta_h = angle_between(n, h);
    float theta_d = angle_between(l, h);
    vec3 away = dot(n, h) * h - n;
    float len = length(away);
    vec3 x = len > 1e-12 ? away / len : orthonormal_to(h);
    vec3 y = cross(h, x);
    return vec4(theta_h, theta_d, atan2_accurate(dot(l, y), dot(l, x)), 1.0);
}

// (u_h, u_d, u_phi): u_h = 90 sqrt(theta_h / (pi/2)), u_d = 90 theta_d / (pi/2), u_phi = 180 phi_d / pi with phi_d
// folded into [0, pi).
vec3 measured_coordinates(float theta_h, float theta_d, float phi_d) {
    float u_h = float(THETA_H_BINS) * sqrt(max(theta_h, 0.0) / (0.5 * PI));
    float u_d = float(THETA_D_BINS) * (max(theta_d, 0.0) / (0.5 * PI));
    float folded = phi_d < 0.0 ? phi_d + PI : phi_d;
    float u_phi = min(float(PHI_D_BINS) * (folded / PI), float(PHI_D_BINS));
    return vec3(u_h, u_d, u_phi >= float(PHI_D_BINS) ? 0.0 : u_phi);
}

// (i, next, t) on an axis of `bins` samples, sample i at u = i + 1/2: the sample below u, the one after (the
// theta axes hold their first and last samples; phi wraps from its last to its first) and the fraction past i.
vec3 measured_axis(float u, uint bins, bool periodic) {
    uint last = bins - 1u;
    float s = u - 0.5;
    if (periodic && s < 0.0) {
        s += float(bins);
    }
    uint i = min(uint(max(floor(s), 0.0)), last);
    float t = clamp(s - float(i), 0.0, 1.0);
    uint next = i < last ? i + 1u : (periodic ? 0u : last);
    return vec3(float(i), float(next), t);
}

// The bin u falls in (truncation): the sample whose centre is nearest.
float measured_bin(float u, uint bins) {
    return float(min(uint(max(floor(u), 0.0)), bins - 1u));
}

// a + t (b - a), in that order (GLSL's mix may be a (1 - t) + b t).
vec3 lerp(vec3 a, vec3 b, float t) {
    return a + t * (b - a);
}

vec4 lerp4(vec4 a, vec4 b, float t) {
    return a + t * (b - a);
}

// The table's rgb at bins (i, j, k) of the table starting at sample `offset` of measured_values[] (a missing
// sample's: its nearest valid sample's).
vec3 measured_sample(uint offset, float i, float j, float k) {
    uint index = uint(k) + PHI_D_BINS * (uint(j) + THETA_D_BINS * uint(i));
    return measured_values[offset + index].rgb;
}

// (a rho, a) at bins (i, j, k): a (the stored alpha) 1 for a valid sample, 0 for a missing one.
vec4 measured_weighted_sample(uint offset, float i, float j, float k) {
    uint index = uint(k) + PHI_D_BINS * (uint(j) + THETA_D_BINS * uint(i));
    vec4 s = measured_values[offset + index];
    return vec4(s.rgb * s.a, s.a);
}

// rho [1/sr] per channel of the table at `offset` for light from l seen from v about n (0 below the horizon);
// `nearest` truncates to the bin, else trilinear over the valid corners (along phi, then theta_d, then theta_h),
// renormalised, or over the held values where no corner is valid.
vec3 measured_brdf(uint offset, bool nearest, vec3 n, vec3 l, vec3 v) {
    if (!(dot(n, l) > 0.0 && dot(n, v) > 0.0)) {
        return vec3(0.0);
    }
    vec4 a = half_diff_angles(n, l, v);
    if (a.w == 0.0) {
        return vec3(0.0);
    }
    vec3 u = measured_coordinates(a.x, a.y, a.z);
    if (nearest) {
        float i = measured_bin(u.x, THETA_H_BINS);
        return measured_sample(offset, i, measured_bin(u.y, THETA_D_BINS), measured_bin(u.z, PHI_D_BINS));
    }
    vec3 h = measured_axis(u.x, THETA_H_BINS, false);
    vec3 d = measured_axis(u.y, THETA_D_BINS, false);
    vec3 p = measured_axis(u.z, PHI_D_BINS, true);
    vec4 w00 = lerp4(measured_weighted_sample(offset, h.x, d.x, p.x), measured_weighted_sample(offset, h.x, d.x, p.y), p.z);
    vec4 w01 = lerp4(measured_weighted_sample(offset, h.x, d.y, p.x), measured_weighted_sample(offset, h.x, d.y, p.y), p.z);
    vec4 w10 = lerp4(measured_weighted_sample(offset, h.y, d.x, p.x), measured_weighted_sample(offset, h.y, d.x, p.y), p.z);
    vec4 w11 = lerp4(measured_weighted_sample(offset, h.y, d.y, p.x), measured_weighted_sample(offset, h.y, d.y, p.y), p.z);
    vec4 weighted = lerp4(lerp4(w00, w01, d.z), lerp4(w10, w11, d.z), h.z);
    if (weighted.a > 0.0) {
        return weighted.rgb / weighted.a;
    }
    vec3 h0d0 = lerp(measured_sample(offset, h.x, d.x, p.x), measured_sample(offset, h.x, d.x, p.y), p.z);
    vec3 h0d1 = lerp(measured_sample(offset, h.x, d.y, p.x), measured_sample(offset, h.x, d.y, p.y), p.z);
    vec3 h1d0 = lerp(measured_sample(offset, h.y, d.x, p.x), measured_sample(offset, h.y, d.x, p.y), p.z);
    vec3 h1d1 = lerp(measured_sample(offset, h.y, d.y, p.x), measured_sample(offset, h.y, d.y, p.y), p.z);
    return lerp(lerp(h0d0, h0d1, d.z), lerp(h1d0, h1d1, d.z), h.z);
}

// The table's part above its floor (params.rgb; the material's kd is pi floor): what the sample grids integrate.
// The table starts at sample kind.w of measured_values[]; params.w is 1 for the nearest lookup.
vec3 measured_residual(MaterialGpu m, vec3 n, vec3 l, vec3 v) {
    if (!(dot(n, l) > 0.0 && dot(n, v) > 0.0)) {
        return vec3(0.0);
    }
    return measured_brdf(m.kind.w, m.params.w != 0.0, n, l, v) - m.params.rgb;
}

// The alpha of the Ward half-vector distribution that draws a measured table's sky samples: its peak width / sqrt(2),
// in [1e-3, 1].
float measured_sampling_alpha(float lobe_width) {
    return clamp(lobe_width / 1.41421356237309504880, 1e-3, 1.0);
}

// One sample of the sky's inverse-CDF grid for a table: Ward's isotropic half vector about n with the table's
// alpha, reflected into `omega`; the table's part above its floor times the weight (n.w)+ 4 (v.h) pi alpha^2
// cos^3 delta / xi1, 0 (omega = n) where h faces away from the viewer (see the Rust). (t, b): a frame about n.
vec3 measured_lobe_sample(MaterialGpu m, vec3 n, vec3 v, vec3 t, vec3 b, float xi1, float phi, out vec3 omega) {
    float alpha = measured_sampling_alpha(m.ks.w);
    float tan2 = -alpha * alpha * log_accurate(xi1);
    float cos_d = 1.0 / sqrt(1.0 + tan2);
    float sin_d = sqrt(tan2) * cos_d;
    vec3 h = sin_d * (cos(phi) * t + sin(phi) * b) + cos_d * n;
    float vh = dot(v, h);
    if (!(vh > 0.0)) {
        omega = n;
        return vec3(0.0);
    }
    omega = 2.0 * vh * h - v;
    float weight = max(dot(n, omega), 0.0) * 4.0 * vh * PI * alpha * alpha * cos_d * cos_d * cos_d / xi1;
    return measured_residual(m, n, omega, v) * weight;
}

#endif
