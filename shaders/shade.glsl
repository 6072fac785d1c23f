// Outgoing radiance at a surface point. Mirrors src/shading/shade.rs name for name.
#ifndef SUNSHADE_SHADE_GLSL
#define SUNSHADE_SHADE_GLSL

#include "bindings.glsl"
#include "brdf.glsl"

// v/|v|, or 0 when |v|^2 is 0 (or flushed to 0) so that a degenerate normal shades to 0 instead of NaN.
vec3 safe_normalize(vec3 v) {
    float len2 = dot(v, v);
    return len2 > 0.0 ? v * inversesqrt(len2) : vec3(0.0);
}

// Outgoing radiance [W/(m^2 sr)] per channel. `normal` is unit (or 0) on the side being seen.
vec3 radiance_out(MaterialGpu material, vec3 position, vec3 normal, vec3 to_viewer) {
    vec3 radiance = vec3(0.0);
    if (lights.sun.irradiance.w != 0.0) {
        float n_dot_l = dot(normal, lights.sun.direction.xyz);
        radiance += lambert_brdf(material.kd.rgb) * sun_irradiance_delta(lights.sun.irradiance.rgb, n_dot_l);
    }
    return radiance;
}

#endif
