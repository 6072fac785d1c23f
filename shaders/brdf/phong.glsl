// The modified Phong lobe in f32: the lobe, its width, one sample of its inverse CDF. Mirrors
// src/shading/brdf/phong.rs name for name (the derivations and the kink the bounds use are there).
#ifndef SUNSHADE_BRDF_PHONG_GLSL
#define SUNSHADE_BRDF_PHONG_GLSL

#include "brdf.glsl"

// Modified Phong lobe (e + 2)/(2 pi) cos^e(alpha), alpha between the mirror of l and v.
float phong_lobe(vec3 n, vec3 l, vec3 v, float exponent) {
    return (exponent + 2.0) / (2.0 * PI) * cos_power(one_minus_dot(mirror(l, n), v), exponent);
}

// The angular width [rad] about the lobe's peak over which the disk integral crowds its samples: 1/sqrt(e + 1).
float phong_lobe_width(float exponent) {
    return 1.0 / sqrt(exponent + 1.0);
}

// One sample of the sky's inverse-CDF grid about `axis` (the mirror direction of the viewer): its weight
// lobe (n.w)+ / pdf = (e + 2)/(e + 1) (n.w)+, and the direction in `omega`.
float phong_lobe_sample(vec3 n, vec3 axis, vec3 t, vec3 b, float exponent, float xi1, float phi, out vec3 omega) {
    omega = cos_power_direction(axis, t, b, exponent, xi1, phi);
    return (exponent + 2.0) / (exponent + 1.0) * max(dot(n, omega), 0.0);
}

#endif
