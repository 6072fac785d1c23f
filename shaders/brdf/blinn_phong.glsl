// The normalized Blinn-Phong lobe in f32: its normalization, the lobe, its width, one sample of its inverse CDF.
// Mirrors src/shading/brdf/blinn_phong.rs name for name.
#ifndef SUNSHADE_BRDF_BLINN_PHONG_GLSL
#define SUNSHADE_BRDF_BLINN_PHONG_GLSL

#include "brdf.glsl"

// Normalization of the Blinn-Phong lobe: (e + 2)(e + 4) / (8 pi (e + 2^(-e/2))).
float blinn_phong_normalization(float exponent) {
    return (exponent + 2.0) * (exponent + 4.0) / (8.0 * PI * (exponent + exp2(-0.5 * exponent)));
}

// Normalized Blinn-Phong lobe N(e) (n.h)^e.
float blinn_phong_lobe(vec3 n, vec3 l, vec3 v, float exponent) {
    vec3 s = l + v;
    float len2 = dot(s, s);
    if (len2 == 0.0) {
        return 0.0;
    }
    vec3 h = s * inversesqrt(len2);
    if (dot(n, h) <= 0.0) {
        return 0.0;
    }
    return blinn_phong_normalization(exponent) * cos_power(one_minus_dot(n, h), exponent);
}

// The angular width [rad] about the lobe's peak over which the disk integral crowds its samples: 2/sqrt(e + 1).
float blinn_phong_lobe_width(float exponent) {
    return 2.0 / sqrt(exponent + 1.0);
}

// One sample of the sky's inverse-CDF grid: the half vector about `axis` (the normal), reflected about it into
// `omega`; its weight lobe (n.w)+ / pdf_w, 0 (omega = n) where h faces away from the viewer (see the Rust).
float blinn_phong_lobe_sample(vec3 n, vec3 v, vec3 axis, vec3 t, vec3 b, float exponent, float xi1, float phi,
                              out vec3 omega) {
    vec3 h = cos_power_direction(axis, t, b, exponent, xi1, phi);
    float vh = dot(v, h);
    if (!(vh > 0.0)) {
        omega = n;
        return 0.0;
    }
    omega = 2.0 * vh * h - v;
    return blinn_phong_normalization(exponent) * 4.0 * vh * max(dot(n, omega), 0.0) * 2.0 * PI / (exponent + 1.0);
}

#endif
