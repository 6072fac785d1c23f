// Radiometry in f32. Mirrors src/shading/radiometry.rs name for name (the Rust is the specification).
// Units: radians, steradians, W/m^2 (irradiance), W/(m^2 sr) (radiance).
#ifndef SUNSHADE_RADIOMETRY_GLSL
#define SUNSHADE_RADIOMETRY_GLSL

const float PI = 3.14159265358979323846;
const float INV_PI = 0.31830988618379067154;

// Irradiance [W/m^2] from the sun as a direction (delta light): E = E_perp * max(0, n.l).
vec3 sun_irradiance_delta(vec3 irradiance_normal, float n_dot_l) {
    return irradiance_normal * max(n_dot_l, 0.0);
}

#endif
