// BRDFs rho [1/sr] in f32. Mirrors src/shading/brdf.rs name for name.
#ifndef SUNSHADE_BRDF_GLSL
#define SUNSHADE_BRDF_GLSL

#include "radiometry.glsl"

// Lambertian: rho = albedo / pi.
vec3 lambert_brdf(vec3 albedo) {
    return albedo * INV_PI;
}

#endif
