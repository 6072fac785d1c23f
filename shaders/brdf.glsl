// BRDFs rho [1/sr] in f32: the Lambertian term and the arithmetic the specular models share. Each specular model
// has its file in brdf/ (its lobe, width and sampling). Mirrors src/shading/brdf.rs name for name (precision notes
// there).
//
// Every branch of a shader on the BRDF kind is a `switch (VARIANT_BRDF)` naming each kind with no default
// (tests/architecture.rs), so that a new kind cannot be forgotten; and the code a kind does not run sits inside the
// switch's other cases, where the specializer (sunshade_glsl::specialize) drops it before the driver sees it.
#ifndef SUNSHADE_BRDF_GLSL
#define SUNSHADE_BRDF_GLSL

#include "math.glsl"

// Lambertian: rho = albedo / pi.
vec3 lambert_brdf(vec3 albedo) {
    return albedo * INV_PI;
}

// 1 - a.b for unit vectors, as |a - b|^2 / 2: no cancellation at the peak of a narrow lobe.
float one_minus_dot(vec3 a, vec3 b) {
    vec3 d = a - b;
    return 0.5 * dot(d, d);
}

// (1 - x)^e as exp(e log1p(-x)); 1 for e = 0, 0 for x >= 1 when e > 0. Replaces pow(cos, e), whose base is
// already rounded (lavapipe: pow(0.999, 1e4) is 6e-4 off). SUNSHADE_NAIVE_MATH (diagnostics) restores pow.
float cos_power(float one_minus_cos, float exponent) {
#ifdef SUNSHADE_NAIVE_MATH
    return pow(max(1.0 - one_minus_cos, 0.0), exponent);
#else
    if (exponent == 0.0) {
        return 1.0;
    }
    if (one_minus_cos >= 1.0) {
        return 0.0;
    }
    return exp(exponent * log1p_accurate(-one_minus_cos));
#endif
}

// The mirror direction of l about n: 2(n.l)n - l (GLSL's reflect() has the opposite sign convention).
vec3 mirror(vec3 l, vec3 n) {
    return 2.0 * dot(n, l) * n - l;
}

// A direction at angle a from the unit `axis` with cos a = (1 - xi1)^(1/(e+1)) and azimuth phi in the frame
// (t, b) about it: the inverse CDF of the pdf (e+1)/(2 pi) cos^e a. 1 - cos a as -expm1(log1p(-xi1)/(e+1)), which
// keeps its digits for large e (see the Rust).
vec3 cos_power_direction(vec3 axis, vec3 t, vec3 b, float exponent, float xi1, float phi) {
    float one_minus_cos = -exp_minus_one(log1p_accurate(-xi1) / (exponent + 1.0));
    float cos_a = 1.0 - one_minus_cos;
    float sin_a = sqrt(one_minus_cos * (1.0 + cos_a));
    return cos_a * axis + sin_a * (cos(phi) * t + sin(phi) * b);
}

#endif
