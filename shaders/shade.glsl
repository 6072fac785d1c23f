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

// Irradiance [W/m^2] per channel from all the lights (models chosen by lights.counts.y (sun) and .z (disks)).
vec3 irradiance(vec3 position, vec3 normal) {
    vec3 e = vec3(0.0);
    if (lights.sun.irradiance.w != 0.0) {
        float n_dot_l = dot(normal, lights.sun.direction.xyz);
        if (lights.counts.y == SUN_MODEL_DELTA) {
            e += sun_irradiance_delta(lights.sun.irradiance.rgb, n_dot_l);
        } else {
            e += sun_irradiance_disk(lights.sun.irradiance.rgb, n_dot_l, lights.sun.direction.w);
        }
    }
    for (uint i = 0u; i < lights.counts.x; ++i) {
        DiskGpu d = lights.disks[i];
        float omega = lights.counts.z == DISK_MODEL_SMALL_SOURCE
            ? disk_projected_solid_angle_small_source(position, normal, d.center_radius.xyz, d.direction.xyz, d.center_radius.w)
            : disk_projected_solid_angle(position, normal, d.center_radius.xyz, d.direction.xyz, d.center_radius.w);
        e += d.radiance.rgb * omega;
    }
    if (lights.sky.w != 0.0) {
        e += sky_irradiance(lights.sky.rgb, normal.y);
    }
    return e;
}

// Outgoing radiance [W/(m^2 sr)] per channel. `normal` is unit (or 0) on the side being seen.
vec3 radiance_out(MaterialGpu material, vec3 position, vec3 normal, vec3 to_viewer) {
    // An undefined (zero) normal reflects nothing: n.l = 0 would otherwise read as a surface edge-on to every light.
    if (dot(normal, normal) == 0.0) {
        return vec3(0.0);
    }
    return lambert_brdf(material.kd.rgb) * irradiance(position, normal);
}

#endif
