// The glTF 2.0 metallic-roughness BRDF (the specification's Appendix B) in f32: its diffuse reflectance, its lobe
// (the GGX distribution, the separable Smith visibility, Schlick's Fresnel; negative where the Fresnel darkening of
// the base colour outweighs the specular lobe), its width, one sample of the sky's mixture grid. Mirrors
// src/shading/brdf/metallic_roughness.rs name for name (the split and the precision notes are there).
#ifndef SUNSHADE_BRDF_METALLIC_ROUGHNESS_GLSL
#define SUNSHADE_BRDF_METALLIC_ROUGHNESS_GLSL

#include "brdf.glsl"

#define GLTF_DIELECTRIC_F0 0.04

// The largest of the dielectric's f0 over the channels.
float f0_max(vec3 f0) {
    return max(max(f0.r, f0.g), f0.b);
}

// 1 - v.h for unit l and v: |l - v|^2 / (2 (2 + |l + v|)), without cancellation where l = v.
float one_minus_v_dot_h(vec3 l, vec3 v) {
    vec3 d = l - v;
    return dot(d, d) / (2.0 * (2.0 + length(l + v)));
}

// Schlick's (1 - v.h)^5, as products.
float schlick_weight(float one_minus_vh) {
    float x2 = one_minus_vh * one_minus_vh;
    return x2 * x2 * one_minus_vh;
}

// GGX's D [1/sr] for the (not necessarily unit) half vector h: alpha^2 / (pi (|n x h|^2 + alpha^2 (n.h)^2)^2)
// scaled by |h|^4; 0 where n.h <= 0.
float ggx_distribution(vec3 n, vec3 h, float alpha) {
    float nh = dot(n, h);
    if (!(nh > 0.0)) {
        return 0.0;
    }
    float a2 = alpha * alpha;
    vec3 c = cross(n, h);
    float across = dot(c, c);
    float h2 = dot(h, h);
    float denominator = across + a2 * nh * nh;
    return a2 * INV_PI * (h2 / denominator) * (h2 / denominator);
}

// The separable Smith visibility V (holding 1/(4 |n.l| |n.v|)).
float smith_visibility(float n_dot_l, float n_dot_v, float alpha) {
    float a2 = alpha * alpha;
    float one_l = abs(n_dot_l) + sqrt(a2 + (1.0 - a2) * n_dot_l * n_dot_l);
    float one_v = abs(n_dot_v) + sqrt(a2 + (1.0 - a2) * n_dot_v * n_dot_v);
    return 1.0 / (one_l * one_v);
}

// The lobe per channel: D V ((1 - m) F_d + m F_m) - (1 - m)(f90 - max f0)(1 - v.h)^5 base/pi, F_d = f0 + (f90 - f0)
// (1 - v.h)^5 the dielectric's Fresnel (0.04 and 1 without KHR_materials_ior/specular); 0 where l = -v.
vec3 gltf_lobe_rgb(vec3 n, vec3 l, vec3 v, vec3 base, float metallic, float alpha, vec3 f0, float f90) {
    vec3 h = l + v;
    if (dot(h, h) == 0.0) {
        return vec3(0.0);
    }
    float specular = ggx_distribution(n, h, alpha) * smith_visibility(dot(n, l), dot(n, v), alpha);
    float s = schlick_weight(one_minus_v_dot_h(l, v));
    float m = metallic;
    float darkening = (1.0 - m) * (f90 - f0_max(f0)) * s;
    vec3 dielectric_f = f0 + (f90 - f0) * s;
    vec3 metal_f = base + (1.0 - base) * s;
    return specular * ((1.0 - m) * dielectric_f + m * metal_f) - darkening * base * INV_PI;
}

// The angular width [rad] about the lobe's peak over which the lights' grids crowd their samples: 2 alpha.
float gltf_lobe_width(float alpha) {
    return 2.0 * alpha;
}

// The density per solid angle of omega when the GGX half vector is drawn about n: D(h) (n.h) / (4 v.h).
float gltf_half_vector_pdf(vec3 n, vec3 omega, vec3 v, float alpha) {
    vec3 sum = omega + v;
    float len = length(sum);
    if (len == 0.0) {
        return 0.0;
    }
    vec3 h = sum / len;
    return ggx_distribution(n, h, alpha) * max(dot(n, h), 0.0) / (4.0 * max(dot(v, h), 1.17549435e-38));
}

// One sample of the sky's grid from the even mixture of GGX's half vector (phi < pi) and the cosine (the others),
// weighted by lobe (n.w)+ / pdf_mix per channel (see the Rust). (n, t, b): the frame about the normal.
vec3 gltf_lobe_sample(vec3 n, vec3 t, vec3 b, vec3 v, vec3 base, float metallic, float alpha, vec3 f0, float f90,
                      float xi1, float phi, out vec3 omega) {
    if (phi < PI) {
        float a2 = alpha * alpha;
        float tan2 = a2 * xi1 / (1.0 - xi1);
        float cos_h = 1.0 / sqrt(1.0 + tan2);
        float sin_h = sqrt(tan2) * cos_h;
        float phi_h = 2.0 * phi;
        vec3 h = sin_h * (cos(phi_h) * t + sin(phi_h) * b) + cos_h * n;
        float vh = dot(v, h);
        if (!(vh > 0.0)) {
            omega = n;
            return vec3(0.0);
        }
        omega = 2.0 * vh * h - v;
    } else {
        float phi_c = 2.0 * phi - 2.0 * PI;
        float sin_t = sqrt(xi1);
        float cos_t = sqrt(1.0 - xi1);
        omega = sin_t * (cos(phi_c) * t + sin(phi_c) * b) + cos_t * n;
    }
    float c = dot(n, omega);
    if (!(c > 0.0)) {
        omega = n;
        return vec3(0.0);
    }
    float pdf = 0.5 * gltf_half_vector_pdf(n, omega, v, alpha) + 0.5 * c * INV_PI;
    return gltf_lobe_rgb(n, omega, v, base, metallic, alpha, f0, f90) * c / pdf;
}

#endif
